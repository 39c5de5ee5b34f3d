//! The XY table's paths (docs/design/two-axis.md §4): the closed set its FMUs follow
//! ([`Path`]: a line, an arc, a NURBS curve or a part program), by name ([`builtin`]) or
//! by file; a part program's moves with their feeds and corner modes ([`Program`]), its
//! corners blended ([`blended`]); and the plan within the table's limits ([`XyPlan`],
//! sampled by [`XyReference`], §4.9).

mod blending;
pub mod builtin;
mod corner_blend;
mod nurbs_pieces;
mod plan;
mod plan_cache;
mod program;
mod reference;

pub use blending::{blended, MIN_BLEND_TURN};
pub use corner_blend::CornerBlend;
pub use plan::{planned_geometry, XyCursor, XyLimits, XyPlan, XyPoint};
pub use plan_cache::XyPlans;
pub use program::{Move, Program, Shape, Standstill};
pub use reference::{SavedXyReference, XyReference};

use serde::{Deserialize, Serialize};

use super::nurbs_file::load_nurbs;
use super::{CircularArc, Curve, CurvePoint, Line, Nurbs, PathError};
use crate::geometry::Vector2;
use crate::part_program::gcode::GcodeOptions;
use crate::part_program::{file_kind, FileKind};

/// Any path the XY table's interpolator and FMUs can follow.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum Path {
    /// Straight segment.
    Line(Line),
    /// Circular arc or full circle.
    Arc(CircularArc),
    /// NURBS curve of any degree up to [`MAX_DEGREE`](super::MAX_DEGREE).
    Nurbs(Nurbs),
    /// A G-code part program: line and arc moves end to end.
    Program(Program),
}

impl Path {
    /// Checks a path that did not come through a constructor (one read back from a saved
    /// state) as its constructor would: a line's or an arc's numbers (a radius > 0, …);
    /// a NURBS and a program check themselves when they are read.
    pub fn check(&self) -> Result<(), PathError> {
        match self {
            Path::Line(l) => Line::new(l.start(), l.end()).map(drop),
            Path::Arc(a) => {
                CircularArc::new(a.center(), a.radius(), a.start_angle(), a.sweep()).map(drop)
            }
            Path::Nurbs(_) | Path::Program(_) => Ok(()),
        }
    }

    /// Builds a path from a built-in name (`circle`, `line`, `arc`, `infinity`, `trident`)
    /// or, failing that, from a G-code program (by its name's ending) or a NURBS JSON file
    /// (relative names resolved against `base_dir`).
    pub fn from_spec(spec: &str, base_dir: Option<&std::path::Path>) -> Result<Path, PathError> {
        Path::from_spec_with(spec, base_dir, &GcodeOptions::default())
    }

    /// [`from_spec`](Self::from_spec) with a G-code program read with `options`.
    pub fn from_spec_with(
        spec: &str,
        base_dir: Option<&std::path::Path>,
        options: &GcodeOptions,
    ) -> Result<Path, PathError> {
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
                match file_kind(fs) {
                    Some(FileKind::GCode) => Program::load_with(&full, options).map(Path::Program),
                    _ if full.is_file() || looks_like_file => load_nurbs(&full).map(Path::Nurbs),
                    _ => Err(PathError::UnknownName(spec.to_string())),
                }
            }
            Err(e) => Err(e),
        }
    }

    /// The path as followed: a program's blended corners (G64) rounded within
    /// `tolerance` where the program gave no tolerance of its own ([`blended`], which the
    /// planner and contour-eval call on a program directly); other paths as they are.
    pub fn blended(self, tolerance: f64) -> Path {
        match self {
            Path::Program(program) => Path::Program(blended(&program, tolerance)),
            other => other,
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
