//! What both machines' references are made of: curves in any dimension ([`Curve`]:
//! lines, planar arcs, NURBS, polylines), the feed-rate interpolator that samples a curve
//! every `Ts` (docs/design/two-axis.md §4.6), the time-optimal feed along a path and the
//! jerk-limited motion of one piece. Units: mm, s.
//!
//! Each machine's own paths are apart: [`planar`] (the XY table: the closed set of paths
//! its FMUs follow, its programs with blended corners, its plan) and [`five_axis`] (the
//! tool path with its axis, the joint references, the plan within the joints' limits).
//! Part programs are read in [`crate::part_program`].

mod arc;
mod feed;
pub mod five_axis;
mod interpolator;
mod line;
mod nurbs;
pub mod nurbs_file;
pub(crate) mod piece_profile;
pub mod planar;
mod polyline;

pub use arc::CircularArc;
pub use feed::{FeedConstraints, FeedPoint, FeedProfile};
pub use interpolator::{Interpolator, Progress, Sample};
pub use line::Line;
pub use nurbs::{clamped_uniform_knots, Nurbs, NurbsData, MAX_DEGREE};
pub use polyline::Polyline;

use std::fmt;

use serde::{Deserialize, Serialize};

use crate::geometry::{self, Vector};

/// Why a path could not be built, loaded or sampled.
#[derive(Clone, Debug, PartialEq)]
pub enum PathError {
    /// Geometry or parameters rejected by a constructor; the message says which and why.
    Invalid(String),
    /// A path name that is neither a built-in nor a readable file.
    UnknownName(String),
    /// A path file could not be read or parsed; `line`/`column` are 1-based when known.
    File {
        /// The file as given by the caller.
        file: String,
        /// 1-based line of a JSON error, 0 when not applicable.
        line: usize,
        /// 1-based column of a JSON error, 0 when not applicable.
        column: usize,
        /// What went wrong.
        message: String,
    },
}

impl PathError {
    pub(crate) fn invalid(msg: impl Into<String>) -> Self {
        PathError::Invalid(msg.into())
    }

    /// The error as one of the file `file` (a file's content that no path can be made of:
    /// the message names the file, without a line).
    pub(crate) fn in_file(self, file: &str) -> Self {
        PathError::File {
            file: file.to_string(),
            line: 0,
            column: 0,
            message: match self {
                PathError::Invalid(m) => m,
                other => other.to_string(),
            },
        }
    }
}

impl fmt::Display for PathError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            PathError::Invalid(m) => write!(f, "invalid path: {m}"),
            PathError::UnknownName(n) => write!(
                f,
                "unknown path '{n}': expected circle, line, arc, infinity, trident, a NURBS JSON file or a G-code program (.ngc, .nc, .gcode, .tap)"
            ),
            PathError::File {
                file,
                line,
                column,
                message,
            } => write_placed(f, file, *line, *column, message),
        }
    }
}

/// `file:line:column: message`, leaving out what is not known (a CL record has a line but
/// no column: `file:line:0:` would read as a place that does not exist).
pub(crate) fn write_placed(
    f: &mut fmt::Formatter<'_>,
    file: &str,
    line: usize,
    column: usize,
    message: &str,
) -> fmt::Result {
    match (line, column) {
        (0, _) => write!(f, "{file}: {message}"),
        (line, 0) => write!(f, "{file}:{line}: {message}"),
        (line, column) => write!(f, "{file}:{line}:{column}: {message}"),
    }
}

impl std::error::Error for PathError {}

/// Point and first two parameter derivatives of a curve at one parameter value.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct CurvePoint<const D: usize = 2> {
    /// C(u), mm.
    pub p: Vector<D>,
    /// C'(u), mm per unit parameter.
    pub d1: Vector<D>,
    /// C''(u).
    pub d2: Vector<D>,
}

impl<const D: usize> CurvePoint<D> {
    /// The unit tangent and the curvature vector d²C/ds² (toward the centre of curvature,
    /// 1/radius long) by arc length s; zeros where the curve has no tangent.
    pub fn frame(&self) -> (Vector<D>, Vector<D>) {
        match crate::geometry::unit(&self.d1) {
            Some(t) => {
                let normal = self.d2 - t * self.d2.dot(&t);
                (t, normal / self.d1.norm_squared())
            }
            None => (Vector::zeros(), Vector::zeros()),
        }
    }
}

impl<const D: usize> Default for CurvePoint<D> {
    fn default() -> Self {
        CurvePoint {
            p: Vector::zeros(),
            d1: Vector::zeros(),
            d2: Vector::zeros(),
        }
    }
}

/// A parametric curve in `D` dimensions on a closed parameter interval.
///
/// Evaluation never allocates and never panics: parameters outside the interval (and NaN)
/// are clamped to it, so a corrupt caller cannot index out of bounds.
pub trait Curve<const D: usize = 2> {
    /// Parameter interval `(u_start, u_end)`, `u_start < u_end`.
    fn param_range(&self) -> (f64, f64);
    /// Point and derivatives at `u`.
    fn eval(&self, u: f64) -> CurvePoint<D>;
    /// Point only (implementations may skip the derivative work).
    fn point(&self, u: f64) -> Vector<D> {
        self.eval(u).p
    }
    /// Arc length between two parameters (absolute, mm).
    fn length_between(&self, u0: f64, u1: f64) -> f64;
    /// Total arc length, mm.
    fn length(&self) -> f64 {
        let (a, b) = self.param_range();
        self.length_between(a, b)
    }
    /// Parameter values where derivatives may jump (knots); always includes both ends.
    /// Used to split integration and search so that each piece is smooth.
    fn breakpoints(&self) -> Vec<f64> {
        let (a, b) = self.param_range();
        vec![a, b]
    }
}

/// Clamps a parameter into `[a, b]`, mapping NaN to `a`.
#[inline]
pub(crate) fn clamp_param(u: f64, a: f64, b: f64) -> f64 {
    if u.is_nan() {
        a
    } else {
        u.clamp(a, b)
    }
}

/// Arc length of a smooth piece [a, b] by the 5-point Gauss–Legendre rule on |C'(u)|.
pub(crate) fn gl5<const D: usize, C: Curve<D> + ?Sized>(c: &C, a: f64, b: f64) -> f64 {
    // Nodes and weights of the 5-point Gauss–Legendre rule on [-1, 1].
    const X: [f64; 5] = [
        0.0,
        -0.538_469_310_105_683_1,
        0.538_469_310_105_683_1,
        -0.906_179_845_938_664,
        0.906_179_845_938_664,
    ];
    const W: [f64; 5] = [
        0.568_888_888_888_888_9,
        0.478_628_670_499_366_5,
        0.478_628_670_499_366_5,
        0.236_926_885_056_189_1,
        0.236_926_885_056_189_1,
    ];
    let m = 0.5 * (a + b);
    let h = 0.5 * (b - a);
    let mut s = 0.0;
    for k in 0..5 {
        s += W[k] * geometry::norm(&c.eval(m + h * X[k]).d1);
    }
    s * h
}

/// Arc length of a smooth piece by adaptive Gauss–Legendre quadrature of |C'(u)|.
///
/// Compares a 5-point rule on the whole interval with the sum over its halves and splits
/// until they agree to `tol` (absolute, mm); depth is bounded so the cost is bounded.
pub(crate) fn gauss_length<const D: usize, C: Curve<D> + ?Sized>(
    c: &C,
    a: f64,
    b: f64,
    tol: f64,
) -> f64 {
    fn rec<const D: usize, C: Curve<D> + ?Sized>(
        c: &C,
        a: f64,
        b: f64,
        whole: f64,
        tol: f64,
        depth: u32,
        budget: &mut u32,
    ) -> f64 {
        let m = 0.5 * (a + b);
        let l = gl5(c, a, m);
        let r = gl5(c, m, b);
        let sum = l + r;
        // Halving cannot get below the rounding of the sum (a piece 1e5 mm long has no
        // digits at 1e-11 mm), make a non-finite length finite, or converge on rounding
        // noise (a control point at 1e121 drowns a derivative of 10 near the others):
        // each would split down to all 2^30 leaves (found by fuzz/nurbs_json). Hence the
        // floor, the finiteness test and a budget of splits no smooth piece comes near.
        let floor = 8.0 * f64::EPSILON * sum.abs();
        *budget = budget.saturating_sub(1);
        if depth == 0 || *budget == 0 || !sum.is_finite() || (sum - whole).abs() <= tol.max(floor) {
            sum
        } else {
            rec(c, a, m, l, 0.5 * tol, depth - 1, budget)
                + rec(c, m, b, r, 0.5 * tol, depth - 1, budget)
        }
    }
    if b <= a {
        return 0.0;
    }
    let mut budget = 1 << 14;
    rec(c, a, b, gl5(c, a, b), tol, 30, &mut budget)
}
