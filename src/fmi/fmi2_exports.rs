//! The 34 exported `fmi2*` functions of FMI 2.0 Co-Simulation. Each one only converts C
//! arguments and hands over to [`Instance`]; [`dispatch`] supplies what all share: the
//! instance lookup in the registry (an FMI 3.0 instance is refused), the lock, the state
//! machine, logging and panic capture.

#![allow(non_snake_case)]

use std::ffi::c_char;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::ptr;

use fmi2_bindings::*;

use super::c_args::{array, array_mut, c_str, slice, slice_mut};
use super::instance::Instance;
use super::logger::{Callback, Category, Logger};
use super::resource_uri::resource_dir;
use super::standard::Standard;
use super::state_calls;
use super::state_machine::Call;
use super::status::{Failure, Outcome, Status};
use crate::framework::variables::{Value, VarType};
use crate::models;

/// [`super::dispatch::dispatch`] for an FMI 2.0 instance.
#[inline]
fn dispatch(
    c: fmi2Component,
    call: Call,
    body: impl FnOnce(&mut Instance) -> Outcome,
) -> fmi2Status {
    super::dispatch::dispatch(Standard::Fmi2, c as usize, call, body)
}

/// [`super::dispatch::dispatch_fast`] for an FMI 2.0 instance.
#[inline(always)]
fn dispatch_fast(
    c: fmi2Component,
    call: Call,
    fast: impl FnOnce(&mut Instance) -> Option<()>,
    body: impl FnOnce(&mut Instance) -> Outcome,
) -> fmi2Status {
    super::dispatch::dispatch_fast(Standard::Fmi2, c as usize, call, fast, body)
}

// ---------------------------------------------------------------------------------------
// Library information

#[no_mangle]
pub extern "C" fn fmi2GetTypesPlatform() -> *const c_char {
    fmi2TypesPlatform.as_ptr() as *const c_char
}

#[no_mangle]
pub extern "C" fn fmi2GetVersion() -> *const c_char {
    fmi2Version.as_ptr() as *const c_char
}

// ---------------------------------------------------------------------------------------
// Life cycle

/// # Safety
/// Arguments as the FMI 2.0 standard defines them.
#[no_mangle]
pub unsafe extern "C" fn fmi2Instantiate(
    instanceName: fmi2String,
    fmuType: fmi2Type,
    fmuGUID: fmi2String,
    fmuResourceLocation: fmi2String,
    functions: *const fmi2CallbackFunctions,
    _visible: fmi2Boolean,
    loggingOn: fmi2Boolean,
) -> fmi2Component {
    let result = catch_unwind(AssertUnwindSafe(|| {
        // Without callbacks there is no way to say what went wrong: just refuse.
        let functions = functions.as_ref()?;
        functions.logger?;
        let name = c_str(instanceName).unwrap_or("");
        let logger = Logger::new(
            Callback::fmi2(functions.logger),
            functions.componentEnvironment,
            name,
            loggingOn != 0,
        );
        let refuse = |message: String| {
            logger.log(
                Status::Error,
                Category::StatusError,
                &format!("fmi2Instantiate: {message}"),
            );
            logger.flush();
            None
        };
        if name.trim().is_empty() {
            return refuse("the instance name is NULL or empty".into());
        }
        if fmuType != fmi2Type_fmi2CoSimulation {
            return refuse(format!(
                "fmuType {fmuType} is not supported: these FMUs are Co-Simulation only"
            ));
        }
        let Some(guid) = c_str(fmuGUID) else {
            return refuse("the GUID is NULL or not UTF-8".into());
        };
        let Some(interface) = models::by_guid(guid) else {
            let known: Vec<String> = models::interfaces()
                .iter()
                .map(|i| format!("{} ({}) {}", i.model.identifier, i.units.name(), i.guid))
                .collect();
            return refuse(format!(
                "unknown GUID {guid}: the modelDescription.xml does not match this binary (it serves {})",
                known.join(", ")
            ));
        };
        let mut environment = super::plans::environment();
        if !fmuResourceLocation.is_null() {
            match c_str(fmuResourceLocation)
                .ok_or_else(|| "resource location is not UTF-8".to_string())
                .and_then(resource_dir)
            {
                Ok(dir) => environment.resource_dir = Some(dir),
                Err(message) => logger.log(
                    Status::Warning,
                    Category::StatusWarning,
                    &format!("fmi2Instantiate: {message}; continuing without resources"),
                ),
            }
        }
        let instance =
            Instance::with_interface(Standard::Fmi2, interface, environment, logger, name);
        instance.log_event(&format!(
            "instantiated {} with the {} interface (GUID {guid}, {})",
            interface.model.identifier,
            interface.units.name(),
            crate::build_identity::described()
        ));
        super::dispatch::register(instance, "fmi2Instantiate").map(|h| h as fmi2Component)
    }));
    match result {
        Ok(Some(c)) => c,
        _ => ptr::null_mut(),
    }
}

/// # Safety
/// `c` as returned by `fmi2Instantiate`; it is invalid afterwards. A NULL, freed or
/// foreign `c` is ignored.
#[no_mangle]
pub unsafe extern "C" fn fmi2FreeInstance(c: fmi2Component) {
    super::dispatch::free_instance(Standard::Fmi2, c as usize);
}

/// # Safety
/// Arguments as the FMI 2.0 standard defines them.
#[no_mangle]
pub unsafe extern "C" fn fmi2SetDebugLogging(
    c: fmi2Component,
    loggingOn: fmi2Boolean,
    nCategories: usize,
    categories: *const fmi2String,
) -> fmi2Status {
    dispatch(c, Call::SetDebugLogging, |instance| {
        let pointers = slice(categories, nCategories, "categories")?;
        let mut names = Vec::with_capacity(pointers.len());
        for &p in pointers {
            names.push(c_str(p).ok_or_else(|| Failure::error("a category is NULL or not UTF-8"))?);
        }
        instance.set_debug_logging(loggingOn != 0, &names)
    })
}

/// # Safety
/// Arguments as the FMI 2.0 standard defines them.
#[no_mangle]
pub unsafe extern "C" fn fmi2SetupExperiment(
    c: fmi2Component,
    _toleranceDefined: fmi2Boolean,
    _tolerance: fmi2Real,
    startTime: fmi2Real,
    stopTimeDefined: fmi2Boolean,
    stopTime: fmi2Real,
) -> fmi2Status {
    dispatch(c, Call::SetupExperiment, |instance| {
        instance.setup_experiment(startTime, (stopTimeDefined != 0).then_some(stopTime))
    })
}

/// # Safety
/// `c` as returned by `fmi2Instantiate`.
#[no_mangle]
pub unsafe extern "C" fn fmi2EnterInitializationMode(c: fmi2Component) -> fmi2Status {
    dispatch(
        c,
        Call::EnterInitializationMode,
        Instance::enter_initialization_mode,
    )
}

/// # Safety
/// `c` as returned by `fmi2Instantiate`.
#[no_mangle]
pub unsafe extern "C" fn fmi2ExitInitializationMode(c: fmi2Component) -> fmi2Status {
    dispatch(
        c,
        Call::ExitInitializationMode,
        Instance::exit_initialization_mode,
    )
}

/// # Safety
/// `c` as returned by `fmi2Instantiate`.
#[no_mangle]
pub unsafe extern "C" fn fmi2Terminate(c: fmi2Component) -> fmi2Status {
    dispatch(c, Call::Terminate, Instance::terminate)
}

/// # Safety
/// `c` as returned by `fmi2Instantiate`.
#[no_mangle]
pub unsafe extern "C" fn fmi2Reset(c: fmi2Component) -> fmi2Status {
    dispatch(c, Call::Reset, Instance::reset)
}

// ---------------------------------------------------------------------------------------
// Getting and setting values

/// Shared body of the four getters: check references and type, then convert each value.
unsafe fn get<T>(
    c: fmi2Component,
    name: &'static str,
    var_type: VarType,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut T,
    convert: impl Fn(&Value) -> T,
) -> fmi2Status {
    dispatch(c, Call::GetValues(name), |instance| {
        let vrs = slice(vr, nvr, "vr")?;
        let out = slice_mut(value, nvr, "value")?;
        instance.get_values_checked(vrs, var_type, |i, v| out[i] = convert(v))
    })
}

/// Shared body of the four setters.
unsafe fn set<T: Copy>(
    c: fmi2Component,
    name: &'static str,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const T,
    convert: impl Fn(T) -> Result<Value, String>,
) -> fmi2Status {
    dispatch(c, Call::SetValues(name), |instance| {
        let vrs = slice(vr, nvr, "vr")?;
        let values = slice(value, nvr, "value")?;
        instance.set_values(vrs, |i| convert(values[i]))
    })
}

/// # Safety
/// Arrays of `nvr` elements as the FMI 2.0 standard defines them.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetReal(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2Real,
) -> fmi2Status {
    // One of the sample's calls (with fmi2SetReal and fmi2DoStep).
    dispatch_fast(
        c,
        Call::GetValues("fmi2GetReal"),
        |instance| instance.get_real_values(array(vr, nvr)?, array_mut(value, nvr)?),
        |instance| {
            let vrs = slice(vr, nvr, "vr")?;
            let out = slice_mut(value, nvr, "value")?;
            instance.get_reals(vrs, out)
        },
    )
}

/// # Safety
/// Arrays of `nvr` elements as the FMI 2.0 standard defines them.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetInteger(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2Integer,
) -> fmi2Status {
    get(
        c,
        "fmi2GetInteger",
        VarType::Integer,
        vr,
        nvr,
        value,
        |v| match *v {
            Value::Integer(x) => x,
            _ => unreachable!("type checked"),
        },
    )
}

/// # Safety
/// Arrays of `nvr` elements as the FMI 2.0 standard defines them.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetBoolean(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2Boolean,
) -> fmi2Status {
    get(
        c,
        "fmi2GetBoolean",
        VarType::Boolean,
        vr,
        nvr,
        value,
        |v| match *v {
            Value::Boolean(x) => x as fmi2Boolean,
            _ => unreachable!("type checked"),
        },
    )
}

/// # Safety
/// Arrays of `nvr` elements as the FMI 2.0 standard defines them. The returned strings
/// stay valid until the next call on this instance.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetString(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2String,
) -> fmi2Status {
    dispatch(c, Call::GetValues("fmi2GetString"), |instance| {
        let vrs = slice(vr, nvr, "vr")?;
        let out = slice_mut(value, nvr, "value")?;
        let held = instance.hold_strings(vrs)?;
        for (slot, text) in out.iter_mut().zip(held) {
            *slot = text.as_ptr();
        }
        Ok(())
    })
}

/// # Safety
/// Arrays of `nvr` elements as the FMI 2.0 standard defines them.
#[no_mangle]
pub unsafe extern "C" fn fmi2SetReal(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2Real,
) -> fmi2Status {
    dispatch_fast(
        c,
        Call::SetValues("fmi2SetReal"),
        |instance| instance.set_free_reals(array(vr, nvr)?, array(value, nvr)?),
        |instance| {
            let vrs = slice(vr, nvr, "vr")?;
            let values = slice(value, nvr, "value")?;
            instance.set_reals(vrs, values)
        },
    )
}

/// # Safety
/// Arrays of `nvr` elements as the FMI 2.0 standard defines them.
#[no_mangle]
pub unsafe extern "C" fn fmi2SetInteger(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2Integer,
) -> fmi2Status {
    set(c, "fmi2SetInteger", vr, nvr, value, |x| {
        Ok(Value::Integer(x))
    })
}

/// # Safety
/// Arrays of `nvr` elements as the FMI 2.0 standard defines them.
#[no_mangle]
pub unsafe extern "C" fn fmi2SetBoolean(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2Boolean,
) -> fmi2Status {
    set(c, "fmi2SetBoolean", vr, nvr, value, |x| {
        Ok(Value::Boolean(x != 0))
    })
}

/// # Safety
/// Arrays of `nvr` elements as the FMI 2.0 standard defines them.
#[no_mangle]
pub unsafe extern "C" fn fmi2SetString(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2String,
) -> fmi2Status {
    set(c, "fmi2SetString", vr, nvr, value, |p| {
        c_str(p)
            .map(|s| Value::String(s.to_owned()))
            .ok_or_else(|| "a string value is NULL or not UTF-8".to_string())
    })
}

// ---------------------------------------------------------------------------------------
// FMU state

/// # Safety
/// `state` points to a variable holding NULL or a state this instance returned earlier.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetFMUstate(c: fmi2Component, state: *mut fmi2FMUstate) -> fmi2Status {
    dispatch(c, Call::FmuState("fmi2GetFMUstate"), |instance| {
        state_calls::get(instance, state)
    })
}

/// # Safety
/// `c` as returned by `fmi2Instantiate`; `state` is only looked up, never dereferenced.
#[no_mangle]
pub unsafe extern "C" fn fmi2SetFMUstate(c: fmi2Component, state: fmi2FMUstate) -> fmi2Status {
    dispatch(c, Call::FmuState("fmi2SetFMUstate"), |instance| {
        instance.restore_state(state as usize)
    })
}

/// # Safety
/// `state` is NULL, points to a variable holding NULL or a state of this instance, or (an
/// importer bug, see [`state_calls::free`]) is a state of this instance itself.
#[no_mangle]
pub unsafe extern "C" fn fmi2FreeFMUstate(
    c: fmi2Component,
    state: *mut fmi2FMUstate,
) -> fmi2Status {
    dispatch(c, Call::FreeFmuState, |instance| {
        state_calls::free(instance, state)
    })
}

/// # Safety
/// `state` as returned by this instance (only looked up); `size` writable.
#[no_mangle]
pub unsafe extern "C" fn fmi2SerializedFMUstateSize(
    c: fmi2Component,
    state: fmi2FMUstate,
    size: *mut usize,
) -> fmi2Status {
    dispatch(
        c,
        Call::FmuState("fmi2SerializedFMUstateSize"),
        |instance| state_calls::serialized_size(instance, state, size),
    )
}

/// # Safety
/// `state` as returned by this instance (only looked up); `serializedState` has room for
/// `size` bytes.
#[no_mangle]
pub unsafe extern "C" fn fmi2SerializeFMUstate(
    c: fmi2Component,
    state: fmi2FMUstate,
    serializedState: *mut fmi2Byte,
    size: usize,
) -> fmi2Status {
    dispatch(c, Call::FmuState("fmi2SerializeFMUstate"), |instance| {
        state_calls::serialize(instance, state, serializedState as *mut u8, size)
    })
}

/// # Safety
/// `serializedState` holds `size` readable bytes; `state` points to a writable variable.
#[no_mangle]
pub unsafe extern "C" fn fmi2DeSerializeFMUstate(
    c: fmi2Component,
    serializedState: *const fmi2Byte,
    size: usize,
    state: *mut fmi2FMUstate,
) -> fmi2Status {
    dispatch(c, Call::FmuState("fmi2DeSerializeFMUstate"), |instance| {
        state_calls::deserialize(instance, serializedState as *const u8, size, state)
    })
}

// ---------------------------------------------------------------------------------------
// Not supported (the model descriptions say so): a clear error instead of a silent no-op

/// # Safety
/// Arguments as the FMI 2.0 standard defines them.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetDirectionalDerivative(
    c: fmi2Component,
    _vUnknown_ref: *const fmi2ValueReference,
    _nUnknown: usize,
    _vKnown_ref: *const fmi2ValueReference,
    _nKnown: usize,
    _dvKnown: *const fmi2Real,
    _dvUnknown: *mut fmi2Real,
) -> fmi2Status {
    dispatch(c, Call::GetDirectionalDerivative, |_| {
        Err(Failure::error(
            "not supported (providesDirectionalDerivative=\"false\")",
        ))
    })
}

/// # Safety
/// Arguments as the FMI 2.0 standard defines them.
#[no_mangle]
pub unsafe extern "C" fn fmi2SetRealInputDerivatives(
    c: fmi2Component,
    _vr: *const fmi2ValueReference,
    _nvr: usize,
    _order: *const fmi2Integer,
    _value: *const fmi2Real,
) -> fmi2Status {
    dispatch(c, Call::SetRealInputDerivatives, |_| {
        Err(Failure::error(
            "not supported (canInterpolateInputs=\"false\")",
        ))
    })
}

/// # Safety
/// Arguments as the FMI 2.0 standard defines them.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetRealOutputDerivatives(
    c: fmi2Component,
    _vr: *const fmi2ValueReference,
    _nvr: usize,
    _order: *const fmi2Integer,
    _value: *mut fmi2Real,
) -> fmi2Status {
    dispatch(c, Call::GetRealOutputDerivatives, |_| {
        Err(Failure::error(
            "not supported (maxOutputDerivativeOrder=\"0\")",
        ))
    })
}

// ---------------------------------------------------------------------------------------
// Stepping and status

/// # Safety
/// `c` as returned by `fmi2Instantiate`.
#[no_mangle]
pub unsafe extern "C" fn fmi2DoStep(
    c: fmi2Component,
    currentCommunicationPoint: fmi2Real,
    communicationStepSize: fmi2Real,
    _noSetFMUStatePriorToCurrentPoint: fmi2Boolean,
) -> fmi2Status {
    dispatch(c, Call::DoStep, |instance| {
        instance.do_step(currentCommunicationPoint, communicationStepSize)
    })
}

/// # Safety
/// `c` as returned by `fmi2Instantiate`.
#[no_mangle]
pub unsafe extern "C" fn fmi2CancelStep(c: fmi2Component) -> fmi2Status {
    // Steps are synchronous: there is never a step in progress to cancel, so the state
    // machine refuses every call.
    dispatch(c, Call::CancelStep, |_| Ok(()))
}

/// # Safety
/// `value` writable.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetStatus(
    c: fmi2Component,
    _s: fmi2StatusKind,
    _value: *mut fmi2Status,
) -> fmi2Status {
    dispatch(c, Call::Status("fmi2GetStatus"), |_| {
        Err(Failure::discard(
            "no asynchronous step status: steps are synchronous",
        ))
    })
}

/// # Safety
/// `value` writable.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetRealStatus(
    c: fmi2Component,
    s: fmi2StatusKind,
    value: *mut fmi2Real,
) -> fmi2Status {
    dispatch(c, Call::Status("fmi2GetRealStatus"), |instance| {
        if s != fmi2StatusKind_fmi2LastSuccessfulTime {
            return Err(Failure::discard(format!(
                "status kind {s} has no Real value"
            )));
        }
        *value
            .as_mut()
            .ok_or_else(|| Failure::error("value is NULL"))? = instance.last_successful_time();
        Ok(())
    })
}

/// # Safety
/// `value` writable.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetIntegerStatus(
    c: fmi2Component,
    s: fmi2StatusKind,
    _value: *mut fmi2Integer,
) -> fmi2Status {
    dispatch(c, Call::Status("fmi2GetIntegerStatus"), |_| {
        Err(Failure::discard(format!(
            "status kind {s} has no Integer value"
        )))
    })
}

/// # Safety
/// `value` writable.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetBooleanStatus(
    c: fmi2Component,
    s: fmi2StatusKind,
    value: *mut fmi2Boolean,
) -> fmi2Status {
    dispatch(c, Call::Status("fmi2GetBooleanStatus"), |_| {
        if s != fmi2StatusKind_fmi2Terminated {
            return Err(Failure::discard(format!(
                "status kind {s} has no Boolean value"
            )));
        }
        // The slave never asks the master to end the simulation.
        *value
            .as_mut()
            .ok_or_else(|| Failure::error("value is NULL"))? = fmi2False as fmi2Boolean;
        Ok(())
    })
}

/// # Safety
/// `value` writable.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetStringStatus(
    c: fmi2Component,
    s: fmi2StatusKind,
    _value: *mut fmi2String,
) -> fmi2Status {
    dispatch(c, Call::Status("fmi2GetStringStatus"), |_| {
        Err(Failure::discard(format!(
            "status kind {s} has no String value"
        )))
    })
}

// ---------------------------------------------------------------------------------------
// Compile-time check of every signature against the standard's header (the fmi2...TYPE
// typedefs that fmi2-bindings holds, generated from third_party/fmi2/):
// a mismatch is a type error here, not a crash in an importer.

const _: () = {
    let _: fmi2GetTypesPlatformTYPE = Some(fmi2GetTypesPlatform);
    let _: fmi2GetVersionTYPE = Some(fmi2GetVersion);
    let _: fmi2SetDebugLoggingTYPE = Some(fmi2SetDebugLogging);
    let _: fmi2InstantiateTYPE = Some(fmi2Instantiate);
    let _: fmi2FreeInstanceTYPE = Some(fmi2FreeInstance);
    let _: fmi2SetupExperimentTYPE = Some(fmi2SetupExperiment);
    let _: fmi2EnterInitializationModeTYPE = Some(fmi2EnterInitializationMode);
    let _: fmi2ExitInitializationModeTYPE = Some(fmi2ExitInitializationMode);
    let _: fmi2TerminateTYPE = Some(fmi2Terminate);
    let _: fmi2ResetTYPE = Some(fmi2Reset);
    let _: fmi2GetRealTYPE = Some(fmi2GetReal);
    let _: fmi2GetIntegerTYPE = Some(fmi2GetInteger);
    let _: fmi2GetBooleanTYPE = Some(fmi2GetBoolean);
    let _: fmi2GetStringTYPE = Some(fmi2GetString);
    let _: fmi2SetRealTYPE = Some(fmi2SetReal);
    let _: fmi2SetIntegerTYPE = Some(fmi2SetInteger);
    let _: fmi2SetBooleanTYPE = Some(fmi2SetBoolean);
    let _: fmi2SetStringTYPE = Some(fmi2SetString);
    let _: fmi2GetFMUstateTYPE = Some(fmi2GetFMUstate);
    let _: fmi2SetFMUstateTYPE = Some(fmi2SetFMUstate);
    let _: fmi2FreeFMUstateTYPE = Some(fmi2FreeFMUstate);
    let _: fmi2SerializedFMUstateSizeTYPE = Some(fmi2SerializedFMUstateSize);
    let _: fmi2SerializeFMUstateTYPE = Some(fmi2SerializeFMUstate);
    let _: fmi2DeSerializeFMUstateTYPE = Some(fmi2DeSerializeFMUstate);
    let _: fmi2GetDirectionalDerivativeTYPE = Some(fmi2GetDirectionalDerivative);
    let _: fmi2SetRealInputDerivativesTYPE = Some(fmi2SetRealInputDerivatives);
    let _: fmi2GetRealOutputDerivativesTYPE = Some(fmi2GetRealOutputDerivatives);
    let _: fmi2DoStepTYPE = Some(fmi2DoStep);
    let _: fmi2CancelStepTYPE = Some(fmi2CancelStep);
    let _: fmi2GetStatusTYPE = Some(fmi2GetStatus);
    let _: fmi2GetRealStatusTYPE = Some(fmi2GetRealStatus);
    let _: fmi2GetIntegerStatusTYPE = Some(fmi2GetIntegerStatus);
    let _: fmi2GetBooleanStatusTYPE = Some(fmi2GetBooleanStatus);
    let _: fmi2GetStringStatusTYPE = Some(fmi2GetStringStatus);
};
