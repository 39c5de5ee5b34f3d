//! The paper's evaluation-function estimate of the five-axis contour errors at one
//! reference point (docs/design.md §5.3): the actual joints near the point are fitted by
//! parabolas, the fit is mapped through the forward kinematics, and the point of the fit
//! that minimises
//!   F(t) = λ1·‖p(t) − R_i‖ + λ2·R·∠(o(t), O_i)
//! gives the tip error ‖p(t*) − R_i‖ and the orientation error ∠(o(t*), O_i).

use super::hmm::angle_between;
use crate::geometry;
use crate::kinematics::{Joints, Pose, TableTiltingAc};

/// mm of tip travel per rad of tool rotation over a whole reference (R of §5.3): makes
/// angles commensurable with lengths by the part's own ratio. 0 when the tool never turns.
pub fn mm_per_rad(reference: &[Pose]) -> f64 {
    let (mut travel, mut turn) = (0.0, 0.0);
    for w in reference.windows(2) {
        travel += geometry::dist(&w[1].tip, &w[0].tip);
        turn += angle_between(&w[1].axis, &w[0].axis);
    }
    if turn > 0.0 {
        travel / turn
    } else {
        0.0
    }
}

/// The weights (λ1, λ2) at a reference point from its neighbours: where the tip moves
/// fast and the tool hardly turns the tip distance dominates, and the reverse.
pub fn weights(before: &Pose, after: &Pose, mm_per_rad: f64) -> (f64, f64) {
    let vp = 0.5 * geometry::dist(&after.tip, &before.tip);
    let vo = 0.5 * mm_per_rad * angle_between(&after.axis, &before.axis);
    if vp + vo > 0.0 {
        (vp / (vp + vo), vo / (vp + vo))
    } else {
        (1.0, 0.0)
    }
}

/// The joints on the parabola through q(−1), q(0), q(1) at `t`.
pub fn parabola(q: &[Joints; 3], t: f64) -> Joints {
    let [qm, q0, qp] = q;
    q0 + (qp - qm) * (0.5 * t) + (qp - q0 * 2.0 + qm) * (0.5 * t * t)
}

/// The estimate at one reference point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Evaluation {
    /// Tip contour error, mm.
    pub tip: f64,
    /// Orientation contour error, rad.
    pub orientation: f64,
    /// Where on the fit, t ∈ [−1, 1].
    pub t: f64,
}

/// Minimises F over the parabolic fit of `q` (three consecutive actual joint samples,
/// the middle one nearest the reference point): a scan of 64 points, then golden-section
/// search in the best scan interval to |Δt| ≤ 1e-9.
pub fn evaluate(
    machine: &TableTiltingAc,
    reference: &Pose,
    lambda: (f64, f64),
    mm_per_rad: f64,
    q: &[Joints; 3],
) -> Evaluation {
    let errors = |t: f64| {
        let pose = machine.forward(&parabola(q, t));
        (
            geometry::dist(&pose.tip, &reference.tip),
            angle_between(&pose.axis, &reference.axis),
        )
    };
    let f = |t: f64| {
        let (tip, angle) = errors(t);
        lambda.0 * tip + lambda.1 * mm_per_rad * angle
    };
    const SCAN: usize = 64;
    let at = |k: usize| -1.0 + 2.0 * k as f64 / SCAN as f64;
    let best = (0..=SCAN).fold(0, |b, k| if f(at(k)) < f(at(b)) { k } else { b });
    let (mut lo, mut hi) = (at(best.saturating_sub(1)), at((best + 1).min(SCAN)));
    let g = 0.5 * (5f64.sqrt() - 1.0);
    let (mut x1, mut x2) = (hi - g * (hi - lo), lo + g * (hi - lo));
    let (mut f1, mut f2) = (f(x1), f(x2));
    while hi - lo > 1e-9 {
        if f1 <= f2 {
            hi = x2;
            (x2, f2) = (x1, f1);
            x1 = hi - g * (hi - lo);
            f1 = f(x1);
        } else {
            lo = x1;
            (x1, f1) = (x2, f2);
            x2 = lo + g * (hi - lo);
            f2 = f(x2);
        }
    }
    let t = 0.5 * (lo + hi);
    let (tip, orientation) = errors(t);
    Evaluation {
        tip,
        orientation,
        t,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::geometry::Vector;

    type V3 = Vector<3>;

    #[test]
    fn the_parabola_passes_through_its_three_points() {
        let q = [
            Joints::new(1.0, 2.0, 3.0, 0.1, 0.2),
            Joints::new(2.0, 2.5, 2.0, 0.15, 0.1),
            Joints::new(4.0, 2.0, 2.0, 0.3, -0.1),
        ];
        for (t, expected) in [(-1.0, q[0]), (0.0, q[1]), (1.0, q[2])] {
            assert!((parabola(&q, t) - expected).amax() < 1e-15);
        }
    }

    #[test]
    fn weights_and_ratio_by_hand() {
        let pose = |x: f64, angle: f64| Pose {
            tip: V3::new(x, 0.0, 0.0),
            axis: V3::new(angle.sin(), 0.0, angle.cos()),
        };
        let path = [pose(0.0, 0.0), pose(3.0, 0.1), pose(6.0, 0.3)];
        assert!((mm_per_rad(&path) - 6.0 / 0.3).abs() < 1e-12);
        // Neighbours 6 mm and 0.3 rad apart: v_p = 3, v_o = 20·0.15 = 3.
        let (l1, l2) = weights(&path[0], &path[2], 20.0);
        assert!((l1 - 0.5).abs() < 1e-12 && (l2 - 0.5).abs() < 1e-12);
        assert_eq!(weights(&path[0], &path[0], 20.0), (1.0, 0.0));
    }

    #[test]
    fn matches_a_dense_brute_force_minimisation_of_the_same_f() {
        let machine = TableTiltingAc::default();
        let q = [
            Joints::new(9.0, 1.0, 30.0, 0.30, 0.50),
            Joints::new(10.0, 1.4, 30.2, 0.32, 0.52),
            Joints::new(11.0, 1.6, 30.3, 0.35, 0.55),
        ];
        // A reference point near the fitted motion.
        let mut target = machine.forward(&parabola(&q, 0.37));
        target.tip += V3::new(0.0, 0.02, -0.01);
        target.axis = geometry::unit(&(target.axis + V3::new(0.003, 0.0, 0.0))).unwrap();
        for lambda in [(1.0, 0.0), (0.5, 0.5), (0.1, 0.9)] {
            let e = evaluate(&machine, &target, lambda, 30.0, &q);
            let f = |t: f64| {
                let pose = machine.forward(&parabola(&q, t));
                lambda.0 * geometry::dist(&pose.tip, &target.tip)
                    + lambda.1 * 30.0 * angle_between(&pose.axis, &target.axis)
            };
            let n = 200_000;
            let brute = (0..=n)
                .map(|k| -1.0 + 2.0 * k as f64 / n as f64)
                .fold(f64::INFINITY, |m, t| m.min(f(t)));
            assert!(f(e.t) <= brute + 1e-12, "{lambda:?}: {} vs {brute}", f(e.t));
            assert!(e.t > 0.2 && e.t < 0.5, "{lambda:?}: t = {}", e.t);
        }
        // Tip only: F is the distance from R_i to the fitted tip curve, no more than the
        // offset that moved R_i off the curve.
        let e = evaluate(&machine, &target, (1.0, 0.0), 30.0, &q);
        assert!(
            e.tip > 0.0 && e.tip <= 0.02f64.hypot(0.01) + 1e-12,
            "{}",
            e.tip
        );
    }
}
