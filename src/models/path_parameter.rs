//! The two-axis `path` parameter, shared by `PathInterpolator2D` (the path to follow) and
//! `ContourCCC2D` (the path its `program` estimator measures against): one spelling, one
//! reading, so the same value names the same path in both FMUs.

use super::line_arc_parameters;
use crate::framework::model::Environment;
use crate::framework::variable_table::{Bool, Int, Reals, Str};
use crate::framework::variables::{EnumItem, EnumType, Start, Values, Variable};
use contour_core::geometry::Vector;
use contour_core::part_program::cutter_compensation::ToolTable;
use contour_core::part_program::gcode::{Dialect, GcodeOptions};
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

/// The `dialect` parameter's type: which controller a G-code program was written for.
pub static DIALECT_TYPE: EnumType = EnumType {
    name: "GcodeDialect",
    description: "The controller a G-code program was written for, where readings differ",
    items: &[
        EnumItem {
            name: "linuxcnc",
            description: "LinuxCNC (RS-274/NGC): G4 P in seconds",
        },
        EnumItem {
            name: "fanuc",
            description: "Fanuc, Haas: G4 P (and a cycle's P) in milliseconds",
        },
    ],
};

/// The dialects in the order of [`DIALECT_TYPE`]'s items.
const DIALECTS: [Dialect; 2] = [Dialect::LinuxCnc, Dialect::Fanuc];

/// The `dialect` parameter, the same in both models.
pub const DIALECT: Variable = Variable::parameter(
    "dialect",
    Start::Integer(1),
    "How a G-code program's words are read where controllers differ: linuxcnc (G4 P in \
     seconds) or fanuc (G4 P in milliseconds)",
)
.enumeration(&DIALECT_TYPE);

/// The `optionalStop` parameter, the same in both models.
pub const OPTIONAL_STOP: Variable = Variable::parameter(
    "optionalStop",
    Start::Boolean(false),
    "Whether a G-code program's M1 stops the reference (the optional-stop switch); M0 \
     always does",
);

/// The `home.*` parameters, the same in both models.
pub const HOME: [Variable; 3] = [
    home(HOME_NAMES[0]),
    home(HOME_NAMES[1]),
    home(HOME_NAMES[2]),
];

const HOME_NAMES: [&str; 3] = ["home.x", "home.y", "home.z"];

const fn home(name: &'static str) -> Variable {
    Variable::parameter(
        name,
        Start::Real(0.0),
        "The machine's home in the program's coordinates: where G28 and G30 go, what G53 \
         counts from (default: the program's origin)",
    )
    .unit("mm")
}

/// The `toolRadii` parameter, the same in every model that reads G-code.
pub const TOOL_RADII: Variable = Variable::parameter(
    "toolRadii",
    Start::String(""),
    "The tools' radii in mm by D number for cutter radius compensation (G41, G42): D:radius \
     pairs, e.g. '1:3, 2:5.5' (a negative radius puts the tool on the other side); G41.1 and \
     G42.1 give the diameter in their D word",
);

/// A model's handles of the G-code reader's parameters.
#[derive(Clone, Copy)]
pub struct ReaderParameters {
    pub dialect: Int,
    pub optional_stop: Bool,
    pub home: Reals<3>,
    pub tools: Str,
}

impl ReaderParameters {
    /// How the model's G-code program is read.
    pub fn options(&self, values: &Values) -> Result<GcodeOptions, String> {
        let value = self.dialect.get(values);
        let dialect = usize::try_from(value)
            .ok()
            .and_then(|v| v.checked_sub(1))
            .and_then(|i| DIALECTS.get(i).copied())
            .ok_or_else(|| {
                format!(
                    "parameter 'dialect' = {value} is not one of {}",
                    DIALECT_TYPE.listing()
                )
            })?;
        let home = self.home.get(values);
        if let Some(bad) = home.iter().position(|v| !v.is_finite()) {
            return Err(format!(
                "parameter '{}' = {} must be finite",
                HOME_NAMES[bad], home[bad]
            ));
        }
        let tools = ToolTable::parse(self.tools.get(values))
            .map_err(|e| format!("parameter 'toolRadii': {e}"))?;
        Ok(GcodeOptions {
            dialect,
            optional_stop: self.optional_stop.get(values),
            home: Vector::<3>::new(home[0], home[1], home[2]),
            tools,
        })
    }
}

/// The path `spec` names, with `line` and `arc` from the model's `line.*`/`arc.*`
/// block and a G-code program read with the model's reader parameters; file errors name
/// the file and line.
pub fn path(
    spec: &str,
    values: &Values,
    geometry: line_arc_parameters::Block,
    reader: ReaderParameters,
    environment: &Environment,
) -> Result<Path, String> {
    let spec = spec.trim();
    let options = reader.options(values)?;
    match spec.to_ascii_lowercase().as_str() {
        "line" => line_arc_parameters::line(values, geometry).map(Path::Line),
        "arc" => line_arc_parameters::arc(values, geometry).map(Path::Arc),
        _ => {
            Path::from_spec_with(spec, environment.resource_dir.as_deref(), &options).map_err(|e| {
                let e = e.to_string();
                format!(
                    "parameter 'path': {e}{}",
                    resource_hint(spec, environment, &e)
                )
            })
        }
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
