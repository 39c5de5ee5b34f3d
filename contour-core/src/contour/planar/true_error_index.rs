//! The true contour error in O(1)-ish time for closed-loop use (the PSO fitness, the
//! evaluation of long runs): the path is cut once into short chunks with conservative
//! bounding boxes in a binary tree; a query first minimises over the chunk of a hint
//! parameter (the previous foot or the interpolator's parameter), then branch-and-bound
//! visits only chunks whose box is nearer than the best distance so far. The hint only
//! speeds the search up: the result is the global minimum of [`true_error`]'s exact
//! distances whatever the hint.

use std::ops::Range;

use super::true_error::{
    arc_error_within, arc_true_error, at_kink, finish, line_error_within, line_true_error,
    move_true_error, refine, signed, Span, TrueError, WHOLE,
};
use crate::geometry::{self, Vector2};
use crate::math;
use crate::path::planar::{Path, Shape};
use crate::path::{CircularArc, Curve, Line};

/// The box of a segment: its end points.
fn line_box(l: &Line) -> BBox {
    union(&point_box(l.start()), &point_box(l.end()))
}

/// The box of an arc: its end points and the extreme points of its circle that the
/// sweep passes.
fn arc_box(a: &CircularArc) -> BBox {
    let mut b = union(&point_box(a.point(0.0)), &point_box(a.point(1.0)));
    for k in 0..4 {
        let phi = k as f64 * std::f64::consts::FRAC_PI_2;
        if a.param_of_angle(phi).is_some() {
            let (s, c) = math::sincos(phi);
            b = union(&b, &point_box(a.center() + Vector2::new(c, s) * a.radius()));
        }
    }
    // Rounding in the extreme points' sines: a nanometre of margin.
    let m = 1e-9 * (1.0 + a.radius());
    [b[0] - m, b[1] - m, b[2] + m, b[3] + m]
}

fn point_box(q: Vector2) -> BBox {
    [q[0], q[1], q[0], q[1]]
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
/// A stretch of at most this many chunks is searched box by box, not through the tree.
const SCAN_CHUNKS: usize = 16;

/// Exact true contour error with a hint parameter, for closed-loop use (see module docs).
#[derive(Clone, Debug)]
pub struct TrueErrorIndex {
    path: Path,
    chunks: Vec<Chunk>,
    /// Arc length from the path's start to the start of every chunk, then the path's
    /// length: `chunks.len() + 1` entries (a program's move starts).
    lengths: Vec<f64>,
    /// Implicit complete binary tree: node i has children 2i, 2i+1; leaves from `leaves`.
    tree: Vec<BBox>,
    leaves: usize,
}

impl TrueErrorIndex {
    /// Preprocesses `path` (allocates once; queries allocate nothing).
    pub fn new(path: &Path) -> Self {
        let mut chunks = Vec::new();
        let mut boxes = Vec::new();
        let mut lengths = vec![0.0];
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
                        turn += math::atan2(geometry::cross(&t0, &d1), t0.dot(&d1)).abs();
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
                    let before = lengths[lengths.len() - 1];
                    lengths.push(before + path.length_between(u0, u1));
                }
            }
        }
        if let Path::Line(_) | Path::Arc(_) = path {
            // One chunk, solved exactly.
            let (u0, u1) = path.param_range();
            chunks.push(Chunk { u0, u1 });
            boxes.push(match path {
                Path::Line(l) => line_box(l),
                Path::Arc(a) => arc_box(a),
                _ => unreachable!("a line or an arc"),
            });
            lengths.push(path.length());
        }
        if let Path::Program(program) = path {
            // One chunk a move, solved exactly.
            for i in 0..program.moves().len() {
                chunks.push(Chunk {
                    u0: program.start_of(i),
                    u1: program.start_of(i + 1),
                });
                boxes.push(match &program.moves()[i].shape {
                    Shape::Line(l) => line_box(l),
                    Shape::Arc(a) => arc_box(a),
                    Shape::Blend(b) => {
                        let [a, v, c] = b.hull();
                        let h = union(&union(&point_box(a), &point_box(v)), &point_box(c));
                        // Rounding in the Fresnel sums: a nanometre of margin.
                        let m = 1e-9 * (1.0 + v.amax());
                        [h[0] - m, h[1] - m, h[2] + m, h[3] + m]
                    }
                });
                lengths.push(program.start_of(i + 1));
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
            lengths,
            tree,
            leaves,
        }
    }

    /// The indexed path.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Number of chunks (1 for a line or an arc).
    pub fn chunk_count(&self) -> usize {
        self.chunks.len()
    }

    /// Exact true contour error of `p`; `hint` is a parameter near the expected foot
    /// (the previous foot or the reference's parameter). Any hint gives the same result.
    pub fn error(&self, p: Vector2, hint: f64) -> TrueError {
        match &self.path {
            Path::Line(l) => line_true_error(l, p),
            Path::Arc(a) => arc_true_error(a, p),
            Path::Nurbs(_) | Path::Program(_) => {
                let any = (f64::NEG_INFINITY, f64::INFINITY);
                self.error_between(p, self.locate(hint), f64::NAN, any.0, any.1)
                    .1
            }
        }
    }

    /// The exact distance from `p` to the stretch of the path between the arc lengths
    /// `from` and `to` (clamped to the path), with the chunk of the foot. `hint` is a
    /// chunk near the foot, `guess` an arc length near it (NaN for none): the search
    /// starts at the chunk that holds the guess, else at the hint, and on a blend Newton
    /// may start at the guess. Any hint and guess give the same result, to the last bits
    /// of Newton's convergence; equal distances go to the earlier chunk.
    pub fn error_between(
        &self,
        p: Vector2,
        hint: usize,
        guess: f64,
        from: f64,
        to: f64,
    ) -> (usize, TrueError) {
        let chunks = self.chunks_between(from, to);
        let near = if guess.is_finite() {
            self.chunk_at(guess, hint)
        } else {
            hint
        };
        let first = near.clamp(chunks.start, chunks.end - 1);
        let chunk_min = |i: usize| self.chunk_min(i, p, from, to, guess);
        let mut best = Nearest::new(first, chunk_min(first));
        // A short stretch (a window along the path) is scanned box by box: cheaper than
        // descending the tree to it, and the same chunks pass the same test.
        if chunks.len() <= SCAN_CHUNKS {
            for i in chunks {
                if i != first && box_dist2(&self.tree[self.leaves + i], p) <= best.bound2 {
                    best.offer(i, chunk_min(i));
                }
            }
            return (best.chunk, self.result(best.found, p));
        }
        // Bottom up from the hint's leaf: the sibling of each of its ancestors in turn
        // (each searched top down), so a tool near the hint's chunk costs a box a level
        // rather than a descent from the root to it.
        let mut ancestor = self.leaves + first;
        let mut pending = Pending::root();
        while ancestor > 1 {
            pending.restart(ancestor ^ 1);
            ancestor /= 2;
            while let Some(node) = pending.pop() {
                let leaves = self.leaves_of(node);
                // Strictly farther only: a move as near as the best may be an earlier
                // one, which wins the tie whatever the hint.
                if leaves.end <= chunks.start
                    || leaves.start >= chunks.end
                    || box_dist2(&self.tree[node], p) > best.bound2
                {
                    continue;
                }
                if node >= self.leaves {
                    let i = node - self.leaves;
                    best.offer(i, chunk_min(i));
                } else {
                    let (l, r) = (2 * node, 2 * node + 1);
                    // The nearer child is searched first.
                    if box_dist2(&self.tree[l], p) <= box_dist2(&self.tree[r], p) {
                        pending.push(r, l);
                    } else {
                        pending.push(l, r);
                    }
                }
            }
        }
        (best.chunk, self.result(best.found, p))
    }

    /// The first place at or after the arc length `from`, in path order, where the path
    /// passes within `tolerance` of `p`: the chunk and the exact distance there; `None`
    /// when there is none. Left-first branch and bound: O(log n) boxes plus the chunks
    /// that pass near `p`.
    pub fn first_within(
        &self,
        p: Vector2,
        from: f64,
        tolerance: f64,
    ) -> Option<(usize, TrueError)> {
        self.first_within_near(p, from, 0, f64::NAN, tolerance)
    }

    /// [`TrueErrorIndex::first_within`] for a point that moves on along the path (the
    /// reference), whose place can be guessed (`hint`, a chunk near `from`; the arc
    /// length `guess`): on a blend that
    /// holds the guess, a Newton step from there instead of a search from samples (see
    /// `near_guess`): the same chunk as first_within's, a foot within `tolerance` of the
    /// point (within nanometres of first_within's at ordinary feeds), wherever it finds the point within `tolerance` inside the blend; otherwise
    /// first_within's search of that chunk.
    pub fn first_within_near(
        &self,
        p: Vector2,
        from: f64,
        hint: usize,
        guess: f64,
        tolerance: f64,
    ) -> Option<(usize, TrueError)> {
        let start = self.chunk_at(from, hint);
        let limit = tolerance * tolerance;
        let chunk_min = |i: usize| {
            self.near_guess(i, p, from, guess, tolerance)
                .unwrap_or_else(|| self.chunk_min(i, p, from, f64::INFINITY, f64::NAN))
        };
        // The first chunk in path order, where a point that moves on along the path (the
        // reference) mostly still is: found there, the tree is not searched.
        if box_dist2(&self.tree[self.leaves + start], p) <= limit {
            let found = chunk_min(start);
            if found.0 <= tolerance {
                return Some((start, self.result(found, p)));
            }
        }
        // Where it has moved on to: the next few chunks in turn, then the tree beyond.
        let scanned = (start + 1 + SCAN_CHUNKS).min(self.chunks.len());
        for i in start + 1..scanned {
            if box_dist2(&self.tree[self.leaves + i], p) > limit {
                continue;
            }
            let found = chunk_min(i);
            if found.0 <= tolerance {
                return Some((i, self.result(found, p)));
            }
        }
        let mut pending = Pending::root();
        while let Some(node) = pending.pop() {
            if self.leaves_of(node).end <= scanned || box_dist2(&self.tree[node], p) > limit {
                continue;
            }
            if node >= self.leaves {
                let i = node - self.leaves;
                let found = self.chunk_min(i, p, from, f64::INFINITY, f64::NAN);
                if found.0 <= tolerance {
                    return Some((i, self.result(found, p)));
                }
            } else {
                // Leaves come off in path order.
                pending.push(2 * node + 1, 2 * node);
            }
        }
        None
    }

    /// The distance from `p` to chunk `i` after the arc length `from` when the chunk is
    /// a blend holding the arc length `guess` and one Newton step from there places `p`
    /// within `tolerance` inside it. For a point on the path (the reference), guessed
    /// from its last two places, the guess is off by its change of step δ and the step
    /// leaves about κ·δ²: 10⁻¹¹ mm at 20 mm/s, 0.02 µm at 200 mm/s on a spiral of short
    /// lines. Only `tolerance` is enforced: the place is within it of the point, and the
    /// distance exact at the place.
    fn near_guess(
        &self,
        i: usize,
        p: Vector2,
        from: f64,
        guess: f64,
        tolerance: f64,
    ) -> Option<ChunkMin> {
        let Path::Program(program) = &self.path else {
            return None;
        };
        let Shape::Blend(b) = &program.moves()[i].shape else {
            return None;
        };
        let (a, end) = (self.lengths[i], self.lengths[i + 1]);
        let (t0, t1) = self.move_span(i, from, f64::INFINITY);
        let u = (guess - a) / (end - a);
        if !(t0 < u && u < t1) {
            return None;
        }
        let at = b.eval(u);
        let foot = u + (p - at.p).dot(&at.d1) / at.d1.dot(&at.d1);
        if !(t0 < foot && foot < t1) {
            return None;
        }
        let q = b.point(foot);
        let d = geometry::dist(&q, &p);
        if d > tolerance {
            return None;
        }
        // Signed against the guess's tangent: the place is what the caller uses.
        let mut e = signed(p, q, at.d1 * (1.0 / (end - a)), foot);
        e.u = program.position(i, foot);
        Some((d, e.u, Some(e)))
    }

    /// Arc length from the path's start to parameter `u` of chunk `i` (within the chunk
    /// by its share of the parameter: exact on a program, a line and an arc).
    pub fn length_at(&self, i: usize, u: f64) -> f64 {
        let Chunk { u0, u1 } = self.chunks[i];
        let (a, b) = (self.lengths[i], self.lengths[i + 1]);
        let share = if u1 > u0 {
            ((u - u0) / (u1 - u0)).clamp(0.0, 1.0)
        } else {
            0.0
        };
        a + share * (b - a)
    }

    /// Chunk `i` is a full circle: its start point is also its end.
    pub fn is_closed(&self, i: usize) -> bool {
        let arc = match &self.path {
            Path::Arc(a) => a,
            Path::Program(program) => match &program.moves()[i].shape {
                Shape::Arc(a) => a,
                _ => return false,
            },
            _ => return false,
        };
        arc.is_full_circle()
    }

    /// Arc lengths to the start and the end of chunk `i`, with the points there.
    pub fn chunk_ends(&self, i: usize) -> [(f64, Vector2); 2] {
        let c = self.chunks[i];
        [
            (self.lengths[i], self.path.point(c.u0)),
            (self.lengths[i + 1], self.path.point(c.u1)),
        ]
    }

    /// The first chunk that ends at or after the arc length `s` (the last when none does),
    /// sought outward from chunk `hint`: galloping, O(log distance) rather than
    /// O(log chunks) when the hint is near.
    fn chunk_at(&self, s: f64, hint: usize) -> usize {
        let ends = &self.lengths[1..];
        let n = ends.len();
        if s.is_nan() {
            return 0;
        }
        let hint = hint.min(n - 1);
        // The answer lies in lo..=hi: widen by doubling steps from the hint.
        let (mut lo, mut hi) = (hint, hint);
        let mut step = 1;
        if ends[hint] < s {
            while hi < n - 1 && ends[hi] < s {
                lo = hi + 1;
                hi = (hi + step).min(n - 1);
                step *= 2;
            }
        } else {
            while lo > 0 && ends[lo - 1] >= s {
                hi = lo - 1;
                lo = lo.saturating_sub(step);
                step *= 2;
            }
        }
        lo + ends[lo..hi].partition_point(|&end| end < s)
    }

    /// The chunks that cover the arc lengths `from` … `to` (at least one).
    fn chunks_between(&self, from: f64, to: f64) -> Range<usize> {
        let n = self.chunks.len();
        // The first chunk that ends at or after `from`, through the last that starts at
        // or before `to`.
        let first = self.lengths[1..]
            .partition_point(|&end| end < from)
            .min(n - 1);
        let end = self.lengths[..n].partition_point(|&start| start <= to);
        first..end.clamp(first + 1, n)
    }

    /// Chunk `i`'s parameters that lie between the arc lengths `from` and `to` (the
    /// whole chunk when it lies inside; its nearer end when outside).
    fn span(&self, i: usize, from: f64, to: f64) -> Span {
        let Chunk { u0, u1 } = self.chunks[i];
        let (a, b) = (self.lengths[i], self.lengths[i + 1]);
        let at = |s: f64| {
            if s <= a || b <= a {
                u0
            } else if s >= b {
                u1
            } else {
                u0 + (s - a) / (b - a) * (u1 - u0)
            }
        };
        (at(from), at(to).max(at(from)))
    }

    /// The leaves (chunk indices) under tree node `node`.
    fn leaves_of(&self, node: usize) -> Range<usize> {
        let level = usize::BITS - 1 - node.leading_zeros();
        let span = self.leaves >> level;
        let first = node * span - self.leaves;
        first..first + span
    }

    /// The signed result of what [`TrueErrorIndex::chunk_min`] found (a NURBS foot is
    /// signed only for the winner).
    fn result(&self, found: ChunkMin, p: Vector2) -> TrueError {
        match found.2 {
            Some(e) => e,
            None => match &self.path {
                Path::Nurbs(n) => at_kink(n, p, finish(n, p, found.1)),
                _ => finish(&self.path, p, found.1),
            },
        }
    }

    /// The move's own parameters (0 … 1) between the arc lengths `from` and `to`.
    fn move_span(&self, i: usize, from: f64, to: f64) -> Span {
        let (a, b) = self.span(i, from, to);
        let Chunk { u0, u1 } = self.chunks[i];
        // A move that rounding left without length: all of it.
        if u1 <= u0 {
            return WHOLE;
        }
        ((a - u0) / (u1 - u0), (b - u0) / (u1 - u0))
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

    /// Minimum distance over chunk `i` between the arc lengths `from` and `to`, and its
    /// parameter: exact on a move, a line or an arc; on a NURBS the best of the chunk's
    /// samples, then Newton in the bracket.
    fn chunk_min(&self, i: usize, p: Vector2, from: f64, to: f64, guess: f64) -> ChunkMin {
        let e = match &self.path {
            Path::Program(program) => {
                let (a, b) = (self.lengths[i], self.lengths[i + 1]);
                let local = (guess - a) / (b - a);
                move_true_error(program, i, p, self.move_span(i, from, to), local)
            }
            Path::Line(l) => line_error_within(l, p, self.span(i, from, to)),
            Path::Arc(a) => arc_error_within(a, p, self.span(i, from, to)),
            Path::Nurbs(_) => {
                let (u0, u1) = self.span(i, from, to);
                let (d, u) = self.curve_min(p, u0, u1);
                return (d, u, None);
            }
        };
        (e.error.abs(), e.u, Some(e))
    }

    /// Minimum distance over the NURBS parameters [u0, u1] (within one chunk).
    fn curve_min(&self, p: Vector2, u0: f64, u1: f64) -> (f64, f64) {
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
        // Not from the chunk's end, which may be a knot (see `refine`).
        let start = if bi == CHUNK_SUB {
            0.5 * (a + u1)
        } else {
            u0 + h * bi as f64
        };
        refine(&self.path, p, a, b.min(u1), start)
    }
}

/// What a chunk's search found: the distance, the foot's parameter and, where it is
/// solved exactly (a move, a line, an arc), the signed result.
type ChunkMin = (f64, f64, Option<TrueError>);

/// The nearest chunk a search has found so far.
struct Nearest {
    chunk: usize,
    found: ChunkMin,
    /// The squared distance a box must not exceed to be searched: the best's, with a
    /// margin (a box's exact squared distance can exceed the square of a tie's rounded
    /// distance, and a tie must be evaluated: the earlier chunk wins it).
    bound2: f64,
}

impl Nearest {
    fn new(chunk: usize, found: ChunkMin) -> Self {
        Nearest {
            chunk,
            found,
            bound2: found.0 * found.0 * (1.0 + 1e-12),
        }
    }

    /// Takes chunk `i`'s result if it is nearer, or as near and earlier.
    fn offer(&mut self, i: usize, found: ChunkMin) {
        if found.0 < self.found.0 || found.0 == self.found.0 && i < self.chunk {
            *self = Nearest::new(i, found);
        }
    }
}

/// The tree nodes still to visit, depth first: a stack of depth ≤ 2·log2(leaves) fits
/// (a path of up to 2⁶³ chunks), so nothing is allocated.
struct Pending {
    nodes: [usize; 128],
    top: usize,
}

impl Pending {
    /// The root alone.
    fn root() -> Self {
        let mut nodes = [0; 128];
        nodes[0] = 1;
        Pending { nodes, top: 1 }
    }

    /// `node` alone, the stack reused.
    fn restart(&mut self, node: usize) {
        self.nodes[0] = node;
        self.top = 1;
    }

    fn pop(&mut self) -> Option<usize> {
        self.top = self.top.checked_sub(1)?;
        Some(self.nodes[self.top])
    }

    /// Pushes two nodes, `first` to be visited first.
    fn push(&mut self, second: usize, first: usize) {
        if self.top + 2 <= self.nodes.len() {
            self.nodes[self.top] = second;
            self.nodes[self.top + 1] = first;
            self.top += 2;
        }
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
    use crate::contour::planar::true_error;
    use crate::path::planar::builtin;

    #[test]
    fn a_chunk_is_found_from_any_hint() {
        let program = Path::Program(
            crate::path::planar::Program::parse_gcode(
                "G1 X1 F600\nX3\nX3.5\nX7\nX7.25\nX9\nX10\n",
                "steps.ngc",
            )
            .unwrap(),
        );
        let index = TrueErrorIndex::new(&program);
        let n = index.chunk_count();
        for s in [
            -1.0, 0.0, 0.5, 1.0, 1.5, 3.0, 3.2, 7.0, 7.1, 9.99, 10.0, 11.0,
        ] {
            let want = index.lengths[1..]
                .partition_point(|&end| end < s)
                .min(n - 1);
            for hint in 0..n + 2 {
                assert_eq!(index.chunk_at(s, hint), want, "{s} from {hint}");
            }
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
