//! The FMU framework: what every model is built from and what the FMI layer drives,
//! knowing no FMU and no control law. A model declares its variables ([`variables`],
//! assembled per axis by [`variable_table`], with [`units`] and fixed [`text`]), steps on
//! a [`sample_clock`], implements [`model::Model`], and saves its state through
//! [`saved_state`], which also checks it on restore.

pub mod interface;
pub mod model;
pub mod sample_clock;
pub mod saved_state;
pub mod text;
pub mod units;
pub mod variable_table;
pub mod variables;
