//! What the machine can do (docs/design/five-axis.md §5.3b): the rotary axes' travel,
//! every joint's velocity and acceleration, and what the path may ask: acceleration and
//! jerk along the tool path, and how far the planned reference may leave the CL data.
//!
//! Defaults are those of a mid-size trunnion table (a cradle tilting −35° … +110°,
//! an endless C table; linear axes at 30 m/min and 0.5 g, rotary axes at about 30 and
//! 50 rpm) cutting a finishing pass: 0.2 g and 100 m/s³ along the path, the tool path
//! within 5 µm and the tool axis within 2 mrad of the CL data.

use serde::{Deserialize, Serialize};

use std::f64::consts::PI;

use crate::kinematics::Joints;

/// The joints' limits, in joint order X, Y, Z (mm, mm/s, mm/s²), A, C (rad, rad/s,
/// rad/s²).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct JointLimits {
    /// Least position of each joint (X, Y, Z unbounded).
    pub min: Joints,
    /// Greatest position of each joint.
    pub max: Joints,
    /// Greatest speed of each joint (> 0).
    pub velocity: Joints,
    /// Greatest acceleration of each joint (> 0).
    pub acceleration: Joints,
}

/// An unlimited travel, as LinuxCNC writes one: far beyond any part.
pub const ENDLESS: f64 = 1e9;

impl JointLimits {
    /// The defaults of the module docs.
    pub const DEFAULT: JointLimits = JointLimits {
        min: Joints::new(-ENDLESS, -ENDLESS, -ENDLESS, -35.0 * PI / 180.0, -ENDLESS),
        max: Joints::new(ENDLESS, ENDLESS, ENDLESS, 110.0 * PI / 180.0, ENDLESS),
        velocity: Joints::new(500.0, 500.0, 500.0, 3.0, 5.0),
        acceleration: Joints::new(5000.0, 5000.0, 5000.0, 20.0, 30.0),
    };

    /// No limit anywhere (every value `ENDLESS`): the machine of the loops before limits.
    pub const UNLIMITED: JointLimits = JointLimits {
        min: Joints::new(-ENDLESS, -ENDLESS, -ENDLESS, -ENDLESS, -ENDLESS),
        max: Joints::new(ENDLESS, ENDLESS, ENDLESS, ENDLESS, ENDLESS),
        velocity: Joints::new(ENDLESS, ENDLESS, ENDLESS, ENDLESS, ENDLESS),
        acceleration: Joints::new(ENDLESS, ENDLESS, ENDLESS, ENDLESS, ENDLESS),
    };
}

impl Default for JointLimits {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// What the tool path may ask of the machine, and how far the planned reference may
/// deviate from the programmed one.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct PathLimits {
    /// Greatest tool-tip feed, mm/s (> 0).
    pub feed: f64,
    /// Greatest acceleration of the tool tip, tangential and centripetal together,
    /// mm/s²; 0 plans nothing (the tip at constant feed, as before limits).
    pub accel: f64,
    /// Greatest jerk of the tool tip, mm/s³; 0: no jerk limit (trapezoidal profiles).
    pub jerk: f64,
    /// How far the planned tool tip may leave the programmed path, mm (≥ 0).
    pub tolerance: f64,
    /// How far the planned tool axis may leave the programmed one, rad (≥ 0).
    pub orientation_tolerance: f64,
    /// Half-angle of the cone about the C axis inside which C's turn is planned instead
    /// of followed, rad (≥ 0).
    pub pole_cone: f64,
}

impl PathLimits {
    /// The defaults at `feed`.
    pub fn at_feed(feed: f64) -> Self {
        PathLimits {
            feed,
            accel: 2000.0,
            jerk: 1e5,
            tolerance: 0.005,
            orientation_tolerance: 2e-3,
            pole_cone: 2.0 * PI / 180.0,
        }
    }
}

impl JointLimits {
    /// Checks the limits; the error names the first bad value.
    pub fn check(&self) -> Result<(), String> {
        const NAMES: [&str; 5] = ["X", "Y", "Z", "A", "C"];
        for (i, name) in NAMES.iter().enumerate() {
            let (lo, hi) = (self.min[i], self.max[i]);
            if !(lo.is_finite() && hi.is_finite() && lo < hi) {
                return Err(format!(
                    "the travel of {name}, [{lo}, {hi}], must be finite and not empty"
                ));
            }
            let (v, a) = (self.velocity[i], self.acceleration[i]);
            if !(v.is_finite() && v > 0.0) {
                return Err(format!("{name}.vmax must be finite and > 0 (got {v})"));
            }
            if !(a.is_finite() && a > 0.0) {
                return Err(format!("{name}.amax must be finite and > 0 (got {a})"));
            }
        }
        Ok(())
    }
}

impl PathLimits {
    /// Checks the limits; the error names the first bad value.
    pub fn check(&self) -> Result<(), String> {
        let positive = [("feed", self.feed)];
        let non_negative = [
            ("accel", self.accel),
            ("jerk", self.jerk),
            ("tolerance", self.tolerance),
            ("orientationTolerance", self.orientation_tolerance),
            ("poleCone", self.pole_cone),
        ];
        for (name, v) in positive {
            if !(v.is_finite() && v > 0.0) {
                return Err(format!("{name} must be finite and > 0 (got {v})"));
            }
        }
        for (name, v) in non_negative {
            if !(v.is_finite() && v >= 0.0) {
                return Err(format!("{name} must be finite and >= 0 (got {v})"));
            }
        }
        if self.accel > 0.0 && self.jerk > 0.0 && self.tolerance == 0.0 {
            return Err(
                "tolerance must be > 0 with a jerk limit: the jerk filter rounds \
                        every corner of the path by up to the tolerance"
                    .into(),
            );
        }
        if self.accel > 0.0 && self.orientation_tolerance == 0.0 {
            return Err(
                "orientationTolerance must be > 0 for a plan: near the C axis the \
                        tool axis can only be kept within a tolerance of the programmed one"
                    .into(),
            );
        }
        if self.pole_cone >= std::f64::consts::FRAC_PI_2 {
            return Err(format!(
                "poleCone must be below pi/2 rad (got {})",
                self.pole_cone
            ));
        }
        Ok(())
    }
}
