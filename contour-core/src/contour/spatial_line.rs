//! Exact contour error to a straight line in any dimension: the distance from the actual
//! point to the line and the unit vector toward its foot point, signed continuously
//! from sample to sample ([`ContinuousSign`]) as the planar
//! [`LineEstimator`](crate::contour::planar::LineEstimator) is signed by the side of travel.
//!
//! Measured to the infinite line, like the planar estimator, so a point lagging behind
//! the segment start still gets the perpendicular error to correct.

use serde::{Deserialize, Serialize};

use crate::contour::{ContinuousSign, ContourEstimate, ContourEstimator};
use crate::geometry::{self, Vector};
use crate::path::Line;

/// Distance-to-line estimator in `D` dimensions.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SpatialLineEstimator<const D: usize> {
    point: Vector<D>,
    dir: Vector<D>,
    sign: ContinuousSign<D>,
}

impl<const D: usize> SpatialLineEstimator<D> {
    /// Exact error against the line through `line`.
    pub fn new(line: &Line<D>) -> Self {
        SpatialLineEstimator {
            point: line.start(),
            dir: line.direction(),
            sign: ContinuousSign::default(),
        }
    }

    /// Foot point of `p` on the infinite line.
    pub fn foot(&self, p: &Vector<D>) -> Vector<D> {
        self.point + self.dir * (p - self.point).dot(&self.dir)
    }
}

impl<const D: usize> ContourEstimator<D> for SpatialLineEstimator<D> {
    fn estimate(&mut self, _reference: Vector<D>, actual: Vector<D>) -> ContourEstimate<D> {
        let to_foot = self.foot(&actual) - actual;
        if !geometry::is_finite(&to_foot) {
            // A NaN or infinite position has no contour error to report, only NaN.
            return ContourEstimate {
                error: f64::NAN,
                normal: to_foot,
            };
        }
        let error = geometry::norm(&to_foot);
        let normal = geometry::unit(&to_foot).unwrap_or_else(Vector::zeros);
        self.sign.orient(ContourEstimate { error, normal })
    }

    fn reset(&mut self) {
        self.sign.reset();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn distance_and_direction_in_three_dimensions() {
        let line = Line::new([0.0, 0.0, 0.0], [10.0, 0.0, 0.0]).unwrap();
        let mut e = SpatialLineEstimator::new(&line);
        let r = Vector::<3>::zeros();
        let est = e.estimate(r, Vector::<3>::new(-4.0, 3.0, 4.0));
        assert_eq!(est.error, 5.0);
        assert!((est.vector() - Vector::<3>::new(0.0, -3.0, -4.0)).amax() < 1e-15);
        let on = e.estimate(r, Vector::<3>::new(7.0, 0.0, 0.0));
        assert_eq!((on.error, on.vector()), (0.0, Vector::<3>::zeros()));
        let nan = e.estimate(r, Vector::<3>::new(f64::NAN, 1.0, 0.0));
        assert!(nan.error.is_nan());
        let inf = e.estimate(r, Vector::<3>::new(0.0, f64::INFINITY, 0.0));
        assert!(inf.error.is_nan());
    }

    #[test]
    fn agrees_with_the_planar_estimator_up_to_one_sign() {
        // Points zig-zagging across the line: the planar error changes sign by the side of
        // travel, the spatial one continuously from its first sample — so the two agree
        // up to one sign for the whole sequence, and the error vectors agree exactly.
        let line = Line::new([1.0, 2.0], [4.0, 6.0]).unwrap();
        let mut spatial = SpatialLineEstimator::new(&line);
        let mut planar = crate::contour::planar::LineEstimator::new(&line);
        let points = [
            [3.0, -1.0],
            [2.0, 3.5],
            [-2.0, 5.0],
            [10.0, 10.5],
            [0.5, 1.0],
        ];
        let mut sign = None;
        for p in points {
            let (s, q) = (
                spatial.estimate(p.into(), p.into()),
                planar.estimate(p.into(), p.into()),
            );
            let k = *sign.get_or_insert(s.error / q.error);
            assert!((k.abs() - 1.0).abs() < 1e-12);
            assert!((s.error - k * q.error).abs() < 1e-12);
            assert!((s.vector() - q.vector()).amax() < 1e-12);
        }
    }
}
