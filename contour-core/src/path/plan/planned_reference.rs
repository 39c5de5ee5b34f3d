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

use crate::math;
use std::cell::Cell;
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
/// The samples all rounds together may measure, in sample budgets: a plan that keeps
/// slowing down near the budget is refused after a few full-length rounds, not thirty
/// (the test paths converge within 3 rounds; a fuzzed restored state had taken 30
/// rounds of 20 000 samples under the sanitizer, past the fuzzer's 10 s).
const MEASURED_BUDGETS: u64 = 4;
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
pub struct PlanReport {
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
/// Between nodes every joint moves linearly in s. A sample's acceleration after the two
/// moving averages (T1 = m1·Ts, then T2 = m2·Ts) is exactly
/// [(r_k − r_{k−m2})/T2 − (r_{k−m1} − r_{k−m1−m2})/T2]/T1 of the raw samples r: the
/// change, over T1, of the raw velocity averaged over T2. At a speed v that is the
/// second difference of the joint's path over the stretches ℓ1 = v·T1 and ℓ2 = v·T2,
/// times v²/(ℓ1·ℓ2): v²·q'' on a smooth path, v·Δg/T1 at a lone kink, and at a jog
/// shorter than ℓ2 (two kinks close together, which a difference of slopes across ℓ1
/// does not see) v·δ/(T1·T2). That difference is piecewise linear in the window's
/// place, so its extremes are where a window's edge meets a node: each node is judged
/// at the places where its own kink meets an edge. The tip's acceleration is the same
/// vector difference of its positions. Without the filter (the optimum the plan is
/// compared with) T2 is the samples' own Ts.
struct Constraints<'a> {
    path: &'a JointPath,
    joints: &'a JointLimits,
    limits: &'a PathLimits,
    /// The filter's first average T1, s (Ts without a filter).
    spread: f64,
    /// The filter's second average T2, s (Ts without it).
    spread2: f64,
    /// The sum of the two averages' lengths squared, s² (0 without a filter): a curve
    /// of curvature κ is drawn in by v²·κ·Σ T²/24.
    smoothing2: f64,
    /// How far, as a time, the filter's samples reach on average beyond a corner
    /// (E|τ| of its kernel: T1/4 + T2²/(12·T1); 0 without a filter): at speed v a
    /// lone kink of angle θ is cut by v·E|τ|·sin θ/2.
    corner_reach: f64,
    /// Per node: the sine of the tip path's turn there.
    kink: Vec<f64>,
    /// Per piece between nodes: each joint's slope.
    slope: Vec<Joints>,
    /// Per node: how much of the speed squared and of the acceleration the samples
    /// allowed.
    speed_scale: &'a [f64],
    accel_scale: &'a [f64],
    /// Per node: the largest speed at its acceleration scale, once found (NaN before);
    /// kept from round to round, since a round changes few nodes' scales.
    top_speed: &'a [Cell<f64>],
    /// The last node, speed and bends found.
    last_bends: Cell<Option<(usize, f64, Bends)>>,
    /// The evaluations of the limits the plan may still make (`WORK_PER_SAMPLE`); at 0
    /// the rest of this feed plan sees only the slopes, and the plan is refused.
    work: &'a Cell<u64>,
}

impl<'a> Constraints<'a> {
    fn new(
        path: &'a JointPath,
        joints: &'a JointLimits,
        limits: &'a PathLimits,
        filter: (usize, usize, f64),
        scales: (&'a [f64], &'a [f64]),
        top_speed: &'a [Cell<f64>],
        work: &'a Cell<u64>,
    ) -> Self {
        let (m1, m2, ts) = filter;
        let count = path.s.len();
        // m2 = 0: the same spread without the filter's deviation (and a 1 + 1 filter is
        // no filter).
        let smooths = m2 > 0 && m1 + m2 > 2;
        let (t1, t2) = (m1 as f64 * ts, m2 as f64 * ts);
        Constraints {
            path,
            joints,
            limits,
            spread: m1 as f64 * ts,
            spread2: m2.max(1) as f64 * ts,
            smoothing2: if smooths {
                ((m1 * m1 + m2 * m2) as f64) * ts * ts
            } else {
                0.0
            },
            corner_reach: if smooths {
                t1 / 4.0 + t2 * t2 / (12.0 * t1)
            } else {
                0.0
            },
            kink: (0..count)
                .map(|n| tip_turn(path, n).map_or(0.0, |(b, a)| geometry::norm(&b.cross(&a))))
                .collect(),
            slope: (0..count - 1)
                .map(|n| (path.joints[n + 1] - path.joints[n]) / (path.s[n + 1] - path.s[n]))
                .collect(),
            speed_scale: scales.0,
            accel_scale: scales.1,
            top_speed,
            last_bends: Cell::new(None),
            work,
        }
    }

    /// The joints and the tip at `s` (mm along the path), linear between nodes and
    /// beyond the ends: a window reaching past an end sees no kink there (the speed,
    /// not the path, comes to rest, and the tangential term holds the acceleration).
    /// Searched outwards from node `near`: a window is a few nodes wide, so this costs
    /// O(log of the nodes it spans) however long the path.
    fn at(&self, s: f64, near: usize) -> (Joints, Vector<3>) {
        let nodes = &self.path.s;
        let last = nodes.len() - 1;
        let near = near.min(last);
        // The last node at or before s (0 before the path).
        let below = if nodes[near] <= s {
            let (mut lo, mut step) = (near, 1);
            loop {
                let hi = (lo + step).min(last);
                if hi == lo || nodes[hi] > s {
                    break lo + nodes[lo..=hi].partition_point(|&x| x <= s) - 1;
                }
                lo = hi;
                step *= 2;
            }
        } else {
            let (mut hi, mut step) = (near, 1);
            loop {
                let lo = hi.saturating_sub(step);
                if lo == hi || nodes[lo] <= s {
                    break (lo + nodes[lo..=hi].partition_point(|&x| x <= s)).saturating_sub(1);
                }
                hi = lo;
                step *= 2;
            }
        };
        let m = below.min(last - 1);
        let (joints, poses) = (&self.path.joints, &self.path.poses);
        let f = (s - nodes[m]) / (nodes[m + 1] - nodes[m]);
        (
            joints[m] + (joints[m + 1] - joints[m]) * f,
            poses[m].tip + (poses[m + 1].tip - poses[m].tip) * f,
        )
    }

    /// At node `n` and speed `v`: each joint's slope (the larger of the pieces beside
    /// it); the least and greatest of its accelerations per speed squared over the
    /// windows that meet the node (see the type's text); and the largest such
    /// acceleration of the tip, its curvature as the samples see it (none at rest).
    fn bends(&self, n: usize, v: f64) -> Bends {
        // The feed planner asks a node again at the speed it just settled on.
        if let Some((m, w, bends)) = self.last_bends.get() {
            if (m, w) == (n, v) {
                return bends;
            }
        }
        let bends = self.bends_now(n, v);
        self.last_bends.set(Some((n, v, bends)));
        bends
    }

    /// [`Constraints::bends`] without the cache.
    fn bends_now(&self, n: usize, v: f64) -> Bends {
        let last = self.slope.len() - 1;
        let (g_in, g_out) = (
            self.slope[n.saturating_sub(1).min(last)],
            self.slope[n.min(last)],
        );
        let slope = g_in.zip_map(&g_out, |a, b| if a.abs() > b.abs() { a } else { b });
        let (l1, l2) = (v * self.spread, v * self.spread2);
        let mut bends = Bends {
            slope,
            least: Joints::zeros(),
            greatest: Joints::zeros(),
            curvature: 0.0,
        };
        if n == 0 || n > last || l1.is_nan() || l1 <= 0.0 || l2 <= 0.0 || self.work.get() == 0 {
            return bends;
        }
        self.work.set(self.work.get() - 1);
        let (a, b) = (0.5 * l1, 0.5 * l2);
        let (centre, area) = (self.path.s[n], l1 * l2);
        for place in [0.0, a - b, b - a, a + b, -a - b] {
            let c = centre + place;
            let (q1, t1) = self.at(c + a + b, n);
            let (q2, t2) = self.at(c + a - b, n);
            let (q3, t3) = self.at(c - a + b, n);
            let (q4, t4) = self.at(c - a - b, n);
            let bend = (q1 - q2 - q3 + q4) / area;
            bends.least = bends.least.inf(&bend);
            bends.greatest = bends.greatest.sup(&bend);
            let tip = (t1 - t2 - t3 + t4) / area;
            bends.curvature = bends.curvature.max(geometry::norm(&tip));
        }
        bends
    }

    /// The largest speed at node `n` (mm/s) its limits allow at zero path acceleration.
    fn top_speed_at(&self, n: usize) -> f64 {
        let mut top = self.limits.feed;
        // The slopes on both sides: the speed is the same at the node.
        let slope = self.bends(n, 0.0).slope;
        for i in 0..5 {
            if slope[i] != 0.0 {
                top = top.min(self.joints.velocity[i] / slope[i].abs());
            }
        }
        let scale = self.accel_scale[n];
        let accel = self.limits.accel * scale;
        let tolerance = self.limits.tolerance;
        Self::largest_speed(top, |v| {
            let bends = self.bends(n, v);
            let x = v * v;
            let joints_ok = (0..5).all(|i| {
                let bend = bends.least[i].abs().max(bends.greatest[i].abs());
                bend * x <= self.joints.acceleration[i] * scale
            });
            let turn = bends.curvature;
            // A curve drawn in, or a corner cut.
            let deviation =
                (x * turn * self.smoothing2 / 24.0).max(v * self.corner_reach * self.kink[n] / 2.0);
            joints_ok && turn * x <= accel && deviation <= tolerance
        })
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
        let known = self.top_speed[n].get();
        let v = if known.is_nan() {
            let v = self.top_speed_at(n);
            self.top_speed[n].set(v);
            v
        } else {
            known
        };
        v * v * self.speed_scale[n]
    }

    fn accel_range(&self, n: usize, x: f64) -> (f64, f64) {
        let v = x.max(0.0).sqrt();
        let bends = self.bends(n, v);
        let scale = self.accel_scale[n];
        let accel = self.limits.accel * scale;
        let normal = bends.curvature * x;
        let tangential = (accel * accel - normal * normal).max(0.0).sqrt();
        let (mut lo, mut hi) = (-tangential, tangential);
        for i in 0..5 {
            let g = bends.slope[i];
            if g.abs() < 1e-12 {
                continue;
            }
            let amax = self.joints.acceleration[i] * scale;
            // g·s̈ + bend·x within ±amax for every bend the windows saw.
            let (a, b) = (
                (-amax - bends.least[i] * x) / g,
                (amax - bends.greatest[i] * x) / g,
            );
            lo = lo.max(a.min(b));
            hi = hi.min(a.max(b));
        }
        (lo, hi)
    }
}

/// The tip's unit directions before and after node `n` (none at the ends or beside a
/// zero-length piece).
fn tip_turn(path: &JointPath, n: usize) -> Option<(Vector<3>, Vector<3>)> {
    let poses = &path.poses;
    if n == 0 || n + 1 >= poses.len() {
        return None;
    }
    let before = geometry::unit(&(poses[n].tip - poses[n - 1].tip))?;
    let after = geometry::unit(&(poses[n + 1].tip - poses[n].tip))?;
    Some((before, after))
}

/// What [`Constraints::bends`] finds at a node.
#[derive(Clone, Copy)]
struct Bends {
    slope: Joints,
    least: Joints,
    greatest: Joints,
    curvature: f64,
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
        // Planning costs a few tens of microseconds per node and round: a path with far
        // more nodes than the samples it may have is refused too (a fuzzed path of tiny
        // moves that the joints' refinement multiplies).
        let nodes = path.s.len() as u64;
        if nodes > 2 * sample_budget() {
            return Err(PathError::invalid(format!(
                "the path needs {nodes} planning nodes: more than twice the {} samples a \
                 plan may have",
                sample_budget()
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
        let work = Cell::new(WORK_PER_SAMPLE.saturating_mul(sample_budget()));
        let worked = |feed: FeedProfile| -> Result<FeedProfile, PathError> {
            if work.get() == 0 {
                return Err(PathError::invalid(format!(
                    "planning this path needs more than {} evaluations of the limits ({} \
                     per sample of the {} a plan may have)",
                    WORK_PER_SAMPLE.saturating_mul(sample_budget()),
                    WORK_PER_SAMPLE,
                    sample_budget()
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
            if samples.is_nan() || samples > sample_budget() as f64 {
                return Err(PathError::invalid(format!(
                    "the planned reference takes at least {duration:.0} s: more than the {} \
                     samples a plan may have",
                    sample_budget()
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
                plan.report = PlanReport {
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

    /// The joints of the sample after `cursor`'s (its own at the end), `cursor` unchanged.
    pub fn peek(&self, cursor: &Cursor) -> Joints {
        if cursor.sample >= self.samples {
            return cursor.joints;
        }
        let t = (cursor.sample + 1) as f64 * self.ts;
        let (raw, _, _) = self.raw(t, cursor.interval);
        self.joints_of(&cursor.filter.peek(&raw))
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

/// The plans used last, kept alive after their instances let go of them: restoring a
/// state checks it (a plan made and dropped) and then takes it (the same plan again), and
/// an importer that rolls back between states of two plans would plan each time.
static RECENT: Mutex<[Option<Arc<Plan>>; RECENT_PLANS]> = Mutex::new([None, None]);
const RECENT_PLANS: usize = 2;
/// Larger plans are not kept beyond their instances (about 120 bytes a node).
const RECENT_NODES: usize = 200_000;

/// Puts `plan` first among the recent plans.
fn remember(plan: &Arc<Plan>) {
    if plan.path.s.len() > RECENT_NODES {
        return;
    }
    let mut recent = RECENT.lock().unwrap_or_else(|e| e.into_inner());
    let at = recent
        .iter()
        .position(|p| p.as_ref().is_some_and(|p| Arc::ptr_eq(p, plan)))
        .unwrap_or(RECENT_PLANS - 1);
    recent[..=at].rotate_right(1);
    recent[0] = Some(Arc::clone(plan));
}

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
            drop(plans);
            remember(&plan);
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
    remember(&plan);
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

    /// The current sample's joints.
    pub fn joints(&self) -> Joints {
        self.cursor.joints
    }

    /// Whether the reference rests at the path's end.
    pub fn is_done(&self) -> bool {
        self.cursor.sample >= self.plan.samples
    }

    /// The joints of the next sample, the reference unchanged.
    pub fn peek(&self) -> Joints {
        self.plan.peek(&self.cursor)
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
