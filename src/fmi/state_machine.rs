//! The FMI 2.0 Co-Simulation state machine (standard section 4.3.3) as one table: for
//! every function taking an instance, the modes in which it may be called.
//!
//! Steps are synchronous, so the standard's `stepInProgress` and `stepCanceled` never
//! occur. A refused call (wrong mode, bad argument) leaves the mode unchanged; only a
//! failing model computation moves to `Error`, and a panic to `Fatal`.

use serde::{Deserialize, Serialize};

use super::standard::Standard;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Mode {
    Instantiated,
    Initialization,
    StepComplete,
    StepFailed,
    Terminated,
    Error,
    Fatal,
}

impl Mode {
    const fn bit(self) -> u8 {
        1 << self as u8
    }
}

/// The instance functions of FMI 2.0 Co-Simulation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Call {
    SetDebugLogging,
    FreeInstance,
    SetupExperiment,
    EnterInitializationMode,
    ExitInitializationMode,
    Terminate,
    Reset,
    GetValues(&'static str),
    SetValues(&'static str),
    /// Get, set, serialize, deserialize and the serialized size of an FMU state.
    FmuState(&'static str),
    FreeFmuState,
    GetDirectionalDerivative,
    /// FMI 3.0 only; allowed where the directional derivative is.
    GetAdjointDerivative,
    SetRealInputDerivatives,
    GetRealOutputDerivatives,
    DoStep,
    CancelStep,
    Status(&'static str),
    /// An FMI 3.0 function these FMUs do not support (Model Exchange, Scheduled Execution,
    /// clocks, configuration and event mode): answered with an error in any live mode.
    Unsupported(&'static str),
}

const INST: u8 = Mode::Instantiated.bit();
const INIT: u8 = Mode::Initialization.bit();
const STEP: u8 = Mode::StepComplete.bit();
const FAIL: u8 = Mode::StepFailed.bit();
const TERM: u8 = Mode::Terminated.bit();
const ERR: u8 = Mode::Error.bit();
const FATAL: u8 = Mode::Fatal.bit();
/// Every mode an instance can be in before a fatal error.
const ALIVE: u8 = INST | INIT | STEP | FAIL | TERM | ERR;
/// No mode: the function is only meaningful in `stepInProgress`, which never occurs.
const NEVER: u8 = 0;

impl Call {
    /// The standard's table (FMI 2.0.4, section 4.3.3), one row per function.
    const fn allowed(self) -> u8 {
        match self {
            Call::SetDebugLogging => ALIVE,
            // Freeing after a fatal error lets the importer release memory; it touches
            // nothing the failed computation left behind.
            Call::FreeInstance => ALIVE | FATAL,
            Call::SetupExperiment => INST,
            Call::EnterInitializationMode => INST,
            Call::ExitInitializationMode => INIT,
            Call::Terminate => STEP | FAIL,
            Call::Reset => ALIVE,
            Call::GetValues(_) => INIT | STEP | FAIL | TERM | ERR,
            Call::SetValues(_) => INST | INIT | STEP,
            Call::FmuState(_) => ALIVE,
            // As for fmi2FreeInstance: after a fatal error the importer must still be able
            // to release the states it holds; freeing one only drops its bytes.
            Call::FreeFmuState => ALIVE | FATAL,
            Call::GetDirectionalDerivative | Call::GetAdjointDerivative => {
                INIT | STEP | FAIL | TERM | ERR
            }
            Call::SetRealInputDerivatives => INST | INIT | STEP,
            Call::GetRealOutputDerivatives => STEP | FAIL | TERM | ERR,
            Call::DoStep => STEP,
            Call::CancelStep => NEVER,
            Call::Status(_) => STEP | FAIL | TERM,
            Call::Unsupported(_) => ALIVE,
        }
    }

    #[inline]
    pub fn is_allowed_in(self, mode: Mode) -> bool {
        self.allowed() & mode.bit() != 0
    }

    /// The C function's name, for log messages.
    /// The function's name in `standard` (calls that exist in one standard only are made
    /// by that standard's exports alone).
    pub fn name(self, standard: Standard) -> &'static str {
        let fmi3 = standard == Standard::Fmi3;
        match self {
            Call::SetDebugLogging if fmi3 => "fmi3SetDebugLogging",
            Call::SetDebugLogging => "fmi2SetDebugLogging",
            Call::FreeInstance if fmi3 => "fmi3FreeInstance",
            Call::FreeInstance => "fmi2FreeInstance",
            Call::SetupExperiment => "fmi2SetupExperiment",
            Call::EnterInitializationMode if fmi3 => "fmi3EnterInitializationMode",
            Call::EnterInitializationMode => "fmi2EnterInitializationMode",
            Call::ExitInitializationMode if fmi3 => "fmi3ExitInitializationMode",
            Call::ExitInitializationMode => "fmi2ExitInitializationMode",
            Call::Terminate if fmi3 => "fmi3Terminate",
            Call::Terminate => "fmi2Terminate",
            Call::Reset if fmi3 => "fmi3Reset",
            Call::Reset => "fmi2Reset",
            Call::FreeFmuState if fmi3 => "fmi3FreeFMUState",
            Call::FreeFmuState => "fmi2FreeFMUstate",
            Call::GetValues(name)
            | Call::SetValues(name)
            | Call::FmuState(name)
            | Call::Status(name)
            | Call::Unsupported(name) => name,
            Call::GetDirectionalDerivative if fmi3 => "fmi3GetDirectionalDerivative",
            Call::GetDirectionalDerivative => "fmi2GetDirectionalDerivative",
            Call::GetAdjointDerivative => "fmi3GetAdjointDerivative",
            Call::SetRealInputDerivatives => "fmi2SetRealInputDerivatives",
            Call::GetRealOutputDerivatives if fmi3 => "fmi3GetOutputDerivatives",
            Call::GetRealOutputDerivatives => "fmi2GetRealOutputDerivatives",
            Call::DoStep if fmi3 => "fmi3DoStep",
            Call::DoStep => "fmi2DoStep",
            Call::CancelStep => "fmi2CancelStep",
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn do_step_only_after_initialization() {
        assert!(Call::DoStep.is_allowed_in(Mode::StepComplete));
        for mode in [
            Mode::Instantiated,
            Mode::Initialization,
            Mode::Terminated,
            Mode::Error,
        ] {
            assert!(!Call::DoStep.is_allowed_in(mode));
        }
    }

    /// The FMU state rows of FMI 2.0's table (and the Reference FMUs' masks): every mode
    /// an instance can be in (Instantiated, InitializationMode, stepComplete, stepFailed,
    /// terminated, error), not fatal; fmi2FreeFMUstate also in fatal (our extension, like
    /// fmi2FreeInstance).
    #[test]
    fn fmu_state_functions_follow_the_standard_table() {
        let alive = [
            Mode::Instantiated,
            Mode::Initialization,
            Mode::StepComplete,
            Mode::StepFailed,
            Mode::Terminated,
            Mode::Error,
        ];
        for name in [
            "fmi2GetFMUstate",
            "fmi2SetFMUstate",
            "fmi2SerializedFMUstateSize",
            "fmi2SerializeFMUstate",
            "fmi2DeSerializeFMUstate",
        ] {
            for mode in alive {
                assert!(Call::FmuState(name).is_allowed_in(mode), "{name} {mode:?}");
            }
            assert!(!Call::FmuState(name).is_allowed_in(Mode::Fatal), "{name}");
        }
        for mode in alive.into_iter().chain([Mode::Fatal]) {
            assert!(Call::FreeFmuState.is_allowed_in(mode), "{mode:?}");
        }
    }

    #[test]
    fn fatal_allows_only_free() {
        let calls = [
            Call::SetDebugLogging,
            Call::Reset,
            Call::GetValues("fmi2GetReal"),
            Call::FmuState("fmi2GetFMUstate"),
            Call::DoStep,
        ];
        for call in calls {
            assert!(!call.is_allowed_in(Mode::Fatal), "{call:?}");
        }
        assert!(Call::FreeInstance.is_allowed_in(Mode::Fatal));
        assert!(Call::FreeFmuState.is_allowed_in(Mode::Fatal));
    }
}
