//! Reference paths (lines and NURBS in any dimension, planar arcs), the built-in shapes
//! and the feed-rate interpolator that samples them every `Ts` (docs/design/two-axis.md §4.6).
//! Units: mm, s.
//!
//! Every geometric type implements [`Curve`] in its dimension, and [`Path`] is the closed
//! set of planar paths the two-axis FMUs choose from by name ([`builtin::by_name`]) or by
//! file ([`file::load_nurbs`]).

mod arc;
pub mod builtin;
pub mod cam_examples;
pub mod cl_data;
pub mod file;
mod five_axis_reference;
mod interpolator;
mod joint_reference;
mod line;
mod nurbs;
pub mod plan;
mod polyline;
pub mod program;
mod tool_path;

pub use arc::CircularArc;
pub use five_axis_reference::{FiveAxisReference, ReferenceSample};
pub use interpolator::{Interpolator, Progress, Sample};
pub use joint_reference::{JointReference, JointSample};
pub use line::Line;
pub use nurbs::{clamped_uniform_knots, Nurbs, NurbsData, MAX_DEGREE};
pub use polyline::Polyline;
pub use program::Program;
pub use tool_path::{load_poses, ToolPath, ToolPathData, BUILTIN_TOOL_PATHS};

use std::fmt;

use serde::{Deserialize, Serialize};

use crate::geometry::{self, Vector, Vector2};

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
            } => {
                // A CL record has a line but no column: "file:line:0:" would read as a
                // position that does not exist.
                if *line > 0 && *column > 0 {
                    write!(f, "{file}:{line}:{column}: {message}")
                } else if *line > 0 {
                    write!(f, "{file}:{line}: {message}")
                } else {
                    write!(f, "{file}: {message}")
                }
            }
        }
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

/// Any path the interpolator and the FMUs can follow.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum Path {
    /// Straight segment.
    Line(Line),
    /// Circular arc or full circle.
    Arc(CircularArc),
    /// NURBS curve of any degree up to [`MAX_DEGREE`].
    Nurbs(Nurbs),
    /// A G-code part program: line and arc moves end to end.
    Program(Program),
}

impl Path {
    /// Builds a path from a built-in name (`circle`, `line`, `arc`, `infinity`, `trident`)
    /// or, failing that, from a G-code program (by its name's ending) or a NURBS JSON file
    /// (relative names resolved against `base_dir`).
    pub fn from_spec(spec: &str, base_dir: Option<&std::path::Path>) -> Result<Path, PathError> {
        match builtin::by_name(spec) {
            Ok(p) => Ok(p),
            Err(PathError::UnknownName(_)) => {
                let fs = std::path::Path::new(spec);
                let full = match base_dir {
                    Some(dir) if fs.is_relative() => dir.join(fs),
                    _ => fs.to_path_buf(),
                };
                // Something that looks like a file gets the file's own error (naming it).
                let looks_like_file = spec.ends_with(".json") || spec.contains(['/', '\\']);
                if program::is_program_file(fs) {
                    program::load_program(&full).map(Path::Program)
                } else if full.is_file() || looks_like_file {
                    file::load_nurbs(&full).map(Path::Nurbs)
                } else {
                    Err(PathError::UnknownName(spec.to_string()))
                }
            }
            Err(e) => Err(e),
        }
    }

    /// First point of the path.
    pub fn start_point(&self) -> Vector2 {
        self.point(self.param_range().0)
    }

    /// Last point of the path.
    pub fn end_point(&self) -> Vector2 {
        self.point(self.param_range().1)
    }

    /// The mirror image about the x axis (y → −y), travelled in the mirrored sense: a
    /// counter-clockwise circle becomes a clockwise one. The controller must give the
    /// mirrored run exactly (the contour error negated sample by sample), which is how the
    /// tests and the demo check that it does not depend on the direction of travel.
    pub fn mirrored(&self) -> Path {
        let flip = |p: Vector2| Vector2::new(p[0], -p[1]);
        let rebuilt = match self {
            Path::Line(l) => Ok(Path::Line(l.mirrored())),
            Path::Arc(a) => Ok(Path::Arc(a.mirrored())),
            Path::Nurbs(n) => Nurbs::new(
                n.degree(),
                n.knots().to_vec(),
                n.control_points().iter().map(|&p| flip(p)).collect(),
                Some(n.weights().to_vec()),
            )
            .map(Path::Nurbs),
            Path::Program(p) => Ok(Path::Program(p.mirrored())),
        };
        // Mirroring keeps every property the constructors check.
        rebuilt.expect("the mirror image of a valid path is valid")
    }
}

impl Curve for Path {
    fn param_range(&self) -> (f64, f64) {
        match self {
            Path::Line(c) => c.param_range(),
            Path::Arc(c) => c.param_range(),
            Path::Nurbs(c) => c.param_range(),
            Path::Program(c) => c.param_range(),
        }
    }
    fn eval(&self, u: f64) -> CurvePoint {
        match self {
            Path::Line(c) => c.eval(u),
            Path::Arc(c) => c.eval(u),
            Path::Nurbs(c) => c.eval(u),
            Path::Program(c) => c.eval(u),
        }
    }
    fn point(&self, u: f64) -> Vector2 {
        match self {
            Path::Line(c) => c.point(u),
            Path::Arc(c) => c.point(u),
            Path::Nurbs(c) => c.point(u),
            Path::Program(c) => c.point(u),
        }
    }
    fn length_between(&self, u0: f64, u1: f64) -> f64 {
        match self {
            Path::Line(c) => c.length_between(u0, u1),
            Path::Arc(c) => c.length_between(u0, u1),
            Path::Nurbs(c) => c.length_between(u0, u1),
            Path::Program(c) => c.length_between(u0, u1),
        }
    }
    fn breakpoints(&self) -> Vec<f64> {
        match self {
            Path::Line(c) => c.breakpoints(),
            Path::Arc(c) => c.breakpoints(),
            Path::Nurbs(c) => c.breakpoints(),
            Path::Program(c) => c.breakpoints(),
        }
    }
}

impl From<Line> for Path {
    fn from(c: Line) -> Self {
        Path::Line(c)
    }
}
impl From<CircularArc> for Path {
    fn from(c: CircularArc) -> Self {
        Path::Arc(c)
    }
}
impl From<Program> for Path {
    fn from(c: Program) -> Self {
        Path::Program(c)
    }
}
impl From<Nurbs> for Path {
    fn from(c: Nurbs) -> Self {
        Path::Nurbs(c)
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
