//! The line and arc geometry parameters shared by `PathInterpolator2D` (the path to
//! follow) and `ContourCCC2D` (the exact line/arc estimators): the same names and
//! defaults in both FMUs, so one set of values describes one path. The defaults are the
//! built-in `line` and `arc` paths (crate::path::builtin).

use std::f64::consts::PI;

use super::variables::{Start, Values, Variable, Vr};
use crate::path::{Arc, Line};

/// Number of variables in the block.
pub const COUNT: usize = 9;

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

const fn length(vr: Vr, name: &'static str, start: f64, description: &'static str) -> Variable {
    Variable::parameter(vr, name, Start::Real(start), description).unit("mm")
}

/// The block's variables, with value references from `first` on.
pub const fn variables(first: Vr) -> [Variable; COUNT] {
    [
        length(first + LINE_X0, "line.x0", 0.0, "Line start, x"),
        length(first + LINE_Y0, "line.y0", 0.0, "Line start, y"),
        length(first + LINE_X1, "line.x1", 40.0, "Line end, x"),
        length(first + LINE_Y1, "line.y1", 30.0, "Line end, y"),
        length(first + ARC_CX, "arc.cx", -20.0, "Arc centre, x"),
        length(first + ARC_CY, "arc.cy", 0.0, "Arc centre, y"),
        length(first + ARC_R, "arc.r", 20.0, "Arc radius"),
        Variable::parameter(
            first + ARC_START,
            "arc.start",
            Start::Real(0.0),
            "Angle of the arc's start point as seen from its centre",
        )
        .unit("rad"),
        Variable::parameter(
            first + ARC_SWEEP,
            "arc.sweep",
            Start::Real(-PI),
            "Swept angle: > 0 counter-clockwise, < 0 clockwise, ±2π a full circle",
        )
        .unit("rad"),
    ]
}

/// The line of the block at `first`.
pub fn line(values: &Values, first: Vr) -> Result<Line, String> {
    let v = |i| values.real(first + i);
    Line::new([v(LINE_X0), v(LINE_Y0)], [v(LINE_X1), v(LINE_Y1)])
        .map_err(|e| format!("parameters 'line.*': {e}"))
}

/// The arc of the block at `first`.
pub fn arc(values: &Values, first: Vr) -> Result<Arc, String> {
    let v = |i| values.real(first + i);
    Arc::new([v(ARC_CX), v(ARC_CY)], v(ARC_R), v(ARC_START), v(ARC_SWEEP))
        .map_err(|e| format!("parameters 'arc.*': {e}"))
}
