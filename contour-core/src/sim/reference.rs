//! What the simulator needs of a reference path beyond its geometry: the exact
//! contour error used as the truth, and the contour estimator the controller runs on it.
//! Planar [`Path`]s give the signed error and the estimator chosen by kind; a straight
//! [`Line`] in any dimension gives the distance and the exact spatial line estimator.

use std::fmt::Debug;

use crate::contour::planar::{Estimator, EstimatorKind, TrueError, TrueErrorIndex};
use crate::contour::{ContourEstimator, SpatialLineEstimator};
use crate::geometry::Vector;
use crate::path::planar::Path;
use crate::path::{Curve, Line};

/// A path the in-process closed loop can follow.
pub trait ReferencePath<const D: usize>: Curve<D> + Clone + Debug {
    /// The prepared exact-distance search (built once per simulator).
    type Truth: Clone + Debug;
    /// The estimator the controller runs.
    type Estimator: ContourEstimator<D> + Clone + Debug;

    /// Prepares the exact-distance search.
    fn truth(&self) -> Self::Truth;
    /// Exact contour error of `p`; `hint` is the previous sample's foot parameter.
    fn true_error(truth: &Self::Truth, p: Vector<D>, hint: f64) -> TrueError<D>;
    /// The estimator of `kind` for this path (paths with one exact estimator ignore it).
    fn estimator(&self, kind: EstimatorKind) -> Self::Estimator;
}

impl ReferencePath<2> for Path {
    type Truth = TrueErrorIndex;
    type Estimator = Estimator;

    fn truth(&self) -> TrueErrorIndex {
        TrueErrorIndex::new(self)
    }
    fn true_error(truth: &TrueErrorIndex, p: Vector<2>, hint: f64) -> TrueError<2> {
        truth.error(p, hint)
    }
    fn estimator(&self, kind: EstimatorKind) -> Estimator {
        Estimator::for_path(kind, self)
    }
}

impl<const D: usize> ReferencePath<D> for Line<D> {
    type Truth = Line<D>;
    type Estimator = SpatialLineEstimator<D>;

    fn truth(&self) -> Line<D> {
        self.clone()
    }
    /// Distance to the segment (not the infinite line: the truth counts overshoot).
    fn true_error(line: &Line<D>, p: Vector<D>, _hint: f64) -> TrueError<D> {
        let u = line.nearest_parameter(&p);
        let foot = line.point(u);
        let error = crate::geometry::dist(&foot, &p);
        let normal = crate::geometry::unit(&(foot - p)).unwrap_or_else(Vector::zeros);
        TrueError {
            error,
            normal,
            u,
            foot,
        }
    }
    fn estimator(&self, _kind: EstimatorKind) -> SpatialLineEstimator<D> {
        SpatialLineEstimator::new(self)
    }
}
