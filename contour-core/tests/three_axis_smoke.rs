//! The generic pieces in three dimensions: an XYZ line through the N-axis cross-coupled
//! controller and three linear servo axes in the in-process simulator. Checked against
//! independent references: the line's own geometry (chord F·Ts, samples on the line),
//! the point-to-segment distance written out here, the planar run of the same line, and
//! the axes permuted.

use contour_core::control::CccMode;
use contour_core::geometry::{Vector, Vector2};
use contour_core::path::Line;
use contour_core::plant::{AxisParams, ServoAxesParams};
use contour_core::sim::{SimConfig, SimResult, Simulator};

type V3 = Vector<3>;

const FEED: f64 = 50.0;

fn line3(a: [f64; 3], b: [f64; 3]) -> Line<3> {
    Line::new(a, b).unwrap()
}

/// The run with `mode`, the `slow` axis's position loop at 20 1/s instead of 28.5 1/s:
/// it lags F·d/Kp behind the others for good, so the tool runs parallel to the line, off
/// it, unless the coupling corrects it (its integral removes the offset).
fn run3(line: Line<3>, mode: CccMode, slow: usize) -> SimResult<3> {
    let mut config = SimConfig::new(line, FEED).with_mode(mode);
    config.settle = 0.1;
    config.controller.axis[slow].kp = 20.0;
    Simulator::new(config).unwrap().run()
}

/// Distance from `p` to the segment a–b, written out independently of the library.
fn segment_distance(p: V3, a: V3, b: V3) -> f64 {
    let d = b - a;
    let t = ((p - a).dot(&d) / d.dot(&d)).clamp(0.0, 1.0);
    let q = a + d * t - p;
    (q[0] * q[0] + q[1] * q[1] + q[2] * q[2]).sqrt()
}

#[test]
fn references_lie_on_the_line_one_chord_apart() {
    let (a, b) = (V3::new(1.0, -2.0, 0.5), V3::new(31.0, 18.0, -9.5));
    let config = SimConfig::new(line3(a.into(), b.into()), FEED);
    let sim = Simulator::new(config).unwrap();
    let refs = sim.references();
    let length = (b - a).norm_squared().sqrt();
    // Samples k = 0 … ⌈L / (F·Ts)⌉, the last one clamped to the end.
    assert_eq!(refs.len(), (length / (FEED * 1e-3)).ceil() as usize + 1);
    for (k, s) in refs.iter().enumerate() {
        let expected = a + (b - a) * ((k as f64 * FEED * 1e-3) / length).min(1.0);
        assert!((s.point - expected).amax() < 1e-9, "k={k}");
    }
    assert_eq!(refs.last().unwrap().point, b);
}

#[test]
fn true_error_is_the_distance_to_the_segment_and_ccc_reduces_it() {
    let (a, b) = ([0.0, 0.0, 0.0], [30.0, 20.0, -15.0]);
    let off = run3(line3(a, b), CccMode::Off, 2);
    let on = run3(line3(a, b), CccMode::Fuzzy, 2);
    for result in [&off, &on] {
        let t = &result.trace;
        assert!(result.metrics.is_stable());
        for k in 0..t.len() {
            let d = segment_distance(t.actual[k], a.into(), b.into());
            assert!((t.true_error[k] - d).abs() < 1e-12, "k={k}");
            // Exact line estimator: the estimate is the distance to the infinite line,
            // equal to the truth while the foot lies within the segment.
            assert!(
                t.estimated_error[k].abs() <= t.true_error[k] + 1e-12,
                "k={k}"
            );
        }
    }
    // Without coupling the offset F·d_z·(1/20 − 1/28.5) stays for the whole line; the
    // coupling's integral removes it (as the planar controller does on a line).
    let last_moving = |r: &SimResult<3>| {
        let t = &r.trace;
        let end = V3::from(b);
        (0..t.len()).rev().find(|&k| t.reference[k] != end).unwrap() - 1
    };
    let (e_off, e_on) = (
        off.trace.true_error[last_moving(&off)],
        on.trace.true_error[last_moving(&on)],
    );
    let chord = V3::from(b) - V3::from(a);
    let direction = chord / chord.norm_squared().sqrt();
    let lag = |kp: f64| V3::from_fn(|i, _| FEED * direction[i] / if i == 2 { 20.0 } else { kp });
    let expected = {
        let l = lag(28.5);
        (l - direction * l.dot(&direction)).norm_squared().sqrt()
    };
    assert!(
        (e_off - expected).abs() < 1e-6 * expected,
        "{e_off} vs {expected}"
    );
    assert!(e_on < 1e-9, "with CCC {e_on} mm vs {e_off} mm without");
}

#[test]
fn in_the_xy_plane_the_run_is_the_planar_run() {
    // Z stays at 0 (reference, start and correction), so X and Y must evolve as in the
    // two-axis loop on the same line with the same line estimator: the per-axis law of
    // three dimensions and the scalar law of the plane agree on a line (to rounding).
    let (a, b) = ([2.0, 1.0], [42.0, 31.0]);
    for mode in [CccMode::Off, CccMode::Fixed, CccMode::Fuzzy] {
        let three = {
            let mut c =
                SimConfig::new(line3([a[0], a[1], 0.0], [b[0], b[1], 0.0]), FEED).with_mode(mode);
            c.plant.axes[1].inertia *= 1.5;
            Simulator::new(c).unwrap().run()
        };
        let two = {
            let mut c = SimConfig::new(Line::<2>::new(a, b).unwrap(), FEED).with_mode(mode);
            c.plant.axes[1].inertia *= 1.5;
            Simulator::new(c).unwrap().run()
        };
        assert_eq!(three.trace.len(), two.trace.len());
        for k in 0..two.trace.len() {
            let xy = |v: V3| Vector2::new(v[0], v[1]);
            let close = |x: Vector2, y: Vector2| (x - y).amax() <= 1e-10 * (1.0 + y.amax());
            assert!(
                close(xy(three.trace.actual[k]), two.trace.actual[k]),
                "{mode:?} k={k}"
            );
            assert!(
                close(xy(three.trace.u[k]), two.trace.u[k]),
                "{mode:?} k={k}"
            );
            assert_eq!(three.trace.actual[k][2], 0.0);
            assert_eq!(three.trace.u[k][2], 0.0);
            let (e3, e2) = (three.trace.estimated_error[k], two.trace.estimated_error[k]);
            assert!(
                (e3.abs() - e2.abs()).abs() <= 1e-12,
                "{mode:?} k={k}: {e3} vs {e2}"
            );
        }
        let (m3, m2) = (three.metrics, two.metrics);
        assert!((m3.max_abs_error - m2.max_abs_error).abs() < 1e-12);
        assert!((m3.mean_abs_error - m2.mean_abs_error).abs() < 1e-12);
    }
}

#[test]
fn permuting_the_axes_permutes_the_run() {
    // No axis is special: the line and the plant with their axes reordered (x, y, z) →
    // (z, x, y) give the same run with the coordinates reordered (to rounding: sums over
    // the axes are taken in another order).
    let perm = |v: V3| V3::new(v[2], v[0], v[1]);
    let (a, b) = (V3::new(0.0, 5.0, -3.0), V3::new(25.0, -10.0, 12.0));
    let slow = AxisParams {
        inertia: 1.5 * AxisParams::PAPER.inertia,
        ..AxisParams::PAPER
    };
    let plant = ServoAxesParams {
        axes: [AxisParams::PAPER, slow, AxisParams::PAPER],
    };
    let permuted_plant = ServoAxesParams {
        axes: [plant.axes[2], plant.axes[0], plant.axes[1]],
    };
    let run = |line: Line<3>, plant| {
        let mut c = SimConfig::new(line, FEED);
        c.plant = plant;
        Simulator::new(c).unwrap().run()
    };
    let original = run(line3(a.into(), b.into()), plant);
    let permuted = run(line3(perm(a).into(), perm(b).into()), permuted_plant);
    assert_eq!(original.trace.len(), permuted.trace.len());
    for k in 0..original.trace.len() {
        let close = |x: V3, y: V3| (x - y).amax() <= 1e-12 * (1.0 + x.amax());
        assert!(
            close(perm(original.trace.actual[k]), permuted.trace.actual[k]),
            "k={k}"
        );
        assert!(
            close(perm(original.trace.u[k]), permuted.trace.u[k]),
            "k={k}"
        );
    }
}
