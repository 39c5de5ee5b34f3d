//! Planned references: on five axes (docs/design/five-axis.md §5.3b) the joints chosen
//! over the whole path within the machine's travel, a feed within every joint's velocity
//! and acceleration limits, a jerk filter; on the XY table (docs/design/two-axis.md §4.9)
//! blended corners and jerk-limited motions piece by piece under a look-ahead. All at
//! planning; O(1) per sample after.

mod feed;
mod jerk_filter;
mod joint_path;
mod nurbs_pieces;
mod piece_profile;
mod planned_reference;
mod xy_plan;
mod xy_reference;

pub use feed::{FeedConstraints, FeedPoint, FeedProfile};
pub use jerk_filter::JerkFilter;
pub use joint_path::{plan_joints, JointPath, NODE_BUDGET};
pub use planned_reference::{
    plan_for, set_sample_budget, Cursor, Plan, PlanInputs, PlanReport, PlannedReference,
    PlannedSample, QUANTUM, SAMPLE_BUDGET,
};
pub use xy_plan::{planned_geometry, XyCursor, XyLimits, XyPlan, XyPoint};
pub use xy_reference::XyReference;
