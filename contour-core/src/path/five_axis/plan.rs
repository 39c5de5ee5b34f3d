//! A planned five-axis reference (docs/design/five-axis.md §5.3b): the joints chosen over
//! the whole path ([`plan_joints`]), the fastest feed along it that keeps every joint's
//! velocity and acceleration and the tool tip's feed and acceleration
//! ([`FeedProfile`]), sampled every Ts and smoothed by the jerk filter: the tip in the
//! workpiece frame, A and C as joints. All of it happens
//! once, at planning; a sample then costs O(1) whatever the path's length.
//!
//! The limits are mapped onto s node by node, with the joints linear between nodes: a
//! joint's speed is its slope times the path speed; its acceleration is the tangential
//! slope·s̈ plus what the filter makes of the path's bends at that speed, the second
//! difference of the joint over the filter's two averages (see [`Constraints`]), which
//! sees a smooth curve, a lone kink and a jog of two kinks alike. What the mapping
//! leaves approximate (the tip seen through the rotary axes, a speed that changes within
//! the filter's window, the filter's deviation from the path) is measured on the
//! samples themselves: where a sample exceeds a limit, the speed where it was planned
//! is lowered by the excess and the plan made again, until every sample keeps every
//! limit.

use std::cell::Cell;

use super::constraints::{tip_turn, Constraints};
use super::jerk_filter::JerkFilter;
use super::joint_path::{plan_joints, JointPath};
use super::programmed_feed::{check_feeds, greatest_feed, FeedChange};
use crate::geometry::{self, Vector};
use crate::kinematics::{Joints, Pose, TableTiltingAc};
use crate::limits::{JointLimits, PathLimits};
use crate::math;
use crate::path::{FeedProfile, PathError};

/// The jerk filter's quantum (mm or rad): the samples' differences are exact to it.
pub const QUANTUM: f64 = 1.0 / (1u64 << 30) as f64;
/// Rounds of plan, measure, slow down.
const ROUNDS: usize = 30;
/// The samples all rounds together may measure, in sample budgets: a plan that keeps
/// slowing down near the budget is refused after a few full-length rounds, not thirty
/// (the test paths converge within 3 rounds; a fuzzed restored state had taken 30
/// rounds of 20 000 samples under the sanitizer, past the fuzzer's 10 s).
const MEASURED_BUDGETS: u64 = 4;
/// The most samples a plan may have by default: 2²⁶, 18.6 hours at 1 ms. Planning costs
/// a few microseconds per sample and round, so this also bounds the time a restored
/// state may spend planning again.
pub const SAMPLE_BUDGET: u64 = 1 << 26;

/// Evaluations of the limits at a node (the windows of [`Constraints::bends`]) all the
/// plans and rounds of one path may make, per sample of the budget: planning costs a few
/// per node and round (the figure-eight, 930 samples on 10 322 nodes, about 55 000; the
/// fuzzers' short CL move through the pole, about 220 000), so the sample budget bounds
/// the time spent planning as well as the plan's length (at the default budget, about a
/// quarter of an hour of a release build). A fuzzed restored state with 30 times the
/// acceleration at the same jerk asked a million (a jerk filter 600 samples long, every
/// node bisected): 0.6 s in a release build, half a minute under the sanitizers.
const WORK_PER_SAMPLE: u64 = 16;

/// What a plan measured on its own samples.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FiveAxisPlanReport {
    /// From the first sample to the one at rest at the end, s.
    pub duration: f64,
    /// The velocity-and-acceleration time optimum of the programmed path: no jerk
    /// limit, no filter, so no blending; every limit judged on the samples every Ts (a
    /// kink of angle θ passed at v·2·sin(θ/2)/Ts ≤ the acceleration), s.
    pub optimum: f64,
    /// A lower bound of `optimum` that ignores the tolerances: the same with every
    /// acceleration averaged over the filter's first average T1 (a kink passed T1/Ts
    /// times faster), s.
    pub relaxed_optimum: f64,
    /// Largest distance of a planned tip from the programmed tip path, mm.
    pub tip_deviation: f64,
    /// Largest angle between a planned and the programmed tool axis, rad.
    pub orientation_deviation: f64,
    /// Plans made before every sample kept every limit.
    pub rounds: usize,
    /// Planning nodes.
    pub nodes: usize,
}

/// The plan a saved place was on, in numbers: a state is restored only onto a plan with
/// the same (one made by another build from the same inputs may differ).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct PlanSummary {
    /// Samples until the reference rests at the path's end.
    pub samples: u64,
    /// The jerk filter's two averages, samples.
    pub filter: (u64, u64),
    /// Planning nodes.
    pub nodes: u64,
}

/// A plan: what every sample is computed from.
#[derive(Debug)]
pub struct FiveAxisPlan {
    pub(super) path: JointPath,
    /// How many programmed poses the plan was made from.
    pub(super) programmed: usize,
    feed: FeedProfile,
    machine: TableTiltingAc,
    ts: f64,
    pub(super) filter: (usize, usize),
    /// How far the tip may leave the programmed path, mm (see `deviation`).
    tolerance: f64,
    /// Samples until the reference rests at the path's end.
    pub(super) samples: u64,
    report: FiveAxisPlanReport,
}

/// Where a reference stands among its samples; what an FMU saves of it.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct FiveAxisCursor {
    /// The current sample's number (sample k at time k·Ts).
    pub(super) sample: u64,
    /// The feed plan's node interval of the current raw sample.
    pub(super) interval: usize,
    pub(super) filter: JerkFilter<5>,
    pub(super) joints: Joints,
    /// The programmed path's node interval nearest the current planned tip.
    pub(super) foot: usize,
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

impl FiveAxisPlan {
    /// Plans the path through `poses` (see the module's text); `name` names a programmed
    /// pose in messages.
    pub fn new(
        poses: &[Pose],
        machine: TableTiltingAc,
        joints: &JointLimits,
        limits: &PathLimits,
        ts: f64,
        name: &dyn Fn(usize) -> String,
    ) -> Result<FiveAxisPlan, PathError> {
        Self::within_budget(
            (poses, &[]),
            machine,
            joints,
            limits,
            ts,
            name,
            SAMPLE_BUDGET,
        )
    }

    /// [`FiveAxisPlan::new`] with the program's speeds move by move (`feeds`, see
    /// [`FeedChange`]; `limits.feed` before the first), refusing a plan of more than
    /// `budget` samples (see [`SAMPLE_BUDGET`]).
    pub fn within_budget(
        (poses, feeds): (&[Pose], &[FeedChange]),
        machine: TableTiltingAc,
        joints: &JointLimits,
        limits: &PathLimits,
        ts: f64,
        name: &dyn Fn(usize) -> String,
        budget: u64,
    ) -> Result<FiveAxisPlan, PathError> {
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
        check_feeds(feeds, poses.len())?;
        // Fine enough for the braking distances the feed planner integrates.
        let fastest = greatest_feed(feeds, limits.feed);
        let braking = fastest * fastest / (2.0 * limits.accel);
        let spacing = (braking / 10.0)
            .clamp(5e-3, 0.5)
            .min(fastest * ts)
            .max(1e-4);
        // At the feed throughout the path would take this many samples at least: refuse
        // before any work what the budget cannot hold.
        let length: f64 = poses
            .windows(2)
            .map(|w| geometry::dist(&w[0].tip, &w[1].tip))
            .sum();
        let least = length / (fastest * ts);
        if least.is_nan() || least > budget as f64 {
            return Err(PathError::invalid(format!(
                "the path is {length:.6e} mm long: at {fastest} mm/s that is more than the \
                 {budget} samples a plan may have"
            )));
        }
        let path = plan_joints(poses, feeds, &machine, joints, limits, spacing, name)?;
        // Planning costs a few tens of microseconds per node and round: a path with far
        // more nodes than the samples it may have is refused too (a fuzzed path of tiny
        // moves that the joints' refinement multiplies).
        let nodes = path.s.len() as u64;
        if nodes > 2 * budget {
            return Err(PathError::invalid(format!(
                "the path needs {nodes} planning nodes: more than twice the {} samples a \
                 plan may have",
                budget
            )));
        }
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
        let unknown = || vec![Cell::new(f64::NAN); path.s.len()];
        let work = Cell::new(WORK_PER_SAMPLE.saturating_mul(budget));
        let worked = |feed: FeedProfile| -> Result<FeedProfile, PathError> {
            if work.get() == 0 {
                return Err(PathError::invalid(format!(
                    "planning this path needs more than {} evaluations of the limits ({} \
                     per sample of the {} a plan may have)",
                    WORK_PER_SAMPLE.saturating_mul(budget),
                    WORK_PER_SAMPLE,
                    budget
                )));
            }
            Ok(feed)
        };
        let optimum_with = |first: usize| -> Result<f64, PathError> {
            let top_speed = unknown();
            let constraints = Constraints::new(
                &path,
                joints,
                limits,
                (first, 0, ts),
                (&speed_scale, &accel_scale),
                &top_speed,
                &work,
            );
            Ok(worked(FeedProfile::plan(&constraints)?)?.duration())
        };
        // Both optima are lower bounds of the plan's duration: a plan they already put
        // beyond the budget is refused before any round.
        let within_budget = |duration: f64| -> Result<f64, PathError> {
            let samples = (duration / ts).ceil() + (filter.0 + filter.1) as f64;
            if samples.is_nan() || samples > budget as f64 {
                return Err(PathError::invalid(format!(
                    "the planned reference takes at least {duration:.0} s: more than the {} \
                     samples a plan may have",
                    budget
                )));
            }
            Ok(duration)
        };
        let optimum = within_budget(optimum_with(1)?)?;
        let relaxed_optimum = within_budget(optimum_with(filter.0)?)?;
        let top_speed = unknown();
        let mut measured = 0u64;
        for round in 1..=ROUNDS {
            let feed = worked(FeedProfile::plan(&Constraints::new(
                &path,
                joints,
                limits,
                (filter.0, filter.1, ts),
                (&speed_scale, &accel_scale),
                &top_speed,
                &work,
            ))?)?;
            let raw = (feed.duration() / ts).ceil();
            if raw.is_nan() || raw + (filter.0 + filter.1) as f64 > budget as f64 {
                return Err(PathError::invalid(format!(
                    "the planned reference takes {:.0} s: more than the {budget} samples a \
                     plan may have",
                    feed.duration()
                )));
            }
            let mut plan = FiveAxisPlan {
                samples: raw as u64 + (filter.0 + filter.1) as u64,
                programmed: poses.len(),
                path,
                feed,
                machine,
                ts,
                filter,
                tolerance: limits.tolerance,
                report: FiveAxisPlanReport::default(),
            };
            measured = measured.saturating_add(plan.samples);
            if measured > MEASURED_BUDGETS * budget {
                return Err(PathError::invalid(format!(
                    "no feed found within the limits after {} plans of up to {} samples \
                     ({MEASURED_BUDGETS} times the {budget} samples a plan may have)",
                    round - 1,
                    plan.samples
                )));
            }
            let (report, slow) = plan.measure(joints, limits);
            if slow.is_empty() {
                plan.report = FiveAxisPlanReport {
                    rounds: round,
                    optimum,
                    relaxed_optimum,
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
                if round_accel[n] < 1.0 {
                    accel_scale[n] *= round_accel[n];
                    top_speed[n].set(f64::NAN);
                }
            }
            path = plan.path;
        }
        Err(PathError::invalid(format!(
            "no feed found within the limits after {ROUNDS} plans"
        )))
    }

    /// What a saved place on the plan checks the plan against.
    pub fn summary(&self) -> PlanSummary {
        PlanSummary {
            samples: self.samples,
            filter: (self.filter.0 as u64, self.filter.1 as u64),
            nodes: self.nodes() as u64,
        }
    }

    /// The plan's nodes along the path.
    pub fn nodes(&self) -> usize {
        self.path.s.len()
    }

    /// What the plan measured on its samples.
    pub fn report(&self) -> &FiveAxisPlanReport {
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
    pub fn start(&self) -> FiveAxisCursor {
        let (raw, _, _) = self.raw(0.0, 0);
        let (end, _, _) = self.raw(self.feed.duration(), self.path.s.len() - 2);
        FiveAxisCursor {
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
    pub fn advance(&self, cursor: &mut FiveAxisCursor) {
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

    /// The joints of the sample after `cursor`'s (its own at the end), `cursor` unchanged.
    pub fn peek(&self, cursor: &FiveAxisCursor) -> Joints {
        if cursor.sample >= self.samples {
            return cursor.joints;
        }
        let t = (cursor.sample + 1) as f64 * self.ts;
        let (raw, _, _) = self.raw(t, cursor.interval);
        self.joints_of(&cursor.filter.peek(&raw))
    }

    /// The sample `cursor` stands at, its deviation from the programmed path measured
    /// from the programmed interval nearest the previous one (which `cursor` keeps).
    pub fn sample(&self, cursor: &mut FiveAxisCursor) -> PlannedSample {
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
    /// distance and the axis's angle from the programmed pose at that point. Where the
    /// tool turns on the spot, every axis of the turn is programmed at that tip: within
    /// `tolerance` of it the angle is the least to any of them (the filter blends the
    /// arrival with the turn, and no speed along the path changes that).
    fn deviation(&self, pose: &Pose, from: usize, ahead: usize) -> (usize, f64, f64) {
        let poses = &self.path.poses;
        let last = poses.len() - 2;
        let (start, end) = (
            from.saturating_sub(2).min(last),
            (ahead + 1).max(from).min(last),
        );
        let mut best = (start, f64::INFINITY, 0.0);
        let mut on_a_turn = f64::INFINITY;
        for n in start..=end {
            let (a, b) = (poses[n].tip, poses[n + 1].tip);
            let d = b - a;
            let length2 = d.norm_squared();
            let t = if length2 > 0.0 {
                ((pose.tip - a).dot(&d) / length2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let distance = geometry::dist(&(a + d * t), &pose.tip);
            if length2 == 0.0 && distance <= self.tolerance {
                let turn = angle_to_arc(&poses[n].axis, &poses[n + 1].axis, &pose.axis);
                on_a_turn = on_a_turn.min(turn);
            }
            if distance < best.1 {
                best = (n, distance, t);
            }
        }
        // Leaving a turn, the nodes of the turn lie behind the search.
        let mut n = start;
        while n > 0
            && poses[n - 1].tip == poses[n].tip
            && geometry::dist(&poses[n].tip, &pose.tip) <= self.tolerance
        {
            let turn = angle_to_arc(&poses[n - 1].axis, &poses[n].axis, &pose.axis);
            on_a_turn = on_a_turn.min(turn);
            n -= 1;
        }
        let (n, distance, t) = best;
        let axis = geometry::slerp(&poses[n].axis, &poses[n + 1].axis, t).unwrap_or(poses[n].axis);
        let angle = geometry::angle_between(&axis, &pose.axis).min(on_a_turn);
        (n, distance, angle)
    }

    /// The programmed speed a filtered sample at speed `v` is held to: its foot's piece's
    /// (`foot`), or where that is exceeded the greatest of the pieces its raw samples
    /// came from (`first..=last`), since the filter carries a speed change over its
    /// window as a controller's filter after interpolation does.
    fn feed_near(&self, foot: usize, first: usize, last: usize, v: f64) -> f64 {
        let feed = &self.path.feed;
        let here = feed[foot.min(feed.len() - 1)];
        if v <= here {
            return here;
        }
        let last = (last + 1).min(feed.len() - 1);
        feed[first.min(last)..=last]
            .iter()
            .fold(here, |m, &f| m.max(f))
    }

    /// The node in `first..=last` where the tip's path turns most.
    fn sharpest_turn(&self, first: usize, last: usize) -> usize {
        // The chord between the directions: it grows up to a reversal (a sine would fall
        // back to 0 there).
        let turn =
            |n: usize| tip_turn(&self.path, n).map_or(0.0, |(b, a)| geometry::norm(&(a - b)));
        (first..=last)
            .max_by(|&m, &n| turn(m).total_cmp(&turn(n)))
            .unwrap_or(first)
    }

    /// Runs every sample and measures it against the limits: the report, and for every
    /// node where a sample exceeded one, the factors its speed squared and acceleration
    /// must be scaled by.
    fn measure(
        &self,
        joints: &JointLimits,
        limits: &PathLimits,
    ) -> (FiveAxisPlanReport, Vec<(usize, f64, f64)>) {
        let ts = self.ts;
        let mut cursor = self.start();
        let mut history: [Option<(Joints, Vector<3>)>; 3] = [None; 3];
        let mut report = FiveAxisPlanReport {
            duration: self.samples as f64 * ts,
            ..FiveAxisPlanReport::default()
        };
        let mut slow: Vec<(usize, f64, f64)> = Vec::new();
        let window = self.filter.0 + self.filter.1;
        let mut intervals = std::collections::VecDeque::with_capacity(window + 1);
        // Where the tip turns back by more than 90° (a plunge and its retract, a
        // zigzag's end), the distance to the path does not see a corner cut short (the
        // tip stays on the path as it turns back early): the nearest sample to such a
        // corner must come within the tolerance of it. Per corner: that distance and the
        // nodes the sample averaged.
        let mut reach: Vec<(usize, f64, (usize, usize))> = (1..self.path.poses.len())
            .filter(|&n| tip_turn(&self.path, n).is_some_and(|(b, a)| b.dot(&a) < 0.0))
            .map(|n| (n, f64::INFINITY, (n, n)))
            .collect();
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
                let feed = self.feed_near(cursor.foot, intervals[0], cursor.interval, v);
                if v > feed * (1.0 + 1e-6) {
                    speed_factor = speed_factor.min((feed / v).powi(2));
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
                        speed_factor = speed_factor.min(math::pow(r, 2.0 / 3.0));
                        accel_factor = accel_factor.min(r);
                    }
                }
            }
            // Every raw sample this one averaged: the nodes from the oldest interval to
            // the newest.
            let (first, last) = (
                intervals[0],
                (cursor.interval + 1).min(self.path.s.len() - 1),
            );
            if speed_factor < 1.0 || accel_factor < 1.0 {
                let accel = if accel_factor < 1.0 {
                    0.95 * accel_factor
                } else {
                    1.0
                };
                for n in first..=last {
                    slow.push((n, 0.9 * speed_factor, accel));
                }
            }
            // The tip leaves the path where it turns most among those nodes (a corner):
            // slow there alone, as for a kink, whose deviation grows with v (a curve's
            // grows with v²: it gives up a little more speed).
            if sample.tip_deviation > limits.tolerance {
                let r = limits.tolerance / sample.tip_deviation;
                let corner = self.sharpest_turn(first, last);
                for n in corner.saturating_sub(1)..=(corner + 1).min(last) {
                    slow.push((n, 0.9 * r * r, 1.0));
                }
            }
            if sample.orientation_deviation > limits.orientation_tolerance {
                let r = limits.orientation_tolerance / sample.orientation_deviation;
                for n in first..=last {
                    slow.push((n, 0.9 * r * r, 1.0));
                }
            }
            let from = reach.partition_point(|c| c.0 < first);
            for corner in reach[from..].iter_mut().take_while(|c| c.0 <= last) {
                let d = geometry::dist(&tip, &self.path.poses[corner.0].tip);
                if d < corner.1 {
                    (corner.1, corner.2) = (d, (first, last));
                }
            }
            history = [Some((cursor.joints, tip)), history[0], history[1]];
            if sample.done {
                break;
            }
            self.advance(&mut cursor);
        }
        for &(_, nearest, (first, last)) in &reach {
            report.tip_deviation = report.tip_deviation.max(nearest.min(1e300));
            if nearest > limits.tolerance && nearest.is_finite() {
                // The shortfall grows with the speed near the corner.
                let r = limits.tolerance / nearest;
                for n in first..=last {
                    slow.push((n, 0.9 * r * r, 1.0));
                }
            }
        }
        (report, slow)
    }
}

/// The angle from unit `v` to the great-circle arc from unit `a` to unit `b` (not
/// opposite), rad.
fn angle_to_arc(a: &Vector<3>, b: &Vector<3>, v: &Vector<3>) -> f64 {
    let ends = geometry::angle_between(a, v).min(geometry::angle_between(b, v));
    let Some(normal) = geometry::unit(&a.cross(b)) else {
        return ends;
    };
    // v's projection onto the arc's plane lies within the arc when it is on a's side of
    // b and on b's side of a; then the angle is v's to the plane.
    let inside = a.cross(v).dot(&normal) >= 0.0 && v.cross(b).dot(&normal) >= 0.0;
    if inside {
        math::asin(v.dot(&normal).abs().min(1.0)).min(ends)
    } else {
        ends
    }
}
