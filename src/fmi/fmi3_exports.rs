//! The 75 exported `fmi3*` functions of FMI 3.0. Co-Simulation is implemented, on the same
//! instances, state machine and FMU states as FMI 2.0 ([`super::dispatch`]: an FMI 2.0
//! instance is refused here); Model Exchange, Scheduled Execution, clocks, configuration
//! and event mode are not (the model descriptions say so), and their functions answer
//! `fmi3Error` with a message. FMI 3.0's differences from 2.0 live here: the experiment
//! comes with `fmi3EnterInitializationMode`, the log callback takes no format arguments,
//! there are no memory callbacks, `fmi3Boolean` is a 1-byte `bool`, enumerations are read
//! and written as Int64, `resourcePath` is a native path, and the independent variable
//! `time` has a value reference of its own (the first after the table's).

#![allow(non_snake_case)]

use std::ffi::c_char;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::PathBuf;
use std::ptr;

use fmi3_bindings::*;

use super::c_args::{array, array_mut, c_str, slice, slice_mut};
use super::instance::Instance;
use super::logger::{Callback, Category, Logger};
use super::standard::Standard;
use super::state_calls;
use super::state_machine::Call;
use super::status::{Failure, Outcome, Status};
use crate::framework::variables::{Value, VarType};
use crate::models;

/// [`super::dispatch::dispatch`] for an FMI 3.0 instance.
#[inline]
fn dispatch(
    instance: fmi3Instance,
    call: Call,
    body: impl FnOnce(&mut Instance) -> Outcome,
) -> fmi3Status {
    super::dispatch::dispatch(Standard::Fmi3, instance as usize, call, body)
}

/// [`super::dispatch::dispatch_fast`] for an FMI 3.0 instance.
#[inline(always)]
fn dispatch_fast(
    instance: fmi3Instance,
    call: Call,
    fast: impl FnOnce(&mut Instance) -> Option<()>,
    body: impl FnOnce(&mut Instance) -> Outcome,
) -> fmi3Status {
    super::dispatch::dispatch_fast(Standard::Fmi3, instance as usize, call, fast, body)
}

/// A function these FMUs do not support: refused in every live mode, with why.
fn unsupported(instance: fmi3Instance, name: &'static str, why: &'static str) -> fmi3Status {
    dispatch(instance, Call::Unsupported(name), |_| {
        Err(Failure::error(format!("not supported: {why}")))
    })
}

const NO_MODEL_EXCHANGE: &str = "these FMUs are Co-Simulation only (no <ModelExchange>)";
const NO_CLOCKS: &str = "these FMUs have no clocks";
const NO_EVENT_MODE: &str =
    "these FMUs have no event mode (hasEventMode=\"false\"): step with fmi3DoStep";

/// FMI 3.0 passes a length for the values beside the references' (arrays have several
/// values per reference); every variable here is a scalar, so they must agree.
fn scalar_count(n_value_references: usize, n_values: usize) -> Outcome {
    if n_values == n_value_references {
        Ok(())
    } else {
        Err(Failure::error(format!(
            "nValues = {n_values} but nValueReferences = {n_value_references}: every \
             variable of these FMUs is a scalar, one value per reference"
        )))
    }
}

/// The refusal of the independent variable in a setter.
fn time_is_not_settable(vr: u32) -> Failure {
    Failure::error(format!(
        "variable 'time' (value reference {vr}) is the independent variable: it cannot be set"
    ))
}

// ---------------------------------------------------------------------------------------
// Library information and life cycle

#[no_mangle]
pub extern "C" fn fmi3GetVersion() -> *const c_char {
    fmi3Version.as_ptr() as *const c_char
}

/// # Safety
/// Arguments as the FMI 3.0 standard defines them.
#[no_mangle]
pub unsafe extern "C" fn fmi3SetDebugLogging(
    instance: fmi3Instance,
    loggingOn: fmi3Boolean,
    nCategories: usize,
    categories: *const fmi3String,
) -> fmi3Status {
    dispatch(instance, Call::SetDebugLogging, |instance| {
        let pointers = slice(categories, nCategories, "categories")?;
        let mut names = Vec::with_capacity(pointers.len());
        for &p in pointers {
            names.push(c_str(p).ok_or_else(|| Failure::error("a category is NULL or not UTF-8"))?);
        }
        instance.set_debug_logging(loggingOn, &names)
    })
}

/// # Safety
/// Arguments as the FMI 3.0 standard defines them.
#[no_mangle]
pub unsafe extern "C" fn fmi3InstantiateModelExchange(
    instanceName: fmi3String,
    _instantiationToken: fmi3String,
    _resourcePath: fmi3String,
    _visible: fmi3Boolean,
    _loggingOn: fmi3Boolean,
    instanceEnvironment: fmi3InstanceEnvironment,
    logMessage: fmi3LogMessageCallback,
) -> fmi3Instance {
    refuse_instantiation(
        instanceName,
        instanceEnvironment,
        logMessage,
        "fmi3InstantiateModelExchange",
        NO_MODEL_EXCHANGE,
    )
}

/// # Safety
/// Arguments as the FMI 3.0 standard defines them.
#[no_mangle]
pub unsafe extern "C" fn fmi3InstantiateScheduledExecution(
    instanceName: fmi3String,
    _instantiationToken: fmi3String,
    _resourcePath: fmi3String,
    _visible: fmi3Boolean,
    _loggingOn: fmi3Boolean,
    instanceEnvironment: fmi3InstanceEnvironment,
    logMessage: fmi3LogMessageCallback,
    _clockUpdate: fmi3ClockUpdateCallback,
    _lockPreemption: fmi3LockPreemptionCallback,
    _unlockPreemption: fmi3UnlockPreemptionCallback,
) -> fmi3Instance {
    refuse_instantiation(
        instanceName,
        instanceEnvironment,
        logMessage,
        "fmi3InstantiateScheduledExecution",
        "these FMUs are Co-Simulation only (no <ScheduledExecution>)",
    )
}

/// An instantiation of an interface type these FMUs do not have: NULL, and why in the log.
unsafe fn refuse_instantiation(
    instance_name: fmi3String,
    environment: fmi3InstanceEnvironment,
    log_message: fmi3LogMessageCallback,
    function: &str,
    why: &str,
) -> fmi3Instance {
    let _ = catch_unwind(AssertUnwindSafe(|| {
        let name = c_str(instance_name).unwrap_or("");
        let logger = Logger::new(Callback::fmi3(log_message), environment, name, true);
        logger.log(
            Status::Error,
            Category::StatusError,
            &format!("{function}: {why}"),
        );
        logger.flush();
    }));
    ptr::null_mut()
}

/// # Safety
/// Arguments as the FMI 3.0 standard defines them.
#[no_mangle]
pub unsafe extern "C" fn fmi3InstantiateCoSimulation(
    instanceName: fmi3String,
    instantiationToken: fmi3String,
    resourcePath: fmi3String,
    _visible: fmi3Boolean,
    loggingOn: fmi3Boolean,
    eventModeUsed: fmi3Boolean,
    earlyReturnAllowed: fmi3Boolean,
    _requiredIntermediateVariables: *const fmi3ValueReference,
    nRequiredIntermediateVariables: usize,
    instanceEnvironment: fmi3InstanceEnvironment,
    logMessage: fmi3LogMessageCallback,
    _intermediateUpdate: fmi3IntermediateUpdateCallback,
) -> fmi3Instance {
    let result = catch_unwind(AssertUnwindSafe(|| {
        // FMI 3.0 allows no logger: the instance then logs nothing.
        let name = c_str(instanceName).unwrap_or("");
        let logger = Logger::new(
            Callback::fmi3(logMessage),
            instanceEnvironment,
            name,
            loggingOn,
        );
        let refuse = |message: String| {
            logger.log(
                Status::Error,
                Category::StatusError,
                &format!("fmi3InstantiateCoSimulation: {message}"),
            );
            logger.flush();
            None
        };
        if name.trim().is_empty() {
            return refuse("the instance name is NULL or empty".into());
        }
        if nRequiredIntermediateVariables > 0 {
            return refuse(format!(
                "{nRequiredIntermediateVariables} intermediate variables requested: these \
                 FMUs have no intermediate update (no variable has intermediateUpdate=\"true\")"
            ));
        }
        let Some(token) = c_str(instantiationToken) else {
            return refuse("the instantiation token is NULL or not UTF-8".into());
        };
        let Some(interface) = models::by_instantiation_token(token) else {
            let known: Vec<String> = models::interfaces()
                .iter()
                .map(|i| {
                    format!(
                        "{} ({}) {}",
                        i.model.identifier,
                        i.units.name(),
                        i.instantiation_token
                    )
                })
                .collect();
            let hint = if models::by_guid(token).is_some() {
                " (it is an FMI 2.0 GUID: the FMI 2.0 modelDescription.xml belongs to fmi2Instantiate)"
            } else {
                ""
            };
            return refuse(format!(
                "unknown instantiation token {token}{hint}: the modelDescription.xml does not \
                 match this binary (it serves {})",
                known.join(", ")
            ));
        };
        let mut environment = super::plans::environment();
        // FMI 3.0: a native path to the resources folder (with a trailing separator), not
        // a URI; NULL when the FMU has none.
        if !resourcePath.is_null() {
            match c_str(resourcePath) {
                Some(path) if !path.is_empty() => {
                    environment.resource_dir = Some(PathBuf::from(path));
                }
                Some(_) => {}
                None => logger.log(
                    Status::Warning,
                    Category::StatusWarning,
                    "fmi3InstantiateCoSimulation: resourcePath is not UTF-8; continuing \
                     without resources",
                ),
            }
        }
        let instance =
            Instance::with_interface(Standard::Fmi3, interface, environment, logger, name);
        instance.log_event(&format!(
            "instantiated {} with the {} interface (FMI 3.0 Co-Simulation, instantiation \
             token {token}, {}){}",
            interface.model.identifier,
            interface.units.name(),
            crate::build_identity::described(),
            if eventModeUsed || earlyReturnAllowed {
                "; eventModeUsed and earlyReturnAllowed are ignored: no event mode, no early \
                 return"
            } else {
                ""
            }
        ));
        super::dispatch::register(instance, "fmi3InstantiateCoSimulation")
            .map(|h| h as fmi3Instance)
    }));
    match result {
        Ok(Some(instance)) => instance,
        _ => ptr::null_mut(),
    }
}

/// # Safety
/// `instance` as returned by `fmi3InstantiateCoSimulation`; it is invalid afterwards. A
/// NULL, freed or foreign `instance` is ignored, and so is an FMI 2.0 instance.
#[no_mangle]
pub unsafe extern "C" fn fmi3FreeInstance(instance: fmi3Instance) {
    super::dispatch::free_instance(Standard::Fmi3, instance as usize);
}

/// # Safety
/// `instance` as returned by `fmi3InstantiateCoSimulation`.
#[no_mangle]
pub unsafe extern "C" fn fmi3EnterInitializationMode(
    instance: fmi3Instance,
    _toleranceDefined: fmi3Boolean,
    _tolerance: fmi3Float64,
    startTime: fmi3Float64,
    stopTimeDefined: fmi3Boolean,
    stopTime: fmi3Float64,
) -> fmi3Status {
    // FMI 3.0 has no fmi3SetupExperiment: the experiment comes here.
    dispatch(instance, Call::EnterInitializationMode, |instance| {
        instance.setup_experiment(startTime, stopTimeDefined.then_some(stopTime))?;
        instance.enter_initialization_mode()
    })
}

/// # Safety
/// `instance` as returned by `fmi3InstantiateCoSimulation`.
#[no_mangle]
pub unsafe extern "C" fn fmi3ExitInitializationMode(instance: fmi3Instance) -> fmi3Status {
    dispatch(
        instance,
        Call::ExitInitializationMode,
        Instance::exit_initialization_mode,
    )
}

/// # Safety
/// `instance` as returned by `fmi3InstantiateCoSimulation`.
#[no_mangle]
pub unsafe extern "C" fn fmi3EnterEventMode(instance: fmi3Instance) -> fmi3Status {
    unsupported(instance, "fmi3EnterEventMode", NO_EVENT_MODE)
}

/// # Safety
/// `instance` as returned by `fmi3InstantiateCoSimulation`.
#[no_mangle]
pub unsafe extern "C" fn fmi3Terminate(instance: fmi3Instance) -> fmi3Status {
    dispatch(instance, Call::Terminate, Instance::terminate)
}

/// # Safety
/// `instance` as returned by `fmi3InstantiateCoSimulation`.
#[no_mangle]
pub unsafe extern "C" fn fmi3Reset(instance: fmi3Instance) -> fmi3Status {
    dispatch(instance, Call::Reset, Instance::reset)
}

// ---------------------------------------------------------------------------------------
// Getting and setting values

/// # Safety
/// Arrays of `nValueReferences` and `nValues` elements.
#[no_mangle]
pub unsafe extern "C" fn fmi3GetFloat64(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *mut fmi3Float64,
    nValues: usize,
) -> fmi3Status {
    // One of the sample's calls (with fmi3SetFloat64 and fmi3DoStep).
    dispatch_fast(
        instance,
        Call::GetValues("fmi3GetFloat64"),
        |instance| {
            if nValues != nValueReferences {
                return None;
            }
            instance.get_real_values(
                array(valueReferences, nValueReferences)?,
                array_mut(values, nValues)?,
            )
        },
        |instance| {
            scalar_count(nValueReferences, nValues)?;
            let vrs = slice(valueReferences, nValueReferences, "valueReferences")?;
            let out = slice_mut(values, nValues, "values")?;
            let time_vr = instance.time_vr();
            if !vrs.contains(&time_vr) {
                return instance.get_reals(vrs, out);
            }
            // The independent variable among the others: one by one, time from the clock.
            for &vr in vrs {
                if vr != time_vr {
                    instance.check_type(&[vr], VarType::Real)?;
                }
            }
            for (slot, &vr) in out.iter_mut().zip(vrs) {
                if vr == time_vr {
                    *slot = instance.time();
                } else {
                    instance.get_reals(&[vr], std::slice::from_mut(slot))?;
                }
            }
            Ok(())
        },
    )
}

/// # Safety
/// Arrays of `nValueReferences` and `nValues` elements.
#[no_mangle]
pub unsafe extern "C" fn fmi3SetFloat64(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *const fmi3Float64,
    nValues: usize,
) -> fmi3Status {
    dispatch_fast(
        instance,
        Call::SetValues("fmi3SetFloat64"),
        |instance| {
            if nValues != nValueReferences {
                return None;
            }
            instance.set_free_reals(
                array(valueReferences, nValueReferences)?,
                array(values, nValues)?,
            )
        },
        |instance| {
            scalar_count(nValueReferences, nValues)?;
            let vrs = slice(valueReferences, nValueReferences, "valueReferences")?;
            let values = slice(values, nValues, "values")?;
            if let Some(&vr) = vrs.iter().find(|&&vr| vr == instance.time_vr()) {
                return Err(time_is_not_settable(vr));
            }
            instance.set_reals(vrs, values)
        },
    )
}

/// Shared body of the Int32 and Int64 getters: Integers as Int32, Enumerations as Int64.
unsafe fn get_integers<T>(
    instance: fmi3Instance,
    name: &'static str,
    enumeration: bool,
    (vr, nvr): (*const fmi3ValueReference, usize),
    (value, nvalues): (*mut T, usize),
    convert: impl Fn(i32) -> T,
) -> fmi3Status {
    dispatch(instance, Call::GetValues(name), |instance| {
        scalar_count(nvr, nvalues)?;
        let vrs = slice(vr, nvr, "valueReferences")?;
        let out = slice_mut(value, nvalues, "values")?;
        instance.check_fmi3_integers(vrs, enumeration)?;
        instance.get_values(vrs, |i, v| match *v {
            Value::Integer(x) => out[i] = convert(x),
            _ => unreachable!("type checked"),
        })
    })
}

/// Shared body of the Int32 and Int64 setters.
unsafe fn set_integers<T: Copy>(
    instance: fmi3Instance,
    name: &'static str,
    enumeration: bool,
    (vr, nvr): (*const fmi3ValueReference, usize),
    (value, nvalues): (*const T, usize),
    convert: impl Fn(T) -> Result<i32, String>,
) -> fmi3Status {
    dispatch(instance, Call::SetValues(name), |instance| {
        scalar_count(nvr, nvalues)?;
        let vrs = slice(vr, nvr, "valueReferences")?;
        let values = slice(value, nvalues, "values")?;
        instance.check_fmi3_integers(vrs, enumeration)?;
        instance.set_values(vrs, |i| convert(values[i]).map(Value::Integer))
    })
}

/// # Safety
/// Arrays of `nValueReferences` and `nValues` elements.
#[no_mangle]
pub unsafe extern "C" fn fmi3GetInt32(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *mut fmi3Int32,
    nValues: usize,
) -> fmi3Status {
    get_integers(
        instance,
        "fmi3GetInt32",
        false,
        (valueReferences, nValueReferences),
        (values, nValues),
        |x| x,
    )
}

/// # Safety
/// Arrays of `nValueReferences` and `nValues` elements.
#[no_mangle]
pub unsafe extern "C" fn fmi3GetInt64(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *mut fmi3Int64,
    nValues: usize,
) -> fmi3Status {
    get_integers(
        instance,
        "fmi3GetInt64",
        true,
        (valueReferences, nValueReferences),
        (values, nValues),
        i64::from,
    )
}

/// # Safety
/// Arrays of `nValueReferences` and `nValues` elements.
#[no_mangle]
pub unsafe extern "C" fn fmi3SetInt32(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *const fmi3Int32,
    nValues: usize,
) -> fmi3Status {
    set_integers(
        instance,
        "fmi3SetInt32",
        false,
        (valueReferences, nValueReferences),
        (values, nValues),
        Ok,
    )
}

/// # Safety
/// Arrays of `nValueReferences` and `nValues` elements.
#[no_mangle]
pub unsafe extern "C" fn fmi3SetInt64(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *const fmi3Int64,
    nValues: usize,
) -> fmi3Status {
    set_integers(
        instance,
        "fmi3SetInt64",
        true,
        (valueReferences, nValueReferences),
        (values, nValues),
        |x| i32::try_from(x).map_err(|_| format!("enumeration value {x} is out of range")),
    )
}

/// # Safety
/// Arrays of `nValueReferences` and `nValues` elements.
#[no_mangle]
pub unsafe extern "C" fn fmi3GetBoolean(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *mut fmi3Boolean,
    nValues: usize,
) -> fmi3Status {
    dispatch(instance, Call::GetValues("fmi3GetBoolean"), |instance| {
        scalar_count(nValueReferences, nValues)?;
        let vrs = slice(valueReferences, nValueReferences, "valueReferences")?;
        let out = slice_mut(values, nValues, "values")?;
        instance.get_values_checked(vrs, VarType::Boolean, |i, v| match *v {
            Value::Boolean(x) => out[i] = x,
            _ => unreachable!("type checked"),
        })
    })
}

/// # Safety
/// Arrays of `nValueReferences` and `nValues` elements.
#[no_mangle]
pub unsafe extern "C" fn fmi3SetBoolean(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *const fmi3Boolean,
    nValues: usize,
) -> fmi3Status {
    dispatch(instance, Call::SetValues("fmi3SetBoolean"), |instance| {
        scalar_count(nValueReferences, nValues)?;
        let vrs = slice(valueReferences, nValueReferences, "valueReferences")?;
        // Read as bytes: a C bool holds 0 or 1, but a byte from a careless importer that
        // holds anything else must be refused, not read as a Rust bool (undefined).
        let bytes = slice(values as *const u8, nValues, "values")?;
        instance.check_type(vrs, VarType::Boolean)?;
        instance.set_values(vrs, |i| match bytes[i] {
            0 => Ok(Value::Boolean(false)),
            1 => Ok(Value::Boolean(true)),
            other => Err(format!(
                "a Boolean value is the byte {other}: fmi3Boolean is a C bool, 0 or 1"
            )),
        })
    })
}

/// # Safety
/// Arrays of `nValueReferences` and `nValues` elements. The returned strings stay valid
/// until the next call on this instance.
#[no_mangle]
pub unsafe extern "C" fn fmi3GetString(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *mut fmi3String,
    nValues: usize,
) -> fmi3Status {
    dispatch(instance, Call::GetValues("fmi3GetString"), |instance| {
        scalar_count(nValueReferences, nValues)?;
        let vrs = slice(valueReferences, nValueReferences, "valueReferences")?;
        let out = slice_mut(values, nValues, "values")?;
        let held = instance.hold_strings(vrs)?;
        for (slot, text) in out.iter_mut().zip(held) {
            *slot = text.as_ptr();
        }
        Ok(())
    })
}

/// # Safety
/// Arrays of `nValueReferences` and `nValues` elements.
#[no_mangle]
pub unsafe extern "C" fn fmi3SetString(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *const fmi3String,
    nValues: usize,
) -> fmi3Status {
    dispatch(instance, Call::SetValues("fmi3SetString"), |instance| {
        scalar_count(nValueReferences, nValues)?;
        let vrs = slice(valueReferences, nValueReferences, "valueReferences")?;
        let values = slice(values, nValues, "values")?;
        instance.check_type(vrs, VarType::String)?;
        instance.set_values(vrs, |i| {
            c_str(values[i])
                .map(|s| Value::String(s.to_owned()))
                .ok_or_else(|| "a string value is NULL or not UTF-8".to_string())
        })
    })
}

/// A getter or setter of a type no variable here has: the counts checked as for every type,
/// then every reference refused as unknown or of another type (nothing to do for none).
unsafe fn no_such_type(
    instance: fmi3Instance,
    call: Call,
    wanted: &'static str,
    (vr, nvr): (*const fmi3ValueReference, usize),
    nvalues: usize,
) -> fmi3Status {
    dispatch(instance, call, |instance| {
        scalar_count(nvr, nvalues)?;
        match slice(vr, nvr, "valueReferences")?.first() {
            Some(&vr) => Err(instance.wrong_type(vr, wanted)),
            None => Ok(()),
        }
    })
}

/// The exported getter and setter of a type no variable of these FMUs has.
macro_rules! no_variables_of_type {
    ($get:ident, $set:ident, $t:ty, $wanted:literal) => {
        /// # Safety
        /// Arrays of `nValueReferences` and `nValues` elements.
        #[no_mangle]
        pub unsafe extern "C" fn $get(
            instance: fmi3Instance,
            valueReferences: *const fmi3ValueReference,
            nValueReferences: usize,
            _values: *mut $t,
            nValues: usize,
        ) -> fmi3Status {
            no_such_type(
                instance,
                Call::GetValues(stringify!($get)),
                $wanted,
                (valueReferences, nValueReferences),
                nValues,
            )
        }

        /// # Safety
        /// Arrays of `nValueReferences` and `nValues` elements.
        #[no_mangle]
        pub unsafe extern "C" fn $set(
            instance: fmi3Instance,
            valueReferences: *const fmi3ValueReference,
            nValueReferences: usize,
            _values: *const $t,
            nValues: usize,
        ) -> fmi3Status {
            no_such_type(
                instance,
                Call::SetValues(stringify!($set)),
                $wanted,
                (valueReferences, nValueReferences),
                nValues,
            )
        }
    };
}

no_variables_of_type!(fmi3GetFloat32, fmi3SetFloat32, fmi3Float32, "Float32");
no_variables_of_type!(fmi3GetInt8, fmi3SetInt8, fmi3Int8, "Int8");
no_variables_of_type!(fmi3GetUInt8, fmi3SetUInt8, fmi3UInt8, "UInt8");
no_variables_of_type!(fmi3GetInt16, fmi3SetInt16, fmi3Int16, "Int16");
no_variables_of_type!(fmi3GetUInt16, fmi3SetUInt16, fmi3UInt16, "UInt16");
no_variables_of_type!(fmi3GetUInt32, fmi3SetUInt32, fmi3UInt32, "UInt32");
no_variables_of_type!(fmi3GetUInt64, fmi3SetUInt64, fmi3UInt64, "UInt64");

/// # Safety
/// Arrays as the FMI 3.0 standard defines them.
#[no_mangle]
pub unsafe extern "C" fn fmi3GetBinary(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    _valueSizes: *mut usize,
    _values: *mut fmi3Binary,
    nValues: usize,
) -> fmi3Status {
    no_such_type(
        instance,
        Call::GetValues("fmi3GetBinary"),
        "Binary",
        (valueReferences, nValueReferences),
        nValues,
    )
}

/// # Safety
/// Arrays as the FMI 3.0 standard defines them.
#[no_mangle]
pub unsafe extern "C" fn fmi3SetBinary(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    _valueSizes: *const usize,
    _values: *const fmi3Binary,
    nValues: usize,
) -> fmi3Status {
    no_such_type(
        instance,
        Call::SetValues("fmi3SetBinary"),
        "Binary",
        (valueReferences, nValueReferences),
        nValues,
    )
}

/// # Safety
/// Arrays as the FMI 3.0 standard defines them.
#[no_mangle]
pub unsafe extern "C" fn fmi3GetClock(
    instance: fmi3Instance,
    _valueReferences: *const fmi3ValueReference,
    _nValueReferences: usize,
    _values: *mut fmi3Clock,
) -> fmi3Status {
    unsupported(instance, "fmi3GetClock", NO_CLOCKS)
}

/// # Safety
/// Arrays as the FMI 3.0 standard defines them.
#[no_mangle]
pub unsafe extern "C" fn fmi3SetClock(
    instance: fmi3Instance,
    _valueReferences: *const fmi3ValueReference,
    _nValueReferences: usize,
    _values: *const fmi3Clock,
) -> fmi3Status {
    unsupported(instance, "fmi3SetClock", NO_CLOCKS)
}

// ---------------------------------------------------------------------------------------
// Variable dependencies and derivatives: not provided (the model descriptions say so)

/// # Safety
/// Arguments as the FMI 3.0 standard defines them.
#[no_mangle]
pub unsafe extern "C" fn fmi3GetNumberOfVariableDependencies(
    instance: fmi3Instance,
    _valueReference: fmi3ValueReference,
    _nDependencies: *mut usize,
) -> fmi3Status {
    unsupported(
        instance,
        "fmi3GetNumberOfVariableDependencies",
        "the dependencies are in the modelDescription.xml's ModelStructure",
    )
}

/// # Safety
/// Arguments as the FMI 3.0 standard defines them.
#[no_mangle]
pub unsafe extern "C" fn fmi3GetVariableDependencies(
    instance: fmi3Instance,
    _dependent: fmi3ValueReference,
    _elementIndicesOfDependent: *mut usize,
    _independents: *mut fmi3ValueReference,
    _elementIndicesOfIndependents: *mut usize,
    _dependencyKinds: *mut fmi3DependencyKind,
    _nDependencies: usize,
) -> fmi3Status {
    unsupported(
        instance,
        "fmi3GetVariableDependencies",
        "the dependencies are in the modelDescription.xml's ModelStructure",
    )
}

/// # Safety
/// Arguments as the FMI 3.0 standard defines them.
#[no_mangle]
pub unsafe extern "C" fn fmi3GetDirectionalDerivative(
    instance: fmi3Instance,
    _unknowns: *const fmi3ValueReference,
    _nUnknowns: usize,
    _knowns: *const fmi3ValueReference,
    _nKnowns: usize,
    _seed: *const fmi3Float64,
    _nSeed: usize,
    _sensitivity: *mut fmi3Float64,
    _nSensitivity: usize,
) -> fmi3Status {
    dispatch(instance, Call::GetDirectionalDerivative, |_| {
        Err(Failure::error(
            "not supported (providesDirectionalDerivatives=\"false\")",
        ))
    })
}

/// # Safety
/// Arguments as the FMI 3.0 standard defines them.
#[no_mangle]
pub unsafe extern "C" fn fmi3GetAdjointDerivative(
    instance: fmi3Instance,
    _unknowns: *const fmi3ValueReference,
    _nUnknowns: usize,
    _knowns: *const fmi3ValueReference,
    _nKnowns: usize,
    _seed: *const fmi3Float64,
    _nSeed: usize,
    _sensitivity: *mut fmi3Float64,
    _nSensitivity: usize,
) -> fmi3Status {
    dispatch(instance, Call::GetAdjointDerivative, |_| {
        Err(Failure::error(
            "not supported (providesAdjointDerivatives=\"false\")",
        ))
    })
}

/// # Safety
/// Arguments as the FMI 3.0 standard defines them.
#[no_mangle]
pub unsafe extern "C" fn fmi3GetOutputDerivatives(
    instance: fmi3Instance,
    _valueReferences: *const fmi3ValueReference,
    _nValueReferences: usize,
    _orders: *const fmi3Int32,
    _values: *mut fmi3Float64,
    _nValues: usize,
) -> fmi3Status {
    dispatch(instance, Call::GetRealOutputDerivatives, |_| {
        Err(Failure::error(
            "not supported (maxOutputDerivativeOrder=\"0\")",
        ))
    })
}

// ---------------------------------------------------------------------------------------
// FMU state (the bodies are FMI 2.0's: super::state_calls)

/// # Safety
/// `FMUState` points to a variable holding NULL or a state this instance returned earlier.
#[no_mangle]
pub unsafe extern "C" fn fmi3GetFMUState(
    instance: fmi3Instance,
    FMUState: *mut fmi3FMUState,
) -> fmi3Status {
    dispatch(instance, Call::FmuState("fmi3GetFMUState"), |instance| {
        state_calls::get(instance, FMUState)
    })
}

/// # Safety
/// `FMUState` is only looked up, never dereferenced.
#[no_mangle]
pub unsafe extern "C" fn fmi3SetFMUState(
    instance: fmi3Instance,
    FMUState: fmi3FMUState,
) -> fmi3Status {
    dispatch(instance, Call::FmuState("fmi3SetFMUState"), |instance| {
        instance.restore_state(FMUState as usize)
    })
}

/// # Safety
/// `FMUState` is NULL or points to a variable holding NULL or a state of this instance.
#[no_mangle]
pub unsafe extern "C" fn fmi3FreeFMUState(
    instance: fmi3Instance,
    FMUState: *mut fmi3FMUState,
) -> fmi3Status {
    dispatch(instance, Call::FreeFmuState, |instance| {
        state_calls::free(instance, FMUState)
    })
}

/// # Safety
/// `FMUState` as returned by this instance (only looked up); `size` writable.
#[no_mangle]
pub unsafe extern "C" fn fmi3SerializedFMUStateSize(
    instance: fmi3Instance,
    FMUState: fmi3FMUState,
    size: *mut usize,
) -> fmi3Status {
    dispatch(
        instance,
        Call::FmuState("fmi3SerializedFMUStateSize"),
        |instance| state_calls::serialized_size(instance, FMUState, size),
    )
}

/// # Safety
/// `FMUState` as returned by this instance (only looked up); `serializedState` has room
/// for `size` bytes.
#[no_mangle]
pub unsafe extern "C" fn fmi3SerializeFMUState(
    instance: fmi3Instance,
    FMUState: fmi3FMUState,
    serializedState: *mut fmi3Byte,
    size: usize,
) -> fmi3Status {
    dispatch(
        instance,
        Call::FmuState("fmi3SerializeFMUState"),
        |instance| state_calls::serialize(instance, FMUState, serializedState, size),
    )
}

/// # Safety
/// `serializedState` holds `size` readable bytes; `FMUState` points to a writable variable.
#[no_mangle]
pub unsafe extern "C" fn fmi3DeserializeFMUState(
    instance: fmi3Instance,
    serializedState: *const fmi3Byte,
    size: usize,
    FMUState: *mut fmi3FMUState,
) -> fmi3Status {
    dispatch(
        instance,
        Call::FmuState("fmi3DeserializeFMUState"),
        |instance| state_calls::deserialize(instance, serializedState, size, FMUState),
    )
}

// ---------------------------------------------------------------------------------------
// Stepping

/// # Safety
/// `instance` as returned by `fmi3InstantiateCoSimulation`; the four results writable.
#[no_mangle]
pub unsafe extern "C" fn fmi3DoStep(
    instance: fmi3Instance,
    currentCommunicationPoint: fmi3Float64,
    communicationStepSize: fmi3Float64,
    _noSetFMUStatePriorToCurrentPoint: fmi3Boolean,
    eventHandlingNeeded: *mut fmi3Boolean,
    terminateSimulation: *mut fmi3Boolean,
    earlyReturn: *mut fmi3Boolean,
    lastSuccessfulTime: *mut fmi3Float64,
) -> fmi3Status {
    dispatch(instance, Call::DoStep, |instance| {
        let (Some(event), Some(terminate), Some(early), Some(last)) = (
            eventHandlingNeeded.as_mut(),
            terminateSimulation.as_mut(),
            earlyReturn.as_mut(),
            lastSuccessfulTime.as_mut(),
        ) else {
            return Err(Failure::error(
                "eventHandlingNeeded, terminateSimulation, earlyReturn or lastSuccessfulTime \
                 is NULL",
            ));
        };
        // No events and no early return: a step ends where it was asked to, or fails.
        let stepped = instance.do_step(currentCommunicationPoint, communicationStepSize);
        (*event, *terminate, *early) = (false, false, false);
        *last = instance.last_successful_time();
        stepped
    })
}

/// # Safety
/// `instance` as returned by `fmi3InstantiateCoSimulation`.
#[no_mangle]
pub unsafe extern "C" fn fmi3EnterStepMode(instance: fmi3Instance) -> fmi3Status {
    unsupported(instance, "fmi3EnterStepMode", NO_EVENT_MODE)
}

// ---------------------------------------------------------------------------------------
// Configuration mode, clocks, Model Exchange and Scheduled Execution: not supported

/// The exported functions of an interface part these FMUs do not have, by their
/// signatures' argument lists (`instance` first).
macro_rules! unsupported_functions {
    ($why:expr; $($name:ident($($arg:ident: $t:ty),*);)*) => {
        $(
            /// # Safety
            /// `instance` as returned by an instantiation (refused in any case).
            #[no_mangle]
            pub unsafe extern "C" fn $name(instance: fmi3Instance $(, $arg: $t)*) -> fmi3Status {
                $(let _ = $arg;)*
                unsupported(instance, stringify!($name), $why)
            }
        )*
    };
}

unsupported_functions! {
    "these FMUs have no structural parameters (no configuration mode)";
    fmi3EnterConfigurationMode();
    fmi3ExitConfigurationMode();
}

unsupported_functions! {
    NO_CLOCKS;
    fmi3GetIntervalDecimal(valueReferences: *const fmi3ValueReference, nValueReferences: usize,
        intervals: *mut fmi3Float64, qualifiers: *mut fmi3IntervalQualifier);
    fmi3GetIntervalFraction(valueReferences: *const fmi3ValueReference, nValueReferences: usize,
        counters: *mut fmi3UInt64, resolutions: *mut fmi3UInt64,
        qualifiers: *mut fmi3IntervalQualifier);
    fmi3GetShiftDecimal(valueReferences: *const fmi3ValueReference, nValueReferences: usize,
        shifts: *mut fmi3Float64);
    fmi3GetShiftFraction(valueReferences: *const fmi3ValueReference, nValueReferences: usize,
        counters: *mut fmi3UInt64, resolutions: *mut fmi3UInt64);
    fmi3SetIntervalDecimal(valueReferences: *const fmi3ValueReference, nValueReferences: usize,
        intervals: *const fmi3Float64);
    fmi3SetIntervalFraction(valueReferences: *const fmi3ValueReference, nValueReferences: usize,
        counters: *const fmi3UInt64, resolutions: *const fmi3UInt64);
    fmi3SetShiftDecimal(valueReferences: *const fmi3ValueReference, nValueReferences: usize,
        shifts: *const fmi3Float64);
    fmi3SetShiftFraction(valueReferences: *const fmi3ValueReference, nValueReferences: usize,
        counters: *const fmi3UInt64, resolutions: *const fmi3UInt64);
    fmi3ActivateModelPartition(clockReference: fmi3ValueReference, activationTime: fmi3Float64);
}

unsupported_functions! {
    NO_EVENT_MODE;
    fmi3EvaluateDiscreteStates();
    fmi3UpdateDiscreteStates(discreteStatesNeedUpdate: *mut fmi3Boolean,
        terminateSimulation: *mut fmi3Boolean, nominalsOfContinuousStatesChanged: *mut fmi3Boolean,
        valuesOfContinuousStatesChanged: *mut fmi3Boolean, nextEventTimeDefined: *mut fmi3Boolean,
        nextEventTime: *mut fmi3Float64);
}

unsupported_functions! {
    NO_MODEL_EXCHANGE;
    fmi3EnterContinuousTimeMode();
    fmi3CompletedIntegratorStep(noSetFMUStatePriorToCurrentPoint: fmi3Boolean,
        enterEventMode: *mut fmi3Boolean, terminateSimulation: *mut fmi3Boolean);
    fmi3SetTime(time: fmi3Float64);
    fmi3SetContinuousStates(continuousStates: *const fmi3Float64, nContinuousStates: usize);
    fmi3GetContinuousStateDerivatives(derivatives: *mut fmi3Float64, nContinuousStates: usize);
    fmi3GetEventIndicators(eventIndicators: *mut fmi3Float64, nEventIndicators: usize);
    fmi3GetContinuousStates(continuousStates: *mut fmi3Float64, nContinuousStates: usize);
    fmi3GetNominalsOfContinuousStates(nominals: *mut fmi3Float64, nContinuousStates: usize);
    fmi3GetNumberOfEventIndicators(nEventIndicators: *mut usize);
    fmi3GetNumberOfContinuousStates(nContinuousStates: *mut usize);
}
