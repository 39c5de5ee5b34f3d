//! ServoDrive and ServoDriveRotary through the C ABI, each closing its velocity loop on a
//! test-side inertia (a 100 kg slide, a 0.1 kg·m² table: the same loop in their own units,
//! ω₁ = Kvp/m = 314 /s, ω₀² = Kvi/m = 9 870 /s²), against the continuous law's closed
//! form: the sampled drive converges to it at first order in the step (1 ms and 0.25 ms),
//! and the SI build gives the same efforts.

use contour_core::math;
use contour_fmu::framework::interface::UnitSystem;
use contour_fmu::framework::model::ModelInfo;
use contour_fmu::models::{self, servo_drive};

use crate::common::linked::{fmi2DoStep, fmi2GetReal, fmi2SetReal, vrs, OwnedInstance};

/// The velocity (the drive's units) and effort of every step of a command step of
/// `command` from rest, the drive on an inertia `inertia` (kg, kg·m²) whose acceleration
/// is effort / inertia × `per_si` (1000 for mm/s: a force in N on kg gives m/s²).
fn step_response(
    model: &ModelInfo,
    units: UnitSystem,
    inertia: f64,
    per_si: f64,
    command: f64,
    h: f64,
    duration: f64,
) -> Vec<(f64, f64, f64)> {
    let drive = OwnedInstance::new(models::interface(model, units), &[]);
    let c = drive.c;
    let [u, vel, effort] = [0, 1, 2].map(|i| vrs(model, &["u", "vel", "effort"])[i]);
    let mut v = 0.0;
    let mut rows = Vec::new();
    let steps = (duration / h).round() as usize;
    for k in 0..steps {
        // SAFETY: a live instance, one value each.
        unsafe {
            assert_eq!(fmi2SetReal(c, &u, 1, &command), 0);
            assert_eq!(fmi2SetReal(c, &vel, 1, &v), 0);
            assert_eq!(fmi2DoStep(c, k as f64 * h, h, 1), 0);
        }
        let mut f = 0.0;
        // SAFETY: as above.
        assert_eq!(unsafe { fmi2GetReal(c, &effort, 1, &mut f) }, 0);
        // The mechanics: the effort held over the step.
        v += f / inertia * per_si * h;
        rows.push(((k + 1) as f64 * h, v, f));
    }
    rows
}

/// The continuous loop's velocity at `t` for a command step `command` from rest:
/// e = u − v solves ë + ω₁ė + ω₀²e = 0, e(0) = U, ė(0) = −ω₁U.
fn continuous(command: f64, t: f64) -> f64 {
    let (w1, w0_2): (f64, f64) = (314.0, 9870.0);
    let root = (w1 * w1 - 4.0 * w0_2).sqrt();
    let (s1, s2) = (0.5 * (-w1 + root), 0.5 * (-w1 - root));
    // A + B = U, A·s1 + B·s2 = −ω₁U.
    let b = command * (-w1 - s1) / (s2 - s1);
    let a = command - b;
    command - (a * math::exp(s1 * t) + b * math::exp(s2 * t))
}

#[test]
fn the_sampled_drive_converges_to_the_continuous_pi_loop_in_both_kinds() {
    for (model, inertia, per_si, command) in [
        (&servo_drive::INFO, 100.0, 1000.0, 10.0),
        (&servo_drive::INFO_ROTARY, 0.1, 1.0, 2.0),
    ] {
        let deviation = |h: f64| {
            step_response(
                model,
                UnitSystem::Millimetre,
                inertia,
                per_si,
                command,
                h,
                0.2,
            )
            .iter()
            .map(|&(t, v, _)| (v - continuous(command, t)).abs() / command)
            .fold(0.0, f64::max)
        };
        let (coarse, fine) = (deviation(1e-3), deviation(2.5e-4));
        // First order in h: a quarter of the step, about a quarter of the deviation.
        assert!(coarse < 0.07, "{}: {coarse}", model.identifier);
        assert!(fine < 0.016, "{}: {fine}", model.identifier);
        let order = math::log(coarse / fine) / math::log(4.0);
        println!(
            "{}: deviation {coarse:.4} at 1 ms, {fine:.4} at 0.25 ms, order {order:.3}",
            model.identifier
        );
        assert!(
            (0.8..1.2).contains(&order),
            "{}: order {order}",
            model.identifier
        );
        // It settles on the command.
        let last = step_response(
            model,
            UnitSystem::Millimetre,
            inertia,
            per_si,
            command,
            1e-3,
            0.5,
        );
        assert!((last.last().unwrap().1 - command).abs() < 1e-3 * command);
    }
}

#[test]
fn the_si_drive_gives_the_mm_drives_forces() {
    // 10 mm/s on a 100 kg slide in mm, 0.01 m/s in SI: the same forces, the velocities
    // scaled.
    let model = &servo_drive::INFO;
    let mm = step_response(
        model,
        UnitSystem::Millimetre,
        100.0,
        1000.0,
        10.0,
        1e-3,
        0.2,
    );
    let si = step_response(model, UnitSystem::Si, 100.0, 1.0, 0.01, 1e-3, 0.2);
    let largest = mm.iter().map(|r| r.2.abs()).fold(0.0, f64::max);
    for ((_, v, f), (_, v_si, f_si)) in mm.iter().zip(&si) {
        assert!((f - f_si).abs() <= 1e-12 * largest, "{f} N vs {f_si} N");
        assert!(
            (v * 1e-3 - v_si).abs() <= 1e-12 * 0.01,
            "{v} mm/s vs {v_si} m/s"
        );
    }
}
