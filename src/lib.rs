//! Cross-coupled contour control for CNC axes, shipped as FMI 2.0 Co-Simulation FMUs.
//!
//! The algorithm modules (`path`, `contour`, `control`, `plant`, `sim`) know nothing of
//! FMI; `models` wraps them as variable tables plus step functions, and `fmi2` is the only
//! place that speaks the FMI C ABI.

pub mod contour;
pub mod control;
pub mod fmi2;
pub mod geometry;
pub mod kinematics;
pub mod models;
pub mod path;
pub mod plant;
pub mod sim;
