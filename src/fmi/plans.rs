//! The plans of this library's instances: one five-axis [`Planner`], one [`XyPlans`] and
//! one [`TrueErrorIndexes`] for the process, which owns the instances, so instances on one
//! path and limits share a plan or an index and a restored state finds its own instead of
//! making it again (contour-core keeps no state of its own).

use std::sync::{Arc, OnceLock};

use crate::framework::model::Environment;

use contour_core::contour::planar::TrueErrorIndexes;
use contour_core::path::five_axis::Planner;
use contour_core::path::planar::XyPlans;

/// The planner every instance of this library is given.
pub fn planner() -> Arc<Planner> {
    static PLANNER: OnceLock<Arc<Planner>> = OnceLock::new();
    Arc::clone(PLANNER.get_or_init(|| Arc::new(Planner::new())))
}

/// The XY plan cache every instance of this library is given.
pub fn xy_plans() -> Arc<XyPlans> {
    static PLANS: OnceLock<Arc<XyPlans>> = OnceLock::new();
    Arc::clone(PLANS.get_or_init(|| Arc::new(XyPlans::new())))
}

/// The exact-distance index cache every instance of this library is given.
pub fn true_error_indexes() -> Arc<TrueErrorIndexes> {
    static INDEXES: OnceLock<Arc<TrueErrorIndexes>> = OnceLock::new();
    Arc::clone(INDEXES.get_or_init(|| Arc::new(TrueErrorIndexes::new())))
}

/// A new instance's environment: this process's plans, no resources yet.
pub fn environment() -> Environment {
    Environment {
        resource_dir: None,
        planner: planner(),
        xy_plans: xy_plans(),
        indexes: true_error_indexes(),
    }
}

/// Sets the most samples a plan may have (a fuzzer's time limit; see
/// [`Planner::set_sample_budget`]). Only in test builds: a packaged FMU plans within the
/// default budget.
#[cfg(feature = "test-hooks")]
pub fn set_plan_sample_budget(samples: u64) {
    planner().set_sample_budget(samples);
}
