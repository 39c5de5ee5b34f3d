//! What every exported instance function of both standards shares: the instance lookup in
//! the registry (a handle of the other standard's instance is refused), the lock, the state
//! machine, logging and panic capture.

use std::panic::{catch_unwind, AssertUnwindSafe};

use super::instance::Instance;
use super::logger::Category;
use super::registry;
use super::standard::Standard;
use super::state_machine::{Call, Mode};
use super::status::{Failure, Outcome, Status};

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
pub fn dispatch(
    standard: Standard,
    handle: usize,
    call: Call,
    body: impl FnOnce(&mut Instance) -> Outcome,
) -> u32 {
    let result = catch_unwind(AssertUnwindSafe(|| {
        let mut instance = registry::instance(handle)?;
        let status = if instance.standard != standard {
            refuse_other_standard(&instance, standard, call)
        } else if !call.is_allowed_in(instance.mode) {
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
pub fn dispatch_fast(
    standard: Standard,
    handle: usize,
    call: Call,
    fast: impl FnOnce(&mut Instance) -> Option<()>,
    body: impl FnOnce(&mut Instance) -> Outcome,
) -> u32 {
    let done = catch_unwind(AssertUnwindSafe(|| {
        let mut instance = registry::instance(handle)?;
        if instance.standard != standard
            || !call.is_allowed_in(instance.mode)
            || instance.logger.is_enabled(Category::All)
        {
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
        Ok(None) => dispatch_out_of_line(standard, handle, call, body),
        Err(payload) => fatal(handle, call, payload),
    }
}

#[inline(never)]
fn dispatch_out_of_line(
    standard: Standard,
    handle: usize,
    call: Call,
    body: impl FnOnce(&mut Instance) -> Outcome,
) -> u32 {
    dispatch(standard, handle, call, body)
}

// The rare paths of `dispatch`, out of line: the per-sample calls stay short.

#[cold]
#[inline(never)]
fn refuse_in_this_mode(instance: &Instance, call: Call) -> Status {
    let failure = Failure::error(format!("illegal call sequence (state {:?})", instance.mode));
    instance.report(call, &failure)
}

/// One standard's function called with the other's instance: refused, the instance left as
/// it was (its importer mixed up two FMUs, or an FMU's two descriptions).
#[cold]
#[inline(never)]
fn refuse_other_standard(instance: &Instance, standard: Standard, call: Call) -> Status {
    let message = format!(
        "{}: called with an instance made by {}: an {} instance answers only the {} functions",
        call.name(standard),
        match instance.standard {
            Standard::Fmi2 => "fmi2Instantiate",
            Standard::Fmi3 => "fmi3InstantiateCoSimulation",
        },
        instance.standard.name(),
        instance.standard.prefix(),
    );
    // Logged through the instance's own importer callback, under its standard.
    instance
        .logger
        .log(Status::Error, Category::StatusError, &message);
    Status::Error
}

#[cold]
#[inline(never)]
fn trace(instance: &Instance, call: Call) {
    let trace = format!("{} called", call.name(instance.standard));
    instance.logger.log(Status::Ok, Category::All, &trace);
}

/// After a panic in a call: marks the instance Fatal (if it is still there: the guard was
/// dropped as the panic unwound, so another thread may have freed it) and logs why.
#[cold]
#[inline(never)]
fn fatal(handle: usize, call: Call, payload: Box<dyn std::any::Any + Send>) -> u32 {
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

/// The end of both standards' instantiation: the instance's messages sent, then the
/// instance registered; its handle, or `None` (logged as `function`'s refusal) when the
/// registry is full.
pub fn register(instance: Instance, function: &str) -> Option<usize> {
    instance.logger.flush();
    match registry::add_instance(instance) {
        Ok(handle) => Some(handle),
        Err(instance) => {
            instance.logger.log(
                Status::Error,
                Category::StatusError,
                &format!("{function}: too many live instances in this process"),
            );
            instance.logger.flush();
            None
        }
    }
}

/// Both standards' `FreeInstance`: logged, then unregistered whatever the log call did (even
/// a panic in it must not leak the instance), once a call still running on another thread
/// has ended; the instance, with its FMU states, is dropped here, outside the registry. A
/// handle that is no live instance of `standard` (the other standard's included) is left
/// alone.
pub fn free_instance(standard: Standard, handle: usize) {
    dispatch(standard, handle, Call::FreeInstance, |instance| {
        instance.log_event("freed");
        Ok(())
    });
    let removed = registry::remove_instance(handle, standard);
    let _ = catch_unwind(AssertUnwindSafe(move || drop(removed)));
}
