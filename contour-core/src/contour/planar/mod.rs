//! The two-axis paper's contour errors (docs/design/two-axis.md §4.1): exact errors of a line and
//! of an arc, the free-curve estimator (two circles through the interpolation points
//! nearest the actual position), the exact error along a whole programmed path, the
//! estimator chosen by name, and the true error by
//! brute-force search that the tests and metrics take as ground truth.

mod arc;
mod choice;
mod free_curve;
mod line;
mod local_circle;
mod program;
mod true_error;
mod true_error_index;
mod true_error_indexes;

pub use arc::ArcEstimator;
pub use choice::{Estimator, EstimatorKind, SavedEstimator};
pub use free_curve::FreeCurveEstimator;
pub use line::LineEstimator;
pub use program::{ProgramEstimator, SavedProgramEstimator, ON_PATH};
pub use true_error::{true_error, TrueError};
pub use true_error_index::TrueErrorIndex;
pub use true_error_indexes::TrueErrorIndexes;
