//! `contour-cosim`: a fixed-step FMI 2.0 Co-Simulation master in Rust. It runs a loop
//! described by SSP files (the loops of `python/contour_fmu/loops/`, or a user's own) through
//! its FMUs, ours or other tools', and gives the same trajectories as `contour_fmu.master`
//! (Python, on fmpy) bit for bit, at the cost of the FMUs themselves.
//!
//! [`ssp`] reads the loop, [`system`] loads and checks its FMUs, [`simulation`] runs it;
//! [`metrics`] measures a run where it ran (a campaign's batch); [`fmi2`] is the only place that calls into an FMU (the only `unsafe`), and [`watchdog`]
//! notices a call that does not return.

pub mod archive;
pub mod fmi2;
pub mod metrics;
pub mod model_description;
pub mod simulation;
pub mod ssp;
pub mod system;
pub mod watchdog;

pub use simulation::{End, Experiment, Recording, Scheme, Simulation, Trace};
pub use ssp::{SystemStructure, Value};
pub use system::System;

/// Why the master cannot go on.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Error {
    /// Before any run: a file, a wiring, a setting or a value the master cannot use. The
    /// message names the file or the variable.
    Refused(String),
    /// A run ended by an FMU: the unit, the call, its status and the FMU's last messages.
    Failed(String),
}

impl std::fmt::Display for Error {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Error::Refused(message) | Error::Failed(message) => f.write_str(message),
        }
    }
}

impl std::error::Error for Error {}
