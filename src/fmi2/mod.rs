//! The FMI 2.0 Co-Simulation boundary: the only code that knows FMI types and the only
//! place with `unsafe`. Models (`crate::models`) are plain Rust behind it.

mod exports;
mod fmu_state;
mod instance;
mod logger;
mod plans;
mod registry;
mod resource_uri;
mod slab;
mod state_machine;
mod status;

pub use logger::Category as LogCategory;
#[cfg(feature = "test-hooks")]
pub use plans::set_plan_sample_budget;

/// The functions of FMI 2.0 for Co-Simulation, in the order of fmi2Functions.h: what the
/// library exports, and nothing else (the packager checks every platform's binary).
pub const FMI2_CO_SIMULATION: [&str; 34] = [
    // Common functions.
    "fmi2GetTypesPlatform",
    "fmi2GetVersion",
    "fmi2SetDebugLogging",
    "fmi2Instantiate",
    "fmi2FreeInstance",
    "fmi2SetupExperiment",
    "fmi2EnterInitializationMode",
    "fmi2ExitInitializationMode",
    "fmi2Terminate",
    "fmi2Reset",
    "fmi2GetReal",
    "fmi2GetInteger",
    "fmi2GetBoolean",
    "fmi2GetString",
    "fmi2SetReal",
    "fmi2SetInteger",
    "fmi2SetBoolean",
    "fmi2SetString",
    "fmi2GetFMUstate",
    "fmi2SetFMUstate",
    "fmi2FreeFMUstate",
    "fmi2SerializedFMUstateSize",
    "fmi2SerializeFMUstate",
    "fmi2DeSerializeFMUstate",
    "fmi2GetDirectionalDerivative",
    // Co-Simulation functions.
    "fmi2SetRealInputDerivatives",
    "fmi2GetRealOutputDerivatives",
    "fmi2DoStep",
    "fmi2CancelStep",
    "fmi2GetStatus",
    "fmi2GetRealStatus",
    "fmi2GetIntegerStatus",
    "fmi2GetBooleanStatus",
    "fmi2GetStringStatus",
];
