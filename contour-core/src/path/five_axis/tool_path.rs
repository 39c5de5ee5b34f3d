//! Five-axis references: the tool tip's path with the tool axis along it, in the
//! workpiece frame (docs/design/five-axis.md §5.3a). Two shapes: a pair of curves (the tip, and the
//! point `length` mm up the tool axis) or a sequence of poses joined by straight tip
//! moves with the axis slerped in between (CL data, sampled built-ins).

use crate::math;
use std::sync::{Arc, OnceLock};

use serde::{Deserialize, Serialize};

use super::programmed_feed::{program_feeds, FeedChange};
use crate::geometry::{self, slerp, Vector};
use crate::kinematics::Pose;
use crate::part_program::cl_data::load_cl;
use crate::part_program::cutter_compensation::compensate;
use crate::part_program::gcode::{load_gcode, GcodeOptions};
use crate::part_program::{file_kind, FileKind, Motion, PartProgram, Speed, Warning};
use crate::path::nurbs_file::read_path_file;
use crate::path::{clamp_param, Curve, Nurbs, NurbsData, PathError};

/// Samples per turn of the sampled built-ins: chords of at most 3.2 µm, deviating from the
/// curves they sample by < 0.3 nm; a nearest point on them lies within 0.1 µm of the one on
/// the curve at 0.3 mm off the tightest bend (the truth for the five-axis tests).
const SAMPLES_PER_TURN: usize = 40_000;

/// The most poses a curve pair is sampled into ([`ToolPath::poses`]): 2^24, 0.8 GB of
/// poses, a 168 m path at `contour-eval`'s 0.01 mm chords. A longer one is a typo in a
/// path file (a control point at 1e308 made the count overflow), refused with a message
/// rather than a failed allocation.
pub const MAX_SAMPLED_POSES: usize = 1 << 24;

/// A five-axis reference. Serialised (FMU state) through [`ToolPathData`], so bytes from
/// elsewhere are validated like a file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "ToolPathData", into = "ToolPathData")]
pub enum ToolPath {
    /// The tip curve and the curve of the point `length` mm up the tool axis, on the same
    /// parameter.
    Curves {
        /// The tool tip's curve, mm.
        tip: Nurbs<3>,
        /// The curve of the point `length` up the tool axis, mm.
        second: Nurbs<3>,
        /// Distance between the two curves along the tool axis, mm.
        length: f64,
    },
    /// Poses in order: tips joined by straight moves, axes by slerp; a tip may repeat
    /// where the tool turns on the spot. Parameter u runs from 0 at the first pose to
    /// n − 1 at the last, pose i at i. Clones share the poses.
    Poses {
        /// The tips, mm.
        tips: Arc<[Vector<3>]>,
        /// The unit tool axes, one per tip.
        axes: Arc<[Vector<3>]>,
    },
}

/// The serialised form of a [`ToolPath`]; converting it back checks it as the
/// constructors do (unit axes kept as they are, to the last bit).
#[derive(Serialize, Deserialize)]
pub enum ToolPathData {
    /// [`ToolPath::Curves`].
    Curves {
        /// The tip curve.
        tip: Nurbs<3>,
        /// The second curve.
        second: Nurbs<3>,
        /// Their distance along the tool axis, mm.
        length: f64,
    },
    /// [`ToolPath::Poses`].
    Poses {
        /// The tips, mm.
        tips: Vec<Vector<3>>,
        /// The unit tool axes.
        axes: Vec<Vector<3>>,
    },
}

impl From<ToolPath> for ToolPathData {
    fn from(path: ToolPath) -> Self {
        match path {
            ToolPath::Curves {
                tip,
                second,
                length,
            } => ToolPathData::Curves {
                tip,
                second,
                length,
            },
            ToolPath::Poses { tips, axes } => ToolPathData::Poses {
                tips: tips.to_vec(),
                axes: axes.to_vec(),
            },
        }
    }
}

impl TryFrom<ToolPathData> for ToolPath {
    type Error = PathError;
    fn try_from(data: ToolPathData) -> Result<Self, PathError> {
        match data {
            ToolPathData::Curves {
                tip,
                second,
                length,
            } => {
                if tip.param_range() != second.param_range() {
                    return Err(PathError::invalid(
                        "tip and second curves have different parameter ranges",
                    ));
                }
                if !(length.is_finite() && length > 0.0) {
                    return Err(PathError::invalid(format!(
                        "length must be > 0 mm, got {length}"
                    )));
                }
                Ok(ToolPath::Curves {
                    tip,
                    second,
                    length,
                })
            }
            ToolPathData::Poses { tips, axes } => {
                if tips.len() != axes.len() {
                    return Err(PathError::invalid(format!(
                        "{} tips but {} tool axes",
                        tips.len(),
                        axes.len()
                    )));
                }
                if let Some(i) = axes.iter().position(|a| {
                    let off = (geometry::norm(a) - 1.0).abs();
                    off.is_nan() || off >= 1e-12
                }) {
                    return Err(PathError::invalid(format!(
                        "tool axis {i} is not a unit vector"
                    )));
                }
                let poses: Vec<Pose> = tips
                    .into_iter()
                    .zip(axes)
                    .map(|(tip, axis)| Pose { tip, axis })
                    .collect();
                let checked = ToolPath::from_poses(&poses)?;
                // Keep the axes as saved (normalising again could move the last bit).
                match checked {
                    ToolPath::Poses { tips, .. } => Ok(ToolPath::Poses {
                        tips,
                        axes: poses.iter().map(|p| p.axis).collect::<Vec<_>>().into(),
                    }),
                    curves => Ok(curves),
                }
            }
        }
    }
}

/// The JSON form: `{"tip": NURBS, "second": NURBS, "length": L}`, each NURBS as in a
/// planar path file but with 3-D control points; `second` is the curve of the point `L`
/// mm up the tool axis and must share the tip curve's parameter range.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ToolPathFile {
    tip: NurbsData<3>,
    second: NurbsData<3>,
    length: f64,
}

/// Names of the built-in five-axis paths.
pub const BUILTIN_TOOL_PATHS: [&str; 2] = ["tilted_helix", "figure_eight"];

/// The largest sag of the chords a G-code arc becomes on the five-axis machine (as a CL
/// `CIRCLE`'s), mm.
pub const GCODE_ARC_SAG: f64 = 5e-4;

/// The most moves a G-code program's arcs may become (2²², under a gigabyte of moves: an
/// arc of 10 m radius is 10 000 chords a turn); a program past it is refused, naming the
/// arc.
pub const MAX_GCODE_MOVES: usize = 1 << 22;

/// A part program as the five-axis machine follows it: the tool centre's moves (cutter
/// radius compensation applied), every arc as chords within [`GCODE_ARC_SAG`].
/// As on the XY table, rapids before the first cut only position the tool: the path
/// starts where the first feed move starts. A dwell or stop is not a standstill of the
/// five-axis plan: it is skipped, with a warning.
pub fn machine_moves(program: &PartProgram) -> Result<PartProgram, PathError> {
    let mut moves = compensate(program)?.with_arcs_as_chords(GCODE_ARC_SAG, MAX_GCODE_MOVES)?;
    let is_move = |m: &crate::part_program::PartMove| !matches!(m.motion, Motion::Dwell(_));
    if let Some(cut) = moves
        .moves
        .iter()
        .position(|m| is_move(m) && m.speed != Speed::Rapid)
    {
        let from = moves.moves[..cut]
            .iter()
            .rev()
            .find(|m| is_move(m))
            .map_or(moves.start, |m| m.end);
        let mut start = moves.moves[cut].clone();
        start.motion = Motion::Line;
        start.end = from;
        moves.moves.splice(..cut, [start]);
    }
    if let Some(dwell) = moves
        .moves
        .iter()
        .find(|m| matches!(m.motion, Motion::Dwell(_)))
    {
        moves.warnings.push(Warning {
            file: moves.file.clone(),
            place: dwell.place,
            message: "dwells and stops (G4, M0, M1) skipped: the five-axis plan has no \
                      standstill; further ones are skipped silently"
                .into(),
        });
    }
    Ok(moves)
}

/// A part program file, CL data or G-code (read with `options`) by its ending, as the
/// five-axis machine follows it ([`machine_moves`]).
pub fn load_program(
    file: &std::path::Path,
    options: &GcodeOptions,
) -> Result<PartProgram, PathError> {
    match file_kind(file) {
        Some(FileKind::GCode) => machine_moves(&load_gcode(file, options)?),
        _ => load_cl(file),
    }
}

/// How a five-axis reference is named: a part program (CL data: `.cl`, `.apt`, `.cls`,
/// `.aptsource`, `.ncl`; G-code: `.ngc`, `.nc`, `.gcode`, `.tap`), a two-curve JSON file
/// (`.json`), or a built-in.
enum Source<'a> {
    Program(&'a str),
    Json(&'a str),
    Builtin(&'a str),
}

fn source(spec: &str) -> Source<'_> {
    match file_kind(std::path::Path::new(spec)) {
        Some(FileKind::ClData | FileKind::GCode) => Source::Program(spec),
        Some(FileKind::Json) => Source::Json(spec),
        _ => Source::Builtin(spec),
    }
}

/// The poses of the reference named `spec` (see [`ToolPath::load`]) and the CL reader's
/// warnings: a CL file's records as written (a tool turning on the spot is kept), a
/// curve pair sampled so that no tip chord exceeds `chord` mm.
pub fn load_poses(spec: &str, chord: f64) -> Result<(Vec<Pose>, Vec<String>), PathError> {
    load_poses_with(spec, chord, &GcodeOptions::default())
}

/// [`load_poses`] with a G-code program read with `gcode`.
pub fn load_poses_with(
    spec: &str,
    chord: f64,
    gcode: &GcodeOptions,
) -> Result<(Vec<Pose>, Vec<String>), PathError> {
    match source(spec) {
        Source::Program(file) => {
            let program = load_program(file.as_ref(), gcode)?;
            Ok((program.poses(), program.warning_lines()))
        }
        Source::Json(file) => {
            let (path, _) = ToolPath::load(spec)?;
            let poses = path.poses(chord).map_err(|e| e.in_file(file))?;
            Ok((poses, Vec::new()))
        }
        Source::Builtin(_) => Ok((ToolPath::load(spec)?.0.poses(chord)?, Vec::new())),
    }
}

/// The piece of a pose path of `count` poses holding parameter `u` (clamped into the
/// path; NaN at the start), and the fraction along it.
pub fn locate(count: usize, u: f64) -> (usize, f64) {
    let u = clamp_param(u, 0.0, (count - 1) as f64);
    let i = (u.floor() as usize).min(count - 2);
    (i, u - i as f64)
}

/// The tip path's length of a pose path, mm.
pub fn tips_length(tips: &[Vector<3>]) -> f64 {
    tips.windows(2).map(|w| geometry::dist(&w[0], &w[1])).sum()
}

/// The pieces a tip curve of `length` mm is first sampled into at chords of at most
/// `chord` mm: one a chord of its length, refused when the poses would pass `budget`
/// (also for a length that overflowed to infinity).
fn first_pieces(length: f64, chord: f64, budget: usize) -> Result<usize, PathError> {
    if !(chord.is_finite() && chord > 0.0) {
        return Err(PathError::invalid(format!(
            "the sampling chord must be finite and > 0 mm, got {chord}"
        )));
    }
    let pieces = (length / chord).ceil();
    // n pieces are n + 1 poses; NaN fails too.
    if pieces.is_nan() || pieces >= budget as f64 {
        return Err(PathError::invalid(format!(
            "the tip curve is {length:e} mm long: at chords of at most {chord} mm that takes \
             {pieces:e} poses, more than the {budget} a path may be sampled into"
        )));
    }
    Ok((pieces as usize).max(1))
}

impl ToolPath {
    /// The built-in path called `name` (one of [`BUILTIN_TOOL_PATHS`]).
    pub fn builtin(name: &str) -> Result<ToolPath, PathError> {
        match name {
            // Sampled once per process and shared: every instance on a built-in holds
            // the same 80 001 poses, and instantiating one costs no sampling.
            "tilted_helix" => {
                static HELIX: OnceLock<ToolPath> = OnceLock::new();
                Ok(HELIX.get_or_init(ToolPath::tilted_helix).clone())
            }
            "figure_eight" => {
                static EIGHT: OnceLock<ToolPath> = OnceLock::new();
                Ok(EIGHT.get_or_init(ToolPath::figure_eight).clone())
            }
            _ => Err(PathError::invalid(format!(
                "unknown five-axis path {name:?}: expected a CL file (.cl, .apt, .cls, .aptsource, \
                 .ncl), a G-code program (.ngc, .nc, .gcode, .tap) or a .json file, or a \
                 built-in ({})",
                BUILTIN_TOOL_PATHS.join(", ")
            ))),
        }
    }

    /// The reference named `spec`: a part program (CL data or G-code, see [`Source`]), a
    /// two-curve JSON file (`.json`), or a built-in name; with the CL reader's warnings.
    pub fn load(spec: &str) -> Result<(ToolPath, Vec<String>), PathError> {
        let (path, _, warnings) = Self::load_with_feeds(spec, 1.0, 1.0)?;
        Ok((path, warnings))
    }

    /// [`ToolPath::load`] with a CL file's speeds move by move ([`program_feeds`]: `feed`
    /// before its first `FEDRAT`, `rapid` at `RAPID`); none for another path.
    pub fn load_with_feeds(
        spec: &str,
        feed: f64,
        rapid: f64,
    ) -> Result<(ToolPath, Vec<FeedChange>, Vec<String>), PathError> {
        match source(spec) {
            Source::Program(file) => {
                let program = load_program(file.as_ref(), &GcodeOptions::default())?;
                Ok((
                    ToolPath::from_poses(&program.poses())?,
                    program_feeds(&program, feed, rapid),
                    program.warning_lines(),
                ))
            }
            Source::Json(file) => {
                let (name, text) = read_path_file(file.as_ref())?;
                Ok((ToolPath::parse_json(&text, &name)?, Vec::new(), Vec::new()))
            }
            Source::Builtin(name) => Ok((ToolPath::builtin(name)?, Vec::new(), Vec::new())),
        }
    }

    /// The reference as poses: the vertices of a pose path; a curve pair sampled
    /// uniformly in its parameter, doubling the count until no tip chord exceeds `chord`
    /// mm (finite, > 0). A curve pair that needs more than [`MAX_SAMPLED_POSES`] poses
    /// for that (a tip curve too long, or too unevenly parametrised) is refused before
    /// anything is allocated for it.
    pub fn poses(&self, chord: f64) -> Result<Vec<Pose>, PathError> {
        self.poses_within(chord, MAX_SAMPLED_POSES)
    }

    /// [`Self::poses`] with at most `budget` poses.
    fn poses_within(&self, chord: f64, budget: usize) -> Result<Vec<Pose>, PathError> {
        match self {
            ToolPath::Poses { tips, axes } => Ok(tips
                .iter()
                .zip(axes.iter())
                .map(|(&tip, &axis)| Pose { tip, axis })
                .collect()),
            ToolPath::Curves { tip, .. } => {
                let mut n = first_pieces(tip.length(), chord, budget)?;
                let (u0, u1) = tip.param_range();
                loop {
                    let poses: Vec<Pose> = (0..=n)
                        .map(|i| self.pose_at(u0 + (u1 - u0) * i as f64 / n as f64))
                        .collect();
                    let longest = poses
                        .windows(2)
                        .map(|w| geometry::dist(&w[0].tip, &w[1].tip))
                        .fold(0.0, f64::max);
                    if longest <= chord {
                        return Ok(poses);
                    }
                    if 2 * n >= budget {
                        return Err(PathError::invalid(format!(
                            "the tip curve's chords are still up to {longest:.3e} mm at {} \
                             poses, over {chord} mm: doubling again would pass the {} a \
                             path may be sampled into (a curve that runs far faster in \
                             parts of its parameter range than in others)",
                            n + 1,
                            budget
                        )));
                    }
                    n *= 2;
                }
            }
        }
    }

    /// Parses the JSON form; `name` is used in messages.
    pub fn parse_json(text: &str, name: &str) -> Result<Self, PathError> {
        let fail = |line: usize, column: usize, message: String| PathError::File {
            file: name.to_string(),
            line,
            column,
            message,
        };
        let file: ToolPathFile = serde_json::from_str(text).map_err(|e| {
            fail(
                e.line(),
                e.column(),
                format!("wrong five-axis path file: {e}"),
            )
        })?;
        let curve = |data: NurbsData<3>, which: &str| {
            Nurbs::try_from(data).map_err(|e| fail(0, 0, format!("{which}: {e}")))
        };
        let (tip, second) = (curve(file.tip, "tip")?, curve(file.second, "second")?);
        if tip.param_range() != second.param_range() {
            return Err(fail(
                0,
                0,
                format!(
                    "tip and second curves have different parameter ranges {:?} and {:?}",
                    tip.param_range(),
                    second.param_range()
                ),
            ));
        }
        if !(file.length.is_finite() && file.length > 0.0) {
            return Err(fail(
                0,
                0,
                format!("length must be > 0 mm, got {}", file.length),
            ));
        }
        Ok(ToolPath::Curves {
            tip,
            second,
            length: file.length,
        })
    }

    /// From poses (at least two, finite, axes nonzero and normalised; consecutive poses
    /// differ in the tip or the axis: a tool may turn on the spot).
    pub fn from_poses(poses: &[Pose]) -> Result<Self, PathError> {
        if poses.len() < 2 {
            return Err(PathError::invalid(format!(
                "a pose path needs at least two poses, got {}",
                poses.len()
            )));
        }
        if let Some(i) = poses.iter().position(|p| !geometry::is_finite(&p.tip)) {
            return Err(PathError::invalid(format!("tip {i} is not finite")));
        }
        let tips: Arc<[Vector<3>]> = poses.iter().map(|p| p.tip).collect();
        let axes = poses
            .iter()
            .enumerate()
            .map(|(i, p)| {
                geometry::unit(&p.axis).ok_or_else(|| {
                    PathError::invalid(format!("tool axis {i} is zero or not finite"))
                })
            })
            .collect::<Result<Vec<_>, _>>()?;
        if let Some(i) = axes
            .windows(2)
            .position(|w| slerp(&w[0], &w[1], 0.5).is_none())
        {
            return Err(PathError::invalid(format!(
                "tool axes {i} and {} are opposite: no unique turn between them",
                i + 1
            )));
        }
        if let Some(i) =
            (1..poses.len()).find(|&i| tips[i] == tips[i - 1] && axes[i] == axes[i - 1])
        {
            return Err(PathError::invalid(format!(
                "poses {} and {i} are the same: a move must move the tip or turn the tool",
                i - 1
            )));
        }
        Ok(ToolPath::Poses {
            tips,
            axes: axes.into(),
        })
    }

    /// The pose at parameter `u` of the tip curve.
    pub fn pose_at(&self, u: f64) -> Pose {
        match self {
            ToolPath::Curves { tip, second, .. } => {
                let p = tip.point(u);
                let axis = geometry::unit(&(second.point(u) - p)).unwrap_or_else(Vector::z);
                Pose { tip: p, axis }
            }
            ToolPath::Poses { tips, axes } => {
                let (i, t) = locate(tips.len(), u);
                let axis = slerp(&axes[i], &axes[i + 1], t).unwrap_or(axes[i]);
                Pose {
                    tip: tips[i] + (tips[i + 1] - tips[i]) * t,
                    axis,
                }
            }
        }
    }

    /// A helix of radius 20 mm and pitch 5 mm, two turns, with the tool tilted 20° from
    /// the helix axis toward its centre line; the helix stands at (30, 10) on the table,
    /// off the C axis. (Centred on the C axis the table would turn the part under a tool
    /// that only rises: every joint moves uniformly and a lag is a pure delay along the
    /// path, with no contour error to correct.)
    pub fn tilted_helix() -> ToolPath {
        let n = 2 * SAMPLES_PER_TURN;
        let tilt = 20f64.to_radians();
        let poses: Vec<Pose> = (0..=n)
            .map(|i| {
                let t = i as f64 / SAMPLES_PER_TURN as f64 * std::f64::consts::TAU;
                let (s, c) = math::sincos(t);
                Pose {
                    tip: Vector::<3>::new(
                        30.0 + 20.0 * c,
                        10.0 + 20.0 * s,
                        5.0 * t / std::f64::consts::TAU,
                    ),
                    axis: Vector::<3>::new(
                        -math::sin(tilt) * c,
                        -math::sin(tilt) * s,
                        math::cos(tilt),
                    ),
                }
            })
            .collect();
        ToolPath::from_poses(&poses).expect("built-in helix is valid")
    }

    /// A figure eight in the plane z = 0 (40 × 20 mm, x = 20 sin t, y = 10 sin 2t) whose
    /// two loops cross at the origin. The tool is tilted 25° toward +y and leans 15°·cos t
    /// toward ±x, so where the tips meet (t = 0 and π) the axes differ by 2·asin(sin 15°·
    /// cos 25°) ≈ 27.1°; the tilt keeps the tool off the C axis (A ≥ 25°), where C would
    /// have to turn half a revolution at once.
    pub fn figure_eight() -> ToolPath {
        let n = 2 * SAMPLES_PER_TURN;
        let poses: Vec<Pose> = (0..=n)
            .map(|i| {
                let t = i as f64 / n as f64 * std::f64::consts::TAU;
                let lean = 15f64.to_radians() * math::cos(t);
                let tilt = 25f64.to_radians();
                Pose {
                    tip: Vector::<3>::new(20.0 * math::sin(t), 10.0 * math::sin(2.0 * t), 0.0),
                    axis: Vector::<3>::new(
                        math::sin(lean) * math::cos(tilt),
                        math::sin(tilt),
                        math::cos(lean) * math::cos(tilt),
                    ),
                }
            })
            .collect();
        ToolPath::from_poses(&poses).expect("built-in figure eight is valid")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::angle_between;
    use crate::kinematics::TableTiltingAc;

    type V3 = Vector<3>;

    #[test]
    fn poses_are_slerped_between_vertices() {
        let path = ToolPath::from_poses(&[
            Pose {
                tip: V3::zeros(),
                axis: V3::z(),
            },
            Pose {
                tip: V3::new(10.0, 0.0, 0.0),
                axis: V3::new(2.0, 0.0, 0.0),
            },
        ])
        .unwrap();
        let pose = path.pose_at(0.5);
        assert_eq!(pose.tip, V3::new(5.0, 0.0, 0.0));
        let half = std::f64::consts::FRAC_PI_4;
        assert!((pose.axis - V3::new(math::sin(half), 0.0, math::cos(half))).amax() < 1e-15);
        let opposite = ToolPath::from_poses(&[
            Pose {
                tip: V3::zeros(),
                axis: V3::z(),
            },
            Pose {
                tip: V3::x(),
                axis: -V3::z(),
            },
        ]);
        assert!(opposite.unwrap_err().to_string().contains("opposite"));
    }

    #[test]
    fn reads_the_two_curve_json_form() {
        // A straight tip move with the second point 100 mm up a tool tilting from +z
        // toward +x: at the middle the axis is the normalised mean.
        let text = r#"{
            "tip": {"degree": 1, "knots": [0, 0, 1, 1], "control_points": [[0, 0, 0], [10, 0, 0]]},
            "second": {"degree": 1, "knots": [0, 0, 1, 1], "control_points": [[0, 0, 100], [110, 0, 0]]},
            "length": 100
        }"#;
        let path = ToolPath::parse_json(text, "tilt.json").unwrap();
        let pose = path.pose_at(0.5);
        assert_eq!(pose.tip, V3::new(5.0, 0.0, 0.0));
        let half = std::f64::consts::FRAC_PI_4;
        assert!((pose.axis - V3::new(math::sin(half), 0.0, math::cos(half))).amax() < 1e-15);
        let bad = text.replace(
            "[0, 0, 1, 1], \"control_points\": [[0, 0, 100]",
            "[0, 0, 2, 2], \"control_points\": [[0, 0, 100]",
        );
        let e = ToolPath::parse_json(&bad, "tilt.json")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("tilt.json") && e.contains("parameter ranges"),
            "{e}"
        );
        let e = ToolPath::parse_json("{\"tip\": 1}", "x.json")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("x.json:1:"), "{e}");
    }

    #[test]
    fn references_are_named_by_file_kind_or_built_in_name() {
        let dir = std::env::temp_dir().join(format!("tool-path-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        // A CL file with a tool turning on the spot: kept as poses and as a path (a plan
        // runs the turn); the reference at constant tip feed refuses it (the tip does not
        // move).
        let cl = dir.join("part.CL");
        std::fs::write(
            &cl,
            "GOTO/0,0,0,0,0,1\nGOTO/1,0,0,0,0,2\nGOTO/1,0,0,0,0.6,0.8\nGOTO/2,0,0,0,0.6,0.8\n",
        )
        .unwrap();
        let spec = cl.to_str().unwrap();
        let (poses, warnings) = load_poses(spec, 0.01).unwrap();
        assert_eq!(poses.len(), 4);
        assert_eq!(warnings.len(), 1, "{warnings:?}");
        let (path, _) = ToolPath::load(spec).unwrap();
        let e = super::super::JointReference::new(path, TableTiltingAc::default(), 10.0, 1e-3)
            .unwrap_err()
            .to_string();
        assert!(e.contains("turns on the spot from pose 1 to pose 2"), "{e}");
        let json = dir.join("tilt.json");
        std::fs::write(
            &json,
            r#"{"tip": {"degree": 1, "knots": [0, 0, 1, 1], "control_points": [[0, 0, 0], [1, 0, 0]]},
                "second": {"degree": 1, "knots": [0, 0, 1, 1], "control_points": [[0, 0, 100], [1, 0, 100]]},
                "length": 100}"#,
        )
        .unwrap();
        // 1 mm sampled at chords ≤ 0.3 mm: 4 pieces.
        let (poses, _) = load_poses(json.to_str().unwrap(), 0.3).unwrap();
        assert_eq!(poses.len(), 5);
        assert!((poses[1].tip - V3::new(0.25, 0.0, 0.0)).amax() < 1e-15);
        let (helix, _) = ToolPath::load("tilted_helix").unwrap();
        assert_eq!(helix, ToolPath::tilted_helix());
        let e = ToolPath::load("spiral").unwrap_err().to_string();
        assert!(e.contains("spiral") && e.contains("figure_eight"), "{e}");
        let e = ToolPath::load(dir.join("missing.json").to_str().unwrap())
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("missing.json") && e.contains("cannot read"),
            "{e}"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// A two-curve file whose tip runs from −1e308 to 1e308 along x (its length
    /// overflows): sampling it used to ask for usize::MAX poses and abort on the capacity
    /// overflow; now it is refused, naming the file, before anything is allocated.
    #[test]
    fn a_path_too_long_to_sample_is_refused_before_allocating() {
        let text = r#"{
            "tip": {"degree": 1, "knots": [0, 0, 1, 1], "control_points": [[-1e308, 0, 0], [1e308, 0, 0]]},
            "second": {"degree": 1, "knots": [0, 0, 1, 1], "control_points": [[-1e308, 0, 100], [1e308, 0, 100]]},
            "length": 100
        }"#;
        let path = ToolPath::parse_json(text, "far.json").unwrap();
        let e = path.poses(0.01).unwrap_err().to_string();
        assert_eq!(
            e,
            "invalid path: the tip curve is inf mm long: at chords of at most 0.01 mm that \
             takes inf poses, more than the 16777216 a path may be sampled into"
        );
        let dir = std::env::temp_dir().join(format!("tool-path-far-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let file = dir.join("far.json");
        std::fs::write(&file, text).unwrap();
        let spec = file.to_str().unwrap();
        let e = load_poses(spec, 0.01).unwrap_err().to_string();
        assert_eq!(
            e,
            format!(
                "{spec}: the tip curve is inf mm long: at chords of at most 0.01 mm that \
                 takes inf poses, more than the 16777216 a path may be sampled into"
            )
        );
        std::fs::remove_dir_all(&dir).unwrap();
        // 1e5 mm is 1e7 poses at 0.01 mm, inside the budget; 1e6 mm is not.
        let line = |x: f64| {
            ToolPath::parse_json(&text.replace("1e308", &x.to_string()), "line.json").unwrap()
        };
        let e = line(5e5).poses(0.01).unwrap_err().to_string();
        assert!(
            e.contains("is 1e6 mm long") && e.contains("takes 1e8 poses"),
            "{e}"
        );
        assert_eq!(line(1.0).poses(0.25).map(|p| p.len()), Ok(9));
        assert_eq!(MAX_SAMPLED_POSES, 1 << 24);
    }

    #[test]
    fn the_pose_budget_counts_poses_not_pieces() {
        // n pieces are n + 1 poses: a budget of 2^24 takes at most 2^24 − 1 pieces.
        let budget = MAX_SAMPLED_POSES;
        assert_eq!(
            first_pieces((budget - 1) as f64, 1.0, budget),
            Ok(budget - 1)
        );
        assert!(first_pieces(budget as f64, 1.0, budget).is_err());
        assert_eq!(first_pieces(0.0, 0.01, budget), Ok(1));
        for (length, chord) in [(1.0, 0.0), (1.0, -1.0), (1.0, f64::NAN), (f64::NAN, 1.0)] {
            assert!(
                first_pieces(length, chord, budget).is_err(),
                "{length} {chord}"
            );
        }
        // A tip that covers 999 of its 1000 mm in the last millionth of its parameter:
        // uniform samples need about 10^9 pieces for chords of 1 mm, so doubling stops at
        // the budget (here 4096 poses) with the chord it reached.
        let text = r#"{
            "tip": {"degree": 1, "knots": [0, 0, 0.999999, 1, 1], "control_points": [[0, 0, 0], [1, 0, 0], [1000, 0, 0]]},
            "second": {"degree": 1, "knots": [0, 0, 0.999999, 1, 1], "control_points": [[0, 0, 100], [1, 0, 100], [1000, 0, 100]]},
            "length": 100
        }"#;
        let path = ToolPath::parse_json(text, "fast.json").unwrap();
        let e = path.poses_within(1.0, 4096).unwrap_err().to_string();
        // 1000 pieces, 2000, 4000: chords of 999 mm still (the fast part between two
        // samples), and 8001 poses would pass 4096.
        assert!(
            e.contains("chords are still up to 9.990e2 mm at 4001 poses, over 1 mm"),
            "{e}"
        );
    }

    #[test]
    fn the_built_ins_have_their_designed_shape() {
        let helix = ToolPath::tilted_helix();
        for u in [0.0, 12345.5, 80000.0] {
            let p = helix.pose_at(u);
            assert!(
                (math::hypot(p.tip[0] - 30.0, p.tip[1] - 10.0) - 20.0).abs() < 1e-5,
                "radius at {u}"
            );
            assert!((angle_between(&p.axis, &V3::z()) - 20f64.to_radians()).abs() < 1e-6);
        }
        let end = helix.pose_at(80000.0).tip;
        assert!((end - V3::new(50.0, 10.0, 10.0)).amax() < 1e-9);

        // The figure eight passes the origin at t = 0, π (and 2π) with the tool leaning
        // +15°, −15° (and +15°) out of its 25° tilt toward +y.
        let eight = ToolPath::figure_eight();
        let (start, middle) = (eight.pose_at(0.0), eight.pose_at(40000.0));
        assert!(start.tip.amax() < 1e-12 && middle.tip.amax() < 1e-9);
        let expected =
            2.0 * math::asin(math::sin(15f64.to_radians()) * math::cos(25f64.to_radians()));
        assert!((angle_between(&start.axis, &middle.axis) - expected).abs() < 1e-9);
        // Never along the C axis: A stays ≥ 25° (less than 1e-9 lost to the chords).
        for i in 0..=8000 {
            let a = angle_between(&eight.pose_at(10.0 * i as f64).axis, &V3::z());
            assert!(a > 25f64.to_radians() - 1e-9, "A = {a} at {i}");
        }
    }
}
