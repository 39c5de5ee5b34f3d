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
//! geometry keeps (an exact stop, a corner into or out of an arc) of more than
//! [`MIN_BLEND_TURN`] is a stop.

use super::piece_profile::{plan_piece, reachable, Phase, PieceLimits};
use crate::geometry::{self, Vector2};
use crate::path::program::{blended, Corner, Move, Program, Shape, Speed, MIN_BLEND_TURN};
use crate::path::{Curve, Path, PathError};

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
    geometry: Program,
    phases: Vec<Phase>,
    duration: f64,
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
}

/// The plan's position in its phases and pieces, for a run of increasing times.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct XyCursor {
    phase: usize,
    piece: usize,
}

/// The geometry a path is planned on: a program's blended moves, a line or an arc as a
/// program of one move.
pub fn planned_geometry(path: &Path, tolerance: f64) -> Result<Program, PathError> {
    let one = |shape: Shape| {
        Program::new(vec![Move {
            shape,
            speed: Speed::Default,
            corner: Corner::ExactStop,
            line: 1,
        }])
    };
    match path {
        Path::Program(program) => Ok(blended(program, tolerance)),
        Path::Line(l) => one(Shape::Line(l.clone())),
        Path::Arc(a) => one(Shape::Arc(a.clone())),
        Path::Nurbs(_) => Err(PathError::invalid(
            "the feed planner takes G-code programs, lines and arcs; a NURBS path runs at the \
             constant 'feed' (accel = 0)",
        )),
    }
}

impl XyLimits {
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

/// Curvature (signed, 1/mm) at the start and the end of a piece, its greatest |κ| and
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

/// A piece's limits along its arc length (module docs).
fn piece_limits(speed: f64, shape: &Shape, limits: &XyLimits) -> PieceLimits {
    let jerk = limits.jerk_limit();
    let (_, kappa, rate) = curvatures(shape);
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
    v = v.min((term / (kappa * kappa)).cbrt());
    if rate > 0.0 {
        v = v.min((term / rate).cbrt());
    }
    PieceLimits {
        speed: v,
        accel: (share * limits.accel).min(term / (3.0 * v * kappa)),
        jerk: term,
    }
}

/// The unit tangent at a piece's start (`u` = 0) or end (1).
fn tangent(shape: &Shape, u: f64) -> Vector2 {
    let d = shape.curve().eval(u).d1;
    d / geometry::norm(&d)
}

impl XyPlan {
    /// Plans `path` within `limits` (checked first).
    pub fn new(path: &Path, limits: &XyLimits) -> Result<Self, PathError> {
        limits.validate().map_err(PathError::invalid)?;
        let geometry = planned_geometry(path, limits.tolerance)?;
        let moves = geometry.moves();
        let n = moves.len();
        // A blend goes at the slower of the moves it joins.
        let speeds: Vec<f64> = (0..n)
            .map(|i| match moves[i].shape {
                Shape::Blend(_) if i + 1 < n => limits
                    .speed_of(&moves[i])
                    .min(limits.speed_of(&moves[i + 1])),
                _ => limits.speed_of(&moves[i]),
            })
            .collect();
        let pieces: Vec<PieceLimits> = (0..n)
            .map(|i| piece_limits(speeds[i], &moves[i].shape, limits))
            .collect();
        let lengths: Vec<f64> = (0..n).map(|i| moves[i].shape.curve().length()).collect();
        // Junction j is the start of piece j; 0 and n are the path's ends, at rest.
        let jerk = limits.jerk_limit();
        let mut junction = vec![0.0; n + 1];
        for j in 1..n {
            let (before, after) = (&moves[j - 1], &moves[j]);
            let mut v = pieces[j - 1].speed.min(pieces[j].speed);
            if before.corner == Corner::ExactStop {
                v = 0.0;
            }
            let (t0, t1) = (tangent(&before.shape, 1.0), tangent(&after.shape, 0.0));
            let turn = geometry::cross(&t0, &t1).atan2(t0.dot(&t1)).abs();
            // A kink the geometry kept (an exact stop, or a corner into an arc) is
            // stopped at; one below the blends' least turn is passed at its cap.
            if turn >= MIN_BLEND_TURN {
                v = 0.0;
            } else if turn > 0.0 {
                v = v.min((limits.accel * limits.ts).min(jerk * limits.ts * limits.ts) / turn);
            }
            let jump = (curvatures(&before.shape).0[1] - curvatures(&after.shape).0[0]).abs();
            if jump > 0.0 {
                v = v.min((jerk * limits.ts / jump).sqrt());
            }
            junction[j] = v;
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
            let start = geometry.start_of(j);
            time += plan_piece(
                lengths[j],
                (junction[j], junction[j + 1]),
                &pieces[j],
                (time, start),
                &mut phases,
            )
            .map_err(|e| PathError::invalid(format!("the move of line {}: {e}", moves[j].line)))?;
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

    /// The planned geometry.
    pub fn geometry(&self) -> &Program {
        &self.geometry
    }

    /// The planned duration, s.
    pub fn duration(&self) -> f64 {
        self.duration
    }

    /// Where the plan stands at time `t` (clamped to the plan), moving `cursor` on from
    /// where it was: a run of increasing times costs O(1) a call, however long the path.
    pub fn at(&self, t: f64, cursor: &mut XyCursor) -> XyPoint {
        let length = self.geometry.length();
        let (s, speed) = if t >= self.duration {
            (length, 0.0)
        } else {
            let t = t.max(0.0);
            while cursor.phase + 1 < self.phases.len() && self.phases[cursor.phase + 1].time <= t {
                cursor.phase += 1;
            }
            let phase = &self.phases[cursor.phase];
            let (s, v, _) = phase.at(t - phase.time);
            (s.clamp(0.0, length), v.max(0.0))
        };
        let last = self.geometry.moves().len() - 1;
        while cursor.piece < last && self.geometry.start_of(cursor.piece + 1) < s {
            cursor.piece += 1;
        }
        XyPoint {
            point: self.geometry.point_in(cursor.piece, s),
            s,
            speed,
        }
    }
}
