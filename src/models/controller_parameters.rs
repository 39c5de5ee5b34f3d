//! Parameter building blocks both controller models use (`ContourCCC2D`, `ContourCCC5X`):
//! gains that must be ≥ 0, per-axis position-loop gains, and the CCC mode from the two
//! switches.

use super::variable_table::{AxisTemplate, AxisUnit, AxisWord};
use super::variables::{Start, Variable};
use crate::control::{CccMode, Gain};

/// A Real parameter ≥ 0 (a gain or factor).
pub const fn nonnegative(name: &'static str, start: f64, description: &'static str) -> Variable {
    Variable::parameter(name, Start::Real(start), description).min(0.0)
}

/// A position-loop gain of every axis (`axis.x.Kp`, `axis.C.Kd`, …), ≥ 0.
pub const fn axis_gain(
    suffix: &'static str,
    start: f64,
    what: &'static str,
    unit: AxisUnit,
) -> AxisTemplate {
    AxisTemplate::parameter(
        ("axis.", suffix),
        (start, start),
        ("", AxisWord::Label, what),
    )
    .unit(unit)
    .min(0.0)
}

/// The CCC mode the `ccc.enable` and `fuzzy.enable` switches select.
pub fn mode(ccc_enable: bool, fuzzy_enable: bool) -> CccMode {
    match (ccc_enable, fuzzy_enable) {
        (false, _) => CccMode::Off,
        (true, false) => CccMode::Fixed,
        (true, true) => CccMode::Fuzzy,
    }
}

/// The position of a gain in a Kp, Ki, Kd block.
pub fn gain_index(gain: Gain) -> usize {
    match gain {
        Gain::Kp => 0,
        Gain::Ki => 1,
        Gain::Kd => 2,
    }
}
