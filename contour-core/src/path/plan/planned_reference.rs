//! A planned five-axis reference (docs/design/five-axis.md §5.3b): the joints chosen over
//! the whole path ([`plan_joints`]), the fastest feed along it that keeps every joint's
//! velocity and acceleration and the tool tip's feed and acceleration
//! ([`FeedProfile`]), sampled every Ts and smoothed by the jerk filter: the tip in the
//! workpiece frame, A and C as joints. All of it happens
//! once, at planning; a sample then costs O(1) whatever the path's length.
//!
//! The limits are mapped onto s node by node, with the joints linear between nodes: a
//! joint's speed is its slope times the path speed, its acceleration slope·s̈ + curvature·ṡ².
//! A change of slope at a node (a kink of the CL polyline, or of a joint's path) is spread
//! by the filter over its first average, so its acceleration is the lesser of
//! v·Δslope/T and v²·Δslope/h. What the mapping leaves approximate (the tip seen through
//! the rotary axes, the filter's deviation from the path) is measured on the samples
//! themselves: where a sample exceeds a limit, the speed where it was planned is lowered
//! by the excess and the plan made again, until every sample keeps every limit.

use std::sync::{Arc, Mutex, Weak};

use super::feed::{FeedConstraints, FeedProfile};
use super::jerk_filter::JerkFilter;
use super::joint_path::{plan_joints, JointPath};
use crate::geometry::{self, Vector};
use crate::kinematics::{Joints, Pose, TableTiltingAc};
use crate::limits::{JointLimits, PathLimits};
use crate::path::{PathError, ToolPath};

/// The jerk filter's quantum (mm or rad): the samples' differences are exact to it.
pub const QUANTUM: f64 = 1.0 / (1u64 << 30) as f64;
/// Rounds of plan, measure, slow down.
const ROUNDS: usize = 30;
/// The most samples a plan may have by default: 2²⁶, 18.6 hours at 1 ms. Planning costs
/// a few microseconds per sample and round, so this also bounds the time a restored
/// state may spend planning again.
pub const SAMPLE_BUDGET: u64 = 1 << 26;

static SAMPLE_LIMIT: std::sync::atomic::AtomicU64 =
    std::sync::atomic::AtomicU64::new(SAMPLE_BUDGET);

/// Sets the most samples a plan may have in this process (at least 1; [`SAMPLE_BUDGET`]
/// by default): a host that must answer within a time (a fuzzer's timeout) lowers it, and
/// a longer plan is refused like any other.
pub fn set_sample_budget(samples: u64) {
    SAMPLE_LIMIT.store(samples.max(1), std::sync::atomic::Ordering::Relaxed);
}

fn sample_budget() -> u64 {
    SAMPLE_LIMIT.load(std::sync::atomic::Ordering::Relaxed)
}

/// What a plan measured on its own samples.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PlanReport {
    /// From the first sample to the one at rest at the end, s.
    pub duration: f64,
    /// The same path's duration under the velocity and acceleration limits alone (the
    /// plan before the jerk filter and before any slowing down for the samples), s.
    pub unfiltered_duration: f64,
    /// Largest distance of a planned tip from the programmed tip path, mm.
    pub tip_deviation: f64,
    /// Largest angle between a planned and the programmed tool axis, rad.
    pub orientation_deviation: f64,
    /// Plans made before every sample kept every limit.
    pub rounds: usize,
    /// Planning nodes.
    pub nodes: usize,
}

/// A plan: what every sample is computed from.
#[derive(Debug)]
pub struct Plan {
    path: JointPath,
    /// How many programmed poses the plan was made from.
    programmed: usize,
    feed: FeedProfile,
    machine: TableTiltingAc,
    ts: f64,
    filter: (usize, usize),
    /// Samples until the reference rests at the path's end.
    samples: u64,
    report: PlanReport,
}

/// The limits of the feed plan at the nodes of a joint path.
///
/// Between nodes every joint moves linearly in s, so a joint's acceleration comes from
/// the changes of its slope at the nodes. The samples see those changes averaged over
/// the filter's first average (T, or Ts without a filter), a stretch of v·T of path: the
/// acceleration at a node is v·Δg/T with Δg the change of slope across that stretch,
/// which is v²·q'' on a smooth path and the spread spike of a lone kink. The tip's
/// centripetal acceleration is the same with the change of its direction.
struct Constraints<'a> {
    path: &'a JointPath,
    joints: &'a JointLimits,
    limits: &'a PathLimits,
    /// The filter's first average, s (Ts without a filter).
    spread: f64,
    /// The sum of the two averages' lengths squared, s² (0 without a filter): a curve
    /// of curvature κ is drawn in by v²·κ·Σ T²/24.
    smoothing2: f64,
    /// Per piece between nodes: each joint's slope, and the tip's direction.
    slope: Vec<Joints>,
    direction: Vec<Vector<3>>,
    /// Per node: how much of the speed squared and of the acceleration the samples
    /// allowed.
    speed_scale: &'a [f64],
    accel_scale: &'a [f64],
}

impl<'a> Constraints<'a> {
    fn new(
        path: &'a JointPath,
        joints: &'a JointLimits,
        limits: &'a PathLimits,
        filter: (usize, usize, f64),
        scales: (&'a [f64], &'a [f64]),
    ) -> Self {
        let (m1, m2, ts) = filter;
        let count = path.s.len();
        Constraints {
            path,
            joints,
            limits,
            spread: m1 as f64 * ts,
            // m2 = 0: the same spread without the filter's deviation.
            smoothing2: if m2 > 0 && m1 + m2 > 2 {
                ((m1 * m1 + m2 * m2) as f64) * ts * ts
            } else {
                0.0
            },
            slope: (0..count - 1)
                .map(|n| (path.joints[n + 1] - path.joints[n]) / (path.s[n + 1] - path.s[n]))
                .collect(),
            direction: (0..count - 1)
                .map(|n| {
                    geometry::unit(&(path.poses[n + 1].tip - path.poses[n].tip))
                        .unwrap_or_else(Vector::z)
                })
                .collect(),
            speed_scale: scales.0,
            accel_scale: scales.1,
        }
    }

    /// The pieces before and after the stretch of `length` mm centred on node `n`.
    fn stretch(&self, n: usize, length: f64) -> (usize, usize) {
        let s = &self.path.s;
        let last = s.len() - 2;
        let half = 0.5 * length;
        let before = if half <= 0.0 || n == 0 {
            n.saturating_sub(1)
        } else {
            s.partition_point(|&x| x < s[n] - half)
                .saturating_sub(1)
                .min(n - 1)
        };
        let after = if half <= 0.0 {
            n.min(last)
        } else {
            s.partition_point(|&x| x <= s[n] + half)
                .saturating_sub(1)
                .clamp(n.min(last), last)
        };
        (before, after)
    }

    /// At node `n` and speed `v`: each joint's slope (the larger of the pieces beside
    /// it), its acceleration per speed squared (Δg/(v·T)), and the tip's curvature seen
    /// the same way (none at rest).
    fn bends(&self, n: usize, v: f64) -> (Joints, Joints, f64) {
        let last = self.slope.len() - 1;
        let (g_in, g_out) = (
            self.slope[n.saturating_sub(1).min(last)],
            self.slope[n.min(last)],
        );
        let slope = g_in.zip_map(&g_out, |a, b| if a.abs() > b.abs() { a } else { b });
        let length = v * self.spread;
        if n == 0 || n > last || length.is_nan() || length <= 0.0 {
            return (slope, Joints::zeros(), 0.0);
        }
        // The stretch holds at least the pieces beside the node: a kink is crossed
        // within T however far its neighbours are.
        let (before, after) = self.stretch(n, length);
        let bend = (self.slope[after] - self.slope[before]) / length;
        // The chord between the unit directions, 2·sin(θ/2): the turn to 1 % up to 30°,
        // without an arctangent (this runs in every node's search of its speed).
        let turn = geometry::norm(&(self.direction[after] - self.direction[before])) / length;
        (slope, bend, turn)
    }

    /// The largest speed at node `n` (mm/s) at which `limit(v) ≥ 0` holds, by bisection
    /// below `top` (the constraints of a node grow with the speed).
    fn largest_speed(top: f64, ok: impl Fn(f64) -> bool) -> f64 {
        if ok(top) {
            return top;
        }
        let (mut lo, mut hi) = (0.0, top);
        // To 2⁻²⁴ of the top speed: well inside what the samples are checked to.
        for _ in 0..24 {
            let mid = 0.5 * (lo + hi);
            if ok(mid) {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        lo
    }
}

impl FeedConstraints for Constraints<'_> {
    fn nodes(&self) -> &[f64] {
        &self.path.s
    }

    fn speed2_max(&self, n: usize) -> f64 {
        let mut top = self.limits.feed;
        // The slopes on both sides: the speed is the same at the node.
        let (slope, _, _) = self.bends(n, 0.0);
        for i in 0..5 {
            if slope[i] != 0.0 {
                top = top.min(self.joints.velocity[i] / slope[i].abs());
            }
        }
        let scale = self.accel_scale[n];
        let accel = self.limits.accel * scale;
        let tolerance = self.limits.tolerance;
        let v = Self::largest_speed(top, |v| {
            let (_, bend, turn) = self.bends(n, v);
            let x = v * v;
            let joints_ok =
                (0..5).all(|i| bend[i].abs() * x <= self.joints.acceleration[i] * scale);
            let deviation = x * turn * self.smoothing2 / 24.0;
            joints_ok && turn * x <= accel && deviation <= tolerance
        });
        v * v * self.speed_scale[n]
    }

    fn accel_range(&self, n: usize, x: f64) -> (f64, f64) {
        let v = x.max(0.0).sqrt();
        let (slope, bend, turn) = self.bends(n, v);
        let scale = self.accel_scale[n];
        let accel = self.limits.accel * scale;
        let normal = turn * x;
        let tangential = (accel * accel - normal * normal).max(0.0).sqrt();
        let (mut lo, mut hi) = (-tangential, tangential);
        for i in 0..5 {
            let g = slope[i];
            if g.abs() < 1e-12 {
                continue;
            }
            let amax = self.joints.acceleration[i] * scale;
            let centripetal = bend[i] * x;
            let (a, b) = ((-amax - centripetal) / g, (amax - centripetal) / g);
            lo = lo.max(a.min(b));
            hi = hi.min(a.max(b));
        }
        (lo, hi)
    }
}

/// Where a reference stands among its samples; what an FMU saves of it.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Cursor {
    /// The current sample's number (sample k at time k·Ts).
    sample: u64,
    /// The feed plan's node interval of the current raw sample.
    interval: usize,
    filter: JerkFilter<5>,
    joints: Joints,
    /// The programmed path's node interval nearest the current planned tip.
    foot: usize,
}

/// One sample of a planned reference.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlannedSample {
    /// The joints (mm, rad).
    pub joints: Joints,
    /// The pose they give.
    pub pose: Pose,
    /// Where the raw (unfiltered) sample stands among the programmed poses.
    pub source: f64,
    /// The planned tip's distance from the programmed path, mm.
    pub tip_deviation: f64,
    /// The angle between the planned and the programmed tool axis there, rad.
    pub orientation_deviation: f64,
    /// Whether the reference rests at the path's end.
    pub done: bool,
}

impl Plan {
    /// Plans the path through `poses` (see the module's text); `name` names a programmed
    /// pose in messages.
    pub fn new(
        poses: &[Pose],
        machine: TableTiltingAc,
        joints: &JointLimits,
        limits: &PathLimits,
        ts: f64,
        name: &dyn Fn(usize) -> String,
    ) -> Result<Plan, PathError> {
        joints.check().map_err(PathError::invalid)?;
        limits.check().map_err(PathError::invalid)?;
        if limits.accel.is_nan() || limits.accel <= 0.0 {
            return Err(PathError::invalid("a plan needs accel > 0"));
        }
        if !(ts.is_finite() && ts > 0.0) {
            return Err(PathError::invalid(format!(
                "sample period {ts} s must be > 0"
            )));
        }
        // Fine enough for the braking distances the feed planner integrates.
        let braking = limits.feed * limits.feed / (2.0 * limits.accel);
        let spacing = (braking / 10.0)
            .clamp(5e-3, 0.5)
            .min(limits.feed * ts)
            .max(1e-4);
        // At the feed throughout the path would take this many samples at least: refuse
        // before any work what the budget cannot hold.
        let length: f64 = poses
            .windows(2)
            .map(|w| geometry::dist(&w[0].tip, &w[1].tip))
            .sum();
        let least = length / (limits.feed * ts);
        if least.is_nan() || least > sample_budget() as f64 {
            return Err(PathError::invalid(format!(
                "the path is {length:.6e} mm long: at {} mm/s that is more than the {} \
                 samples a plan may have",
                limits.feed,
                sample_budget()
            )));
        }
        let path = plan_joints(poses, &machine, joints, limits, spacing, name)?;
        let filter = if limits.jerk > 0.0 {
            // A step of the full acceleration becomes a ramp at the jerk limit; the
            // second, shorter average smooths the ramp's corners and a kink's spike.
            let m1 = (limits.accel / (limits.jerk * ts)).ceil().clamp(1.0, 1e5) as usize;
            (m1, m1.div_ceil(4))
        } else {
            (1, 1)
        };
        let mut path = path;
        let mut speed_scale = vec![1.0; path.s.len()];
        let mut accel_scale = vec![1.0; path.s.len()];
        // The velocity-and-acceleration optimum: the same limits with the accelerations
        // seen over the same T, no jerk limit, no tolerance.
        let unfiltered = FeedProfile::plan(&Constraints::new(
            &path,
            joints,
            limits,
            (filter.0, 0, ts),
            (&speed_scale, &accel_scale),
        ))?
        .duration();
        for round in 1..=ROUNDS {
            let feed = FeedProfile::plan(&Constraints::new(
                &path,
                joints,
                limits,
                (filter.0, filter.1, ts),
                (&speed_scale, &accel_scale),
            ))?;
            let raw = (feed.duration() / ts).ceil();
            let budget = sample_budget();
            if raw.is_nan() || raw + (filter.0 + filter.1) as f64 > budget as f64 {
                return Err(PathError::invalid(format!(
                    "the planned reference takes {:.0} s: more than the {budget} samples a \
                     plan may have",
                    feed.duration()
                )));
            }
            let mut plan = Plan {
                samples: raw as u64 + (filter.0 + filter.1) as u64,
                programmed: poses.len(),
                path,
                feed,
                machine,
                ts,
                filter,
                report: PlanReport::default(),
            };
            let (report, slow) = plan.measure(joints, limits);
            if slow.is_empty() {
                plan.report = PlanReport {
                    rounds: round,
                    unfiltered_duration: unfiltered,
                    nodes: plan.path.s.len(),
                    ..report
                };
                return Ok(plan);
            }
            // The worst excess at each node this round, compounded on the earlier ones.
            let mut round_speed = vec![1.0f64; speed_scale.len()];
            let mut round_accel = vec![1.0f64; accel_scale.len()];
            for (n, speed, accel) in slow {
                round_speed[n] = round_speed[n].min(speed);
                round_accel[n] = round_accel[n].min(accel);
            }
            for n in 0..speed_scale.len() {
                speed_scale[n] *= round_speed[n];
                accel_scale[n] *= round_accel[n];
            }
            path = plan.path;
        }
        Err(PathError::invalid(format!(
            "no feed found within the limits after {ROUNDS} plans"
        )))
    }

    /// What the plan measured on its samples.
    pub fn report(&self) -> &PlanReport {
        &self.report
    }

    /// The joint path the plan runs on.
    pub fn joint_path(&self) -> &JointPath {
        &self.path
    }

    /// The feed plan.
    pub fn feed(&self) -> &FeedProfile {
        &self.feed
    }

    /// The sample period, s.
    pub fn ts(&self) -> f64 {
        self.ts
    }

    /// The cursor at the first sample (the path's start, at rest).
    pub fn start(&self) -> Cursor {
        let (raw, _, _) = self.raw(0.0, 0);
        let (end, _, _) = self.raw(self.feed.duration(), self.path.s.len() - 2);
        Cursor {
            sample: 0,
            interval: 0,
            filter: JerkFilter::new(self.filter.0, self.filter.1, &raw, &end),
            joints: self.path.joints[0],
            foot: 0,
        }
    }

    /// The raw sample at `t`: the programmed tip (workpiece frame) and the planned A and
    /// C; with the feed interval it lies in and its place among the programmed poses.
    fn raw(&self, t: f64, hint: usize) -> (Vector<5>, usize, f64) {
        let point = self.feed.at(t, hint);
        let n = point.interval;
        let (s0, s1) = (self.path.s[n], self.path.s[n + 1]);
        let f = ((point.s - s0) / (s1 - s0)).clamp(0.0, 1.0);
        let (a, b) = (&self.path.poses[n].tip, &self.path.poses[n + 1].tip);
        // At a node exactly the node (a + (b − a)·1 may round off b): the reference
        // rests exactly on the path's end.
        let tip = if f >= 1.0 { *b } else { a + (b - a) * f };
        let (qa, qb) = (&self.path.joints[n], &self.path.joints[n + 1]);
        let rotary = |i: usize| {
            if f >= 1.0 {
                qb[i]
            } else {
                qa[i] + (qb[i] - qa[i]) * f
            }
        };
        let raw = Vector::<5>::new(tip[0], tip[1], tip[2], rotary(3), rotary(4));
        let source = self.path.source[n] + (self.path.source[n + 1] - self.path.source[n]) * f;
        (raw, n, source)
    }

    /// The joints of a filtered sample: the tip filtered where the part is (a straight
    /// move stays straight), the table's angles filtered as joints (C's planned turn
    /// through the pole kept), the linear axes following both.
    fn joints_of(&self, filtered: &Vector<5>) -> Joints {
        let tip = Vector::<3>::new(filtered[0], filtered[1], filtered[2]);
        self.machine.joints_at(&tip, filtered[3], filtered[4])
    }

    /// Moves `cursor` one sample on.
    pub fn advance(&self, cursor: &mut Cursor) {
        if cursor.sample >= self.samples {
            return;
        }
        cursor.sample += 1;
        let t = cursor.sample as f64 * self.ts;
        let (raw, interval, _) = self.raw(t, cursor.interval);
        cursor.interval = interval;
        let filtered = cursor.filter.push(&raw);
        cursor.joints = self.joints_of(&filtered);
    }

    /// The sample `cursor` stands at, its deviation from the programmed path measured
    /// from the programmed interval nearest the previous one (which `cursor` keeps).
    pub fn sample(&self, cursor: &mut Cursor) -> PlannedSample {
        let pose = self.machine.forward(&cursor.joints);
        let (_, _, source) = self.raw(cursor.sample as f64 * self.ts, cursor.interval);
        let (foot, tip_deviation, orientation_deviation) =
            self.deviation(&pose, cursor.foot, cursor.interval);
        cursor.foot = foot;
        PlannedSample {
            joints: cursor.joints,
            pose,
            source,
            tip_deviation,
            orientation_deviation,
            done: cursor.sample >= self.samples,
        }
    }

    /// The programmed interval nearest `pose`'s tip, searched from `from` up to the raw
    /// sample's interval `ahead` (the filtered tip is behind the raw one), with the tip's
    /// distance and the axis's angle from the programmed pose at that point.
    fn deviation(&self, pose: &Pose, from: usize, ahead: usize) -> (usize, f64, f64) {
        let poses = &self.path.poses;
        let last = poses.len() - 2;
        let (start, end) = (
            from.saturating_sub(2).min(last),
            (ahead + 1).max(from).min(last),
        );
        let mut best = (start, f64::INFINITY, 0.0);
        for n in start..=end {
            let (a, b) = (poses[n].tip, poses[n + 1].tip);
            let d = b - a;
            let t = ((pose.tip - a).dot(&d) / d.norm_squared()).clamp(0.0, 1.0);
            let distance = geometry::dist(&(a + d * t), &pose.tip);
            if distance < best.1 {
                best = (n, distance, t);
            }
        }
        let (n, distance, t) = best;
        let axis = geometry::slerp(&poses[n].axis, &poses[n + 1].axis, t).unwrap_or(poses[n].axis);
        (n, distance, geometry::angle_between(&axis, &pose.axis))
    }

    /// Runs every sample and measures it against the limits: the report, and for every
    /// node where a sample exceeded one, the factors its speed squared and acceleration
    /// must be scaled by.
    fn measure(
        &self,
        joints: &JointLimits,
        limits: &PathLimits,
    ) -> (PlanReport, Vec<(usize, f64, f64)>) {
        let ts = self.ts;
        let mut cursor = self.start();
        let mut history: [Option<(Joints, Vector<3>)>; 3] = [None; 3];
        let mut report = PlanReport {
            duration: self.samples as f64 * ts,
            ..PlanReport::default()
        };
        let mut slow: Vec<(usize, f64, f64)> = Vec::new();
        let window = self.filter.0 + self.filter.1;
        let mut intervals = std::collections::VecDeque::with_capacity(window + 1);
        loop {
            let sample = self.sample(&mut cursor);
            intervals.push_back(cursor.interval);
            if intervals.len() > window + 1 {
                intervals.pop_front();
            }
            report.tip_deviation = report.tip_deviation.max(sample.tip_deviation);
            report.orientation_deviation = report
                .orientation_deviation
                .max(sample.orientation_deviation);
            // The worst excess of this sample: (ratio limit/value, kind).
            let mut speed_factor: f64 = 1.0;
            let mut accel_factor: f64 = 1.0;
            let tip = sample.pose.tip;
            if let (Some((q1, p1)), Some((q2, p2))) = (history[0], history[1]) {
                for i in 0..5 {
                    let v = ((cursor.joints[i] - q1[i]) / ts).abs();
                    let a = ((cursor.joints[i] - 2.0 * q1[i] + q2[i]) / (ts * ts)).abs();
                    let (vmax, amax) = (joints.velocity[i], joints.acceleration[i]);
                    if v > vmax * (1.0 + 1e-9) + 2.0 * QUANTUM / ts {
                        speed_factor = speed_factor.min((vmax / v).powi(2));
                    }
                    if a > amax * (1.0 + 1e-6) + 4.0 * QUANTUM / (ts * ts) {
                        let r = amax / a;
                        speed_factor = speed_factor.min(r);
                        accel_factor = accel_factor.min(r);
                    }
                }
                let v = geometry::dist(&tip, &p1) / ts;
                let a = geometry::norm(&(tip - p1 * 2.0 + p2)) / (ts * ts);
                if v > limits.feed * (1.0 + 1e-6) {
                    speed_factor = speed_factor.min((limits.feed / v).powi(2));
                }
                if a > limits.accel * (1.0 + 1e-6) + 1e-3 {
                    let r = limits.accel / a;
                    speed_factor = speed_factor.min(r);
                    accel_factor = accel_factor.min(r);
                }
                if let (Some((_, p3)), true) = (history[2], limits.jerk > 0.0) {
                    let j = geometry::norm(&(tip - p1 * 3.0 + p2 * 3.0 - p3)) / ts.powi(3);
                    if j > limits.jerk * (1.0 + 1e-6) + 1.0 {
                        let r = limits.jerk / j;
                        speed_factor = speed_factor.min(r.powf(2.0 / 3.0));
                        accel_factor = accel_factor.min(r);
                    }
                }
            }
            // A kink's deviation grows with v, a curve's with v²: slow as for a kink
            // (convergence in a round or two; a curve gives up a little more speed).
            if sample.tip_deviation > limits.tolerance {
                let r = limits.tolerance / sample.tip_deviation;
                speed_factor = speed_factor.min(r * r);
            }
            if sample.orientation_deviation > limits.orientation_tolerance {
                let r = limits.orientation_tolerance / sample.orientation_deviation;
                speed_factor = speed_factor.min(r * r);
            }
            if speed_factor < 1.0 || accel_factor < 1.0 {
                // Every raw sample this one averaged: the nodes from the oldest interval
                // to the newest.
                let (first, last) = (intervals[0], cursor.interval + 1);
                for n in first..=last.min(self.path.s.len() - 1) {
                    slow.push((n, 0.9 * speed_factor, 0.95 * accel_factor));
                }
            }
            history = [Some((cursor.joints, tip)), history[0], history[1]];
            if sample.done {
                break;
            }
            self.advance(&mut cursor);
        }
        (report, slow)
    }
}

/// What a plan is made from: the programmed path (a built-in by name), the machine, its
/// limits and the sample period. Saved with the place on the plan; restoring plans again
/// (or finds the plan in [`plan_for`]'s cache).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PlanInputs {
    /// The programmed path (saved by name when it is the built-in `builtin`, see
    /// `SavedInputs`).
    pub path: ToolPath,
    /// The built-in's name when the path is one.
    pub builtin: Option<String>,
    /// The machine's geometry.
    pub machine: TableTiltingAc,
    /// The joints' limits.
    pub joints: JointLimits,
    /// The path's limits and tolerances.
    pub limits: PathLimits,
    /// The sample period, s.
    pub ts: f64,
}

/// The plans alive in this process, by a fingerprint of their inputs: instances on the
/// same path and limits share one, and a restored state finds it instead of planning
/// again.
static PLANS: Mutex<Vec<(u64, Weak<Plan>)>> = Mutex::new(Vec::new());

fn fingerprint(inputs: &PlanInputs) -> u64 {
    use std::hash::{Hash, Hasher};
    let mut hasher = std::hash::DefaultHasher::new();
    match &inputs.builtin {
        Some(name) => name.hash(&mut hasher),
        None => postcard::to_stdvec(&inputs.path)
            .unwrap_or_default()
            .hash(&mut hasher),
    }
    let rest = (&inputs.machine, &inputs.joints, &inputs.limits, inputs.ts);
    postcard::to_stdvec(&rest)
        .unwrap_or_default()
        .hash(&mut hasher);
    hasher.finish()
}

/// The plan for `inputs`, from the cache or made now; `name` names a programmed pose in
/// messages.
pub fn plan_for(
    inputs: &PlanInputs,
    name: &dyn Fn(usize) -> String,
) -> Result<Arc<Plan>, PathError> {
    let key = fingerprint(inputs);
    {
        let mut plans = PLANS.lock().unwrap_or_else(|e| e.into_inner());
        plans.retain(|(_, plan)| plan.strong_count() > 0);
        if let Some(plan) = plans
            .iter()
            .find(|(k, _)| *k == key)
            .and_then(|(_, p)| p.upgrade())
        {
            return Ok(plan);
        }
    }
    let poses = inputs.path.poses(PLAN_CHORD)?;
    let plan = Arc::new(Plan::new(
        &poses,
        inputs.machine,
        &inputs.joints,
        &inputs.limits,
        inputs.ts,
        name,
    )?);
    PLANS
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .push((key, Arc::downgrade(&plan)));
    Ok(plan)
}

/// The chord a curve pair is sampled at for planning, mm: the planned tip leaves the
/// curve by at most chord²·κ/8 (2.5 nm at a 5 mm radius).
const PLAN_CHORD: f64 = 0.01;

/// A planned reference: the plan shared by the instances that run it, with one
/// instance's place on it.
#[derive(Clone, Debug)]
pub struct PlannedReference {
    inputs: Arc<PlanInputs>,
    plan: Arc<Plan>,
    cursor: Cursor,
}

impl PlannedReference {
    /// At the start of the plan for `inputs`.
    pub fn new(inputs: PlanInputs, name: &dyn Fn(usize) -> String) -> Result<Self, PathError> {
        let plan = plan_for(&inputs, name)?;
        let cursor = plan.start();
        Ok(PlannedReference {
            inputs: Arc::new(inputs),
            plan,
            cursor,
        })
    }

    /// On `plan` at a saved `cursor`, checked against the plan.
    fn resume(inputs: PlanInputs, cursor: Cursor) -> Result<Self, String> {
        let plan = plan_for(&inputs, &|i| format!("pose {i}")).map_err(|e| e.to_string())?;
        cursor.filter.check()?;
        let (m1, m2) = cursor.filter.lengths();
        if (m1, m2) != plan.filter {
            return Err(format!(
                "the saved jerk filter has {m1} + {m2} samples, the plan {} + {}",
                plan.filter.0, plan.filter.1
            ));
        }
        if cursor.sample > plan.samples
            || cursor.interval + 1 >= plan.path.s.len()
            || cursor.foot + 1 >= plan.path.s.len()
            || !geometry::is_finite(&cursor.joints)
        {
            return Err("the saved place lies outside the plan".into());
        }
        Ok(PlannedReference {
            inputs: Arc::new(inputs),
            plan,
            cursor,
        })
    }

    /// The plan.
    pub fn plan(&self) -> &Arc<Plan> {
        &self.plan
    }

    /// What the plan was made from.
    pub fn inputs(&self) -> &PlanInputs {
        &self.inputs
    }

    /// The current sample.
    pub fn current(&mut self) -> PlannedSample {
        self.plan.sample(&mut self.cursor)
    }

    /// The programmed path's parameter at `source` (a place among the programmed poses,
    /// as [`PlannedSample::source`]): the polyline's own for poses, the curve's for a
    /// curve pair (sampled uniformly in it for planning).
    pub fn path_parameter(&self, source: f64) -> f64 {
        match &self.inputs.path {
            ToolPath::Poses { .. } => source,
            ToolPath::Curves { tip, .. } => {
                let (u0, u1) = crate::path::Curve::param_range(tip);
                let last = (self.plan.programmed.max(2) - 1) as f64;
                u0 + (u1 - u0) * (source / last).clamp(0.0, 1.0)
            }
        }
    }

    /// Advances one period.
    pub fn step(&mut self) -> PlannedSample {
        self.plan.advance(&mut self.cursor);
        self.current()
    }
}

impl PartialEq for PlannedReference {
    fn eq(&self, other: &Self) -> bool {
        self.inputs == other.inputs && self.cursor == other.cursor
    }
}

#[derive(serde::Serialize)]
struct SavedReference<'a> {
    inputs: SavedInputs<'a>,
    cursor: &'a Cursor,
}

#[derive(serde::Serialize)]
enum SavedInputs<'a> {
    Builtin(
        &'a str,
        &'a TableTiltingAc,
        &'a JointLimits,
        &'a PathLimits,
        f64,
    ),
    Data(&'a PlanInputs),
}

#[derive(serde::Deserialize)]
struct RestoredReference {
    inputs: RestoredInputs,
    cursor: Cursor,
}

#[derive(serde::Deserialize)]
enum RestoredInputs {
    Builtin(String, TableTiltingAc, JointLimits, PathLimits, f64),
    Data(PlanInputs),
}

impl serde::Serialize for PlannedReference {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let i = &*self.inputs;
        let inputs = match &i.builtin {
            Some(name) => SavedInputs::Builtin(name, &i.machine, &i.joints, &i.limits, i.ts),
            None => SavedInputs::Data(i),
        };
        SavedReference {
            inputs,
            cursor: &self.cursor,
        }
        .serialize(serializer)
    }
}

impl<'de> serde::Deserialize<'de> for PlannedReference {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        let saved = RestoredReference::deserialize(deserializer)?;
        let inputs = match saved.inputs {
            RestoredInputs::Builtin(name, machine, joints, limits, ts) => PlanInputs {
                path: ToolPath::builtin(&name).map_err(serde::de::Error::custom)?,
                builtin: Some(name),
                machine,
                joints,
                limits,
                ts,
            },
            RestoredInputs::Data(inputs) => inputs,
        };
        PlannedReference::resume(inputs, saved.cursor).map_err(serde::de::Error::custom)
    }
}
