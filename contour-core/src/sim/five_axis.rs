//! In-process five-axis closed loop: joint reference (planned within the machine's
//! limits, or at constant tip feed through the inverse kinematics) →
//! five-axis controller → five servo axes, sampled every `Ts` (docs/design/five-axis.md §5.5), with
//! the true contour errors for the metrics.
//!
//! The sample sequence is the two-axis one (module docs of `sim`): for k = 0, 1, …
//! reference joints q_r,k (the start at k = 0, then one interpolator step each), measured
//! joints q_k = plant position at t_k, `controller.sample(q_r,k, q_k)`, record, then the
//! plant integrates the command over [t_k, t_k+1). The plant starts at rest at the start
//! joints. The run ends `settle` seconds after the reference is done.
//!
//! True errors: the actual tip's nearest point on the exact reference (a polyline with
//! slerped axes is exact: searched segment by segment in closed form; a curve pair by a
//! dense scan refined by golden section), on the branch being traced — the search covers
//! the reference parameters of the last `TRUTH_WINDOW` samples, so on the figure-eight the
//! other branch through the crossing is never taken. The orientation error is the angle
//! between the actual tool axis and the reference axis at that nearest point.

use std::sync::Arc;

use serde::{Deserialize, Serialize};

use super::config::SimError;
use super::metrics::{Divergence, DivergenceKind};
use crate::contour::five_axis::evaluation_online::PointEvaluation;
use crate::contour::five_axis::hmm::segment_fraction;
use crate::control::{CccMode, FiveAxisConfig, FiveAxisController, Hold};
use crate::geometry::{self, angle_between, Vector};
use crate::kinematics::Joints;
use crate::limits::{JointLimits, PathLimits};
use crate::path::five_axis::{FeedChange, FiveAxisInputs, FiveAxisReference, Planner, ToolPath};
use crate::path::{Curve, PathError};
use crate::plant::{ServoAxes, ServoAxesParams};

/// Reference samples the truth search looks back over: the default loops trail by about
/// 35 samples, up to 65 through the figure-eight's tightest bends; 150 leaves room and
/// stays far from the other branch through the crossing (about 1800 samples away).
const TRUTH_WINDOW: usize = 150;

/// A five-axis closed-loop run.
#[derive(Clone, Debug)]
pub struct FiveAxisSimConfig {
    /// The reference tool path.
    pub path: ToolPath,
    /// The built-in's name when the path is one (plans of it are shared by name).
    pub builtin: Option<String>,
    /// A CL file's speeds move by move (see [`ToolPath::load_with_feeds`]); none:
    /// `path_limits.feed` throughout.
    pub feeds: Vec<FeedChange>,
    /// The tip's feed and, with `accel` > 0, the plan's limits and tolerances (see
    /// [`FiveAxisReference`]).
    pub path_limits: PathLimits,
    /// The joints' limits a plan keeps.
    pub joint_limits: JointLimits,
    /// The five-axis controller.
    pub controller: FiveAxisConfig,
    /// The five servo axes, X Y Z A C.
    pub plant: ServoAxesParams<5>,
    /// Seconds simulated after the reference is done.
    pub settle: f64,
    /// The run stops when the true tip error exceeds this, mm. Default 10 mm.
    pub abort_tip_error: f64,
    /// Makes and keeps the plans: configs cloned from one share it, so their runs on one
    /// path and limits plan once.
    pub planner: Arc<Planner>,
}

impl FiveAxisSimConfig {
    /// `path` at `feed` planned within the default limits, with the default controller
    /// (fuzzy CCC on both errors) and the trunnion-table plant, 0.1 s of settling.
    pub fn new(path: ToolPath, feed: f64) -> Self {
        FiveAxisSimConfig {
            path,
            builtin: None,
            feeds: Vec::new(),
            path_limits: PathLimits::at_feed(feed),
            joint_limits: JointLimits::default(),
            controller: FiveAxisConfig::DEFAULT,
            plant: ServoAxesParams::<5>::TRUNNION,
            settle: 0.1,
            abort_tip_error: 10.0,
            planner: Arc::new(Planner::new()),
        }
    }

    /// A built-in five-axis path (`tilted_helix`, `figure_eight`) at 50 mm/s.
    pub fn builtin(name: &str) -> Result<Self, PathError> {
        let mut config = Self::new(ToolPath::builtin(name)?, 50.0);
        config.builtin = Some(name.to_owned());
        Ok(config)
    }

    /// The reference at constant feed, unplanned (`accel` = 0: the loop before limits).
    pub fn unplanned(mut self) -> Self {
        self.path_limits.accel = 0.0;
        self
    }

    /// Both contour laws in `mode`.
    pub fn with_mode(mut self, mode: CccMode) -> Self {
        self.controller = self.controller.with_mode(mode);
        self
    }
}

/// One recorded sample.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct FiveAxisRecord {
    /// s.
    pub t: f64,
    /// Joint reference (mm, rad).
    pub reference: Joints,
    /// Measured joints (mm, rad).
    pub actual: Joints,
    /// Velocity commands (mm/s, rad/s).
    pub u: Joints,
    /// True tip contour error, mm.
    pub tip: f64,
    /// True orientation contour error, rad.
    pub orientation: f64,
    /// The controller's foot-point tip estimate, mm (NaN before the mapping has a segment).
    pub tip_estimate: f64,
    /// The controller's foot-point orientation estimate, rad (NaN likewise).
    pub orientation_estimate: f64,
    /// The actual tip's nearest reference parameter.
    pub foot: f64,
    /// The reference segment the controller mapped the sample to (index of its first
    /// reference sample among the distinct ones).
    pub segment: Option<usize>,
    /// The reference's parameter at this sample.
    pub reference_u: f64,
    /// The controller's newest evaluation-function estimate.
    pub evaluation: Option<PointEvaluation>,
    /// The correction's weight (1 full, 0 stood aside).
    pub weight: f64,
    /// Why it stood aside.
    #[serde(skip)]
    pub hold: Hold,
}

/// Summary of a five-axis run (true errors).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct FiveAxisMetrics {
    /// Samples run.
    pub samples: usize,
    /// Largest tip error, mm.
    pub max_tip: f64,
    /// Mean tip error, mm.
    pub mean_tip: f64,
    /// Largest orientation error, rad.
    pub max_orientation: f64,
    /// Mean orientation error, rad.
    pub mean_orientation: f64,
    /// Largest |tip estimate − truth| over the samples with an estimate, mm.
    pub max_tip_estimate_deviation: f64,
    /// Largest |orientation estimate − truth| likewise, rad.
    pub max_orientation_estimate_deviation: f64,
    /// Largest distance of the reference's tip from the programmed path, mm: the plan's
    /// share of the true errors, which the controller (seeing only the reference) cannot
    /// know (0 without a plan).
    pub max_reference_tip_deviation: f64,
    /// Largest angle of the reference's tool axis from the programmed one, rad.
    pub max_reference_orientation_deviation: f64,
    /// Set when the run stopped early.
    pub divergence: Option<Divergence>,
}

/// The nearest point of the reference's tip to `point` for parameters in `[lo, hi]`:
/// (parameter, distance).
pub fn nearest_on_branch(path: &ToolPath, point: &Vector<3>, lo: f64, hi: f64) -> (f64, f64) {
    match path {
        ToolPath::Poses { tips, .. } => {
            let points = &tips[..];
            let last = points.len() - 2;
            let first = (lo.floor().max(0.0) as usize).min(last);
            let end = (hi.ceil().max(0.0) as usize).clamp(first, last);
            let mut best = (f64::INFINITY, 0.0);
            for i in first..=end {
                let t = segment_fraction(point, &points[i], &points[i + 1]);
                let u = (i as f64 + t).clamp(lo, hi);
                let distance = geometry::dist(&path.pose_at(u).tip, point);
                if distance < best.0 {
                    best = (distance, u);
                }
            }
            (best.1, best.0)
        }
        ToolPath::Curves { tip, .. } => {
            const SCAN: usize = 256;
            let at = |k: usize| lo + (hi - lo) * k as f64 / SCAN as f64;
            let distance = |u: f64| geometry::dist(&tip.point(u), point);
            let best = (0..=SCAN).fold(0, |b, k| {
                if distance(at(k)) < distance(at(b)) {
                    k
                } else {
                    b
                }
            });
            let (mut a, mut b) = (at(best.saturating_sub(1)), at((best + 1).min(SCAN)));
            let ratio = (5f64.sqrt() - 1.0) / 2.0;
            while b - a > 1e-12 * (1.0 + hi.abs()) {
                let (c, d) = (b - ratio * (b - a), a + ratio * (b - a));
                if distance(c) < distance(d) {
                    b = d;
                } else {
                    a = c;
                }
            }
            let u = 0.5 * (a + b);
            (u, distance(u))
        }
    }
}

/// Runs the loop; with `record`, every sample is returned as well.
pub fn simulate_five_axis(
    config: &FiveAxisSimConfig,
    record: bool,
) -> Result<(FiveAxisMetrics, Vec<FiveAxisRecord>), SimError> {
    let ts = config.controller.ts;
    let inputs = FiveAxisInputs {
        path: config.path.clone(),
        builtin: config.builtin.clone(),
        feeds: config.feeds.clone(),
        machine: config.controller.machine,
        joints: config.joint_limits,
        limits: config.path_limits,
        ts,
    };
    let mut reference = FiveAxisReference::new(inputs, &config.planner, &|i| format!("pose {i}"))?;
    let mut controller = FiveAxisController::new(config.controller)?;
    config.plant.validate().map_err(SimError::Plant)?;
    let start = reference.current();
    let mut plant = ServoAxes::new(config.plant, start.joints);
    let settle = (config.settle / ts).round() as usize;
    let machine = config.controller.machine;

    let mut window = [start.u; TRUTH_WINDOW];
    let mut records = Vec::new();
    let (mut sums, mut count) = ((0.0, 0.0), 0usize);
    let mut metrics = FiveAxisMetrics {
        samples: 0,
        max_tip: 0.0,
        mean_tip: 0.0,
        max_orientation: 0.0,
        mean_orientation: 0.0,
        max_tip_estimate_deviation: 0.0,
        max_orientation_estimate_deviation: 0.0,
        max_reference_tip_deviation: 0.0,
        max_reference_orientation_deviation: 0.0,
        divergence: None,
    };
    let mut sample = start;
    let mut after_done = 0;
    for k in 0.. {
        if k > 0 {
            sample = reference.step()?;
        }
        window[k % TRUTH_WINDOW] = sample.u;
        let t = k as f64 * ts;
        let actual = plant.position();
        let diverged = |value: f64, kind| Divergence { k, t, kind, value };
        let out = match controller.sample(&sample.joints, &actual) {
            Ok(out) if geometry::is_finite(&out.u) => out,
            _ => {
                metrics.divergence = Some(diverged(f64::NAN, DivergenceKind::NonFinite));
                break;
            }
        };
        let pose = machine.forward(&actual);
        let lo = window[(k + 1) % TRUTH_WINDOW].min(sample.u);
        let (foot, tip) = nearest_on_branch(&config.path, &pose.tip, lo, sample.u);
        if tip > config.abort_tip_error {
            metrics.divergence = Some(diverged(tip, DivergenceKind::ErrorLimit));
            break;
        }
        let orientation = angle_between(&pose.axis, &config.path.pose_at(foot).axis);
        let (tip_estimate, orientation_estimate) = out.error.map_or((f64::NAN, f64::NAN), |e| {
            (geometry::norm(&e.tip), e.orientation)
        });
        if let Some(e) = out.error {
            metrics.max_tip_estimate_deviation = metrics
                .max_tip_estimate_deviation
                .max((geometry::norm(&e.tip) - tip).abs());
            metrics.max_orientation_estimate_deviation = metrics
                .max_orientation_estimate_deviation
                .max((e.orientation - orientation).abs());
        }
        metrics.max_reference_tip_deviation = metrics
            .max_reference_tip_deviation
            .max(sample.tip_deviation);
        metrics.max_reference_orientation_deviation = metrics
            .max_reference_orientation_deviation
            .max(sample.orientation_deviation);
        metrics.max_tip = metrics.max_tip.max(tip);
        metrics.max_orientation = metrics.max_orientation.max(orientation);
        sums = (sums.0 + tip, sums.1 + orientation);
        count += 1;
        if record {
            records.push(FiveAxisRecord {
                t,
                reference: sample.joints,
                actual,
                u: out.u,
                tip,
                orientation,
                tip_estimate,
                orientation_estimate,
                foot,
                segment: out.segment,
                reference_u: sample.u,
                evaluation: out.evaluation,
                weight: out.weight,
                hold: out.hold,
            });
        }
        if sample.done {
            if after_done == settle {
                break;
            }
            after_done += 1;
        }
        plant.step(out.u, ts);
    }
    metrics.samples = count;
    if count > 0 {
        metrics.mean_tip = sums.0 / count as f64;
        metrics.mean_orientation = sums.1 / count as f64;
    }
    Ok((metrics, records))
}
