//! The SI build (framework::interface) through the C ABI: the two-axis closed loop with
//! every FMU in SI (m, m/s, m/s², m/s³) runs the mm loop's trajectories, scaled by 10⁻³,
//! to 10⁻¹² relative; its bounds are the mm ones in metres; its GUID is its own.

use contour_fmu::framework::interface::UnitSystem;
use contour_fmu::models;

use crate::common::linked::{
    self, fmi2DoStep, fmi2GetReal, fmi2SetReal, vrs, OwnedInstance, Start,
};

/// One instance of `model` in `units` with `parameters` set (values in those units).
fn instance(model: &str, units: UnitSystem, parameters: &[(&str, Start)]) -> OwnedInstance {
    OwnedInstance::new(models::interface(linked::model(model), units), parameters)
}

fn get(i: &OwnedInstance, model: &str, names: &[&str]) -> Vec<f64> {
    let vrs = vrs(linked::model(model), names);
    let mut out = vec![0.0; vrs.len()];
    // SAFETY: a live instance; buffers of the length passed.
    assert_eq!(
        unsafe { fmi2GetReal(i.c, vrs.as_ptr(), vrs.len(), out.as_mut_ptr()) },
        0
    );
    out
}

fn set(i: &OwnedInstance, model: &str, names: &[&str], values: &[f64]) -> u32 {
    let vrs = vrs(linked::model(model), names);
    // SAFETY: a live instance; buffers of the length passed.
    unsafe { fmi2SetReal(i.c, vrs.as_ptr(), vrs.len(), values.as_ptr()) }
}

/// Reference, position, command and estimated contour error of every sample of the
/// planned circle under the fuzzy CCC, in the interface's units.
fn closed_loop(units: UnitSystem) -> Vec<[f64; 7]> {
    // The same limits in each system: mm/s, mm/s², mm/s³, mm, or their SI values.
    let f = if units == UnitSystem::Si { 1e-3 } else { 1.0 };
    let interpolator = instance(
        "PathInterpolator2D",
        units,
        &[
            ("feed", Start::Real(40.0 * f)),
            ("accel", Start::Real(2000.0 * f)),
            ("jerk", Start::Real(1e5 * f)),
        ],
    );
    let reference = get(&interpolator, "PathInterpolator2D", &["ref.x", "ref.y"]);
    let plant = instance(
        "XYServoPlant",
        units,
        &[
            ("pos0.x", Start::Real(reference[0])),
            ("pos0.y", Start::Real(reference[1])),
        ],
    );
    let controller = instance("ContourCCC2D", units, &[]);
    let mut rows = Vec::new();
    let h = 1e-3;
    for k in 0..2500 {
        let t = k as f64 * h;
        let r = get(&interpolator, "PathInterpolator2D", &["ref.x", "ref.y"]);
        let p = get(&plant, "XYServoPlant", &["pos.x", "pos.y"]);
        let inputs = [r[0], r[1], p[0], p[1]];
        assert_eq!(
            set(
                &controller,
                "ContourCCC2D",
                &["ref.x", "ref.y", "pos.x", "pos.y"],
                &inputs
            ),
            0
        );
        // SAFETY: live instances.
        assert_eq!(unsafe { fmi2DoStep(controller.c, t, h, 1) }, 0);
        let u = get(&controller, "ContourCCC2D", &["u.x", "u.y", "contourError"]);
        assert_eq!(set(&plant, "XYServoPlant", &["u.x", "u.y"], &u[..2]), 0);
        // SAFETY: live instances.
        unsafe {
            assert_eq!(fmi2DoStep(plant.c, t, h, 1), 0);
            assert_eq!(fmi2DoStep(interpolator.c, t, h, 1), 0);
        }
        rows.push([r[0], r[1], p[0], p[1], u[0], u[1], u[2]]);
    }
    rows
}

#[test]
fn the_si_loop_runs_the_mm_loops_trajectories_in_metres() {
    let (mm, si) = (
        closed_loop(UnitSystem::Millimetre),
        closed_loop(UnitSystem::Si),
    );
    let mut largest = 0.0f64;
    for (k, (a, b)) in mm.iter().zip(&si).enumerate() {
        for (i, (&x, &y)) in a.iter().zip(b).enumerate() {
            let scale = a.iter().map(|v| v.abs()).fold(1e-9, f64::max);
            let off = (y * 1e3 - x).abs() / scale;
            largest = largest.max(off);
            assert!(off <= 1e-12, "sample {k}, column {i}: {x} mm vs {y} m");
        }
    }
    // The loop did something: the circle is 10 mm in radius.
    let reach = mm
        .iter()
        .map(|r| r[0].abs().max(r[1].abs()))
        .fold(0.0, f64::max);
    assert!(reach > 9.0, "{reach}");
    println!("largest relative difference: {largest:e}");
}

#[test]
fn si_parameters_and_bounds_are_the_mm_ones_in_metres() {
    // The feed in m/s: the interpolator runs at 40 mm/s and reports 0.04 m/s.
    let si = instance(
        "PathInterpolator2D",
        UnitSystem::Si,
        &[("feed", Start::Real(0.04))],
    );
    // SAFETY: a live instance.
    assert_eq!(unsafe { fmi2DoStep(si.c, 0.0, 1e-3, 1) }, 0);
    let rate = get(&si, "PathInterpolator2D", &["feedRate"])[0];
    assert!((rate - 0.04).abs() <= 1e-17, "{rate}");
    let bound = |units: UnitSystem, name: &str| {
        models::interface(linked::model("PathInterpolator2D"), units)
            .variables
            .iter()
            .find(|v| v.name == name)
            .map(|v| (v.min, v.max, v.unit))
            .unwrap()
    };
    let (mm_min, mm_max, _) = bound(UnitSystem::Millimetre, "feed");
    assert_eq!(
        bound(UnitSystem::Si, "feed"),
        (
            mm_min.map(|x| x * 1e-3),
            mm_max.map(|x| x * 1e-3),
            Some("m/s")
        )
    );
    // A finite value in m that overflows in mm is refused, the old value kept: fast path
    // (an input without bounds) and checked path (a parameter).
    let plant = instance("XYServoPlant", UnitSystem::Si, &[]);
    assert_ne!(set(&plant, "XYServoPlant", &["u.x"], &[1e306]), 0);
    assert_eq!(get(&plant, "XYServoPlant", &["u.x"]), [0.0]);
    assert_eq!(set(&plant, "XYServoPlant", &["u.x"], &[0.02]), 0);
    assert_eq!(get(&plant, "XYServoPlant", &["u.x"]), [0.02]);
    // The interpolator's first output, in m, is the circle's start in mm over 1000.
    let mm = instance("PathInterpolator2D", UnitSystem::Millimetre, &[]);
    let si_default = instance("PathInterpolator2D", UnitSystem::Si, &[]);
    let (a, b) = (
        get(&mm, "PathInterpolator2D", &["ref.x", "ref.y"]),
        get(&si_default, "PathInterpolator2D", &["ref.x", "ref.y"]),
    );
    assert!((a[0] * 1e-3 - b[0]).abs() <= 1e-15 && (a[1] * 1e-3 - b[1]).abs() <= 1e-15);
}
