//! The five-axis paper's contour errors (docs/design/five-axis.md §5.2–5.3a): measured samples mapped
//! to reference segments by a hidden Markov model solved by Viterbi (offline over a run,
//! windowed, or online as samples arrive), the tip and orientation errors at the foot
//! point (online on the swept normal plane, offline on the reference read as straight
//! moves or as a smooth curve, [`reference_shape`]), and the evaluation-function estimate; [`run_evaluation`] puts them together for
//! a whole measured run. The three mappers differ in which segments are candidates and
//! where the costs and back-pointers are kept; the recursion itself is one core,
//! [`viterbi`], that they share.

pub mod evaluation;
pub mod evaluation_online;
pub mod hmm;
pub mod hmm_online;
pub mod pose_error;
pub mod reference_shape;
pub mod run_evaluation;
pub mod run_mapping;
pub mod viterbi;
pub mod window_costs;
