//! A run's summary (maximum and mean |true contour error|, overall and after the
//! start-up transient) and how it stopped early, if it did.

use serde::{Deserialize, Serialize};

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
    /// Mean over all samples (the PSO fitness of docs/design/two-axis.md §4.4).
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

/// Running sums of the metrics; the recorded and the metrics-only paths share it, so they
/// agree bit for bit.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Accumulator {
    n: usize,
    max: f64,
    sum: f64,
    settled_n: usize,
    settled_max: f64,
    settled_sum: f64,
}

impl Accumulator {
    pub(crate) fn add(&mut self, settled: bool, abs_error: f64) {
        self.n += 1;
        self.max = self.max.max(abs_error);
        self.sum += abs_error;
        if settled {
            self.settled_n += 1;
            self.settled_max = self.settled_max.max(abs_error);
            self.settled_sum += abs_error;
        }
    }

    pub(crate) fn metrics(&self, divergence: Option<Divergence>) -> Metrics {
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
