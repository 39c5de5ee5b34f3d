//! The feed plan of an XY path (docs/design/two-axis.md §4.9): the planned geometry (the
//! program with its blended corners rounded), a speed, acceleration and jerk for each of
//! its pieces, the speed at every junction from a look-ahead over the whole path, and a
//! time-optimal jerk-limited motion over each piece between them.
//!
//! The reference's acceleration is the tangential s̈·T plus the centripetal v²κ·N, and
//! its jerk (ṡ̈ − v³κ²)·T + (3vκ·s̈ + v³κ′)·N. On a curved piece each of the four terms
//! gets its share: the normal acceleration and the tangential one within accel/√2 each,
//! and each jerk component within jerk/√2 (half of it to each of its two terms), at the
//! piece's greatest curvature and curvature rate. A line has the whole acceleration and
//! jerk for its tangential motion, so a single line is Ruckig's time-optimal motion.
//! Where the samples every Ts see a jump, the junction's speed is capped: a curvature
//! jump Δκ makes an acceleration step v²Δκ in one sample (v²Δκ ≤ jerk·Ts), a kink of
//! angle θ a one-sample velocity turn v·θ (v·θ ≤ accel·Ts and ≤ jerk·Ts²). A kink the
//! geometry keeps (an exact stop, a corner into or out of an arc, a NURBS's kink) of
//! more than [`MIN_BLEND_TURN`] is a stop. A NURBS is planned on its pieces of
//! [`NurbsPieces`], whose curvature bounds are sampled.

use super::nurbs_pieces::NurbsPieces;
use crate::geometry::{self, Vector2};
use crate::math;
use crate::part_program::{Corner, Speed};
use crate::path::piece_profile::{plan_piece, reachable, Phase, PieceLimits};
use crate::path::planar::{blended, Move, Path, Program, Shape, Standstill, MIN_BLEND_TURN};
use crate::path::{Curve, PathError};

/// What the plan obeys.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct XyLimits {
    /// Speed of moves without an F word (mm/s, > 0).
    pub feed: f64,
    /// Speed of G0 (mm/s, > 0).
    pub rapid: f64,
    /// Acceleration along the path, tangential and centripetal together (mm/s², > 0).
    pub accel: f64,
    /// Jerk (mm/s³, ≥ 0; 0: no jerk limit).
    pub jerk: f64,
    /// The blend tolerance of bare G64 and of the start (mm, ≥ 0; 0: exact stops).
    pub tolerance: f64,
    /// The sample period the limits are judged at (s, > 0).
    pub ts: f64,
}

/// A planned XY path: its geometry and its motion.
#[derive(Clone, Debug, PartialEq)]
pub struct XyPlan {
    geometry: Geometry,
    phases: Vec<Phase>,
    duration: f64,
}

/// The planned geometry as the samples run along it.
#[derive(Clone, Debug, PartialEq)]
enum Geometry {
    /// Moves whose own parameter is proportional to their arc length.
    Program(Program),
    /// A NURBS, mapped from arc length to its parameter.
    Nurbs(NurbsPieces),
}

/// Where a plan stands at one time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct XyPoint {
    /// Position, mm.
    pub point: Vector2,
    /// Arc length along the planned geometry, mm.
    pub s: f64,
    /// Path speed, mm/s.
    pub speed: f64,
    /// The unit tangent of the planned geometry there (the direction of travel).
    pub direction: Vector2,
    /// Acceleration, mm/s²: the path acceleration along the tangent plus speed² times
    /// the curvature vector.
    pub acceleration: Vector2,
}

/// The plan's position in its phases and along its geometry (a program's move, a
/// NURBS's cell), for a run of increasing times.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct XyCursor {
    phase: usize,
    piece: usize,
}

/// What the planner needs of one piece of the geometry.
struct PlanPiece {
    /// Arc length at its start and its length, mm.
    start: f64,
    length: f64,
    /// The programmed speed, mm/s.
    speed: f64,
    /// Signed curvature at the start and the end, 1/mm.
    kappa: [f64; 2],
    /// The greatest |κ| (1/mm) and |κ′| (1/mm²).
    kappa_max: f64,
    rate_max: f64,
    /// Unit tangent at the start and the end.
    tangent: [Vector2; 2],
    /// An exact stop at its end.
    stops: bool,
    /// How long the table stands there, s.
    standstill: f64,
    /// Where it comes from, for messages.
    origin: Origin,
}

#[derive(Clone, Copy)]
enum Origin {
    Line(usize),
    Parameter(f64),
}

impl std::fmt::Display for Origin {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Origin::Line(n) => write!(f, "the move of line {n}"),
            Origin::Parameter(u) => write!(f, "the NURBS piece from u = {u}"),
        }
    }
}

/// The geometry a path is planned on: a program's blended moves, a line or an arc as a
/// program of one move, a NURBS itself (its kinks are exact stops, never blended).
pub fn planned_geometry(path: &Path, tolerance: f64) -> Result<Path, PathError> {
    let one = |shape: Shape| {
        Program::new(vec![Move {
            shape,
            speed: Speed::Default,
            corner: Corner::ExactStop,
            line: 1,
            standstill: Standstill::default(),
        }])
        .map(Path::Program)
    };
    match path {
        Path::Program(program) => Ok(Path::Program(blended(program, tolerance))),
        Path::Line(l) => one(Shape::Line(l.clone())),
        Path::Arc(a) => one(Shape::Arc(a.clone())),
        Path::Nurbs(n) => Ok(Path::Nurbs(n.clone())),
    }
}

impl XyLimits {
    /// Limits for the tests: 50 mm/s, rapids at 100, 2 m/s², 10⁵ mm/s³, 5 µm, 1 ms.
    #[cfg(test)]
    pub(crate) fn example() -> Self {
        XyLimits {
            feed: 50.0,
            rapid: 100.0,
            accel: 2000.0,
            jerk: 1e5,
            tolerance: 0.005,
            ts: 1e-3,
        }
    }

    /// Checks every value; the message names it.
    pub fn validate(&self) -> Result<(), String> {
        let positive = [
            ("feed", self.feed),
            ("rapid", self.rapid),
            ("accel", self.accel),
            ("Ts", self.ts),
        ];
        for (name, v) in positive {
            if !(v.is_finite() && v > 0.0) {
                return Err(format!("'{name}' = {v} must be finite and > 0"));
            }
        }
        for (name, v) in [("jerk", self.jerk), ("tolerance", self.tolerance)] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(format!("'{name}' = {v} must be finite and >= 0"));
            }
        }
        Ok(())
    }

    /// The jerk limit as the profiles take it.
    fn jerk_limit(&self) -> f64 {
        if self.jerk > 0.0 {
            self.jerk
        } else {
            f64::INFINITY
        }
    }

    /// The programmed speed of a move.
    fn speed_of(&self, m: &Move) -> f64 {
        match m.speed {
            Speed::Feed(f) => f,
            Speed::Default => self.feed,
            Speed::Rapid => self.rapid,
        }
    }
}

/// Curvature (signed, 1/mm) at the start and the end of a move, its greatest |κ| and
/// its greatest |κ′| (1/mm²).
fn curvatures(shape: &Shape) -> ([f64; 2], f64, f64) {
    match shape {
        Shape::Line(_) => ([0.0; 2], 0.0, 0.0),
        Shape::Arc(a) => {
            let k = a.sweep().signum() / a.radius();
            ([k; 2], k.abs(), 0.0)
        }
        Shape::Blend(b) => ([0.0; 2], b.peak_curvature(), b.curvature_rate()),
    }
}

/// A program's moves as pieces; a blend goes at the slower of the moves it joins.
fn program_pieces(program: &Program, limits: &XyLimits) -> Vec<PlanPiece> {
    let moves = program.moves();
    let n = moves.len();
    (0..n)
        .map(|i| {
            let m = &moves[i];
            let speed = match m.shape {
                Shape::Blend(_) if i + 1 < n => {
                    limits.speed_of(m).min(limits.speed_of(&moves[i + 1]))
                }
                _ => limits.speed_of(m),
            };
            let (kappa, kappa_max, rate_max) = curvatures(&m.shape);
            PlanPiece {
                start: program.start_of(i),
                length: m.shape.curve().length(),
                speed,
                kappa,
                kappa_max,
                rate_max,
                tangent: [m.shape.end_tangent(0), m.shape.end_tangent(1)],
                stops: m.corner == Corner::ExactStop,
                standstill: m.standstill.duration(limits.feed, limits.rapid),
                origin: Origin::Line(m.line),
            }
        })
        .collect()
}

/// A NURBS's pieces, at the `feed` parameter.
fn nurbs_pieces(cut: &NurbsPieces, limits: &XyLimits) -> Vec<PlanPiece> {
    cut.pieces()
        .iter()
        .map(|p| PlanPiece {
            start: p.s[0],
            length: p.s[1] - p.s[0],
            speed: limits.feed,
            kappa: p.kappa,
            kappa_max: p.kappa_max,
            rate_max: p.rate_max,
            tangent: p.tangent,
            stops: false,
            standstill: 0.0,
            origin: Origin::Parameter(p.u[0]),
        })
        .collect()
}

/// A piece's limits along its arc length (module docs).
fn piece_limits(piece: &PlanPiece, limits: &XyLimits) -> PieceLimits {
    let jerk = limits.jerk_limit();
    let (speed, kappa, rate) = (piece.speed, piece.kappa_max, piece.rate_max);
    if kappa == 0.0 {
        return PieceLimits {
            speed,
            accel: limits.accel,
            jerk,
        };
    }
    let share = std::f64::consts::FRAC_1_SQRT_2;
    let term = 0.5 * share * jerk;
    let mut v = speed.min((share * limits.accel / kappa).sqrt());
    v = v.min(math::cbrt(term / (kappa * kappa)));
    if rate > 0.0 {
        v = v.min(math::cbrt(term / rate));
    }
    PieceLimits {
        speed: v,
        accel: (share * limits.accel).min(term / (3.0 * v * kappa)),
        jerk: term,
    }
}

/// The speed cap of the junction between `before` and `after` (module docs).
fn junction_cap(before: &PlanPiece, after: &PlanPiece, limits: &XyLimits) -> f64 {
    if before.stops {
        return 0.0;
    }
    let (t0, t1) = (before.tangent[1], after.tangent[0]);
    let turn = math::atan2(geometry::cross(&t0, &t1), t0.dot(&t1)).abs();
    // A kink the geometry kept (an exact stop, a corner into an arc, a NURBS's kink) is
    // stopped at; one below the blends' least turn is passed at its cap.
    if turn >= MIN_BLEND_TURN || turn.is_nan() {
        return 0.0;
    }
    let (ts, jerk) = (limits.ts, limits.jerk_limit());
    let mut v = f64::INFINITY;
    if turn > 0.0 {
        v = (limits.accel * ts).min(jerk * ts * ts) / turn;
    }
    let jump = (before.kappa[1] - after.kappa[0]).abs();
    if jump > 0.0 {
        v = v.min((jerk * ts / jump).sqrt());
    }
    v
}

impl XyPlan {
    /// Plans `path` within `limits` (checked first).
    pub fn new(path: &Path, limits: &XyLimits) -> Result<Self, PathError> {
        limits.validate().map_err(PathError::invalid)?;
        let (geometry, plan_pieces) = match planned_geometry(path, limits.tolerance)? {
            Path::Program(program) => {
                let pieces = program_pieces(&program, limits);
                (Geometry::Program(program), pieces)
            }
            Path::Nurbs(nurbs) => {
                let cut = NurbsPieces::new(nurbs)?;
                let pieces = nurbs_pieces(&cut, limits);
                (Geometry::Nurbs(cut), pieces)
            }
            Path::Line(_) | Path::Arc(_) => {
                return Err(PathError::invalid(
                    "a line or an arc is planned as a program",
                ))
            }
        };
        let n = plan_pieces.len();
        let pieces: Vec<PieceLimits> = plan_pieces
            .iter()
            .map(|p| piece_limits(p, limits))
            .collect();
        let lengths: Vec<f64> = plan_pieces.iter().map(|p| p.length).collect();
        // Junction j is the start of piece j; 0 and n are the path's ends, at rest.
        let mut junction = vec![0.0; n + 1];
        for j in 1..n {
            let cap = junction_cap(&plan_pieces[j - 1], &plan_pieces[j], limits);
            junction[j] = cap.min(pieces[j - 1].speed).min(pieces[j].speed);
        }
        // Look-ahead: slow in time for every later junction, then reach what the
        // earlier ones allow. The profiles get a margin of 10⁻⁹ of each length.
        let usable = |j: usize| lengths[j] * (1.0 - 1e-9);
        for j in (0..n).rev() {
            junction[j] = reachable(junction[j + 1], usable(j), junction[j], &pieces[j]);
        }
        for j in 0..n {
            junction[j + 1] = reachable(junction[j], usable(j), junction[j + 1], &pieces[j]);
        }
        let mut phases = Vec::with_capacity(4 * n);
        let mut time = 0.0;
        for j in 0..n {
            time += plan_piece(
                lengths[j],
                (junction[j], junction[j + 1]),
                &pieces[j],
                (time, plan_pieces[j].start),
                &mut phases,
            )
            .map_err(|e| PathError::invalid(format!("{}: {e}", plan_pieces[j].origin)))?;
            let standstill = plan_pieces[j].standstill;
            if standstill > 0.0 {
                // At rest at the piece's end for that long: a phase without motion.
                phases.push(Phase {
                    time,
                    s: plan_pieces[j].start + lengths[j],
                    speed: 0.0,
                    accel: 0.0,
                    jerk: 0.0,
                });
                time += standstill;
            }
        }
        if !(time.is_finite() && time > 0.0) {
            return Err(PathError::invalid(format!(
                "the planned duration {time} s is not a positive number"
            )));
        }
        Ok(XyPlan {
            geometry,
            phases,
            duration: time,
        })
    }

    /// The planned geometry (a program's blended corners included).
    pub fn geometry(&self) -> Path {
        match &self.geometry {
            Geometry::Program(p) => Path::Program(p.clone()),
            Geometry::Nurbs(cut) => Path::Nurbs(cut.nurbs().clone()),
        }
    }

    /// The planned duration, s.
    pub fn duration(&self) -> f64 {
        self.duration
    }

    /// The length of the planned geometry, mm.
    fn length(&self) -> f64 {
        match &self.geometry {
            Geometry::Program(p) => p.length(),
            Geometry::Nurbs(cut) => cut.length(),
        }
    }

    /// Where the plan stands at time `t` (clamped to the plan), moving `cursor` on from
    /// where it was: a run of increasing times costs O(1) a call, however long the path.
    pub fn at(&self, t: f64, cursor: &mut XyCursor) -> XyPoint {
        let length = self.length();
        let (s, speed, along) = if t >= self.duration {
            (length, 0.0, 0.0)
        } else {
            let t = t.max(0.0);
            while cursor.phase + 1 < self.phases.len() && self.phases[cursor.phase + 1].time <= t {
                cursor.phase += 1;
            }
            let phase = &self.phases[cursor.phase];
            let (s, v, a) = phase.at(t - phase.time);
            (s.clamp(0.0, length), v.max(0.0), a)
        };
        let (point, (direction, curvature)) = match &self.geometry {
            Geometry::Program(program) => {
                let last = program.moves().len() - 1;
                while cursor.piece < last && program.start_of(cursor.piece + 1) < s {
                    cursor.piece += 1;
                }
                (
                    program.point_in(cursor.piece, s),
                    program.frame_in(cursor.piece, s),
                )
            }
            Geometry::Nurbs(cut) => {
                let point = cut.point(s, &mut cursor.piece);
                (point, cut.frame(s, cursor.piece))
            }
        };
        XyPoint {
            point,
            s,
            speed,
            direction,
            acceleration: direction * along + curvature * (speed * speed),
        }
    }
}
