//! What every contour-error estimator returns, and the interface the cross-coupled
//! controller drives them through, in any dimension.

use serde::{Deserialize, Serialize};

use crate::geometry::Vector;

/// A contour error and the direction to correct along (docs/design/two-axis.md §4.1).
///
/// `error · normal` is the error vector from the actual point to its foot point on the
/// path. In the plane `error` is signed (positive when the actual point lies right of the
/// direction of travel) and `normal` is the path's left unit normal, so both stay smooth
/// when the tool crosses the path. In space an estimator measures the distance and the
/// unit vector toward the path and signs them continuously from sample to sample
/// ([`ContinuousSign`](super::ContinuousSign)), so the error changes sign where the tool
/// crosses the path, as in the plane.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ContourEstimate<const D: usize = 2> {
    /// Contour error, mm, signed (see above).
    pub error: f64,
    /// Unit direction such that `error · normal` points from the actual point to the path.
    pub normal: Vector<D>,
}

impl<const D: usize> ContourEstimate<D> {
    /// The error vector: from the actual point to its foot point on the path, mm.
    pub fn vector(&self) -> Vector<D> {
        self.normal * self.error
    }
}

impl<const D: usize> Default for ContourEstimate<D> {
    fn default() -> Self {
        ContourEstimate {
            error: 0.0,
            normal: Vector::zeros(),
        }
    }
}

/// A contour-error estimator fed once per control sample.
pub trait ContourEstimator<const D: usize = 2> {
    /// Takes the newest reference (command) point and the measured actual point, both mm.
    fn estimate(&mut self, reference: Vector<D>, actual: Vector<D>) -> ContourEstimate<D>;
    /// Forgets all history (e.g. on FMI reset).
    fn reset(&mut self);
}
