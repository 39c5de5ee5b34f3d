//! Contour-error estimation (in progress).

pub mod estimate;

pub use estimate::{ContourEstimate, ContourEstimator};
