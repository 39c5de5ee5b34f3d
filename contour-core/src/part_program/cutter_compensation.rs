//! Cutter radius compensation (G41, G42, G40; docs/design/two-axis.md §4.7b): the
//! programmed contour is the part's edge, and the tool's centre runs the tool's radius to
//! the side G41 (left) or G42 (right) names, in the plane of G17 or G18. [`compensate`]
//! turns a [`PartProgram`]'s compensated moves into the moves of the tool's centre, by
//! LinuxCNC's rules: a straight entry move to the first point offset perpendicular to it
//! (an entry arc to its arc's offset end), an arc of the tool's radius about a convex
//! corner, the offset paths cut at their meeting point in a concave one, and a straight
//! exit move after G40. What cannot be compensated is refused with its line: an entry
//! ending within the tool's radius, an exit on an arc, an arc the tool does not fit inside,
//! a concave corner the tool cannot reach without cutting into the part.

use std::collections::BTreeMap;
use std::f64::consts::TAU;

use super::arc_words::nearest_on_bisector;
use super::{Compensation, Motion, PartMove, PartProgram, Plane, Side};
use crate::geometry::{self, Vector, Vector2};
use crate::math;
use crate::path::{CircularArc, PathError};

/// The tools' radii by their D number, mm.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ToolTable(BTreeMap<u32, f64>);

/// The largest tool radius a table may hold, mm.
pub const MAX_TOOL_RADIUS: f64 = 1000.0;

impl ToolTable {
    /// Reads `D:radius` pairs (or `D=radius`) separated by commas, semicolons or spaces,
    /// radii in mm: `"1:3, 2:5.5"`. Empty: no tools. A negative radius puts the tool on
    /// the other side of the contour (LinuxCNC's reading of a negative diameter).
    pub fn parse(text: &str) -> Result<Self, String> {
        let mut table = BTreeMap::new();
        for pair in text
            .split([',', ';', ' ', '\t', '\n'])
            .map(str::trim)
            .filter(|p| !p.is_empty())
        {
            let (d, r) = pair
                .split_once([':', '='])
                .ok_or_else(|| format!("tool table: {pair:?} is not D:radius (e.g. 1:3.0)"))?;
            let d = d.trim().trim_start_matches(['D', 'd']);
            let d: u32 = d
                .parse()
                .map_err(|_| format!("tool table: {d:?} in {pair:?} is not a tool number"))?;
            let r: f64 = r
                .trim()
                .parse()
                .map_err(|_| format!("tool table: {r:?} in {pair:?} is not a radius in mm"))?;
            if !(r.is_finite() && r.abs() <= MAX_TOOL_RADIUS) {
                return Err(format!(
                    "tool table: D{d}'s radius {r} must be finite and within ±{MAX_TOOL_RADIUS} mm"
                ));
            }
            if table.insert(d, r).is_some() {
                return Err(format!("tool table: D{d} is given twice"));
            }
        }
        Ok(ToolTable(table))
    }

    /// The radius of tool `d` (a D word's value), mm; D0 is radius 0 unless the table
    /// gives it.
    pub fn radius(&self, d: f64) -> Result<f64, String> {
        if !(d.fract() == 0.0 && (0.0..=u32::MAX as f64).contains(&d)) {
            return Err(format!("D{d} is not a tool number"));
        }
        let number = d as u32;
        match self.0.get(&number) {
            Some(&r) => Ok(r),
            None if number == 0 => Ok(0.0),
            None => Err(format!(
                "D{number} is not in the tool table (parameter toolRadii: {})",
                if self.0.is_empty() {
                    "empty; give it as D:radius pairs, e.g. 1:3.0".to_string()
                } else {
                    self.0
                        .iter()
                        .map(|(d, r)| format!("{d}:{r}"))
                        .collect::<Vec<_>>()
                        .join(", ")
                }
            )),
        }
    }
}

/// How near two points must be to count as one, mm.
const SAME_POINT: f64 = 1e-7;

/// The shape of a piece of the tool centre's path in the plane.
#[derive(Clone, Copy, Debug)]
enum Shape {
    Line,
    Arc {
        centre: Vector2,
        radius: f64,
        /// The start angle about the centre.
        start: f64,
        /// Signed: > 0 counter-clockwise.
        sweep: f64,
    },
}

/// One move of the tool centre in a compensated stretch, with what its corners need.
#[derive(Clone, Debug)]
struct Piece {
    shape: Shape,
    from: Vector2,
    to: Vector2,
    /// The programmed contour's direction where the move starts and ends.
    start_tangent: Vector2,
    end_tangent: Vector2,
    /// The programmed end (the corner with the next move), in the plane.
    corner: Vector2,
    /// The move as programmed (its speed, corner mode, line, and its end's third axis).
    programmed: PartMove,
}

impl Piece {
    /// Where along the piece the point `p` (on its line or circle) lies, 0 at `from`
    /// and 1 at `to`, in units of the piece's length for the tolerance.
    fn share(&self, p: Vector2) -> (f64, f64) {
        match self.shape {
            Shape::Line => {
                let d = self.to - self.from;
                let length = geometry::norm(&d);
                ((p - self.from).dot(&d) / (length * length), length)
            }
            Shape::Arc {
                centre,
                radius,
                start,
                sweep,
            } => {
                let angle = math::atan2(p[1] - centre[1], p[0] - centre[0]);
                let mut turned = (angle - start).rem_euclid(TAU);
                if sweep < 0.0 {
                    turned = (TAU - turned).rem_euclid(TAU);
                }
                // Just before the start reads as a whole turn on.
                if (TAU - turned) * radius < SAME_POINT {
                    turned = 0.0;
                }
                (turned / sweep.abs(), radius * sweep.abs())
            }
        }
    }

    fn length(&self) -> f64 {
        self.share(self.to).1
    }

    /// The piece starting at `p`, which lies on it.
    fn start_at(&mut self, p: Vector2) {
        let (t, _) = self.share(p);
        if let Shape::Arc { start, sweep, .. } = &mut self.shape {
            let turned = t * sweep.abs();
            *start += turned * sweep.signum();
            *sweep -= turned * sweep.signum();
        }
        self.from = p;
    }

    /// The piece ending at `p`, which lies on it.
    fn end_at(&mut self, p: Vector2) {
        let (mut t, _) = self.share(p);
        if let Shape::Arc { sweep, .. } = &mut self.shape {
            // On a whole circle its start is its end: a point just short of it (read as
            // the start) ends the whole turn.
            if t == 0.0 && sweep.abs() >= TAU * (1.0 - 1e-12) {
                t = 1.0;
            }
            *sweep *= t;
        }
        self.to = p;
    }

    /// The tool centre's move.
    fn to_move(&self, plane: Plane, w_end: f64) -> Result<PartMove, String> {
        let motion = match self.shape {
            Shape::Line => Motion::Line,
            Shape::Arc {
                centre,
                radius,
                start,
                sweep,
            } => Motion::Arc {
                arc: CircularArc::new(centre, radius, start, sweep).map_err(|e| e.to_string())?,
                plane,
            },
        };
        Ok(PartMove {
            motion,
            end: plane.point(self.to, w_end),
            compensation: None,
            ..self.programmed.clone()
        })
    }
}

/// The tool centre's path of `program`: every move under G41 or G42 offset by its tool's
/// radius (see the module docs); the result has no compensated moves.
pub fn compensate(program: &PartProgram) -> Result<PartProgram, PathError> {
    if program.moves.iter().all(|m| m.compensation.is_none()) {
        return Ok(program.clone());
    }
    let mut pass = Pass {
        file: &program.file,
        moves: Vec::with_capacity(program.moves.len() + program.moves.len() / 4),
        programmed: program.start,
        centre: program.start,
        stretch: None,
        exiting: None,
    };
    for m in &program.moves {
        pass.take(m)?;
    }
    pass.end_stretch()?;
    Ok(PartProgram {
        moves: pass.moves,
        ..program.clone()
    })
}

/// A compensated stretch being read: the move waiting for its corner with the next, and
/// the moves across the plane (the third axis alone, dwells) read after it.
struct Stretch {
    compensation: Compensation,
    pending: Option<Piece>,
    across: Vec<PartMove>,
}

struct Pass<'a> {
    file: &'a str,
    moves: Vec<PartMove>,
    /// The programmed position after the last move read.
    programmed: Vector<3>,
    /// The tool centre there.
    centre: Vector<3>,
    stretch: Option<Stretch>,
    /// The plane of the stretch that ended, until the exit move leaves it.
    exiting: Option<Plane>,
}

impl Pass<'_> {
    fn error(&self, m: &PartMove, message: String) -> PathError {
        PathError::File {
            file: self.file.to_string(),
            line: m.place.line,
            column: m.place.column.max(1),
            message,
        }
    }

    fn take(&mut self, m: &PartMove) -> Result<(), PathError> {
        let same = self
            .stretch
            .as_ref()
            .is_some_and(|s| Some(s.compensation) == m.compensation);
        if !same {
            self.end_stretch()?;
            if let Some(c) = m.compensation {
                self.stretch = Some(Stretch {
                    compensation: c,
                    pending: None,
                    across: Vec::new(),
                });
            }
        }
        let from = self.programmed;
        if !matches!(m.motion, Motion::Dwell(_)) {
            self.programmed = m.end;
        }
        let Some(c) = self.stretch.as_ref().map(|s| s.compensation) else {
            return self.uncompensated(m, from);
        };
        let plane = c.plane;
        if !moves_in_plane(plane, &from, m) {
            let stretch = self.stretch.as_mut().expect("in a stretch");
            if stretch.pending.is_none() {
                // Before the entry move: the tool is where it was programmed to be.
                let mut m = m.clone();
                m.end = match m.motion {
                    Motion::Dwell(_) => self.centre,
                    _ => plane.point(plane.in_plane(&self.centre), plane.across(&m.end)),
                };
                m.compensation = None;
                self.centre = m.end;
                self.moves.push(m);
            } else {
                stretch.across.push(m.clone());
            }
            return Ok(());
        }
        let next = self.piece(m, from, c)?;
        let stretch = self.stretch.as_mut().expect("in a stretch");
        let Some(mut pending) = stretch.pending.take() else {
            // The entry: the tool leaves the last stretch's offset point.
            stretch.pending = Some(next);
            self.exiting = None;
            return Ok(());
        };
        let mut next = next;
        let corner_arc = join(&mut pending, &mut next, c).map_err(|e| self.error(m, e))?;
        self.flush(pending)?;
        if let Some(arc) = corner_arc {
            self.push_piece(&arc, plane, plane.across(&from))
                .map_err(|e| self.error(m, e))?;
        }
        self.stretch.as_mut().expect("in a stretch").pending = Some(next);
        Ok(())
    }

    /// A move without compensation: as programmed, the one after a stretch (the exit move)
    /// straight from where the tool centre stands.
    fn uncompensated(&mut self, m: &PartMove, from: Vector<3>) -> Result<(), PathError> {
        let mut m = m.clone();
        if let Some(plane) = self.exiting {
            if !moves_in_plane(plane, &from, &m) {
                m.end = plane.point(plane.in_plane(&self.centre), plane.across(&m.end));
            } else if matches!(m.motion, Motion::Arc { .. }) {
                return Err(self.error(
                    &m,
                    "the move after G40 (cutter compensation off) must be straight, not an arc"
                        .into(),
                ));
            } else {
                self.exiting = None;
            }
        }
        if !matches!(m.motion, Motion::Dwell(_)) {
            self.centre = m.end;
        } else {
            m.end = self.centre;
        }
        self.moves.push(m);
        Ok(())
    }

    /// The tool centre's piece for the programmed move `m` from `from`: the entry move
    /// when the stretch has none yet.
    fn piece(&self, m: &PartMove, from: Vector<3>, c: Compensation) -> Result<Piece, PathError> {
        let plane = c.plane;
        let side = c.side.sign();
        let (p0, p1) = (plane.in_plane(&from), plane.in_plane(&m.end));
        let entry = self.stretch.as_ref().is_some_and(|s| s.pending.is_none());
        let start = plane.in_plane(&self.centre);
        if entry {
            let length = geometry::dist(&start, &p1);
            if length <= c.radius {
                return Err(self.error(
                    m,
                    format!(
                        "the move that starts cutter compensation ends {length:.4} mm from \
                         where the tool is, not more than the tool's radius {:.4} mm",
                        c.radius
                    ),
                ));
            }
            if let Motion::Arc { arc, .. } = &m.motion {
                return self.entry_arc(m, arc, start, p1, c);
            }
            let direction = (p1 - start) / length;
            return Ok(Piece {
                shape: Shape::Line,
                from: start,
                to: p1 + geometry::perp(&direction) * (side * c.radius),
                start_tangent: direction,
                end_tangent: direction,
                corner: p1,
                programmed: m.clone(),
            });
        }
        match &m.motion {
            Motion::Arc { arc, .. } => self.offset_arc(m, arc, p1, c),
            _ => {
                let direction = (p1 - p0) / geometry::dist(&p0, &p1);
                let offset = geometry::perp(&direction) * (side * c.radius);
                Ok(Piece {
                    shape: Shape::Line,
                    from: p0 + offset,
                    to: p1 + offset,
                    start_tangent: direction,
                    end_tangent: direction,
                    corner: p1,
                    programmed: m.clone(),
                })
            }
        }
    }

    /// The offset of the programmed arc `arc` ending at `p1`: the same centre, the radius
    /// less or more by the tool's (inside it or outside).
    fn offset_arc(
        &self,
        m: &PartMove,
        arc: &CircularArc,
        p1: Vector2,
        c: Compensation,
    ) -> Result<Piece, PathError> {
        let side = c.side.sign();
        let ccw = arc.sweep() > 0.0;
        let inward = if ccw { side } else { -side };
        let radius = arc.radius() - inward * c.radius;
        if radius <= SAME_POINT {
            return Err(self.error(
                m,
                format!(
                    "the tool's radius {:.4} mm is not less than this arc's radius \
                     {:.4} mm with the tool inside it: the compensated tool cannot \
                     follow it",
                    c.radius,
                    arc.radius()
                ),
            ));
        }
        let tangent = |angle: f64| {
            let (s, co) = math::sincos(angle);
            Vector2::new(-s, co) * arc.sweep().signum()
        };
        let centre = arc.center();
        let (a0, a1) = (arc.start_angle(), arc.start_angle() + arc.sweep());
        let at = |a: f64| {
            let (s, co) = math::sincos(a);
            centre + Vector2::new(co, s) * radius
        };
        Ok(Piece {
            shape: Shape::Arc {
                centre,
                radius,
                start: a0,
                sweep: arc.sweep(),
            },
            from: at(a0),
            to: at(a1),
            start_tangent: tangent(a0),
            end_tangent: tangent(a1),
            corner: p1,
            programmed: m.clone(),
        })
    }

    /// The entry move on an arc (LinuxCNC allows one): from where the tool is to the
    /// programmed arc's offset end, on the circle through both whose centre is the point
    /// of their bisector nearest the programmed centre (LinuxCNC cuts a spiral about the
    /// programmed centre between the two radii; the entry is off the part either way).
    fn entry_arc(
        &self,
        m: &PartMove,
        arc: &CircularArc,
        start: Vector2,
        p1: Vector2,
        c: Compensation,
    ) -> Result<Piece, PathError> {
        let offset = self.offset_arc(m, arc, p1, c)?;
        let end = offset.to;
        let centre = nearest_on_bisector(start, end, arc.center());
        let radius = geometry::dist(&start, &centre);
        let angle = |p: Vector2| math::atan2(p[1] - centre[1], p[0] - centre[0]);
        let (a0, a1) = (angle(start), angle(end));
        let ccw = arc.sweep() > 0.0;
        let mut sweep = (if ccw { a1 - a0 } else { a0 - a1 }).rem_euclid(TAU);
        if sweep == 0.0 {
            sweep = TAU;
        }
        if radius <= SAME_POINT || !radius.is_finite() {
            return Err(self.error(
                m,
                "the arc that starts cutter compensation has no circle through where the \
                 tool is and its offset end"
                    .into(),
            ));
        }
        Ok(Piece {
            shape: Shape::Arc {
                centre,
                radius,
                start: a0,
                sweep: if ccw { sweep } else { -sweep },
            },
            from: start,
            to: end,
            ..offset
        })
    }

    /// Writes `piece` and the moves across the plane read after it.
    fn flush(&mut self, piece: Piece) -> Result<(), PathError> {
        let stretch = self.stretch.as_mut().expect("in a stretch");
        let plane = stretch.compensation.plane;
        let across = std::mem::take(&mut stretch.across);
        let w = plane.across(&piece.programmed.end);
        self.push_piece(&piece, plane, w)
            .map_err(|e| self.error(&piece.programmed, e))?;
        for mut m in across {
            m.end = plane.point(piece.to, plane.across(&m.end));
            if let Motion::Dwell(_) = m.motion {
                m.end = self.centre;
            }
            m.compensation = None;
            self.centre = m.end;
            self.moves.push(m);
        }
        Ok(())
    }

    fn push_piece(&mut self, piece: &Piece, plane: Plane, w: f64) -> Result<(), String> {
        let end = plane.point(piece.to, w);
        // A piece a concave corner cut to nothing leaves only its third axis's move.
        if piece.length() <= SAME_POINT {
            if end != self.centre {
                let mut m = piece.to_move(plane, w)?;
                m.motion = Motion::Line;
                self.centre = m.end;
                self.moves.push(m);
            }
            return Ok(());
        }
        let m = piece.to_move(plane, w)?;
        self.centre = m.end;
        self.moves.push(m);
        Ok(())
    }

    /// Ends the stretch in progress (G40, or the program's end): its last piece as it is.
    fn end_stretch(&mut self) -> Result<(), PathError> {
        let Some(mut stretch) = self.stretch.take() else {
            return Ok(());
        };
        let plane = stretch.compensation.plane;
        if let Some(piece) = stretch.pending.take() {
            self.stretch = Some(stretch);
            self.flush(piece)?;
            self.stretch = None;
            self.exiting = Some(plane);
        }
        Ok(())
    }
}

/// Whether `m`, from `from`, moves in `plane` (an arc always does; a move of the third
/// axis alone, or a dwell, does not).
fn moves_in_plane(plane: Plane, from: &Vector<3>, m: &PartMove) -> bool {
    matches!(m.motion, Motion::Arc { .. })
        || geometry::dist(&plane.in_plane(from), &plane.in_plane(&m.end)) > SAME_POINT
}

/// The corner between `prev` and `next`: at a convex one, the arc of the tool's radius
/// about the programmed corner that joins them; at a concave one, both cut where they
/// meet (an error where they do not meet on both: the tool would gouge the part).
fn join(prev: &mut Piece, next: &mut Piece, c: Compensation) -> Result<Option<Piece>, String> {
    if geometry::dist(&prev.to, &next.from) <= SAME_POINT {
        next.start_at(prev.to);
        return Ok(None);
    }
    let side = c.side.sign();
    let turn = geometry::cross(&prev.end_tangent, &next.start_tangent) * side;
    let corner = prev.corner;
    if turn > 0.0 {
        let meeting = meeting_points(prev, next)
            .into_iter()
            .filter(|&p| {
                let on = |piece: &Piece| {
                    let (t, length) = piece.share(p);
                    let slack = SAME_POINT / length.max(SAME_POINT);
                    (-slack..=1.0 + slack).contains(&t)
                };
                on(prev) && on(next)
            })
            .min_by(|a, b| geometry::dist(a, &corner).total_cmp(&geometry::dist(b, &corner)));
        let Some(p) = meeting else {
            return Err(format!(
                "concave corner with line {}: the tool of radius {:.4} mm cannot reach it \
                 without gouging the part (the offset paths do not meet on both moves)",
                prev.programmed.place.line, c.radius
            ));
        };
        prev.end_at(p);
        next.start_at(p);
        return Ok(None);
    }
    // Convex: around the corner on the tool's radius, turning the way the path turns.
    let angle = |p: Vector2| math::atan2(p[1] - corner[1], p[0] - corner[0]);
    let (a0, a1) = (angle(prev.to), angle(next.from));
    let ccw = c.side == Side::Right;
    let mut sweep = (if ccw { a1 - a0 } else { a0 - a1 }).rem_euclid(TAU);
    if sweep == 0.0 {
        sweep = TAU;
    }
    let sweep = if ccw { sweep } else { -sweep };
    Ok(Some(Piece {
        shape: Shape::Arc {
            centre: corner,
            radius: c.radius,
            start: a0,
            sweep,
        },
        from: prev.to,
        to: next.from,
        start_tangent: prev.end_tangent,
        end_tangent: next.start_tangent,
        corner,
        programmed: next.programmed.clone(),
    }))
}

/// Where the line or circle of `a` meets that of `b` (none, one or two points).
fn meeting_points(a: &Piece, b: &Piece) -> Vec<Vector2> {
    match (a.shape, b.shape) {
        (Shape::Line, Shape::Line) => {
            let (d, e) = (a.to - a.from, b.to - b.from);
            let denominator = geometry::cross(&d, &e);
            if denominator.abs() < 1e-15 * geometry::norm(&d) * geometry::norm(&e) {
                return Vec::new();
            }
            let t = geometry::cross(&(b.from - a.from), &e) / denominator;
            vec![a.from + d * t]
        }
        (Shape::Line, Shape::Arc { centre, radius, .. }) => line_circle(a, centre, radius),
        (Shape::Arc { centre, radius, .. }, Shape::Line) => line_circle(b, centre, radius),
        (
            Shape::Arc {
                centre: c0,
                radius: r0,
                ..
            },
            Shape::Arc {
                centre: c1,
                radius: r1,
                ..
            },
        ) => {
            let d = geometry::dist(&c0, &c1);
            if d == 0.0 || d > r0 + r1 || d < (r0 - r1).abs() {
                return Vec::new();
            }
            let along = (d * d + r0 * r0 - r1 * r1) / (2.0 * d);
            let h = (r0 * r0 - along * along).max(0.0).sqrt();
            let u = (c1 - c0) / d;
            let foot = c0 + u * along;
            let n = geometry::perp(&u);
            vec![foot + n * h, foot - n * h]
        }
    }
}

/// Where the line of `line` meets the circle about `centre`.
fn line_circle(line: &Piece, centre: Vector2, radius: f64) -> Vec<Vector2> {
    let d = line.to - line.from;
    let length = geometry::norm(&d);
    let u = d / length;
    let foot = line.from + u * (centre - line.from).dot(&u);
    let off = geometry::dist(&foot, &centre);
    if off > radius {
        return Vec::new();
    }
    let h = (radius * radius - off * off).sqrt();
    vec![foot + u * h, foot - u * h]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Vector;
    use crate::part_program::gcode::{parse_gcode, GcodeOptions};
    use crate::path::Curve;

    /// A programmed move in the plane: a line to `end`, or an arc to `end` about
    /// `centre` (counter-clockwise when `ccw`).
    #[derive(Clone, Copy)]
    struct Step {
        end: Vector2,
        arc: Option<(Vector2, bool)>,
    }

    fn line(x: f64, y: f64) -> Step {
        Step {
            end: Vector2::new(x, y),
            arc: None,
        }
    }

    fn arc(x: f64, y: f64, cx: f64, cy: f64, ccw: bool) -> Step {
        Step {
            end: Vector2::new(x, y),
            arc: Some((Vector2::new(cx, cy), ccw)),
        }
    }

    /// The profile the other way round from its last point.
    fn reversed(start: Vector2, steps: &[Step]) -> (Vector2, Vec<Step>) {
        let mut points = vec![start];
        points.extend(steps.iter().map(|s| s.end));
        let mut back = Vec::new();
        for k in (0..steps.len()).rev() {
            back.push(Step {
                end: points[k],
                arc: steps[k].arc.map(|(c, ccw)| (c, !ccw)),
            });
        }
        (*points.last().unwrap(), back)
    }

    /// A program in `plane` ((u, v) the profile's coordinates, w = −1): a rapid to 15 mm
    /// before `start` along the first step, compensation `code` on with D1 on the move to
    /// `start`, the profile, then G40 on a move 15 mm on along the last step.
    fn program(plane: Plane, code: &str, start: Vector2, steps: &[Step]) -> String {
        // The direction of a step's arc at `p`.
        let along = |s: &Step, p: Vector2| match s.arc {
            Some((c, ccw)) => {
                geometry::perp(&geometry::unit(&(p - c)).unwrap()) * if ccw { 1.0 } else { -1.0 }
            }
            None => Vector2::zeros(),
        };
        let approach = start - along(&steps[0], start) * 15.0;
        let last = steps.last().unwrap();
        let exit = last.end + along(last, last.end) * 15.0;
        let [u, v, w] = plane.axes();
        let names = ['X', 'Y', 'Z'];
        let at = |p: Vector2| format!("{}{:.6} {}{:.6}", names[u], p[0], names[v], p[1]);
        let centre_words = ['I', 'J', 'K'];
        let mut text = format!(
            "G21 G90 {}\nG0 {} {}-1\n{code} D1 G1 {} F600\n",
            plane.code(),
            at(approach),
            names[w],
            at(start)
        );
        let mut from = start;
        for s in steps {
            match s.arc {
                None => text += &format!("G1 {}\n", at(s.end)),
                Some((c, ccw)) => {
                    text += &format!(
                        "{} {} {}{:.6} {}{:.6}\n",
                        if ccw { "G3" } else { "G2" },
                        at(s.end),
                        centre_words[u],
                        c[0] - from[0],
                        centre_words[v],
                        c[1] - from[1]
                    )
                }
            }
            from = s.end;
        }
        text + &format!("G40 G1 {}\nM2\n", at(exit))
    }

    fn options(radius: f64) -> GcodeOptions {
        GcodeOptions {
            tools: ToolTable::parse(&format!("1:{radius}")).unwrap(),
            ..GcodeOptions::default()
        }
    }

    /// The distance from `p` to a programmed step from `from`, the nearest point and
    /// the contour's direction there (none at an end: a corner has two).
    fn nearest(p: Vector2, from: Vector2, s: &Step) -> (f64, Vector2, Option<Vector2>) {
        match s.arc {
            None => {
                let d = s.end - from;
                let t = ((p - from).dot(&d) / d.dot(&d)).clamp(0.0, 1.0);
                let q = from + d * t;
                let inside = t > 0.0 && t < 1.0;
                (
                    geometry::dist(&p, &q),
                    q,
                    inside.then(|| d / geometry::norm(&d)),
                )
            }
            Some((c, ccw)) => {
                let r = geometry::dist(&from, &c);
                let angle = |q: Vector2| math::atan2(q[1] - c[1], q[0] - c[0]);
                let turn = |a: f64, b: f64| {
                    let t = (b - a).rem_euclid(TAU);
                    if ccw {
                        t
                    } else {
                        (TAU - t).rem_euclid(TAU)
                    }
                };
                let mut sweep = turn(angle(from), angle(s.end));
                if sweep == 0.0 {
                    sweep = TAU;
                }
                let along = turn(angle(from), angle(p));
                if along > 0.0 && along < sweep {
                    let radial = geometry::unit(&(p - c)).unwrap();
                    let q = c + radial * r;
                    let tangent = geometry::perp(&radial) * if ccw { 1.0 } else { -1.0 };
                    (geometry::dist(&p, &q), q, Some(tangent))
                } else {
                    let (a, b) = (geometry::dist(&p, &from), geometry::dist(&p, &s.end));
                    if a < b {
                        (a, from, None)
                    } else {
                        (b, s.end, None)
                    }
                }
            }
        }
    }

    /// Checks the tool centre's path of `text` by the definition of compensation: from
    /// the end of the entry move to the start of the exit move, every point is `radius`
    /// from the programmed profile and no nearer, on `side` of it; the third axis as
    /// programmed. The first and last steps are lead arcs. Returns the number of moves
    /// checked.
    fn check(
        text: &str,
        plane: Plane,
        start: Vector2,
        steps: &[Step],
        radius: f64,
        side: Side,
    ) -> usize {
        let programmed = parse_gcode(text, "p.ngc", &options(radius)).unwrap();
        let centre = compensate(&programmed).unwrap_or_else(|e| panic!("{e}\n{text}"));
        assert!(centre.moves.iter().all(|m| m.compensation.is_none()));
        // The moves between the entry's (line 3) and the exit's (the last line).
        let exit_line = text.lines().count() - 1;
        let mut from = centre.start;
        let mut checked = 0;
        for m in &centre.moves {
            let this_from = from;
            from = m.end;
            if m.place.line <= 3 || m.place.line >= exit_line {
                continue;
            }
            checked += 1;
            assert_eq!(plane.across(&m.end), -1.0, "{text}");
            for k in 0..=64 {
                let t = k as f64 / 64.0;
                let p = match &m.motion {
                    Motion::Arc { arc, plane: p } => {
                        assert_eq!(*p, plane);
                        arc.point(t)
                    }
                    _ => {
                        let (a, b) = (plane.in_plane(&this_from), plane.in_plane(&m.end));
                        a + (b - a) * t
                    }
                };
                // The lead arcs on the tool's side pass within its radius of the profile
                // beside them: each is measured alone, the profile without them.
                let lead = [4, 3 + steps.len()].contains(&m.place.line);
                let mut best = (f64::INFINITY, Vector2::zeros(), None);
                let mut step_from = start;
                for (k, s) in steps.iter().enumerate() {
                    let is_lead = k == 0 || k + 1 == steps.len();
                    let own = m.place.line == 4 + k;
                    if (lead && own) || (!lead && !is_lead) {
                        let n = nearest(p, step_from, s);
                        if n.0 < best.0 {
                            best = n;
                        }
                    }
                    step_from = s.end;
                }
                let (d, q, tangent) = best;
                assert!(
                    (d - radius).abs() < 1e-9,
                    "line {} at {t}: {p:?} is {d} from the profile, not {radius}\n{text}",
                    m.place.line
                );
                if let Some(tangent) = tangent.filter(|_| radius > 0.0) {
                    let left = geometry::cross(&tangent, &(p - q)) > 0.0;
                    assert_eq!(
                        left,
                        side == Side::Left,
                        "line {} at {t}\n{text}",
                        m.place.line
                    );
                }
            }
        }
        checked
    }

    /// A 40 × 30 plate with a rounded corner (r 10), a slot 10 wide and 15 deep in its
    /// top edge and a 1.5 mm fillet, counter-clockwise from (20, 0), with lead-in and
    /// lead-out arcs of 10 mm tangent to its bottom edge, inside the plate or outside;
    /// from the lead-in's start.
    fn plate(inside: bool) -> (Vector2, Vec<Step>) {
        let y = if inside { 10.0 } else { -10.0 };
        let steps = vec![
            arc(20.0, 0.0, 20.0, y, inside),
            line(40.0, 0.0),
            line(40.0, 20.0),
            arc(30.0, 30.0, 30.0, 20.0, true),
            line(20.0, 30.0),
            line(20.0, 16.5),
            arc(18.5, 15.0, 18.5, 16.5, false),
            line(10.0, 15.0),
            line(10.0, 30.0),
            line(0.0, 30.0),
            line(0.0, 0.0),
            line(20.0, 0.0),
            arc(30.0, y, 20.0, y, inside),
        ];
        (Vector2::new(10.0, y), steps)
    }

    #[test]
    fn the_tool_centre_runs_its_radius_from_the_profile_on_the_side_named() {
        for plane in [Plane::Xy, Plane::Zx] {
            for forward in [true, false] {
                for (code, side) in [("G41", Side::Left), ("G42", Side::Right)] {
                    // Left of the counter-clockwise plate is inside it.
                    let inside = (side == Side::Left) == forward;
                    let (s0, steps) = plate(inside);
                    let (s0, steps) = if forward {
                        (s0, steps)
                    } else {
                        reversed(s0, &steps)
                    };
                    for radius in [0.0, 1.0, 1.4999, 3.0, 4.9] {
                        let text = program(plane, code, s0, &steps);
                        // Outside the plate the tool is inside its 1.5 mm fillet.
                        if !inside && radius >= 1.5 {
                            let part = parse_gcode(&text, "p.ngc", &options(radius)).unwrap();
                            let e = compensate(&part).unwrap_err().to_string();
                            assert!(e.contains("not less than this arc's radius"), "{e}");
                            continue;
                        }
                        let n = check(&text, plane, s0, &steps, radius, side);
                        assert!(n >= steps.len(), "{n} moves checked\n{text}");
                    }
                }
            }
        }
    }

    fn refusal(text: &str, radius: f64) -> String {
        match parse_gcode(text, "p.ngc", &options(radius)) {
            Err(e) => e.to_string(),
            Ok(part) => compensate(&part).unwrap_err().to_string(),
        }
    }

    #[test]
    fn what_cannot_be_compensated_is_refused_with_its_line() {
        let head = "G21 G90 G17\nG0 X-10 Y-10\n";
        for (body, radius, want) in [
            // The entry move no longer than the radius.
            (
                "G41 D1 G1 X-8 Y-10 F600\nG1 X20\n",
                3.0,
                "p.ngc:3:1: the move that starts",
            ),
            // The exit on an arc; an entry arc ending within the radius.
            (
                "G41 D1\nG2 X-8 Y-10 I1 J0 F600\n",
                3.0,
                "p.ngc:4:1: the move that starts",
            ),
            (
                "G41 D1 G1 X0 Y0 F600\nG1 X20\nG40 G2 X30 Y-10 I0 J-10\n",
                3.0,
                "p.ngc:5:1: the move after G40",
            ),
            // A slot 4 mm wide for a 6 mm tool: the offset walls do not meet.
            (
                "G42 D1 G1 X0 Y0 F600\nG1 X10\nG1 Y10\nG1 X14\nG1 Y0\nG1 X30\n",
                3.0,
                "p.ngc:7:1: concave corner with line 6",
            ),
            // An arc of 2 mm with a 3 mm tool inside it.
            (
                "G41 D1 G1 X0 Y0 F600\nG3 X4 Y0 I2 J0\n",
                3.0,
                "p.ngc:4:1: the tool's radius 3.0000 mm is not less than this arc's radius",
            ),
            (
                "G41 D1 G1 X0 Y0 F600\nG42 D1 G1 X10\n",
                3.0,
                "p.ngc:4:1: cutter radius compensation is already on",
            ),
            (
                "G41 D1 G1 X0 Y0 F600\nG18 G1 X10\n",
                3.0,
                "p.ngc:4:1: the plane cannot change",
            ),
            (
                "G41 D1 G1 X0 Y0 F600\nT2 M6\n",
                3.0,
                "p.ngc:4:4: no tool change",
            ),
            (
                "G41 D1 G1 X0 Y0 F600\nG28\n",
                3.0,
                "p.ngc:4:1: G28, G30, G53 and G92",
            ),
            (
                "G41 D1 G1 X0 Y0 F600\nG43 H1\n",
                3.0,
                "p.ngc:4:1: the tool length offset",
            ),
            (
                "G41 D1 G1 X0 Y0 F600\nG81 X5 Y5 Z-3 R1\n",
                3.0,
                "p.ngc:4:1: drilling cycles are not allowed",
            ),
            (
                "G19 G41 D1 G1 Y0 Z0 F600\n",
                3.0,
                "p.ngc:3:5: cutter radius compensation is allowed only",
            ),
            (
                "G41 D2 G1 X0 Y0 F600\n",
                3.0,
                "p.ngc:3:5: D2 is not in the tool table (parameter toolRadii: 1:3)",
            ),
            ("G41 G1 X0 Y0 F600\n", 3.0, "p.ngc:3:1: G41 and G42 need D"),
            (
                "G41 D1.5 G1 X0 Y0 F600\n",
                3.0,
                "p.ngc:3:5: D1.5 is not a tool number",
            ),
            (
                "G40 G41 D1 G1 X0 Y0 F600\n",
                3.0,
                "p.ngc:3:5: two of G40, G41, G42",
            ),
        ] {
            let text = format!("{head}{body}M2\n");
            let e = refusal(&text, radius);
            assert!(e.starts_with(want), "{text}\n{e}");
        }
        for (table, want) in [
            ("1", "is not D:radius"),
            ("1:x", "is not a radius"),
            ("1:3, 1:4", "D1 is given twice"),
            ("1:1e9", "within"),
            ("a:3", "is not a tool number"),
        ] {
            assert!(
                ToolTable::parse(table).unwrap_err().contains(want),
                "{table}"
            );
        }
        let table = ToolTable::parse("D1=3; 2:-2.5 7:0.25").unwrap();
        assert_eq!(
            (
                table.radius(1.0),
                table.radius(2.0),
                table.radius(7.0),
                table.radius(0.0)
            ),
            (Ok(3.0), Ok(-2.5), Ok(0.25), Ok(0.0))
        );
    }

    /// The tool centre's points at the moves' ends, in X and Y.
    fn ends(text: &str, radius: f64) -> Vec<Vector<3>> {
        let part = parse_gcode(text, "p.ngc", &options(radius)).unwrap();
        compensate(&part)
            .unwrap()
            .moves
            .iter()
            .map(|m| m.end)
            .collect()
    }

    #[test]
    fn diameters_negative_radii_and_the_third_axis_at_a_corner() {
        let near = |a: &[Vector<3>], b: &[Vector<3>]| {
            a.len() == b.len() && a.iter().zip(b).all(|(p, q)| geometry::dist(p, q) < 1e-12)
        };
        let square = |code: &str, d: &str| {
            format!(
                "G21 G90\nG0 X-10 Y-10 Z0\n{code} {d} G1 X0 Y0 F600\nG1 X20\nG1 Z-2\nG4 P1\n\
                 G1 X20 Y20 Z-3\nG1 X0\nG40 G1 X-10 Y30\nM2\n"
            )
        };
        // G41 D1 with r 2, G41.1 D4 (the diameter) and G42 D1 with r −2 alike.
        let by_number = ends(&square("G41", "D1"), 2.0);
        assert!(near(&by_number, &ends(&square("G41.1", "D4"), 7.0)));
        assert!(near(&by_number, &ends(&square("G42", "D1"), -2.0)));
        // G41 on the counter-clockwise square's outside... its left is inside: the
        // entry end 2 mm left of the entry's direction, the sides offset inward, the
        // corner at (20, 0) concave; Z and the dwell stand at the cut corner, then the
        // ramp to (18, 18) on Z −3, the exit from (0, 18) to the programmed point.
        let s = std::f64::consts::FRAC_1_SQRT_2 * 2.0;
        let want = [
            Vector::<3>::new(-10.0, -10.0, 0.0),
            Vector::<3>::new(-s, s, 0.0),
            Vector::<3>::new(18.0, 2.0, 0.0),
            Vector::<3>::new(18.0, 2.0, -2.0),
            Vector::<3>::new(18.0, 2.0, -2.0),
            Vector::<3>::new(18.0, 18.0, -3.0),
            Vector::<3>::new(0.0, 18.0, -3.0),
            Vector::<3>::new(-10.0, 30.0, -3.0),
        ];
        // The entry's corner with the first side is convex: an arc about (0, 0).
        let got = &by_number;
        assert_eq!(got.len(), want.len() + 1, "{got:?}");
        assert!(geometry::dist(&got[2], &Vector::<3>::new(0.0, 2.0, 0.0)) < 1e-12);
        let without_arc: Vec<_> = got[..2].iter().chain(&got[3..]).copied().collect();
        assert!(near(&without_arc, &want), "{without_arc:?}");
    }

    #[test]
    fn an_entry_arc_ends_on_its_arcs_offset_and_the_next_move_follows_on() {
        // LinuxCNC's gmoccapy demo: from the centre (50, 50) a half circle G3 to (70, 50)
        // about (60, 50) under G41 (inside it: r 10 − 3), then the full circle about
        // (50, 50) (inside: r 20 − 3).
        let text = "G21 G90\nG0 X50 Y50 Z5\nG1 Z0 F250\nG41 D1\nG3 X70 Y50 Z-1 I10 J0\n\
                    G3 I-20\nG40 G0 X50 Y50\nM2\n";
        let part = parse_gcode(text, "p.ngc", &options(3.0)).unwrap();
        let centre = compensate(&part).unwrap();
        let arcs: Vec<_> = centre
            .moves
            .iter()
            .filter_map(|m| match &m.motion {
                Motion::Arc { arc, .. } => Some((arc.clone(), m.end)),
                _ => None,
            })
            .collect();
        assert_eq!(arcs.len(), 2, "{:?}", centre.moves);
        // The entry: from (50, 50) to (67, 50) on the circle through both whose centre is
        // nearest (60, 50): (58.5, 50), r 8.5, counter-clockwise, Z to −1.
        let (entry, end) = &arcs[0];
        assert!(geometry::dist(&entry.center(), &Vector2::new(58.5, 50.0)) < 1e-12);
        assert!((entry.radius() - 8.5).abs() < 1e-12 && entry.sweep() > 0.0);
        assert!(geometry::dist(end, &Vector::<3>::new(67.0, 50.0, -1.0)) < 1e-12);
        assert!(geometry::dist(&entry.point(0.0), &Vector2::new(50.0, 50.0)) < 1e-12);
        // The full circle on r 17 from there, tangent to the entry's end.
        let (full, end) = &arcs[1];
        assert!(geometry::dist(&full.center(), &Vector2::new(50.0, 50.0)) < 1e-12);
        assert!((full.radius() - 17.0).abs() < 1e-12);
        assert!((full.sweep() - TAU).abs() < 1e-12);
        assert!(geometry::dist(end, &Vector::<3>::new(67.0, 50.0, -1.0)) < 1e-12);
        // The exit, straight back to the programmed point.
        let last = centre.moves.last().unwrap();
        assert!(
            matches!(last.motion, Motion::Line) && last.end == Vector::<3>::new(50.0, 50.0, -1.0)
        );
    }

    #[test]
    fn stretches_entries_and_exits_as_the_review_found_them() {
        let head = "G21 G90\nG0 X-10 Y-10\nG41 D1 G1 X0 Y0 F600\nG1 X20\n";
        // G40 then G41 with nothing moving between: a new entry from (20, 3), the first
        // stretch's last offset end, toward (17, 20), cut where it meets the offset of
        // the next side (y = 17).
        let ends = ends(
            &format!("{head}G40\nG41 D1\nG1 X20 Y20\nG1 X0\nG40 G1 X-10 Y30\n"),
            3.0,
        );
        let at = ends
            .iter()
            .position(|p| geometry::dist(p, &Vector::<3>::new(20.0, 3.0, 0.0)) < 1e-12)
            .expect("the first stretch ends at its offset end");
        let x = 20.0 - 3.0 * 14.0 / 17.0;
        assert!(
            geometry::dist(&ends[at + 1], &Vector::<3>::new(x, 17.0, 0.0)) < 1e-12,
            "{ends:?}"
        );
        // A whole circle whose end meets the next move's offset at a nearly tangent
        // concave corner stays whole.
        let text = "G0 X10 Y-20\nG41 D1 G1 X10 Y-10 F600\nG1 Y0\nG3 I-10 J0\n\
                    G1 X9.9999995 Y10\nG40 G1 X0 Y20\n";
        let part = parse_gcode(text, "p.ngc", &options(3.0)).unwrap();
        let centre = compensate(&part).unwrap();
        let sweeps: Vec<f64> = centre
            .moves
            .iter()
            .filter_map(|m| match &m.motion {
                Motion::Arc { arc, .. } => Some(arc.sweep()),
                _ => None,
            })
            .collect();
        assert_eq!(sweeps.len(), 1);
        assert!((sweeps[0] - TAU).abs() < 1e-6, "{sweeps:?}");
        // A stretch that moves Z alone leaves the tool at the last offset point: the
        // move after the next G40 is still an exit move, and an arc there is refused.
        let e = refusal(
            &format!("{head}G40 G0 Z5\nG41 D1 G0 Z6\nG40 G2 X30 Y-10 I0 J-10\n"),
            3.0,
        );
        assert!(e.starts_with("p.ngc:7:1: the move after G40"), "{e}");
        // G40 and G49 in one block: compensation is off before the length offset.
        let text = format!("{head}G40 G49 G0 X30 Y-10\n");
        assert!(parse_gcode(&text, "p.ngc", &options(3.0)).is_ok());
    }
}
