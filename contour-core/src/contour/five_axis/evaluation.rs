//! The paper's evaluation-function estimate of the five-axis contour errors at one
//! reference point (docs/design/five-axis.md §5.3): the actual joints near the point are fitted by
//! parabolas, the fit is mapped through the forward kinematics, and the point of the fit
//! that minimises
//!   F(t) = λ1·‖p(t) − R_i‖ + λ2·R·∠(o(t), O_i)
//! gives the tip error ‖p(t*) − R_i‖ and the orientation error ∠(o(t*), O_i).

use crate::geometry;
use crate::geometry::angle_between;
use crate::kinematics::{Joints, Pose, TableTiltingAc};
use crate::math;

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

/// How closely t* is found. At the minimum F is flat: a step δt changes F by ½F''·δt²,
/// and F's rounding (≈ 10⁻¹⁸ mm) hides steps below ~10⁻⁹, where a finer tolerance only
/// makes the search thrash. The errors at t* move by ~10⁻¹² (mm, rad) over 10⁻⁸.
/// Half-width of the first three points around the guess, in t (1 = one sample): wide
/// enough that F²'s rounding does not disturb the first parabola, narrow enough that it
/// fits the minimum.
const GUESS_SPAN: f64 = 0.05;

const T_TOLERANCE: f64 = 1e-7;

/// Minimises F over the parabolic fit of `q` (three consecutive actual joint samples,
/// the middle one nearest the reference point): F at the three samples and at the
/// reference tip's foot on the fit's tangent, then Brent's method on t ∈ [−1, 1] from
/// those to |Δt| ≤ [`T_TOLERANCE`] (about 10 evaluations in all; each is a forward
/// kinematics, the cost of the estimate).
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
    // F², squared because F is nearly V-shaped
    // (a distance to a point passing by), which parabolic steps fit badly, while F² is
    // nearly a parabola; both have the same minimiser.
    let pose_at = |t: f64| machine.forward(&parabola(q, t));
    let squared = |pose: &Pose| {
        let cross = pose.axis.cross(&reference.axis);
        let angle = math::atan2(geometry::norm(&cross), pose.axis.dot(&reference.axis));
        let tip = geometry::dist(&pose.tip, &reference.tip);
        let value = lambda.0 * tip + lambda.1 * mm_per_rad * angle;
        value * value
    };
    let f = |t: f64| squared(&pose_at(t));
    let (before, middle, after) = (pose_at(-1.0), pose_at(0.0), pose_at(1.0));
    // A first guess: the reference tip's foot on the tangent of the fit at t = 0.
    let velocity = (after.tip - before.tip) * 0.5;
    let speed2 = velocity.norm_squared();
    let guess = if speed2 > 0.0 {
        ((reference.tip - middle.tip).dot(&velocity) / speed2).clamp(-1.0, 1.0)
    } else {
        0.0
    };
    // F² near the guess is close to a parabola: two more points either side seed it.
    let side = |t: f64| {
        let t = t.clamp(-1.0, 1.0);
        (t, f(t))
    };
    let mut points = [
        side(guess),
        side(guess - GUESS_SPAN),
        side(guess + GUESS_SPAN),
    ];
    points.sort_by(|a, b| a.1.total_cmp(&b.1));
    let t = brent_minimum(f, (-1.0, 1.0), points, T_TOLERANCE);
    let (tip, orientation) = errors(t);
    Evaluation {
        tip,
        orientation,
        t,
    }
}

/// Brent's method: the minimum of `f` on `bracket`, to an absolute tolerance `tol` in t,
/// from three points (t, f(t)) already evaluated, the best first (x, then w and v of the
/// method). Parabolic steps through the three best points while they behave, golden-section
/// steps otherwise, so it converges superlinearly on a smooth minimum and never worse than
/// golden section; with three distinct points the first step is already parabolic.
fn brent_minimum(
    f: impl Fn(f64) -> f64,
    bracket: (f64, f64),
    points: [(f64, f64); 3],
    tol: f64,
) -> f64 {
    const GOLDEN: f64 = 0.381_966_011_250_105_2; // (3 − √5)/2
    let (mut a, mut b) = bracket;
    // x: the best point; w: the second best; v: the previous w.
    let [(mut x, mut fx), (mut w, mut fw), (mut v, mut fv)] = points;
    // d: the last step; e: the step before it (a parabolic step must halve it): the
    // bracket's width lets the first one be parabolic.
    let (mut d, mut e) = (b - a, b - a);
    for _ in 0..100 {
        let middle = 0.5 * (a + b);
        if (x - middle).abs() <= 2.0 * tol - 0.5 * (b - a) {
            break;
        }
        let mut parabolic = false;
        if e.abs() > tol {
            let r = (x - w) * (fx - fv);
            let mut q = (x - v) * (fx - fw);
            let mut p = (x - v) * q - (x - w) * r;
            q = 2.0 * (q - r);
            if q > 0.0 {
                p = -p;
            } else {
                q = -q;
            }
            let before = e;
            e = d;
            if p.abs() < (0.5 * q * before).abs() && p > q * (a - x) && p < q * (b - x) {
                d = p / q;
                let u = x + d;
                if u - a < 2.0 * tol || b - u < 2.0 * tol {
                    d = tol.copysign(middle - x);
                }
                parabolic = true;
            }
        }
        if !parabolic {
            e = if x >= middle { a - x } else { b - x };
            d = GOLDEN * e;
        }
        let u = if d.abs() >= tol {
            x + d
        } else {
            x + tol.copysign(d)
        };
        let fu = f(u);
        // A parabolic step this short means x has converged (on a smooth minimum the
        // bracket would shrink to it only a tolerance-sized step at a time).
        let converged = parabolic && d.abs() <= tol;
        if fu <= fx {
            if u >= x {
                a = x;
            } else {
                b = x;
            }
            (v, fv) = (w, fw);
            (w, fw) = (x, fx);
            (x, fx) = (u, fu);
        } else {
            if u < x {
                a = u;
            } else {
                b = u;
            }
            if fu <= fw || w == x {
                (v, fv) = (w, fw);
                (w, fw) = (u, fu);
            } else if fu <= fv || v == x || v == w {
                (v, fv) = (u, fu);
            }
        }
        if converged {
            break;
        }
    }
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::geometry::Vector;

    type V3 = Vector<3>;

    #[test]
    fn brent_finds_smooth_and_kinked_minima_in_few_evaluations() {
        type Case = (fn(f64) -> f64, f64);
        let cases: [Case; 4] = [
            (|t| (t - 0.3).powi(2) + 1.0, 0.3),
            (|t| math::cosh(t - 0.123), 0.123),
            (|t| (t + 0.07).abs() + 0.2 * t * t, -0.07),
            (|t| ((t - 0.01).powi(2) + 1e-6).sqrt(), 0.01),
        ];
        for (f, expected) in cases {
            let calls = std::cell::Cell::new(0);
            let counted = |t: f64| {
                calls.set(calls.get() + 1);
                f(t)
            };
            let (lo, hi) = (-0.125, 0.375);
            let (x, y) = if f(0.0) < f(0.25) {
                (0.0, 0.25)
            } else {
                (0.25, 0.0)
            };
            let points = [(x, f(x)), (y, f(y)), (lo, f(lo))];
            let t = brent_minimum(counted, (lo, hi), points, 1e-9);
            assert!((t - expected).abs() < 1e-8, "{t} vs {expected}");
            assert!(calls.get() <= 60, "{} evaluations", calls.get());
        }
    }

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
            axis: V3::new(math::sin(angle), 0.0, math::cos(angle)),
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
            e.tip > 0.0 && e.tip <= math::hypot(0.02f64, 0.01) + 1e-12,
            "{}",
            e.tip
        );
    }
}
