//! Planned references (docs/design/five-axis.md §5.3b): the joints chosen over the whole
//! path within the machine's travel, a feed within every joint's velocity and
//! acceleration limits, a jerk filter, all at planning; O(1) per sample after.

mod feed;
mod jerk_filter;
mod joint_path;
mod planned_reference;

pub use feed::{FeedConstraints, FeedPoint, FeedProfile};
pub use jerk_filter::JerkFilter;
pub use joint_path::{plan_joints, JointPath, NODE_BUDGET};
pub use planned_reference::{
    plan_for, set_sample_budget, Cursor, Plan, PlanInputs, PlanReport, PlannedReference,
    PlannedSample, QUANTUM, SAMPLE_BUDGET,
};
