//! Control laws: discrete PID, the Mamdani fuzzy gain scheduler with its rule tables, the
//! scalar contour law and the N-axis cross-coupled contour controller around it
//! (docs/design/two-axis.md §4.2, 4.3), and a servo drive's velocity loop (§4.10).

mod ccc_law;
mod config;
mod correction_guard;
mod cross_coupled;
mod feed_forward;
mod five_axis;
mod fuzzy;
mod lanes;
mod pid;
mod rules;
mod velocity_drive;

pub use ccc_law::{folded_inputs, CccLaw, CccStep, VectorLaw};
pub use config::{
    CccConfig, CccMode, ConfigError, ControllerConfig, FuzzyFactor, FuzzyFactors, Gain, Parameter,
};
pub use correction_guard::{CorrectionGuard, Hold, LIMIT_SLACK};
pub use cross_coupled::{ControlOutput, CrossCoupledController};
pub use feed_forward::FeedForward;
pub use five_axis::{FiveAxisConfig, FiveAxisController, FiveAxisOutput, SampleError};
pub use fuzzy::{centroid, evaluate_table, membership, FuzzyEngine, FuzzyOutput, UNIVERSE};
pub use pid::{Pid, PidGains};
pub use rules::{RuleTable, Term, FUZZY_PID_RULES, KD_RULES, KI_RULES, KP_RULES};
pub use velocity_drive::{DriveParams, VelocityDrive};
