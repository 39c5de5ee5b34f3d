//! Local-circle geometry shared by the estimators.
//!
//! A circle is described by a point `a` on it, the unit tangent `t` of travel there and the
//! signed curvature κ (> 0 turning left). The signed contour error of P (positive right of
//! travel) is then, with q = P − a and left normal n = perp(t),
//!   ε = (κ|q|² − 2 q·n) / (1 + |κq − n|),   normal = (n − κq)/|n − κq|,
//! which is ‖P − O‖ − r for a CCW circle and r − ‖P − O‖ for a CW one, rewritten so that it
//! stays exact as κ → 0, where it becomes the signed distance to the tangent line. So
//! collinear samples need no special threshold and large radii lose no digits.

use crate::contour::ContourEstimate;
use crate::geometry::{self, Vector2};
use crate::math;

/// Signed error of `p` against the circle through `a` with tangent `t` and curvature `kappa`.
pub(crate) fn circle_error(p: Vector2, a: Vector2, t: Vector2, kappa: f64) -> ContourEstimate {
    let q = p - a;
    let n = geometry::perp(&t);
    let m = n - (q * kappa);
    let mlen = geometry::norm(&m);
    let error = (kappa * q.dot(&q) - 2.0 * q.dot(&n)) / (1.0 + mlen);
    let normal = if mlen > 1e-300 {
        m * (1.0 / mlen)
    } else {
        // P at the centre: every direction is a foot direction; keep the anchor's normal.
        n
    };
    ContourEstimate { error, normal }
}

/// Signed curvature of the circle through three points in travel order `a → b → c`
/// (κ = 2·(b − a)×(c − b) / (|b − a||c − b||c − a|)); 0 when degenerate.
#[cfg(test)]
pub(crate) fn curvature3(a: Vector2, b: Vector2, c: Vector2) -> f64 {
    let (ab, bc) = ((b - a), (c - b));
    curvature_of(ab, bc, geometry::norm(&ab), geometry::norm(&bc), &(c - a))
}

/// [`curvature3`] from the chords `ab`, `bc` whose lengths the caller has (a triple
/// needs them again for its tangents).
fn curvature_of(ab: Vector2, bc: Vector2, ab_len: f64, bc_len: f64, ac: &Vector2) -> f64 {
    let den = ab_len * bc_len * geometry::norm(ac);
    let k = 2.0 * geometry::cross(&ab, &bc) / den;
    if den > 0.0 && k.is_finite() {
        k
    } else {
        0.0
    }
}

/// Half the angle a chord of length `len` subtends on a circle of curvature `kappa`.
fn half_angle(len: f64, kappa: f64) -> f64 {
    math::asin((0.5 * kappa * len).clamp(-1.0, 1.0))
}

/// The unit tangents at the start and at the end of the chord `c` (length `len`, half
/// angle `half`): the chord's direction turned back and forward by `half`. One `sincos`
/// serves both ends: it is odd in the sine and even in the cosine bit for bit (`math`'s
/// tests check it).
fn chord_tangents(c: Vector2, len: f64, half: f64) -> [Vector2; 2] {
    if len == 0.0 {
        return [Vector2::zeros(); 2];
    }
    let dir = c * (1.0 / len);
    let (s, co) = math::sincos(half);
    let turned = |s: f64| Vector2::new(dir[0] * co - dir[1] * s, dir[0] * s + dir[1] * co);
    [turned(-s), turned(s)]
}

/// The tangent at the middle sample from the tangents there of its two chords.
fn middle_tangent(t1: Vector2, t2: Vector2) -> Vector2 {
    let s = t1 + t2;
    let l = geometry::norm(&s);
    if l > 0.0 {
        s * (1.0 / l)
    } else {
        t2
    }
}

/// Estimate against the circle through `a → b → c` at whichever of the three is `anchor`
/// (0 = a, 1 = b, 2 = c).
pub(crate) fn triple_error(p: Vector2, pts: [Vector2; 3], anchor: usize) -> ContourEstimate {
    let [a, b, c] = pts;
    let (ab, bc) = (b - a, c - b);
    let [ab_len, bc_len] = [geometry::norm(&ab), geometry::norm(&bc)];
    let k = curvature_of(ab, bc, ab_len, bc_len, &(c - a));
    let ab_tangents = || chord_tangents(ab, ab_len, half_angle(ab_len, k));
    let bc_tangents = || chord_tangents(bc, bc_len, half_angle(bc_len, k));
    let t = match anchor {
        0 => ab_tangents()[0],
        2 => bc_tangents()[1],
        _ => middle_tangent(ab_tangents()[1], bc_tangents()[0]),
    };
    circle_error(p, pts[anchor.min(2)], t, k)
}

/// The circle through three samples `a → b → c`, ready to be evaluated at any of them: its
/// curvature and the unit tangent of travel at each sample. It depends on the samples
/// alone, so an estimator that meets the same three again keeps it instead of measuring
/// it again (the asin, sincos and hypot calls are most of an estimate's cost).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct SampleCircle {
    kappa: f64,
    tangents: [Vector2; 3],
}

/// The first half of measuring a [`SampleCircle`]: its curvature and the half angle each
/// chord subtends. Measured on one sample and finished on the next, the two halves are
/// two short chains of dependent operations instead of one long one (hypot, a division,
/// asin; then sincos, hypot, a division), which the processor overlaps with other work.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct CircleStart {
    kappa: f64,
    halves: [f64; 2],
}

impl SampleCircle {
    /// The circle through `pts`, given the lengths of the chords a → b and b → c as
    /// [`geometry::norm`] measures them. Evaluated at a sample, it gives the bits of
    /// [`triple_error`] there.
    #[cfg(test)]
    pub(crate) fn through(pts: [Vector2; 3], chords: [f64; 2]) -> Self {
        Self::finish(Self::start(pts, chords), pts, chords)
    }

    /// [`Self::through`]'s first half.
    pub(crate) fn start(pts: [Vector2; 3], chords: [f64; 2]) -> CircleStart {
        let [a, b, c] = pts;
        let [ab_len, bc_len] = chords;
        let kappa = curvature_of(b - a, c - b, ab_len, bc_len, &(c - a));
        CircleStart {
            kappa,
            halves: [half_angle(ab_len, kappa), half_angle(bc_len, kappa)],
        }
    }

    /// [`Self::through`] from its first half, measured on the same samples.
    pub(crate) fn finish(start: CircleStart, pts: [Vector2; 3], chords: [f64; 2]) -> Self {
        let [a, b, c] = pts;
        let [ab_len, bc_len] = chords;
        let [ab_start, ab_end] = chord_tangents(b - a, ab_len, start.halves[0]);
        let [bc_start, bc_end] = chord_tangents(c - b, bc_len, start.halves[1]);
        SampleCircle {
            kappa: start.kappa,
            tangents: [ab_start, middle_tangent(ab_end, bc_start), bc_end],
        }
    }

    /// The estimate of `p` against this circle at its sample `anchor` (0 = a, 1 = b,
    /// 2 = c), which is `at`.
    pub(crate) fn error(&self, p: Vector2, at: Vector2, anchor: usize) -> ContourEstimate {
        circle_error(p, at, self.tangents[anchor.min(2)], self.kappa)
    }
}

/// Mean of two estimates: errors averaged, normals averaged and renormalised.
pub(crate) fn mean(e1: ContourEstimate, e2: ContourEstimate) -> ContourEstimate {
    let s = e1.normal + e2.normal;
    let l = geometry::norm(&s);
    ContourEstimate {
        error: 0.5 * (e1.error + e2.error),
        normal: if l > 0.0 { s * (1.0 / l) } else { e1.normal },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn circle_error_matches_radial_distance_both_directions() {
        // Unit circle about the origin, anchor (1, 0).
        let a = Vector2::new(1.0, 0.0);
        // CCW: tangent +y, κ = +1. Outside point → positive (right of travel).
        let e = circle_error(Vector2::new(2.0, 0.0), a, Vector2::new(0.0, 1.0), 1.0);
        assert!((e.error - 1.0).abs() < 1e-15);
        assert!((e.normal[0] + 1.0).abs() < 1e-15);
        let e = circle_error(Vector2::new(0.0, 0.5), a, Vector2::new(0.0, 1.0), 1.0);
        assert!((e.error + 0.5).abs() < 1e-15);
        // CW: tangent −y, κ = −1. Inside point is right of travel → positive.
        let e = circle_error(Vector2::new(0.0, 0.5), a, Vector2::new(0.0, -1.0), -1.0);
        assert!((e.error - 0.5).abs() < 1e-15);
        assert!((e.normal[1] - 1.0).abs() < 1e-15);
        // Centre: ε = −r (CCW), finite normal.
        let e = circle_error(Vector2::new(0.0, 0.0), a, Vector2::new(0.0, 1.0), 1.0);
        assert!((e.error + 1.0).abs() < 1e-15 && e.normal[0].is_finite());
        // κ = 0: line distance.
        let e = circle_error(Vector2::new(5.0, -3.0), a, Vector2::new(0.0, 1.0), 0.0);
        assert!((e.error - 4.0).abs() < 1e-15 && e.normal == Vector2::new(-1.0, 0.0));
    }

    /// The tangent at one end of a chord as it was measured before one `sincos` served
    /// both ends: its own asin and its own sincos of ±half the angle.
    fn chord_tangent_one_end(c: Vector2, len: f64, kappa: f64, at_end: bool) -> Vector2 {
        if len == 0.0 {
            return Vector2::zeros();
        }
        let dir = c * (1.0 / len);
        let half = math::asin((0.5 * kappa * len).clamp(-1.0, 1.0));
        let (s, co) = math::sincos(if at_end { half } else { -half });
        Vector2::new(dir[0] * co - dir[1] * s, dir[0] * s + dir[1] * co)
    }

    /// A kept circle evaluated at any of its samples gives the bits of the estimate
    /// measured from the three samples there, and of the estimate as it was measured
    /// before (each end of a chord on its own).
    #[test]
    fn a_sample_circle_gives_the_triple_estimates() {
        use rand::rngs::StdRng;
        use rand::{RngExt, SeedableRng};
        let mut rng = StdRng::seed_from_u64(11);
        for i in 0..20_000 {
            let scale = [1e-3, 1.0, 50.0][i % 3];
            let mut v = || {
                Vector2::new(
                    rng.random_range(-scale..scale),
                    rng.random_range(-scale..scale),
                )
            };
            let (a, p) = (v(), v());
            // Collinear, coincident and sharp triples too.
            let (b, c) = match i % 5 {
                0 => (a * 2.0, a * 3.0),
                1 => (a, v()),
                _ => (v(), v()),
            };
            let pts = [a, b, c];
            let chords = [geometry::norm(&(b - a)), geometry::norm(&(c - b))];
            let circle = SampleCircle::through(pts, chords);
            let (ab, bc) = (b - a, c - b);
            let k = curvature_of(ab, bc, chords[0], chords[1], &(c - a));
            let before = [
                chord_tangent_one_end(ab, chords[0], k, false),
                middle_tangent(
                    chord_tangent_one_end(ab, chords[0], k, true),
                    chord_tangent_one_end(bc, chords[1], k, false),
                ),
                chord_tangent_one_end(bc, chords[1], k, true),
            ];
            for anchor in 0..3 {
                let kept = circle.error(p, pts[anchor], anchor);
                assert_eq!(kept, triple_error(p, pts, anchor), "{pts:?} at {anchor}");
                assert_eq!(kept, circle_error(p, pts[anchor], before[anchor], k));
            }
        }
    }

    #[test]
    fn triple_recovers_circle() {
        let pt = |t: f64| Vector2::new(3.0 + 2.0 * math::cos(t), -1.0 + 2.0 * math::sin(t));
        let pts = [pt(0.1), pt(0.15), pt(0.2)];
        assert!((curvature3(pts[0], pts[1], pts[2]) - 0.5).abs() < 1e-12);
        for anchor in 0..3 {
            let p = Vector2::new(
                3.0 + 2.5 * math::cos(0.3f64),
                -1.0 + 2.5 * math::sin(0.3f64),
            );
            let e = triple_error(p, pts, anchor);
            assert!(
                (e.error - 0.5).abs() < 1e-12,
                "anchor {anchor}: {}",
                e.error
            );
        }
        // Reversed order = clockwise travel: the outside is then left of travel, so the
        // error flips sign.
        let e = triple_error(Vector2::new(3.0 + 2.5, -1.0), [pts[2], pts[1], pts[0]], 1);
        assert!((e.error + 0.5).abs() < 1e-12);
    }
}
