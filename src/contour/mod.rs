//! Contour-error estimation: exact line/arc errors, the free-curve two-circle estimator,
//! and the brute-force true contour error used as ground truth.

pub mod arc;
pub mod estimate;
pub mod estimator;
pub mod free_curve;
mod geom;
pub mod line;
pub mod true_error;

pub use arc::ArcEstimator;
pub use estimate::{ContourEstimate, ContourEstimator};
pub use estimator::{Estimator, EstimatorKind};
pub use free_curve::FreeCurveEstimator;
pub use line::LineEstimator;
pub use true_error::{true_error, TrueError, TrueErrorIndex};
