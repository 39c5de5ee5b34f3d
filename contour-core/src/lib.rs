//! Cross-coupled contour control for CNC axes, without FMI: everything the FMUs of
//! `contour-fmu` compute, and the in-process loops and offline evaluation that the tools
//! (`contour-eval`, `contour-tune`), tests and benchmarks run.
//!
//! The floors, each using only those above it: [`geometry`], [`kinematics`] and [`limits`];
//! [`path`] (the curves both machines' references are made of, the feed-rate interpolator)
//! with [`part_program`] (what CAM systems write, read into one model) and each machine's
//! paths (`path::planar`, `path::five_axis`); [`contour`] (contour errors, split by
//! paper into `planar` and `five_axis`); [`control`] (PID, fuzzy gain scheduling, the
//! cross-coupled controllers); [`plant`] (the test plants); [`sim`] (the closed loops in
//! process); [`shared`] keeps what instances share (plans, indexes) for their owner. Units:
//! mm, rad, s.

#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub mod contour;
pub mod control;
pub mod geometry;
pub mod kinematics;
pub mod limits;
pub mod math;
pub mod part_program;
pub mod path;
pub mod plant;
pub mod shared;
pub mod sim;
