//! Tuning the fuzzy CCC's five scaling factors with particle swarm optimisation.

pub mod objective;
pub mod pso;

pub use pso::{minimize, Algorithm, PsoResult, PsoSettings, Swarm};
