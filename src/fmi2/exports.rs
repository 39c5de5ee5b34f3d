//! The 34 exported `fmi2*` functions of FMI 2.0 Co-Simulation. Each one only converts C
//! arguments and hands over to [`Instance`]; [`dispatch`] supplies what all share: the
//! instance lookup in the registry, the lock, the state machine, logging and panic capture.

#![allow(non_snake_case)]

use std::ffi::{c_char, CStr};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::ptr;

use fmi2_bindings::*;

use super::instance::Instance;
use super::logger::{Category, Logger};
use super::registry;
use super::resource_uri::resource_dir;
use super::slab::is_handle;
use super::state_machine::{Call, Mode};
use super::status::{Failure, Outcome, Status};
use crate::framework::model::Environment;
use crate::framework::variables::{Value, VarType};
use crate::models;

fn panic_text(payload: &(dyn std::any::Any + Send)) -> String {
    payload
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "unknown panic".into())
}

/// Runs one instance function: looks `c` up in the registry, which locks the instance for
/// the call (a NULL, freed or foreign pointer is `fmi2Error` without touching it; there is
/// no instance to log to), checks the mode, runs `body`, logs a failure, and turns a panic
/// into `fmi2Fatal` (the instance then only accepts `fmi2FreeInstance` and
/// `fmi2FreeFMUstate`).
#[inline]
fn dispatch(
    c: fmi2Component,
    call: Call,
    body: impl FnOnce(&mut Instance) -> Outcome,
) -> fmi2Status {
    let handle = c as usize;
    let result = catch_unwind(AssertUnwindSafe(|| {
        let mut instance = registry::instance(handle)?;
        let status = if !call.is_allowed_in(instance.mode) {
            refuse_in_this_mode(&instance, call)
        } else {
            if instance.logger.is_enabled(Category::All) {
                trace(&instance, call);
            }
            match body(&mut instance) {
                Ok(()) => Status::Ok,
                Err(failure) => instance.report(call, &failure),
            }
        };
        // Sent after the lock is released: the importer's logger may call us back.
        let outbox = instance.logger.take();
        drop(instance);
        if let Some(outbox) = outbox {
            outbox.send();
        }
        Some(status)
    }));
    match result {
        Ok(Some(status)) => status.code(),
        Ok(None) => Status::Error.code(),
        Err(payload) => fatal(handle, call, payload),
    }
}

/// [`dispatch`] for `fmi2SetReal` and `fmi2GetReal`: `fast` does the call's common case
/// with the instance locked once and none of the general path's bookkeeping, or declines
/// (`None`, having changed nothing); then [`dispatch`] runs `body`, the call in full (it
/// looks the instance up again: if another thread freed it meanwhile, the call is refused
/// as if it had come a moment later). `fast` does exactly what `body` does in the case it
/// accepts, in a mode the state machine allows and with `logAll` off (no trace to log).
#[inline(always)]
fn dispatch_fast(
    c: fmi2Component,
    call: Call,
    fast: impl FnOnce(&mut Instance) -> Option<()>,
    body: impl FnOnce(&mut Instance) -> Outcome,
) -> fmi2Status {
    let handle = c as usize;
    let done = catch_unwind(AssertUnwindSafe(|| {
        let mut instance = registry::instance(handle)?;
        if !call.is_allowed_in(instance.mode) || instance.logger.is_enabled(Category::All) {
            return None;
        }
        fast(&mut instance)?;
        let outbox = instance.logger.take();
        drop(instance);
        if let Some(outbox) = outbox {
            outbox.send();
        }
        Some(())
    }));
    match done {
        Ok(Some(())) => Status::Ok.code(),
        Ok(None) => dispatch_out_of_line(c, call, body),
        Err(payload) => fatal(handle, call, payload),
    }
}

#[inline(never)]
fn dispatch_out_of_line(
    c: fmi2Component,
    call: Call,
    body: impl FnOnce(&mut Instance) -> Outcome,
) -> fmi2Status {
    dispatch(c, call, body)
}

// The rare paths of `dispatch`, out of line: the per-sample calls stay short.

#[cold]
#[inline(never)]
fn refuse_in_this_mode(instance: &Instance, call: Call) -> Status {
    let failure = Failure::error(format!("illegal call sequence (state {:?})", instance.mode));
    instance.report(call, &failure)
}

#[cold]
#[inline(never)]
fn trace(instance: &Instance, call: Call) {
    let trace = format!("{} called", call.name());
    instance.logger.log(Status::Ok, Category::All, &trace);
}

/// After a panic in a call: marks the instance Fatal (if it is still there: the guard was
/// dropped as the panic unwound, so another thread may have freed it) and logs why.
#[cold]
#[inline(never)]
fn fatal(handle: usize, call: Call, payload: Box<dyn std::any::Any + Send>) -> fmi2Status {
    let message = panic_text(payload.as_ref());
    let _ = catch_unwind(AssertUnwindSafe(|| {
        let Some(mut instance) = registry::instance(handle) else {
            return;
        };
        instance.mode = Mode::Fatal;
        instance.report(
            call,
            &Failure {
                status: Status::Fatal,
                message: format!("internal error (panic): {message}"),
            },
        );
        let outbox = instance.logger.take();
        drop(instance);
        if let Some(outbox) = outbox {
            outbox.send();
        }
    }));
    Status::Fatal.code()
}

/// A slice from a C array, refusing NULL with a non-zero length.
#[inline]
unsafe fn slice<'a, T>(data: *const T, len: usize, what: &str) -> Outcome<&'a [T]> {
    if len == 0 {
        Ok(&[])
    } else if data.is_null() {
        Err(null_array(what, len))
    } else {
        Ok(std::slice::from_raw_parts(data, len))
    }
}

#[inline]
unsafe fn slice_mut<'a, T>(data: *mut T, len: usize, what: &str) -> Outcome<&'a mut [T]> {
    if len == 0 {
        Ok(&mut [])
    } else if data.is_null() {
        Err(null_array(what, len))
    } else {
        Ok(std::slice::from_raw_parts_mut(data, len))
    }
}

/// A slice from a C array for a fast path: `None` for NULL with a non-zero length.
#[inline(always)]
unsafe fn array<'a, T>(data: *const T, len: usize) -> Option<&'a [T]> {
    match len {
        0 => Some(&[]),
        _ if data.is_null() => None,
        _ => Some(std::slice::from_raw_parts(data, len)),
    }
}

#[inline(always)]
unsafe fn array_mut<'a, T>(data: *mut T, len: usize) -> Option<&'a mut [T]> {
    match len {
        0 => Some(&mut []),
        _ if data.is_null() => None,
        _ => Some(std::slice::from_raw_parts_mut(data, len)),
    }
}

#[cold]
#[inline(never)]
fn null_array(what: &str, len: usize) -> Failure {
    Failure::error(format!("{what} is NULL but its length is {len}"))
}

unsafe fn c_str<'a>(text: fmi2String) -> Option<&'a str> {
    if text.is_null() {
        None
    } else {
        CStr::from_ptr(text).to_str().ok()
    }
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
            functions.logger,
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
        let mut environment = Environment {
            resource_dir: None,
            planner: super::plans::planner(),
            xy_plans: super::plans::xy_plans(),
            indexes: super::plans::true_error_indexes(),
        };
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
        let instance = Instance::with_interface(interface, environment, logger, name);
        instance.log_event(&format!(
            "instantiated {} with the {} interface (GUID {guid}, {})",
            interface.model.identifier,
            interface.units.name(),
            crate::build_identity::described()
        ));
        instance.logger.flush();
        match registry::add_instance(instance) {
            Ok(handle) => Some(handle as fmi2Component),
            Err(instance) => {
                instance.logger.log(
                    Status::Error,
                    Category::StatusError,
                    "fmi2Instantiate: too many live instances in this process",
                );
                instance.logger.flush();
                None
            }
        }
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
    // Nothing happens for a handle that is not a live instance.
    dispatch(c, Call::FreeInstance, |instance| {
        instance.log_event("freed");
        Ok(())
    });
    // Unregistered whatever the log call did (even a panic in it must not leak the
    // instance), once a call still running on another thread has ended. The instance,
    // with its FMU states, is dropped here, outside the registry.
    let removed = registry::remove_instance(c as usize);
    let _ = catch_unwind(AssertUnwindSafe(move || drop(removed)));
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

/// The variable behind an `fmi2FMUstate*` argument. The argument must be the address of
/// the importer's variable; if it is one of our FMU state handles instead (see
/// `fmi2FreeFMUstate`), it is no address at all, so it is refused before it is
/// dereferenced.
///
/// # Safety
/// `slot` is NULL, one of our handles, or points to a writable `fmi2FMUstate`.
unsafe fn state_slot<'a>(slot: *mut fmi2FMUstate) -> Outcome<&'a mut fmi2FMUstate> {
    if is_handle(slot as usize) {
        // Live or freed, a handle of ours is not an address (see slab.rs).
        return Err(Failure::error(
            "the FMUstate* argument is an FMU state, not the address of a variable holding one",
        ));
    }
    slot.as_mut()
        .ok_or_else(|| Failure::error("FMUstate (the address of the variable) is NULL"))
}

/// # Safety
/// `state` points to a variable holding NULL or a state this instance returned earlier.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetFMUstate(c: fmi2Component, state: *mut fmi2FMUstate) -> fmi2Status {
    dispatch(c, Call::FmuState("fmi2GetFMUstate"), |instance| {
        let slot = state_slot(state)?;
        let existing = *slot as usize;
        // FMI 2.0: a non-NULL *FMUstate is an earlier state to be overwritten.
        if existing != 0 && !instance.states.contains(existing) {
            return Err(instance.states.unknown(existing));
        }
        let bytes = instance.snapshot()?;
        if existing == 0 {
            *slot = instance.states.add(bytes) as fmi2FMUstate;
        } else {
            instance.states.overwrite(existing, bytes)?;
        }
        Ok(())
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
/// `state` is NULL, points to a variable holding NULL or a state of this instance, or (the
/// importer bug handled below) is a state of this instance itself.
#[no_mangle]
pub unsafe extern "C" fn fmi2FreeFMUstate(
    c: fmi2Component,
    state: *mut fmi2FMUstate,
) -> fmi2Status {
    dispatch(c, Call::FreeFmuState, |instance| {
        let handle = state as usize;
        // fmusim 0.0.39 calls fmi2FreeFMUstate(c, FMUState): the state instead of the
        // address of the variable holding it. Dereferencing it (as the standard signature
        // asks) would read our own state object as a pointer and then free whatever that
        // points to: the SIGSEGV this used to be. Handles are never user-space addresses
        // (slab.rs), so the misuse is recognised exactly, also with a freed state.
        // We free the state and answer fmi2OK (with a warning in the log):
        // - memory stays safe either way: the importer's variable keeps the stale value,
        //   but every later use of it is looked up here first and refused, never read;
        // - refusing would leak the state until fmi2FreeInstance and, worse, end fmusim's
        //   run (it aborts on any status above fmi2OK), although the intent is clear.
        if instance.states.contains(handle) {
            instance.states.free(handle)?;
            instance.log_warning(&format!(
                "fmi2FreeFMUstate: the argument is the FMU state {handle:#x} itself, not the \
                 address of a variable holding it (an importer bug); the state was freed, \
                 the importer's variable could not be set to NULL"
            ));
            return Ok(());
        }
        if is_handle(handle) {
            // The same misuse with another instance's state or a freed one: refused, and
            // never dereferenced (a handle is not an address).
            return Err(instance.states.unknown(handle));
        }
        // FMI 2.0: a NULL pointer (or a variable holding NULL) is ignored.
        let Some(slot) = state.as_mut() else {
            return Ok(());
        };
        if slot.is_null() {
            return Ok(());
        }
        instance.states.free(*slot as usize)?;
        *slot = ptr::null_mut();
        Ok(())
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
        |instance| {
            let bytes = instance.states.bytes(state as usize)?;
            *size
                .as_mut()
                .ok_or_else(|| Failure::error("size is NULL"))? = bytes.len();
            Ok(())
        },
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
        let bytes = instance.states.bytes(state as usize)?;
        if size < bytes.len() {
            return Err(Failure::error(format!(
                "buffer of {size} bytes is too small for the state's {} bytes",
                bytes.len()
            )));
        }
        let out = slice_mut(serializedState as *mut u8, bytes.len(), "serializedState")?;
        out.copy_from_slice(bytes);
        Ok(())
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
        let slot = state_slot(state)?;
        let bytes = slice(serializedState as *const u8, size, "serializedState")?;
        instance.check_snapshot(bytes)?;
        let existing = *slot as usize;
        // A state of this instance is reused; anything else in the variable (NULL, or
        // whatever an importer left there) is replaced by a new state, never read.
        if instance.states.contains(existing) {
            instance.states.overwrite(existing, bytes.to_vec())?;
        } else {
            *slot = instance.states.add(bytes.to_vec()) as fmi2FMUstate;
        }
        Ok(())
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
