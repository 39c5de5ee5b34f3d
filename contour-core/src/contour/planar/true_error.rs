//! True contour error: the signed distance from P to the exact path (docs/design/two-axis.md §4.1 ground
//! truth), with the estimators' sign convention (positive right of travel, normal = left
//! unit normal at the foot point).
//!
//! Here, the exact distance to each kind of piece, and [`true_error`]: the global brute
//! force over a whole path, dense sampling then safeguarded Newton refinement of every
//! promising local minimum. Slow (thousands of evaluations per query) but simple: the
//! reference for tests. [`TrueErrorIndex`](super::TrueErrorIndex) gives the same answer
//! fast, for closed loops.
//!
//! Lines and arcs are solved analytically (the finite segment/arc: beyond its ends the
//! nearest end point is the foot).

use crate::math;

use serde::{Deserialize, Serialize};

use crate::contour::ContourEstimate;
use crate::geometry::{self, Vector, Vector2};
use crate::path::planar::{CornerBlend, Path, Program, Shape};
use crate::path::{CircularArc, Curve, CurvePoint, Line, Nurbs};

/// Exact contour error of one point.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct TrueError<const D: usize = 2> {
    /// Distance to the path, mm; for a planar [`Path`] signed, positive right of travel
    /// (a path type without sides, e.g. a spatial line, reports the distance).
    pub error: f64,
    /// Unit direction with `error · normal` from the point to the foot point (in the
    /// plane: the path's left unit normal there).
    pub normal: Vector<D>,
    /// Curve parameter of the foot point.
    pub u: f64,
    /// Foot point (nearest point of the path).
    pub foot: Vector<D>,
}

impl<const D: usize> TrueError<D> {
    /// As an estimator result.
    pub fn estimate(&self) -> ContourEstimate<D> {
        ContourEstimate {
            error: self.error,
            normal: self.normal,
        }
    }
}

/// Global brute-force true contour error of `p` against `path`.
pub fn true_error(path: &Path, p: Vector2) -> TrueError {
    match path {
        Path::Line(l) => line_true_error(l, p),
        Path::Arc(a) => arc_true_error(a, p),
        Path::Nurbs(n) => at_kink(n, p, curve_true_error(n, p)),
        Path::Program(program) => (0..program.moves().len())
            .map(|i| move_true_error(program, i, p, WHOLE, f64::NAN))
            .fold(None, |best: Option<TrueError>, e| match best {
                Some(b) if b.error.abs() <= e.error.abs() => Some(b),
                _ => Some(e),
            })
            .expect("a program has a move"),
    }
}

/// A parameter interval [t₀, t₁] the foot is sought in.
pub(super) type Span = (f64, f64);

/// All of a move or a line or an arc.
pub(super) const WHOLE: Span = (0.0, 1.0);

/// Exact distance to move `i` of a program, its foot within the move's own parameters
/// `span` and reported as the path position s.
/// Where the foot is a corner's vertex (the move's end, shared with the next move, or
/// its start, shared with the one before; on a closed program also the start and the end)
/// the point is as far from both moves, and the side is judged against the bisector of
/// the two tangents: against either one alone, a point beyond a corner that turns by
/// more than 90° would be on the wrong side.
pub(super) fn move_true_error(
    program: &Program,
    i: usize,
    p: Vector2,
    span: Span,
    guess: f64,
) -> TrueError {
    let moves = program.moves();
    let mut e = match &moves[i].shape {
        Shape::Line(l) => line_error_within(l, p, span),
        Shape::Arc(a) => arc_error_within(a, p, span),
        Shape::Blend(b) => blend_error_within(b, p, span, guess),
    };
    let last = moves.len() - 1;
    // Only asked at an end of the first or last move.
    let closed =
        || last > 0 && moves[0].shape.curve().point(0.0) == moves[last].shape.curve().point(1.0);
    let neighbour = match e.u {
        u if u == 1.0 && i < last => Some((i, i + 1)),
        u if u == 1.0 && closed() => Some((i, 0)),
        u if u == 0.0 && i > 0 => Some((i - 1, i)),
        u if u == 0.0 && closed() => Some((last, i)),
        _ => None,
    };
    if let Some((before, after)) = neighbour {
        let (t0, t1) = (
            moves[before].shape.end_tangent(1),
            moves[after].shape.end_tangent(0),
        );
        e = signed_at_corner(p, e, t0, t1);
    }
    e.u = program.position(i, e.u);
    e
}

/// `e`, whose foot is a corner between unit tangents `before` and `after`, signed against
/// their bisector: against either one alone, a point beyond a corner that turns by more
/// than 90° would be on the wrong side. A reversal has no bisector: `e` stands.
fn signed_at_corner(p: Vector2, mut e: TrueError, before: Vector2, after: Vector2) -> TrueError {
    let bisector = before + after;
    let length = geometry::norm(&bisector);
    if length > 1e-9 {
        let here = signed(p, e.foot, bisector * (1.0 / length), e.u);
        e.error = here.error;
        e.normal = here.normal;
    }
    e
}

/// Samples over a right-angle corner blend's span before the refinement; a blend that
/// turns less gets as many per radian (at least 2), one that turns more no more.
const BLEND_SAMPLES: usize = 8;

/// Exact distance to the part `span` of a corner blend: the best of its samples, then
/// safeguarded Newton in the bracket around it (a blend is short and turns by less than
/// π: one minimum near the path). The samples are no farther apart in turn than a right
/// angle's eight: a blend of a small turn, nearly straight, needs few (most of the
/// corners of a program of short lines, where the nearest point costs mostly these).
///
/// With a `guess` (the foot's expected parameter; NaN for none) on a blend where the
/// squared distance to `p` is convex, Newton starts at the guess instead (see
/// [`convex_around`]): one minimum, no samples needed.
fn blend_error_within(b: &CornerBlend, p: Vector2, (t0, t1): Span, guess: f64) -> TrueError {
    if guess.is_finite() && convex_around(b, p) {
        let (u, at) = newton(b, p, (t0, t1), guess.clamp(t0, t1), Convexity::Convex);
        return finish_at(b, at, p, u);
    }
    let samples = ((BLEND_SAMPLES as f64 * b.turn().abs() / std::f64::consts::FRAC_PI_2).ceil()
        as usize)
        .clamp(2, BLEND_SAMPLES);
    let at = |k: usize| t0 + (t1 - t0) * k as f64 / samples as f64;
    let mut d2 = [0.0; BLEND_SAMPLES + 1];
    for (k, d) in d2.iter_mut().enumerate().take(samples + 1) {
        *d = geometry::dist2(&b.point(at(k)), &p);
    }
    let nearest = (0..=samples)
        .min_by(|&i, &j| d2[i].total_cmp(&d2[j]))
        .unwrap_or(0);
    let (below, above) = (nearest.saturating_sub(1), (nearest + 1).min(samples));
    let (lo, hi) = (at(below), at(above));
    // Newton starts at the vertex of the parabola through the squared distances of the
    // nearest sample and its neighbours (two or three iterations fewer than from the
    // sample itself).
    let mut start = at(nearest);
    if 0 < nearest && nearest < samples {
        let (g0, g1, g2) = (d2[nearest - 1], d2[nearest], d2[nearest + 1]);
        let curvature = g0 - 2.0 * g1 + g2;
        if curvature > 0.0 {
            let h = (t1 - t0) / samples as f64;
            let vertex = start - 0.5 * h * (g2 - g0) / curvature;
            if vertex > lo && vertex < hi {
                start = vertex;
            }
        }
    }
    // The iterate or a bracket end, whichever is nearer; the iterate's evaluation
    // serves the result too.
    let (u, at) = newton(b, p, (lo, hi), start, Convexity::Unknown);
    if geometry::dist2(&at.p, &p) <= d2[below].min(d2[above]) {
        finish_at(b, at, p, u)
    } else {
        let end = if d2[below] <= d2[above] { lo } else { hi };
        finish(b, p, end)
    }
}

/// The squared distance from `p` is convex along all of blend `b`: its second derivative
/// along the arc length, 1 + (C − p)·C'', is at least 1 − κ·|C − p|, and |C − p| is at
/// most the distance to the farthest corner of the triangle that holds the blend (its
/// ends and vertex). Then the distance has one minimum on any span of the blend, which
/// safeguarded Newton finds from anywhere in it. True for a tool near a gentle blend (a
/// program of short lines), false near a sharp one (a tool farther than its radius).
fn convex_around(b: &CornerBlend, p: Vector2) -> bool {
    let far2 = b
        .hull()
        .iter()
        .map(|h| geometry::dist2(h, &p))
        .fold(0.0, f64::max);
    let k = b.peak_curvature();
    // κ·|C − p| below 0.87, not 1: a margin for rounding.
    k * k * far2 < 0.75
}

/// Samples per smooth piece in the brute force.
const BRUTE_SAMPLES: usize = 256;

/// Global brute force for any [`Curve`]: dense sampling + Newton refinement.
pub fn curve_true_error<C: Curve + ?Sized>(c: &C, p: Vector2) -> TrueError {
    let bps = c.breakpoints();
    // Dense samples (parameter, distance) over every smooth piece.
    let mut us = Vec::with_capacity(bps.len() * BRUTE_SAMPLES);
    for w in bps.windows(2) {
        for i in 0..BRUTE_SAMPLES {
            us.push(w[0] + (w[1] - w[0]) * i as f64 / BRUTE_SAMPLES as f64);
        }
    }
    us.push(*bps.last().unwrap_or(&c.param_range().1));
    let pts: Vec<Vector2> = us.iter().map(|&u| c.point(u)).collect();
    let ds: Vec<f64> = pts.iter().map(|&q| geometry::dist(&q, &p)).collect();
    let max_chord = pts
        .windows(2)
        .map(|w| geometry::dist(&w[0], &w[1]))
        .fold(0.0, f64::max);
    let dmin = ds.iter().cloned().fold(f64::INFINITY, f64::min);
    let n = us.len();
    let mut best = (f64::INFINITY, us[0]);
    for i in 0..n {
        let lower = i == 0 || ds[i] <= ds[i - 1];
        let upper = i + 1 == n || ds[i] <= ds[i + 1];
        // A true minimum inside a sample bracket is at most one chord below the samples.
        if lower && upper && ds[i] <= dmin + max_chord {
            // Each side of the sample on its own: the sample may be a knot.
            let a = us[i.saturating_sub(1)];
            let b = us[(i + 1).min(n - 1)];
            let middle = |x: f64, y: f64| 0.5 * (x + y);
            for r in [
                refine(c, p, a, us[i], middle(a, us[i])),
                refine(c, p, us[i], b, us[i]),
            ] {
                if r.0 < best.0 {
                    best = r;
                }
            }
        }
    }
    finish(c, p, best.1)
}

/// Minimises |C(u) − P| over [a, b] starting from `u`: safeguarded Newton on
/// f(u) = (C − P)·C' with bisection fallback; also compares the bracket ends.
/// Returns (distance, parameter).
///
/// The iterates after the start stay strictly inside the bracket. The bracket's upper
/// end may be a knot where the curve kinks, and C' there is the next span's, which would
/// stop the search at the knot (a degree-1 NURBS's corner, found planning issue 23's
/// square as a NURBS): callers never start there on a NURBS.
pub(super) fn refine<C: Curve + ?Sized>(
    c: &C,
    p: Vector2,
    a0: f64,
    b0: f64,
    u0: f64,
) -> (f64, f64) {
    // Evaluated again: a NURBS's knot, where it may kink, can lie within the last step.
    let (u, _) = newton(c, p, (a0, b0), u0, Convexity::Unknown);
    let mut best = (geometry::dist2(&c.point(u), &p), u);
    for v in [a0, b0] {
        let d = geometry::dist2(&c.point(v), &p);
        if d < best.0 {
            best = (d, v);
        }
    }
    (best.0.sqrt(), best.1)
}

/// What [`newton`] may assume of the squared distance along its bracket.
#[derive(Clone, Copy, PartialEq)]
enum Convexity {
    /// Unknown: the caller compares the iterate with the bracket's ends.
    Unknown,
    /// Convex ([`convex_around`]): one minimum, at an end where the derivative does not
    /// change sign.
    Convex,
}

/// The safeguarded Newton iteration of [`refine`] in the bracket (a0, b0) from `u0`:
/// its last iterate and the curve there. The iteration stops once its step is below
/// 10⁻¹⁵ of the parameter (or forecast to be). The curve at the last iterate is the
/// last evaluation carried over the last step by its Taylor series to second order
/// where that step is below 10⁻⁹ of the bracket (off by about step³ times the third
/// derivative: far below rounding on a smooth curve, a blend, and one evaluation
/// cheaper); after a longer one it is evaluated.
///
/// Where the distance is [`Convexity::Convex`], the first Newton step out of the bracket
/// is checked at that end: where the derivative there has the sign it has here, it
/// keeps that sign in between and the minimum is the end (bisection would creep to it,
/// one halving at a time).
fn newton<C: Curve + ?Sized>(
    c: &C,
    p: Vector2,
    (a0, b0): (f64, f64),
    u0: f64,
    convexity: Convexity,
) -> (f64, CurvePoint) {
    let (mut a, mut b, mut u) = (a0, b0, u0);
    let mut e = c.eval(u);
    let mut evaluated_at = u;
    // The last Newton step (not a bisection), for the convergence forecast.
    let mut last_newton = f64::NAN;
    // Each end of the bracket is checked once.
    let mut ends_checked = convexity == Convexity::Unknown;
    for iteration in 0..64 {
        if iteration > 0 {
            e = c.eval(u);
            evaluated_at = u;
        }
        let q = e.p - p;
        let f = q.dot(&e.d1);
        if f == 0.0 {
            break;
        }
        let fp = e.d1.dot(&e.d1) + q.dot(&e.d2);
        if f > 0.0 {
            b = u;
        } else {
            a = u;
        }
        let mut un = if fp > 0.0 { u - f / fp } else { f64::NAN };
        let inside = un > a0 && un < b0;
        if !(ends_checked || inside) {
            ends_checked = true;
            let end = if f > 0.0 { a0 } else { b0 };
            let at_end = c.eval(end);
            if (at_end.p - p).dot(&at_end.d1) * f >= 0.0 {
                return (end, at_end);
            }
        }
        let newton = un > a && un < b;
        if !newton {
            un = 0.5 * (a + b);
        }
        let tol = 1e-15 * (1.0 + u.abs());
        let step = (un - u).abs();
        u = un;
        if step <= tol || b - a <= tol {
            break;
        }
        // Quadratic convergence, seen in two Newton steps (the second a thousandth of
        // the first or less), leaves an error of about step³/last² after this one:
        // below the tolerance, the evaluation that would only confirm it is saved.
        let forecast = step * step * step;
        if newton && step <= 1e-3 * last_newton && forecast <= tol * last_newton * last_newton {
            break;
        }
        last_newton = if newton { step } else { f64::NAN };
    }
    let h = u - evaluated_at;
    if h.abs() > 1e-9 * (b0 - a0) {
        return (u, c.eval(u));
    }
    let carried = CurvePoint {
        p: e.p + e.d1 * h + e.d2 * (0.5 * h * h),
        d1: e.d1 + e.d2 * h,
        d2: e.d2,
    };
    (u, carried)
}

/// `e` signed again where its foot is a NURBS's kink (an interior knot where the tangent
/// turns): against the bisector of the tangents from below and above, as a program's
/// corner is ([`move_true_error`]); the next span's tangent alone puts a point beyond a
/// corner of more than 90° on the wrong side.
pub(super) fn at_kink(n: &Nurbs, p: Vector2, e: TrueError) -> TrueError {
    let (a, b) = n.param_range();
    if !(e.u > a && e.u < b && n.knots().contains(&e.u)) {
        return e;
    }
    let unit = |d: Vector2| {
        let l = geometry::norm(&d);
        (l > 0.0).then(|| d * (1.0 / l))
    };
    let (Some(before), Some(after)) = (unit(n.eval_from_below(e.u).d1), unit(n.eval(e.u).d1))
    else {
        return e;
    };
    // A smooth knot needs no bisector.
    if geometry::cross(&before, &after).abs() > 1e-12 {
        signed_at_corner(p, e, before, after)
    } else {
        e
    }
}

/// Builds the result at foot parameter `u`.
pub(super) fn finish<C: Curve + ?Sized>(c: &C, p: Vector2, u: f64) -> TrueError {
    finish_at(c, c.eval(u), p, u)
}

/// [`finish`] with the curve already evaluated at `u`.
fn finish_at<C: Curve + ?Sized>(c: &C, e: CurvePoint, p: Vector2, u: f64) -> TrueError {
    let mut t = e.d1;
    let mut tl = geometry::norm(&t);
    if tl < 1e-12 {
        // Degenerate speed (repeated control points): use a short secant instead.
        let (lo, hi) = c.param_range();
        let h = 1e-7 * (hi - lo);
        t = c.point((u + h).min(hi)) - c.point((u - h).max(lo));
        tl = geometry::norm(&t);
    }
    let t = if tl > 0.0 {
        t * (1.0 / tl)
    } else {
        Vector2::new(1.0, 0.0)
    };
    signed(p, e.p, t, u)
}

pub(super) fn signed(p: Vector2, foot: Vector2, t: Vector2, u: f64) -> TrueError {
    let q = p - foot;
    let dist = geometry::norm(&q);
    let side = -geometry::cross(&t, &q);
    TrueError {
        error: dist.copysign(side),
        normal: geometry::perp(&t),
        u,
        foot,
    }
}

/// Exact distance to a finite segment.
pub(super) fn line_true_error(l: &Line, p: Vector2) -> TrueError {
    line_error_within(l, p, WHOLE)
}

/// Exact distance to the part `span` of a segment.
pub(super) fn line_error_within(l: &Line, p: Vector2, (t0, t1): Span) -> TrueError {
    let u = l.nearest_parameter(&p).clamp(t0, t1);
    signed(p, l.point(u), l.direction(), u)
}

/// Exact distance to a finite arc.
pub(super) fn arc_true_error(arc: &CircularArc, p: Vector2) -> TrueError {
    arc_error_within(arc, p, WHOLE)
}

/// Exact distance to the part `span` of an arc: the radial foot when it lies in the
/// span (on a full circle the start angle is both 0 and 1), else the nearer end of it
/// (the distance to a circle's points grows with the angle from the radial foot).
pub(super) fn arc_error_within(arc: &CircularArc, p: Vector2, (t0, t1): Span) -> TrueError {
    let o = arc.center();
    let d = p - o;
    let r = geometry::norm(&d);
    let radial = if r > 0.0 {
        arc.param_of_angle(math::atan2(d[1], d[0]))
    } else {
        Some(t0)
    };
    let inside = |u: f64| (t0..=t1).contains(&u);
    let within = match radial {
        Some(u) if inside(u) => Some(u),
        Some(u) if arc.is_full_circle() && inside(u + 1.0) => Some(u + 1.0),
        _ => None,
    };
    let u = match within {
        Some(u) => u,
        None => {
            if geometry::dist(&arc.point(t0), &p) <= geometry::dist(&arc.point(t1), &p) {
                t0
            } else {
                t1
            }
        }
    };
    let e = arc.eval(u);
    let t = e.d1 * (1.0 / geometry::norm(&e.d1));
    let mut res = signed(p, e.p, t, u);
    if within.is_some() {
        // Radial formula: exact sign even at the centre (where q ∥ n gives side 0 issues).
        let err = if arc.is_ccw() {
            r - arc.radius()
        } else {
            arc.radius() - r
        };
        res.error = err;
    }
    res
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contour::planar::TrueErrorIndex;
    use crate::path::planar::builtin;
    use std::f64::consts::PI;

    #[test]
    fn a_degree_one_nurbs_is_measured_to_its_edges_near_a_corner() {
        // A 20 mm square as a polygon NURBS: points on and just inside the bottom edge
        // near the corner (20, 0), whose nearest sample is the knot there. The knot's
        // derivative is the next edge's, which once stopped the search at the corner.
        let square = Path::Nurbs(
            crate::path::Nurbs::new(
                1,
                crate::path::clamped_uniform_knots(5, 1),
                vec![
                    [0.0, 0.0],
                    [20.0, 0.0],
                    [20.0, 20.0],
                    [0.0, 20.0],
                    [0.0, 0.0],
                ],
                None,
            )
            .unwrap(),
        );
        let index = TrueErrorIndex::new(&square);
        for k in 0..200 {
            let x = 19.9 + 0.0005 * k as f64;
            for y in [0.0f64, 0.001, 0.01] {
                // Inside the square, left of travel: negative, the edge or the right
                // side the nearer.
                let want = -(y.min(20.0 - x));
                for e in [
                    true_error(&square, Vector2::new(x, y)),
                    index.error(Vector2::new(x, y), 0.0),
                ] {
                    assert!(
                        (e.error - want).abs() < 1e-12,
                        "({x}, {y}): {} vs {want}",
                        e.error
                    );
                }
            }
        }
    }

    #[test]
    fn a_point_beyond_a_sharp_corner_is_signed_by_the_bisector_and_ties_go_to_the_earlier_move() {
        // A corner of 153° as a polygon NURBS and as G-code: beyond its tip both put the
        // point right of travel (the bisector's side; the next edge's tangent alone says
        // left). Found in review.
        let polygon = Path::Nurbs(
            crate::path::Nurbs::new(
                1,
                crate::path::clamped_uniform_knots(3, 1),
                vec![[0.0, 0.0], [10.0, 0.0], [0.0, 5.0]],
                None,
            )
            .unwrap(),
        );
        let program = Path::Program(
            crate::path::planar::Program::parse_gcode("G1 X10 F600\nX0 Y5\n", "tip.ngc").unwrap(),
        );
        let p = Vector2::new(11.0, -0.8);
        let want = math::hypot(1.0f64, 0.8);
        for path in [&polygon, &program] {
            let index = TrueErrorIndex::new(path);
            for e in [
                true_error(path, p),
                index.error(p, 0.0),
                index.error(p, 1e9),
            ] {
                assert!((e.error - want).abs() < 1e-12, "{path:?}: {}", e.error);
            }
        }
        // Equidistant from two moves (the foot their shared vertex): the earlier move,
        // whichever the search starts from.
        let index = TrueErrorIndex::new(&program);
        let q = Vector2::new(10.0, 0.0) + Vector2::new(2.0, -3.0);
        for (hint, guess) in [(0, f64::NAN), (1, f64::NAN), (0, 11.0), (1, 3.0)] {
            let (chunk, _) = index.error_between(q, hint, guess, f64::NEG_INFINITY, f64::INFINITY);
            assert_eq!(chunk, 0, "hint {hint}, guess {guess}");
        }
    }

    #[test]
    fn line_and_arc_hand_cases() {
        let l = Path::Line(Line::new(Vector2::new(0.0, 0.0), Vector2::new(4.0, 0.0)).unwrap());
        let r = true_error(&l, Vector2::new(2.0, -1.5));
        assert_eq!((r.error, r.u, r.normal), (1.5, 0.5, Vector2::new(0.0, 1.0)));
        // Beyond the end: distance to the end point, sign by side.
        let r = true_error(&l, Vector2::new(7.0, 4.0));
        assert_eq!((r.error, r.u), (-5.0, 1.0));
        let a = Path::Arc(CircularArc::new(Vector2::new(0.0, 0.0), 2.0, 0.0, PI / 2.0).unwrap());
        let r = true_error(&a, Vector2::new(0.0, 3.0));
        assert!((r.error - 1.0).abs() < 1e-15 && (r.u - 1.0).abs() < 1e-15);
        // Beyond the arc end (angle 3π/4): nearest is the end point (0, 2).
        let r = true_error(&a, Vector2::new(-1.0, 1.0));
        assert!((r.error.abs() - 2f64.sqrt()).abs() < 1e-15 && r.u == 1.0);
        // At the centre: −r for CCW.
        let r = true_error(&a, Vector2::new(0.0, 0.0));
        assert_eq!(r.error, -2.0);
        let cw =
            Path::Arc(CircularArc::new(Vector2::new(0.0, 0.0), 2.0, PI / 2.0, -PI / 2.0).unwrap());
        let r = true_error(&cw, Vector2::new(0.3, 0.4));
        assert!((r.error - 1.5).abs() < 1e-15);
    }

    #[test]
    fn nurbs_brute_force_on_exact_circle() {
        let c = Path::Nurbs(builtin::rational_unit_circle());
        for k in 0..50 {
            let ang = 0.123 + k as f64 * 0.1257;
            let rad = 0.2 + 0.05 * k as f64;
            let r = true_error(&c, Vector2::new(rad * math::cos(ang), rad * math::sin(ang)));
            assert!((r.error - (rad - 1.0)).abs() < 1e-13, "k={k}: {}", r.error);
            assert!((r.normal[0] + math::cos(ang)).abs() < 1e-9);
        }
    }
}
