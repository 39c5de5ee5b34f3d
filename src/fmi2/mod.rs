//! The FMI 2.0 Co-Simulation boundary: the only code that knows FMI types and the only
//! place with `unsafe`. Models (`crate::models`) are plain Rust behind it.

mod exports;
mod fmu_state;
mod instance;
mod logger;
mod registry;
mod resource_uri;
mod state_machine;
mod status;

pub use logger::Category as LogCategory;
