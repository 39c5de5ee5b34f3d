//! The FMI 2.0 boundary, exercised through the C ABI of the built library: the state
//! machine, instantiation checks, logging, FMU state, bad input and panics.
//!
//! Needs the `test-hooks` feature (the `FaultProbe` model); the README's test command
//! enables it.
#![cfg(feature = "test-hooks")]

mod common;

use common::*;
use contour_fmu::models::{fault_probe as probe, xy_servo_plant as plant};

const U_X: u32 = plant::U.at(0).vr() as u32;
const U_Y: u32 = plant::U.at(1).vr() as u32;
const POS_X: u32 = plant::POS.at(0).vr() as u32;
const POS_Y: u32 = plant::POS.at(1).vr() as u32;
const VEL_X: u32 = plant::VEL.at(0).vr() as u32;
const X_J: u32 = 6;
const POS0_X: u32 = plant::POS0.at(0).vr() as u32;

// ---------------------------------------------------------------------------------------
// State machine

#[derive(Clone, Copy, Debug, PartialEq)]
enum Mode {
    Instantiated,
    Initialization,
    StepComplete,
    Terminated,
    Error,
    Fatal,
}
use Mode::*;
const MODES: [Mode; 6] = [
    Instantiated,
    Initialization,
    StepComplete,
    Terminated,
    Error,
    Fatal,
];

/// A FaultProbe instance driven into a mode, with an FMU state of it (saved before it got
/// there, in Instantiated or StepComplete) and that state's serialized bytes, so the FMU
/// state functions have real work to do in every mode.
struct Probe {
    i: Instance,
    saved: fmi2FMUstate,
    bytes: Vec<u8>,
}

fn probe_in(mode: Mode) -> Probe {
    let i = Instance::new(&probe::INFO);
    let save = |i: &Instance| {
        let (s, saved) = i.get_state();
        assert_eq!(s, OK);
        let (s, bytes) = i.serialize(saved);
        assert_eq!(s, OK);
        (saved, bytes)
    };
    if mode == Instantiated {
        let (saved, bytes) = save(&i);
        return Probe { i, saved, bytes };
    }
    assert_eq!(i.setup(0.0, None), OK);
    assert_eq!(i.enter_init(), OK);
    if mode == Initialization {
        let (saved, bytes) = save(&i);
        return Probe { i, saved, bytes };
    }
    assert_eq!(i.exit_init(), OK);
    let (saved, bytes) = save(&i);
    match mode {
        StepComplete => {}
        Terminated => assert_eq!(i.terminate(), OK),
        Error => {
            assert_eq!(i.set_boolean(probe::FAIL.vr() as u32, true), OK);
            assert_eq!(i.step(0.0, 0.1), ERROR);
        }
        Fatal => {
            assert_eq!(i.set_boolean(probe::PANIC.vr() as u32, true), OK);
            assert_eq!(i.step(0.0, 0.1), FATAL);
        }
        _ => unreachable!(),
    }
    i.clear_log();
    Probe { i, saved, bytes }
}

type Call = fn(&mut Probe) -> fmi2Status;

/// What a function answers where it is allowed: the status, and for anything but fmi2OK
/// the start of the logged reason (the documented behaviour).
#[derive(Clone, Copy, Debug)]
enum Answer {
    Ok,
    Documented(fmi2Status, &'static str),
}

/// Every instance function, called with well-formed arguments, the modes in which FMI 2.0
/// (section 4.3.3, Co-Simulation; the Reference FMUs' masks) allows it, and its answer
/// there. Written from the standard, not from the library's own table.
fn functions() -> Vec<(&'static str, Call, &'static [Mode], Answer)> {
    const ALIVE: &[Mode] = &[
        Instantiated,
        Initialization,
        StepComplete,
        Terminated,
        Error,
    ];
    const GET: &[Mode] = &[Initialization, StepComplete, Terminated, Error];
    const SET: &[Mode] = &[Instantiated, Initialization, StepComplete];
    const STATUS: &[Mode] = &[StepComplete, Terminated];
    const EVERY: &[Mode] = &MODES;
    use Answer::{Documented, Ok as Fine};
    vec![
        (
            "fmi2SetDebugLogging",
            |p| p.i.set_debug_logging(true, &[]),
            ALIVE,
            Fine,
        ),
        (
            "fmi2SetupExperiment",
            |p| p.i.setup(0.0, None),
            &[Instantiated],
            Fine,
        ),
        (
            "fmi2EnterInitializationMode",
            |p| p.i.enter_init(),
            &[Instantiated],
            Fine,
        ),
        (
            "fmi2ExitInitializationMode",
            |p| p.i.exit_init(),
            &[Initialization],
            Fine,
        ),
        ("fmi2Terminate", |p| p.i.terminate(), &[StepComplete], Fine),
        ("fmi2Reset", |p| p.i.reset(), ALIVE, Fine),
        (
            "fmi2GetReal",
            |p| p.i.get_reals(&[probe::GAIN.vr() as u32]).0,
            GET,
            Fine,
        ),
        (
            "fmi2GetInteger",
            |p| p.i.get_integer(probe::STEPS.vr() as u32).0,
            GET,
            Fine,
        ),
        (
            "fmi2GetBoolean",
            |p| p.i.get_boolean(probe::FAIL.vr() as u32).0,
            GET,
            Fine,
        ),
        (
            "fmi2GetString",
            |p| p.i.get_string(probe::LABEL.vr() as u32).0,
            GET,
            Fine,
        ),
        (
            "fmi2SetReal",
            // A tunable parameter: settable in all three modes.
            |p| p.i.set_reals(&[probe::GAIN.vr() as u32], &[2.0]),
            SET,
            Fine,
        ),
        (
            "fmi2SetInteger",
            |p| p.i.set_integer(probe::LEVEL.vr() as u32, 3),
            SET,
            Fine,
        ),
        (
            "fmi2SetBoolean",
            |p| p.i.set_boolean(probe::FAIL.vr() as u32, false),
            SET,
            Fine,
        ),
        (
            "fmi2SetString",
            |p| p.i.set_string(probe::NOTE.vr() as u32, "x"),
            SET,
            Fine,
        ),
        (
            "fmi2GetFMUstate",
            |p| {
                let (s, mut state) = p.i.get_state();
                if !state.is_null() {
                    assert_eq!(p.i.free_state(&mut state), OK);
                }
                s
            },
            ALIVE,
            Fine,
        ),
        ("fmi2SetFMUstate", |p| p.i.set_state(p.saved), ALIVE, Fine),
        (
            "fmi2FreeFMUstate",
            |p| {
                let mut state = p.saved;
                let s = p.i.free_state(&mut state);
                if s == OK {
                    assert!(state.is_null(), "the variable is set to NULL");
                }
                s
            },
            // Also after a fatal error, so that stored states can be released.
            EVERY,
            Fine,
        ),
        (
            "fmi2SerializedFMUstateSize",
            |p| {
                let (s, size) = p.i.state_size(p.saved);
                if s == OK {
                    assert_eq!(size, p.bytes.len());
                }
                s
            },
            ALIVE,
            Fine,
        ),
        (
            "fmi2SerializeFMUstate",
            |p| {
                let mut buffer = vec![0 as fmi2Byte; p.bytes.len()];
                let s = unsafe {
                    lib().fmi2SerializeFMUstate(p.i.c, p.saved, buffer.as_mut_ptr(), buffer.len())
                };
                if s == OK {
                    let bytes: Vec<u8> = buffer.iter().map(|&b| b as u8).collect();
                    assert_eq!(bytes, p.bytes);
                }
                s
            },
            ALIVE,
            Fine,
        ),
        (
            "fmi2DeSerializeFMUstate",
            |p| {
                let bytes = p.bytes.clone();
                let (s, mut state) = p.i.deserialize(&bytes);
                if s == OK {
                    assert!(!state.is_null());
                    assert_eq!(p.i.free_state(&mut state), OK);
                }
                s
            },
            ALIVE,
            Fine,
        ),
        (
            "fmi2GetDirectionalDerivative",
            |p| {
                let (vr, dv, mut out) = (0u32, 1.0, 0.0);
                unsafe { lib().fmi2GetDirectionalDerivative(p.i.c, &vr, 1, &vr, 1, &dv, &mut out) }
            },
            GET,
            Documented(
                ERROR,
                "not supported (providesDirectionalDerivative=\"false\")",
            ),
        ),
        (
            "fmi2SetRealInputDerivatives",
            |p| {
                let (vr, order, v) = (0u32, 1, 0.0);
                unsafe { lib().fmi2SetRealInputDerivatives(p.i.c, &vr, 1, &order, &v) }
            },
            SET,
            Documented(ERROR, "not supported (canInterpolateInputs=\"false\")"),
        ),
        (
            "fmi2GetRealOutputDerivatives",
            |p| {
                let (vr, order, mut v) = (0u32, 1, 0.0);
                unsafe { lib().fmi2GetRealOutputDerivatives(p.i.c, &vr, 1, &order, &mut v) }
            },
            &[StepComplete, Terminated, Error],
            Documented(ERROR, "not supported (maxOutputDerivativeOrder=\"0\")"),
        ),
        ("fmi2DoStep", |p| p.i.step(0.0, 0.01), &[StepComplete], Fine),
        (
            "fmi2CancelStep",
            |p| unsafe { lib().fmi2CancelStep(p.i.c) },
            &[],
            Fine,
        ),
        (
            "fmi2GetStatus",
            |p| {
                let mut v = 0;
                unsafe { lib().fmi2GetStatus(p.i.c, fmi2StatusKind_fmi2DoStepStatus, &mut v) }
            },
            STATUS,
            Documented(DISCARD, "no asynchronous step status"),
        ),
        (
            "fmi2GetRealStatus",
            |p| {
                let mut v = f64::NAN;
                let s = unsafe {
                    lib().fmi2GetRealStatus(p.i.c, fmi2StatusKind_fmi2LastSuccessfulTime, &mut v)
                };
                if s == OK {
                    assert_eq!(v, 0.0, "no step was taken");
                }
                s
            },
            STATUS,
            Fine,
        ),
        (
            "fmi2GetIntegerStatus",
            |p| {
                let mut v = 0;
                unsafe {
                    lib().fmi2GetIntegerStatus(p.i.c, fmi2StatusKind_fmi2DoStepStatus, &mut v)
                }
            },
            STATUS,
            Documented(DISCARD, "status kind 0 has no Integer value"),
        ),
        (
            "fmi2GetBooleanStatus",
            |p| {
                let mut v = 7;
                let s = unsafe {
                    lib().fmi2GetBooleanStatus(p.i.c, fmi2StatusKind_fmi2Terminated, &mut v)
                };
                if s == OK {
                    assert_eq!(v, 0);
                }
                s
            },
            STATUS,
            Fine,
        ),
        (
            "fmi2GetStringStatus",
            |p| {
                let mut v: fmi2String = std::ptr::null();
                unsafe {
                    lib().fmi2GetStringStatus(p.i.c, fmi2StatusKind_fmi2PendingStatus, &mut v)
                }
            },
            STATUS,
            Documented(DISCARD, "status kind 1 has no String value"),
        ),
        (
            "fmi2FreeInstance",
            |p| {
                p.i.free();
                // No status (void): the instance must be gone, so a call on it is refused.
                let (s, _) = p.i.get_reals(&[probe::GAIN.vr() as u32]);
                assert_eq!(s, ERROR);
                OK
            },
            EVERY,
            Fine,
        ),
    ]
}

#[test]
fn every_function_answers_as_documented_where_allowed_and_is_refused_elsewhere() {
    let mut checked = 0;
    for (name, call, allowed, answer) in functions() {
        for mode in MODES {
            let mut p = probe_in(mode);
            let status = call(&mut p);
            let messages: Vec<(fmi2Status, String)> =
                p.i.records()
                    .into_iter()
                    .map(|r| (r.status, r.message))
                    .collect();
            let illegal = messages
                .iter()
                .any(|(_, m)| m.starts_with(&format!("{name}: illegal call sequence")));
            if allowed.contains(&mode) {
                assert!(!illegal, "{name} refused in {mode:?}: {messages:?}");
                match answer {
                    Answer::Ok => assert_eq!(status, OK, "{name} in {mode:?}: {messages:?}"),
                    Answer::Documented(expected, reason) => {
                        assert_eq!(status, expected, "{name} in {mode:?}: {messages:?}");
                        // Errors are always logged; a Discard only with logging on.
                        if expected == ERROR {
                            let logged = format!("{name}: {reason}");
                            assert!(
                                messages.iter().any(|(s, m)| *s == expected && m == &logged),
                                "{name} in {mode:?}: {messages:?}"
                            );
                        }
                    }
                }
            } else {
                assert_eq!(status, ERROR, "{name} in {mode:?}");
                assert!(
                    illegal,
                    "{name} in {mode:?} did not log an illegal call sequence: {messages:?}"
                );
            }
            checked += 1;
        }
    }
    assert_eq!(checked, 31 * MODES.len());
}

/// The Discard answers give their reason in the log when warnings are logged.
#[test]
fn discarded_status_requests_say_why() {
    let p = probe_in(StepComplete);
    assert_eq!(p.i.set_debug_logging(true, &["logStatusWarning"]), OK);
    let mut v = 0;
    let s = unsafe { lib().fmi2GetStatus(p.i.c, fmi2StatusKind_fmi2DoStepStatus, &mut v) };
    assert_eq!(s, DISCARD);
    assert!(p
        .i
        .messages(DISCARD)
        .contains(&"fmi2GetStatus: no asynchronous step status: steps are synchronous".into()));
}

#[test]
fn all_34_functions_are_exported_and_report_the_platform() {
    let lib = lib();
    let present = [
        lib.fmi2GetTypesPlatform.is_ok(),
        lib.fmi2GetVersion.is_ok(),
        lib.fmi2SetDebugLogging.is_ok(),
        lib.fmi2Instantiate.is_ok(),
        lib.fmi2FreeInstance.is_ok(),
        lib.fmi2SetupExperiment.is_ok(),
        lib.fmi2EnterInitializationMode.is_ok(),
        lib.fmi2ExitInitializationMode.is_ok(),
        lib.fmi2Terminate.is_ok(),
        lib.fmi2Reset.is_ok(),
        lib.fmi2GetReal.is_ok(),
        lib.fmi2GetInteger.is_ok(),
        lib.fmi2GetBoolean.is_ok(),
        lib.fmi2GetString.is_ok(),
        lib.fmi2SetReal.is_ok(),
        lib.fmi2SetInteger.is_ok(),
        lib.fmi2SetBoolean.is_ok(),
        lib.fmi2SetString.is_ok(),
        lib.fmi2GetFMUstate.is_ok(),
        lib.fmi2SetFMUstate.is_ok(),
        lib.fmi2FreeFMUstate.is_ok(),
        lib.fmi2SerializedFMUstateSize.is_ok(),
        lib.fmi2SerializeFMUstate.is_ok(),
        lib.fmi2DeSerializeFMUstate.is_ok(),
        lib.fmi2GetDirectionalDerivative.is_ok(),
        lib.fmi2SetRealInputDerivatives.is_ok(),
        lib.fmi2GetRealOutputDerivatives.is_ok(),
        lib.fmi2DoStep.is_ok(),
        lib.fmi2CancelStep.is_ok(),
        lib.fmi2GetStatus.is_ok(),
        lib.fmi2GetRealStatus.is_ok(),
        lib.fmi2GetIntegerStatus.is_ok(),
        lib.fmi2GetBooleanStatus.is_ok(),
        lib.fmi2GetStringStatus.is_ok(),
    ];
    assert_eq!(present.len(), 34);
    assert!(present.iter().all(|&p| p));
    let platform = unsafe { std::ffi::CStr::from_ptr(lib.fmi2GetTypesPlatform()) };
    let version = unsafe { std::ffi::CStr::from_ptr(lib.fmi2GetVersion()) };
    assert_eq!(platform.to_str().unwrap(), "default");
    assert_eq!(version.to_str().unwrap(), "2.0");
}

#[test]
fn status_functions_answer_as_documented() {
    let i = Instance::new(&plant::INFO);
    i.start();
    assert_eq!(i.step(0.0, 0.25), OK);
    let mut t = 0.0;
    assert_eq!(
        unsafe { lib().fmi2GetRealStatus(i.c, fmi2StatusKind_fmi2LastSuccessfulTime, &mut t) },
        OK
    );
    assert_eq!(t, 0.25);
    let mut terminated = 7;
    assert_eq!(
        unsafe { lib().fmi2GetBooleanStatus(i.c, fmi2StatusKind_fmi2Terminated, &mut terminated) },
        OK
    );
    assert_eq!(terminated, 0);
    let mut s = 0;
    assert_eq!(
        unsafe { lib().fmi2GetStatus(i.c, fmi2StatusKind_fmi2DoStepStatus, &mut s) },
        DISCARD
    );
    assert_eq!(
        unsafe { lib().fmi2GetRealStatus(i.c, fmi2StatusKind_fmi2DoStepStatus, &mut t) },
        DISCARD
    );
}

// ---------------------------------------------------------------------------------------
// Instantiation

#[test]
fn instantiate_refuses_wrong_guid_type_callbacks_and_name() {
    let guid = plant::INFO.guid();
    let (c, log, _cb) = instantiate_raw(
        Some("a"),
        fmi2Type_fmi2CoSimulation,
        Some("{00000000-0000-0000-0000-000000000000}"),
        None,
        false,
    );
    assert!(c.is_null());
    let messages = log.records.lock().unwrap().clone();
    assert!(
        messages
            .iter()
            .any(|r| r.status == ERROR && r.message.contains("unknown GUID")),
        "{messages:?}"
    );

    let (c, log, _cb) = instantiate_raw(
        Some("a"),
        fmi2Type_fmi2ModelExchange,
        Some(&guid),
        None,
        false,
    );
    assert!(c.is_null());
    assert!(log.records.lock().unwrap()[0]
        .message
        .contains("Co-Simulation only"));

    let (c, _log, _cb) = instantiate_raw(Some("a"), fmi2Type_fmi2CoSimulation, None, None, false);
    assert!(c.is_null());
    let (c, _log, _cb) = instantiate_raw(
        Some(" "),
        fmi2Type_fmi2CoSimulation,
        Some(&guid),
        None,
        false,
    );
    assert!(c.is_null());
    let (c, _log, _cb) = instantiate_raw(None, fmi2Type_fmi2CoSimulation, Some(&guid), None, false);
    assert!(c.is_null());

    // NULL callbacks, and callbacks without a logger: refused without a crash.
    let name = cstr("a");
    let guid_c = cstr(&guid);
    let c = unsafe {
        lib().fmi2Instantiate(
            name.as_ptr(),
            fmi2Type_fmi2CoSimulation,
            guid_c.as_ptr(),
            std::ptr::null(),
            std::ptr::null(),
            0,
            0,
        )
    };
    assert!(c.is_null());
    let log = Log::default();
    let mut callbacks = callbacks(&log);
    callbacks.logger = None;
    let c = unsafe {
        lib().fmi2Instantiate(
            name.as_ptr(),
            fmi2Type_fmi2CoSimulation,
            guid_c.as_ptr(),
            std::ptr::null(),
            &*callbacks,
            0,
            0,
        )
    };
    assert!(c.is_null());
}

#[test]
fn resource_locations_in_every_common_form_are_accepted() {
    let guid = plant::INFO.guid();
    let forms = [
        Some("file:///tmp/some%20dir/resources"),
        Some("file:///tmp/some%20dir/resources/"),
        Some("file:/tmp/some%20dir/resources"),
        Some("file://localhost/tmp/resources/"),
        None,
    ];
    for form in forms {
        let (c, log, _cb) = instantiate_raw(
            Some("r"),
            fmi2Type_fmi2CoSimulation,
            Some(&guid),
            form,
            true,
        );
        assert!(!c.is_null(), "{form:?}");
        let records = log.records.lock().unwrap().clone();
        assert!(
            records.iter().all(|r| r.status == OK),
            "{form:?}: {records:?}"
        );
        unsafe { lib().fmi2FreeInstance(c) };
    }
    // Not a local folder: the instance still works, with a warning.
    let (c, log, _cb) = instantiate_raw(
        Some("r"),
        fmi2Type_fmi2CoSimulation,
        Some(&guid),
        Some("http://host/r"),
        true,
    );
    assert!(!c.is_null());
    assert!(log
        .records
        .lock()
        .unwrap()
        .iter()
        .any(|r| r.status == WARNING && r.message.contains("not a file: URI")));
    unsafe { lib().fmi2FreeInstance(c) };
}

// ---------------------------------------------------------------------------------------
// Logging

#[test]
fn logging_categories_are_honoured_and_errors_always_logged() {
    let i = Instance::new(&plant::INFO);
    // Logging was off at instantiation: no event messages.
    assert!(i.records().is_empty());
    i.start();
    assert!(i.records().is_empty());
    // An error is logged even so.
    assert_eq!(i.step(0.0, -1.0), ERROR);
    let records = i.records();
    assert_eq!(records.len(), 1);
    assert_eq!(records[0].category, "logStatusError");
    assert!(records[0]
        .message
        .starts_with("fmi2DoStep: communication step size must be finite and > 0"));
    assert_eq!(records[0].instance, "test");
    i.clear_log();

    // Events only.
    assert_eq!(i.set_debug_logging(true, &["logEvents"]), OK);
    assert_eq!(i.terminate(), OK);
    let records = i.records();
    assert_eq!(records.len(), 1, "{records:?}");
    assert_eq!(records[0].category, "logEvents");
    assert!(records[0].message.starts_with("terminated at t = 0"));
    i.clear_log();

    // logAll traces every call.
    assert_eq!(i.set_debug_logging(true, &["logAll"]), OK);
    i.clear_log();
    let _ = i.get_real(POS_X);
    assert!(i
        .records()
        .iter()
        .any(|r| r.message == "fmi2GetReal called"));

    // Off for everything: only errors remain.
    assert_eq!(i.set_debug_logging(false, &[]), OK);
    i.clear_log();
    assert_eq!(i.reset(), OK);
    assert!(i.records().is_empty());

    // Unknown category: refused, nothing changed.
    assert_eq!(
        i.set_debug_logging(true, &["logEvents", "logNonsense"]),
        ERROR
    );
    assert!(i
        .last_error()
        .contains("unknown log category 'logNonsense'"));
    i.clear_log();
    assert_eq!(i.setup(0.0, None), OK);
    assert!(i.records().is_empty(), "logEvents must still be off");
}

#[test]
fn a_logger_may_call_back_into_the_instance() {
    let i = Instance::new(&plant::INFO);
    i.start();
    i.log
        .reenter
        .store(i.c, std::sync::atomic::Ordering::SeqCst);
    // The error is logged while the call is in progress; the logger's own call must get
    // through instead of deadlocking on the instance.
    let c = i.c as usize;
    let (sender, receiver) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let status = unsafe { lib().fmi2DoStep(c as fmi2Component, 0.0, -1.0, 1) };
        sender.send(status).unwrap();
    });
    let status = receiver
        .recv_timeout(std::time::Duration::from_secs(10))
        .expect("fmi2DoStep deadlocked in its logger callback");
    assert_eq!(status, ERROR);
    let records = i.records();
    assert!(
        records
            .iter()
            .any(|r| r.category == "reentered" && r.message.ends_with("returned 0")),
        "{records:?}"
    );
}

#[test]
fn debug_logging_with_categories_logs_only_those() {
    let (c, log, _cb) = instantiate_raw(
        Some("cat"),
        fmi2Type_fmi2CoSimulation,
        Some(&plant::INFO.guid()),
        None,
        true,
    );
    let only = cstr("logStatusWarning");
    let p = only.as_ptr();
    assert_eq!(unsafe { lib().fmi2SetDebugLogging(c, 1, 1, &p) }, OK);
    log.records.lock().unwrap().clear();
    unsafe {
        assert_eq!(lib().fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0), OK);
        assert_eq!(lib().fmi2EnterInitializationMode(c), OK);
        assert_eq!(lib().fmi2ExitInitializationMode(c), OK);
    }
    // Neither call traces (logAll) nor events (logEvents): only warnings were asked for.
    assert!(
        log.records.lock().unwrap().is_empty(),
        "{:?}",
        log.records.lock().unwrap()
    );
    unsafe { lib().fmi2FreeInstance(c) };
}

#[test]
fn messages_are_always_passed_through_a_percent_s_format() {
    let (c, log, _cb) = instantiate_raw(
        Some("%s%n%x"),
        fmi2Type_fmi2CoSimulation,
        Some(&plant::INFO.guid()),
        None,
        true,
    );
    assert!(!c.is_null());
    let nasty = cstr("%s%n%p%s");
    let p = nasty.as_ptr();
    let status = unsafe { lib().fmi2SetDebugLogging(c, 1, 1, &p) };
    assert_eq!(status, ERROR);
    let records = log.records.lock().unwrap().clone();
    assert!(!records.is_empty());
    for r in &records {
        assert_eq!(r.format, "%s");
        assert_eq!(r.instance, "%s%n%x");
    }
    assert!(records
        .iter()
        .any(|r| r.message.contains("unknown log category '%s%n%p%s'")));
    unsafe { lib().fmi2FreeInstance(c) };
}

// ---------------------------------------------------------------------------------------
// Bad input

#[test]
fn non_finite_values_are_refused_and_the_old_value_kept() {
    let i = Instance::new(&plant::INFO);
    i.start();
    assert_eq!(i.set_reals(&[U_X], &[3.0]), OK);
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        assert_eq!(i.set_reals(&[U_Y, U_X], &[1.0, bad]), ERROR);
        assert!(i.last_error().contains("non-finite"), "{}", i.last_error());
        // Atomic: neither value of the refused call was stored.
        assert_eq!(i.get_reals(&[U_X, U_Y]), (OK, vec![3.0, 0.0]));
    }
    // The instance carries on.
    assert_eq!(i.step(0.0, 0.01), OK);
}

#[test]
fn unknown_references_wrong_types_and_outputs_are_errors() {
    let i = Instance::new(&plant::INFO);
    i.start();
    let (s, _) = i.get_reals(&[POS_X, 999]);
    assert_eq!(s, ERROR);
    assert!(i.last_error().contains("unknown value reference 999"));
    assert_eq!(i.set_reals(&[1000], &[1.0]), ERROR);
    assert_eq!(i.get_integer(POS_X).0, ERROR);
    assert!(
        i.last_error()
            .contains("'pos.x' (value reference 2) is of type Real, not Integer"),
        "{}",
        i.last_error()
    );
    assert_eq!(i.set_boolean(U_X, true), ERROR);
    assert!(i.last_error().contains("is of type Real, not Boolean"));
    assert_eq!(i.set_reals(&[POS_X], &[1.0]), ERROR);
    assert!(i.last_error().contains("'pos.x' is an output"));
    // A fixed parameter after initialization.
    assert_eq!(i.set_reals(&[X_J], &[0.02]), ERROR);
    assert!(i.last_error().contains("parameter 'x.J' is fixed"));
    // NULL arrays with a non-zero length.
    let s = unsafe { lib().fmi2GetReal(i.c, std::ptr::null(), 1, std::ptr::null_mut()) };
    assert_eq!(s, ERROR);
    // Zero-length requests are fine.
    let s = unsafe { lib().fmi2GetReal(i.c, std::ptr::null(), 0, std::ptr::null_mut()) };
    assert_eq!(s, OK);
}

#[test]
fn parameters_are_range_checked() {
    let i = Instance::new(&plant::INFO);
    assert_eq!(i.setup(0.0, None), OK);
    assert_eq!(i.enter_init(), OK);
    assert_eq!(i.set_reals(&[X_J], &[-1.0]), ERROR);
    assert!(i.last_error().contains("'x.J' = -1 is below its minimum 0"));
    // Zero passes the bound but is unphysical: refused when initialization ends, and the
    // instance stays in initialization mode so the value can be corrected.
    assert_eq!(i.set_reals(&[X_J], &[0.0]), OK);
    assert_eq!(i.exit_init(), ERROR);
    assert!(
        i.last_error().contains("parameter 'x.J' must be > 0"),
        "{}",
        i.last_error()
    );
    assert_eq!(i.set_reals(&[X_J], &[0.015]), OK);
    assert_eq!(i.exit_init(), OK);
    assert_eq!(i.step(0.0, 0.01), OK);
}

#[test]
fn tunable_parameters_are_checked_by_the_model_and_restored_when_refused() {
    let i = Instance::new(&probe::INFO);
    i.start();
    let gain = probe::GAIN.vr() as u32;
    assert_eq!(i.set_reals(&[gain], &[5.0]), OK);
    assert_eq!(i.set_reals(&[gain], &[12.0]), ERROR);
    assert!(i.last_error().contains("'gain' must be < 10"));
    assert_eq!(i.get_real(gain), 5.0);
}

#[test]
fn do_step_checks_step_size_communication_point_and_stop_time() {
    let i = Instance::new(&plant::INFO);
    assert_eq!(i.setup(0.0, Some(0.05)), OK);
    assert_eq!(i.enter_init(), OK);
    assert_eq!(i.exit_init(), OK);
    for h in [0.0, -0.01, f64::NAN, f64::INFINITY] {
        assert_eq!(i.step(0.0, h), ERROR, "h = {h}");
    }
    assert_eq!(i.step(0.001, 0.01), ERROR);
    assert!(i
        .last_error()
        .contains("does not match the instance time 0"));
    // fmpy-style rounding: t = 0.01 computed as 0.009999999999999998.
    assert_eq!(i.step(0.0, 0.009999999999999998), OK);
    assert_eq!(i.step(0.01, 0.01), OK);
    // Past the stop time.
    assert_eq!(i.step(0.02, 0.04), ERROR);
    assert!(i.last_error().contains("would pass the stop time 0.05"));
    // Exactly to the stop time, with rounding.
    assert_eq!(i.step(0.02, 0.030000000000000002), OK);
    // Refused calls did not change the mode.
    assert_eq!(i.terminate(), OK);
}

#[test]
fn a_panic_in_a_model_becomes_fatal_and_the_instance_refuses_further_work() {
    let mut i = Instance::new(&probe::INFO);
    i.start();
    assert_eq!(i.step(0.0, 0.1), OK);
    assert_eq!(i.set_boolean(probe::PANIC.vr() as u32, true), OK);
    assert_eq!(i.step(0.1, 0.1), FATAL);
    let fatal = i.messages(FATAL);
    assert_eq!(fatal.len(), 1);
    assert!(fatal[0].contains("fmi2DoStep: internal error (panic): FaultProbe: injected panic"));
    assert_eq!(i.get_integer(probe::STEPS.vr() as u32).0, ERROR);
    assert_eq!(i.reset(), ERROR);
    // Other instances are unaffected.
    let other = Instance::new(&probe::INFO);
    other.start();
    assert_eq!(other.step(0.0, 0.1), OK);
    i.free();
}

#[test]
fn a_failing_step_moves_to_error_and_a_saved_state_recovers() {
    let i = Instance::new(&probe::INFO);
    i.start();
    assert_eq!(i.step(0.0, 0.1), OK);
    let (s, mut state) = i.get_state();
    assert_eq!(s, OK);
    assert_eq!(i.set_boolean(probe::FAIL.vr() as u32, true), OK);
    assert_eq!(i.step(0.1, 0.1), ERROR);
    assert!(i.last_error().contains("FaultProbe: injected failure"));
    assert_eq!(i.step(0.1, 0.1), ERROR);
    assert!(i
        .last_error()
        .contains("illegal call sequence (state Error)"));
    assert_eq!(i.set_state(state), OK);
    assert_eq!(i.get_boolean(probe::FAIL.vr() as u32), (OK, false));
    assert_eq!(i.step(0.1, 0.1), OK);
    assert_eq!(i.get_integer(probe::STEPS.vr() as u32), (OK, 2));
    assert_eq!(i.free_state(&mut state), OK);
    assert!(state.is_null());
}

#[test]
fn strings_stay_valid_until_the_next_call() {
    let i = Instance::new(&probe::INFO);
    assert_eq!(i.setup(0.0, None), OK);
    assert_eq!(i.enter_init(), OK);
    assert_eq!(i.set_string(probe::LABEL.vr() as u32, "spindle ✓"), OK);
    let (s, ptr, text) = i.get_string(probe::ECHO.vr() as u32);
    assert_eq!((s, text.as_str()), (OK, "spindle ✓"));
    // Still readable after the caller's own work, before the next call.
    let again = unsafe { std::ffi::CStr::from_ptr(ptr) }
        .to_str()
        .unwrap()
        .to_owned();
    assert_eq!(again, "spindle ✓");
    assert_eq!(i.exit_init(), OK);
}

// ---------------------------------------------------------------------------------------
// FMU state

fn run_plant(i: &Instance, from: usize, to: usize) -> Vec<[f64; 3]> {
    let h = 0.001;
    (from..to)
        .map(|k| {
            let t = k as f64 * h;
            let u = [20.0 * (5.0 * t).sin(), 15.0 * (3.0 * t).cos()];
            assert_eq!(i.set_reals(&[U_X, U_Y], &u), OK);
            assert_eq!(i.step(t, h), OK);
            let (_, v) = i.get_reals(&[POS_X, POS_Y, VEL_X]);
            [v[0], v[1], v[2]]
        })
        .collect()
}

#[test]
fn state_save_restore_and_serialization_give_bit_identical_trajectories() {
    let i = Instance::new(&plant::INFO);
    i.start();
    run_plant(&i, 0, 50);
    let (s, mut state) = i.get_state();
    assert_eq!(s, OK);
    let reference = run_plant(&i, 50, 120);

    // Restore in place.
    assert_eq!(i.set_state(state), OK);
    assert_eq!(run_plant(&i, 50, 120), reference);

    // Serialize, deserialize into a fresh instance, continue there.
    let (s, bytes) = i.serialize(state);
    assert_eq!(s, OK);
    // A state saved after initialization goes into an initialized instance.
    let other = Instance::new(&plant::INFO);
    other.start();
    let (s, mut restored) = other.deserialize(&bytes);
    assert_eq!(s, OK);
    assert_eq!(other.set_state(restored), OK);
    assert_eq!(run_plant(&other, 50, 120), reference);

    // Overwriting an existing state object in place (FMI allows passing it back).
    let mut reuse = state;
    assert_eq!(unsafe { lib().fmi2GetFMUstate(i.c, &mut reuse) }, OK);
    assert_eq!(reuse, state);

    assert_eq!(i.free_state(&mut state), OK);
    assert_eq!(other.free_state(&mut restored), OK);
}

#[test]
fn corrupt_truncated_and_foreign_state_bytes_are_refused() {
    let i = Instance::new(&plant::INFO);
    i.start();
    run_plant(&i, 0, 10);
    let (_, mut state) = i.get_state();
    let (_, bytes) = i.serialize(state);
    let before = i.get_real(POS_X);

    let mut corrupt = bytes.clone();
    let middle = corrupt.len() / 2;
    corrupt[middle] ^= 0x01;
    for bad in [
        corrupt,
        bytes[..bytes.len() - 1].to_vec(),
        b"not a state at all".to_vec(),
        Vec::new(),
    ] {
        let (s, st) = i.deserialize(&bad);
        assert_eq!(s, ERROR);
        assert!(st.is_null());
    }
    // A state of another model.
    let probe = Instance::new(&probe::INFO);
    probe.start();
    let (_, mut probe_state) = probe.get_state();
    let (_, probe_bytes) = probe.serialize(probe_state);
    assert_eq!(i.deserialize(&probe_bytes).0, ERROR);
    assert!(i.last_error().contains("belongs to another model"));
    // Too small a buffer.
    let mut small = vec![0u8; 4];
    let s = unsafe {
        lib().fmi2SerializeFMUstate(i.c, state, small.as_mut_ptr() as *mut fmi2Byte, small.len())
    };
    assert_eq!(s, ERROR);
    // Nothing above disturbed the instance.
    assert_eq!(i.get_real(POS_X), before);
    i.free_state(&mut state);
    probe.free_state(&mut probe_state);
}

/// fmi2SetFMUstate restores the mode the state was saved in, whatever the mode now (as
/// the Reference FMUs do): the instance then behaves exactly like the one that saved it.
#[test]
fn restoring_a_state_brings_back_the_mode_it_was_saved_in() {
    let i = Instance::new(&plant::INFO);
    let (_, mut early) = i.get_state();
    i.start();
    run_plant(&i, 0, 10);
    let (_, mut running) = i.get_state();
    let reference = run_plant(&i, 10, 30);

    // Saved before initialization: the instance is back in Instantiated with start values.
    assert_eq!(i.set_state(early), OK);
    assert_eq!(i.step(0.01, 0.001), ERROR);
    assert!(i
        .last_error()
        .contains("illegal call sequence (state Instantiated)"));
    assert_eq!(
        i.get_reals(&[POS0_X]).0,
        ERROR,
        "no fmi2GetReal before initialization"
    );
    assert_eq!(i.setup(0.0, None), OK);
    assert_eq!(i.enter_init(), OK);
    assert_eq!(i.get_reals(&[U_X, POS_X]), (OK, vec![0.0, 0.0]));

    // Terminated, then a state saved while stepping: stepping again, bit for bit.
    assert_eq!(i.exit_init(), OK);
    assert_eq!(i.terminate(), OK);
    assert_eq!(i.set_state(running), OK);
    assert_eq!(run_plant(&i, 10, 30), reference);

    // A state set into a freshly instantiated instance: no initialization needed.
    let fresh = Instance::new(&plant::INFO);
    let (_, bytes) = i.serialize(running);
    let (s, mut restored) = fresh.deserialize(&bytes);
    assert_eq!(s, OK);
    assert_eq!(fresh.set_state(restored), OK);
    assert_eq!(run_plant(&fresh, 10, 30), reference);

    assert_eq!(i.free_state(&mut early), OK);
    assert_eq!(i.free_state(&mut running), OK);
    assert_eq!(fresh.free_state(&mut restored), OK);
}

// ---------------------------------------------------------------------------------------
// Instances and threads

#[test]
fn instances_are_independent_when_interleaved_and_across_threads() {
    let alone = Instance::new(&plant::INFO);
    alone.start();
    let reference = run_plant(&alone, 0, 200);

    let a = Instance::named(&plant::INFO, "a");
    let b = Instance::named(&plant::INFO, "b");
    a.start();
    assert_eq!(b.setup(0.0, None), OK);
    assert_eq!(b.enter_init(), OK);
    assert_eq!(b.set_reals(&[POS0_X], &[5.0]), OK);
    assert_eq!(b.exit_init(), OK);
    let mut from_a = Vec::new();
    for k in 0..200 {
        from_a.extend(run_plant(&a, k, k + 1));
        assert_eq!(b.set_reals(&[U_X], &[-100.0]), OK);
        assert_eq!(b.step(k as f64 * 0.001, 0.001), OK);
    }
    assert_eq!(from_a, reference);
    assert!(b.get_real(POS_X) < 5.0 - 10.0);

    // Each instance stepped on its own thread, concurrently.
    let results: Vec<Vec<[f64; 3]>> = std::thread::scope(|scope| {
        let handles: Vec<_> = (0..2)
            .map(|_| {
                scope.spawn(|| {
                    let i = Instance::new(&plant::INFO);
                    i.start();
                    run_plant(&i, 0, 200)
                })
            })
            .collect();
        handles.into_iter().map(|h| h.join().unwrap()).collect()
    });
    assert_eq!(results[0], reference);
    assert_eq!(results[1], reference);
}

#[test]
fn reset_restores_start_values() {
    let i = Instance::new(&plant::INFO);
    assert_eq!(i.setup(0.0, None), OK);
    assert_eq!(i.enter_init(), OK);
    assert_eq!(i.set_reals(&[POS0_X], &[7.0]), OK);
    assert_eq!(i.exit_init(), OK);
    assert_eq!(i.get_real(POS_X), 7.0);
    run_plant(&i, 0, 20);
    assert_eq!(i.reset(), OK);
    assert_eq!(i.setup(0.0, None), OK);
    assert_eq!(i.enter_init(), OK);
    assert_eq!(
        i.get_reals(&[POS0_X, POS_X, U_X]),
        (OK, vec![0.0, 0.0, 0.0])
    );
}

// ---------------------------------------------------------------------------------------
// XYServoPlant through the ABI

#[test]
fn one_long_step_equals_many_short_ones() {
    let coarse = Instance::new(&plant::INFO);
    let fine = Instance::new(&plant::INFO);
    coarse.start();
    fine.start();
    let mut t = 0.0;
    for k in 0..20 {
        let u = [50.0 * (k as f64 * 0.7).sin(), -30.0 + k as f64];
        assert_eq!(coarse.set_reals(&[U_X, U_Y], &u), OK);
        assert_eq!(fine.set_reals(&[U_X, U_Y], &u), OK);
        assert_eq!(coarse.step(t, 0.01), OK);
        for j in 0..10 {
            assert_eq!(fine.step(t + j as f64 * 0.001, 0.001), OK);
        }
        t += 0.01;
        let (_, a) = coarse.get_reals(&[POS_X, POS_Y, VEL_X]);
        let (_, b) = fine.get_reals(&[POS_X, POS_Y, VEL_X]);
        for (x, y) in a.iter().zip(&b) {
            assert!((x - y).abs() <= 1e-12 * x.abs().max(1.0), "{a:?} vs {b:?}");
        }
    }
}
