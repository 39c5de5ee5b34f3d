//! The FMI 2.0 state machine: every instance function in every mode, as the standard
//! allows or refuses it, and the status functions.

use crate::common::*;
use contour_fmu::models::{fault_probe as probe, xy_servo_plant as plant};

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
