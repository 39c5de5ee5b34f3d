//! One axis of a digital servo drive: the velocity loop a real machine has in each axis's
//! drive, between the NC's velocity command and the mechanics' force or torque
//! (issue 24's ServoDrive; docs/design/two-axis.md §4.10).
//!
//! Like a digital drive it samples its inputs once per step h (the velocity command u
//! and the measured velocity v, held over the step) and gives one effort for the step:
//!
//! ```text
//! v_f ← v_f + (1 − e^(−h/Tf))·(v − v_f)         velocity filter (Tf = 0: v_f = v)
//! e   = u − v_f
//! d   = Kvp·e + I                                I = Kvi·∫e dt up to the sample
//! d_s = clamp(d, ±effortMax)
//! I   ← I + Kvi·e·h   unless d is saturated and e drives it further in (anti-windup)
//! f   ← f + (1 − e^(−h/Tc))·(d_s − f)           current-loop lag (Tc = 0: f = d_s)
//! ```
//!
//! I is the exact integral of the held error, so without saturation the effort is the
//! law effort = Kvp·e + Kvi·∫e dt at every sample. The filter and the lag are first-order
//! systems discretised exactly for an input held over the step, so at common sample
//! times their values do not depend on the step. The integral is also kept within
//! ±effortMax (conditional integration alone lets it drift while the proportional part
//! saturates). Units are the caller's: effort per velocity for Kvp, effort per length
//! (or angle) for Kvi, so the same law serves a linear axis (N, mm/s) and a rotary one
//! (N·m, rad/s).

use crate::math;
use serde::{Deserialize, Serialize};

/// The drive's gains and limits.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct DriveParams {
    /// Proportional gain: effort per unit of velocity error (N·s/mm, N·m·s/rad).
    pub kvp: f64,
    /// Integral gain: effort per unit of integrated velocity error (N/mm, N·m/rad).
    pub kvi: f64,
    /// Largest effort either way (N, N·m), > 0.
    pub effort_max: f64,
    /// Time constant of the current loop, s (0: the effort follows at once).
    pub current_lag: f64,
    /// Time constant of the measured velocity's low-pass filter, s (0: unfiltered).
    pub velocity_filter: f64,
}

impl DriveParams {
    /// Checks every field: finite; gains and time constants ≥ 0; effortMax > 0.
    pub fn validate(&self) -> Result<(), String> {
        for (name, value) in [
            ("Kvp", self.kvp),
            ("Kvi", self.kvi),
            ("currentLag", self.current_lag),
            ("velocityFilter", self.velocity_filter),
        ] {
            if !(value.is_finite() && value >= 0.0) {
                return Err(format!("{name} must be finite and >= 0 (got {value})"));
            }
        }
        if !(self.effort_max.is_finite() && self.effort_max > 0.0) {
            return Err(format!(
                "effortMax must be finite and > 0 (got {})",
                self.effort_max
            ));
        }
        Ok(())
    }
}

/// The drive's state: the filtered velocity, the integral term and the effort.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct VelocityDrive {
    params: DriveParams,
    filtered_velocity: f64,
    /// Kvi·∫e dt, in effort units.
    integral: f64,
    effort: f64,
}

/// The share of the way a first-order system with time constant `tau` goes toward an
/// input held over `h`: 1 − e^(−h/τ), exactly 1 without a lag.
fn approach(tau: f64, h: f64) -> f64 {
    if tau > 0.0 {
        -math::expm1(-h / tau)
    } else {
        1.0
    }
}

impl VelocityDrive {
    /// A drive at rest with its filter at the measured velocity `velocity`.
    pub fn new(params: DriveParams, velocity: f64) -> Result<Self, String> {
        params.validate()?;
        if !velocity.is_finite() {
            return Err(format!("the measured velocity {velocity} is not finite"));
        }
        Ok(VelocityDrive {
            params,
            filtered_velocity: velocity,
            integral: 0.0,
            effort: 0.0,
        })
    }

    /// Its gains and limits.
    pub fn params(&self) -> &DriveParams {
        &self.params
    }

    /// The effort of the last step (0 before the first).
    pub fn effort(&self) -> f64 {
        self.effort
    }

    /// Kvi·∫e dt so far, in effort units.
    pub fn integral(&self) -> f64 {
        self.integral
    }

    /// One step of length `h` > 0 with the command `command` and the measured velocity
    /// `velocity` sampled at its start: returns the effort for the step.
    pub fn step(&mut self, command: f64, velocity: f64, h: f64) -> f64 {
        let p = self.params;
        // Without a filter (or a lag) the value is taken as it is: x + 1·(y − x) is not
        // always y in floating point.
        if p.velocity_filter > 0.0 {
            self.filtered_velocity +=
                approach(p.velocity_filter, h) * (velocity - self.filtered_velocity);
        } else {
            self.filtered_velocity = velocity;
        }
        let error = command - self.filtered_velocity;
        let demand = p.kvp * error + self.integral;
        let limited = demand.clamp(-p.effort_max, p.effort_max);
        // Conditional integration: not while the demand is saturated and the error
        // pushes it further into the limit.
        let winding_up = demand != limited && error * demand > 0.0;
        if !winding_up {
            self.integral = (self.integral + p.kvi * error * h).clamp(-p.effort_max, p.effort_max);
        }
        self.effort = if p.current_lag > 0.0 {
            // Between the last effort and the new demand, both within the limit, but for
            // rounding.
            (self.effort + approach(p.current_lag, h) * (limited - self.effort))
                .clamp(-p.effort_max, p.effort_max)
        } else {
            limited
        };
        self.effort
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const P: DriveParams = DriveParams {
        kvp: 30.0,
        kvi: 2000.0,
        effort_max: 5000.0,
        current_lag: 0.0,
        velocity_filter: 0.0,
    };

    #[test]
    fn without_saturation_the_effort_is_the_pi_law_of_the_held_error() {
        // A constant error e: Kvp·e + Kvi·e·t at t = k·h (the integral of the error held
        // over the k steps before the sample).
        let mut drive = VelocityDrive::new(P, 0.0).unwrap();
        let (e, h) = (10.0, 1e-3);
        for k in 0..100 {
            let t = k as f64 * h;
            let want = P.kvp * e + P.kvi * e * t;
            let got = drive.step(e, 0.0, h);
            assert!((got - want).abs() <= 1e-12 * want, "{k}: {got} vs {want}");
        }
    }

    #[test]
    fn the_filter_and_the_lag_are_first_order_exactly_whatever_the_step() {
        // A step of the measured velocity through the filter alone (Kvi = 0, Kvp = 1:
        // the effort is −v_f): v_f(t) = v·(1 − e^(−t/Tf)) at the samples, for h and h/4.
        let filtered = DriveParams {
            kvp: 1.0,
            kvi: 0.0,
            velocity_filter: 0.004,
            ..P
        };
        for (h, every) in [(1e-3, 1), (2.5e-4, 4)] {
            let mut drive = VelocityDrive::new(filtered, 0.0).unwrap();
            for k in 1..=200 {
                let effort = drive.step(0.0, 3.0, h);
                if k % every == 0 {
                    let t = k as f64 * h;
                    let want = -3.0 * -math::expm1(-t / 0.004f64);
                    assert!(
                        (effort - want).abs() < 1e-13,
                        "h {h}, t {t}: {effort} vs {want}"
                    );
                }
            }
        }
        // A constant demand through the current lag: f(t) = d·(1 − e^(−t/Tc)).
        let lagged = DriveParams {
            kvi: 0.0,
            current_lag: 0.002,
            ..P
        };
        let mut drive = VelocityDrive::new(lagged, 0.0).unwrap();
        for k in 1..=50 {
            let effort = drive.step(4.0, 0.0, 1e-3);
            let want = 120.0 * -math::expm1(-(k as f64) * 1e-3 / 0.002f64);
            assert!((effort - want).abs() < 1e-12, "{k}: {effort} vs {want}");
        }
    }

    #[test]
    fn a_saturated_drive_does_not_wind_up() {
        // A command far above what the limit gives (the axis cannot follow: v = 0) for
        // 2 s, then the command drops to the velocity: the effort leaves the limit at
        // once and is what the integral held when the demand saturated, not what 2 s of
        // integration would give (2000·100·2 = 4·10⁵).
        let mut drive = VelocityDrive::new(P, 0.0).unwrap();
        let h = 1e-3;
        let mut integral_at_saturation = None;
        for _ in 0..2000 {
            let effort = drive.step(100.0, 0.0, h);
            assert!(effort.abs() <= P.effort_max);
            if effort == P.effort_max && integral_at_saturation.is_none() {
                integral_at_saturation = Some(drive.integral());
            }
        }
        let held = integral_at_saturation.expect("the demand saturated");
        // Kvp·100 = 3000: the integral saturates the demand at 2000, after 10 steps.
        assert!((held - 2000.0).abs() <= P.kvi * 100.0 * h, "{held}");
        assert!(drive.integral() <= held + 1e-9);
        let after = drive.step(0.0, 0.0, h);
        assert_eq!(after, drive.integral());
        assert!(after < P.effort_max && after <= held + 1e-9, "{after}");
    }

    #[test]
    fn the_effort_never_passes_the_limit_by_rounding() {
        // From a negative effort into positive saturation: x + 1·(max − x) rounds above
        // max for some x (−3656.3575588759877 with max 5000, 4 % of them); the effort
        // must stay within the limit, with and without a current lag, and be the limit
        // exactly without one.
        for lag in [0.0, 1e-4] {
            let params = DriveParams {
                current_lag: lag,
                kvi: 0.0,
                ..P
            };
            let mut drive = VelocityDrive::new(params, 0.0).unwrap();
            for k in 0..2000 {
                let command = if k % 2 == 0 {
                    -(3656.3575588759877 + k as f64 * 0.37) / P.kvp
                } else {
                    1e6
                };
                let effort = drive.step(command, 0.0, 1e-3);
                assert!(
                    effort.abs() <= P.effort_max,
                    "lag {lag}, step {k}: {effort}"
                );
                if lag == 0.0 && k % 2 == 1 {
                    assert_eq!(effort, P.effort_max);
                }
            }
        }
    }

    #[test]
    fn both_directions_are_the_same_law() {
        let (mut up, mut down) = (
            VelocityDrive::new(P, 0.0).unwrap(),
            VelocityDrive::new(P, 0.0).unwrap(),
        );
        for k in 0..3000 {
            let u = 80.0 * math::sin(k as f64 * 0.003);
            let v = 0.5 * u;
            assert_eq!(up.step(u, v, 1e-3), -down.step(-u, -v, 1e-3));
        }
    }

    #[test]
    fn absurd_parameters_are_refused_with_their_name() {
        for (bad, name) in [
            (DriveParams { kvp: -1.0, ..P }, "Kvp"),
            (DriveParams { kvi: f64::NAN, ..P }, "Kvi"),
            (
                DriveParams {
                    effort_max: 0.0,
                    ..P
                },
                "effortMax",
            ),
            (
                DriveParams {
                    current_lag: f64::INFINITY,
                    ..P
                },
                "currentLag",
            ),
            (
                DriveParams {
                    velocity_filter: -1e-3,
                    ..P
                },
                "velocityFilter",
            ),
        ] {
            let message = VelocityDrive::new(bad, 0.0).unwrap_err();
            assert!(message.starts_with(name), "{message}");
        }
        assert!(VelocityDrive::new(P, f64::NAN).is_err());
    }
}
