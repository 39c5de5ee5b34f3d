//! What every two-axis contour-error estimator returns, and the interface the
//! cross-coupled controller drives them through.

use serde::{Deserialize, Serialize};

/// Signed contour error and the direction to correct along (docs/design.md §4.1).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ContourEstimate {
    /// Signed distance from the actual point to the path, mm; positive when the actual
    /// point lies to the right of the direction of travel.
    pub error: f64,
    /// Left unit normal of the path at the foot point; for a point right of the path it
    /// points from the actual point toward the path.
    pub normal: [f64; 2],
}

/// A contour-error estimator fed once per control sample.
pub trait ContourEstimator {
    /// Takes the newest reference (command) point and the measured actual point, both mm.
    fn estimate(&mut self, reference: [f64; 2], actual: [f64; 2]) -> ContourEstimate;
    /// Forgets all history (e.g. on FMI reset).
    fn reset(&mut self);
}
