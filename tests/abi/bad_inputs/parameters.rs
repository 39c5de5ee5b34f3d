//! Absurd parameters: refused when set, when initialization ends (within their bounds but
//! not physical), or when the first step overflows.

use super::*;

pub(super) static CASES: &[Case] = &[
    case(
        "a zero effort limit (servo drive)",
        SD,
        Initialization,
        |s| s.exit_with(|s| s.set_real("effortMax", 0.0)),
        ERROR,
        Some("fmi2ExitInitializationMode: effortMax must be finite and > 0 (got 0)"),
        Corrected,
    ),
    case(
        "a negative integral gain (rotary servo drive)",
        SR,
        Initialization,
        |s| s.set_real("Kvi", -1.0),
        ERROR,
        Some("fmi2SetReal: variable 'Kvi' = -1 is below its minimum 0"),
        Usable,
    ),
    case(
        "stiction below the Coulomb friction (XY plant)",
        XY,
        Initialization,
        |s| {
            s.exit_with(|s| {
                let status = s.set_real("y.coulomb", 0.2);
                s.ok(status);
                s.set_real("y.stiction", 0.1)
            })
        },
        ERROR,
        Some(
            "fmi2ExitInitializationMode: axis y: stiction (0.1) must be 0 or at least coulomb \
             (0.2)",
        ),
        Corrected,
    ),
    case(
        "a negative backlash (five-axis plant)",
        F5,
        Initialization,
        |s| s.set_real("A.backlash", -1e-4),
        ERROR,
        Some("fmi2SetReal: variable 'A.backlash' = -0.0001 is below its minimum 0"),
        Usable,
    ),
    case(
        "Ts = 0 (controller)",
        C2,
        Initialization,
        |s| s.exit_with(|s| s.set_real("Ts", 0.0)),
        ERROR,
        Some("fmi2ExitInitializationMode: parameter 'Ts' must be at least 1e-6 s (got 0)"),
        Corrected,
    ),
    case(
        "Ts < 0 (five-axis controller)",
        C5,
        Initialization,
        |s| s.exit_with(|s| s.set_real("Ts", -1e-3)),
        ERROR,
        Some("fmi2ExitInitializationMode: parameter 'Ts' must be at least 1e-6 s (got -0.001)"),
        Corrected,
    ),
    case(
        "Ts of 1 ns (five-axis interpolator)",
        P5,
        Initialization,
        |s| s.exit_with(|s| s.set_real("Ts", 1e-9)),
        ERROR,
        Some("fmi2ExitInitializationMode: parameter 'Ts' must be at least 1e-6 s"),
        Corrected,
    ),
    case(
        "a negative feed",
        P2,
        Initialization,
        |s| s.exit_with(|s| s.set_real("feed", -5.0)),
        ERROR,
        Some("fmi2ExitInitializationMode: parameter 'feed' must be > 0 (got -5)"),
        Corrected,
    ),
    case(
        "a zero feed (five-axis)",
        P5,
        Initialization,
        |s| s.exit_with(|s| s.set_real("feed", 0.0)),
        ERROR,
        Some("fmi2ExitInitializationMode: parameter 'feed' must be > 0 (got 0)"),
        Corrected,
    ),
    case(
        "a zero tolerance with a jerk limit (five-axis interpolator)",
        P5,
        Initialization,
        |s| s.exit_with(|s| s.set_real("tolerance", 0.0)),
        ERROR,
        Some("fmi2ExitInitializationMode: plan: tolerance must be > 0 with a jerk limit"),
        Corrected,
    ),
    case(
        "an empty A travel (five-axis interpolator)",
        P5,
        Initialization,
        |s| s.exit_with(|s| s.set_real("A.max", -1.0)),
        ERROR,
        Some("fmi2ExitInitializationMode: machine limits: the travel of A, [-0.6108652381980153, -1], must be finite and not empty"),
        Corrected,
    ),
    case(
        "a zero C speed (five-axis interpolator)",
        P5,
        Initialization,
        |s| s.exit_with(|s| s.set_real("C.vmax", 0.0)),
        ERROR,
        Some("fmi2ExitInitializationMode: machine limits: C.vmax must be finite and > 0 (got 0)"),
        Corrected,
    ),
    case(
        "a negative jerk (five-axis interpolator)",
        P5,
        Initialization,
        |s| s.set_real("jerk", -1.0),
        ERROR,
        Some("fmi2SetReal: variable 'jerk' = -1 is below its minimum 0"),
        Usable,
    ),
    case(
        "a line of zero length",
        P2,
        Initialization,
        |s| {
            s.exit_with(|s| {
                let status = s.set_string("path", "line");
                s.ok(status);
                s.i().set_reals(&[s.vr("line.x1"), s.vr("line.y1")], &[0.0, 0.0])
            })
        },
        ERROR,
        Some("fmi2ExitInitializationMode: parameters 'line.*'"),
        Corrected,
    ),
    case(
        "an arc of negative radius",
        P2,
        Initialization,
        |s| {
            s.exit_with(|s| {
                let status = s.set_string("path", "arc");
                s.ok(status);
                s.set_real("arc.r", -3.0)
            })
        },
        ERROR,
        Some("fmi2ExitInitializationMode: parameters 'arc.*': invalid path: arc radius"),
        Corrected,
    ),
    case(
        "an arc estimator of zero radius",
        C2,
        Initialization,
        |s| {
            s.exit_with(|s| {
                let status = s.set_integer("estimator", 3);
                s.ok(status);
                s.set_real("arc.r", 0.0)
            })
        },
        ERROR,
        Some("fmi2ExitInitializationMode: parameters 'arc.*': invalid path: arc radius"),
        Corrected,
    ),
    case(
        "a zero contour correction limit",
        C2,
        Initialization,
        |s| s.exit_with(|s| s.set_real("ccc.limit", 0.0)),
        ERROR,
        Some("fmi2ExitInitializationMode: parameter ccc.limit = 0 is invalid"),
        Corrected,
    ),
    case(
        "a negative position-loop gain",
        C2,
        Initialization,
        |s| s.set_real("axis.y.Ki", -1.0),
        ERROR,
        Some("fmi2SetReal: variable 'axis.y.Ki' = -1 is below its minimum 0"),
        Usable,
    ),
    case(
        "a negative damping of the Jacobian inverse",
        C5,
        Initialization,
        |s| s.exit_with(|s| s.set_real("damping", -1.0)),
        ERROR,
        Some("fmi2ExitInitializationMode: parameter damping = -1 is invalid"),
        Corrected,
    ),
    case(
        "a zero correction share (five-axis controller)",
        C5,
        Initialization,
        |s| s.exit_with(|s| s.set_real("correctionShare", 0.0)),
        ERROR,
        Some("fmi2ExitInitializationMode: parameter correctionShare = 0 is invalid: must be in (0, 1]"),
        Corrected,
    ),
    case(
        "a pole cone of the controller at 90 degrees",
        C5,
        Initialization,
        |s| s.exit_with(|s| s.set_real("poleCone", std::f64::consts::FRAC_PI_2)),
        ERROR,
        Some("fmi2ExitInitializationMode: parameter poleCone = 1.5707963267948966 is invalid"),
        Corrected,
    ),
    case(
        "a controller's C speed of zero",
        C5,
        Initialization,
        |s| s.exit_with(|s| s.set_real("C.vmax", 0.0)),
        ERROR,
        Some("fmi2ExitInitializationMode: machine limits: C.vmax must be finite and > 0"),
        Corrected,
    ),
    case(
        "a controller's A travel that is empty",
        C5,
        Initialization,
        |s| s.exit_with(|s| s.set_real("A.max", -1.0)),
        ERROR,
        Some("fmi2ExitInitializationMode: machine limits: the travel of A"),
        Corrected,
    ),
    case(
        "a zero tool length",
        C5,
        Initialization,
        |s| s.exit_with(|s| s.set_real("toolLength", 0.0)),
        ERROR,
        Some("fmi2ExitInitializationMode: parameter toolLength = 0 is invalid"),
        Corrected,
    ),
    case(
        "a negative tool length",
        C5,
        Initialization,
        |s| s.exit_with(|s| s.set_real("toolLength", -150.0)),
        ERROR,
        Some("fmi2ExitInitializationMode: parameter toolLength = -150 is invalid"),
        Corrected,
    ),
    case(
        "a zero mapping beam",
        C5,
        Initialization,
        |s| s.exit_with(|s| s.set_real("hmm.beam", 0.0)),
        ERROR,
        Some("fmi2ExitInitializationMode: parameter hmm.beam = 0 is invalid"),
        Corrected,
    ),
    case(
        "a zero inertia",
        XY,
        Initialization,
        |s| s.exit_with(|s| s.set_real("x.J", 0.0)),
        ERROR,
        Some("fmi2ExitInitializationMode: parameter 'x.J' must be > 0 (got 0)"),
        Corrected,
    ),
    case(
        "a negative viscous friction (damping)",
        XY,
        Initialization,
        |s| s.set_real("y.B", -1.0),
        ERROR,
        Some("fmi2SetReal: variable 'y.B' = -1 is below its minimum 0"),
        Usable,
    ),
    case(
        "a zero gear ratio",
        F5,
        Initialization,
        |s| s.exit_with(|s| s.set_real("A.ratio", 0.0)),
        ERROR,
        Some("fmi2ExitInitializationMode: parameter 'A.ratio' must be > 0 (got 0)"),
        Corrected,
    ),
    case(
        "a zero ball-screw lead",
        F5,
        Initialization,
        |s| s.exit_with(|s| s.set_real("Z.lead", 0.0)),
        ERROR,
        Some("fmi2ExitInitializationMode: parameter 'Z.lead' must be > 0 (got 0)"),
        Corrected,
    ),
    case(
        "an inertia of 1e-300 (the plant overflows in its first step)",
        XY,
        Initialization,
        |s| {
            let status = s.exit_with(|s| s.set_real("x.J", 1e-300));
            s.ok(status);
            s.i().step(0.0, H)
        },
        ERROR,
        Some("fmi2DoStep: step at t = 0 failed: output 'pos.x' = NaN is not finite"),
        ResetRequired,
    ),
    case(
        "a velocity-loop gain of 1e300 (the plant overflows in its first step)",
        F5,
        Initialization,
        |s| {
            let status = s.exit_with(|s| s.set_real("X.Kvp", 1e300));
            s.ok(status);
            s.i().step(0.0, H)
        },
        ERROR,
        Some("fmi2DoStep: step at t = 0 failed: output 'pos.X' = NaN is not finite"),
        ResetRequired,
    ),
    case(
        "an unknown built-in path",
        P2,
        Initialization,
        |s| s.exit_with(|s| s.set_string("path", "spiral")),
        ERROR,
        Some("fmi2ExitInitializationMode: parameter 'path': unknown path 'spiral'"),
        Corrected,
    ),
    case(
        "an unknown five-axis built-in path",
        P5,
        Initialization,
        |s| s.exit_with(|s| s.set_string("path", "spiral")),
        ERROR,
        Some("fmi2ExitInitializationMode: parameter 'path': invalid path: unknown five-axis path \"spiral\""),
        Corrected,
    ),
];
