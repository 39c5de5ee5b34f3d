//! The FMI 2.0 Co-Simulation boundary: the only code that knows FMI types and the only
//! place with `unsafe`. Models (`crate::models`) are plain Rust behind it.

/// The FMI 2.0 C types and constants, generated from third_party/fmi2/ by
/// `cargo run -p xtask -- bindings` and kept as bindgen wrote it (rustfmt would make it
/// differ from the generator's output). Public for the ABI tests, which call the library
/// through the same types an importer uses.
#[rustfmt::skip]
pub mod bindings;
mod exports;
mod fmu_state;
mod instance;
mod logger;
mod registry;
mod resource_uri;
mod state_machine;
mod status;

pub use logger::Category as LogCategory;
