//! One axis of a test plant (docs/design/two-axis.md §4.5): a servo drive whose PI loop closes on
//! motor speed, a motor with inertia and viscous friction, and a transmission — a ball
//! screw for a linear axis (position in mm) or a gearbox for a rotary one (rad).
//!
//! The drive takes a velocity command `v` (mm/s or rad/s). In axis coordinates (x = θ/k,
//! with k = 2π/lead or the gear ratio the motor angle per axis unit) the three states
//! are position x, velocity ẋ and the PI integral z of the velocity error, and the
//! dynamics are linear:
//!
//! ```text
//! ẍ = (CT·(Kvp·(v − ẋ) + Kvi·z) − B·ẋ) / J,    ż = v − ẋ
//! ```
//!
//! (k cancels out of the dynamics; it only scales the motor current, so a linear and a
//! rotary axis with the same drive follow the same law in their own units). The
//! command is held constant over a step (zero-order hold), so the exact discretisation
//! by the matrix exponential makes the trajectory independent of the step size.

use nalgebra::{Matrix3, Matrix4, Vector3};
use serde::{Deserialize, Serialize};

/// How motor revolutions become axis motion.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum Transmission {
    /// Ball screw: the axis position is in mm, `lead` mm per motor revolution.
    Linear {
        /// mm per motor revolution.
        lead: f64,
    },
    /// Gearbox: the axis position is in rad, `ratio` motor revolutions per axis revolution.
    Rotary {
        /// Motor revolutions per axis revolution.
        ratio: f64,
    },
}

impl Transmission {
    /// Motor angle per axis unit: rad/mm (2π/lead) or rad/rad (the gear ratio).
    pub fn motor_per_axis_unit(&self) -> f64 {
        match *self {
            Transmission::Linear { lead } => 2.0 * std::f64::consts::PI / lead,
            Transmission::Rotary { ratio } => ratio,
        }
    }

    fn validate(&self) -> Result<(), String> {
        let (name, value) = match *self {
            Transmission::Linear { lead } => ("lead", lead),
            Transmission::Rotary { ratio } => ("ratio", ratio),
        };
        if value.is_finite() && value > 0.0 {
            Ok(())
        } else {
            Err(format!("{name} must be finite and > 0 (got {value})"))
        }
    }
}

/// Physical and drive parameters of one axis, SI-like units as the paper gives them.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct AxisParams {
    /// Rotor plus reflected load inertia, kg·m².
    pub inertia: f64,
    /// Viscous friction, N·m·s/rad.
    pub friction: f64,
    /// Motor torque constant, N·m/A.
    pub torque_constant: f64,
    /// Ball screw (linear axis) or gearbox (rotary axis).
    pub transmission: Transmission,
    /// Drive velocity-loop proportional gain, A·s/rad.
    pub kvp: f64,
    /// Drive velocity-loop integral gain, A/rad.
    pub kvi: f64,
}

impl AxisParams {
    /// The paper's motor (CT = 0.57 N·m/A, B = 1.2 N·m·s, J = 0.015 kg·m², 10 mm lead)
    /// with the drive of docs/design/two-axis.md §4.5: the PI zero cancels the B/J pole, 50 Hz velocity bandwidth.
    pub const PAPER: AxisParams = AxisParams {
        inertia: 0.015,
        friction: 1.2,
        torque_constant: 0.57,
        transmission: Transmission::Linear { lead: 10.0 },
        kvp: 8.26,
        kvi: 661.0,
    };

    /// Tilt (A) axis of a small trunnion table: the same 0.57 N·m/A servo motor through a
    /// 90:1 worm gear; rotor 1.0·10⁻⁴ kg·m² plus a 0.8 kg·m² cradle with fixture and part
    /// reflected by 1/90² (0.99·10⁻⁴). As for the linear axes the drive puts its PI zero
    /// on the mechanical pole (B/J = 80 rad/s, so B = 0.016 N·m·s/rad at the motor) and
    /// closes the velocity loop at 314 rad/s (50 Hz): Kvp = 314·J/CT, Kvi = 80·Kvp.
    pub const TRUNNION_A: AxisParams = AxisParams::trunnion_drive(1.99e-4);

    /// Rotary (C) axis of the same table: a Ø170 mm, 15 kg platter with part
    /// (½·m·r² = 0.054 kg·m², reflected 0.67·10⁻⁵) on the same motor and 90:1 gear; drive
    /// tuned by the same rule.
    pub const TRUNNION_C: AxisParams = AxisParams::trunnion_drive(1.067e-4);

    /// A trunnion-table axis of motor-side inertia `inertia`: the 0.57 N·m/A motor, a
    /// 90:1 gear, the PI zero on the mechanical pole (80 rad/s) and a 314 rad/s loop.
    const fn trunnion_drive(inertia: f64) -> AxisParams {
        AxisParams {
            inertia,
            friction: 80.0 * inertia,
            torque_constant: 0.57,
            transmission: Transmission::Rotary { ratio: 90.0 },
            kvp: 314.0 * inertia / 0.57,
            kvi: 80.0 * 314.0 * inertia / 0.57,
        }
    }

    /// Checks that the parameters describe a physical, stable drive; the error names
    /// the offending field.
    pub fn validate(&self) -> Result<(), String> {
        let positive = [
            ("inertia", self.inertia),
            ("torque_constant", self.torque_constant),
        ];
        for (name, value) in positive {
            if !(value.is_finite() && value > 0.0) {
                return Err(format!("{name} must be finite and > 0 (got {value})"));
            }
        }
        let non_negative = [
            ("friction", self.friction),
            ("kvp", self.kvp),
            ("kvi", self.kvi),
        ];
        for (name, value) in non_negative {
            if !(value.is_finite() && value >= 0.0) {
                return Err(format!("{name} must be finite and >= 0 (got {value})"));
            }
        }
        self.transmission.validate()
    }

    /// Continuous-time system matrices (A, b) of the state (x, ẋ, z) with input v.
    fn continuous(&self) -> (Matrix3<f64>, Vector3<f64>) {
        let ct_j = self.torque_constant / self.inertia;
        let a = Matrix3::new(
            0.0,
            1.0,
            0.0,
            0.0,
            -(self.friction / self.inertia + ct_j * self.kvp),
            ct_j * self.kvi,
            0.0,
            -1.0,
            0.0,
        );
        let b = Vector3::new(0.0, ct_j * self.kvp, 1.0);
        (a, b)
    }
}

/// Exact zero-order-hold transition for one step length: s ← Φ·s + Γ·v.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
struct Discretisation {
    step: f64,
    phi: Matrix3<f64>,
    gamma: Vector3<f64>,
}

impl Discretisation {
    fn new(params: &AxisParams, step: f64) -> Self {
        let (a, b) = params.continuous();
        // exp([[A, b], [0, 0]]·h) holds Φ = e^{Ah} and Γ = ∫e^{As}ds·b side by side.
        let mut augmented = Matrix4::zeros();
        augmented.fixed_view_mut::<3, 3>(0, 0).copy_from(&a);
        augmented.fixed_view_mut::<3, 1>(0, 3).copy_from(&b);
        let scaled = augmented * step;
        // nalgebra's exp squares s times, s from the norms of the matrix's powers up to
        // the 10th: past ~1e30 an entry makes them infinite and s = u64::MAX, a loop for
        // ever (found by fuzz/deserialize_state). Such a step (h·A beyond 1e25) has no
        // useful answer: NaN, which the FMI layer refuses as an overflow.
        let exp = if scaled.iter().all(|x| x.abs() <= 1e25) {
            scaled.exp()
        } else {
            Matrix4::from_element(f64::NAN)
        };
        Discretisation {
            step,
            phi: exp.fixed_view::<3, 3>(0, 0).into_owned(),
            gamma: exp.fixed_view::<3, 1>(0, 3).into_owned(),
        }
    }
}

/// State and parameters of one axis.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ServoAxis {
    params: AxisParams,
    /// (x mm, ẋ mm/s, z mm).
    state: Vector3<f64>,
    /// The last step length's transition, reused while the step length stays the same.
    cached: Option<Discretisation>,
}

impl ServoAxis {
    /// An axis at rest at `position` (mm or rad).
    pub fn new(params: AxisParams, position: f64) -> Self {
        ServoAxis {
            params,
            state: Vector3::new(position, 0.0, 0.0),
            cached: None,
        }
    }

    /// The parameters the axis was built from.
    pub fn params(&self) -> &AxisParams {
        &self.params
    }

    /// Position, mm or rad.
    pub fn position(&self) -> f64 {
        self.state[0]
    }

    /// Velocity, mm/s or rad/s.
    pub fn velocity(&self) -> f64 {
        self.state[1]
    }

    /// Motor current demanded by the drive, A.
    pub fn current(&self, command: f64) -> f64 {
        let p = &self.params;
        let scale = p.transmission.motor_per_axis_unit();
        scale * (p.kvp * (command - self.state[1]) + p.kvi * self.state[2])
    }

    /// Advances by `step` seconds with the velocity command `command` (mm/s or rad/s) held.
    /// No heap allocation; the matrix exponential is only recomputed when the step
    /// length changes.
    pub fn step(&mut self, command: f64, step: f64) {
        let d = match self.cached {
            Some(d) if d.step == step => d,
            _ => {
                let d = Discretisation::new(&self.params, step);
                self.cached = Some(d);
                d
            }
        };
        self.state = d.phi * self.state + d.gamma * command;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A step so long that the powers of h·A overflow (1e40 s, 1e57 s) used to make the
    /// matrix exponential square for ever; it is NaN now, which the FMI layer refuses.
    #[test]
    fn a_step_too_long_for_f64_is_nan_not_a_hang() {
        for step in [1e40, 1e57] {
            let mut axis = ServoAxis::new(AxisParams::PAPER, 0.0);
            axis.step(1.0, step);
            assert!(axis.position().is_nan(), "{step}");
        }
        let mut axis = ServoAxis::new(AxisParams::PAPER, 0.0);
        axis.step(1.0, 1e-3);
        assert!(axis.position().is_finite());
    }
}
