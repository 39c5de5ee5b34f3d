//! The five-axis machine's paths (docs/design/five-axis.md §5.3): the tool path, its tip
//! with the tool axis along it in the workpiece frame ([`ToolPath`]); the joint reference
//! at a constant tip feed ([`JointReference`], §5.3a); the plan within the joints' limits
//! ([`FiveAxisPlan`]: the joints chosen over the whole path, the feed, the jerk filter,
//! §5.3b), made and kept by a [`Planner`]; and the reference an FMU runs, either of the two
//! ([`FiveAxisReference`]).

pub mod cam_examples;
mod constraints;
mod jerk_filter;
mod joint_path;
mod joint_reference;
mod plan;
mod planned_reference;
mod planner;
mod programmed_feed;
mod reference;
mod tool_path;

pub use jerk_filter::JerkFilter;
pub use joint_path::{plan_joints, JointPath, NODE_BUDGET};
pub use joint_reference::{JointReference, JointSample};
pub use plan::{
    FiveAxisCursor, FiveAxisPlan, FiveAxisPlanReport, PlanSummary, PlannedSample, QUANTUM,
    SAMPLE_BUDGET,
};
pub use planned_reference::{PlannedFiveAxisReference, SavedPlannedReference};
pub use planner::{fingerprint, FiveAxisInputs, Planner};
pub use programmed_feed::{check_feeds, feed_of_move, greatest_feed, program_feeds, FeedChange};
pub use reference::{FiveAxisReference, ReferenceSample, SavedFiveAxisReference};
pub use tool_path::{
    load_poses, load_poses_with, load_program, machine_moves, ToolPath, ToolPathData,
    BUILTIN_TOOL_PATHS, GCODE_ARC_SAG,
};
