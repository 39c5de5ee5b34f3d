//! Parameter building blocks both controller models use (`ContourCCC2D`, `ContourCCC5X`):
//! gains that must be ≥ 0, per-axis position-loop gains, and the CCC mode from the two
//! switches; and their internal state ([`ControllerState`]), whose check both share.

use crate::framework::model::Environment;
use crate::framework::sample_clock::SampleClock;
use crate::framework::saved_state::SavedState;
use crate::framework::variable_table::{Axis, AxisTemplate, AxisUnit, AxisWord};
use crate::framework::variables::{Start, Variable};
use contour_core::control::{CccMode, FeedForward, Gain, Pid};

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

/// The acceleration feed-forward time T_a: the command gains T_a times the acceleration
/// at the middle of the sample's hold ([`FeedForward`]). A drive whose velocity loop has
/// the time constant τ takes T_a = Ts/(1 − e^(−Ts/τ)) ≈ τ + Ts/2.
pub const ACCELERATION_FEED_FORWARD: Variable = nonnegative(
    "accelerationFeedForward",
    0.0,
    "Acceleration feed-forward time: the command adds accelerationFeedForward times aref \
     extrapolated to the middle of the sample's hold; for drives whose velocity loops have \
     the time constant tau, Ts/(1 - exp(-Ts/tau)), about tau + Ts/2 (0: none)",
)
.unit("s");

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

/// A controller model's internal state (saved as `Option<ControllerState<_>>` with the
/// model's layout): its control law `C`, the sample clock it runs on and the feed-forward.
#[derive(Clone, serde::Serialize, serde::Deserialize)]
pub struct ControllerState<C, const D: usize> {
    pub controller: C,
    pub clock: SampleClock,
    pub feed_forward: FeedForward<D>,
}

/// A controller model's control law, as the check of its restored [`ControllerState`]
/// sees it: the part both models share is checked once, the rest by the model.
pub trait SavedController<const D: usize>: Sized {
    /// The axes of the position loops.
    const AXES: &'static [Axis];

    /// The configuration's sample period Ts, s.
    fn ts(&self) -> f64;

    /// The configuration's own check; the error names the model's parameter.
    fn check_config(&self) -> Result<(), String>;

    /// The position loops, one per axis of [`SavedController::AXES`].
    fn position_loops(&self) -> &[Pid];

    /// The model's own part of the check: its contour laws and their memories (`state`
    /// whole, so that a field's path in a message starts at the state).
    fn check_rest(state: &ControllerState<Self, D>) -> Result<(), String>;
}

impl<C, const D: usize> SavedState for ControllerState<C, D>
where
    C: SavedController<D> + serde::de::DeserializeOwned,
{
    /// Checks a restored state like the parameters it was built from; the error names
    /// the offending value.
    fn validate(&self, time: f64, _environment: &Environment) -> Result<(), String> {
        self.clock.validate_at(time)?;
        self.feed_forward
            .validate_at(time)
            .map_err(|e| format!("feed-forward: {e}"))?;
        let controller = &self.controller;
        controller
            .check_config()
            .map_err(|e| format!("controller configuration: {e}"))?;
        let ts = controller.ts();
        if self.clock.period() != ts {
            return Err(format!(
                "sample clock period {} s differs from the controller's Ts = {ts} s",
                self.clock.period(),
            ));
        }
        for (axis, pid) in C::AXES.iter().zip(controller.position_loops()) {
            check_pid(&format!("{} position loop", axis.label), pid, ts)?;
        }
        C::check_rest(self)
    }
}
