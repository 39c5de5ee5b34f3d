//! NURBS curve in any dimension, of any degree 1..=[`MAX_DEGREE`] with positive rational weights and a
//! clamped knot vector, with first and second derivatives (docs/design/two-axis.md §4.6).
//!
//! Evaluation builds the triangle of B-spline basis values of degrees 0..p on the knot
//! span of u by the Cox–de Boor recurrence, then differentiates the degree-p functions
//! with the derivative rule N'_{i,k} = k·(N_{i,k−1}/(u_{i+k} − u_i) − N_{i+1,k−1}/(u_{i+k+1} −
//! u_{i+1})), applied twice for C''. The homogeneous sums A = Σ N·w·P and W = Σ N·w are
//! then divided with the quotient rule:
//! C = A/W, C' = (A' − W'·C)/W, C'' = (A'' − 2W'·C' − W''·C)/W.
//! All scratch lives in fixed-size stack arrays, so evaluation never allocates; that is why
//! the degree is bounded.

use serde::{Deserialize, Serialize};

use super::{clamp_param, gauss_length, Curve, CurvePoint, PathError};
use crate::geometry::{self, Vector};

/// Highest supported degree (bounds the stack scratch of the evaluator).
pub const MAX_DEGREE: usize = 10;

const M: usize = MAX_DEGREE + 1;

/// The serialised / file form of a NURBS; converting it to [`Nurbs`] validates it, so a
/// corrupt state blob or file can never produce a curve that panics when evaluated.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NurbsData<const D: usize = 2> {
    /// Polynomial degree p.
    pub degree: usize,
    /// Clamped, nondecreasing knot vector of length n + p + 1 (n control points).
    pub knots: Vec<f64>,
    /// Control points [x, y, …], mm.
    pub control_points: Vec<Vector<D>>,
    /// Optional weights (all 1 when absent), each finite and > 0. Always serialised (no
    /// `skip_serializing_if`) so non-self-describing formats such as postcard round-trip.
    #[serde(default)]
    pub weights: Option<Vec<f64>>,
}

/// Clamped uniform knot vector on [0, 1] for `n` control points of degree `p`
/// (p + 1 zeros, interior knots k/(n − p), p + 1 ones).
pub fn clamped_uniform_knots(n: usize, p: usize) -> Vec<f64> {
    let spans = n.saturating_sub(p).max(1);
    let mut k = vec![0.0; p + 1];
    k.extend((1..spans).map(|i| i as f64 / spans as f64));
    k.extend(std::iter::repeat_n(1.0, p + 1));
    k
}

/// A validated NURBS curve; the parameter runs over `[knots[0], knots[last]]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "NurbsData<D>", into = "NurbsData<D>")]
pub struct Nurbs<const D: usize = 2> {
    degree: usize,
    knots: Vec<f64>,
    ctrl: Vec<Vector<D>>,
    weights: Vec<f64>,
}

impl<const D: usize> TryFrom<NurbsData<D>> for Nurbs<D> {
    type Error = PathError;
    fn try_from(d: NurbsData<D>) -> Result<Self, PathError> {
        Nurbs::new(d.degree, d.knots, d.control_points, d.weights)
    }
}

impl<const D: usize> From<Nurbs<D>> for NurbsData<D> {
    fn from(n: Nurbs<D>) -> Self {
        let rational = n.weights.iter().any(|&w| w != 1.0);
        NurbsData {
            degree: n.degree,
            knots: n.knots,
            control_points: n.ctrl,
            weights: rational.then_some(n.weights),
        }
    }
}

impl<const D: usize> Nurbs<D> {
    /// Validates and builds a curve. Requirements: 1 ≤ degree ≤ [`MAX_DEGREE`]; at least
    /// degree + 1 control points, all finite; knot count = control points + degree + 1;
    /// knots finite and nondecreasing, clamped (first and last degree + 1 knots equal),
    /// interior multiplicity ≤ degree, nonempty range; weights (if given) one per control
    /// point, finite and > 0.
    pub fn new(
        degree: usize,
        knots: Vec<f64>,
        control_points: Vec<impl Into<Vector<D>>>,
        weights: Option<Vec<f64>>,
    ) -> Result<Self, PathError> {
        let control_points: Vec<Vector<D>> = control_points.into_iter().map(Into::into).collect();
        let p = degree;
        if p == 0 || p > MAX_DEGREE {
            return Err(PathError::invalid(format!(
                "NURBS degree must be 1..={MAX_DEGREE}, got {p}"
            )));
        }
        let n = control_points.len();
        if n < p + 1 {
            return Err(PathError::invalid(format!(
                "a degree-{p} NURBS needs at least {} control points, got {n}",
                p + 1
            )));
        }
        if let Some(i) = control_points.iter().position(|c| !geometry::is_finite(c)) {
            return Err(PathError::invalid(format!(
                "control point {i} is not finite"
            )));
        }
        if knots.len() != n + p + 1 {
            return Err(PathError::invalid(format!(
                "knot count must be control points + degree + 1 = {}, got {}",
                n + p + 1,
                knots.len()
            )));
        }
        if let Some(i) = knots.iter().position(|k| !k.is_finite()) {
            return Err(PathError::invalid(format!("knot {i} is not finite")));
        }
        if let Some(i) = knots.windows(2).position(|w| w[1] < w[0]) {
            return Err(PathError::invalid(format!(
                "knots must be nondecreasing: knot {} = {} < knot {i} = {}",
                i + 1,
                knots[i + 1],
                knots[i]
            )));
        }
        let last = knots.len() - 1;
        if knots[..=p].iter().any(|&k| k != knots[0])
            || knots[last - p..].iter().any(|&k| k != knots[last])
        {
            return Err(PathError::invalid(format!(
                "knot vector must be clamped: the first and last {} knots must be equal",
                p + 1
            )));
        }
        if knots[0] >= knots[last] {
            return Err(PathError::invalid(
                "knot vector has an empty parameter range",
            ));
        }
        // End multiplicity above p + 1 leaves a control point unused; interior multiplicity
        // above p breaks the curve apart.
        let mut i = 0;
        while i <= last {
            let mut j = i;
            while j < last && knots[j + 1] == knots[i] {
                j += 1;
            }
            let mult = j - i + 1;
            let end = i == 0 || j == last;
            if (end && mult != p + 1) || (!end && mult > p) {
                return Err(PathError::invalid(format!(
                    "knot {} has multiplicity {mult}; end knots need exactly {} and interior knots at most {p}",
                    knots[i],
                    p + 1
                )));
            }
            i = j + 1;
        }
        let weights = match weights {
            None => vec![1.0; n],
            Some(w) => {
                if w.len() != n {
                    return Err(PathError::invalid(format!(
                        "need one weight per control point ({n}), got {}",
                        w.len()
                    )));
                }
                if let Some(i) = w.iter().position(|&x| !(x.is_finite() && x > 0.0)) {
                    return Err(PathError::invalid(format!(
                        "weight {i} must be finite and > 0, got {}",
                        w[i]
                    )));
                }
                w
            }
        };
        Ok(Nurbs {
            degree,
            knots,
            ctrl: control_points,
            weights,
        })
    }

    /// Degree p.
    pub fn degree(&self) -> usize {
        self.degree
    }
    /// Knot vector.
    pub fn knots(&self) -> &[f64] {
        &self.knots
    }
    /// Control points.
    pub fn control_points(&self) -> &[Vector<D>] {
        &self.ctrl
    }
    /// Weights (all 1 for a non-rational curve).
    pub fn weights(&self) -> &[f64] {
        &self.weights
    }

    /// Index s of the knot span with knots[s] ≤ u < knots[s+1] (the last nonempty span at
    /// the end of the range). `u` must already be clamped into the range.
    fn span(&self, u: f64) -> usize {
        let p = self.degree;
        let n = self.ctrl.len() - 1;
        if u >= self.knots[n + 1] {
            return n;
        }
        let (mut lo, mut hi) = (p, n + 1);
        while hi - lo > 1 {
            let mid = (lo + hi) / 2;
            if u < self.knots[mid] {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        lo
    }

    /// Basis triangle: `t[k][j]` = N_{s−k+j, k}(u) for k = 0..=p, j = 0..=k.
    fn basis_triangle(&self, s: usize, u: f64) -> [[f64; M]; M] {
        let p = self.degree;
        let kn = &self.knots;
        let mut t = [[0.0; M]; M];
        t[0][0] = 1.0;
        for k in 1..=p {
            for j in 0..=k {
                let i = s + j - k;
                let mut v = 0.0;
                if j >= 1 {
                    let den = kn[i + k] - kn[i];
                    if den > 0.0 {
                        v += (u - kn[i]) / den * t[k - 1][j - 1];
                    }
                }
                if j < k {
                    let den = kn[i + k + 1] - kn[i + 1];
                    if den > 0.0 {
                        v += (kn[i + k + 1] - u) / den * t[k - 1][j];
                    }
                }
                t[k][j] = v;
            }
        }
        t
    }

    /// Derivative rule: from values `d` attached to the degree-(k−1) functions of span `s`
    /// (d[j] ↔ N_{s−k+1+j, k−1}), the derivative of the degree-k functions (out[j] ↔ N_{s−k+j, k}).
    fn diff_level(&self, s: usize, k: usize, d: &[f64; M]) -> [f64; M] {
        let kn = &self.knots;
        let kf = k as f64;
        let mut out = [0.0; M];
        for (j, o) in out.iter_mut().enumerate().take(k + 1) {
            let i = s + j - k;
            let mut v = 0.0;
            if j >= 1 {
                let den = kn[i + k] - kn[i];
                if den > 0.0 {
                    v += d[j - 1] / den;
                }
            }
            if j < k {
                let den = kn[i + k + 1] - kn[i + 1];
                if den > 0.0 {
                    v -= d[j] / den;
                }
            }
            *o = kf * v;
        }
        out
    }

    /// Point and derivatives at `u` as the limit from below: at an interior knot those
    /// of the span that ends there (the feed planner's view of a kink or a curvature jump).
    pub fn eval_from_below(&self, u: f64) -> CurvePoint<D> {
        let u = self.clamp(u);
        let mut s = self.span(u);
        // The span that ends at u, when u starts the one `span` found.
        while s > self.degree && self.knots[s] >= u {
            s -= 1;
        }
        self.eval_in_span(s, u)
    }

    /// Point and derivatives at `u` by the basis functions of span `s`.
    fn eval_in_span(&self, s: usize, u: f64) -> CurvePoint<D> {
        let p = self.degree;
        let t = self.basis_triangle(s, u);
        let n0 = t[p];
        let n1 = self.diff_level(s, p, &t[p - 1]);
        let n2 = if p >= 2 {
            let d1 = self.diff_level(s, p - 1, &t[p - 2]);
            self.diff_level(s, p, &d1)
        } else {
            [0.0; M]
        };
        // Homogeneous sums and their derivatives.
        let (mut a0, mut a1, mut a2) = ([0.0; D], [0.0; D], [0.0; D]);
        let (mut w0, mut w1, mut w2) = (0.0, 0.0, 0.0);
        for j in 0..=p {
            let i = s + j - p;
            let w = self.weights[i];
            let c = self.ctrl[i];
            let (b0, b1, b2) = (n0[j] * w, n1[j] * w, n2[j] * w);
            w0 += b0;
            w1 += b1;
            w2 += b2;
            for d in 0..D {
                a0[d] += b0 * c[d];
                a1[d] += b1 * c[d];
                a2[d] += b2 * c[d];
            }
        }
        let mut out = CurvePoint::default();
        for d in 0..D {
            let c0 = a0[d] / w0;
            let c1 = (a1[d] - w1 * c0) / w0;
            let c2 = (a2[d] - 2.0 * w1 * c1 - w2 * c0) / w0;
            out.p[d] = c0;
            out.d1[d] = c1;
            out.d2[d] = c2;
        }
        out
    }

    fn clamp(&self, u: f64) -> f64 {
        let (a, b) = self.param_range();
        clamp_param(u, a, b)
    }
}

impl<const D: usize> Curve<D> for Nurbs<D> {
    fn param_range(&self) -> (f64, f64) {
        (self.knots[0], self.knots[self.knots.len() - 1])
    }

    fn eval(&self, u: f64) -> CurvePoint<D> {
        let u = self.clamp(u);
        self.eval_in_span(self.span(u), u)
    }

    fn point(&self, u: f64) -> Vector<D> {
        let u = self.clamp(u);
        let p = self.degree;
        let s = self.span(u);
        let t = self.basis_triangle(s, u);
        let (mut a, mut w) = ([0.0; D], 0.0);
        for (j, nj) in t[p].iter().enumerate().take(p + 1) {
            let i = s + j - p;
            let b = nj * self.weights[i];
            w += b;
            let c = &self.ctrl[i];
            for d in 0..D {
                a[d] += b * c[d];
            }
        }
        Vector::from(a) / w
    }

    fn length_between(&self, u0: f64, u1: f64) -> f64 {
        let (a, b) = {
            let (x, y) = (self.clamp(u0), self.clamp(u1));
            if x <= y {
                (x, y)
            } else {
                (y, x)
            }
        };
        // Integrate knot span by knot span: |C'| is smooth inside each.
        let mut total = 0.0;
        let mut lo = a;
        for &k in self.knots.iter().filter(|&&k| k > a && k < b) {
            if k > lo {
                total += gauss_length(self, lo, k, 1e-11);
                lo = k;
            }
        }
        total + gauss_length(self, lo, b, 1e-11)
    }

    fn breakpoints(&self) -> Vec<f64> {
        let mut v: Vec<f64> = self.knots.clone();
        v.dedup();
        v
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Vector2;
    use crate::math;

    /// docs/design/two-axis.md §4.6: exact unit circle, degree 2, 9 control points on a square.
    fn unit_circle() -> Nurbs {
        crate::path::planar::builtin::rational_unit_circle()
    }

    #[test]
    fn rational_circle_points_on_unit_radius() {
        let c = unit_circle();
        for k in 0..=2000 {
            let u = k as f64 / 2000.0;
            let e = c.eval(u);
            let r = math::hypot(e.p[0], e.p[1]);
            assert!((r - 1.0).abs() < 1e-14, "u={u} r={r}");
            assert!((c.point(u)[0] - e.p[0]).abs() < 1e-15);
            // Tangent ⟂ radius, and C''·C radially consistent: d/du (|C|²) = 2 C·C' = 0.
            let dot = e.p[0] * e.d1[0] + e.p[1] * e.d1[1];
            assert!(
                dot.abs() < 1e-12 * (1.0 + math::hypot(e.d1[0], e.d1[1])),
                "u={u}"
            );
            // d²/du² |C|² = 2(|C'|² + C·C'') = 0.
            let dd = e.d1[0] * e.d1[0] + e.d1[1] * e.d1[1] + e.p[0] * e.d2[0] + e.p[1] * e.d2[1];
            assert!(
                dd.abs() < 1e-10 * (1.0 + e.d1[0].powi(2) + e.d1[1].powi(2)),
                "u={u}"
            );
        }
        assert!((c.length() - 2.0 * std::f64::consts::PI).abs() < 1e-9);
    }

    #[test]
    fn derivatives_match_central_differences() {
        use crate::path::planar::builtin;
        for c in [builtin::infinity(), builtin::trident(), unit_circle()] {
            let h = 1e-6;
            let (a, b) = c.param_range();
            let kn = c.breakpoints();
            for k in 1..1000 {
                let u = a + (b - a) * k as f64 / 1000.0 + 1.234e-5;
                // Skip samples whose stencil straddles a knot (derivatives may jump there).
                if kn.iter().any(|&t| (t - u).abs() < 2.0 * h) {
                    continue;
                }
                let e = c.eval(u);
                let (pm, pp) = (c.eval(u - h), c.eval(u + h));
                let scale = 1.0 + math::hypot(e.d1[0], e.d1[1]) + math::hypot(e.d2[0], e.d2[1]);
                for d in 0..2 {
                    let fd1 = (pp.p[d] - pm.p[d]) / (2.0 * h);
                    let fd2 = (pp.d1[d] - pm.d1[d]) / (2.0 * h);
                    let fd2b = (pp.p[d] - 2.0 * e.p[d] + pm.p[d]) / (h * h);
                    assert!((fd1 - e.d1[d]).abs() < 1e-6 * scale, "d1 u={u}");
                    assert!((fd2 - e.d2[d]).abs() < 1e-5 * scale, "d2 u={u}");
                    assert!((fd2b - e.d2[d]).abs() < 2e-2 * scale, "d2 (points) u={u}");
                }
            }
        }
    }

    #[test]
    fn degree_one_is_polyline() {
        let c = Nurbs::new(
            1,
            vec![0., 0., 0.5, 1., 1.],
            vec![
                Vector2::new(0., 0.),
                Vector2::new(2., 0.),
                Vector2::new(2., 2.),
            ],
            None,
        )
        .unwrap();
        assert_eq!(c.point(0.25), Vector2::new(1.0, 0.0));
        assert_eq!(c.eval(0.75).d1, Vector2::new(0.0, 4.0));
        assert_eq!(c.eval(0.75).d2, Vector2::new(0.0, 0.0));
        assert!((c.length() - 4.0).abs() < 1e-12);
    }

    #[test]
    fn rejects_bad_input_with_clear_messages() {
        let pts = vec![
            Vector2::new(0., 0.),
            Vector2::new(1., 1.),
            Vector2::new(2., 0.),
            Vector2::new(3., 1.),
        ];
        let ok = clamped_uniform_knots(4, 3);
        assert_eq!(ok, vec![0., 0., 0., 0., 1., 1., 1., 1.]);
        let err = |r: Result<Nurbs, PathError>| r.unwrap_err().to_string();
        assert!(err(Nurbs::new(3, vec![0.; 7], pts.clone(), None)).contains("knot count"));
        assert!(err(Nurbs::new(
            3,
            vec![0., 0., 0., 0., 1., 1., 1., 0.9],
            pts.clone(),
            None
        ))
        .contains("nondecreasing"));
        assert!(err(Nurbs::new(
            3,
            vec![0., 0., 0., 0.5, 1., 1., 1., 1.],
            pts.clone(),
            None
        ))
        .contains("clamped"));
        assert!(err(Nurbs::new(
            3,
            ok.clone(),
            pts.clone(),
            Some(vec![1., 0., 1., 1.])
        ))
        .contains("weight 1"));
        assert!(
            err(Nurbs::new(3, ok.clone(), pts.clone(), Some(vec![1., 1.]))).contains("one weight")
        );
        assert!(err(Nurbs::new(0, ok.clone(), pts.clone(), None)).contains("degree"));
        assert!(err(Nurbs::new(11, ok.clone(), pts.clone(), None)).contains("degree"));
        assert!(err(Nurbs::new(5, ok.clone(), pts.clone(), None)).contains("at least"));
        let mut nan = pts.clone();
        nan[2][1] = f64::NAN;
        assert!(err(Nurbs::new(3, ok.clone(), nan, None)).contains("control point 2"));
        assert!(err(Nurbs::new(
            3,
            vec![0., 0., 0., 0., f64::NAN, 1., 1., 1.],
            pts.clone(),
            None
        ))
        .contains("not finite"));
        assert!(err(Nurbs::new(3, vec![1.; 8], pts, None)).contains("empty"));
    }

    #[test]
    fn serde_round_trip_validates() {
        let c = unit_circle();
        let s = serde_json::to_string(&c).unwrap();
        let back: Nurbs = serde_json::from_str(&s).unwrap();
        assert_eq!(back, c);
        let bad = s.replace("0.25,0.25", "0.25,0.2");
        assert!(serde_json::from_str::<Nurbs>(&bad).is_err());
    }

    #[test]
    fn out_of_range_parameters_are_clamped() {
        let c = unit_circle();
        assert_eq!(c.point(-1.0), c.point(0.0));
        assert_eq!(c.point(f64::NAN), c.point(0.0));
        assert_eq!(c.point(7.0), c.point(1.0));
        assert!(c.eval(f64::INFINITY).p[0].is_finite());
    }

    /// A control point 3e19 mm out (a typo in a path file), a length beyond f64, or one
    /// whose rounding noise swamps the derivative used to split the length integral down
    /// to all 2^30 pieces, never meeting 1e-11 mm.
    #[test]
    fn length_of_a_huge_or_overflowing_curve_returns() {
        let far = Nurbs::<3>::new(
            2,
            vec![0.0, 0.0, 0.0, 0.4, 1.0, 1.0, 1.0],
            vec![
                [3.0, 0.0, 0.0],
                [10.0, 5.0, 0.0],
                [20.0, 0.0, 1.0],
                [3e19, 0.0, 51.0],
            ],
            None,
        )
        .unwrap();
        let length = far.length();
        assert!((length / 3e19 - 1.0).abs() < 1e-6, "{length}");
        let overflowing = Nurbs::<3>::new(
            1,
            vec![0.0, 0.0, 1.0, 1.0],
            vec![[-1e308, 0.0, 0.0], [1e308, 0.0, 0.0]],
            None,
        )
        .unwrap();
        assert_eq!(overflowing.length(), f64::INFINITY);
        // A control point at 3e121 drowns the derivative near the others in rounding
        // noise: the length is rough, but it comes back.
        let noisy = Nurbs::<2>::new(
            3,
            vec![0.0, 0.0, 0.0, 0.0, 0.5, 1.0, 1.0, 1.0, 1.0],
            vec![
                [1.0, 0.0],
                [10.0, 5.0],
                [40.0, 1.0],
                [3.07e121, 5.0],
                [40.0, 0.0],
            ],
            Some(vec![1.0, 1.0, 2.0, 1.0, 1.0]),
        )
        .unwrap();
        assert!(noisy.length() > 1e120, "{}", noisy.length());
    }
}
