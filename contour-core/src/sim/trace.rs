//! What a run records: one [`Record`] per sample, collected into a plot-ready [`Trace`].

use serde::{Deserialize, Serialize};

use super::metrics::Metrics;
use crate::geometry::Vector;

/// One recorded sample.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Record<const D: usize = 2> {
    /// Sample index.
    pub k: usize,
    /// t_k = k·Ts, s.
    pub t: f64,
    /// Reference (command) point R_k, mm.
    pub reference: Vector<D>,
    /// Actual point P_k (plant position at t_k), mm.
    pub actual: Vector<D>,
    /// True contour error of P_k, mm (in the plane signed, positive right of travel).
    pub true_error: f64,
    /// The controller's estimated contour error, mm.
    pub estimated_error: f64,
    /// CCC gains (Kp, Ki, Kd) used; 0 with the CCC off.
    pub gains: [f64; 3],
    /// Velocity commands in axis order, mm/s, held over [t_k, t_k+1).
    pub u: Vector<D>,
}

/// The time series of a run, one entry per sample (struct of vectors, plot-ready).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Trace<const D: usize = 2> {
    /// Sample times, s.
    pub t: Vec<f64>,
    /// Reference points, mm.
    pub reference: Vec<Vector<D>>,
    /// Measured points, mm.
    pub actual: Vec<Vector<D>>,
    /// True contour errors, mm.
    pub true_error: Vec<f64>,
    /// The controller's estimates, mm.
    pub estimated_error: Vec<f64>,
    /// The contour law's Kp, Ki, Kd in use.
    pub gains: Vec<[f64; 3]>,
    /// Velocity commands, mm/s.
    pub u: Vec<Vector<D>>,
}

impl<const D: usize> Trace<D> {
    pub(crate) fn with_capacity(n: usize) -> Self {
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

    pub(crate) fn push(&mut self, r: &Record<D>) {
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
pub struct SimResult<const D: usize = 2> {
    /// Every sample.
    pub trace: Trace<D>,
    /// The summary.
    pub metrics: Metrics,
}
