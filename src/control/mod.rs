//! Control laws: discrete PID, the Mamdani fuzzy gain scheduler with its rule tables, the
//! scalar contour law and the N-axis cross-coupled contour controller around it
//! (docs/design.md §4.2, 4.3).

pub mod ccc_law;
pub mod config;
pub mod cross_coupled;
pub mod five_axis;
pub mod fuzzy;
pub mod pid;
pub mod rules;

pub use ccc_law::{folded_inputs, CccLaw, CccStep, VectorLaw};
pub use config::{
    CccConfig, CccMode, ConfigError, ControllerConfig, FuzzyFactor, FuzzyFactors, Gain, Parameter,
};
pub use cross_coupled::{ControlOutput, CrossCoupledController};
pub use five_axis::{FiveAxisConfig, FiveAxisController, FiveAxisOutput, SampleError};
pub use fuzzy::{FuzzyEngine, FuzzyOutput};
pub use pid::{Pid, PidGains};
pub use rules::{RuleTable, Term};
