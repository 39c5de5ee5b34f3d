//! Control laws: discrete PID, the Mamdani fuzzy gain scheduler with its rule tables, and
//! the two-axis cross-coupled contour controller (docs/design.md §4.2, 4.3).

pub mod ccc;
pub mod fuzzy;
pub mod pid;
pub mod rules;

pub use ccc::{
    folded_inputs, CccConfig, CccLaw, CccMode, CccStep, ConfigError, ControlOutput,
    ControllerConfig, CrossCoupledController, FuzzyFactors,
};
pub use fuzzy::{FuzzyEngine, FuzzyOutput};
pub use pid::{Pid, PidGains};
pub use rules::{RuleTable, Term};
