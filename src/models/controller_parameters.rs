//! Parameter building blocks both controller models use (`ContourCCC2D`, `ContourCCC5X`):
//! gains that must be ≥ 0, per-axis position-loop gains, and the CCC mode from the two
//! switches.

use crate::framework::variable_table::{AxisTemplate, AxisUnit, AxisWord};
use crate::framework::variables::{Start, Variable};
use contour_core::control::{CccMode, Gain, Pid};

/// A Real parameter ≥ 0 (a gain or factor).
pub const fn nonnegative(name: &'static str, start: f64, description: &'static str) -> Variable {
    Variable::parameter(name, Start::Real(start), description).min(0.0)
}

/// The velocity feed-forward gain: the command gains `feedForward`·vref (1 adds the
/// reference's own velocity; 0, the default, none).
pub const FEED_FORWARD: Variable = nonnegative(
    "feedForward",
    0.0,
    "Velocity feed-forward gain: the command adds feedForward * vref (0: none, 1: the \
     reference's velocity)",
);

/// The acceleration feed-forward time: the command gains `accelerationFeedForward`·aref
/// (a drive's velocity loop lags by about its time constant times the acceleration).
pub const ACCELERATION_FEED_FORWARD: Variable = nonnegative(
    "accelerationFeedForward",
    0.0,
    "Acceleration feed-forward time: the command adds accelerationFeedForward * aref; the \
     drives' velocity-loop time constant cancels their lag behind the velocity feed-forward \
     (0: none)",
)
.unit("s");

/// Checks a restored state's feed-forward parameters (`feedForward`,
/// `accelerationFeedForward`) as the parameters' own checks would.
pub fn check_feed_forward(velocity: f64, acceleration: f64) -> Result<(), String> {
    for (parameter, value) in [
        (&FEED_FORWARD, velocity),
        (&ACCELERATION_FEED_FORWARD, acceleration),
    ] {
        if !(value.is_finite() && value >= 0.0) {
            return Err(format!(
                "{} = {value} must be finite and >= 0",
                parameter.name
            ));
        }
    }
    Ok(())
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

/// A PID restored from bytes: its period, gains, limit and memory (integral and previous
/// error) as the configuration would have made them.
pub fn check_pid(name: &str, pid: &Pid, ts: f64) -> Result<(), String> {
    if pid.ts() != ts {
        return Err(format!(
            "{name}: PID sample period {} s differs from Ts = {ts} s",
            pid.ts()
        ));
    }
    if !pid.integral().is_finite() {
        return Err(format!(
            "{name}: PID memory (integral) = {} is not finite",
            pid.integral()
        ));
    }
    if let Some(e) = pid.previous_error().filter(|e| !e.is_finite()) {
        return Err(format!(
            "{name}: PID memory (previous error) = {e} is not finite"
        ));
    }
    let g = pid.gains();
    for (gain, value) in [("Kp", g.kp), ("Ki", g.ki), ("Kd", g.kd)] {
        if !(value.is_finite() && value >= 0.0) {
            return Err(format!(
                "{name}: PID gain {gain} = {value} must be finite and >= 0"
            ));
        }
    }
    if let Some(limit) = pid.limit().filter(|l| !(l.is_finite() && *l > 0.0)) {
        return Err(format!(
            "{name}: PID output limit {limit} must be finite and > 0"
        ));
    }
    Ok(())
}
