//! Running a closed loop: [`Simulator`] prepares a configuration once (reference
//! samples, the exact-distance index) and replays it as often as wanted; each [`Run`] is
//! an iterator over the samples of one run (the sequence of the module docs).

use super::config::{SimConfig, SimError, MAX_SAMPLES};
use super::metrics::{Accumulator, Divergence, DivergenceKind, Metrics};
use super::reference::ReferencePath;
use super::trace::{Record, SimResult, Trace};
use crate::control::{ConfigError, ControllerConfig, CrossCoupledController};
use crate::geometry::Vector;
use crate::path::planar::Path;
use crate::path::{Interpolator, Sample};
use crate::plant::ServoAxes;

/// A validated configuration with its reference samples and true-error index prepared,
/// ready to run any number of times (also with other controller configurations).
#[derive(Clone, Debug)]
pub struct Simulator<const D: usize = 2, P: ReferencePath<D> = Path> {
    config: SimConfig<D, P>,
    references: Vec<Sample<D>>,
    truth: P::Truth,
    transient_k: usize,
}

impl<const D: usize, P: ReferencePath<D>> Simulator<D, P> {
    /// Validates `config`, runs the interpolator and indexes the path.
    pub fn new(config: SimConfig<D, P>) -> Result<Self, SimError> {
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
            truth: config.path.truth(),
            config,
            references,
            transient_k,
        })
    }

    /// The configuration.
    pub fn config(&self) -> &SimConfig<D, P> {
        &self.config
    }

    /// Number of samples of a complete run.
    pub fn samples(&self) -> usize {
        self.references.len()
    }

    /// The reference samples R_0, R_1, … as the interpolator produced them.
    pub fn references(&self) -> &[Sample<D>] {
        &self.references
    }

    /// Starts a run with the configured controller. Allocates the controller once; the
    /// samples themselves allocate nothing.
    pub fn start(&self) -> Run<'_, D, P> {
        self.start_with(&self.config.controller)
            .expect("controller validated in Simulator::new")
    }

    /// Starts a run with another controller configuration on the same path and plant
    /// (the PSO's case); its `ts` is replaced by the run's.
    pub fn start_with(
        &self,
        controller: &ControllerConfig<D>,
    ) -> Result<Run<'_, D, P>, ConfigError> {
        let config = ControllerConfig {
            ts: self.config.ts,
            ..*controller
        };
        let estimator = self.config.path.estimator(self.config.estimator);
        let controller = CrossCoupledController::new(config, estimator)?;
        let start = self.references[0];
        Ok(Run {
            sim: self,
            plant: ServoAxes::new(self.config.plant, start.point),
            controller,
            k: 0,
            judge: Judge::new(self),
            finished: false,
        })
    }

    /// A complete recorded run.
    pub fn run(&self) -> SimResult<D> {
        record(self.start())
    }

    /// A recorded run with another controller configuration.
    pub fn run_with(&self, controller: &ControllerConfig<D>) -> Result<SimResult<D>, ConfigError> {
        Ok(record(self.start_with(controller)?))
    }

    /// Metrics of a complete run without storing the time series.
    pub fn metrics(&self) -> Metrics {
        self.start().finish()
    }

    /// Metrics with another controller configuration, without storing the time series.
    pub fn metrics_with(&self, controller: &ControllerConfig<D>) -> Result<Metrics, ConfigError> {
        Ok(self.start_with(controller)?.finish())
    }

    /// Metrics of a run made elsewhere (the same loop through FMUs, say) from its actual
    /// positions at t_0, t_1, … and the commands the controller gave there: each sample
    /// judged as a run here judges its own (a non-finite position or command, the true
    /// error searched from the last foot, the abort rule, the sums), so a loop that
    /// reproduces this simulator gets these metrics bit for bit. Samples past the planned
    /// ones are not judged; a run that gives fewer ends diverged where it stopped.
    pub fn metrics_of(&self, samples: impl IntoIterator<Item = (Vector<D>, Vector<D>)>) -> Metrics {
        let mut judge = Judge::new(self);
        let mut judged = 0;
        for (k, (actual, u)) in samples.into_iter().take(self.samples()).enumerate() {
            if let Some(v) = first_non_finite(&actual, &u) {
                judge.diverge(self, k, DivergenceKind::NonFinite, v);
            }
            if judge.divergence.is_some() || judge.judge(self, k, actual).is_none() {
                break;
            }
            judged = k + 1;
        }
        if judge.divergence.is_none() && judged < self.samples() {
            judge.diverge(self, judged, DivergenceKind::NonFinite, f64::NAN);
        }
        judge.acc.metrics(judge.divergence)
    }
}

/// What a run's samples are judged by: the true error (searched from the last sample's
/// foot), the abort rule and the metrics' sums. A run here and [`Simulator::metrics_of`]
/// share it, so they agree bit for bit.
#[derive(Clone, Copy, Debug)]
struct Judge {
    /// Foot parameter of the previous sample's true error (search hint).
    hint: f64,
    acc: Accumulator,
    divergence: Option<Divergence>,
}

impl Judge {
    fn new<const D: usize, P: ReferencePath<D>>(sim: &Simulator<D, P>) -> Judge {
        Judge {
            hint: sim.references[0].u,
            acc: Accumulator::default(),
            divergence: None,
        }
    }

    fn diverge<const D: usize, P: ReferencePath<D>>(
        &mut self,
        sim: &Simulator<D, P>,
        k: usize,
        kind: DivergenceKind,
        value: f64,
    ) {
        self.divergence = Some(Divergence {
            k,
            t: k as f64 * sim.config.ts,
            kind,
            value,
        });
    }

    /// The true error of sample `k` at `actual`, counted; None when the run diverges there.
    fn judge<const D: usize, P: ReferencePath<D>>(
        &mut self,
        sim: &Simulator<D, P>,
        k: usize,
        actual: Vector<D>,
    ) -> Option<f64> {
        let truth = P::true_error(&sim.truth, actual, self.hint);
        if !truth.error.is_finite() {
            self.diverge(sim, k, DivergenceKind::NonFinite, truth.error);
            return None;
        }
        if truth.error.abs() > sim.config.abort_error {
            self.diverge(sim, k, DivergenceKind::ErrorLimit, truth.error.abs());
            return None;
        }
        self.hint = truth.u;
        self.acc.add(k >= sim.transient_k, truth.error.abs());
        Some(truth.error)
    }
}

fn record<const D: usize, P: ReferencePath<D>>(mut run: Run<'_, D, P>) -> SimResult<D> {
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
pub fn simulate<const D: usize, P: ReferencePath<D>>(
    config: SimConfig<D, P>,
) -> Result<SimResult<D>, SimError> {
    Ok(Simulator::new(config)?.run())
}

/// Validates, prepares and runs `config`, metrics only.
pub fn simulate_metrics<const D: usize, P: ReferencePath<D>>(
    config: SimConfig<D, P>,
) -> Result<Metrics, SimError> {
    Ok(Simulator::new(config)?.metrics())
}

/// A run in progress: an iterator over its [`Record`]s, one per sample, which ends at the
/// planned last sample or at a divergence. Each `next` is one loop body of the module
/// docs and allocates nothing.
#[derive(Clone, Debug)]
pub struct Run<'a, const D: usize = 2, P: ReferencePath<D> = Path> {
    sim: &'a Simulator<D, P>,
    plant: ServoAxes<D>,
    controller: CrossCoupledController<P::Estimator, D>,
    k: usize,
    judge: Judge,
    finished: bool,
}

impl<const D: usize, P: ReferencePath<D>> Run<'_, D, P> {
    /// Metrics of the samples so far.
    pub fn metrics(&self) -> Metrics {
        self.judge.acc.metrics(self.judge.divergence)
    }

    /// Runs the remaining samples and returns the metrics.
    pub fn finish(mut self) -> Metrics {
        while self.next().is_some() {}
        self.metrics()
    }

    /// The plant (state inspection).
    pub fn plant(&self) -> &ServoAxes<D> {
        &self.plant
    }

    /// The controller (state inspection).
    pub fn controller(&self) -> &CrossCoupledController<P::Estimator, D> {
        &self.controller
    }

    fn diverge(&mut self, kind: DivergenceKind, value: f64) -> Option<Record<D>> {
        self.judge.diverge(self.sim, self.k, kind, value);
        self.finished = true;
        None
    }
}

/// The first non-finite value among the actual position's and then the command's.
fn first_non_finite<const D: usize>(actual: &Vector<D>, u: &Vector<D>) -> Option<f64> {
    actual
        .iter()
        .chain(u.iter())
        .copied()
        .find(|v| !v.is_finite())
}

impl<const D: usize, P: ReferencePath<D>> Iterator for Run<'_, D, P> {
    type Item = Record<D>;

    fn next(&mut self) -> Option<Record<D>> {
        if self.finished {
            return None;
        }
        let sim = self.sim;
        let ts = sim.config.ts;
        let k = self.k;
        let reference = sim.references[k];
        let actual = self.plant.position();
        let out = self.controller.sample(reference.point, actual);
        if let Some(v) = first_non_finite(&actual, &out.u) {
            return self.diverge(DivergenceKind::NonFinite, v);
        }
        let Some(true_error) = self.judge.judge(sim, k, actual) else {
            self.finished = true;
            return None;
        };
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
            true_error,
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
    fn metrics_of_a_runs_positions_are_the_runs_metrics_bit_for_bit() {
        let mut config = SimConfig::builtin("trident").unwrap();
        config.transient = 0.1;
        let sim = Simulator::new(config).unwrap();
        let run = sim.run();
        let samples = || {
            run.trace
                .actual
                .iter()
                .copied()
                .zip(run.trace.u.iter().copied())
        };
        assert_eq!(sim.metrics_of(samples()), run.metrics);
        assert!(run.metrics.settled_samples < run.metrics.samples);
        // A position or a command that is not finite ends the judged run there, as a run
        // here ends.
        for (k, in_command) in [(700, false), (900, true)] {
            let mut given: Vec<_> = samples().collect();
            if in_command {
                given[k].1.y = f64::INFINITY;
            } else {
                given[k].0.x = f64::NAN;
            }
            let m = sim.metrics_of(given);
            assert_eq!((m.samples, m.divergence.unwrap().k), (k, k));
            assert_eq!(m.divergence.unwrap().kind, DivergenceKind::NonFinite);
        }
        // One far off the path is an error-limit divergence.
        let mut given: Vec<_> = samples().collect();
        given[10].0.y += 100.0;
        assert_eq!(
            sim.metrics_of(given).divergence.unwrap().kind,
            DivergenceKind::ErrorLimit
        );
        // A run that stops short ends diverged where it stopped.
        let m = sim.metrics_of(samples().take(50));
        assert_eq!((m.samples, m.divergence.unwrap().k), (50, 50));
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
        c.plant.axes[1].inertia = 0.0;
        assert!(matches!(Simulator::new(c), Err(SimError::Plant(_))));
        let mut c = SimConfig::paper_circle();
        c.settle = f64::NAN;
        assert!(matches!(Simulator::new(c), Err(SimError::Invalid(_))));
    }
}
