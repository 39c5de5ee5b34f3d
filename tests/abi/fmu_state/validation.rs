//! Deserialized FMU states are validated like parameters: bytes that pass the checksum but
//! carry a bad value inside (a sample period ≤ 0, a negative radius, a non-finite PID
//! memory, …) or come from another state layout are refused by fmi2DeSerializeFMUstate
//! with fmi2Error and a message naming the cause, and the instance is left as it was.
//!
//! The bytes are opened and resealed by hand (tests/abi/common: magic, format version, payload,
//! CRC-32); values are found in the model's part by their exact bit patterns, computed
//! independently (parameters we set, the in-process controller's PID integral).

use crate::common::*;
use contour_core::contour::planar::{Estimator, FreeCurveEstimator};
use contour_core::control::{ControllerConfig, CrossCoupledController};
use contour_core::geometry::Vector2;
use contour_core::math;
use contour_fmu::framework::variables::Value;
use contour_fmu::models::{
    contour_ccc_2d as ccc, contour_ccc_5x, line_arc_parameters as geometry,
    path_interpolator_2d as interp, path_interpolator_5x, xy_servo_plant as plant,
};

/// A Ts that appears nowhere else in the state.
const TS: f64 = 0.00125;
/// An arc radius that appears nowhere else in the state.
const RADIUS: f64 = 17.25;

const INPUTS: [u32; 4] = [
    ccc::REF.at(0).vr() as u32,
    ccc::REF.at(1).vr() as u32,
    ccc::POS.at(0).vr() as u32,
    ccc::POS.at(1).vr() as u32,
];

fn held_inputs(k: usize) -> [f64; 4] {
    let a = 0.05 * (k / 4) as f64;
    [
        10.0 * math::cos(a) - 10.0,
        10.0 * math::sin(a),
        9.98 * math::cos(a - 0.01) - 10.0,
        9.98 * math::sin(a - 0.01),
    ]
}

/// A controller with Ts = `TS` (and the arc estimator of radius `RADIUS` when `arc`),
/// stepped 30 samples; the instance and its serialized state.
fn controller_state(arc: bool) -> (Instance, Vec<u8>) {
    let i = Instance::new(&ccc::INFO);
    assert_eq!(i.setup(0.0, None), OK);
    assert_eq!(i.enter_init(), OK);
    assert_eq!(i.set_reals(&[ccc::TS.vr() as u32], &[TS]), OK);
    if arc {
        assert_eq!(i.set_integer(ccc::ESTIMATOR.vr() as u32, 3), OK);
        let r = ccc::GEOMETRY.at(geometry::ARC_R).vr() as u32;
        assert_eq!(i.set_reals(&[r], &[RADIUS]), OK);
    }
    assert_eq!(i.exit_init(), OK, "{}", i.last_error());
    for k in 0..30 {
        assert_eq!(i.set_reals(&INPUTS, &held_inputs(k)), OK);
        assert_eq!(i.step(k as f64 * TS, TS), OK);
    }
    let (_, mut state) = i.get_state();
    let (s, bytes) = i.serialize(state);
    assert_eq!(s, OK);
    assert_eq!(i.free_state(&mut state), OK);
    (i, bytes)
}

/// The X position loop's integral after the same 30 samples, computed in process.
fn controller_x_integral() -> f64 {
    let config = ControllerConfig {
        ts: TS,
        ..ControllerConfig::default()
    };
    let mut c =
        CrossCoupledController::new(config, Estimator::FreeCurve(FreeCurveEstimator::default()))
            .unwrap();
    for k in 0..30 {
        let x = held_inputs(k);
        c.sample(Vector2::new(x[0], x[1]), Vector2::new(x[2], x[3]));
    }
    c.axes()[0].integral()
}

/// Applies `edit` to the model part of `bytes`, reseals, and deserializes into `i`:
/// expects fmi2Error with `cause` in the log, no state, and an undisturbed instance.
fn refused(i: &Instance, bytes: &[u8], edit: impl FnOnce(&mut StateEnvelope), cause: &str) {
    let (format, mut envelope) = open_state(bytes);
    edit(&mut envelope);
    let corrupt = seal_state(format, &envelope);
    let (s, state) = i.deserialize(&corrupt);
    assert_eq!(s, ERROR, "{cause}");
    assert!(state.is_null());
    let message = i.last_error();
    assert!(
        message.starts_with("fmi2DeSerializeFMUstate: ") && message.contains(cause),
        "expected '{cause}' in: {message}"
    );
}

/// The untouched bytes, opened and resealed, are accepted: the surgery itself is sound.
fn resealed_is_accepted(i: &Instance, bytes: &[u8]) {
    let (format, envelope) = open_state(bytes);
    assert_eq!(format, STATE_FORMAT);
    assert_eq!(seal_state(format, &envelope), bytes);
    let (s, mut state) = i.deserialize(bytes);
    assert_eq!(s, OK, "{}", i.last_error());
    assert_eq!(i.free_state(&mut state), OK);
}

/// The only position of `value` in `bytes`.
fn unique(bytes: &[u8], value: f64) -> usize {
    let at = find_f64(bytes, value);
    assert_eq!(at.len(), 1, "{value} at {at:?}");
    at[0]
}

#[test]
fn controller_states_with_bad_clock_pid_or_radius_are_refused() {
    let (i, bytes) = controller_state(false);
    resealed_is_accepted(&i, &bytes);
    let model = open_state(&bytes).1.model;

    // The sample clock is the state's last field; its period is the last TS in it (the
    // controller's configuration and PIDs hold the others).
    let periods = find_f64(&model, TS);
    assert_eq!(
        periods.len(),
        7,
        "config, two axis PIDs, contour PID, two per-axis contour PIDs, clock"
    );
    let clock = *periods.last().unwrap();
    for bad in [0.0, -TS, f64::NAN] {
        refused(
            &i,
            &bytes,
            |e| put_f64(&mut e.model, clock, bad),
            &format!("sample clock period {bad} s must be at least 1e-6 s"),
        );
    }
    // A clock far behind the state's time (its start precedes its period): the first
    // step would have to run 10⁹ samples to catch up.
    refused(
        &i,
        &bytes,
        |e| put_f64(&mut e.model, clock - 8, -1e6),
        "sample clock: the next sample is due at",
    );
    // The controller's own Ts (first in the configuration) out of line with the clock.
    refused(
        &i,
        &bytes,
        |e| put_f64(&mut e.model, periods[0], -TS),
        "controller configuration: parameter Ts = -0.00125 is invalid",
    );

    // The X position loop's integral, as the library computes it in process.
    let integral = controller_x_integral();
    assert!(integral != 0.0);
    let at = unique(&model, integral);
    for bad in [f64::NAN, f64::INFINITY] {
        refused(
            &i,
            &bytes,
            |e| put_f64(&mut e.model, at, bad),
            &format!("X position loop: PID memory (integral) = {bad} is not finite"),
        );
    }

    // A parameter value in the saved variables, outside its range.
    refused(
        &i,
        &bytes,
        |e| e.values.set(ccc::AXIS_GAINS.at(0).vr(), Value::Real(-1.0)),
        "the FMU state is invalid: variable 'axis.x.Kp' = -1 is below its minimum 0",
    );
    refused(
        &i,
        &bytes,
        |e| e.values.set(ccc::ESTIMATOR.vr(), Value::Integer(7)),
        "variable 'estimator' = 7 is not a value of its enumeration",
    );

    // After all that, the instance carries on from where it was.
    assert_eq!(i.step(30.0 * TS, TS), OK, "{}", i.last_error());
}

#[test]
fn controller_states_with_bad_feed_forward_memory_are_refused() {
    let (i, bytes) = controller_state(false);
    let model = open_state(&bytes).1.model;
    // The feed-forward last read its inputs at the 30th sample's communication point.
    let read_at = 29.0 * TS;
    let at = unique(&model, read_at);
    refused(
        &i,
        &bytes,
        |e| put_f64(&mut e.model, at, 30.0 * TS),
        "feed-forward: inputs read at t = 0.0375 s, not before the state's time",
    );
    refused(
        &i,
        &bytes,
        |e| put_f64(&mut e.model, at, f64::NAN),
        "feed-forward: memory holds a value that is not finite",
    );
    assert_eq!(i.step(30.0 * TS, TS), OK, "{}", i.last_error());
}

#[test]
fn an_arc_estimator_with_a_negative_radius_is_refused() {
    let (i, bytes) = controller_state(true);
    resealed_is_accepted(&i, &bytes);
    let at = unique(&open_state(&bytes).1.model, RADIUS);
    refused(
        &i,
        &bytes,
        |e| put_f64(&mut e.model, at, -RADIUS),
        "estimator: controller.estimator.Arc.mode.Fixed.radius = -17.25 must be > 0",
    );
}

#[test]
fn interpolator_states_with_a_bad_path_or_clock_are_refused() {
    let i = Instance::new(&interp::INFO);
    assert_eq!(i.setup(0.0, None), OK);
    assert_eq!(i.enter_init(), OK);
    assert_eq!(i.set_string(interp::PATH.vr() as u32, "arc"), OK);
    let r = interp::GEOMETRY.at(geometry::ARC_R).vr() as u32;
    assert_eq!(i.set_reals(&[r, interp::TS.vr() as u32], &[RADIUS, TS]), OK);
    assert_eq!(i.exit_init(), OK, "{}", i.last_error());
    for k in 0..20 {
        assert_eq!(i.step(k as f64 * TS, TS), OK);
    }
    let (_, mut state) = i.get_state();
    let (_, bytes) = i.serialize(state);
    resealed_is_accepted(&i, &bytes);
    let model = open_state(&bytes).1.model;

    let at = unique(&model, RADIUS);
    refused(
        &i,
        &bytes,
        |e| put_f64(&mut e.model, at, -RADIUS),
        "interpolator path: invalid path: arc radius must be > 0, got -17.25",
    );
    let periods = find_f64(&model, TS);
    assert_eq!(periods.len(), 2, "interpolator, clock");
    refused(
        &i,
        &bytes,
        |e| put_f64(&mut e.model, periods[1], 0.0),
        "sample clock period 0 s must be at least 1e-6 s",
    );
    refused(
        &i,
        &bytes,
        |e| put_f64(&mut e.model, periods[0], 2.0 * TS),
        "interpolator period 0.0025 s differs from the sample clock period 0.00125 s",
    );
    assert_eq!(i.free_state(&mut state), OK);
}

#[test]
fn plant_states_with_bad_axis_values_are_refused() {
    let i = Instance::new(&plant::INFO);
    i.start();
    assert_eq!(i.set_reals(&[plant::U.at(0).vr() as u32], &[12.5]), OK);
    for k in 0..5 {
        assert_eq!(i.step(k as f64 * 0.01, 0.01), OK);
    }
    let pos_x = i.get_real(plant::POS.at(0).vr() as u32);
    let (_, mut state) = i.get_state();
    let (_, bytes) = i.serialize(state);
    resealed_is_accepted(&i, &bytes);
    let model = open_state(&bytes).1.model;

    let at = unique(&model, pos_x);
    refused(
        &i,
        &bytes,
        |e| put_f64(&mut e.model, at, f64::NAN),
        &format!(
            "the FMU state is invalid (saved by contour-fmu {}): axis x: state[0] = NaN is not \
             finite",
            env!("CARGO_PKG_VERSION")
        ),
    );
    // The X axis's parameters come first.
    let inertia = find_f64(&model, 0.015)[0];
    refused(
        &i,
        &bytes,
        |e| put_f64(&mut e.model, inertia, -0.015),
        "axis x: inertia must be finite and > 0 (got -0.015)",
    );
    // The cached transition of 10 ms steps, relabelled as one of 20 ms steps.
    let step = find_f64(&model, 0.01)[0];
    refused(
        &i,
        &bytes,
        |e| put_f64(&mut e.model, step, 0.02),
        "axis x: the cached transition for steps of 0.02 s does not match the axis parameters",
    );
    assert_eq!(i.free_state(&mut state), OK);
}

#[test]
fn plant_states_with_the_table_beyond_the_play_are_refused() {
    // X with 0.0625 mm of backlash, pushed forward: the table is 0.03125 mm behind the
    // motor. Moved a millimetre further, it would be outside the play.
    let i = Instance::new(&plant::INFO);
    assert_eq!(i.setup(0.0, None), OK);
    let backlash = plant::EFFECTS.at(3).vr() as u32;
    assert_eq!(i.set_reals(&[backlash], &[0.0625]), OK);
    assert_eq!(i.enter_init(), OK);
    assert_eq!(i.exit_init(), OK, "{}", i.last_error());
    assert_eq!(i.set_reals(&[plant::U.at(0).vr() as u32], &[12.5]), OK);
    for k in 0..5 {
        assert_eq!(i.step(k as f64 * 0.01, 0.01), OK);
    }
    let pos_x = i.get_real(plant::POS.at(0).vr() as u32);
    let (_, mut state) = i.get_state();
    let (_, bytes) = i.serialize(state);
    resealed_is_accepted(&i, &bytes);
    let model = open_state(&bytes).1.model;
    let (at, play) = (unique(&model, pos_x), unique(&model, 0.0625));
    refused(
        &i,
        &bytes,
        |e| put_f64(&mut e.model, at, pos_x - 1.0),
        "axis x: the table is 1.03125",
    );
    refused(
        &i,
        &bytes,
        |e| put_f64(&mut e.model, play, -0.0625),
        "axis x: backlash must be finite and >= 0 (got -0.0625)",
    );
    assert_eq!(i.free_state(&mut state), OK);
}

#[test]
fn states_from_an_older_layout_or_format_are_refused_with_a_clear_message() {
    let (controller, controller_bytes) = controller_state(false);
    let plant_instance = Instance::new(&plant::INFO);
    plant_instance.start();
    let (_, mut state) = plant_instance.get_state();
    let (_, plant_bytes) = plant_instance.serialize(state);
    plant_instance.free_state(&mut state);
    let interpolator = Instance::new(&interp::INFO);
    let (_, mut state) = interpolator.get_state();
    let (_, interpolator_bytes) = interpolator.serialize(state);
    interpolator.free_state(&mut state);
    let five_axis = |info| {
        let instance = Instance::new(info);
        let (_, mut state) = instance.get_state();
        let (_, bytes) = instance.serialize(state);
        instance.free_state(&mut state);
        (instance, bytes)
    };
    let (controller_5x, controller_5x_bytes) = five_axis(&contour_ccc_5x::INFO);
    let (interpolator_5x, interpolator_5x_bytes) = five_axis(&path_interpolator_5x::INFO);

    // The models' current layout versions: ContourCCC2D 7 (the feed-forward remembers its
    // inputs; 6: a program's moves carry their standstill; 5: the acceleration feed-forward; 4: the feed-forward gain; 3: the
    // program estimator keeps its last two feet; 2: the controller became N-axis),
    // XYServoPlant 3 (each axis gained its effects and the table behind the play; 2: the
    // lead became a transmission), PathInterpolator2D 3 (a program's moves carry their
    // standstill; 2: the planned reference joined the constant-feed one), ContourCCC5X 5 (the feed-forward
    // remembers its inputs; 4: the feed-forward gains, the guard's averaged speeds and
    // commands), PathInterpolator5X 6 (a plan saved with its inputs' fingerprint and its
    // summary; 5: a plan's inputs carry a CL file's speeds; 4: the sample before the
    // current one, for vref and aref).
    for (i, bytes, model, version) in [
        (&controller, &controller_bytes, "ContourCCC2D", 7u16),
        (&plant_instance, &plant_bytes, "XYServoPlant", 3),
        (&interpolator, &interpolator_bytes, "PathInterpolator2D", 3),
        (&controller_5x, &controller_5x_bytes, "ContourCCC5X", 5),
        (
            &interpolator_5x,
            &interpolator_5x_bytes,
            "PathInterpolator5X",
            6,
        ),
    ] {
        let (_, envelope) = open_state(bytes);
        assert_eq!(
            &envelope.model[..2],
            &version.to_le_bytes(),
            "{model}: layout version {version}"
        );
        refused(
            i,
            bytes,
            |e| e.model[..2].copy_from_slice(&0u16.to_le_bytes()),
            &format!(
                "the {model} state has internal layout version 0, this build reads layout \
                 version {version} only: it was saved by an older build of contour-fmu and \
                 cannot be restored"
            ),
        );
        // The layout just before this one (a state saved by the last release).
        let before = version - 1;
        refused(
            i,
            bytes,
            |e| e.model[..2].copy_from_slice(&before.to_le_bytes()),
            &format!(
                "the {model} state has internal layout version {before}, this build reads \
                 layout version {version} only: it was saved by an older build of \
                 contour-fmu and cannot be restored"
            ),
        );
        // The envelope of the states before per-model layouts (format 1).
        let (_, envelope) = open_state(bytes);
        let old = seal_state(1, &envelope);
        let (s, st) = i.deserialize(&old);
        assert_eq!(s, ERROR);
        assert!(st.is_null());
        assert_eq!(
            i.last_error(),
            "fmi2DeSerializeFMUstate: FMU state format version 1 is not supported (this \
             library reads 2): the state was saved by an older build of contour-fmu"
        );
    }
}
