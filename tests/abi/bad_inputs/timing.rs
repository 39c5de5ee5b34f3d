//! Other bad times, parameters set while stepping, failing models.

use super::*;

pub(super) static CASES: &[Case] = &[
    case(
        "a zero communication step size",
        C2,
        Stepping,
        |s| s.i().step(s.time, 0.0),
        ERROR,
        Some("fmi2DoStep: communication step size must be finite and > 0 (got 0)"),
        Usable,
    ),
    case(
        "a negative communication step size",
        F5,
        Stepping,
        |s| s.i().step(s.time, -H),
        ERROR,
        Some("fmi2DoStep: communication step size must be finite and > 0 (got -0.001)"),
        Usable,
    ),
    case(
        "a communication point behind the instance time",
        XY,
        Stepping,
        |s| s.i().step(0.0, H),
        ERROR,
        Some("fmi2DoStep: communication point 0 does not match the instance time"),
        Usable,
    ),
    case(
        "a stop time before the start time",
        C2,
        Instantiated,
        |s| s.i().setup(1.0, Some(0.5)),
        ERROR,
        Some("fmi2SetupExperiment: stop time 0.5 must be finite and not before the start time 1"),
        Usable,
    ),
    case(
        "a tunable parameter the model refuses while stepping",
        PROBE,
        Stepping,
        |s| s.set_real("gain", 12.0),
        ERROR,
        Some("fmi2SetReal: parameter 'gain' must be < 10 (got 12)"),
        Usable,
    ),
    case(
        "a fixed parameter set while stepping",
        XY,
        Stepping,
        |s| s.set_real("x.J", 0.02),
        ERROR,
        Some("fmi2SetReal: parameter 'x.J' is fixed"),
        Usable,
    ),
    case(
        "a failing model step (FaultProbe)",
        PROBE,
        Stepping,
        |s| {
            let status = s.set_boolean("fail", true);
            s.ok(status);
            s.i().step(s.time, H)
        },
        ERROR,
        Some("fmi2DoStep: step at t = 0.003 failed: FaultProbe: injected failure"),
        ResetRequired,
    ),
    case(
        "a panicking model step (FaultProbe)",
        PROBE,
        Stepping,
        |s| {
            let status = s.set_boolean("panic", true);
            s.ok(status);
            s.i().step(s.time, H)
        },
        FATAL,
        Some("fmi2DoStep: internal error (panic): FaultProbe: injected panic"),
        FreeOnly,
    ),
];
