//! ContourCCC2D and PathInterpolator2D through the C ABI of the built library, as an
//! importer drives them: multi-rate stepping against the in-process computation, FMU
//! state save/restore (in place, serialized into a fresh instance, and fmusim's
//! `--initial-fmu-state-file` sequence), and bad parameters.

use contour_core::math;
use std::collections::BTreeMap;

use crate::common::*;
use contour_core::contour::planar::{Estimator, FreeCurveEstimator};
use contour_core::control::{ControllerConfig, CrossCoupledController};
use contour_core::geometry::Vector2;
use contour_core::path::planar::builtin;
use contour_core::path::Interpolator;
use contour_fmu::framework::model::ModelInfo;
use contour_fmu::framework::variables::Start;
use contour_fmu::models::{
    contour_ccc_2d as ccc, line_arc_parameters as geometry, path_interpolator_2d as interp,
};

const INPUTS: [u32; 4] = [
    ccc::REF.at(0).vr() as u32,
    ccc::REF.at(1).vr() as u32,
    ccc::POS.at(0).vr() as u32,
    ccc::POS.at(1).vr() as u32,
];
/// u.x, u.y, contourError, err.x, err.y, ccc.Kp, ccc.Ki, ccc.Kd.
const OUTPUTS: [u32; 8] = [
    ccc::U.at(0).vr() as u32,
    ccc::U.at(1).vr() as u32,
    ccc::CONTOUR_ERROR.vr() as u32,
    ccc::ERR.at(0).vr() as u32,
    ccc::ERR.at(1).vr() as u32,
    ccc::CCC_GAINS.at(0).vr() as u32,
    ccc::CCC_GAINS.at(1).vr() as u32,
    ccc::CCC_GAINS.at(2).vr() as u32,
];
const REF: [u32; 2] = [interp::REF.at(0).vr() as u32, interp::REF.at(1).vr() as u32];

/// Piecewise-constant inputs, changing every 5 ms (a communication point of every step
/// size used here): a circle and a point lagging inside it.
fn held_inputs(t: f64) -> [f64; 4] {
    let k = (t / 0.005 + 1e-9).floor();
    let a = 0.05 * k;
    [
        10.0 * math::cos(a) - 10.0,
        10.0 * math::sin(a),
        9.98 * math::cos(a - 0.01) - 10.0,
        9.98 * math::sin(a - 0.01),
    ]
}

/// Communication points as whole microseconds, to match points of different step sizes.
fn micros(t: f64) -> u64 {
    (t * 1e6).round() as u64
}

fn controller_outputs(i: &Instance) -> Vec<f64> {
    let (s, v) = i.get_reals(&OUTPUTS);
    assert_eq!(s, OK, "{}", i.last_error());
    v
}

/// Steps the controller from step `from` to `to` (step size `h`, inputs held per step);
/// the outputs at every reached communication point.
fn drive_controller(i: &Instance, h: f64, from: usize, to: usize) -> BTreeMap<u64, Vec<f64>> {
    (from..to)
        .map(|k| {
            let t = k as f64 * h;
            assert_eq!(i.set_reals(&INPUTS, &held_inputs(t)), OK);
            assert_eq!(i.step(t, h), OK, "{}", i.last_error());
            (micros((k + 1) as f64 * h), controller_outputs(i))
        })
        .collect()
}

/// The same controller in process: one sample every Ts = 1 ms on the held inputs; entry
/// n is the output after sample n, which the FMU shows from t = (n + 1) ms on.
fn controller_reference(samples: usize) -> Vec<Vec<f64>> {
    let mut controller = CrossCoupledController::new(
        ControllerConfig::default(),
        Estimator::FreeCurve(FreeCurveEstimator::default()),
    )
    .unwrap();
    (0..samples)
        .map(|n| {
            let x = held_inputs(n as f64 * 1e-3);
            let out = controller.sample(Vector2::new(x[0], x[1]), Vector2::new(x[2], x[3]));
            vec![
                out.u[0],
                out.u[1],
                out.contour.error,
                out.following_error[0],
                out.following_error[1],
                out.gains.0,
                out.gains.1,
                out.gains.2,
            ]
        })
        .collect()
}

/// Asserts that the coarser runs equal the finest (`runs[0]`) wherever their output
/// times coincide (bit for bit); returns how many points were compared.
fn compare_at_shared_points<T: PartialEq + std::fmt::Debug>(runs: &[BTreeMap<u64, T>]) -> usize {
    let mut shared = 0;
    for run in &runs[1..] {
        for (t, out) in run {
            if let Some(fine) = runs[0].get(t) {
                assert_eq!(out, fine, "t = {t} us");
                shared += 1;
            }
        }
    }
    shared
}

#[test]
fn controller_outputs_do_not_depend_on_the_communication_step_and_match_the_library() {
    let stop = 0.1;
    let runs: Vec<BTreeMap<u64, Vec<f64>>> = [0.001, 0.0025, 0.005]
        .iter()
        .map(|&h| {
            let i = Instance::new(&ccc::INFO);
            i.start();
            drive_controller(&i, h, 0, (stop / h).round() as usize)
        })
        .collect();
    let reference = controller_reference(100);
    // Every 1 ms point is the in-process sample before it, bit for bit.
    assert_eq!(runs[0].len(), 100);
    for (&t, out) in &runs[0] {
        let n = (t / 1000) as usize;
        assert_eq!(out, &reference[n - 1], "t = {t} us");
    }
    // The 2.5 and 5 ms runs give the same values at their points (5 ms apart in common).
    let shared = compare_at_shared_points(&runs);
    assert_eq!(shared, 20 + 20);
    // The controller really acted: a velocity command and a fuzzy-adapted Kp.
    let last = &reference[99];
    assert!(last[0].abs() > 1.0, "{last:?}");
    assert!(last[5] > 0.0 && last[5] != 100.0, "{last:?}");
}

fn start_interpolator(path: &str, feed: f64) -> Instance {
    let i = Instance::new(&interp::INFO);
    assert_eq!(i.setup(0.0, None), OK);
    assert_eq!(i.enter_init(), OK);
    assert_eq!(i.set_string(interp::PATH.vr() as u32, path), OK);
    assert_eq!(i.set_reals(&[interp::FEED.vr() as u32], &[feed]), OK);
    assert_eq!(i.exit_init(), OK, "{}", i.last_error());
    i
}

fn interpolator_outputs(i: &Instance) -> (f64, f64, bool) {
    let (s, v) = i.get_reals(&REF);
    assert_eq!(s, OK);
    let (s, done) = i.get_boolean(interp::DONE.vr() as u32);
    assert_eq!(s, OK);
    (v[0], v[1], done)
}

fn drive_interpolator(
    i: &Instance,
    h: f64,
    from: usize,
    to: usize,
) -> BTreeMap<u64, (f64, f64, bool)> {
    (from..to)
        .map(|k| {
            assert_eq!(i.step(k as f64 * h, h), OK, "{}", i.last_error());
            (micros((k + 1) as f64 * h), interpolator_outputs(i))
        })
        .collect()
}

#[test]
fn interpolator_outputs_do_not_depend_on_the_communication_step_and_match_the_library() {
    let stop = 0.2;
    let runs: Vec<BTreeMap<u64, (f64, f64, bool)>> = [0.001, 0.0025, 0.005]
        .iter()
        .map(|&h| {
            let i = start_interpolator("trident", 40.0);
            drive_interpolator(&i, h, 0, (stop / h).round() as usize)
        })
        .collect();
    // In process: one sample every 1 ms; the output at t is the latest sample.
    let mut reference =
        Interpolator::new(builtin::by_name("trident").unwrap(), 40.0, 1e-3).unwrap();
    for (&t, &out) in &runs[0] {
        let sample = reference.step();
        assert_eq!(
            out,
            (sample.point[0], sample.point[1], sample.done),
            "t = {t} us"
        );
    }
    let shared = compare_at_shared_points(&runs);
    assert_eq!(shared, 40 + 40);
    // 0.2 s at 40 mm/s: 8 mm along the path from the start point (40.2, -0.1).
    let (x, y, done) = runs[0][&200_000];
    let travelled = math::hypot(x - 40.2, y + 0.1);
    assert!(travelled > 6.0 && travelled <= 8.0 + 1e-9, "{travelled}");
    assert!(!done);
}

// ---------------------------------------------------------------------------------------
// FMU state

#[test]
fn controller_state_restores_the_estimator_and_pid_memories_bit_for_bit() {
    let h = 0.001;
    let i = Instance::new(&ccc::INFO);
    i.start();
    drive_controller(&i, h, 0, 40);
    let (s, mut state) = i.get_state();
    assert_eq!(s, OK);
    let at_save = controller_outputs(&i);
    let expected = drive_controller(&i, h, 40, 90);
    // The continuation is the in-process computation (not just self-consistent).
    let reference = controller_reference(90);
    for (&t, out) in &expected {
        assert_eq!(out, &reference[(t / 1000) as usize - 1]);
    }

    // In place.
    assert_eq!(i.set_state(state), OK);
    assert_eq!(controller_outputs(&i), at_save);
    assert_eq!(drive_controller(&i, h, 40, 90), expected);

    // Serialized, then deserialized into a freshly instantiated instance (no setup, no
    // initialization) and continued there.
    let (s, bytes) = i.serialize(state);
    assert_eq!(s, OK);
    let fresh = Instance::new(&ccc::INFO);
    let (s, mut restored) = fresh.deserialize(&bytes);
    assert_eq!(s, OK, "{}", fresh.last_error());
    assert_eq!(fresh.set_state(restored), OK, "{}", fresh.last_error());
    assert_eq!(controller_outputs(&fresh), at_save);
    assert_eq!(drive_controller(&fresh, h, 40, 90), expected);

    // Also with other step sizes after the restore: the samples fall where they fell.
    assert_eq!(fresh.set_state(restored), OK);
    let coarse = drive_controller(&fresh, 0.005, 8, 18);
    for (t, out) in &coarse {
        assert_eq!(out, &expected[t], "t = {t} us");
    }

    assert_eq!(i.free_state(&mut state), OK);
    assert_eq!(fresh.free_state(&mut restored), OK);
}

#[test]
fn interpolator_state_restores_bit_for_bit_in_place_and_in_a_fresh_instance() {
    let h = 0.001;
    let i = start_interpolator("infinity", 50.0);
    drive_interpolator(&i, h, 0, 300);
    let (s, mut state) = i.get_state();
    assert_eq!(s, OK);
    let expected = drive_interpolator(&i, h, 300, 700);
    assert_eq!(i.set_state(state), OK);
    assert_eq!(drive_interpolator(&i, h, 300, 700), expected);

    let (_, bytes) = i.serialize(state);
    let fresh = Instance::new(&interp::INFO);
    let (s, mut restored) = fresh.deserialize(&bytes);
    assert_eq!(s, OK, "{}", fresh.last_error());
    assert_eq!(fresh.set_state(restored), OK);
    assert_eq!(drive_interpolator(&fresh, h, 300, 700), expected);
    // The restored instance carries the path: it is the infinity, not the start value's
    // circle.
    let (s, path) = {
        let (s, _, text) = fresh.get_string(interp::PATH.vr() as u32);
        (s, text)
    };
    assert_eq!((s, path.as_str()), (OK, "infinity"));

    assert_eq!(i.free_state(&mut state), OK);
    assert_eq!(fresh.free_state(&mut restored), OK);
}

/// Reference FMUs' fmusim, `--initial-fmu-state-file`: fmi2Instantiate, then
/// fmi2DeSerializeFMUstate, fmi2SetFMUstate, fmi2FreeFMUstate (v0.0.39 passes the state
/// instead of its address), then fmi2DoStep from the saved time without fmi2SetupExperiment
/// or initialization.
#[test]
fn fmusim_initial_state_file_sequence_continues_bit_for_bit() {
    let h = 0.001;
    let saver = Instance::new(&ccc::INFO);
    saver.start();
    fmusim_sequence(&ccc::INFO, saver, 25, 60, |i, from, to| {
        drive_controller(i, h, from, to)
    });
    let saver = start_interpolator("trident", 45.0);
    fmusim_sequence(&interp::INFO, saver, 120, 400, |i, from, to| {
        drive_interpolator(i, h, from, to)
    });
}

/// `saver`, initialised, is driven to sample `saved`, its state serialized (the file) and
/// then driven on to `end`; a fresh instance of `info` that deserializes and sets the file
/// (and frees the state fmusim's way) must produce the same samples from `saved` on.
fn fmusim_sequence<T: PartialEq + std::fmt::Debug>(
    info: &'static ModelInfo,
    saver: Instance,
    saved: usize,
    end: usize,
    drive: impl Fn(&Instance, usize, usize) -> T,
) {
    drive(&saver, 0, saved);
    let (_, mut state) = saver.get_state();
    let (_, file) = saver.serialize(state);
    let expected = drive(&saver, saved, end);

    let fmusim = Instance::new(info);
    let (s, restored) = fmusim.deserialize(&file);
    assert_eq!(s, OK);
    assert_eq!(fmusim.set_state(restored), OK);
    assert_eq!(fmusim.free_state_raw(restored as *mut fmi2FMUstate), OK);
    assert_eq!(drive(&fmusim, saved, end), expected);
    // The misused handle was freed: any later use is refused, not read.
    assert_eq!(fmusim.set_state(restored), ERROR);
    assert!(fmusim.last_error().contains("is not a live FMU state"));
    assert_eq!(saver.free_state(&mut state), OK);
}

// ---------------------------------------------------------------------------------------
// Bad parameters

fn real_start(vr: usize, table: &contour_fmu::framework::model::ModelInfo) -> f64 {
    match table.variables[vr].start {
        Start::Real(x) => x,
        other => panic!("{other:?}"),
    }
}

#[test]
fn out_of_range_parameters_are_refused_when_set_and_the_old_value_kept() {
    let i = Instance::new(&ccc::INFO);
    assert_eq!(i.setup(0.0, None), OK);
    assert_eq!(i.enter_init(), OK);
    let kp = ccc::AXIS_GAINS.at(0).vr() as u32;
    let kp0 = ccc::CCC_GAINS0.at(0).vr() as u32;
    let estimator = ccc::ESTIMATOR.vr() as u32;

    assert_eq!(i.set_reals(&[kp], &[-1.0]), ERROR);
    assert_eq!(
        i.last_error(),
        "fmi2SetReal: variable 'axis.x.Kp' = -1 is below its minimum 0"
    );
    assert_eq!(
        i.get_real(kp),
        real_start(ccc::AXIS_GAINS.at(0).vr(), &ccc::INFO)
    );

    assert_eq!(i.set_reals(&[kp0], &[f64::NAN]), ERROR);
    assert_eq!(
        i.last_error(),
        "fmi2SetReal: variable 'ccc.Kp0' refuses the non-finite value NaN"
    );
    assert_eq!(
        i.get_real(kp0),
        real_start(ccc::CCC_GAINS0.at(0).vr(), &ccc::INFO)
    );

    // The estimator is an enumeration, set with fmi2SetInteger.
    for bad in [0, 5, -1] {
        assert_eq!(i.set_integer(estimator, bad), ERROR);
        assert_eq!(
            i.last_error(),
            format!(
                "fmi2SetInteger: variable 'estimator' = {bad} is not a value of its \
                 enumeration ContourEstimator (1 = free_curve, 2 = line, 3 = arc, 4 = program)"
            )
        );
        assert_eq!(i.get_integer(estimator), (OK, 1));
    }
    assert_eq!(i.set_string(estimator, "arc"), ERROR);
    assert_eq!(
        i.last_error(),
        "fmi2SetString: variable 'estimator' is of type Integer, not String"
    );
    assert_eq!(i.set_integer(estimator, 3), OK);
    assert_eq!(i.get_integer(estimator), (OK, 3));

    // All or nothing: a call with one bad value stores none.
    let ki = kp + 1;
    assert_eq!(i.set_reals(&[ki, kp], &[7.0, -2.0]), ERROR);
    assert_eq!(
        i.get_real(ki),
        real_start(ccc::AXIS_GAINS.at(1).vr(), &ccc::INFO)
    );
    assert_eq!(i.exit_init(), OK, "{}", i.last_error());
}

/// Values that pass their bounds but not the model: refused by
/// fmi2ExitInitializationMode with the parameter named; the instance stays in
/// initialization mode, and the corrected value is accepted.
#[test]
fn inconsistent_parameters_are_refused_at_the_end_of_initialization() {
    type Setter = fn(&Instance) -> fmi2Status;
    let cases: Vec<(&str, Setter, Setter, &str)> = vec![
        (
            "ContourCCC2D",
            |i| i.set_reals(&[ccc::TS.vr() as u32], &[0.0]),
            |i| i.set_reals(&[ccc::TS.vr() as u32], &[1e-3]),
            "parameter 'Ts' must be at least 1e-6 s (got 0)",
        ),
        (
            "ContourCCC2D",
            |i| i.set_reals(&[ccc::CCC_LIMIT.vr() as u32], &[0.0]),
            |i| i.set_reals(&[ccc::CCC_LIMIT.vr() as u32], &[50.0]),
            "parameter ccc.limit = 0 is invalid: must be finite and > 0 when set",
        ),
        (
            "ContourCCC2D",
            |i| {
                let r = ccc::GEOMETRY.at(geometry::ARC_R).vr() as u32;
                i.set_integer(ccc::ESTIMATOR.vr() as u32, 3)
                    .max(i.set_reals(&[r], &[0.0]))
            },
            |i| i.set_reals(&[ccc::GEOMETRY.at(geometry::ARC_R).vr() as u32], &[5.0]),
            "parameters 'arc.*': invalid path: arc radius must be > 0, got 0",
        ),
        (
            "PathInterpolator2D",
            |i| i.set_reals(&[interp::FEED.vr() as u32], &[-5.0]),
            |i| i.set_reals(&[interp::FEED.vr() as u32], &[5.0]),
            "parameter 'feed' must be > 0 (got -5)",
        ),
        (
            "PathInterpolator2D",
            |i| i.set_reals(&[interp::TS.vr() as u32], &[1e-9]),
            |i| i.set_reals(&[interp::TS.vr() as u32], &[2e-3]),
            "parameter 'Ts' must be at least 1e-6 s (got 0.000000001)",
        ),
        (
            "PathInterpolator2D",
            |i| i.set_string(interp::PATH.vr() as u32, "spiral"),
            |i| i.set_string(interp::PATH.vr() as u32, "line"),
            "parameter 'path': unknown path 'spiral'",
        ),
    ];
    for (model, set_bad, set_good, words) in cases {
        let info = if model == "ContourCCC2D" {
            &ccc::INFO
        } else {
            &interp::INFO
        };
        let i = Instance::new(info);
        assert_eq!(i.setup(0.0, None), OK);
        assert_eq!(i.enter_init(), OK);
        assert_eq!(set_bad(&i), OK, "{}", i.last_error());
        assert_eq!(i.exit_init(), ERROR, "{words}");
        let error = i.last_error();
        assert!(
            error.starts_with("fmi2ExitInitializationMode: ") && error.contains(words),
            "{error} / {words}"
        );
        // Still in initialization mode: stepping is refused, correcting is accepted.
        assert_eq!(i.step(0.0, 1e-3), ERROR);
        assert!(i
            .last_error()
            .contains("illegal call sequence (state Initialization)"));
        assert_eq!(set_good(&i), OK);
        assert_eq!(i.exit_init(), OK, "{}", i.last_error());
        assert_eq!(i.step(0.0, 1e-3), OK);
    }
}

// XYServoPlant through the ABI.

mod xy_servo_plant {
    use crate::common::plant_vr::{POS_X, POS_Y, U_X, U_Y, VEL_X};
    use crate::common::*;
    use contour_core::math;
    use contour_fmu::models::xy_servo_plant as plant;

    #[test]
    fn one_long_step_equals_many_short_ones() {
        let coarse = Instance::new(&plant::INFO);
        let fine = Instance::new(&plant::INFO);
        coarse.start();
        fine.start();
        let mut t = 0.0;
        for k in 0..20 {
            let u = [50.0 * math::sin(k as f64 * 0.7), -30.0 + k as f64];
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
}
