//! A part program on the XY table: the line and arc moves of a [`PartProgram`] in the XY
//! plane, in mm, each with the speed it was programmed at and the corner mode at its end
//! (docs/design/two-axis.md §4.7). The table has no third axis: Z is followed only where
//! the table stands still while it moves.
//!
//! As a [`Curve`] a program is parameterised by arc length s ∈ [0, L]: move i covers
//! [sᵢ, sᵢ₊₁], and its own parameter is (s − sᵢ)/ℓᵢ. A query finds its move by binary
//! search over the starts (O(log n), no allocation).

use std::collections::BTreeSet;

use serde::{Deserialize, Serialize};

use super::CornerBlend;
use crate::geometry::{self, Vector2};
use crate::part_program::cutter_compensation::compensate;
use crate::part_program::gcode::{load_gcode, parse_gcode, GcodeOptions};
use crate::part_program::{Corner, Motion, PartProgram, Place, Plane, Speed, Warning};
use crate::path::{clamp_param, CircularArc, Curve, CurvePoint, Line, PathError};

/// The geometry of one move.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum Shape {
    /// G0 or G1.
    Line(Line),
    /// G2 (clockwise, sweep < 0) or G3 (counter-clockwise, sweep > 0).
    Arc(CircularArc),
    /// A corner rounded by the planner (never read from a program).
    Blend(CornerBlend),
}

impl Shape {
    /// The move as a curve of its own parameter, 0 … 1.
    pub fn curve(&self) -> &dyn Curve {
        match self {
            Shape::Line(l) => l,
            Shape::Arc(a) => a,
            Shape::Blend(b) => b,
        }
    }

    /// The unit tangent at the move's start (`end` = 0) or end (1): a line's and a
    /// blend's without evaluating them.
    pub fn end_tangent(&self, end: usize) -> Vector2 {
        match self {
            Shape::Line(l) => l.direction(),
            Shape::Blend(b) => b.end_directions()[end.min(1)],
            Shape::Arc(a) => {
                let d = a.eval(end.min(1) as f64).d1;
                d * (1.0 / geometry::norm(&d))
            }
        }
    }

    /// The mirror image about the x axis (y → −y).
    fn mirrored(&self) -> Shape {
        match self {
            Shape::Line(l) => Shape::Line(l.mirrored()),
            Shape::Arc(a) => Shape::Arc(a.mirrored()),
            Shape::Blend(b) => Shape::Blend(b.mirrored()),
        }
    }
}

/// One move of a program.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Move {
    /// The programmed geometry.
    pub shape: Shape,
    /// The programmed speed.
    pub speed: Speed,
    /// The corner mode in force at the move's end.
    pub corner: Corner,
    /// 1-based line of the program that made the move.
    pub line: usize,
    /// How long the table stands at the move's end (an exact stop then).
    pub standstill: Standstill,
}

/// The time the table stands still at a move's end, while the program dwells or moves
/// Z alone: seconds the program gives, plus Z travel at the interpolator's `feed` (moves
/// before the first F) and at its `rapid`, which are known only when it plans.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Standstill {
    /// Dwells, and Z travel at a programmed feed, s.
    pub seconds: f64,
    /// Z travel at the `feed` parameter, mm.
    pub at_feed: f64,
    /// Z travel at `rapid`, mm.
    pub at_rapid: f64,
}

impl Standstill {
    /// The time it lasts with the interpolator's `feed` and `rapid` (mm/s), s.
    pub fn duration(&self, feed: f64, rapid: f64) -> f64 {
        self.seconds + self.at_feed / feed + self.at_rapid / rapid
    }

    /// Adds Z travel of `distance` mm at `speed`.
    fn add_travel(&mut self, distance: f64, speed: Speed) {
        match speed {
            Speed::Feed(f) => self.seconds += distance / f,
            Speed::Default => self.at_feed += distance,
            Speed::Rapid => self.at_rapid += distance,
        }
    }

    /// Checks bytes from elsewhere: every part finite and >= 0.
    fn validate(&self) -> Result<(), String> {
        let parts = [self.seconds, self.at_feed, self.at_rapid];
        if parts.iter().all(|v| v.is_finite() && *v >= 0.0) {
            Ok(())
        } else {
            Err(format!("standstill {self:?} is invalid"))
        }
    }
}

/// The moves of a program end to end, with their starts along the path. It serialises
/// as its moves alone, and bytes from elsewhere (a restored FMU state) go through the
/// same checks as [`Program::new`]'s.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(into = "ProgramData", try_from = "ProgramData")]
pub struct Program {
    moves: Vec<Move>,
    /// sᵢ of every move, then L: `moves.len() + 1` entries, increasing.
    starts: Vec<f64>,
    /// What the reader skipped, one line per kind (for the importer's log; not saved).
    pub warnings: Vec<String>,
}

impl Program {
    /// The program of `moves`, each starting where the one before ends (within 1e-9 mm
    /// plus 1e-12 of the coordinates: a reader's arithmetic, not a gap in the program).
    pub fn new(moves: Vec<Move>) -> Result<Self, PathError> {
        if moves.is_empty() {
            return Err(PathError::invalid("the program has no XY motion"));
        }
        let mut starts = Vec::with_capacity(moves.len() + 1);
        let mut s = 0.0;
        starts.push(s);
        for pair in moves.windows(2) {
            let (end, start) = (
                pair[0].shape.curve().point(1.0),
                pair[1].shape.curve().point(0.0),
            );
            let gap = (end - start).amax();
            if gap > 1e-9 + 1e-12 * end.amax() || gap.is_nan() {
                return Err(PathError::invalid(format!(
                    "the move of line {} does not start where the move of line {} ends \
                     ({gap:e} mm apart)",
                    pair[1].line, pair[0].line
                )));
            }
        }
        for m in &moves {
            s += m.shape.curve().length();
            starts.push(s);
        }
        if !s.is_finite() {
            return Err(PathError::invalid("the program's length is not finite"));
        }
        Ok(Program {
            moves,
            starts,
            warnings: Vec::new(),
        })
    }

    /// The XY program of the G-code file `file`, read as LinuxCNC does.
    pub fn load(file: impl AsRef<std::path::Path>) -> Result<Self, PathError> {
        Program::load_with(file, &GcodeOptions::default())
    }

    /// The XY program of the G-code file `file`, read with `options`.
    pub fn load_with(
        file: impl AsRef<std::path::Path>,
        options: &GcodeOptions,
    ) -> Result<Self, PathError> {
        Program::from_part_program(&load_gcode(file, options)?)
    }

    /// The XY program of the G-code text `text`, read as LinuxCNC does; `name` is used in
    /// messages.
    pub fn parse_gcode(text: &str, name: &str) -> Result<Self, PathError> {
        Program::parse_gcode_with(text, name, &GcodeOptions::default())
    }

    /// The XY program of the G-code text `text`, read with `options`.
    pub fn parse_gcode_with(
        text: &str,
        name: &str,
        options: &GcodeOptions,
    ) -> Result<Self, PathError> {
        Program::from_part_program(&parse_gcode(text, name, options)?)
    }

    /// The XY part of `part`, with its reader's warnings and what the table leaves out:
    /// rapids before the first cut (the first feed move, in Z too) only position the
    /// tool, so the path starts at the first XY move after it; a rapid's Z is left to the
    /// rapid; where Z moves alone or the program dwells or stops, the table stands at an
    /// exact stop for that time ([`Standstill`]; before the path's first move it is not
    /// part of the path). A move of X or Y together with Z at a feed (a ramp or a helix)
    /// is refused at its Z word: it needs the third axis.
    pub fn from_part_program(part: &PartProgram) -> Result<Self, PathError> {
        let part = &compensate(part)?;
        let mut skipped = BTreeSet::new();
        let mut warnings = part.warning_lines();
        let mut skip = |kind: &'static str, line: usize| {
            if skipped.insert(kind) {
                let message = format!(
                    "{kind} skipped (not part of the XY contour); further ones are skipped \
                     silently"
                );
                let place = Place { line, column: 0 };
                let file = part.file.clone();
                warnings.push(
                    Warning {
                        file,
                        place,
                        message,
                    }
                    .to_string(),
                );
            }
        };
        let mut position = Vector2::new(part.start[0], part.start[1]);
        let mut z = part.start[2];
        let mut moves: Vec<Move> = Vec::new();
        let mut cutting = false;
        // The table stands at the end of the last move (an exact stop there).
        let stand = |moves: &mut Vec<Move>, add: &dyn Fn(&mut Standstill)| {
            if let Some(last) = moves.last_mut() {
                last.corner = Corner::ExactStop;
                add(&mut last.standstill);
            }
        };
        for m in &part.moves {
            let line = m.place.line;
            if let Motion::Dwell(seconds) = m.motion {
                stand(&mut moves, &|s| s.seconds += seconds);
                continue;
            }
            let end = Vector2::new(m.end[0], m.end[1]);
            let arc = matches!(m.motion, Motion::Arc { .. });
            if let Motion::Arc {
                plane: plane @ (Plane::Zx | Plane::Yz),
                ..
            } = m.motion
            {
                return Err(PathError::File {
                    file: part.file.clone(),
                    line,
                    column: m.place.column.max(1),
                    message: format!(
                        "{} arcs are in a plane with the third axis, which the XY table does \
                         not have: run the program on the five-axis machine \
                         (PathInterpolator5X)",
                        plane.code()
                    ),
                });
            }
            if m.speed != Speed::Rapid {
                cutting = true;
            }
            if m.end[2] != z {
                if m.speed != Speed::Rapid && (end != position || arc) {
                    let at = m.z_place.unwrap_or(m.place);
                    return Err(PathError::File {
                        file: part.file.clone(),
                        line: at.line,
                        column: at.column.max(1),
                        message: "a move of X or Y together with Z (a ramp or a helix) needs \
                                  the third axis, which the XY table does not have (its feed \
                                  is along the 3D path): run the program on the five-axis \
                                  machine (PathInterpolator5X), or move Z in a block of its \
                                  own"
                        .into(),
                    });
                }
                if end != position {
                    // A rapid goes there at the machine's rapid whatever Z does.
                    skip("Z in rapids (their XY part is followed)", line);
                } else {
                    let distance = (m.end[2] - z).abs();
                    stand(&mut moves, &|s| s.add_travel(distance, m.speed));
                }
                z = m.end[2];
            }
            let shape = match &m.motion {
                Motion::Line if end == position => continue,
                // Finite ends that differ make a line (the readers' values are decimals).
                Motion::Line => {
                    Shape::Line(Line::new(position, end).map_err(|e| PathError::File {
                        file: part.file.clone(),
                        line,
                        column: m.place.column.max(1),
                        message: e.to_string(),
                    })?)
                }
                Motion::Arc { arc, .. } => Shape::Arc(arc.clone()),
                Motion::Dwell(_) => continue,
            };
            if !cutting {
                // Rapids before the first cut only position the tool: the path starts
                // at the cut.
                position = end;
                continue;
            }
            moves.push(Move {
                shape,
                speed: m.speed,
                corner: m.corner,
                line,
                standstill: Standstill::default(),
            });
            position = end;
        }
        let mut program = Program::new(moves).map_err(|e| e.in_file(&part.file))?;
        program.warnings = warnings;
        Ok(program)
    }

    /// The moves, in program order.
    pub fn moves(&self) -> &[Move] {
        &self.moves
    }

    /// Where move `i` starts along the path, mm (`i = moves().len()`: the length).
    pub fn start_of(&self, i: usize) -> f64 {
        self.starts[i.min(self.moves.len())]
    }

    /// The move that holds path position `s` (clamped; a move's end belongs to it, a
    /// NaN to the first move).
    pub fn move_at(&self, s: f64) -> usize {
        let s = clamp_param(s, 0.0, self.length());
        // The first move whose end is ≥ s.
        self.starts[1..]
            .partition_point(|&end| end < s)
            .min(self.moves.len() - 1)
    }

    /// Path position s of the point at parameter `u` of move `i`.
    pub fn position(&self, i: usize, u: f64) -> f64 {
        let i = i.min(self.moves.len() - 1);
        self.starts[i] + clamp_param(u, 0.0, 1.0) * (self.starts[i + 1] - self.starts[i])
    }

    /// The point of move `i` at path position `s` (clamped into the move).
    pub fn point_in(&self, i: usize, s: f64) -> Vector2 {
        self.moves[i].shape.curve().point(self.local(i, s))
    }

    /// The unit tangent of move `i` at path position `s` (clamped into the move), in the
    /// direction of travel, and the curvature vector there; zeros where the move has no
    /// tangent (a point).
    pub fn frame_in(&self, i: usize, s: f64) -> (Vector2, Vector2) {
        self.moves[i].shape.curve().eval(self.local(i, s)).frame()
    }

    /// The mirror image about the x axis, travelled in the mirrored sense.
    pub fn mirrored(&self) -> Program {
        let moves = self
            .moves
            .iter()
            .map(|m| Move {
                shape: m.shape.mirrored(),
                ..m.clone()
            })
            .collect();
        Program::new(moves).expect("the mirror image of a valid program is valid")
    }

    /// Move `i`'s own parameter at path position `s`.
    fn local(&self, i: usize, s: f64) -> f64 {
        let (a, b) = (self.starts[i], self.starts[i + 1]);
        ((s - a) / (b - a)).clamp(0.0, 1.0)
    }
}

/// A program as saved: its moves.
#[derive(Serialize, Deserialize)]
struct ProgramData {
    moves: Vec<Move>,
}

impl From<Program> for ProgramData {
    fn from(p: Program) -> Self {
        ProgramData { moves: p.moves }
    }
}

impl TryFrom<ProgramData> for Program {
    type Error = String;
    fn try_from(data: ProgramData) -> Result<Self, String> {
        for m in &data.moves {
            let checked = match &m.shape {
                Shape::Line(l) => Line::new(l.start(), l.end()).map(drop),
                Shape::Arc(a) => {
                    CircularArc::new(a.center(), a.radius(), a.start_angle(), a.sweep()).map(drop)
                }
                Shape::Blend(b) => b.validate(),
            };
            checked.map_err(|e| format!("move of line {}: {e}", m.line))?;
            m.standstill
                .validate()
                .map_err(|e| format!("move of line {}: {e}", m.line))?;
            let speed_ok = match m.speed {
                Speed::Feed(f) => f.is_finite() && f > 0.0,
                Speed::Rapid | Speed::Default => true,
            };
            let corner_ok = match m.corner {
                Corner::Blend(t) => t.is_finite() && t > 0.0,
                Corner::ExactStop | Corner::BlendDefault => true,
            };
            if !(speed_ok && corner_ok) {
                return Err(format!(
                    "move of line {}: feed {:?} or corner {:?} is invalid",
                    m.line, m.speed, m.corner
                ));
            }
        }
        Program::new(data.moves).map_err(|e| e.to_string())
    }
}

impl Curve for Program {
    fn param_range(&self) -> (f64, f64) {
        (0.0, self.length())
    }
    fn eval(&self, s: f64) -> CurvePoint {
        let i = self.move_at(s);
        let scale = 1.0 / (self.starts[i + 1] - self.starts[i]);
        let e = self.moves[i].shape.curve().eval(self.local(i, s));
        CurvePoint {
            p: e.p,
            d1: e.d1 * scale,
            d2: e.d2 * (scale * scale),
        }
    }
    fn point(&self, s: f64) -> Vector2 {
        let i = self.move_at(s);
        self.moves[i].shape.curve().point(self.local(i, s))
    }
    fn length_between(&self, s0: f64, s1: f64) -> f64 {
        let (a, b) = self.param_range();
        (clamp_param(s1, a, b) - clamp_param(s0, a, b)).abs()
    }
    fn length(&self) -> f64 {
        self.starts[self.moves.len()]
    }
    fn breakpoints(&self) -> Vec<f64> {
        self.starts.clone()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    fn feed_move(shape: Shape, line: usize) -> Move {
        Move {
            shape,
            speed: Speed::Feed(10.0),
            corner: Corner::ExactStop,
            line,
            standstill: Standstill::default(),
        }
    }

    #[test]
    fn a_line_then_a_half_circle_by_arc_length() {
        let line = Shape::Line(Line::new([0.0, 0.0], [10.0, 0.0]).unwrap());
        let arc = Shape::Arc(CircularArc::new([10.0, 5.0], 5.0, -PI / 2.0, PI).unwrap());
        let p = Program::new(vec![feed_move(line, 1), feed_move(arc, 2)]).unwrap();
        assert!((p.length() - (10.0 + 5.0 * PI)).abs() < 1e-12);
        assert_eq!(p.breakpoints(), vec![0.0, 10.0, 10.0 + 5.0 * PI]);
        assert_eq!(p.move_at(10.0), 0);
        assert_eq!(p.move_at(10.0 + 1e-9), 1);
        assert_eq!(p.move_at(f64::NAN), 0);
        // Half way round the half circle (at its angle 0): unit speed in s, curvature 1/5.
        let e = p.eval(10.0 + 5.0 * PI / 2.0);
        assert!((e.p - Vector2::new(15.0, 5.0)).amax() < 1e-12);
        assert!((e.d1 - Vector2::new(0.0, 1.0)).amax() < 1e-12);
        assert!(
            (e.d2 - Vector2::new(-0.2, 0.0)).amax() < 1e-12,
            "{:?}",
            e.d2
        );
        assert_eq!(p.position(1, 0.5), 10.0 + 5.0 * PI / 2.0);
        let m = p.mirrored();
        assert!((m.point(12.0) - Vector2::new(p.point(12.0)[0], -p.point(12.0)[1])).amax() < 1e-12);
    }

    #[test]
    fn bytes_from_elsewhere_are_checked_as_new_programs_are() {
        let line = |a: [f64; 2], b: [f64; 2]| Shape::Line(Line::new(a, b).unwrap());
        let p = Program::new(vec![
            feed_move(line([0.0, 0.0], [1.0, 0.0]), 1),
            feed_move(line([1.0, 0.0], [1.0, 2.0]), 2),
        ])
        .unwrap();
        let bytes = postcard::to_stdvec(&p).unwrap();
        assert_eq!(postcard::from_bytes::<Program>(&bytes).unwrap(), p);
        // The same moves with a gap between them, and with a feed of −1 mm/s.
        let mut gap = p.moves.clone();
        gap[1].shape = line([1.0, 0.5], [1.0, 2.0]);
        let bytes = postcard::to_stdvec(&ProgramData { moves: gap }).unwrap();
        assert!(postcard::from_bytes::<Program>(&bytes).is_err());
        let mut slow = p.moves.clone();
        slow[0].speed = Speed::Feed(-1.0);
        let bytes = postcard::to_stdvec(&ProgramData { moves: slow }).unwrap();
        assert!(postcard::from_bytes::<Program>(&bytes).is_err());
        let bytes = postcard::to_stdvec(&ProgramData { moves: vec![] }).unwrap();
        assert!(postcard::from_bytes::<Program>(&bytes).is_err());
    }

    #[test]
    fn refuses_a_gap_and_an_empty_program() {
        let a = Shape::Line(Line::new([0.0, 0.0], [10.0, 0.0]).unwrap());
        let b = Shape::Line(Line::new([10.0, 1e-6], [10.0, 5.0]).unwrap());
        let e = Program::new(vec![feed_move(a, 3), feed_move(b, 4)]).unwrap_err();
        assert!(
            e.to_string().contains("line 4") && e.to_string().contains("line 3"),
            "{e}"
        );
        assert!(Program::new(vec![]).is_err());
    }
}
