//! Tuning the fuzzy CCC's five scaling factors with particle swarm optimisation: the PSO
//! (`pso`), the closed-loop objective over contour-core's simulator (`objective`) or
//! through a loop of FMUs in contour-cosim (`fmu_objective`), run in worker processes
//! (`candidate_process`), and the `ccc-tune` program. Kept out of the contour-fmu crate
//! so that the FMU library links nothing of it (no rayon, no random generator, no
//! progress bar).

pub mod candidate_process;
pub mod fmu_objective;
pub mod objective;
pub mod pso;

pub use pso::{minimize, Algorithm, PsoResult, PsoSettings, Swarm};
