//! Planning bounded by the sample budget, and plans found again on restore (the fuzz
//! finding of `deserialize_state`: a restored five-axis state planned for seconds, three
//! times over, under the sanitizers).

use std::sync::Arc;

use contour_core::kinematics::TableTiltingAc;
use contour_core::limits::{JointLimits, PathLimits};
use contour_core::path::five_axis::{FiveAxisInputs, Planner, ToolPath};

fn figure_eight(limits: PathLimits) -> FiveAxisInputs {
    FiveAxisInputs {
        path: ToolPath::builtin("figure_eight").expect("a built-in"),
        builtin: Some("figure_eight".into()),
        feeds: Vec::new(),
        machine: TableTiltingAc::default(),
        joints: JointLimits::DEFAULT,
        limits,
        ts: 1e-3,
    }
}

#[test]
fn planning_work_is_bounded_by_the_sample_budget() {
    // The fuzzers' budget: the figure-eight's own plan (930 samples, about 55 000
    // evaluations of the limits) fits; 30 times the acceleration at the same jerk asks a
    // jerk filter 600 samples long and about a million evaluations, refused at 320 000.
    let planner = Planner::new();
    planner.set_sample_budget(20_000);
    let base = PathLimits::at_feed(50.0);
    assert!(planner
        .plan(&figure_eight(base), &|i| format!("{i}"))
        .is_ok());
    let heavy = PathLimits {
        accel: 30.0 * base.accel,
        ..base
    };
    let error = planner
        .plan(&figure_eight(heavy), &|i| format!("{i}"))
        .expect_err("beyond the work budget")
        .to_string();
    assert!(
        error.contains("more than 320000 evaluations of the limits"),
        "{error}"
    );
}

#[test]
fn a_plan_dropped_by_its_last_instance_is_found_again() {
    // Restoring a state checks it (plan, drop) and then takes it (the same plan): the
    // second must not plan again.
    let inputs = figure_eight(PathLimits {
        tolerance: 0.004,
        ..PathLimits::at_feed(40.0)
    });
    let planner = Planner::new();
    let first = planner.plan(&inputs, &|i| format!("{i}")).expect("plans");
    let kept = Arc::downgrade(&first);
    drop(first);
    let alive = kept.upgrade().expect("the plan outlives its last instance");
    let again = planner.plan(&inputs, &|i| format!("{i}")).expect("plans");
    assert!(Arc::ptr_eq(&alive, &again));
    // Another planner keeps its own plans: no state is shared through the core.
    let other = Planner::new()
        .plan(&inputs, &|i| format!("{i}"))
        .expect("plans");
    assert!(!Arc::ptr_eq(&alive, &other));
}
