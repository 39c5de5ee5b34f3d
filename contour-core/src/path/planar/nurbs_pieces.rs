//! A NURBS cut for the XY feed planner (docs/design/two-axis.md §4.9): cells of bounded
//! turn, each with its arc length and a quintic map from arc length to the NURBS parameter,
//! grouped into pieces whose curvature bounds the speed as an arc's or a blend's does.
//!
//! A NURBS parameter is not its arc length, and the plan runs on arc length. Each cell
//! maps s to u by the quintic Hermite interpolant of u(s) with du/ds = 1/|C′(u)| and
//! d²u/ds² = −C′·C″/|C′|⁴ at its ends, so that the samples' velocity and acceleration are
//! continuous from cell to cell. The map is checked against the arc length integrated to
//! its quarter points (5-point Gauss–Legendre on each quarter, which must agree with the
//! rule on the whole cell) and the cell split until it agrees within [`MAP_TOLERANCE`]: a
//! sample is C(u(s)), on the curve exactly, at most that far along it from the planned
//! place. Every cell costs a fixed number of evaluations and their number is bounded
//! ([`MAX_CELLS`]), so a NURBS from a state cannot make the planning run away. Cells never
//! cross a knot, where a NURBS may have a kink or a curvature jump, and turn at most
//! [`CELL_TURN`]; their curvature at five points equally spaced in s gives the greatest
//! |κ| and |κ′| of the cell (the sampled values with a margin for what lies between).
//!
//! A piece is a run of cells between two knots where the curve is not smooth (kink or
//! curvature jump), of at most [`PIECE_TURN`] and of curvatures within a factor 2 of
//! each other: each piece is one motion of the plan, starting and ending at zero
//! tangential acceleration, so pieces are kept long where the curvature allows it.

use crate::geometry::{self, Vector2};
use crate::math;
use crate::path::{gl5, Curve, CurvePoint, Nurbs, PathError};

/// The largest gap (mm) between a cell's map and the integrated arc length.
pub const MAP_TOLERANCE: f64 = 1e-10;

/// The largest turn of one cell, rad.
pub const CELL_TURN: f64 = 0.1;

/// The largest turn of one piece, rad.
pub const PIECE_TURN: f64 = 0.4;

/// The most cells a NURBS may need, and 16 more a knot span (a bound on the planning
/// work of a state from elsewhere; the built-in curves need a few hundred in all).
pub const MAX_CELLS: usize = 1 << 14;

/// The greatest |κ| a cell is planned with, 1/mm: a cusp (|C′| = 0) is taken as a corner
/// of 1 nm radius, passed slowly, rather than an infinite curvature.
const KAPPA_CAP: f64 = 1e6;

/// Curvatures within this much (1/mm) of each other count as equal when pieces are
/// grouped: radii beyond 100 mm limit no speed a table reaches.
const KAPPA_FLOOR: f64 = 1e-2;

/// Splits of one knot span, at most.
const MAX_DEPTH: u32 = 40;

/// One cell: arc lengths and parameters at its ends, and du/ds and d²u/ds² there.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Cell {
    s: [f64; 2],
    u: [f64; 2],
    slope: [f64; 2],
    bend: [f64; 2],
}

impl Cell {
    /// The parameter at arc length `s` (clamped into the cell): the quintic Hermite
    /// interpolant of u(s), so that u, du/ds and d²u/ds² (and with them the samples'
    /// velocity and acceleration) are continuous from cell to cell.
    fn parameter(&self, s: f64) -> f64 {
        let h = self.s[1] - self.s[0];
        let t = ((s - self.s[0]) / h).clamp(0.0, 1.0);
        let (t2, t3) = (t * t, t * t * t);
        let (t4, t5) = (t3 * t, t3 * t2);
        let end = 10.0 * t3 - 15.0 * t4 + 6.0 * t5;
        let u = (1.0 - end) * self.u[0]
            + end * self.u[1]
            + (t - 6.0 * t3 + 8.0 * t4 - 3.0 * t5) * h * self.slope[0]
            + (-4.0 * t3 + 7.0 * t4 - 3.0 * t5) * h * self.slope[1]
            + 0.5 * (t2 - 3.0 * t3 + 3.0 * t4 - t5) * h * h * self.bend[0]
            + 0.5 * (t3 - 2.0 * t4 + t5) * h * h * self.bend[1];
        u.clamp(self.u[0], self.u[1])
    }
}

/// What the planner needs of one piece.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NurbsPiece {
    /// Arc length at its start and end, mm.
    pub s: [f64; 2],
    /// Parameter at its start and end.
    pub u: [f64; 2],
    /// Signed curvature at its start and end (from inside the piece), 1/mm.
    pub kappa: [f64; 2],
    /// Unit tangent at its start and end.
    pub tangent: [Vector2; 2],
    /// The greatest |κ| (1/mm) and |dκ/ds| (1/mm²) along it.
    pub kappa_max: f64,
    pub rate_max: f64,
}

/// A NURBS by arc length, cut into cells and pieces.
#[derive(Clone, Debug, PartialEq)]
pub struct NurbsPieces {
    nurbs: Nurbs,
    cells: Vec<Cell>,
    pieces: Vec<NurbsPiece>,
}

/// A cell as measured before it is kept or split.
struct Probe {
    cell: Cell,
    /// Curvature at five points equally spaced in s.
    kappa: [f64; 5],
    /// Unit tangents at the ends.
    tangent: [Vector2; 2],
}

impl Probe {
    fn rate(&self) -> f64 {
        let q = 0.25 * (self.cell.s[1] - self.cell.s[0]);
        let steps = self.kappa.windows(2).map(|w| (w[1] - w[0]).abs());
        steps.fold(0.0, f64::max) / q
    }

    /// The greatest |κ|: the samples' and what a rate 25 % above the sampled one reaches
    /// half way between two of them.
    fn kappa_max(&self) -> f64 {
        let q = 0.25 * (self.cell.s[1] - self.cell.s[0]);
        let sampled = self.kappa.iter().fold(0.0f64, |m, k| m.max(k.abs()));
        (sampled + 1.25 * self.rate() * 0.5 * q).min(KAPPA_CAP)
    }

    fn kappa_min(&self) -> f64 {
        self.kappa.iter().fold(f64::INFINITY, |m, k| m.min(k.abs()))
    }

    /// ∫|κ| ds by Simpson's rule on the samples.
    fn turn(&self) -> f64 {
        let h = self.cell.s[1] - self.cell.s[0];
        let k = self.kappa.map(f64::abs);
        h / 12.0 * (k[0] + 4.0 * k[1] + 2.0 * k[2] + 4.0 * k[3] + k[4])
    }
}

/// Signed curvature of a point and derivatives, capped.
fn curvature(d1: Vector2, d2: Vector2) -> f64 {
    let speed = geometry::norm(&d1);
    let k = geometry::cross(&d1, &d2) / (speed * speed * speed);
    if k.is_finite() {
        k.clamp(-KAPPA_CAP, KAPPA_CAP)
    } else {
        KAPPA_CAP
    }
}

/// The unit direction of travel at a point, `leaving` it or arriving at it: at a cusp
/// (C′ = 0, a repeated control point) the curve arrives along −C″ and leaves along C″.
fn direction(e: &CurvePoint, leaving: bool) -> Vector2 {
    let (d, sign) = if geometry::norm(&e.d1) > 0.0 {
        (e.d1, 1.0)
    } else if leaving {
        (e.d2, 1.0)
    } else {
        (e.d2, -1.0)
    };
    let n = geometry::norm(&d);
    if n > 0.0 {
        d * (sign / n)
    } else {
        Vector2::zeros()
    }
}

impl NurbsPieces {
    /// Cuts `nurbs` (module docs); refuses a curve of zero length or one that needs more
    /// than [`MAX_CELLS`] cells.
    pub fn new(nurbs: Nurbs) -> Result<Self, PathError> {
        let mut knots = nurbs.breakpoints();
        knots.dedup();
        let mut probes = Vec::new();
        let budget = MAX_CELLS + 16 * knots.len();
        let mut s = 0.0;
        for span in knots.windows(2) {
            let (u0, u1) = (span[0], span[1]);
            cut(
                &nurbs,
                (u0, u1, true),
                MAX_DEPTH,
                (&mut s, budget),
                &mut probes,
            )?;
        }
        if probes.is_empty() || !(s.is_finite() && s > 0.0) {
            return Err(PathError::invalid(format!(
                "the NURBS has no length to plan a motion along ({s} mm)"
            )));
        }
        let pieces = group(&nurbs, &knots, &probes);
        Ok(NurbsPieces {
            nurbs,
            cells: probes.iter().map(|p| p.cell).collect(),
            pieces,
        })
    }

    /// The pieces, end to end from s = 0.
    pub fn pieces(&self) -> &[NurbsPiece] {
        &self.pieces
    }

    /// Arc length of the whole curve, mm.
    pub fn length(&self) -> f64 {
        self.cells[self.cells.len() - 1].s[1]
    }

    /// The curve.
    pub fn nurbs(&self) -> &Nurbs {
        &self.nurbs
    }

    /// The point at arc length `s`, moving `cell` on from where it was: a run of
    /// increasing `s` costs O(1) a call.
    pub fn point(&self, s: f64, cell: &mut usize) -> Vector2 {
        let last = self.cells.len() - 1;
        *cell = (*cell).min(last);
        while *cell < last && self.cells[*cell].s[1] < s {
            *cell += 1;
        }
        while *cell > 0 && self.cells[*cell].s[0] > s {
            *cell -= 1;
        }
        self.nurbs.point(self.cells[*cell].parameter(s))
    }
}

impl NurbsPieces {
    /// The unit tangent and the curvature vector at arc length `s` in cell `cell` (as
    /// [`NurbsPieces::point`] left it); zeros where the curve has no tangent.
    pub fn frame(&self, s: f64, cell: usize) -> (Vector2, Vector2) {
        self.nurbs.eval(self.cells[cell].parameter(s)).frame()
    }
}

/// Measures the cell (u0, u1) starting at arc length `*s`, keeps it (appending to
/// `out`, advancing `*s`, at most `budget` cells in all) or splits it. `at_knot`: u1
/// ends a knot span.
fn cut(
    nurbs: &Nurbs,
    (u0, u1, at_knot): (f64, f64, bool),
    depth: u32,
    (s, budget): (&mut f64, usize),
    out: &mut Vec<Probe>,
) -> Result<(), PathError> {
    // The length by Gauss-Legendre on the cell's quarters, checked against the rule on
    // the whole cell: a fixed number of evaluations a cell (the number of cells is
    // bounded, and with it the work, whatever the NURBS).
    let whole = gl5(nurbs, u0, u1);
    let h: f64 = (0..4)
        .map(|k| {
            let at = |k: usize| u0 + (u1 - u0) * k as f64 / 4.0;
            gl5(nurbs, at(k), if k == 3 { u1 } else { at(k + 1) })
        })
        .sum();
    if !h.is_finite() {
        return Err(PathError::invalid(format!(
            "the NURBS's length from u = {u0} to {u1} is not a number ({h} mm)"
        )));
    }
    if h <= 0.0 {
        // No length (repeated control points): nothing to move along.
        return Ok(());
    }
    let start = nurbs.eval(u0);
    let end = if at_knot {
        nurbs.eval_from_below(u1)
    } else {
        nurbs.eval(u1)
    };
    // du/ds = 1/|C′| and d²u/ds² = −C′·C″/|C′|⁴; at a cusp (|C′| = 0) the secant's.
    let secant = (u1 - u0) / h;
    let derivatives = |e: &CurvePoint| {
        let speed2 = e.d1.dot(&e.d1);
        let slope = 1.0 / speed2.sqrt();
        let bend = -e.d1.dot(&e.d2) / (speed2 * speed2);
        if slope.is_finite() && bend.is_finite() {
            (slope, bend)
        } else {
            (secant, 0.0)
        }
    };
    let (d0, d1) = (derivatives(&start), derivatives(&end));
    let cell = Cell {
        s: [*s, *s + h],
        u: [u0, u1],
        slope: [d0.0, d1.0],
        bend: [d0.1, d1.1],
    };
    // Curvature at the quarter points by the map; the turn first, the cheaper test.
    let quarter = |k: usize| cell.parameter(*s + 0.25 * h * k as f64);
    let mut kappa = [0.0; 5];
    kappa[0] = curvature(start.d1, start.d2);
    kappa[4] = curvature(end.d1, end.d2);
    for (k, kappa_k) in kappa.iter_mut().enumerate().take(4).skip(1) {
        let e = nurbs.eval(quarter(k));
        *kappa_k = curvature(e.d1, e.d2);
    }
    let probe = Probe {
        cell,
        kappa,
        tangent: [direction(&start, true), direction(&end, false)],
    };
    // The map at the quarter points against the arc length integrated to them.
    let slack = MAP_TOLERANCE + 16.0 * f64::EPSILON * (*s + h);
    let mapped = || {
        let (mut u_prev, mut along) = (u0, 0.0);
        (1..4).all(|k| {
            let u = quarter(k);
            along += gl5(nurbs, u_prev, u);
            u_prev = u;
            (along - 0.25 * h * k as f64).abs() <= slack
        })
    };
    let smooth = (h - whole).abs() <= 0.1 * slack;
    let least = depth == 0 || u1 - u0 <= 1e-12 * u1.abs().max(1.0);
    if least || (smooth && probe.turn() <= CELL_TURN && mapped()) {
        if out.len() >= budget {
            return Err(PathError::invalid(format!(
                "the NURBS needs more than {budget} pieces of at most {CELL_TURN} rad to plan a \
                 motion along it"
            )));
        }
        *s += h;
        out.push(probe);
        return Ok(());
    }
    let m = 0.5 * (u0 + u1);
    cut(nurbs, (u0, m, false), depth - 1, (s, budget), out)?;
    cut(nurbs, (m, u1, at_knot), depth - 1, (s, budget), out)
}

/// Groups the cells into pieces (module docs).
fn group(nurbs: &Nurbs, knots: &[f64], probes: &[Probe]) -> Vec<NurbsPiece> {
    // Interior knots where the curve is not smooth: a kink or a curvature jump.
    let breaks: Vec<f64> = knots[1..knots.len() - 1]
        .iter()
        .copied()
        .filter(|&u| {
            let (a, b) = (nurbs.eval_from_below(u), nurbs.eval(u));
            let (ka, kb) = (curvature(a.d1, a.d2), curvature(b.d1, b.d2));
            let (ta, tb) = (direction(&a, false), direction(&b, true));
            let turn = math::atan2(geometry::cross(&ta, &tb), ta.dot(&tb)).abs();
            !(turn <= 1e-9 && (ka - kb).abs() <= 1e-9 * (ka.abs() + kb.abs()) + 1e-12)
        })
        .collect();
    let mut pieces: Vec<NurbsPiece> = Vec::new();
    let mut next_break = 0;
    let (mut turn, mut low) = (0.0f64, 0.0f64);
    for (i, p) in probes.iter().enumerate() {
        // Cells and breaks both come in parameter order: one pass over each.
        while next_break < breaks.len() && breaks[next_break] < p.cell.u[0] {
            next_break += 1;
        }
        let starts_at_break = breaks.get(next_break) == Some(&p.cell.u[0]);
        let joins = i > 0 && !starts_at_break && {
            let last = pieces.last().expect("a piece before");
            let high = last.kappa_max.max(p.kappa_max());
            let low = low.min(p.kappa_min());
            turn + p.turn() <= PIECE_TURN && high <= 2.0 * low + KAPPA_FLOOR
        };
        if joins {
            let last = pieces.last_mut().expect("a piece before");
            last.s[1] = p.cell.s[1];
            last.u[1] = p.cell.u[1];
            last.kappa[1] = p.kappa[4];
            last.tangent[1] = p.tangent[1];
            last.kappa_max = last.kappa_max.max(p.kappa_max());
            last.rate_max = last.rate_max.max(1.25 * p.rate());
            turn += p.turn();
            low = low.min(p.kappa_min());
        } else {
            pieces.push(NurbsPiece {
                s: p.cell.s,
                u: p.cell.u,
                kappa: [p.kappa[0], p.kappa[4]],
                tangent: p.tangent,
                kappa_max: p.kappa_max(),
                rate_max: 1.25 * p.rate(),
            });
            turn = p.turn();
            low = p.kappa_min();
        }
    }
    pieces
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::path::planar::builtin;

    #[test]
    fn the_map_follows_the_arc_length_of_the_builtin_curves() {
        for nurbs in [builtin::infinity(), builtin::trident()] {
            let cut = NurbsPieces::new(nurbs.clone()).unwrap();
            let length = nurbs.length();
            assert!((cut.length() - length).abs() < 1e-9, "{}", cut.length());
            // Points along the map against the arc length integrated to them.
            let mut cell = 0;
            for k in 0..=1000 {
                let s = length * k as f64 / 1000.0;
                let p = cut.point(s, &mut cell);
                let u = cut.cells[cell].parameter(s);
                assert!((nurbs.point(u) - p).amax() == 0.0);
                let along = nurbs.length_between(0.0, u);
                assert!((along - s).abs() < 1e-9, "{k}: {along} vs {s}");
            }
            // Pieces end to end, each within its turn.
            let pieces = cut.pieces();
            assert_eq!(pieces[0].s[0], 0.0);
            assert!(pieces.windows(2).all(|w| w[0].s[1] == w[1].s[0]));
            assert!(pieces.len() < cut.cells.len());
        }
    }

    #[test]
    fn a_circle_as_nurbs_has_the_circle_curvature() {
        let circle = builtin::rational_unit_circle();
        let cut = NurbsPieces::new(circle).unwrap();
        assert!((cut.length() - 2.0 * std::f64::consts::PI).abs() < 1e-9);
        for p in cut.pieces() {
            assert!((p.kappa_max - 1.0).abs() < 0.2, "{p:?}");
            assert!((p.kappa[0] - 1.0).abs() < 1e-9 && (p.kappa[1] - 1.0).abs() < 1e-9);
        }
    }
}

#[cfg(test)]
mod pathological {
    use super::*;
    use crate::path::planar::{Path, XyCursor, XyLimits, XyPlan};

    #[test]
    fn a_cusp_is_a_stop_and_wild_control_points_are_refused_in_bounded_work() {
        // A cusp: a repeated interior control point of a quadratic (C′ = 0 at (10, 0),
        // where the path turns back by 153°).
        let cusp = Nurbs::new(
            2,
            vec![0.0, 0.0, 0.0, 1.0, 2.0, 2.0, 2.0],
            vec![[0.0, 0.0], [10.0, 0.0], [10.0, 0.0], [0.0, 5.0]],
            None,
        )
        .unwrap();
        let cut = NurbsPieces::new(cusp.clone()).unwrap();
        assert!((cut.length() - cusp.length()).abs() < 1e-9);
        // The pieces meet at the cusp, where the direction turns back.
        let at = cut.pieces().iter().position(|p| p.u[0] == 1.0).unwrap();
        let (arrive, leave) = (cut.pieces()[at - 1].tangent[1], cut.pieces()[at].tangent[0]);
        assert!(
            (arrive - Vector2::new(1.0, 0.0)).amax() < 1e-12,
            "{arrive:?}"
        );
        assert!(
            (leave - Vector2::new(-2.0, 1.0) / 5f64.sqrt()).amax() < 1e-12,
            "{leave:?}"
        );
        // The plan stops there: the samples either side of the cusp within the first
        // step from rest.
        let limits = XyLimits {
            feed: 50.0,
            rapid: 200.0,
            accel: 2000.0,
            jerk: 1e5,
            tolerance: 0.0,
            ts: 1e-3,
        };
        let plan = XyPlan::new(&Path::Nurbs(cusp), &limits).unwrap();
        let mut cursor = XyCursor::default();
        let first = limits.jerk * 1e-9 / 6.0;
        let near: Vec<f64> = (0..(plan.duration() * 1e3) as usize)
            .map(|k| {
                let p = plan.at(k as f64 * 1e-3, &mut cursor).point;
                geometry::norm(&(p - Vector2::new(10.0, 0.0)))
            })
            .collect();
        assert!(near.windows(2).any(|w| w[0] <= first && w[1] <= first));
        // Control points 10³⁰⁰ apart: refused with a message, after bounded work.
        let wild = Nurbs::new(
            3,
            vec![0.0, 0.0, 0.0, 0.0, 0.5, 1.0, 1.0, 1.0, 1.0],
            vec![
                [0.0, 0.0],
                [1e150, 1.0],
                [-1e150, 2.0],
                [1e-150, 3.0],
                [0.0, 1e100],
            ],
            None,
        )
        .unwrap();
        let e = NurbsPieces::new(wild).unwrap_err().to_string();
        assert!(e.contains("needs more than"), "{e}");
    }
}
