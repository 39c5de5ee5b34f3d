//! True contour error: the signed distance from P to the exact path (docs/design/two-axis.md §4.1 ground
//! truth), with the estimators' sign convention (positive right of travel, normal = left
//! unit normal at the foot point).
//!
//! Two ways to get it:
//! - [`true_error`]: global brute force, dense sampling of the whole path then safeguarded
//!   Newton refinement of every promising local minimum. Slow (thousands of evaluations
//!   per query) but simple: the reference for tests.
//! - [`TrueErrorIndex`]: the same answer in O(1)-ish time for closed-loop use (the PSO
//!   fitness). The path is cut once into short chunks with conservative bounding boxes in
//!   a binary tree; a query first minimises over the chunk of a hint parameter (e.g. the
//!   previous foot or the interpolator's parameter), then branch-and-bound visits only
//!   chunks whose box is nearer than the best distance so far. The hint only speeds the
//!   search up: the result is the global minimum whatever the hint.
//!
//! Lines and arcs are solved analytically (the finite segment/arc: beyond its ends the
//! nearest end point is the foot).

use serde::{Deserialize, Serialize};

use crate::contour::ContourEstimate;
use crate::geometry::{self, Vector, Vector2};
use crate::path::program::Shape;
use crate::path::{CircularArc, Curve, Line, Path, Program};

/// Exact contour error of one point.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct TrueError<const D: usize = 2> {
    /// Distance to the path, mm; for a planar [`Path`] signed, positive right of travel
    /// (a path type without sides, e.g. a spatial line, reports the distance).
    pub error: f64,
    /// Unit direction with `error · normal` from the point to the foot point (in the
    /// plane: the path's left unit normal there).
    pub normal: Vector<D>,
    /// Curve parameter of the foot point.
    pub u: f64,
    /// Foot point (nearest point of the path).
    pub foot: Vector<D>,
}

impl<const D: usize> TrueError<D> {
    /// As an estimator result.
    pub fn estimate(&self) -> ContourEstimate<D> {
        ContourEstimate {
            error: self.error,
            normal: self.normal,
        }
    }
}

/// Global brute-force true contour error of `p` against `path`.
pub fn true_error(path: &Path, p: Vector2) -> TrueError {
    match path {
        Path::Line(l) => line_true_error(l, p),
        Path::Arc(a) => arc_true_error(a, p),
        Path::Nurbs(n) => curve_true_error(n, p),
        Path::Program(program) => (0..program.moves().len())
            .map(|i| move_true_error(program, i, p))
            .fold(None, |best: Option<TrueError>, e| match best {
                Some(b) if b.error.abs() <= e.error.abs() => Some(b),
                _ => Some(e),
            })
            .expect("a program has a move"),
    }
}

/// Exact distance to move `i` of a program, its foot parameter the path position s.
/// Where the foot is a corner's vertex (the move's end, shared with the next move, or
/// its start, shared with the one before; on a closed program also the start and the end)
/// the point is as far from both moves, and the side is judged against the bisector of
/// the two tangents: against either one alone, a point beyond a corner that turns by
/// more than 90° would be on the wrong side.
fn move_true_error(program: &Program, i: usize, p: Vector2) -> TrueError {
    let moves = program.moves();
    let mut e = match &moves[i].shape {
        Shape::Line(l) => line_true_error(l, p),
        Shape::Arc(a) => arc_true_error(a, p),
    };
    let last = moves.len() - 1;
    // Only asked at an end of the first or last move.
    let closed =
        || last > 0 && moves[0].shape.curve().point(0.0) == moves[last].shape.curve().point(1.0);
    let neighbour = match e.u {
        u if u == 1.0 && i < last => Some((i, i + 1)),
        u if u == 1.0 && closed() => Some((i, 0)),
        u if u == 0.0 && i > 0 => Some((i - 1, i)),
        u if u == 0.0 && closed() => Some((last, i)),
        _ => None,
    };
    if let Some((before, after)) = neighbour {
        let tangent = |j: usize, u: f64| {
            let d = moves[j].shape.curve().eval(u).d1;
            d * (1.0 / geometry::norm(&d))
        };
        let bisector = tangent(before, 1.0) + tangent(after, 0.0);
        let length = geometry::norm(&bisector);
        // A reversal has no bisector: the move's own side stands.
        if length > 1e-9 {
            let signed_here = signed(p, e.foot, bisector * (1.0 / length), e.u);
            e.error = signed_here.error;
            e.normal = signed_here.normal;
        }
    }
    e.u = program.position(i, e.u);
    e
}

/// The box of move `i` of a program: its end points, and on an arc the extreme points
/// of its circle that the sweep passes.
fn move_box(program: &Program, i: usize) -> BBox {
    let point = |q: Vector2| [q[0], q[1], q[0], q[1]];
    match &program.moves()[i].shape {
        Shape::Line(l) => union(&point(l.start()), &point(l.end())),
        Shape::Arc(a) => {
            let mut b = union(&point(a.point(0.0)), &point(a.point(1.0)));
            for k in 0..4 {
                let phi = k as f64 * std::f64::consts::FRAC_PI_2;
                if a.param_of_angle(phi).is_some() {
                    let (s, c) = phi.sin_cos();
                    b = union(&b, &point(a.center() + Vector2::new(c, s) * a.radius()));
                }
            }
            // Rounding in the extreme points' sines: a nanometre of margin.
            let m = 1e-9 * (1.0 + a.radius());
            [b[0] - m, b[1] - m, b[2] + m, b[3] + m]
        }
    }
}

/// Samples per smooth piece in the brute force.
const BRUTE_SAMPLES: usize = 256;

/// Global brute force for any [`Curve`]: dense sampling + Newton refinement.
pub fn curve_true_error<C: Curve + ?Sized>(c: &C, p: Vector2) -> TrueError {
    let bps = c.breakpoints();
    // Dense samples (parameter, distance) over every smooth piece.
    let mut us = Vec::with_capacity(bps.len() * BRUTE_SAMPLES);
    for w in bps.windows(2) {
        for i in 0..BRUTE_SAMPLES {
            us.push(w[0] + (w[1] - w[0]) * i as f64 / BRUTE_SAMPLES as f64);
        }
    }
    us.push(*bps.last().unwrap_or(&c.param_range().1));
    let pts: Vec<Vector2> = us.iter().map(|&u| c.point(u)).collect();
    let ds: Vec<f64> = pts.iter().map(|&q| geometry::dist(&q, &p)).collect();
    let max_chord = pts
        .windows(2)
        .map(|w| geometry::dist(&w[0], &w[1]))
        .fold(0.0, f64::max);
    let dmin = ds.iter().cloned().fold(f64::INFINITY, f64::min);
    let n = us.len();
    let mut best = (f64::INFINITY, us[0]);
    for i in 0..n {
        let lower = i == 0 || ds[i] <= ds[i - 1];
        let upper = i + 1 == n || ds[i] <= ds[i + 1];
        // A true minimum inside a sample bracket is at most one chord below the samples.
        if lower && upper && ds[i] <= dmin + max_chord {
            let a = us[i.saturating_sub(1)];
            let b = us[(i + 1).min(n - 1)];
            let r = refine(c, p, a, b, us[i]);
            if r.0 < best.0 {
                best = r;
            }
        }
    }
    finish(c, p, best.1)
}

/// Minimises |C(u) − P| over [a, b] starting from `u`: safeguarded Newton on
/// f(u) = (C − P)·C' with bisection fallback; also compares the bracket ends.
/// Returns (distance, parameter).
fn refine<C: Curve + ?Sized>(c: &C, p: Vector2, a0: f64, b0: f64, u0: f64) -> (f64, f64) {
    let (mut a, mut b, mut u) = (a0, b0, u0);
    for _ in 0..64 {
        let e = c.eval(u);
        let q = e.p - p;
        let f = q.dot(&e.d1);
        if f == 0.0 {
            break;
        }
        let fp = e.d1.dot(&e.d1) + q.dot(&e.d2);
        if f > 0.0 {
            b = u;
        } else {
            a = u;
        }
        let mut un = if fp > 0.0 { u - f / fp } else { f64::NAN };
        if !(un >= a && un <= b) {
            un = 0.5 * (a + b);
        }
        let tol = 1e-15 * (1.0 + u.abs());
        let step = (un - u).abs();
        u = un;
        if step <= tol || b - a <= tol {
            break;
        }
    }
    let mut best = (geometry::dist(&c.point(u), &p), u);
    for v in [a0, b0] {
        let d = geometry::dist(&c.point(v), &p);
        if d < best.0 {
            best = (d, v);
        }
    }
    best
}

/// Builds the result at foot parameter `u`.
fn finish<C: Curve + ?Sized>(c: &C, p: Vector2, u: f64) -> TrueError {
    let e = c.eval(u);
    let mut t = e.d1;
    if geometry::norm(&t) < 1e-12 {
        // Degenerate speed (repeated control points): use a short secant instead.
        let (lo, hi) = c.param_range();
        let h = 1e-7 * (hi - lo);
        t = c.point((u + h).min(hi)) - c.point((u - h).max(lo));
    }
    let tl = geometry::norm(&t);
    let t = if tl > 0.0 {
        t * (1.0 / tl)
    } else {
        Vector2::new(1.0, 0.0)
    };
    signed(p, e.p, t, u)
}

fn signed(p: Vector2, foot: Vector2, t: Vector2, u: f64) -> TrueError {
    let q = p - foot;
    let dist = geometry::norm(&q);
    let side = -geometry::cross(&t, &q);
    TrueError {
        error: dist.copysign(side),
        normal: geometry::perp(&t),
        u,
        foot,
    }
}

/// Exact distance to a finite segment.
fn line_true_error(l: &Line, p: Vector2) -> TrueError {
    let u = l.nearest_parameter(&p);
    signed(p, l.point(u), l.direction(), u)
}

/// Exact distance to a finite arc.
fn arc_true_error(arc: &CircularArc, p: Vector2) -> TrueError {
    let o = arc.center();
    let d = p - o;
    let r = geometry::norm(&d);
    let within = if r > 0.0 {
        arc.param_of_angle(d[1].atan2(d[0]))
    } else {
        Some(0.0)
    };
    let u = match within {
        Some(u) => u,
        None => {
            if geometry::dist(&arc.point(0.0), &p) <= geometry::dist(&arc.point(1.0), &p) {
                0.0
            } else {
                1.0
            }
        }
    };
    let e = arc.eval(u);
    let t = e.d1 * (1.0 / geometry::norm(&e.d1));
    let mut res = signed(p, e.p, t, u);
    if within.is_some() {
        // Radial formula: exact sign even at the centre (where q ∥ n gives side 0 issues).
        let err = if arc.is_ccw() {
            r - arc.radius()
        } else {
            arc.radius() - r
        };
        res.error = err;
    }
    res
}

/// One chunk of the path: a parameter interval with a conservative bounding box.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Chunk {
    u0: f64,
    u1: f64,
}

/// Axis-aligned box [xmin, ymin, xmax, ymax]; empty when xmin > xmax.
type BBox = [f64; 4];

const EMPTY: BBox = [
    f64::INFINITY,
    f64::INFINITY,
    f64::NEG_INFINITY,
    f64::NEG_INFINITY,
];

fn box_dist2(b: &BBox, p: Vector2) -> f64 {
    if b[0] > b[2] {
        return f64::INFINITY;
    }
    let dx = (b[0] - p[0]).max(0.0).max(p[0] - b[2]);
    let dy = (b[1] - p[1]).max(0.0).max(p[1] - b[3]);
    dx * dx + dy * dy
}

fn union(a: &BBox, b: &BBox) -> BBox {
    [
        a[0].min(b[0]),
        a[1].min(b[1]),
        a[2].max(b[2]),
        a[3].max(b[3]),
    ]
}

/// Target chunk arc length, mm, and turning, rad: short enough that the distance to a
/// point near the path is unimodal along a chunk.
const CHUNK_LEN: f64 = 0.5;
const CHUNK_TURN: f64 = 0.2;
/// Sub-intervals sampled per chunk (box building and the per-chunk search).
const CHUNK_SUB: usize = 4;

/// Exact true contour error with a hint parameter, for closed-loop use (see module docs).
#[derive(Clone, Debug)]
pub struct TrueErrorIndex {
    path: Path,
    chunks: Vec<Chunk>,
    /// Implicit complete binary tree: node i has children 2i, 2i+1; leaves from `leaves`.
    tree: Vec<BBox>,
    leaves: usize,
}

impl TrueErrorIndex {
    /// Preprocesses `path` (allocates once; queries allocate nothing).
    pub fn new(path: &Path) -> Self {
        let mut chunks = Vec::new();
        let mut boxes = Vec::new();
        if let Path::Nurbs(_) = path {
            let bps = path.breakpoints();
            for w in bps.windows(2) {
                let (a, b) = (w[0], w[1]);
                // Length and turning of the piece from a coarse scan.
                const SCAN: usize = 64;
                let mut turn = 0.0;
                let mut prev_t: Option<Vector2> = None;
                for i in 0..=SCAN {
                    let d1 = path.eval(a + (b - a) * i as f64 / SCAN as f64).d1;
                    if let Some(t0) = prev_t {
                        turn += geometry::cross(&t0, &d1).atan2(t0.dot(&d1)).abs();
                    }
                    prev_t = Some(d1);
                }
                let len = path.length_between(a, b);
                let m = ((len / CHUNK_LEN).ceil().max((turn / CHUNK_TURN).ceil()) as usize)
                    .clamp(1, 1 << 20);
                for j in 0..m {
                    let u0 = a + (b - a) * j as f64 / m as f64;
                    let u1 = if j + 1 == m {
                        b
                    } else {
                        a + (b - a) * (j + 1) as f64 / m as f64
                    };
                    chunks.push(Chunk { u0, u1 });
                    boxes.push(chunk_box(path, u0, u1));
                }
            }
        }
        if let Path::Program(program) = path {
            // One chunk a move, solved exactly.
            for i in 0..program.moves().len() {
                chunks.push(Chunk {
                    u0: program.start_of(i),
                    u1: program.start_of(i + 1),
                });
                boxes.push(move_box(program, i));
            }
        }
        let leaves = chunks.len().max(1).next_power_of_two();
        let mut tree = vec![EMPTY; 2 * leaves];
        for (i, b) in boxes.into_iter().enumerate() {
            tree[leaves + i] = b;
        }
        for i in (1..leaves).rev() {
            tree[i] = union(&tree[2 * i], &tree[2 * i + 1]);
        }
        TrueErrorIndex {
            path: path.clone(),
            chunks,
            tree,
            leaves,
        }
    }

    /// The indexed path.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Number of chunks (0 for analytic paths).
    pub fn chunk_count(&self) -> usize {
        self.chunks.len()
    }

    /// Exact true contour error of `p`; `hint` is a parameter near the expected foot
    /// (the previous foot or the reference's parameter). Any hint gives the same result.
    pub fn error(&self, p: Vector2, hint: f64) -> TrueError {
        match &self.path {
            Path::Line(l) => return line_true_error(l, p),
            Path::Arc(a) => return arc_true_error(a, p),
            Path::Nurbs(_) | Path::Program(_) => {}
        }
        let first = self.locate(hint);
        let mut best = self.chunk_min(first, p);
        let mut best_chunk = first;
        let mut best2 = best.0 * best.0;
        // Depth-first branch and bound; a stack of depth ≤ 2·log2(leaves) suffices.
        let mut stack = [0usize; 128];
        let mut top = 1;
        stack[0] = 1;
        while top > 0 {
            top -= 1;
            let node = stack[top];
            // Strictly farther only: a move as near as the best may be an earlier one,
            // which wins the tie whatever the hint.
            if box_dist2(&self.tree[node], p) > best2 {
                continue;
            }
            if node >= self.leaves {
                let i = node - self.leaves;
                if i != first && i < self.chunks.len() {
                    let r = self.chunk_min(i, p);
                    if r.0 < best.0 || r.0 == best.0 && i < best_chunk {
                        best = r;
                        best2 = r.0 * r.0;
                        best_chunk = i;
                    }
                }
            } else if top + 2 <= stack.len() {
                let (l, r) = (2 * node, 2 * node + 1);
                // Push the farther child first so the nearer one is searched first.
                if box_dist2(&self.tree[l], p) <= box_dist2(&self.tree[r], p) {
                    stack[top] = r;
                    stack[top + 1] = l;
                } else {
                    stack[top] = l;
                    stack[top + 1] = r;
                }
                top += 2;
            }
        }
        match &self.path {
            Path::Program(program) => move_true_error(program, best_chunk, p),
            _ => finish(&self.path, p, best.1),
        }
    }

    /// Chunk containing parameter `u` (clamped).
    fn locate(&self, u: f64) -> usize {
        let n = self.chunks.len();
        if u.is_nan() {
            return 0;
        }
        // First chunk whose end is ≥ u.
        self.chunks.partition_point(|c| c.u1 < u).min(n - 1)
    }

    /// Minimum distance over chunk `i`: best of its samples, then Newton in the bracket.
    fn chunk_min(&self, i: usize, p: Vector2) -> (f64, f64) {
        if let Path::Program(program) = &self.path {
            let e = move_true_error(program, i, p);
            return (e.error.abs(), e.u);
        }
        let Chunk { u0, u1 } = self.chunks[i];
        let h = (u1 - u0) / CHUNK_SUB as f64;
        let mut bi = 0;
        let mut bd = f64::INFINITY;
        for k in 0..=CHUNK_SUB {
            let d = geometry::dist2(&self.path.point(u0 + h * k as f64), &p);
            if d < bd {
                bd = d;
                bi = k;
            }
        }
        let a = u0 + h * bi.saturating_sub(1) as f64;
        let b = if bi == CHUNK_SUB {
            u1
        } else {
            u0 + h * (bi + 1) as f64
        };
        refine(&self.path, p, a, b.min(u1), u0 + h * bi as f64)
    }
}

/// Conservative box of the curve over [u0, u1]: box of samples widened by twice the
/// largest sampled |C''|·h²/8 (the bound on a curve's departure from its chords).
fn chunk_box(c: &Path, u0: f64, u1: f64) -> BBox {
    const S: usize = 8;
    let h = (u1 - u0) / S as f64;
    let mut b = EMPTY;
    let mut acc: f64 = 0.0;
    for k in 0..=S {
        let e = c.eval(u0 + h * k as f64);
        b = union(&b, &[e.p[0], e.p[1], e.p[0], e.p[1]]);
        acc = acc.max(geometry::norm(&e.d2));
    }
    let m = 2.0 * acc * h * h / 8.0 + 1e-9;
    [b[0] - m, b[1] - m, b[2] + m, b[3] + m]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::path::builtin;
    use std::f64::consts::PI;

    #[test]
    fn line_and_arc_hand_cases() {
        let l = Path::Line(Line::new(Vector2::new(0.0, 0.0), Vector2::new(4.0, 0.0)).unwrap());
        let r = true_error(&l, Vector2::new(2.0, -1.5));
        assert_eq!((r.error, r.u, r.normal), (1.5, 0.5, Vector2::new(0.0, 1.0)));
        // Beyond the end: distance to the end point, sign by side.
        let r = true_error(&l, Vector2::new(7.0, 4.0));
        assert_eq!((r.error, r.u), (-5.0, 1.0));
        let a = Path::Arc(CircularArc::new(Vector2::new(0.0, 0.0), 2.0, 0.0, PI / 2.0).unwrap());
        let r = true_error(&a, Vector2::new(0.0, 3.0));
        assert!((r.error - 1.0).abs() < 1e-15 && (r.u - 1.0).abs() < 1e-15);
        // Beyond the arc end (angle 3π/4): nearest is the end point (0, 2).
        let r = true_error(&a, Vector2::new(-1.0, 1.0));
        assert!((r.error.abs() - 2f64.sqrt()).abs() < 1e-15 && r.u == 1.0);
        // At the centre: −r for CCW.
        let r = true_error(&a, Vector2::new(0.0, 0.0));
        assert_eq!(r.error, -2.0);
        let cw =
            Path::Arc(CircularArc::new(Vector2::new(0.0, 0.0), 2.0, PI / 2.0, -PI / 2.0).unwrap());
        let r = true_error(&cw, Vector2::new(0.3, 0.4));
        assert!((r.error - 1.5).abs() < 1e-15);
    }

    #[test]
    fn nurbs_brute_force_on_exact_circle() {
        let c = Path::Nurbs(builtin::rational_unit_circle());
        for k in 0..50 {
            let ang = 0.123 + k as f64 * 0.1257;
            let rad = 0.2 + 0.05 * k as f64;
            let r = true_error(&c, Vector2::new(rad * ang.cos(), rad * ang.sin()));
            assert!((r.error - (rad - 1.0)).abs() < 1e-13, "k={k}: {}", r.error);
            assert!((r.normal[0] + ang.cos()).abs() < 1e-9);
        }
    }

    #[test]
    fn index_equals_brute_force_for_any_hint() {
        for name in ["infinity", "trident"] {
            let path = builtin::by_name(name).unwrap();
            let idx = TrueErrorIndex::new(&path);
            assert!(idx.chunk_count() > 400);
            let mut s: u64 = 0x9e37_79b9_7f4a_7c15;
            let mut rnd = || {
                s ^= s << 13;
                s ^= s >> 7;
                s ^= s << 17;
                (s >> 11) as f64 / (1u64 << 53) as f64
            };
            for _ in 0..200 {
                let u = rnd();
                let e = path.eval(u);
                let n = geometry::perp(&(e.d1 * (1.0 / geometry::norm(&e.d1))));
                let off = (rnd() - 0.5) * if rnd() < 0.8 { 0.4 } else { 20.0 };
                let p = e.p + n * off;
                let g = true_error(&path, p);
                for hint in [u, rnd(), 0.0] {
                    let h = idx.error(p, hint);
                    assert!((h.error - g.error).abs() < 1e-12, "{name}: {h:?} vs {g:?}");
                }
            }
        }
    }
}
