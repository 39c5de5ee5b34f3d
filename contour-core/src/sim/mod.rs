//! In-process closed loop: interpolator → cross-coupled controller → servo axes, sampled
//! every `Ts` (docs/design/two-axis.md §4.2, 4.5, 4.6). The reference for everything the FMUs must match in
//! co-simulation, and the fitness evaluator of the PSO tuner.
//!
//! # The sample sequence (the FMU co-simulation reproduces it, keep it exactly so)
//!
//! For k = 0, 1, …, with t_k = k·Ts:
//! 1. reference R_k: `interpolator.current().point` at k = 0, then
//!    `interpolator.step().point` for k ≥ 1;
//! 2. actual P_k = `plant.position()` (the plant state at t_k);
//! 3. `out = controller.sample(R_k, P_k)`;
//! 4. record the sample: true contour error of P_k (exact distance to the path, signed,
//!    via [`TrueErrorIndex`] with the previous foot parameter as hint), the estimator's
//!    contour error, the CCC gains and `out.u`;
//! 5. `plant.step(out.u, Ts)`: the command is held over [t_k, t_k+1). (Skipped after the
//!    last sample: nothing would observe it.)
//!
//! The plant starts at rest at the path's start point; controller and estimator start
//! empty. The reference does not depend on the loop, so [`Simulator::new`] runs the
//! interpolator once and keeps its samples; every run replays the same values (the
//! interpolator is deterministic), which keeps a PSO run to controller + plant + true
//! error.
//!
//! # Run length
//!
//! Until the interpolator reports `done` plus `settle` seconds, i.e. the last sample is
//! k_done + round(settle/Ts); or, when `duration` is set, the samples with t_k ≤ duration.
//!
//! # Divergence
//!
//! An unstable loop (absurd gains) must neither panic nor smuggle NaN into a fitness. A
//! run stops at the first sample whose actual position or command is not finite or whose
//! |true contour error| exceeds `abort_error`; that sample is not recorded, the metrics
//! cover the samples before it, and [`Metrics::divergence`] says where and why.

mod config;
mod five_axis;
mod metrics;
mod reference;
mod run;
mod trace;

pub use config::{
    preset_feed, SimConfig, SimError, FREE_CURVE_FEED, MAX_SAMPLES, PAPER_CIRCLE_FEED,
};
pub use five_axis::{
    nearest_on_branch, simulate_five_axis, FiveAxisMetrics, FiveAxisRecord, FiveAxisSimConfig,
};
pub use metrics::{Divergence, DivergenceKind, Metrics};
pub use reference::ReferencePath;
pub use run::{simulate, simulate_metrics, Run, Simulator};
pub use trace::{Record, SimResult, Trace};
