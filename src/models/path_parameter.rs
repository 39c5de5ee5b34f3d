//! The two-axis `path` parameter, shared by `PathInterpolator2D` (the path to follow) and
//! `ContourCCC2D` (the path its `program` estimator measures against): one spelling, one
//! reading, so the same value names the same path in both FMUs.

use super::line_arc_parameters;
use crate::framework::model::Environment;
use crate::framework::variables::{Start, Values, Variable};
use contour_core::path::planar::Path;

/// The parameter's start value: the paper's circle.
pub const DEFAULT: &str = "circle";

/// The parameter's description in both model descriptions.
pub const DESCRIPTION: &str = "circle (the paper's), line or arc (from the line.*/arc.* \
     parameters), infinity, trident, a NURBS JSON file or a G-code program (.ngc, .nc, \
     .gcode, .tap): absolute, or relative to the FMU's resources folder";

/// The `tolerance` parameter, the same in both models.
pub const TOLERANCE: Variable = Variable::parameter(
    "tolerance",
    Start::Real(0.0),
    "How far a blended corner may leave the programmed one: the blend of bare G64 and \
     until a program's first G61/G64 (0: exact stops); the interpolator and the \
     controller's program estimator need the same value",
)
.unit("mm")
.min(0.0);

/// The path `spec` names, with `line` and `arc` from the model's `line.*`/`arc.*`
/// block; file errors name the file and line.
pub fn path(
    spec: &str,
    values: &Values,
    geometry: line_arc_parameters::Block,
    environment: &Environment,
) -> Result<Path, String> {
    let spec = spec.trim();
    match spec.to_ascii_lowercase().as_str() {
        "line" => line_arc_parameters::line(values, geometry).map(Path::Line),
        "arc" => line_arc_parameters::arc(values, geometry).map(Path::Arc),
        _ => Path::from_spec(spec, environment.resource_dir.as_deref()).map_err(|e| {
            let e = e.to_string();
            format!(
                "parameter 'path': {e}{}",
                resource_hint(spec, environment, &e)
            )
        }),
    }
}

/// What the reader skipped in a G-code program, for the log (and gone from the path).
pub fn reader_warnings(path: &mut Path) -> Vec<String> {
    match path {
        Path::Program(program) => std::mem::take(&mut program.warnings)
            .into_iter()
            .map(|w| format!("parameter 'path': {w}"))
            .collect(),
        _ => Vec::new(),
    }
}

/// The cause when a relative path file cannot be read and the importer gave no usable
/// resource location (NULL, or not a local file URI) to look it up in: the file system's
/// "No such file" alone would hide it.
pub fn resource_hint(spec: &str, environment: &Environment, error: &str) -> &'static str {
    let relative = std::path::Path::new(spec.trim()).is_relative();
    if relative && environment.resource_dir.is_none() && error.contains("cannot read") {
        " (looked up in the working directory: the importer gave no usable resource location)"
    } else {
        ""
    }
}
