//! NaN and infinities: on every Real input and parameter of every model (a test of its own,
//! one case a variable and value, made as it runs), in a call of several values (nothing is
//! stored), and as the times of fmi3EnterInitializationMode and fmi3DoStep.

use std::panic::{catch_unwind, AssertUnwindSafe};

use super::*;
use contour_fmu::framework::variables::{Causality, Variability};

pub(super) static CASES: &[Case<Fmi3>] = &[
    case(
        "NaN among good values on Real inputs (nothing is stored)",
        C5,
        Stepping,
        |s| s.set_float64(&s.vrs(&["ref.X", "ref.Y", "pos.A"]), &[1.0, 2.0, f64::NAN]),
        ERROR3,
        Some("fmi3SetFloat64: variable 'pos.A' refuses the non-finite value NaN"),
        Usable,
    ),
    case(
        "+Inf among good values on Real parameters (nothing is stored)",
        P2,
        Initialization,
        |s| s.set_float64(&s.vrs(&["feed", "Ts", "rapid"]), &[10.0, f64::INFINITY, 50.0]),
        ERROR3,
        Some("fmi3SetFloat64: variable 'Ts' refuses the non-finite value inf"),
        Usable,
    ),
    case(
        "NaN with the bits of a signalling NaN",
        XY,
        Stepping,
        |s| s.set_float64(&[s.vr("u.y")], &[f64::from_bits(0x7ff0_0000_0000_0001)]),
        ERROR3,
        Some("fmi3SetFloat64: variable 'u.y' refuses the non-finite value NaN"),
        Usable,
    ),
    case(
        "NaN as the communication step size",
        XY,
        Stepping,
        |s| s.step_reporting(s.time, f64::NAN, s.time),
        ERROR3,
        Some("fmi3DoStep: communication step size must be finite and > 0 (got NaN)"),
        Usable,
    ),
    case(
        "+Inf as the communication step size",
        P2,
        Stepping,
        |s| s.step_reporting(s.time, f64::INFINITY, s.time),
        ERROR3,
        Some("fmi3DoStep: communication step size must be finite and > 0 (got inf)"),
        Usable,
    ),
    case(
        "a communication step of 1e300 s (a sampled model would never return)",
        C2,
        Stepping,
        |s| s.step_reporting(s.time, 1e300, s.time),
        ERROR3,
        Some("fmi3DoStep: communication step size 1e300 s refused: it would take 1e303 samples of Ts = 0.001 s"),
        Usable,
    ),
    case(
        "a communication step of 1e5 s (1e8 samples)",
        P5,
        Stepping,
        |s| s.step_reporting(s.time, 1e5, s.time),
        ERROR3,
        Some("fmi3DoStep: communication step size 1e5 s refused: it would take"),
        Usable,
    ),
    case(
        "NaN as the communication point",
        C5,
        Stepping,
        |s| s.step_reporting(f64::NAN, H, s.time),
        ERROR3,
        Some("fmi3DoStep: communication point NaN does not match the instance time"),
        Usable,
    ),
    case(
        "-Inf as the communication point",
        F5,
        Stepping,
        |s| s.step_reporting(f64::NEG_INFINITY, H, s.time),
        ERROR3,
        Some("fmi3DoStep: communication point -inf does not match the instance time"),
        Usable,
    ),
    case(
        "NaN as the start time",
        XY,
        Instantiated,
        |s| s.enter_init(f64::NAN, None),
        ERROR3,
        Some("fmi3EnterInitializationMode: start time NaN is not finite"),
        Usable,
    ),
    case(
        "-Inf as the start time",
        SD,
        Instantiated,
        |s| s.enter_init(f64::NEG_INFINITY, Some(1.0)),
        ERROR3,
        Some("fmi3EnterInitializationMode: start time -inf is not finite"),
        Usable,
    ),
    case(
        "+Inf as the stop time",
        P2,
        Instantiated,
        |s| s.enter_init(0.0, Some(f64::INFINITY)),
        ERROR3,
        Some("fmi3EnterInitializationMode: stop time inf must be finite"),
        Usable,
    ),
    case(
        "NaN as the stop time",
        C2,
        Instantiated,
        |s| s.enter_init(0.0, Some(f64::NAN)),
        ERROR3,
        Some("fmi3EnterInitializationMode: stop time NaN must be finite"),
        Usable,
    ),
];

/// The values every Real input and parameter refuses, as the log names them.
const NON_FINITE: [(f64, &str); 3] = [
    (f64::NAN, "NaN"),
    (f64::INFINITY, "inf"),
    (f64::NEG_INFINITY, "-inf"),
];

/// NaN, +Inf and -Inf through fmi3SetFloat64 on every Real input and parameter of every
/// model, in initialization mode; NaN also while stepping on every input and tunable
/// parameter. Each one a case of the catalogue: fmi3Error, the log line naming the
/// variable, nothing stored (equal to a twin, bit for bit), and the recovery.
#[test]
fn nan_and_infinities_on_every_real_input_and_parameter() {
    let models = models::all().into_iter().chain([PROBE]);
    let mut failed = Vec::new();
    let mut total = 0;
    for model in models {
        let settable = model
            .variables
            .iter()
            .filter(|v| v.var_type() == VarType::Real && v.causality != Causality::Output);
        for v in settable {
            let stepping = v.causality == Causality::Input || v.variability == Variability::Tunable;
            let mut setups = vec![(Initialization, NON_FINITE.as_slice())];
            if stepping {
                setups.push((Stepping, &NON_FINITE[..1]));
            }
            for (setup, values) in setups {
                for &(value, text) in values {
                    total += 1;
                    let name = "a non-finite value";
                    let shape = case(name, model, setup, |_| ERROR3, ERROR3, None, Usable);
                    let log = format!(
                        "fmi3SetFloat64: variable '{}' refuses the non-finite value {text}",
                        v.name
                    );
                    let set = |s: &mut Subject<Fmi3>| Fmi3::set(s.c(), v, Value::Real(value));
                    let outcome = catch_unwind(AssertUnwindSafe(|| check(&shape, set, Some(&log))));
                    if let Some(problem) = problem(outcome) {
                        failed.push(format!(
                            "- {text} on '{}' ({}, {setup:?}): {problem}",
                            v.name, model.identifier
                        ));
                    }
                }
            }
        }
    }
    assert!(total > 300, "{total}");
    assert_none_failed(&failed, total);
}
