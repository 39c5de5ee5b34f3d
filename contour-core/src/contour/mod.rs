//! Contour-error estimation, split by paper: [`planar`] (the two-axis paper: exact line
//! and arc errors, the free-curve two-circle estimator, the brute-force true error used as
//! ground truth) and [`five_axis`] (the five-axis paper: HMM segment mapping by Viterbi,
//! tip and orientation errors, the evaluation-function estimate). Here: what both share,
//! the estimator interface, and the exact error to a straight line in any dimension.

mod continuous_sign;
mod estimate;
pub mod five_axis;
pub mod planar;
mod spatial_line;

pub use continuous_sign::ContinuousSign;
pub use estimate::{ContourEstimate, ContourEstimator};
pub use spatial_line::SpatialLineEstimator;
