//! The tuner's objective (docs/design/two-axis.md §4.4): a closed-loop run of the in-process simulator
//! with candidate fuzzy factors, scored by the true contour error (against the exact
//! path, not the controller's estimate). Diverging runs get a large finite penalty, so
//! the swarm is steered away from them instead of crashing on NaN.

use serde::{Deserialize, Serialize};

use contour_core::control::{ControllerConfig, FuzzyFactors};
use contour_core::path::planar::Path;
use contour_core::plant::XyTableParams;
use contour_core::sim::{Metrics, SimConfig, Simulator};

/// The tuned factors, in the order of a PSO position, named as in ContourCCC2D
/// (`fuzzy.<name>`).
pub const FACTOR_NAMES: [&str; 5] = ["ke", "kde", "kp", "ki", "kd"];

/// Default search box (docs/design/two-axis.md §4.4), from the physics of the contour loop
/// rather than from where earlier optima fell:
/// - kε, kΔε ≤ 10 per µm (per µm and sample): the fuzzy inputs saturate no finer than
///   0.3 µm, three counts of a 0.1 µm linear scale; finer would schedule on encoder noise.
/// - kpf ≤ 340, kif ≤ 6800, kdf ≤ 3.8: the largest Kp, Ki, Kd the folded tables can
///   schedule (Kp0 + 8/3·kpf, Ki0 + 2·kif, Kd0 + kdf) stay below half the gain at which
///   the sampled contour loop (test plant, Ts = 1 ms, the other gains at Kp0, Ki0, Kd0)
///   goes unstable: 2063 1/s, 37 500 1/s², 7.7 (a 6 dB gain margin each).
/// - 0 for every lower bound: a zero factor switches that adaptation off.
pub const LOWER: [f64; 5] = [0.0; 5];
pub const UPPER: [f64; 5] = [10.0, 10.0, 340.0, 6800.0, 3.8];

/// Fitness of a run that diverged: above any stable run's (those abort at 10 mm), and
/// lower the later the divergence, so the swarm still sees a slope.
pub const PENALTY_MM: f64 = 1000.0;

/// What the swarm minimises.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Fitness {
    /// Mean |true contour error| over the run (docs/design/two-axis.md §4.4, the paper's).
    Mean,
    /// Maximum |true contour error| over the run.
    Max,
}

impl std::str::FromStr for Fitness {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "mean" => Ok(Fitness::Mean),
            "max" => Ok(Fitness::Max),
            _ => Err(format!("unknown fitness '{s}': expected mean or max")),
        }
    }
}

/// The closed loop a tuning run scores; shared read-only by the evaluating threads.
pub struct ContourObjective {
    simulator: Simulator,
    base: ControllerConfig,
    fitness: Fitness,
}

/// The plant preset called `name`.
pub fn plant_preset(name: &str) -> Result<XyTableParams, String> {
    match name {
        "paper" => Ok(XyTableParams::PAPER),
        "mismatched" => Ok(XyTableParams::mismatched()),
        _ => Err(format!(
            "unknown plant '{name}': expected paper or mismatched"
        )),
    }
}

/// The controller configuration with `factors` (ke, kde, kp, ki, kd) as fuzzy factors.
pub fn with_factors(base: &ControllerConfig, factors: &[f64]) -> ControllerConfig {
    let mut config = *base;
    config.ccc.fuzzy = FuzzyFactors {
        ke: factors[0],
        kde: factors[1],
        kpf: factors[2],
        kif: factors[3],
        kdf: factors[4],
    };
    config
}

impl ContourObjective {
    /// The default fuzzy-PID CCC on `path` at `feed` with the named plant preset.
    pub fn new(path: Path, feed: f64, plant: &str, fitness: Fitness) -> Result<Self, String> {
        Self::lasting(path, feed, plant, fitness, None)
    }

    /// [`new`](Self::new) with a run of `duration` seconds instead of the path end at
    /// the constant feed (the length of a planned run made elsewhere, which this one judges).
    pub fn lasting(
        path: Path,
        feed: f64,
        plant: &str,
        fitness: Fitness,
        duration: Option<f64>,
    ) -> Result<Self, String> {
        let mut config = SimConfig::new(path, feed).with_plant(plant_preset(plant)?);
        config.duration = duration;
        let base = config.effective_controller();
        let simulator = Simulator::new(config).map_err(|e| e.to_string())?;
        Ok(ContourObjective {
            simulator,
            base,
            fitness,
        })
    }

    pub fn ts(&self) -> f64 {
        self.simulator.config().ts
    }

    /// The prepared closed loop (reference samples, true-error index).
    pub fn simulator(&self) -> &Simulator {
        &self.simulator
    }

    /// Metrics of the closed loop with these factors.
    pub fn metrics(&self, factors: &[f64]) -> Result<Metrics, String> {
        self.simulator
            .metrics_with(&with_factors(&self.base, factors))
            .map_err(|e| e.to_string())
    }

    /// The fitness (mm) of these factors; always finite.
    pub fn evaluate(&self, factors: &[f64]) -> f64 {
        match self.metrics(factors) {
            Ok(m) => self.score(&m),
            Err(_) => 2.0 * PENALTY_MM,
        }
    }

    /// The fitness of a run's metrics.
    pub fn score(&self, m: &Metrics) -> f64 {
        if m.is_stable() {
            match self.fitness {
                Fitness::Mean => m.mean_abs_error,
                Fitness::Max => m.max_abs_error,
            }
        } else {
            let planned = self.simulator.samples().max(1) as f64;
            PENALTY_MM * (2.0 - m.samples as f64 / planned)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use contour_core::path::planar::builtin;

    #[test]
    fn paper_factors_score_the_simulators_metrics_and_divergence_is_penalised() {
        let circle = Path::Arc(builtin::circle());
        let objective = ContourObjective::new(
            circle.clone(),
            contour_core::sim::PAPER_CIRCLE_FEED,
            "paper",
            Fitness::Mean,
        )
        .unwrap();
        let paper = [1.0, 1.2, 87.0, 8.5, 4.0];
        let sim =
            Simulator::new(SimConfig::new(circle, contour_core::sim::PAPER_CIRCLE_FEED)).unwrap();
        let m = sim.metrics();
        assert_eq!(objective.evaluate(&paper), m.mean_abs_error);
        assert!(m.mean_abs_error > 0.0 && m.mean_abs_error < 1e-3);
        // Even absurd factors stay stable: the correction is bounded by ccc.limit.
        let wild = objective.evaluate(&[5.0, 5.0, 1e9, 1e9, 1e9]);
        assert!(wild.is_finite() && wild < 1.0, "{wild}");
        // A diverged run scores above any stable one, less so the later it diverged.
        let diverged = |samples| Metrics {
            samples,
            divergence: Some(contour_core::sim::Divergence {
                k: samples,
                t: samples as f64 * 1e-3,
                kind: contour_core::sim::DivergenceKind::NonFinite,
                value: f64::NAN,
            }),
            ..m
        };
        let early = objective.score(&diverged(10));
        let late = objective.score(&diverged(1500));
        assert!(early > late && late > PENALTY_MM && early.is_finite());
        assert!(plant_preset("steel").is_err());
    }
}
