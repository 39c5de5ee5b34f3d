//! What makes a real axis nonlinear (docs/design/two-axis.md §4.5b): Coulomb and Stribeck
//! friction, backlash in the transmission and the drive's current limit. All off by
//! default; an axis with none of them is the linear axis of §4.5, integrated exactly.

use crate::math;
use serde::{Deserialize, Serialize};

/// The nonlinear effects of one axis. Torques are at the motor, like the viscous
/// friction B; velocities and the play in axis units (mm or rad).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct AxisEffects {
    /// Coulomb (sliding) friction torque, N·m at the motor.
    pub coulomb: f64,
    /// Static (breakaway) friction torque, N·m at the motor: 0 for none beyond the
    /// Coulomb torque, otherwise ≥ it.
    pub stiction: f64,
    /// Stribeck velocity, mm/s or rad/s: the friction falls from the static to the
    /// Coulomb torque as e^(−(v/vs)²); 0 for a drop at once.
    pub stribeck_velocity: f64,
    /// Total play of the transmission, mm or rad (0: none).
    pub backlash: f64,
    /// The drive's current limit, A (0: none).
    pub current_max: f64,
}

impl Default for AxisEffects {
    fn default() -> Self {
        Self::NONE
    }
}

impl AxisEffects {
    /// No friction beyond the viscous, no play, no current limit: the linear axis.
    pub const NONE: AxisEffects = AxisEffects {
        coulomb: 0.0,
        stiction: 0.0,
        stribeck_velocity: 0.0,
        backlash: 0.0,
        current_max: 0.0,
    };

    /// True when every effect is off, so the axis is linear and integrated exactly.
    pub fn is_none(&self) -> bool {
        *self == Self::NONE
    }

    /// Every field finite and ≥ 0, the static torque 0 or at least the Coulomb one. The
    /// error names the field as the FMUs spell it.
    pub fn validate(&self) -> Result<(), String> {
        for (name, value) in [
            ("coulomb", self.coulomb),
            ("stiction", self.stiction),
            ("stribeckVelocity", self.stribeck_velocity),
            ("backlash", self.backlash),
            ("currentMax", self.current_max),
        ] {
            if !(value.is_finite() && value >= 0.0) {
                return Err(format!("{name} must be finite and >= 0 (got {value})"));
            }
        }
        if self.stiction > 0.0 && self.stiction < self.coulomb {
            return Err(format!(
                "stiction ({}) must be 0 or at least coulomb ({})",
                self.stiction, self.coulomb
            ));
        }
        Ok(())
    }

    /// The torque that must be passed to move the axis from rest, N·m.
    pub fn breakaway(&self) -> f64 {
        self.coulomb.max(self.stiction)
    }

    /// The friction torque opposing a sliding speed `speed` > 0, N·m:
    /// Tc + (Ts − Tc)·e^(−(v/vs)²), the Coulomb torque alone without a Stribeck velocity.
    pub fn sliding_friction(&self, speed: f64) -> f64 {
        let drop = self.breakaway() - self.coulomb;
        if drop > 0.0 && self.stribeck_velocity > 0.0 {
            let r = speed / self.stribeck_velocity;
            self.coulomb + drop * math::exp(-r * r)
        } else {
            self.coulomb
        }
    }

    /// The current limit, A (infinite when there is none).
    pub fn current_limit(&self) -> f64 {
        if self.current_max > 0.0 {
            self.current_max
        } else {
            f64::INFINITY
        }
    }
}
