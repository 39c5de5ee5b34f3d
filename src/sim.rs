//! In-process closed loop: interpolator → cross-coupled controller → XY table, sampled
//! every `Ts` (docs/design.md §4.2, 4.5, 4.6). The reference for everything the FMUs must match in
//! co-simulation, and the fitness evaluator of the PSO tuner.
//!
//! # The sample sequence (the FMU co-simulation reproduces it, keep it exactly so)
//!
//! For k = 0, 1, …, with t_k = k·Ts:
//! 1. reference R_k: `interpolator.current().point` at k = 0, then
//!    `interpolator.step().point` for k ≥ 1;
//! 2. actual P_k = `plant.position()` (the plant state at t_k);
//! 3. `out = controller.sample(R_k, P_k)`;
//! 4. record the sample: true contour error of P_k (exact distance to the path, signed,
//!    via [`TrueErrorIndex`] with the previous foot parameter as hint), the estimator's
//!    contour error, the CCC gains and `out.u`;
//! 5. `plant.step(out.u, Ts)`: the command is held over [t_k, t_k+1). (Skipped after the
//!    last sample: nothing would observe it.)
//!
//! The plant starts at rest at the path's start point; controller and estimator start
//! empty. The reference does not depend on the loop, so [`Simulator::new`] runs the
//! interpolator once and keeps its samples; every run replays the same values (the
//! interpolator is deterministic), which keeps a PSO run to controller + plant + true
//! error.
//!
//! # Run length
//!
//! Until the interpolator reports `done` plus `settle` seconds, i.e. the last sample is
//! k_done + round(settle/Ts); or, when `duration` is set, the samples with t_k ≤ duration.
//!
//! # Divergence
//!
//! An unstable loop (absurd gains) must neither panic nor smuggle NaN into a fitness. A
//! run stops at the first sample whose actual position or command is not finite or whose
//! |true contour error| exceeds `abort_error`; that sample is not recorded, the metrics
//! cover the samples before it, and [`Metrics::divergence`] says where and why.

use std::fmt;

use serde::{Deserialize, Serialize};

use crate::contour::{Estimator, EstimatorKind, TrueErrorIndex};
use crate::control::{CccMode, ConfigError, ControllerConfig, CrossCoupledController};
use crate::path::{builtin, Interpolator, Path, PathError, Sample};
use crate::plant::{XyTable, XyTableParams};

/// The paper's circle feed, mm/s: at 10π the built-in `circle` is x = 10 cos πt − 10,
/// y = 10 sin πt, one turn in 2 s.
pub const PAPER_CIRCLE_FEED: f64 = 10.0 * std::f64::consts::PI;

/// Feed used for the built-in free curves (`infinity`, `trident`, `line`, `arc`), mm/s.
/// 50 mm/s gives a following error of 50/28.5 ≈ 1.75 mm and at the trident's 4.2 mm
/// minimum radius an acceleration of 0.6 m/s² (≈ 4 A of drive current): well inside what
/// the test plant does linearly, yet fast enough that the curvature makes contour error.
pub const FREE_CURVE_FEED: f64 = 50.0;

/// The feed a path is run at unless one is given: [`PAPER_CIRCLE_FEED`] for a full
/// circle (the paper's experiment), [`FREE_CURVE_FEED`] for anything else. Decided on the
/// path itself, not on how it was named, so `circle`, `Circle` and its mirror agree.
pub fn preset_feed(path: &Path) -> f64 {
    if matches!(path, Path::Arc(a) if a.is_full_circle()) {
        PAPER_CIRCLE_FEED
    } else {
        FREE_CURVE_FEED
    }
}

/// Refuses runs longer than this many samples (a feed too small for the path).
pub const MAX_SAMPLES: usize = 50_000_000;

/// Everything a closed-loop run depends on.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SimConfig {
    /// The reference path; the plant starts at rest at its start point.
    pub path: Path,
    /// Feed, mm/s (> 0 unless `duration` is set).
    pub feed: f64,
    /// Sample period of interpolator, controller and plant, s. Overrides `controller.ts`
    /// so the two can never disagree.
    pub ts: f64,
    /// Plant parameters.
    pub plant: XyTableParams,
    /// Controller configuration (`ts` ignored, see above).
    pub controller: ControllerConfig,
    /// Contour estimator the controller runs.
    pub estimator: EstimatorKind,
    /// Seconds simulated after the interpolator reaches the path end (≥ 0).
    pub settle: f64,
    /// Fixed run length, s: when set, replaces "path end + settle".
    pub duration: Option<f64>,
    /// Start-up time excluded from the `settled_*` metrics, s. Default 0.2 s: the axis
    /// loops start at rest behind a reference that jumps to full feed, and their lag
    /// builds up with time constant 1/Kpp = 35 ms; after ~6 of them only the path's own
    /// contour error is left.
    pub transient: f64,
    /// |true contour error| (mm) above which the run counts as diverged. Default 10 mm,
    /// far above anything a stable loop produces on the built-in paths.
    pub abort_error: f64,
}

impl SimConfig {
    /// `path` at `feed` with the defaults: Ts = 1 ms, the paper's plant, the default
    /// controller (fuzzy-PID CCC), the free-curve estimator, no settle time.
    pub fn new(path: Path, feed: f64) -> Self {
        SimConfig {
            path,
            feed,
            ts: 1e-3,
            plant: XyTableParams::PAPER,
            controller: ControllerConfig::default(),
            estimator: EstimatorKind::FreeCurve,
            settle: 0.0,
            duration: None,
            transient: 0.2,
            abort_error: 10.0,
        }
    }

    /// The paper's experiment: the circle at 10π mm/s (2 s), paper plant, defaults.
    pub fn paper_circle() -> Self {
        Self::new(Path::Arc(builtin::circle()), PAPER_CIRCLE_FEED)
    }

    /// A built-in path by name at its [`preset_feed`].
    pub fn builtin(name: &str) -> Result<Self, PathError> {
        let path = builtin::by_name(name)?;
        let feed = preset_feed(&path);
        Ok(Self::new(path, feed))
    }

    /// The same run with another plant (e.g. [`XyTableParams::mismatched`]).
    pub fn with_plant(mut self, plant: XyTableParams) -> Self {
        self.plant = plant;
        self
    }

    /// The same run with another CCC mode (the rest of the controller kept).
    pub fn with_mode(mut self, mode: CccMode) -> Self {
        self.controller.ccc.mode = mode;
        self
    }

    /// The controller configuration actually used (`ts` taken from the run).
    pub fn effective_controller(&self) -> ControllerConfig {
        ControllerConfig {
            ts: self.ts,
            ..self.controller
        }
    }
}

/// Why a configuration cannot be simulated.
#[derive(Clone, Debug, PartialEq)]
pub enum SimError {
    /// Feed or sample period rejected by the interpolator.
    Path(PathError),
    /// Controller configuration rejected.
    Controller(ConfigError),
    /// Plant parameters rejected; the message names the field.
    Plant(String),
    /// A run parameter (`settle`, `duration`, `transient`, `abort_error`, `feed`) rejected.
    Invalid(String),
}

impl fmt::Display for SimError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SimError::Path(e) => write!(f, "{e}"),
            SimError::Controller(e) => write!(f, "{e}"),
            SimError::Plant(m) => write!(f, "invalid plant: {m}"),
            SimError::Invalid(m) => write!(f, "invalid simulation: {m}"),
        }
    }
}

impl std::error::Error for SimError {}

impl From<PathError> for SimError {
    fn from(e: PathError) -> Self {
        SimError::Path(e)
    }
}

impl From<ConfigError> for SimError {
    fn from(e: ConfigError) -> Self {
        SimError::Controller(e)
    }
}

/// What made a run stop early.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum DivergenceKind {
    /// Actual position, command or contour error not finite.
    NonFinite,
    /// |true contour error| above `abort_error`.
    ErrorLimit,
}

/// Where a run diverged.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Divergence {
    /// Sample index of the offending sample (not recorded).
    pub k: usize,
    /// Its time, s.
    pub t: f64,
    /// Why.
    pub kind: DivergenceKind,
    /// The offending |true contour error| (mm), or the first non-finite value.
    pub value: f64,
}

/// Summary of a run. Errors are |true contour error| in mm; every field is finite.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Metrics {
    /// Samples evaluated (all of them unless the run diverged).
    pub samples: usize,
    /// Maximum over all samples.
    pub max_abs_error: f64,
    /// Mean over all samples (the PSO fitness of docs/design.md §4.4).
    pub mean_abs_error: f64,
    /// Samples with t ≥ `transient`.
    pub settled_samples: usize,
    /// Maximum over the samples with t ≥ `transient` (0 if there are none).
    pub settled_max_abs_error: f64,
    /// Mean over the samples with t ≥ `transient` (0 if there are none).
    pub settled_mean_abs_error: f64,
    /// Set when the run stopped early.
    pub divergence: Option<Divergence>,
}

impl Metrics {
    /// True when the run reached its planned end.
    pub fn is_stable(&self) -> bool {
        self.divergence.is_none()
    }
}

/// One recorded sample.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Record {
    /// Sample index.
    pub k: usize,
    /// t_k = k·Ts, s.
    pub t: f64,
    /// Reference (command) point R_k, mm.
    pub reference: [f64; 2],
    /// Actual point P_k (plant position at t_k), mm.
    pub actual: [f64; 2],
    /// Signed true contour error of P_k, mm (positive right of travel).
    pub true_error: f64,
    /// The controller's estimated contour error, mm.
    pub estimated_error: f64,
    /// CCC gains (Kp, Ki, Kd) used; 0 with the CCC off.
    pub gains: [f64; 3],
    /// Velocity commands (u_x, u_y), mm/s, held over [t_k, t_k+1).
    pub u: [f64; 2],
}

/// The time series of a run, one entry per sample (struct of vectors, plot-ready).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Trace {
    pub t: Vec<f64>,
    pub reference: Vec<[f64; 2]>,
    pub actual: Vec<[f64; 2]>,
    pub true_error: Vec<f64>,
    pub estimated_error: Vec<f64>,
    pub gains: Vec<[f64; 3]>,
    pub u: Vec<[f64; 2]>,
}

impl Trace {
    fn with_capacity(n: usize) -> Self {
        Trace {
            t: Vec::with_capacity(n),
            reference: Vec::with_capacity(n),
            actual: Vec::with_capacity(n),
            true_error: Vec::with_capacity(n),
            estimated_error: Vec::with_capacity(n),
            gains: Vec::with_capacity(n),
            u: Vec::with_capacity(n),
        }
    }

    fn push(&mut self, r: &Record) {
        self.t.push(r.t);
        self.reference.push(r.reference);
        self.actual.push(r.actual);
        self.true_error.push(r.true_error);
        self.estimated_error.push(r.estimated_error);
        self.gains.push(r.gains);
        self.u.push(r.u);
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        self.t.len()
    }

    /// True when nothing was recorded.
    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }
}

/// A recorded run.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SimResult {
    pub trace: Trace,
    pub metrics: Metrics,
}

/// A validated configuration with its reference samples and true-error index prepared,
/// ready to run any number of times (also with other controller configurations).
#[derive(Clone, Debug)]
pub struct Simulator {
    config: SimConfig,
    references: Vec<Sample>,
    index: TrueErrorIndex,
    transient_k: usize,
}

impl Simulator {
    /// Validates `config`, runs the interpolator and indexes the path.
    pub fn new(config: SimConfig) -> Result<Self, SimError> {
        let ts = config.ts;
        let mut interpolator = Interpolator::new(config.path.clone(), config.feed, ts)?;
        config.effective_controller().validate()?;
        config.plant.validate().map_err(SimError::Plant)?;
        let non_negative = |name: &str, v: f64| {
            if v.is_finite() && v >= 0.0 {
                Ok(())
            } else {
                Err(SimError::Invalid(format!(
                    "{name} must be finite and >= 0 (got {v})"
                )))
            }
        };
        non_negative("settle", config.settle)?;
        non_negative("transient", config.transient)?;
        if !(config.abort_error.is_finite() && config.abort_error > 0.0) {
            return Err(SimError::Invalid(format!(
                "abort_error must be finite and > 0 (got {})",
                config.abort_error
            )));
        }
        // Last sample index. The small allowance absorbs rounding in duration/Ts.
        let last_k = match config.duration {
            Some(d) => {
                non_negative("duration", d)?;
                let n = (d / ts + 1e-9).floor();
                if n >= MAX_SAMPLES as f64 {
                    return Err(SimError::Invalid(format!(
                        "duration {d} s is more than {MAX_SAMPLES} samples"
                    )));
                }
                Some(n as usize)
            }
            None => {
                if config.feed <= 0.0 {
                    return Err(SimError::Invalid(
                        "feed must be > 0 when the run ends at the path end".into(),
                    ));
                }
                None
            }
        };
        let settle_k = (config.settle / ts).round();
        let mut references = Vec::new();
        references.push(interpolator.current());
        let mut end = last_k.or(if references[0].done {
            Some(settle_k as usize)
        } else {
            None
        });
        while end.is_none_or(|e| references.len() <= e) {
            if references.len() >= MAX_SAMPLES {
                return Err(SimError::Invalid(format!(
                    "the run would exceed {MAX_SAMPLES} samples (feed too small?)"
                )));
            }
            let s = interpolator.step();
            references.push(s);
            if end.is_none() && s.done {
                let k = (references.len() - 1) as f64 + settle_k;
                if k >= MAX_SAMPLES as f64 {
                    return Err(SimError::Invalid(format!(
                        "settle {} s is more than {MAX_SAMPLES} samples",
                        config.settle
                    )));
                }
                end = Some(k as usize);
            }
        }
        let transient_k = (config.transient / ts - 1e-9).ceil().max(0.0) as usize;
        Ok(Simulator {
            index: TrueErrorIndex::new(&config.path),
            config,
            references,
            transient_k,
        })
    }

    /// The configuration.
    pub fn config(&self) -> &SimConfig {
        &self.config
    }

    /// Number of samples of a complete run.
    pub fn samples(&self) -> usize {
        self.references.len()
    }

    /// The reference samples R_0, R_1, … as the interpolator produced them.
    pub fn references(&self) -> &[Sample] {
        &self.references
    }

    /// Starts a run with the configured controller. Allocates the controller once; the
    /// samples themselves allocate nothing.
    pub fn start(&self) -> Run<'_> {
        self.start_with(&self.config.controller)
            .expect("controller validated in Simulator::new")
    }

    /// Starts a run with another controller configuration on the same path and plant
    /// (the PSO's case); its `ts` is replaced by the run's.
    pub fn start_with(&self, controller: &ControllerConfig) -> Result<Run<'_>, ConfigError> {
        let config = ControllerConfig {
            ts: self.config.ts,
            ..*controller
        };
        let estimator = Estimator::for_path(self.config.estimator, &self.config.path);
        let controller = CrossCoupledController::new(config, estimator)?;
        let start = self.references[0];
        Ok(Run {
            sim: self,
            plant: XyTable::new(self.config.plant, start.point),
            controller,
            k: 0,
            hint: start.u,
            acc: Accumulator::default(),
            divergence: None,
            finished: false,
        })
    }

    /// A complete recorded run.
    pub fn run(&self) -> SimResult {
        record(self.start())
    }

    /// A recorded run with another controller configuration.
    pub fn run_with(&self, controller: &ControllerConfig) -> Result<SimResult, ConfigError> {
        Ok(record(self.start_with(controller)?))
    }

    /// Metrics of a complete run without storing the time series.
    pub fn metrics(&self) -> Metrics {
        self.start().finish()
    }

    /// Metrics with another controller configuration, without storing the time series.
    pub fn metrics_with(&self, controller: &ControllerConfig) -> Result<Metrics, ConfigError> {
        Ok(self.start_with(controller)?.finish())
    }
}

fn record(mut run: Run<'_>) -> SimResult {
    let mut trace = Trace::with_capacity(run.sim.samples());
    for r in run.by_ref() {
        trace.push(&r);
    }
    SimResult {
        trace,
        metrics: run.metrics(),
    }
}

/// Validates, prepares and runs `config`, recording the time series.
pub fn simulate(config: SimConfig) -> Result<SimResult, SimError> {
    Ok(Simulator::new(config)?.run())
}

/// Validates, prepares and runs `config`, metrics only.
pub fn simulate_metrics(config: SimConfig) -> Result<Metrics, SimError> {
    Ok(Simulator::new(config)?.metrics())
}

/// Running sums of the metrics; the recorded and the metrics-only paths share it, so they
/// agree bit for bit.
#[derive(Clone, Copy, Debug, Default)]
struct Accumulator {
    n: usize,
    max: f64,
    sum: f64,
    settled_n: usize,
    settled_max: f64,
    settled_sum: f64,
}

impl Accumulator {
    fn add(&mut self, settled: bool, abs_error: f64) {
        self.n += 1;
        self.max = self.max.max(abs_error);
        self.sum += abs_error;
        if settled {
            self.settled_n += 1;
            self.settled_max = self.settled_max.max(abs_error);
            self.settled_sum += abs_error;
        }
    }

    fn metrics(&self, divergence: Option<Divergence>) -> Metrics {
        let mean = |sum: f64, n: usize| if n > 0 { sum / n as f64 } else { 0.0 };
        Metrics {
            samples: self.n,
            max_abs_error: self.max,
            mean_abs_error: mean(self.sum, self.n),
            settled_samples: self.settled_n,
            settled_max_abs_error: self.settled_max,
            settled_mean_abs_error: mean(self.settled_sum, self.settled_n),
            divergence,
        }
    }
}

/// A run in progress: an iterator over its [`Record`]s, one per sample, which ends at the
/// planned last sample or at a divergence. Each `next` is one loop body of the module
/// docs and allocates nothing.
#[derive(Clone, Debug)]
pub struct Run<'a> {
    sim: &'a Simulator,
    plant: XyTable,
    controller: CrossCoupledController<Estimator>,
    k: usize,
    /// Foot parameter of the previous sample's true error (search hint).
    hint: f64,
    acc: Accumulator,
    divergence: Option<Divergence>,
    finished: bool,
}

impl Run<'_> {
    /// Metrics of the samples so far.
    pub fn metrics(&self) -> Metrics {
        self.acc.metrics(self.divergence)
    }

    /// Runs the remaining samples and returns the metrics.
    pub fn finish(mut self) -> Metrics {
        while self.next().is_some() {}
        self.metrics()
    }

    /// The plant (state inspection).
    pub fn plant(&self) -> &XyTable {
        &self.plant
    }

    /// The controller (state inspection).
    pub fn controller(&self) -> &CrossCoupledController<Estimator> {
        &self.controller
    }

    fn diverge(&mut self, kind: DivergenceKind, value: f64) -> Option<Record> {
        self.divergence = Some(Divergence {
            k: self.k,
            t: self.k as f64 * self.sim.config.ts,
            kind,
            value,
        });
        self.finished = true;
        None
    }
}

fn first_non_finite(values: &[f64]) -> Option<f64> {
    values.iter().copied().find(|v| !v.is_finite())
}

impl Iterator for Run<'_> {
    type Item = Record;

    fn next(&mut self) -> Option<Record> {
        if self.finished {
            return None;
        }
        let sim = self.sim;
        let ts = sim.config.ts;
        let k = self.k;
        let reference = sim.references[k];
        let actual = self.plant.position();
        let out = self.controller.sample(reference.point, actual);
        if let Some(v) = first_non_finite(&[actual[0], actual[1], out.u[0], out.u[1]]) {
            return self.diverge(DivergenceKind::NonFinite, v);
        }
        let truth = sim.index.error(actual, self.hint);
        if !truth.error.is_finite() {
            return self.diverge(DivergenceKind::NonFinite, truth.error);
        }
        if truth.error.abs() > sim.config.abort_error {
            return self.diverge(DivergenceKind::ErrorLimit, truth.error.abs());
        }
        self.hint = truth.u;
        self.acc.add(k >= sim.transient_k, truth.error.abs());
        if k + 1 < sim.references.len() {
            self.plant.step(out.u, ts);
            self.k += 1;
        } else {
            self.finished = true;
        }
        let (kp, ki, kd) = out.gains;
        Some(Record {
            k,
            t: k as f64 * ts,
            reference: reference.point,
            actual,
            true_error: truth.error,
            estimated_error: out.contour.error,
            gains: [kp, ki, kd],
            u: out.u,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn run_length_follows_done_settle_and_duration() {
        let sim = Simulator::new(SimConfig::paper_circle()).unwrap();
        // k = 0 … 2000: the circle is done exactly at t = 2 s.
        assert_eq!(sim.samples(), 2001);
        assert!(sim.references()[2000].done && !sim.references()[1999].done);
        let mut c = SimConfig::paper_circle();
        c.settle = 0.25;
        assert_eq!(Simulator::new(c.clone()).unwrap().samples(), 2251);
        c.duration = Some(0.5);
        assert_eq!(Simulator::new(c.clone()).unwrap().samples(), 501);
        c.duration = Some(3.0);
        let s = Simulator::new(c).unwrap();
        assert_eq!(s.samples(), 3001);
        assert!(s.references()[3000].done);
    }

    #[test]
    fn bad_configs_are_refused() {
        let mut c = SimConfig::paper_circle();
        c.feed = 0.0;
        assert!(matches!(
            Simulator::new(c.clone()),
            Err(SimError::Invalid(_))
        ));
        c.duration = Some(0.1);
        assert_eq!(Simulator::new(c).unwrap().samples(), 101);
        let mut c = SimConfig::paper_circle();
        c.ts = 0.0;
        assert!(matches!(Simulator::new(c), Err(SimError::Path(_))));
        let mut c = SimConfig::paper_circle();
        c.controller.axis[0].kp = -1.0;
        assert!(matches!(Simulator::new(c), Err(SimError::Controller(_))));
        let mut c = SimConfig::paper_circle();
        c.plant.y.inertia = 0.0;
        assert!(matches!(Simulator::new(c), Err(SimError::Plant(_))));
        let mut c = SimConfig::paper_circle();
        c.settle = f64::NAN;
        assert!(matches!(Simulator::new(c), Err(SimError::Invalid(_))));
    }
}
