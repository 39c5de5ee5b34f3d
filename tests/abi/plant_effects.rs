//! The test plants with their nonlinear effects on (friction, backlash, current limit)
//! through the C ABI: a state saved mid-run and restored into a fresh instance goes on
//! exactly as the original, and the effects change the run (they are read at all).

use crate::common::*;
use contour_core::math;
use contour_fmu::models::{five_axis_plant, xy_servo_plant as plant};

/// X: Stribeck friction and a current limit; Y: Coulomb friction and backlash.
fn with_effects() -> Instance {
    let i = Instance::new(&plant::INFO);
    assert_eq!(i.setup(0.0, None), OK);
    let e = |k: usize| plant::EFFECTS.at(k).vr() as u32;
    let values = [
        (e(0), 0.3),  // x.coulomb
        (e(1), 0.5),  // x.stiction
        (e(2), 1.0),  // x.stribeckVelocity
        (e(4), 80.0), // x.currentMax
        (e(5), 0.4),  // y.coulomb
        (e(8), 0.02), // y.backlash
    ];
    for (vr, value) in values {
        assert_eq!(i.set_reals(&[vr], &[value]), OK);
    }
    assert_eq!(i.enter_init(), OK);
    assert_eq!(i.exit_init(), OK, "{}", i.last_error());
    i
}

/// Positions and velocities of `steps` steps of 1 ms from step `from`, under commands
/// that reverse (so the axes stick, cross the play and saturate).
fn run(i: &Instance, from: usize, steps: usize) -> Vec<[f64; 4]> {
    let u = [plant::U.at(0).vr() as u32, plant::U.at(1).vr() as u32];
    let out = [plant::POS, plant::VEL].map(|b| [b.at(0).vr() as u32, b.at(1).vr() as u32]);
    (from..from + steps)
        .map(|k| {
            let t = k as f64 * 1e-3;
            let w = 2.0 * std::f64::consts::PI * t;
            assert_eq!(
                i.set_reals(&u, &[60.0 * math::sin(w), 8.0 * math::cos(w)]),
                OK
            );
            assert_eq!(i.step(t, 1e-3), OK);
            let (_, p) = i.get_reals(&out[0]);
            let (_, v) = i.get_reals(&out[1]);
            [p[0], p[1], v[0], v[1]]
        })
        .collect()
}

#[test]
fn a_plant_with_effects_restored_into_a_fresh_instance_goes_on_alike() {
    let original = with_effects();
    run(&original, 0, 700);
    let (_, mut state) = original.get_state();
    let (_, bytes) = original.serialize(state);
    let expected = run(&original, 700, 600);

    let fresh = Instance::new(&plant::INFO);
    fresh.start();
    let (s, mut restored) = fresh.deserialize(&bytes);
    assert_eq!(s, OK, "{}", fresh.last_error());
    assert_eq!(fresh.set_state(restored), OK);
    assert_eq!(run(&fresh, 700, 600), expected);

    // The effects act: the same commands on the linear plant give another run.
    let linear = Instance::new(&plant::INFO);
    linear.start();
    let plain = run(&linear, 0, 1300);
    let differs = |axis: usize| {
        plain[700..]
            .iter()
            .zip(&expected)
            .map(|(a, b)| (a[axis] - b[axis]).abs())
            .fold(0.0, f64::max)
    };
    assert!(
        differs(0) > 1e-3 && differs(1) > 5e-3,
        "{} {}",
        differs(0),
        differs(1)
    );
    assert_eq!(original.free_state(&mut state), OK);
    assert_eq!(fresh.free_state(&mut restored), OK);
}

#[test]
fn the_five_axis_plant_reads_the_effects_of_a_rotary_joint() {
    // 1 mrad of play on C: the table (pos.C) starts 0.5 mrad behind the motor once the
    // command turns it.
    let i = Instance::new(&five_axis_plant::INFO);
    assert_eq!(i.setup(0.0, None), OK);
    let backlash_c = five_axis_plant::EFFECTS.at(4 * 5 + 3).vr() as u32;
    assert_eq!(i.set_reals(&[backlash_c], &[1e-3]), OK);
    assert_eq!(i.enter_init(), OK);
    assert_eq!(i.exit_init(), OK, "{}", i.last_error());
    let linear = Instance::new(&five_axis_plant::INFO);
    linear.start();
    let u_c = five_axis_plant::U.at(4).vr() as u32;
    let pos_c = five_axis_plant::POS.at(4).vr() as u32;
    for (k, instance) in [&i, &linear].into_iter().enumerate() {
        assert_eq!(instance.set_reals(&[u_c], &[0.5]), OK, "{k}");
        for step in 0..200 {
            assert_eq!(instance.step(step as f64 * 1e-3, 1e-3), OK);
        }
    }
    let lag = linear.get_real(pos_c) - i.get_real(pos_c);
    assert!((lag - 0.5e-3).abs() < 1e-9, "{lag}");
}
