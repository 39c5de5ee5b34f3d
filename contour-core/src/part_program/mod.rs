//! Part programs as CAM systems write them, read in one place: G-code ([`gcode`]) and APT
//! cutter-location data ([`cl_data`]) become one model, a [`PartProgram`]: the tool's moves
//! in the workpiece frame with their feeds, corner modes and, where the format gives it,
//! the tool axis; each with the line it was read from, and the reader's warnings with
//! file, line and column. The XY table turns a part program into its
//! [`Program`](crate::path::planar::Program), the five-axis machine into its
//! [`ToolPath`](crate::path::five_axis::ToolPath); [`file_kind`] decides what a file is.
//! Units: mm, rad, s.

mod arc_words;
pub mod cl_data;
pub mod cutter_compensation;
mod drilling;
pub mod gcode;

use std::fmt;

use serde::{Deserialize, Serialize};

use crate::geometry::{Vector, Vector2};
use crate::kinematics::Pose;
use crate::path::{CircularArc, Curve, PathError};

/// The speed a move was programmed at.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum Speed {
    /// G0 (a CL `RAPID`): the machine's rapid.
    Rapid,
    /// Before the program's first feed word: the interpolator's `feed` parameter.
    Default,
    /// After a feed word (G-code F, CL `FEDRAT`), mm/s.
    Feed(f64),
}

/// What the machine does at the end of a move, where the next one begins.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum Corner {
    /// G61 (or G61.1), or the end of XY motion for a Z-only move: stop exactly.
    ExactStop,
    /// G64 P…: blend within this many mm of the programmed corner.
    Blend(f64),
    /// Bare G64: blend within the interpolator's `tolerance` parameter.
    BlendDefault,
}

/// The path of one move from the previous move's end to its own.
#[derive(Clone, Debug, PartialEq)]
pub enum Motion {
    /// A straight move of the tip (G0, G1, a CL `GOTO`).
    Line,
    /// A circular arc (G2, G3) in `plane`, in its (u, v) coordinates; the third axis w
    /// goes from the start's to the end's in proportion to the angle (a helix where they
    /// differ).
    Arc {
        /// The arc in the plane's (u, v) coordinates.
        arc: CircularArc,
        /// The plane it lies in.
        plane: Plane,
    },
    /// The tool stands where it is for this many seconds (G4, a drilling cycle's dwell);
    /// 0: a stop (M0, M1) and nothing more. Its `end` is where it stands.
    Dwell(f64),
}

/// The plane of an arc and of cutter radius compensation (G17, G18, G19), as its axes
/// (u, v, w), right-handed: an arc turns in (u, v), counter-clockwise (G3) as seen from
/// +w, and a helix climbs along w.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum Plane {
    /// G17: (X, Y, Z).
    #[default]
    Xy,
    /// G18: (Z, X, Y).
    Zx,
    /// G19: (Y, Z, X).
    Yz,
}

impl Plane {
    /// The indices (0 = X, 1 = Y, 2 = Z) of u, v and w.
    pub fn axes(self) -> [usize; 3] {
        match self {
            Plane::Xy => [0, 1, 2],
            Plane::Zx => [2, 0, 1],
            Plane::Yz => [1, 2, 0],
        }
    }

    /// The G code that selects it.
    pub fn code(self) -> &'static str {
        match self {
            Plane::Xy => "G17",
            Plane::Zx => "G18",
            Plane::Yz => "G19",
        }
    }

    /// `p`'s (u, v).
    pub fn in_plane(self, p: &Vector<3>) -> Vector2 {
        let [u, v, _] = self.axes();
        Vector2::new(p[u], p[v])
    }

    /// `p`'s w.
    pub fn across(self, p: &Vector<3>) -> f64 {
        p[self.axes()[2]]
    }

    /// The point at (u, v) and w.
    pub fn point(self, uv: Vector2, w: f64) -> Vector<3> {
        let [u, v, n] = self.axes();
        let mut p = Vector::<3>::zeros();
        p[u] = uv[0];
        p[v] = uv[1];
        p[n] = w;
        p
    }
}

/// Which side of the programmed contour the tool runs on, looking along the motion.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Side {
    /// G41.
    Left,
    /// G42.
    Right,
}

impl Side {
    /// +1 left of the motion, −1 right: the factor of the left normal that points to the
    /// tool.
    pub fn sign(self) -> f64 {
        match self {
            Side::Left => 1.0,
            Side::Right => -1.0,
        }
    }
}

/// The angle of a chord of a circle of `radius` whose sag is `sag` (both mm, > 0): the
/// most an arc may turn per chord to stay within `sag` of it (a whole turn when the sag
/// reaches the diameter).
pub fn chord_angle(radius: f64, sag: f64) -> f64 {
    2.0 * crate::math::acos((1.0 - sag / radius).max(-1.0))
}

/// Cutter radius compensation in force on a move (G41, G42): the programmed contour is
/// the part's edge, and the tool's centre runs `radius` mm to its `side` in `plane`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Compensation {
    /// The side of the contour the tool is on.
    pub side: Side,
    /// The tool's radius, mm (≥ 0).
    pub radius: f64,
    /// The plane the offset lies in (G17 or G18).
    pub plane: Plane,
    /// Which G41 or G42 of the program turned it on (from 1): a G40 and a G41 with
    /// nothing moving between them start a new stretch, with its own entry move.
    pub stretch: u32,
}

/// Where in its file something was read: 1-based line and column, 0 when not known.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Place {
    /// 1-based line, 0 when not known.
    pub line: usize,
    /// 1-based column, 0 when not known.
    pub column: usize,
}

/// One move of a part program.
#[derive(Clone, Debug, PartialEq)]
pub struct PartMove {
    /// How the tip gets to `end`.
    pub motion: Motion,
    /// Whether it is a rapid, or at which feed.
    pub speed: Speed,
    /// The tool tip at the move's end, mm, in the workpiece frame.
    pub end: Vector<3>,
    /// The tool axis at the move's end (a unit vector from the tip toward the spindle),
    /// where the format gives one (CL data); `None` for G-code, whose tool stays vertical.
    pub tool_axis: Option<Vector<3>>,
    /// The corner mode in force at the move's end.
    pub corner: Corner,
    /// The block or record the move was read from.
    pub place: Place,
    /// Where the Z word of the block was, when it had one (a third-axis move is refused
    /// there by a machine that has no third axis).
    pub z_place: Option<Place>,
    /// Cutter radius compensation in force on the move: `end` (and an arc) are then the
    /// part's contour, not the tool's centre ([`cutter_compensation`]).
    pub compensation: Option<Compensation>,
}

/// Something a reader read past or corrected, with where.
#[derive(Clone, Debug, PartialEq)]
pub struct Warning {
    /// The file as given by the caller.
    pub file: String,
    /// Where in it.
    pub place: Place,
    /// What was done.
    pub message: String,
}

impl fmt::Display for Warning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        crate::path::write_placed(
            f,
            &self.file,
            self.place.line,
            self.place.column,
            &self.message,
        )
    }
}

/// A part program: the tool's moves in order from `start`, as the file programmed them.
#[derive(Clone, Debug, PartialEq)]
pub struct PartProgram {
    /// The file as given by the caller, for messages.
    pub file: String,
    /// The tip before the first move, mm (the program's origin: a G-code program starts
    /// where its first move starts from; CL data starts at its first `GOTO`, a move from
    /// here too).
    pub start: Vector<3>,
    /// The moves in order.
    pub moves: Vec<PartMove>,
    /// What the reader read past or corrected, in the order it met them.
    pub warnings: Vec<Warning>,
}

impl PartProgram {
    /// The tool's pose at the end of every move: the tip, and the tool axis where the
    /// program gave one (+Z until it does, the vertical tool of a G-code program).
    pub fn poses(&self) -> Vec<Pose> {
        let mut axis = Vector::<3>::z();
        self.moves
            .iter()
            .filter(|m| !matches!(m.motion, Motion::Dwell(_)))
            .map(|m| {
                axis = m.tool_axis.unwrap_or(axis);
                Pose { tip: m.end, axis }
            })
            .collect()
    }

    /// The line every move of [`poses`](Self::poses) was read from, in order.
    pub fn lines(&self) -> Vec<usize> {
        self.moves
            .iter()
            .filter(|m| !matches!(m.motion, Motion::Dwell(_)))
            .map(|m| m.place.line)
            .collect()
    }

    /// The program with every arc as straight chords leaving it by at most `sag` mm (a
    /// helix's chords rise with it); a program that would pass `max_moves` moves is
    /// refused, naming the arc's line.
    pub fn with_arcs_as_chords(&self, sag: f64, max_moves: usize) -> Result<Self, PathError> {
        let mut moves = Vec::with_capacity(self.moves.len());
        let mut from = self.start;
        for m in &self.moves {
            if let Motion::Arc { arc, plane } = &m.motion {
                let chords = (arc.sweep().abs() / chord_angle(arc.radius(), sag))
                    .ceil()
                    .max(1.0);
                if chords + moves.len() as f64 >= max_moves as f64 {
                    return Err(PathError::File {
                        file: self.file.clone(),
                        line: m.place.line,
                        column: m.place.column.max(1),
                        message: format!(
                            "this arc as chords of sag {sag} mm would make the program more \
                             than {max_moves} moves"
                        ),
                    });
                }
                let chords = chords as usize;
                let (w0, w1) = (plane.across(&from), plane.across(&m.end));
                for k in 1..chords {
                    let t = k as f64 / chords as f64;
                    let end = plane.point(arc.point(t), w0 + (w1 - w0) * t);
                    moves.push(PartMove {
                        motion: Motion::Line,
                        corner: Corner::BlendDefault,
                        ..m.clone()
                    });
                    moves.last_mut().expect("pushed").end = end;
                }
                moves.push(PartMove {
                    motion: Motion::Line,
                    ..m.clone()
                });
            } else {
                moves.push(m.clone());
            }
            if !matches!(m.motion, Motion::Dwell(_)) {
                from = m.end;
            }
        }
        Ok(PartProgram {
            moves,
            ..self.clone()
        })
    }

    /// The warnings as text, `file:line[:column]: message` each.
    pub fn warning_lines(&self) -> Vec<String> {
        self.warnings.iter().map(ToString::to_string).collect()
    }
}

/// What a part or path file holds, by its name's ending (case-insensitive).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FileKind {
    /// G-code (`.ngc`, `.nc`, `.gcode`, `.tap`).
    GCode,
    /// APT cutter-location data (`.cl`, `.apt`, NX's `.cls`, CATIA's `.aptsource`, Creo's
    /// `.ncl`).
    ClData,
    /// A JSON path: a planar NURBS curve or a five-axis curve pair.
    Json,
}

/// The endings read as G-code.
pub const GCODE_EXTENSIONS: [&str; 4] = ["ngc", "nc", "gcode", "tap"];
/// The endings read as CL data.
pub const CL_EXTENSIONS: [&str; 5] = ["cl", "apt", "cls", "aptsource", "ncl"];

/// What the file named `file` holds by its ending, `None` for another ending or none.
/// The one place that decides it: the FMUs, the simulator and the tools all ask here.
pub fn file_kind(file: &std::path::Path) -> Option<FileKind> {
    let extension = file.extension().and_then(|e| e.to_str())?;
    let is = |list: &[&str]| list.iter().any(|x| x.eq_ignore_ascii_case(extension));
    if is(&GCODE_EXTENSIONS) {
        Some(FileKind::GCode)
    } else if is(&CL_EXTENSIONS) {
        Some(FileKind::ClData)
    } else if extension.eq_ignore_ascii_case("json") {
        Some(FileKind::Json)
    } else {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn file_kinds_by_ending_in_any_case() {
        let kind = |name: &str| file_kind(std::path::Path::new(name));
        assert_eq!(kind("dir.v2/part.NGC"), Some(FileKind::GCode));
        assert_eq!(kind("p.tap"), Some(FileKind::GCode));
        assert_eq!(kind("blade.cl"), Some(FileKind::ClData));
        assert_eq!(kind("C:\\cam\\blade.APT"), Some(FileKind::ClData));
        assert_eq!(kind("impeller.cls"), Some(FileKind::ClData));
        assert_eq!(kind("Part1.aptsource"), Some(FileKind::ClData));
        assert_eq!(kind("op10.NCL"), Some(FileKind::ClData));
        assert_eq!(kind("curve.Json"), Some(FileKind::Json));
        assert_eq!(kind("trident"), None);
        assert_eq!(kind("notes.txt"), None);
    }
}
