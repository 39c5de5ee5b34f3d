//! The FMUs through the C ABI of the built library, as importers call them: one test
//! binary (the library is linked once), one module per topic. Most modules dlopen the
//! cdylib (`common::lib`); `no_alloc` and `threads` call the same functions linked
//! statically (`common::linked`). Modules marked `test-hooks` need that feature (the
//! `FaultProbe` model); `make test` and `make check` enable it.

mod common;

#[cfg(feature = "test-hooks")]
mod bad_inputs;
#[cfg(feature = "test-hooks")]
mod bad_inputs_fmi3;
#[cfg(target_os = "linux")]
mod exported_symbols;
mod fmi3;
mod fmu_state;
#[cfg(feature = "test-hooks")]
mod handles;
#[cfg(feature = "test-hooks")]
mod instantiation;
#[cfg(feature = "test-hooks")]
mod logging;
mod models_vs_sim;
mod no_alloc;
mod plant_effects;
mod servo_drive;
mod si_interface;
#[cfg(feature = "test-hooks")]
mod state_machine;
mod threads;
mod two_axis_models;
