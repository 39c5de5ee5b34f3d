//! Contour-error estimation: exact line/arc errors, the free-curve two-circle estimator,
//! the brute-force true contour error used as ground truth (all planar), and the exact
//! error to a straight line in any dimension.

pub mod arc;
pub mod choice;
pub mod continuous_sign;
pub mod estimate;
pub mod evaluation;
pub mod evaluation_online;
pub mod free_curve;
pub mod hmm;
pub mod hmm_online;
pub mod line;
mod local_circle;
pub mod pose_error;
pub mod run_evaluation;
pub mod spatial_line;
pub mod true_error;

pub use arc::ArcEstimator;
pub use choice::{Estimator, EstimatorKind};
pub use continuous_sign::ContinuousSign;
pub use estimate::{ContourEstimate, ContourEstimator};
pub use free_curve::FreeCurveEstimator;
pub use line::LineEstimator;
pub use spatial_line::SpatialLineEstimator;
pub use true_error::{true_error, TrueError, TrueErrorIndex};
