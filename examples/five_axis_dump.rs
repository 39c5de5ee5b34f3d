//! Prints the five-axis kinematics and the five-axis test plant as JSON, for comparison
//! with independent scipy models (tests/reference/test_kinematics_scipy.py and
//! tests/reference/test_five_axis_plant_scipy.py).
//!
//! Usage:
//! - `five_axis_dump kinematics SEED N`: N pseudo-random cases of the table-tilting A–C
//!   machine (`contour_core::kinematics`). Joints X, Y, Z in ±200 mm, A in [0, 1.5] rad,
//!   C in ±7 rad; pivots with every component nonzero (5 to 120 mm, either sign, so the
//!   components the kinematics must ignore are set as well). Output per case: joints,
//!   pivots, the forward pose (tip, axis), the previous C handed to the inverse (the true
//!   C plus up to ±0.5 rad of noise), the inverse of the pose, the inverse of the same
//!   pose with its axis scaled by 3.7 (the axis need not be unit), and the analytic
//!   Jacobian (6 rows of 5). A further list `vertical` holds cases with A = 0 exactly,
//!   where the inverse must hold the previous C, and `near_vertical` cases with A = 10⁻²
//!   down to 10⁻⁸ rad (still above the inverse's vertical threshold, sin A < 10⁻⁹).
//! - `five_axis_dump plant STEPS DT`: the `ServoAxesParams::<5>::TRUNNION` plant (X, Y, Z
//!   linear, A, C rotary) at rest at a fixed start position, driven for STEPS steps of DT
//!   seconds by a deterministic velocity command per axis (mm/s, rad/s): X steps, Y ramps
//!   and saturates, Z is a sine, A steps up and back, C is a ramp plus a sine. Output:
//!   the axis parameters, the start, the command of every step and the positions and
//!   velocities after every step (row k is after step k + 1).
//! - `five_axis_dump closed_loop PATH MODE [FEED [unplanned]]`: the in-process five-axis
//!   closed loop (`contour_core::sim::simulate_five_axis`) on a built-in path or a CL/JSON
//!   file, CCC `off`, `fixed` or `fuzzy`, at FEED mm/s (default 50), the reference planned
//!   (or at constant feed with `unplanned`): the metrics and every sample's record
//!   (time, reference and actual joints, command, true and estimated errors), for the
//!   FMU closed loop to reproduce (tests/fmpy/test_five_axis_fmus.py).

use contour_core::control::CccMode;
use contour_core::geometry::Vector;
use contour_core::kinematics::{Joints, Pose, TableTiltingAc};
use contour_core::math;
use contour_core::path::five_axis::ToolPath;
use contour_core::plant::{ServoAxes, ServoAxesParams};
use contour_core::sim::{simulate_five_axis, FiveAxisSimConfig};
use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};
use serde_json::{json, Value};

fn fail(msg: impl std::fmt::Display) -> ! {
    eprintln!("five_axis_dump: {msg}");
    std::process::exit(2);
}

/// 5 to 120 in magnitude, either sign: never zero.
fn offset(rng: &mut StdRng) -> f64 {
    let magnitude = rng.random_range(5.0..120.0);
    if rng.random_bool(0.5) {
        -magnitude
    } else {
        magnitude
    }
}

fn vec<const D: usize>(v: &Vector<D>) -> Vec<f64> {
    v.iter().copied().collect()
}

fn case(rng: &mut StdRng, a_angle: f64) -> Value {
    let q = Joints::new(
        rng.random_range(-200.0..200.0),
        rng.random_range(-200.0..200.0),
        rng.random_range(-200.0..200.0),
        a_angle,
        rng.random_range(-7.0..7.0),
    );
    let machine = TableTiltingAc {
        a_pivot: Vector::<3>::new(offset(rng), offset(rng), offset(rng)),
        c_pivot: Vector::<3>::new(offset(rng), offset(rng), offset(rng)),
    };
    let previous_c = q[4] + rng.random_range(-0.5..0.5);
    let pose = machine.forward(&q);
    let inverse = machine.inverse(&pose, previous_c);
    let scaled = machine.inverse(
        &Pose {
            tip: pose.tip,
            axis: pose.axis * 3.7,
        },
        previous_c,
    );
    let j = machine.jacobian(&q);
    let rows: Vec<Vec<f64>> = (0..6)
        .map(|r| (0..5).map(|k| j[(r, k)]).collect())
        .collect();
    json!({
        "joints": vec(&q),
        "a_pivot": vec(&machine.a_pivot),
        "c_pivot": vec(&machine.c_pivot),
        "tip": vec(&pose.tip),
        "axis": vec(&pose.axis),
        "previous_c": previous_c,
        "inverse": inverse.as_ref().map(vec),
        "inverse_scaled_axis": scaled.as_ref().map(vec),
        "jacobian": rows,
    })
}

fn kinematics(seed: u64, count: usize) -> Value {
    let mut rng = StdRng::seed_from_u64(seed);
    let cases: Vec<Value> = (0..count)
        .map(|_| {
            let a = rng.random_range(0.0..1.5);
            case(&mut rng, a)
        })
        .collect();
    let vertical: Vec<Value> = (0..4).map(|_| case(&mut rng, 0.0)).collect();
    let near_vertical: Vec<Value> = [1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8]
        .iter()
        .map(|&a| case(&mut rng, a))
        .collect();
    json!({
        "seed": seed,
        "cases": cases,
        "vertical": vertical,
        "near_vertical": near_vertical,
    })
}

/// The velocity command of step k (held over [k·dt, (k + 1)·dt)), mm/s and rad/s.
fn command(t: f64) -> Vector<5> {
    let tau = std::f64::consts::TAU;
    Vector::<5>::new(
        if t < 0.05 { 20.0 } else { -35.0 },
        (400.0 * t).min(60.0),
        30.0 * math::sin(tau * 7.0 * t),
        if (0.02..0.12).contains(&t) { 0.8 } else { -0.3 },
        5.0 * t + 2.0 * math::sin(tau * 3.0 * t),
    )
}

fn plant(steps: usize, dt: f64) -> Value {
    let params = ServoAxesParams::<5>::TRUNNION;
    params.validate().unwrap_or_else(|e| fail(e));
    let start = Vector::<5>::new(10.0, -5.0, 2.5, 0.2, -1.0);
    let mut axes = ServoAxes::new(params, start);
    let mut commands = Vec::with_capacity(steps);
    let mut positions = Vec::with_capacity(steps);
    let mut velocities = Vec::with_capacity(steps);
    for k in 0..steps {
        let u = command(k as f64 * dt);
        axes.step(u, dt);
        commands.push(vec(&u));
        positions.push(vec(&axes.position()));
        velocities.push(vec(&axes.velocity()));
    }
    json!({
        "dt": dt,
        "axes": params.axes,
        "start": vec(&start),
        "commands": commands,
        "position": positions,
        "velocity": velocities,
    })
}

fn closed_loop(path: &str, mode: &str, feed: f64, unplanned: bool) -> Value {
    let mode = match mode {
        "off" => CccMode::Off,
        "fixed" => CccMode::Fixed,
        "fuzzy" => CccMode::Fuzzy,
        other => fail(format!("MODE must be off, fixed or fuzzy (got {other})")),
    };
    // A CL file's FEDRATs and RAPIDs as the interpolator FMU reads them (its `rapid`
    // parameter's default: 100 mm/s).
    let (tool_path, feeds, _) =
        ToolPath::load_with_feeds(path, feed, 100.0).unwrap_or_else(|e| fail(e));
    let mut config = FiveAxisSimConfig::new(tool_path, feed).with_mode(mode);
    config.feeds = feeds;
    if unplanned {
        config = config.unplanned();
    }
    config.settle = 0.1;
    let (metrics, records) = simulate_five_axis(&config, true).unwrap_or_else(|e| fail(e));
    json!({
        "ts": config.controller.ts,
        "feed": feed,
        "metrics": metrics,
        "records": records,
    })
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let arg = |i: usize| args.get(i).map(String::as_str);
    let out = match arg(0) {
        Some("kinematics") => {
            let seed = arg(1)
                .unwrap_or("1")
                .parse()
                .unwrap_or_else(|e| fail(format!("SEED: {e}")));
            let count = arg(2)
                .unwrap_or("200")
                .parse()
                .unwrap_or_else(|e| fail(format!("N: {e}")));
            kinematics(seed, count)
        }
        Some("plant") => {
            let steps = arg(1)
                .unwrap_or("1000")
                .parse()
                .unwrap_or_else(|e| fail(format!("STEPS: {e}")));
            let dt: f64 = arg(2)
                .unwrap_or("0.001")
                .parse()
                .unwrap_or_else(|e| fail(format!("DT: {e}")));
            if !(dt.is_finite() && dt > 0.0) {
                fail(format!("DT must be finite and > 0 (got {dt})"));
            }
            plant(steps, dt)
        }
        Some("closed_loop") => closed_loop(
            arg(1).unwrap_or("tilted_helix"),
            arg(2).unwrap_or("fuzzy"),
            arg(3)
                .unwrap_or("50")
                .parse()
                .unwrap_or_else(|e| fail(format!("FEED: {e}"))),
            arg(4) == Some("unplanned"),
        ),
        _ => fail(
            "usage: five_axis_dump kinematics SEED N | five_axis_dump plant STEPS DT | \
             five_axis_dump closed_loop PATH MODE [FEED [unplanned]]",
        ),
    };
    println!("{out}");
}
