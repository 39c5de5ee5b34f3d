//! A sign for contour errors that have none. In the plane the error is signed against
//! the path's left normal, so when the tool crosses the path the error passes through
//! zero and changes sign while the normal stays put — which is what lets the contour
//! PID's integral unwind. In space a distance and the direction toward the path have no
//! such convention: at a crossing the direction flips and the distance bounces off zero,
//! so an integral of distances only grows and the correction chatters about the path.
//!
//! [`ContinuousSign`] restores the planar behaviour: it keeps the direction of the
//! previous sample and, when the new direction points against it, reports the opposite
//! direction with a negative error. The error vector `error · normal` is unchanged.

use serde::{Deserialize, Serialize};

use crate::contour::ContourEstimate;
use crate::geometry::Vector;

/// The direction last reported (zero until the first nonzero error).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ContinuousSign<const D: usize> {
    previous: Vector<D>,
}

impl<const D: usize> Default for ContinuousSign<D> {
    fn default() -> Self {
        ContinuousSign {
            previous: Vector::zeros(),
        }
    }
}

impl<const D: usize> ContinuousSign<D> {
    /// Orients `estimate` (a distance ≥ 0 and the unit direction toward the path, or a
    /// zero direction on the path) continuously with the previous samples.
    pub fn orient(&mut self, estimate: ContourEstimate<D>) -> ContourEstimate<D> {
        if estimate.normal == Vector::<D>::zeros() {
            // On the path: any direction will do; keep the last one so the sign carries on.
            return ContourEstimate {
                error: 0.0,
                normal: self.previous,
            };
        }
        let oriented = if estimate.normal.dot(&self.previous) < 0.0 {
            ContourEstimate {
                error: -estimate.error,
                normal: -estimate.normal,
            }
        } else {
            estimate
        };
        self.previous = oriented.normal;
        oriented
    }

    /// Forgets the direction.
    pub fn reset(&mut self) {
        self.previous = Vector::zeros();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn crossing_the_path_changes_the_sign_not_the_direction() {
        let mut sign = ContinuousSign::<3>::default();
        let up = Vector::<3>::new(0.0, 0.0, 1.0);
        let first = sign.orient(ContourEstimate {
            error: 2.0,
            normal: up,
        });
        assert_eq!((first.error, first.normal), (2.0, up));
        let on = sign.orient(ContourEstimate {
            error: 0.0,
            normal: Vector::zeros(),
        });
        assert_eq!((on.error, on.normal), (0.0, up));
        // Past the path the direction toward it is −up: reported as −1 along +up.
        let past = sign.orient(ContourEstimate {
            error: 1.0,
            normal: -up,
        });
        assert_eq!((past.error, past.normal), (-1.0, up));
        assert_eq!(past.vector(), -up);
        sign.reset();
        let fresh = sign.orient(ContourEstimate {
            error: 1.0,
            normal: -up,
        });
        assert_eq!((fresh.error, fresh.normal), (1.0, -up));
    }
}
