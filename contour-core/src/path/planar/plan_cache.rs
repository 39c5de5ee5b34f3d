//! The XY plans alive: instances on the same path and limits share one plan, and a
//! restored state finds its plan instead of planning again (a NURBS path's plan takes
//! milliseconds; an importer may restore at every step). Whoever owns the instances owns
//! the cache (the FMU library one per process), as with the five-axis [`Planner`].
//!
//! [`Planner`]: crate::path::five_axis::Planner

use std::sync::Arc;

use super::plan::{XyLimits, XyPlan};
use super::Path;
use crate::path::PathError;
use crate::shared::Shared;

/// Plans XY paths, keeping each plan while an instance holds it, and the one used last.
#[derive(Debug, Default)]
pub struct XyPlans(Shared<(Path, XyLimits), XyPlan>);

impl XyPlans {
    /// An empty cache.
    pub fn new() -> Self {
        XyPlans::default()
    }

    /// How many plans were made, not found kept.
    pub fn plans_made(&self) -> u64 {
        self.0.made()
    }

    /// The plan of `path` within `limits`, kept or made now.
    pub fn plan(&self, path: &Path, limits: &XyLimits) -> Result<Arc<XyPlan>, PathError> {
        self.0.get_or_make(
            |(p, l)| p == path && l == limits,
            || (path.clone(), *limits),
            || XyPlan::new(path, limits),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::path::planar::builtin;

    #[test]
    fn a_plan_is_made_once_for_a_path_and_its_limits_and_kept_while_used() {
        let plans = XyPlans::new();
        let path = builtin::by_name("infinity").unwrap();
        let limits = XyLimits::example();
        let a = plans.plan(&path, &limits).unwrap();
        let b = plans.plan(&path, &limits).unwrap();
        assert!(Arc::ptr_eq(&a, &b));
        assert_eq!(plans.plans_made(), 1);
        // Other limits, another plan; the same plan as a fresh one, bit for bit.
        let slower = XyLimits {
            feed: 40.0,
            ..limits
        };
        let c = plans.plan(&path, &slower).unwrap();
        assert!(!Arc::ptr_eq(&a, &c));
        assert_eq!(*a, XyPlan::new(&path, &limits).unwrap());
        assert_eq!(plans.plans_made(), 2);
        // Let go of by everyone but the cache's last used: that one is still found.
        drop((a, b));
        let again = plans.plan(&path, &slower).unwrap();
        assert!(Arc::ptr_eq(&again, &c));
        drop((again, c));
        plans.plan(&path, &slower).unwrap();
        assert_eq!(plans.plans_made(), 2);
        plans.plan(&path, &limits).unwrap();
        assert_eq!(plans.plans_made(), 3, "let go of: planned again");
    }
}
