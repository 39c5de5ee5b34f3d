//! Planning five-axis references, and the plans alive: instances on the same path and
//! limits share one plan, and a restored state finds it instead of planning again. The
//! [`Planner`] belongs to whoever owns the instances' lifetimes (the FMU library keeps one
//! per process, an in-process loop its own), so the core holds no state of its own.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex, Weak};

use super::plan::{FiveAxisPlan, SAMPLE_BUDGET};
use super::{FeedChange, ToolPath};
use crate::kinematics::TableTiltingAc;
use crate::limits::{JointLimits, PathLimits};
use crate::path::PathError;

/// What a plan is made from: the programmed path (a built-in by name), the machine, its
/// limits and the sample period. Saved with the place on the plan; restoring plans again
/// (or finds the plan kept by the [`Planner`]).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct FiveAxisInputs {
    /// The programmed path (saved by name when it is the built-in `builtin`, see
    /// `SavedInputs`).
    pub path: ToolPath,
    /// The built-in's name when the path is one.
    pub builtin: Option<String>,
    /// The program's speeds move by move (a CL file's `FEDRAT`s and `RAPID`s); none:
    /// `limits.feed` throughout.
    pub feeds: Vec<FeedChange>,
    /// The machine's geometry.
    pub machine: TableTiltingAc,
    /// The joints' limits.
    pub joints: JointLimits,
    /// The path's limits and tolerances.
    pub limits: PathLimits,
    /// The sample period, s.
    pub ts: f64,
}

/// Plans five-axis references within a sample budget, and keeps the plans alive by a
/// fingerprint of their inputs: instances on the same path and limits share one, and a
/// restored state finds it instead of planning again.
#[derive(Debug)]
pub struct Planner {
    /// The most samples a plan may have (at least 1).
    sample_budget: AtomicU64,
    /// Each plan alive with its inputs' fingerprint and the inputs (compared in full on
    /// a fingerprint's match: a collision plans anew rather than share a plan).
    plans: Mutex<Vec<(u64, FiveAxisInputs, Weak<FiveAxisPlan>)>>,
    /// The plans used last, kept alive after their instances let go of them: restoring a
    /// state checks it (a plan made and dropped) and then takes it (the same plan again),
    /// and an importer that rolls back between states of two plans would plan each time.
    recent: Mutex<[Option<Arc<FiveAxisPlan>>; RECENT_PLANS]>,
    /// Plans made (not found kept).
    made: AtomicU64,
}

const RECENT_PLANS: usize = 2;
/// Larger plans are not kept beyond their instances (about 120 bytes a node).
const RECENT_NODES: usize = 200_000;

impl Default for Planner {
    fn default() -> Self {
        Planner::new()
    }
}

impl Planner {
    /// A planner with no plans and the default budget, [`SAMPLE_BUDGET`].
    pub const fn new() -> Self {
        Planner {
            sample_budget: AtomicU64::new(SAMPLE_BUDGET),
            plans: Mutex::new(Vec::new()),
            recent: Mutex::new([None, None]),
            made: AtomicU64::new(0),
        }
    }

    /// Sets the most samples a plan may have (at least 1): a host that must answer within a
    /// time (a fuzzer's timeout) lowers it, and a longer plan is refused like any other.
    pub fn set_sample_budget(&self, samples: u64) {
        self.sample_budget.store(samples.max(1), Ordering::Relaxed);
    }

    /// The most samples a plan may have.
    pub fn sample_budget(&self) -> u64 {
        self.sample_budget.load(Ordering::Relaxed)
    }

    /// How many plans were made, not found kept.
    pub fn plans_made(&self) -> u64 {
        self.made.load(Ordering::Relaxed)
    }

    /// The plan for `inputs`, kept or made now; `name` names a programmed pose in
    /// messages.
    pub fn plan(
        &self,
        inputs: &FiveAxisInputs,
        name: &dyn Fn(usize) -> String,
    ) -> Result<Arc<FiveAxisPlan>, PathError> {
        let key = fingerprint(inputs);
        {
            let mut plans = self.plans.lock().unwrap_or_else(|e| e.into_inner());
            plans.retain(|(_, _, plan)| plan.strong_count() > 0);
            if let Some(plan) = plans
                .iter()
                .find(|(k, made_from, _)| *k == key && made_from == inputs)
                .and_then(|(_, _, p)| p.upgrade())
            {
                drop(plans);
                self.remember(&plan);
                return Ok(plan);
            }
        }
        self.made.fetch_add(1, Ordering::Relaxed);
        let poses = inputs.path.poses(PLAN_CHORD)?;
        let plan = Arc::new(FiveAxisPlan::within_budget(
            (&poses, &inputs.feeds),
            inputs.machine,
            &inputs.joints,
            &inputs.limits,
            inputs.ts,
            name,
            self.sample_budget(),
        )?);
        self.plans.lock().unwrap_or_else(|e| e.into_inner()).push((
            key,
            inputs.clone(),
            Arc::downgrade(&plan),
        ));
        self.remember(&plan);
        Ok(plan)
    }

    /// Puts `plan` first among the recent plans.
    fn remember(&self, plan: &Arc<FiveAxisPlan>) {
        if plan.nodes() > RECENT_NODES {
            return;
        }
        let mut recent = self.recent.lock().unwrap_or_else(|e| e.into_inner());
        let at = recent
            .iter()
            .position(|p| p.as_ref().is_some_and(|p| Arc::ptr_eq(p, plan)))
            .unwrap_or(RECENT_PLANS - 1);
        recent[..=at].rotate_right(1);
        recent[0] = Some(Arc::clone(plan));
    }
}

/// A fingerprint of what a plan is made from, the same in every build and on every
/// platform: FNV-1a over the inputs' postcard bytes, a built-in by its name. The plan
/// cache's key, and what a saved state's inputs are checked against before they are
/// planned (a damaged state is refused without planning).
pub fn fingerprint(inputs: &FiveAxisInputs) -> u64 {
    let mut hash = Fnv::default();
    match &inputs.builtin {
        Some(name) => {
            hash.write(&[1]);
            hash.write(name.as_bytes());
        }
        None => {
            hash.write(&[0]);
            hash.write(&postcard::to_stdvec(&inputs.path).unwrap_or_default());
        }
    }
    let rest = (
        &inputs.machine,
        &inputs.joints,
        &inputs.limits,
        inputs.ts,
        &inputs.feeds,
    );
    hash.write(&postcard::to_stdvec(&rest).unwrap_or_default());
    hash.0
}

/// FNV-1a, 64 bits.
struct Fnv(u64);

impl Default for Fnv {
    fn default() -> Self {
        Fnv(0xcbf2_9ce4_8422_2325)
    }
}

impl Fnv {
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = (self.0 ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3);
        }
    }
}

/// The chord a curve pair is sampled at for planning, mm: the planned tip leaves the
/// curve by at most chord²·κ/8 (2.5 nm at a 5 mm radius).
const PLAN_CHORD: f64 = 0.01;

#[cfg(test)]
mod tests {
    use super::Fnv;

    /// FNV-1a 64 as its authors publish it (the reference test vectors of
    /// draft-eastlake-fnv): the fingerprint saved states carry is that function.
    #[test]
    fn the_hash_is_fnv_1a_64() {
        for (text, expected) in [
            ("", 0xcbf2_9ce4_8422_2325_u64),
            ("a", 0xaf63_dc4c_8601_ec8c),
            ("foobar", 0x8594_4171_f739_67e8),
        ] {
            let mut hash = Fnv::default();
            hash.write(text.as_bytes());
            assert_eq!(hash.0, expected, "{text:?}");
        }
    }
}
