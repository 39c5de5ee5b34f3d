//! Cross-coupled contour control for CNC axes, shipped as FMI 2.0 and FMI 3.0 Co-Simulation
//! FMUs.
//!
//! The algorithms live in the `contour-core` crate and know nothing of FMI. Here,
//! [`framework`] is what every FMU is built from (model trait, variable tables, units,
//! sample clock, state codec and checks), [`models`] holds the eight FMUs (and two test-only
//! ones), and [`fmi`] is the only place that speaks the FMI C ABI (the only `unsafe`).

pub mod build_identity;
pub mod fmi;
pub mod framework;
pub mod models;
