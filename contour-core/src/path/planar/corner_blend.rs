//! A corner between two lines rounded by two mirror-image clothoids (Euler spirals),
//! docs/design/two-axis.md §4.9. Along a clothoid the curvature grows linearly with arc
//! length, so the blend leaves the incoming line with zero curvature, reaches its peak at
//! the corner's bisector and joins the outgoing line with zero curvature again: the
//! acceleration of a reference passing it changes continuously (a circular blend would
//! jump to v²/r and make a jerk spike in the samples), and its parameter is exact arc
//! length. Its points are Fresnel integrals, summed as power series (their argument is
//! at most √(π/2) here).

use crate::math;
use serde::{Deserialize, Serialize};

use crate::geometry::{self, Vector2};
use crate::path::{Curve, CurvePoint, PathError};

/// Two clothoids, each `half` long, turning by `turn` together.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(from = "SavedBlend", into = "SavedBlend")]
pub struct CornerBlend {
    /// Where the blend leaves the incoming line.
    start: Vector2,
    /// The incoming line's unit direction.
    incoming: Vector2,
    /// The turn from the incoming to the outgoing direction, rad (> 0 to the left),
    /// 0 < |turn| < π.
    turn: f64,
    /// Arc length of each clothoid, mm.
    half: f64,
    /// Distance from the vertex to either end, mm (a function of the above, kept so that
    /// a point on the second clothoid costs one Fresnel sum).
    trim: f64,
    /// The outgoing line's unit direction (`incoming` turned by `turn`, not saved: a
    /// point on the second clothoid needs it, and its sine and cosine cost as much as
    /// the Fresnel sum).
    outgoing: Vector2,
}

/// What a [`CornerBlend`] saves: the values it is made of.
#[derive(Serialize, Deserialize)]
struct SavedBlend {
    start: Vector2,
    incoming: Vector2,
    turn: f64,
    half: f64,
    trim: f64,
}

impl From<SavedBlend> for CornerBlend {
    fn from(b: SavedBlend) -> Self {
        CornerBlend::from_parts(b.start, b.incoming, b.turn, b.half, b.trim)
    }
}

impl From<CornerBlend> for SavedBlend {
    fn from(b: CornerBlend) -> Self {
        SavedBlend {
            start: b.start,
            incoming: b.incoming,
            turn: b.turn,
            half: b.half,
            trim: b.trim,
        }
    }
}

/// Terms of the series kept: at |x| ≤ √(π/2) the first left out is below 10⁻¹⁹
/// (absolute: cos(x²) goes to 0 at the end of the range).
const FRESNEL_TERMS: usize = 12;

/// Power series in x⁴, coefficient n first.
struct FresnelSeries {
    /// (−1)ⁿ / ((4n+1)(2n)!): the cosine integral, times x.
    cos_integral: [f64; FRESNEL_TERMS],
    /// (−1)ⁿ / ((4n+3)(2n+1)!): the sine integral, times x³.
    sin_integral: [f64; FRESNEL_TERMS],
    /// (−1)ⁿ / (2n)!: cos(x²), the cosine integral's derivative.
    cos: [f64; FRESNEL_TERMS],
    /// (−1)ⁿ / (2n+1)!: sin(x²), times x², the sine integral's derivative.
    sin: [f64; FRESNEL_TERMS],
}

const FRESNEL_COEFFICIENTS: FresnelSeries = {
    let mut series = FresnelSeries {
        cos_integral: [0.0; FRESNEL_TERMS],
        sin_integral: [0.0; FRESNEL_TERMS],
        cos: [0.0; FRESNEL_TERMS],
        sin: [0.0; FRESNEL_TERMS],
    };
    // (2n)! as it grows; exact in f64 up to 22!.
    let mut factorial = 1.0;
    let mut n = 0;
    while n < FRESNEL_TERMS {
        let k = n as f64;
        let sign = if n % 2 == 0 { 1.0 } else { -1.0 };
        series.cos[n] = sign / factorial;
        series.sin[n] = sign / (factorial * (2.0 * k + 1.0));
        series.cos_integral[n] = series.cos[n] / (4.0 * k + 1.0);
        series.sin_integral[n] = series.sin[n] / (4.0 * k + 3.0);
        factorial *= (2.0 * k + 1.0) * (2.0 * k + 2.0);
        n += 1;
    }
    series
};

/// ∫₀ˣ cos(w²) dw and ∫₀ˣ sin(w²) dw by their power series in Horner's form (|x| ≤
/// √(π/2) here, where 12 terms reach the last bit): no division, no branch, since a blend's
/// nearest point evaluates it a few dozen times a sample.
fn fresnel(x: f64) -> (f64, f64) {
    let x2 = x * x;
    let x4 = x2 * x2;
    let series = &FRESNEL_COEFFICIENTS;
    let (mut c, mut s) = (0.0, 0.0);
    for n in (0..FRESNEL_TERMS).rev() {
        c = c * x4 + series.cos_integral[n];
        s = s * x4 + series.sin_integral[n];
    }
    (x * c, x * x2 * s)
}

/// [`fresnel`] and its integrands cos(x²) and sin(x²) (the tangent of the clothoid, whose
/// angle is x²), by the same kind of series: cheaper than a libm sine and cosine, and
/// one loop.
fn fresnel_with_integrands(x: f64) -> ((f64, f64), (f64, f64)) {
    let x2 = x * x;
    let x4 = x2 * x2;
    let series = &FRESNEL_COEFFICIENTS;
    let (mut c, mut s, mut dc, mut ds) = (0.0, 0.0, 0.0, 0.0);
    for n in (0..FRESNEL_TERMS).rev() {
        c = c * x4 + series.cos_integral[n];
        s = s * x4 + series.sin_integral[n];
        dc = dc * x4 + series.cos[n];
        ds = ds * x4 + series.sin[n];
    }
    ((x * c, x * x2 * s), (dc, x2 * ds))
}

/// The left unit normal.
fn left(t: Vector2) -> Vector2 {
    Vector2::new(-t[1], t[0])
}

impl CornerBlend {
    /// The blend of its parts, with the outgoing direction they give.
    fn from_parts(start: Vector2, incoming: Vector2, turn: f64, half: f64, trim: f64) -> Self {
        let (sin, cos) = math::sincos(turn);
        let outgoing = Vector2::new(
            incoming[0] * cos - incoming[1] * sin,
            incoming[0] * sin + incoming[1] * cos,
        );
        CornerBlend {
            start,
            incoming,
            turn,
            half,
            trim,
            outgoing,
        }
    }

    /// The blend of a corner at `vertex` from unit direction `incoming` to `outgoing`,
    /// leaving the two lines by at most `tolerance` and starting no more than `reach`
    /// before the vertex (it ends as far after it). `None` for a turn it cannot round
    /// (none, or a reversal) or limits that leave nothing.
    pub fn at_corner(
        vertex: Vector2,
        incoming: Vector2,
        outgoing: Vector2,
        tolerance: f64,
        reach: f64,
    ) -> Option<(CornerBlend, f64)> {
        let turn = math::atan2(
            geometry::cross(&incoming, &outgoing),
            incoming.dot(&outgoing),
        );
        if !(turn.abs() > 0.0 && turn.abs() < std::f64::consts::PI - 1e-6) {
            return None;
        }
        // A unit-length half: its end's offsets along and across the incoming line.
        let unit =
            CornerBlend::from_parts(Vector2::zeros(), Vector2::new(1.0, 0.0), turn, 1.0, 0.0);
        let (along, across) = unit.first_half(1.0);
        let across = across.abs();
        let beta = 0.5 * turn.abs();
        // The middle lies on the bisector: the trim before the vertex per unit half.
        let trim = along + across * math::tan(beta);
        let half = (tolerance / across).min(reach / trim);
        if !(half.is_finite() && half > 0.0) {
            return None;
        }
        let blend = CornerBlend::from_parts(
            vertex - incoming * (trim * half),
            incoming,
            turn,
            half,
            trim * half,
        );
        Some((blend, trim * half))
    }

    /// Checks restored values as [`CornerBlend::at_corner`] makes them.
    pub fn validate(&self) -> Result<(), PathError> {
        let unit = (geometry::norm(&self.incoming) - 1.0).abs() < 1e-9;
        let finite = self.start.iter().all(|v| v.is_finite());
        let shape = unit
            && finite
            && self.turn.abs() > 0.0
            && self.turn.abs() < std::f64::consts::PI
            && self.half.is_finite()
            && self.half > 0.0;
        if shape && (self.trim - self.computed_trim()).abs() <= 1e-9 * (1.0 + self.trim) {
            Ok(())
        } else {
            Err(PathError::invalid(format!(
                "corner blend {self:?} is invalid"
            )))
        }
    }

    /// The turn, rad (> 0 to the left).
    pub fn turn(&self) -> f64 {
        self.turn
    }

    /// The peak curvature (at the bisector), 1/mm.
    pub fn peak_curvature(&self) -> f64 {
        self.turn.abs() / self.half
    }

    /// The rate of change of the curvature along the blend, 1/mm².
    pub fn curvature_rate(&self) -> f64 {
        self.turn.abs() / (self.half * self.half)
    }

    /// The unit directions at its start and its end: the lines' (no Fresnel sum).
    pub fn end_directions(&self) -> [Vector2; 2] {
        [self.incoming, self.outgoing]
    }

    /// The three corners of the triangle the blend lies in: its ends and the vertex.
    pub fn hull(&self) -> [Vector2; 3] {
        [
            self.start,
            self.start + self.incoming * self.trim,
            self.end(),
        ]
    }

    /// Where the blend joins the outgoing line (exactly its point at u = 1).
    fn end(&self) -> Vector2 {
        self.start + (self.incoming + self.outgoing) * self.trim
    }

    /// The trim the other values make: the first clothoid's end offsets, the middle on the
    /// bisector.
    fn computed_trim(&self) -> f64 {
        let (along, across) = self.first_half(self.half);
        along + across.abs() * math::tan(0.5 * self.turn.abs())
    }

    /// The blend mirrored about the x axis (y → −y), travelled the mirrored way.
    pub fn mirrored(&self) -> CornerBlend {
        CornerBlend::from_parts(
            Vector2::new(self.start[0], -self.start[1]),
            Vector2::new(self.incoming[0], -self.incoming[1]),
            -self.turn,
            self.half,
            self.trim,
        )
    }

    /// The first clothoid's point at arc length `s` ≤ `half` in the incoming frame:
    /// (along the incoming line, across it, > 0 to the left for a left turn).
    fn first_half(&self, s: f64) -> (f64, f64) {
        let scale = self.fresnel_scale();
        let (c, s) = fresnel(s / scale);
        (scale * c, scale * s * self.turn.signum())
    }

    /// The arc length per unit of the Fresnel argument w: φ(s) = s²/(2A²) with
    /// φ(half) = |turn|/2, so A² = half²/|turn|, and w = s/(A√2) makes φ = w².
    fn fresnel_scale(&self) -> f64 {
        let a = self.half / self.turn.abs().sqrt();
        a * std::f64::consts::SQRT_2
    }

    /// The point at arc length `s` from the start (what [`Curve::point`] asks, without
    /// the tangent and the curvature).
    fn point_at(&self, s: f64) -> Vector2 {
        let h = self.half;
        if s <= h {
            let (x, y) = self.first_half(s);
            self.start + self.incoming * x + left(self.incoming) * y
        } else {
            // The second clothoid from the end, backwards: the mirror image of the first.
            let (x, y) = self.first_half(2.0 * h - s);
            self.end() - self.outgoing * x + left(self.outgoing) * y
        }
    }
}

impl Curve for CornerBlend {
    fn param_range(&self) -> (f64, f64) {
        (0.0, 1.0)
    }

    fn point(&self, u: f64) -> Vector2 {
        self.point_at(u.clamp(0.0, 1.0) * 2.0 * self.half)
    }

    fn eval(&self, u: f64) -> CurvePoint {
        let length = 2.0 * self.half;
        let s = u.clamp(0.0, 1.0) * length;
        let h = self.half;
        let sign = self.turn.signum();
        // The point and the tangent from the nearer end's clothoid (the second one
        // backwards from the end: the mirror image of the first), as in point_at.
        let first = s <= h;
        let from_end = if first { s } else { 2.0 * h - s };
        let scale = self.fresnel_scale();
        let ((c, sn), (cos, sin)) = fresnel_with_integrands(from_end / scale);
        let (x, y) = (scale * c, scale * sn * sign);
        let (p, tangent) = if first {
            let n = left(self.incoming);
            (
                self.start + self.incoming * x + n * y,
                self.incoming * cos + n * (sign * sin),
            )
        } else {
            let n = left(self.outgoing);
            (
                self.end() - self.outgoing * x + n * y,
                self.outgoing * cos - n * (sign * sin),
            )
        };
        // κ(s): rising to the bisector, then falling, with the turn's sign.
        let kappa = sign * self.curvature_rate() * from_end;
        CurvePoint {
            p,
            d1: tangent * length,
            d2: left(tangent) * (kappa * length * length),
        }
    }

    fn length_between(&self, u0: f64, u1: f64) -> f64 {
        (u1.clamp(0.0, 1.0) - u0.clamp(0.0, 1.0)).abs() * 2.0 * self.half
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::{FRAC_PI_2, PI};

    #[test]
    fn the_series_are_the_fresnel_integrals() {
        // By the midpoint rule on a fine grid (independent of the series).
        for x in [0.0, 0.1, 0.5, 1.0, 1.2533] {
            let n = 200_000;
            let h: f64 = x / n as f64;
            let (mut c, mut s) = (0.0, 0.0);
            for k in 0..n {
                let w: f64 = (k as f64 + 0.5) * h;
                c += math::cos(w * w) * h;
                s += math::sin(w * w) * h;
            }
            let (fc, fs) = fresnel(x);
            assert!((fc - c).abs() < 1e-10 && (fs - s).abs() < 1e-10, "{x}");
        }
    }

    #[test]
    fn a_right_angle_blend_keeps_the_tolerance_joins_both_lines_and_is_arc_length() {
        let vertex = Vector2::new(10.0, 0.0);
        for (incoming, outgoing) in [
            (Vector2::new(1.0, 0.0), Vector2::new(0.0, 1.0)),
            (Vector2::new(1.0, 0.0), Vector2::new(0.0, -1.0)),
            (Vector2::new(0.6, 0.8), Vector2::new(-0.8, 0.6)),
        ] {
            let (b, trim) = CornerBlend::at_corner(vertex, incoming, outgoing, 0.01, 5.0).unwrap();
            assert!((b.turn().abs() - FRAC_PI_2).abs() < 1e-12);
            // Ends on the two lines, `trim` from the vertex, tangent to them.
            assert!((b.point(0.0) - (vertex - incoming * trim)).amax() < 1e-12);
            assert!((b.point(1.0) - (vertex + outgoing * trim)).amax() < 1e-12);
            let e0 = b.eval(0.0);
            let e1 = b.eval(1.0);
            assert!((e0.d1 / geometry::norm(&e0.d1) - incoming).amax() < 1e-12);
            assert!((e1.d1 / geometry::norm(&e1.d1) - outgoing).amax() < 1e-12);
            // Zero curvature at both ends.
            assert!(geometry::norm(&e0.d2) < 1e-12 && geometry::norm(&e1.d2) < 1e-9);
            // Continuous at the bisector; the middle 0.01 mm from both lines.
            let h = 0.5;
            let (below, above) = (b.point(h - 1e-12), b.point(h + 1e-12));
            assert!((below - above).amax() < 1e-9);
            let middle = b.point(h);
            let off = |p: Vector2, t: Vector2| geometry::cross(&t, &(p - vertex)).abs();
            assert!((off(middle, incoming) - 0.01).abs() < 1e-12);
            assert!((off(middle, outgoing) - 0.01).abs() < 1e-12);
            // Arc length: chords of 20 000 steps sum to the length (short of it by
            // Σκ²Δs³/24 ≈ 3·10⁻¹¹ mm); the derivative's length is the length.
            let n = 20_000;
            let chords: f64 = (0..n)
                .map(|k| {
                    geometry::dist(
                        &b.point(k as f64 / n as f64),
                        &b.point((k + 1) as f64 / n as f64),
                    )
                })
                .sum();
            assert!((chords - b.length()).abs() < 1e-9 * b.length(), "{chords}");
            for k in 0..=20 {
                let e = b.eval(k as f64 / 20.0);
                assert!((geometry::norm(&e.d1) - b.length()).abs() < 1e-12);
                // The second derivative by central differences of the first.
                let d = 1e-6;
                let u = (k as f64 / 20.0).clamp(d, 1.0 - d);
                let numeric = (b.eval(u + d).d1 - b.eval(u - d).d1) / (2.0 * d);
                assert!((numeric - b.eval(u).d2).amax() < 1e-5 * b.length(), "{k}");
                // The point and the tangent (their series) agree with point() and
                // with its central differences.
                assert!(
                    (b.eval(u).p - b.point(u)).amax() < 1e-15,
                    "{k}: {:?}",
                    b.eval(u).p - b.point(u)
                );
                let numeric = (b.point(u + d) - b.point(u - d)) / (2.0 * d);
                // (rounding: an ulp of the 10 mm coordinates over the 2·10⁻⁶ step)
                assert!((numeric - b.eval(u).d1).amax() < 1e-7, "{k}");
            }
            // Every point within the tolerance of the nearer line.
            for k in 0..=1000 {
                let p = b.point(k as f64 / 1000.0);
                assert!(off(p, incoming).min(off(p, outgoing)) <= 0.01 + 1e-12);
            }
        }
    }

    #[test]
    fn a_short_side_limits_the_blend_and_reversals_are_not_rounded() {
        let v = Vector2::new(0.0, 0.0);
        let (b, trim) =
            CornerBlend::at_corner(v, Vector2::new(1.0, 0.0), Vector2::new(0.0, 1.0), 1.0, 0.2)
                .unwrap();
        assert!((trim - 0.2).abs() < 1e-15 && b.length() < 0.4);
        let back = Vector2::new(-1.0, 0.0);
        assert!(CornerBlend::at_corner(v, Vector2::new(1.0, 0.0), back, 0.1, 1.0).is_none());
        let sharp = Vector2::new(math::cos(PI - 0.1), math::sin(PI - 0.1));
        assert!(CornerBlend::at_corner(v, Vector2::new(1.0, 0.0), sharp, 0.1, 1.0).is_some());
    }
}
