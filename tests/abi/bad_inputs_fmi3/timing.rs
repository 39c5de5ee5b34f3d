//! Bad step times (what fmi3DoStep reports when it refuses one), parameters set while
//! stepping, failing and panicking models (FaultProbe): Error mode, then Fatal with only
//! fmi3FreeInstance and fmi3FreeFMUState accepted.

use super::*;

pub(super) static CASES: &[Case<Fmi3>] = &[
    case(
        "a zero communication step size",
        C2,
        Stepping,
        |s| s.step_reporting(s.time, 0.0, s.time),
        ERROR3,
        Some("fmi3DoStep: communication step size must be finite and > 0 (got 0)"),
        Usable,
    ),
    case(
        "a negative communication step size",
        F5,
        Stepping,
        |s| s.step_reporting(s.time, -H, s.time),
        ERROR3,
        Some("fmi3DoStep: communication step size must be finite and > 0 (got -0.001)"),
        Usable,
    ),
    case(
        "a negative zero communication step size",
        SR,
        Stepping,
        |s| s.step_reporting(s.time, -0.0, s.time),
        ERROR3,
        Some("fmi3DoStep: communication step size must be finite and > 0 (got -0)"),
        Usable,
    ),
    case(
        "a communication point behind the instance time",
        XY,
        Stepping,
        |s| s.step_reporting(0.0, H, s.time),
        ERROR3,
        Some("fmi3DoStep: communication point 0 does not match the instance time 0.003"),
        Usable,
    ),
    case(
        "a communication point ahead of the instance time",
        P2,
        Stepping,
        |s| s.step_reporting(s.time + H, H, s.time),
        ERROR3,
        Some("fmi3DoStep: communication point 0.004 does not match the instance time 0.003"),
        Usable,
    ),
    case(
        "a negative communication point",
        PROBE,
        Stepping,
        |s| s.step_reporting(-s.time, H, s.time),
        ERROR3,
        Some("fmi3DoStep: communication point -0.003 does not match the instance time 0.003"),
        Usable,
    ),
    case(
        "a stop time before the start time",
        C2,
        Instantiated,
        |s| s.enter_init(1.0, Some(0.5)),
        ERROR3,
        Some("fmi3EnterInitializationMode: stop time 0.5 must be finite and not before the start time 1"),
        Usable,
    ),
    case(
        "a tunable parameter the model refuses while stepping",
        PROBE,
        Stepping,
        |s| s.set_float64(&[s.vr("gain")], &[12.0]),
        ERROR3,
        Some("fmi3SetFloat64: parameter 'gain' must be < 10 (got 12)"),
        Usable,
    ),
    case(
        "a tunable parameter below its minimum while stepping",
        PROBE,
        Stepping,
        |s| s.set_float64(&[s.vr("gain")], &[-1.0]),
        ERROR3,
        Some("fmi3SetFloat64: variable 'gain' = -1 is below its minimum 0"),
        Usable,
    ),
    case(
        "a fixed parameter set while stepping",
        XY,
        Stepping,
        |s| s.set_float64(&[s.vr("y.J")], &[0.02]),
        ERROR3,
        Some("fmi3SetFloat64: parameter 'y.J' is fixed: set it before fmi3ExitInitializationMode"),
        Usable,
    ),
    case(
        "a fixed String parameter set while stepping",
        P5,
        Stepping,
        |s| s.set_string("path", "figure_eight"),
        ERROR3,
        Some("fmi3SetString: parameter 'path' is fixed: set it before fmi3ExitInitializationMode"),
        Usable,
    ),
    case(
        "a failing model step (FaultProbe)",
        PROBE,
        Stepping,
        |s| s.step_failing("fail"),
        ERROR3,
        Some("fmi3DoStep: step at t = 0.003 failed: FaultProbe: injected failure"),
        ResetRequired,
    ),
    case(
        "a panicking model step (FaultProbe)",
        PROBE,
        Stepping,
        |s| s.step_failing("panic"),
        FATAL3,
        Some("fmi3DoStep: internal error (panic): FaultProbe: injected panic"),
        FreeOnly,
    ),
    case(
        "fmi3FreeFMUState after a fatal error (accepted, to release what the importer holds)",
        PROBE,
        Fatal,
        |s| {
            let status = Fmi3::free_state(s.c(), &mut s.saved);
            assert!(s.saved.is_null(), "the variable was set to NULL");
            status
        },
        OK3,
        None,
        FreeOnly,
    ),
];

/// A stop time given to fmi3EnterInitializationMode: steps up to it are taken, one past it
/// is refused (the instance stays where it was), lastSuccessfulTime follows.
#[test]
fn a_step_past_the_fmi3_stop_time_is_refused() {
    let mut s = Subject::<Fmi3>::create(XY, Instantiated, Resources::Null, "stop");
    s.ok(s.enter_init(0.0, Some(2.0 * H)));
    s.ok(s.call(Fmi3Binding::fmi3ExitInitializationMode));
    s.ok(s.step_reporting(0.0, H, H));
    s.ok(s.step_reporting(H, H, 2.0 * H));
    assert_eq!(s.step_reporting(2.0 * H, H, 2.0 * H), ERROR3);
    assert!(
        s.last_error()
            .contains("fmi3DoStep: step to t = 0.003 would pass the stop time 0.002"),
        "{}",
        s.last_error()
    );
    s.free();
}

/// Far from t = 0 a step can vanish in rounding: refused (a sampled model would wait for
/// ever for its next sample), the instance as it was.
#[test]
fn an_fmi3_step_lost_in_the_rounding_of_the_time_is_refused() {
    let s = Subject::<Fmi3>::create(P2, Instantiated, Resources::Null, "far");
    s.ok(s.enter_init(1e300, None));
    s.ok(s.call(Fmi3Binding::fmi3ExitInitializationMode));
    assert_eq!(s.step_reporting(1e300, 1e-3, 1e300), ERROR3);
    assert!(
        s.last_error()
            .contains("fmi3DoStep: communication step size 1e-3 s is lost in the rounding of the time 1e300 s"),
        "{}",
        s.last_error()
    );
}
