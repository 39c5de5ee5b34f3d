//! The joints along a five-axis path, chosen over the whole path (docs/design/five-axis.md
//! §5.3b). Every tool axis off the C axis has two joint solutions, (A, C) and (−A, C + π);
//! along a stretch that stays off the pole one branch must be kept (switching means
//! swinging the tool through vertical), so the choice is made where the path comes near
//! the pole: inside a cone about the C axis, where C hardly turns the tool, C's turn is
//! planned instead of followed, and the tool axis may leave the programmed one by at most
//! half the orientation tolerance (the rest is the jerk filter's). A dynamic programme
//! over the stretches picks the branch and the turn of C that keep the travel with the
//! least rotary motion.
//!
//! Inside the cone, with the programmed axis at tilt φ and azimuth γ, the closest axis
//! with the table at C has A = atan2(sin φ·cos(γ − C), cos φ) and deviates by
//! asin(sin φ·|sin(γ − C)|): within a tolerance ε wherever |sin(γ − C)| ≤ sin ε / sin φ,
//! a band about γ (and about γ + π, with A < 0) that covers every C once φ ≤ ε. C is
//! interpolated in s from where it enters the cone to where it leaves and clamped into
//! the band it occupies, so it turns where the band lets it.

use super::programmed_feed::{feed_of_move, FeedChange};
use crate::geometry::{self, slerp, Vector};
use crate::kinematics::{axis_angles, unwrap_near, Joints, Pose, TableTiltingAc};
use crate::limits::{JointLimits, PathLimits};
use crate::math;
use crate::path::PathError;

use std::f64::consts::PI;

/// Nodes at most this much apart in tool-axis angle outside the cone (rad)…
const AXIS_STEP: f64 = 5e-3;
/// …and in C (rad), so that joints interpolated linearly between nodes stay on the path.
const C_STEP: f64 = 2e-2;
/// The most nodes a path may have (the planner's memory: about 150 bytes each, 1.3 GB at
/// the budget; a 100 000-point CL raster of 25 m has 630 000).
pub const NODE_BUDGET: usize = 1 << 23;
/// The length along s a tool turning on the spot moves per radian of its turn, mm: far
/// below any tip move a CAM system writes, so only such turns see it.
const TURN_LENGTH: f64 = 1e-3;
/// The share of its band C is held in near the pole (see `through_cone`).
const BAND_SHARE: f64 = 0.9;
/// Rounds of refinement inside the cones before the plan gives up.
const REFINE_ROUNDS: usize = 24;

/// The joints at the nodes of a path, with the programmed poses they stand for.
#[derive(Clone, Debug, PartialEq)]
pub struct JointPath {
    /// Arc length of the programmed tip path at each node, mm.
    pub s: Vec<f64>,
    /// The planned joints at each node.
    pub joints: Vec<Joints>,
    /// The programmed pose at each node.
    pub poses: Vec<Pose>,
    /// Where each node lies among the programmed poses: pose i at i, fractions between.
    pub source: Vec<f64>,
    /// Angle between the planned and the programmed tool axis at each node, rad.
    pub deviation: Vec<f64>,
    /// The programmed speed of the piece from each node to the next (the last node: its
    /// piece before), mm/s.
    pub feed: Vec<f64>,
}

/// One node's programmed pose with its place and angles.
#[derive(Clone, Copy, Debug)]
struct Node {
    pose: Pose,
    source: f64,
    s: f64,
    /// Tilt of the programmed axis from the C axis (A on the A ≥ 0 branch).
    tilt: f64,
    /// Its azimuth (C on that branch), in (−π, π].
    azimuth: f64,
}

/// The poses between programmed poses `i` and `i + 1`, `pieces` of them, the first
/// excluded: tips straight, axes slerped.
fn subdivide(a: &Pose, b: &Pose, pieces: usize) -> impl Iterator<Item = (f64, Pose)> {
    let (a, b) = (*a, *b);
    (1..=pieces).map(move |k| {
        let t = k as f64 / pieces as f64;
        let axis = if k == pieces {
            b.axis
        } else {
            slerp(&a.axis, &b.axis, t).unwrap_or(a.axis)
        };
        let tip = if k == pieces {
            b.tip
        } else {
            a.tip + (b.tip - a.tip) * t
        };
        (t, Pose { tip, axis })
    })
}

/// The wrapped difference b − a, in (−π, π].
fn wrapped(b: f64, a: f64) -> f64 {
    unwrap_near(b, a) - a
}

/// How far a pose the plan skips may lie from the chord that replaces it: a hundredth of
/// the tolerances (and never more than 0.1 µm, 1 µrad).
fn skip_limits(path: &PathLimits) -> (f64, f64) {
    (
        (path.tolerance / 100.0).min(1e-4),
        (path.orientation_tolerance / 100.0).min(1e-6),
    )
}

/// The programmed poses the plan keeps: all of them where they are sparser than
/// `spacing`; where they are denser (a sampled curve, a CL file at microns), only those
/// the straight move between their neighbours would leave by more than `limits` (tip mm,
/// axis rad): planning time then follows the path's length, not its point count.
/// A pose in `breaks` (where the programmed speed changes) is always kept.
fn kept(poses: &[Pose], spacing: f64, limits: (f64, f64), breaks: &[usize]) -> Vec<usize> {
    // Whether the straight move from pose a to pose b stands for every pose between.
    let fits = |a: usize, b: usize| {
        let (pa, pb) = (&poses[a], &poses[b]);
        let chord = pb.tip - pa.tip;
        geometry::norm(&chord) <= spacing
            && (a + 1..b).all(|k| {
                let p = &poses[k];
                let t = ((p.tip - pa.tip).dot(&chord) / chord.norm_squared()).clamp(0.0, 1.0);
                // The normalised blend is the slerp to the cube of the angle, and the
                // chord between unit vectors the angle to its cube: no trigonometry in
                // a check that runs k² times per stretch.
                let blend = pa.axis * (1.0 - t) + pb.axis * t;
                geometry::dist2(&(pa.tip + chord * t), &p.tip) <= limits.0 * limits.0
                    && geometry::dist2(&(blend / geometry::norm(&blend)), &p.axis)
                        <= limits.1 * limits.1
            })
    };
    let last = poses.len() - 1;
    let mut out = vec![0];
    let mut anchor = 0;
    while anchor < last {
        let mut end = anchor + 1;
        while end < last && breaks.binary_search(&end).is_err() && fits(anchor, end + 1) {
            end += 1;
        }
        out.push(end);
        anchor = end;
    }
    out
}

/// The nodes: the kept programmed poses, and between them enough that no piece is
/// longer than `spacing` mm or turns the axis (or, off the cone, C) by more than a step;
/// within `fine` rad of the cone, steps of an eighth of the plan's orientation budget.
fn nodes(
    all: &[Pose],
    breaks: &[usize],
    spacing: f64,
    skip: (f64, f64),
    cone: f64,
    fine: f64,
) -> Result<Vec<Node>, PathError> {
    // The pieces the spacing alone asks for, before any is made.
    let length: f64 = all
        .windows(2)
        .map(|w| geometry::dist(&w[0].tip, &w[1].tip))
        .sum();
    let pieces = length / spacing;
    if pieces.is_nan() || pieces > NODE_BUDGET as f64 {
        return Err(PathError::invalid(format!(
            "the path is {length:.6e} mm long: at nodes {spacing} mm apart that is more than \
             the {NODE_BUDGET} planning nodes a path may have"
        )));
    }
    let keep = kept(all, spacing, skip, breaks);
    let poses: Vec<Pose> = keep.iter().map(|&k| all[k]).collect();
    let mut out = Vec::with_capacity(poses.len());
    let node = |pose: Pose, source: f64, s: f64| {
        let (tilt, azimuth) = axis_angles(&pose.axis);
        Node {
            pose,
            source,
            s,
            tilt,
            azimuth,
        }
    };
    out.push(node(poses[0], 0.0, 0.0));
    for (i, w) in poses.windows(2).enumerate() {
        let (a, b) = (&w[0], &w[1]);
        let turn = geometry::angle_between(&a.axis, &b.axis);
        // A pose written twice adds nothing; a tool turning on the spot (a retract's
        // tilt, a CAM system's repeated point) moves along s by its turn at
        // `TURN_LENGTH` mm a radian, so the feed plan has a length to run it on.
        let length = geometry::dist(&a.tip, &b.tip).max(TURN_LENGTH * turn);
        if length == 0.0 {
            continue;
        }
        let (ta, ga) = axis_angles(&a.axis);
        let (tb, gb) = axis_angles(&b.axis);
        let near_pole = ta.min(tb) < cone + turn;
        let mut pieces = (length / spacing).ceil().max(1.0);
        if near_pole {
            pieces = pieces.max((turn / fine).ceil());
        } else {
            pieces = pieces
                .max((turn / AXIS_STEP).ceil())
                .max((wrapped(gb, ga).abs() / C_STEP).ceil());
        }
        if !(pieces.is_finite() && out.len() as f64 + pieces <= NODE_BUDGET as f64) {
            return Err(PathError::invalid(format!(
                "the path needs more than {NODE_BUDGET} planning nodes (at pose {i})"
            )));
        }
        let s0 = out[out.len() - 1].s;
        let (from, to) = (keep[i] as f64, keep[i + 1] as f64);
        for (t, pose) in subdivide(a, b, pieces as usize) {
            out.push(node(pose, from + (to - from) * t, s0 + length * t));
        }
    }
    Ok(out)
}

/// Halves the piece before each node in `at` (indices into `nodes`).
fn refine(nodes: &mut Vec<Node>, at: &[usize]) {
    let mut out = Vec::with_capacity(nodes.len() + at.len());
    let mut marks = at.iter().copied().peekable();
    for (n, node) in nodes.iter().enumerate() {
        while marks.peek().is_some_and(|&m| m < n) {
            marks.next();
        }
        if n > 0 && marks.peek() == Some(&n) {
            let prev: &Node = &nodes[n - 1];
            let (_, mid) = subdivide(&prev.pose, &node.pose, 2).next().unwrap();
            let (tilt, azimuth) = axis_angles(&mid.axis);
            out.push(Node {
                pose: mid,
                source: 0.5 * (prev.source + node.source),
                s: 0.5 * (prev.s + node.s),
                tilt,
                azimuth,
            });
        }
        out.push(*node);
    }
    *nodes = out;
}

/// A run of nodes all inside the cone or all outside it.
#[derive(Clone, Copy, Debug)]
struct Run {
    start: usize,
    end: usize,
    cone: bool,
}

fn runs(nodes: &[Node], cone: f64) -> Vec<Run> {
    let mut out: Vec<Run> = Vec::new();
    for (n, node) in nodes.iter().enumerate() {
        let inside = node.tilt < cone;
        match out.last_mut() {
            Some(run) if run.cone == inside => run.end = n,
            _ => out.push(Run {
                start: n,
                end: n,
                cone: inside,
            }),
        }
    }
    out
}

/// A way through a run off the cone: its branch (A ≥ 0 or A ≤ 0) and C at its start.
#[derive(Clone, Copy, Debug)]
struct State {
    negative: bool,
    c_start: f64,
    cost: f64,
    /// The state of the previous off-cone run it came from.
    from: Option<usize>,
}

/// What went wrong with one way through a cone.
enum ConeFailure {
    /// Outside the travel or off the band: this way is impossible.
    Impossible,
    /// C moves too far between nodes for the joints to be interpolated: the pieces
    /// before these nodes must be halved.
    Refine(Vec<usize>),
}

struct Planner<'a> {
    joints: &'a JointLimits,
    /// The cone's share of the orientation tolerance, rad.
    budget: f64,
    cone: f64,
}

impl Planner<'_> {
    fn a_ok(&self, a: f64) -> bool {
        a >= self.joints.min[3] && a <= self.joints.max[3]
    }

    fn c_ok(&self, c: f64) -> bool {
        c >= self.joints.min[4] && c <= self.joints.max[4]
    }

    /// The C values at the start of an off-cone run near `near`: the nearest turn and
    /// the next ones. The travel may rule the nearest out; and where the azimuth swings
    /// far inside the cone before it, C following it arrives a turn from the nearest.
    fn c_candidates(&self, base: f64, near: f64) -> Vec<f64> {
        let nearest = unwrap_near(base, near);
        vec![nearest, nearest - 2.0 * PI, nearest + 2.0 * PI]
    }

    /// Whether a run off the cone can be driven on this branch from `c_start`: the first
    /// node that cannot, if any.
    fn off_cone_violation(
        &self,
        nodes: &[Node],
        run: Run,
        negative: bool,
        c_start: f64,
    ) -> Option<usize> {
        let mut c = c_start;
        let mut previous = nodes[run.start].azimuth;
        for (n, node) in nodes.iter().enumerate().take(run.end + 1).skip(run.start) {
            c += wrapped(node.azimuth, previous);
            previous = node.azimuth;
            let a = if negative { -node.tilt } else { node.tilt };
            if !(self.a_ok(a) && self.c_ok(c)) {
                return Some(n);
            }
        }
        None
    }

    /// The rotary joints of an off-cone run from `c_start`.
    fn off_cone(&self, nodes: &[Node], run: Run, negative: bool, c_start: f64) -> Vec<(f64, f64)> {
        let mut c = c_start;
        let mut previous = nodes[run.start].azimuth;
        (run.start..=run.end)
            .map(|n| {
                let node = &nodes[n];
                c += wrapped(node.azimuth, previous);
                previous = node.azimuth;
                (if negative { -node.tilt } else { node.tilt }, c)
            })
            .collect()
    }

    /// C's turn through a cone run, from `c_in` at the node before it to `c_out` at the
    /// node after it (either missing at a path end): the rotary joints at its nodes and
    /// the rotary motion they cost.
    ///
    /// Where the programmed axis is within the budget of the C axis (the band is the
    /// whole turn) C is free and crosses linearly between the values beside; elsewhere
    /// it is the interpolation from `c_in` to `c_out` clamped into BAND_SHARE of its band
    /// (the band's edge opens like asin near a whole turn: following it to the end would
    /// ask C for an unbounded speed).
    fn through_cone(
        &self,
        nodes: &[Node],
        run: Run,
        c_in: Option<f64>,
        c_out: Option<f64>,
    ) -> Result<(Vec<(f64, f64)>, f64), ConeFailure> {
        let before = run.start.checked_sub(1);
        let after = (run.end + 1 < nodes.len()).then_some(run.end + 1);
        let (s_in, s_out) = (
            before.map_or(nodes[run.start].s, |n| nodes[n].s),
            after.map_or(nodes[run.end].s, |n| nodes[n].s),
        );
        let linear = |s: f64| match (c_in, c_out) {
            (Some(a), Some(b)) if s_out > s_in => a + (b - a) * (s - s_in) / (s_out - s_in),
            (Some(a), _) => a,
            (None, Some(b)) => b,
            (None, None) => 0.0,
        };
        let negative_ok = self.joints.min[3] < 0.0;
        let positive_ok = self.joints.max[3] > 0.0;
        let sin_budget = math::sin(self.budget);
        let count = run.end - run.start + 1;
        // First the band nodes (None: free). Along each stretch of them the band's centre
        // follows the azimuth continuously, on one branch: the branch and the turn (2πk)
        // whose centre lies nearest the target at both ends of the stretch. (Chosen at
        // its first node alone, a stretch whose azimuth swings far before C leaves the
        // cone took the branch that suits its start, and left the cone half a turn from
        // where C goes next.)
        let mut c: Vec<Option<f64>> = vec![None; count];
        let in_band = |node: &Node| math::sin(node.tilt) > sin_budget;
        let mut k = 0;
        while k < count {
            if !in_band(&nodes[run.start + k]) {
                k += 1;
                continue;
            }
            let first = k;
            let mut track = vec![nodes[run.start + k].azimuth];
            k += 1;
            while k < count && in_band(&nodes[run.start + k]) {
                let previous = track[track.len() - 1];
                track.push(unwrap_near(nodes[run.start + k].azimuth, previous));
                k += 1;
            }
            let (t_first, t_last) = (
                linear(nodes[run.start + first].s),
                linear(nodes[run.start + k - 1].s),
            );
            let (a, b) = (track[0], track[track.len() - 1]);
            // The shift of the branch's track (a whole number of turns) that brings its
            // ends nearest the targets, and how far they then are. An end of the path
            // (no C beside the run there) sets no target.
            let weights = match (c_in, c_out) {
                (None, None) => (1.0, 0.0),
                _ => (
                    f64::from(u8::from(c_in.is_some())),
                    f64::from(u8::from(c_out.is_some())),
                ),
            };
            let fit = |flip: f64| {
                let tau = std::f64::consts::TAU;
                [t_first - a - flip, t_last - b - flip]
                    .into_iter()
                    .map(|d| flip + (d / tau).round() * tau)
                    .map(|shift| {
                        let miss = weights.0 * (a + shift - t_first).abs()
                            + weights.1 * (b + shift - t_last).abs();
                        (miss, shift)
                    })
                    .fold(
                        (f64::INFINITY, 0.0),
                        |best, x| if x.0 < best.0 { x } else { best },
                    )
            };
            let (up, down) = (fit(0.0), fit(PI));
            let shift = if (up.0 <= down.0 && positive_ok) || !negative_ok {
                up.1
            } else {
                down.1
            };
            for (m, azimuth) in track.iter().enumerate() {
                let node = &nodes[run.start + first + m];
                let half_width = math::asin(BAND_SHARE * sin_budget / math::sin(node.tilt));
                let mid = azimuth + shift;
                c[first + m] = Some(linear(node.s).clamp(mid - half_width, mid + half_width));
            }
        }
        // Then the free stretches: straight across from the values beside them.
        let mut k = 0;
        while k < count {
            if c[k].is_some() {
                k += 1;
                continue;
            }
            let first = k;
            while k < count && c[k].is_none() {
                k += 1;
            }
            let left = if first > 0 {
                c[first - 1].map(|v| (nodes[run.start + first - 1].s, v))
            } else {
                None
            };
            let right = if k < count {
                c[k].map(|v| (nodes[run.start + k].s, v))
            } else {
                None
            };
            for m in first..k {
                let s = nodes[run.start + m].s;
                c[m] = Some(match (left, right) {
                    (Some((sa, a)), Some((sb, b))) => a + (b - a) * (s - sa) / (sb - sa),
                    _ => linear(s),
                });
            }
        }
        let (va, vc) = (self.joints.velocity[3], self.joints.velocity[4]);
        let mut out = Vec::with_capacity(count);
        let mut previous = before.map(|b| (nodes[b].tilt, c_in.unwrap_or(0.0)));
        let mut cost = 0.0;
        let mut refine = Vec::new();
        // A piece this short that still jumps is a jump: no refinement will smooth it.
        let too_short = |n: usize| nodes[n].s - nodes[n - 1].s < 1e-7;
        for (m, node) in nodes[run.start..=run.end].iter().enumerate() {
            let n = run.start + m;
            let c = c[m].unwrap_or(0.0);
            let (sin_tilt, cos_tilt) = math::sincos(node.tilt);
            let a = math::atan2(sin_tilt * math::cos(node.azimuth - c), cos_tilt)
                .clamp(self.joints.min[3], self.joints.max[3]);
            let planned = Vector::<3>::new(
                math::sin(c) * math::sin(a),
                math::cos(c) * math::sin(a),
                math::cos(a),
            );
            let deviation = geometry::angle_between(&planned, &node.pose.axis);
            if !(deviation <= self.budget * (1.0 + 1e-9) + 1e-12 && self.c_ok(c)) {
                return Err(ConeFailure::Impossible);
            }
            if let Some((pa, pc)) = previous {
                let step = (c - pc).abs();
                if step * math::sin(a.abs().max(pa.abs())) > 0.25 * self.budget || step > 0.2 {
                    if n == 0 || too_short(n) {
                        return Err(ConeFailure::Impossible);
                    }
                    refine.push(n);
                }
                cost += (a - pa).abs() / va + step / vc;
            }
            previous = Some((a, c));
            out.push((a, c));
        }
        if let (Some(n), Some(c), Some((_, pc))) = (after, c_out, previous) {
            let step = (c - pc).abs();
            let a = nodes[n].tilt;
            if step > 0.2 || step * math::sin(a) > 0.25 * self.budget {
                // Leaving the band C holds for another: either this way is wrong, or
                // the nodes are too sparse to tell.
                if step > 1.0 || too_short(n) {
                    return Err(ConeFailure::Impossible);
                }
                refine.push(n);
            }
            cost += step / vc;
        }
        if !refine.is_empty() {
            return Err(ConeFailure::Refine(refine));
        }
        Ok((out, cost))
    }
}

/// Chooses the joints along `poses` (see the module's text) for `machine` within
/// `joints`' travel and `path`'s tolerances, with nodes at most `spacing` mm apart;
/// `name` names a programmed pose in messages ("CL line 12"). A path that no choice
/// keeps within the travel is refused, naming the first pose none can reach. Each piece
/// carries its move's programmed speed (`feeds`; `path.feed` before the first change).
pub fn plan_joints(
    poses: &[Pose],
    feeds: &[FeedChange],
    machine: &TableTiltingAc,
    joints: &JointLimits,
    path: &PathLimits,
    spacing: f64,
    name: &dyn Fn(usize) -> String,
) -> Result<JointPath, PathError> {
    if poses.len() < 2 {
        return Err(PathError::invalid("a path needs at least two poses"));
    }
    let budget = 0.5 * path.orientation_tolerance;
    let planner = Planner {
        joints,
        budget,
        cone: path.pole_cone,
    };
    // An eighth of the budget per node near the pole resolves where the band opens.
    let fine = (budget / 8.0).max(1e-6);
    // The pose before each change ends the last move at the old speed.
    let breaks: Vec<usize> = feeds.iter().map(|c| c.from - 1).collect();
    let mut nodes = nodes(
        poses,
        &breaks,
        spacing,
        skip_limits(path),
        path.pole_cone,
        fine,
    )?;
    for _ in 0..REFINE_ROUNDS {
        match choose(&planner, &nodes, name) {
            Ok(rotary) => {
                let mut joint_path = assemble(machine, &nodes, &rotary);
                joint_path.feed = piece_feeds(&joint_path.source, feeds, path.feed);
                return Ok(joint_path);
            }
            Err(Choice::Refine(mut at)) => {
                at.sort_unstable();
                at.dedup();
                if nodes.len() + at.len() > NODE_BUDGET {
                    break;
                }
                refine(&mut nodes, &at);
            }
            Err(Choice::Refused(e)) => return Err(e),
        }
    }
    Err(PathError::invalid(
        "C's turns near the pole could not be resolved within the node budget",
    ))
}

enum Choice {
    Refine(Vec<usize>),
    Refused(PathError),
}

/// The refusal at node `n`: the pose, what failed, and the joint that cannot follow with
/// the value it would need and its travel (degrees, as a machine's limits are written).
fn unreachable(
    planner: &Planner,
    nodes: &[Node],
    n: usize,
    name: &dyn Fn(usize) -> String,
    why: &str,
) -> Choice {
    let node = &nodes[n];
    let pose = node.source.round() as usize;
    let (min, max) = (planner.joints.min, planner.joints.max);
    let degrees = |x: f64| x.to_degrees();
    let joint = if !planner.a_ok(node.tilt) && !planner.a_ok(-node.tilt) {
        format!(
            "A would have to be {:.3}° (or {:.3}° on the other branch), outside its travel \
             {:.3}° … {:.3}°",
            degrees(node.tilt),
            degrees(-node.tilt),
            degrees(min[3]),
            degrees(max[3])
        )
    } else {
        format!(
            "C must follow the tool axis's azimuth ({:.3}° here) and no turn of it keeps C \
             within its travel {:.3}° … {:.3}°",
            degrees(node.azimuth),
            degrees(min[4]),
            degrees(max[4])
        )
    };
    Choice::Refused(PathError::invalid(format!(
        "{}: {why}: {joint} (tool axis {:.3}° from the C axis)",
        name(pose),
        degrees(node.tilt)
    )))
}

/// The dynamic programme over the runs: the rotary joints at every node.
fn choose(
    planner: &Planner,
    nodes: &[Node],
    name: &dyn Fn(usize) -> String,
) -> Result<Vec<(f64, f64)>, Choice> {
    let runs = runs(nodes, planner.cone);
    let off: Vec<usize> = (0..runs.len()).filter(|&r| !runs[r].cone).collect();
    if off.is_empty() {
        // The whole path inside the cone: C held where the band allows.
        let run = runs[0];
        return planner
            .through_cone(nodes, run, None, None)
            .map(|(rotary, _)| rotary)
            .map_err(|f| match f {
                ConeFailure::Refine(at) => Choice::Refine(at),
                ConeFailure::Impossible => unreachable(
                    planner,
                    nodes,
                    0,
                    name,
                    "no joints within the travel reach this pose",
                ),
            });
    }
    let mut refine = Vec::new();
    // states[k]: the ways through off-cone run off[k].
    let mut states: Vec<Vec<State>> = Vec::with_capacity(off.len());
    for (k, &r) in off.iter().enumerate() {
        let run = runs[r];
        let mut here: Vec<State> = Vec::new();
        let mut first_violation: Option<usize> = None;
        let mut consider = |state: State, here: &mut Vec<State>| match planner.off_cone_violation(
            nodes,
            run,
            state.negative,
            state.c_start,
        ) {
            Some(n) => {
                first_violation = Some(first_violation.map_or(n, |f: usize| f.max(n)));
            }
            None => match here
                .iter_mut()
                .find(|s| s.negative == state.negative && s.c_start == state.c_start)
            {
                Some(s) if s.cost <= state.cost => {}
                Some(s) => *s = state,
                None => here.push(state),
            },
        };
        let azimuth = nodes[run.start].azimuth;
        if k == 0 {
            // The path's start: the A ≥ 0 branch and C nearest 0 win a tie.
            let leading = (r > 0).then(|| runs[r - 1]);
            for negative in [false, true] {
                let base = azimuth + if negative { PI } else { 0.0 };
                for c in planner.c_candidates(base, 0.0) {
                    let mut cost = if negative { 1e-9 } else { 0.0 } + 1e-12 * c.abs();
                    if let Some(lead) = leading {
                        match planner.through_cone(nodes, lead, None, Some(c)) {
                            Ok((_, extra)) => cost += extra,
                            Err(ConeFailure::Refine(at)) => {
                                refine.extend(at);
                                continue;
                            }
                            Err(ConeFailure::Impossible) => continue,
                        }
                    }
                    consider(
                        State {
                            negative,
                            c_start: c,
                            cost,
                            from: None,
                        },
                        &mut here,
                    );
                }
            }
        } else {
            let (prev_run, cone) = (runs[off[k - 1]], runs[r - 1]);
            for (i, from) in states[k - 1].iter().enumerate() {
                let path = planner.off_cone(nodes, prev_run, from.negative, from.c_start);
                let c_end = path[path.len() - 1].1;
                for negative in [false, true] {
                    let base = azimuth + if negative { PI } else { 0.0 };
                    for c in planner.c_candidates(base, c_end) {
                        match planner.through_cone(nodes, cone, Some(c_end), Some(c)) {
                            Ok((_, extra)) => consider(
                                State {
                                    negative,
                                    c_start: c,
                                    cost: from.cost + extra,
                                    from: Some(i),
                                },
                                &mut here,
                            ),
                            Err(ConeFailure::Refine(at)) => refine.extend(at),
                            Err(ConeFailure::Impossible) => {}
                        }
                    }
                }
            }
        }
        if here.is_empty() {
            if !refine.is_empty() {
                return Err(Choice::Refine(refine));
            }
            let n = first_violation.unwrap_or(if r > 0 { runs[r - 1].start } else { run.start });
            return Err(unreachable(
                planner,
                nodes,
                n,
                name,
                "no choice of branch and turn keeps A and C within their travel here",
            ));
        }
        states.push(here);
    }
    // The trailing cone, if any, must be passable from the chosen end.
    let last_off = off[off.len() - 1];
    let trailing = (last_off + 1 < runs.len()).then(|| runs[last_off + 1]);
    let last_run = runs[last_off];
    let mut best: Option<(usize, f64)> = None;
    for (i, state) in states[off.len() - 1].iter().enumerate() {
        let mut cost = state.cost;
        if let Some(trail) = trailing {
            let path = planner.off_cone(nodes, last_run, state.negative, state.c_start);
            match planner.through_cone(nodes, trail, Some(path[path.len() - 1].1), None) {
                Ok((_, extra)) => cost += extra,
                Err(ConeFailure::Refine(at)) => {
                    refine.extend(at);
                    continue;
                }
                Err(ConeFailure::Impossible) => continue,
            }
        }
        if best.is_none_or(|(_, b)| cost < b) {
            best = Some((i, cost));
        }
    }
    if !refine.is_empty() {
        return Err(Choice::Refine(refine));
    }
    let Some((mut index, _)) = best else {
        let n = trailing.map_or(last_run.end, |t| t.start);
        return Err(unreachable(
            planner,
            nodes,
            n,
            name,
            "C cannot turn through the pole within the travel",
        ));
    };
    // Back along the chosen states: each off-cone run's joints, and the cones between.
    let mut chosen = vec![
        State {
            negative: false,
            c_start: 0.0,
            cost: 0.0,
            from: None,
        };
        off.len()
    ];
    for k in (0..off.len()).rev() {
        chosen[k] = states[k][index];
        index = chosen[k].from.unwrap_or(0);
    }
    let mut rotary = vec![(0.0, 0.0); nodes.len()];
    let mut ends: Vec<(f64, f64)> = Vec::with_capacity(off.len());
    for (k, &r) in off.iter().enumerate() {
        let run = runs[r];
        let path = planner.off_cone(nodes, run, chosen[k].negative, chosen[k].c_start);
        ends.push((path[0].1, path[path.len() - 1].1));
        rotary[run.start..=run.end].copy_from_slice(&path);
    }
    for (r, run) in runs.iter().enumerate() {
        if !run.cone {
            continue;
        }
        let k_after = off.iter().position(|&o| o > r);
        let c_in = k_after
            .map_or(Some(off.len() - 1), |k| k.checked_sub(1))
            .map(|k| ends[k].1);
        let c_out = k_after.map(|k| ends[k].0);
        // The search above passed every cone between its states, so this one passes too;
        // should it not, the path is refused at the cone rather than refined for ever.
        let (path, _) = planner
            .through_cone(nodes, *run, c_in, c_out)
            .map_err(|failure| match failure {
                ConeFailure::Refine(at) if !at.is_empty() => Choice::Refine(at),
                _ => unreachable(
                    planner,
                    nodes,
                    run.start,
                    name,
                    "C cannot turn through the pole between the branches on either side",
                ),
            })?;
        rotary[run.start..=run.end].copy_from_slice(&path);
    }
    Ok(rotary)
}

fn assemble(machine: &TableTiltingAc, nodes: &[Node], rotary: &[(f64, f64)]) -> JointPath {
    let mut path = JointPath {
        s: Vec::with_capacity(nodes.len()),
        joints: Vec::with_capacity(nodes.len()),
        poses: Vec::with_capacity(nodes.len()),
        source: Vec::with_capacity(nodes.len()),
        deviation: Vec::with_capacity(nodes.len()),
        feed: Vec::new(),
    };
    for (node, &(a, c)) in nodes.iter().zip(rotary) {
        let planned = Vector::<3>::new(
            math::sin(c) * math::sin(a),
            math::cos(c) * math::sin(a),
            math::cos(a),
        );
        path.s.push(node.s);
        path.joints.push(machine.joints_at(&node.pose.tip, a, c));
        path.poses.push(node.pose);
        path.source.push(node.source);
        path.deviation
            .push(geometry::angle_between(&planned, &node.pose.axis));
    }
    path
}

/// The programmed speed of the piece after each node (see [`JointPath::feed`]): the
/// move its middle lies on. The poses where the speed changes are nodes, so a piece lies
/// on moves of one speed.
fn piece_feeds(source: &[f64], feeds: &[FeedChange], default: f64) -> Vec<f64> {
    let mut out: Vec<f64> = source
        .windows(2)
        .map(|w| {
            let middle = 0.5 * (w[0] + w[1]);
            feed_of_move(feeds, default, middle.floor() as usize + 1)
        })
        .collect();
    let last = out.last().copied().unwrap_or(default);
    out.push(last);
    out
}
