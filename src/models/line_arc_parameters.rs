//! The line and arc geometry parameters shared by `PathInterpolator2D` (the path to
//! follow) and `ContourCCC2D` (the exact line/arc estimators): the same names and
//! defaults in both FMUs, so one set of values describes one path. The defaults are the
//! core's built-in `line` and `arc` (`builtin::LINE_ENDS`, `builtin::ARC`): `line` and
//! `arc` name the same paths in the core and in the FMUs until these parameters change.

use crate::framework::variable_table::Reals;
use crate::framework::variables::{Start, Values, Variable};
use contour_core::path::planar::builtin;
use contour_core::path::{CircularArc, Line};

/// Number of variables in the block.
pub const COUNT: usize = 9;

/// The block's handle in a model's table.
pub type Block = Reals<COUNT>;

/// Offsets of the variables in the block.
pub const LINE_X0: usize = 0;
pub const LINE_Y0: usize = 1;
pub const LINE_X1: usize = 2;
pub const LINE_Y1: usize = 3;
pub const ARC_CX: usize = 4;
pub const ARC_CY: usize = 5;
pub const ARC_R: usize = 6;
pub const ARC_START: usize = 7;
pub const ARC_SWEEP: usize = 8;

const fn length(name: &'static str, start: f64, description: &'static str) -> Variable {
    Variable::parameter(name, Start::Real(start), description).unit("mm")
}

/// The block's variables, in offset order.
pub const VARIABLES: [Variable; COUNT] = [
    length("line.x0", builtin::LINE_ENDS[0][0], "Line start, x"),
    length("line.y0", builtin::LINE_ENDS[0][1], "Line start, y"),
    length("line.x1", builtin::LINE_ENDS[1][0], "Line end, x"),
    length("line.y1", builtin::LINE_ENDS[1][1], "Line end, y"),
    length("arc.cx", builtin::ARC.0[0], "Arc centre, x"),
    length("arc.cy", builtin::ARC.0[1], "Arc centre, y"),
    length("arc.r", builtin::ARC.1, "Arc radius"),
    Variable::parameter(
        "arc.start",
        Start::Real(builtin::ARC.2),
        "Angle of the arc's start point as seen from its centre",
    )
    .unit("rad"),
    Variable::parameter(
        "arc.sweep",
        Start::Real(builtin::ARC.3),
        "Swept angle: > 0 counter-clockwise, < 0 clockwise, ±2π a full circle",
    )
    .unit("rad"),
];

/// The line of the block.
pub fn line(values: &Values, block: Block) -> Result<Line, String> {
    let v = block.get(values);
    Line::new([v[LINE_X0], v[LINE_Y0]], [v[LINE_X1], v[LINE_Y1]])
        .map_err(|e| format!("parameters 'line.*': {e}"))
}

/// The arc of the block.
pub fn arc(values: &Values, block: Block) -> Result<CircularArc, String> {
    let v = block.get(values);
    CircularArc::new([v[ARC_CX], v[ARC_CY]], v[ARC_R], v[ARC_START], v[ARC_SWEEP])
        .map_err(|e| format!("parameters 'arc.*': {e}"))
}
