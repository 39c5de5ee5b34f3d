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

use nalgebra::{Matrix3, Matrix4, Matrix5, Vector3};
use serde::{Deserialize, Serialize};

use super::axis_effects::AxisEffects;

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
    /// Friction beyond the viscous, backlash and the current limit; none by default.
    #[serde(default)]
    pub effects: AxisEffects,
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
        effects: AxisEffects::NONE,
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
            effects: AxisEffects::NONE,
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
        self.transmission.validate()?;
        self.effects.validate()
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

/// exp(M·h) of a system matrix M scaled by h, or NaN where h·M is beyond 1e25.
///
/// nalgebra's exp squares s times, s from the norms of the matrix's powers up to the
/// 10th: past ~1e30 an entry makes them infinite and s = u64::MAX, a loop for ever (found
/// by fuzz/deserialize_state). Such a step has no useful answer: NaN, which the FMI layer
/// refuses as an overflow.
fn guarded_exp<const N: usize>(scaled: nalgebra::SMatrix<f64, N, N>) -> nalgebra::SMatrix<f64, N, N>
where
    nalgebra::Const<N>: nalgebra::DimMin<nalgebra::Const<N>, Output = nalgebra::Const<N>>,
{
    if scaled.iter().all(|x| x.abs() <= 1e25) {
        scaled.exp()
    } else {
        nalgebra::SMatrix::from_element(f64::NAN)
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
        let exp = guarded_exp(augmented * step);
        Discretisation {
            step,
            phi: exp.fixed_view::<3, 3>(0, 0).into_owned(),
            gamma: exp.fixed_view::<3, 1>(0, 3).into_owned(),
        }
    }
}

/// The longest substep of an axis with [`AxisEffects`], s. Friction's direction, sticking,
/// contact in the play and the current limit are decided at the start of each substep,
/// so events are placed to within one; 1 ms, 0.5 ms, 0.25 ms, 0.1 ms and 2 ms are whole
/// numbers of it, so those communication steps share the substep grid.
pub const MAX_SUBSTEP: f64 = 1e-5;

/// The most substeps in one communication step (a step beyond 10 s gets longer
/// substeps, and beyond ~1e25 s NaN).
const MAX_SUBSTEPS: u32 = 1_000_000;

/// One substep's exact transition with the command v and an external motor torque τ
/// held: s ← Φ·s + Γv·v + Γτ·τ.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
struct HeldInputs {
    phi: Matrix3<f64>,
    gamma_command: Vector3<f64>,
    gamma_torque: Vector3<f64>,
}

impl HeldInputs {
    fn new(a: Matrix3<f64>, b_command: Vector3<f64>, b_torque: Vector3<f64>, h: f64) -> Self {
        let mut augmented = Matrix5::zeros();
        augmented.fixed_view_mut::<3, 3>(0, 0).copy_from(&a);
        augmented.fixed_view_mut::<3, 1>(0, 3).copy_from(&b_command);
        augmented.fixed_view_mut::<3, 1>(0, 4).copy_from(&b_torque);
        let exp = guarded_exp(augmented * h);
        HeldInputs {
            phi: exp.fixed_view::<3, 3>(0, 0).into_owned(),
            gamma_command: exp.fixed_view::<3, 1>(0, 3).into_owned(),
            gamma_torque: exp.fixed_view::<3, 1>(0, 4).into_owned(),
        }
    }

    fn apply(&self, state: &Vector3<f64>, command: f64, torque: f64) -> Vector3<f64> {
        self.phi * state + self.gamma_command * command + self.gamma_torque * torque
    }
}

/// The substeps of one communication step of an axis with effects: the transitions with
/// the drive's PI loop closed (`linear`) and with its current at the limit (`saturated`,
/// the current then an external torque).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
struct SubstepDiscretisation {
    /// The communication step these substeps make up, s.
    step: f64,
    substeps: u32,
    linear: HeldInputs,
    saturated: HeldInputs,
}

impl SubstepDiscretisation {
    fn new(params: &AxisParams, step: f64) -> Self {
        let substeps = ((step / MAX_SUBSTEP) * (1.0 - 1e-12))
            .ceil()
            .clamp(1.0, MAX_SUBSTEPS as f64);
        let substeps = if substeps.is_nan() {
            1
        } else {
            substeps as u32
        };
        let h = step / f64::from(substeps);
        let (a, b) = params.continuous();
        // A torque τ at the motor accelerates the axis by τ/(J·k) in axis units.
        let b_torque = Vector3::new(
            0.0,
            1.0 / (params.inertia * params.transmission.motor_per_axis_unit()),
            0.0,
        );
        // At the limit the current no longer depends on the state: only the viscous
        // friction acts on ẋ, and the command reaches the integral alone.
        let a_saturated = Matrix3::new(
            0.0,
            1.0,
            0.0, //
            0.0,
            -params.friction / params.inertia,
            0.0, //
            0.0,
            -1.0,
            0.0,
        );
        SubstepDiscretisation {
            step,
            substeps,
            linear: HeldInputs::new(a, b, b_torque, h),
            saturated: HeldInputs::new(a_saturated, Vector3::new(0.0, 0.0, 1.0), b_torque, h),
        }
    }

    fn substep(&self) -> f64 {
        self.step / f64::from(self.substeps)
    }
}

/// Where the motor is in the transmission's play: pushing the table forward, backward,
/// or in between (the table held by its friction).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Contact {
    /// In the play, the table left where the motor last pushed it.
    Gap,
    /// Pushing the table toward +.
    Forward,
    /// Pushing the table toward −.
    Backward,
}

/// The table behind the transmission's play (backlash only).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
struct Table {
    /// mm or rad.
    position: f64,
    /// mm/s or rad/s: the motor's while it pushes, 0 in the play.
    velocity: f64,
    contact: Contact,
}

/// State and parameters of one axis.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ServoAxis {
    params: AxisParams,
    /// The motor side in axis units: (x mm, ẋ mm/s, z mm).
    state: Vector3<f64>,
    /// The table, which follows the motor through the play (with backlash; otherwise
    /// the motor's position is the table's).
    table: Table,
    /// The last step length's transition, reused while the step length stays the same.
    cached: Option<Discretisation>,
    /// The same with effects: the last step length's substeps.
    cached_substeps: Option<SubstepDiscretisation>,
}

impl ServoAxis {
    /// An axis at rest at `position` (mm or rad); with backlash the motor is in the
    /// middle of the play.
    pub fn new(params: AxisParams, position: f64) -> Self {
        ServoAxis {
            params,
            state: Vector3::new(position, 0.0, 0.0),
            table: Table {
                position,
                velocity: 0.0,
                contact: Contact::Gap,
            },
            cached: None,
            cached_substeps: None,
        }
    }

    /// The parameters the axis was built from.
    pub fn params(&self) -> &AxisParams {
        &self.params
    }

    /// Position of the table, mm or rad (as a linear scale measures it): the motor's
    /// but for backlash.
    pub fn position(&self) -> f64 {
        if self.params.effects.backlash > 0.0 {
            self.table.position
        } else {
            self.state[0]
        }
    }

    /// Velocity of the table, mm/s or rad/s: the motor's but for backlash, where the
    /// table stands still in the play.
    pub fn velocity(&self) -> f64 {
        if self.params.effects.backlash > 0.0 {
            self.table.velocity
        } else {
            self.state[1]
        }
    }

    /// The motor's position and velocity in axis units (what the drive's encoder
    /// measures and its velocity loop feeds back).
    pub fn motor(&self) -> (f64, f64) {
        (self.state[0], self.state[1])
    }

    /// Where the motor is in the play.
    pub fn contact(&self) -> Contact {
        self.table.contact
    }

    /// Motor current demanded by the drive, A (within the current limit).
    pub fn current(&self, command: f64) -> f64 {
        let limit = self.params.effects.current_limit();
        self.demand(command).clamp(-limit, limit)
    }

    /// The drive's PI law before its current limit, A.
    fn demand(&self, command: f64) -> f64 {
        let p = &self.params;
        p.transmission.motor_per_axis_unit()
            * (p.kvp * (command - self.state[1]) + p.kvi * self.state[2])
    }

    /// Advances by `step` seconds with the velocity command `command` (mm/s or rad/s) held.
    /// No heap allocation; the transitions are only recomputed when the step length
    /// changes. A linear axis takes one exact step; one with effects [`MAX_SUBSTEP`]s.
    pub fn step(&mut self, command: f64, step: f64) {
        if self.params.effects.is_none() {
            let d = match self.cached {
                Some(d) if d.step == step => d,
                _ => {
                    let d = Discretisation::new(&self.params, step);
                    self.cached = Some(d);
                    d
                }
            };
            self.state = d.phi * self.state + d.gamma * command;
            return;
        }
        let d = match self.cached_substeps {
            Some(d) if d.step == step => d,
            _ => {
                let d = SubstepDiscretisation::new(&self.params, step);
                self.cached_substeps = Some(d);
                d
            }
        };
        for _ in 0..d.substeps {
            self.substep(command, &d);
        }
    }

    /// One substep: the current, its limit and the friction decided at its start and
    /// held over it (docs/design/two-axis.md §4.5b).
    fn substep(&mut self, command: f64, d: &SubstepDiscretisation) {
        let p = self.params;
        let effects = p.effects;
        let [x, velocity, integral] = [self.state[0], self.state[1], self.state[2]];
        let demand = self.demand(command);
        let current = self.current(command);
        let saturated = current != demand;
        // Conditional integration: the integral holds while the current is at the limit
        // and the error drives it further in.
        let winding_up = saturated && (command - velocity) * demand > 0.0;
        // Friction reaches the motor only through a closed play.
        let no_play = effects.backlash == 0.0;
        let engaged_forward = no_play || self.table.contact == Contact::Forward;
        let engaged_backward = no_play || self.table.contact == Contact::Backward;
        let drive_torque = p.torque_constant * current;
        let friction = if velocity > 0.0 {
            if engaged_forward {
                effects.sliding_friction(velocity)
            } else {
                0.0
            }
        } else if velocity < 0.0 {
            if engaged_backward {
                -effects.sliding_friction(-velocity)
            } else {
                0.0
            }
        } else {
            let engaged = if drive_torque >= 0.0 {
                engaged_forward
            } else {
                engaged_backward
            };
            let breakaway = effects.breakaway();
            if engaged && breakaway > 0.0 && drive_torque.abs() <= breakaway {
                // Stuck: nothing moves; the integral sees the whole command as error.
                if !winding_up {
                    self.state[2] = integral + d.substep() * command;
                }
                self.table.velocity = 0.0;
                return;
            }
            if engaged {
                breakaway.copysign(drive_torque)
            } else {
                0.0
            }
        };
        let mut next = if saturated {
            d.saturated
                .apply(&self.state, command, drive_torque - friction)
        } else {
            d.linear.apply(&self.state, command, -friction)
        };
        if winding_up {
            next[2] = integral;
        }
        // Friction stops a motion; it never reverses one, nor carries the motor back past
        // where the substep started (which would open the play under a stuck motor and
        // let it go free).
        if friction * next[1] < 0.0 {
            next[1] = 0.0;
            next[0] = if friction > 0.0 {
                next[0].max(x)
            } else {
                next[0].min(x)
            };
        }
        self.state = next;
        if !no_play {
            self.follow_through_play(x);
        }
    }

    /// Moves the table where the motor, now at `state[0]` (from `before`), pushes it.
    fn follow_through_play(&mut self, before: f64) {
        let half = 0.5 * self.params.effects.backlash;
        let (motor, velocity) = (self.state[0], self.state[1]);
        let table = &mut self.table;
        if motor - half > table.position {
            table.position = motor - half;
            table.contact = Contact::Forward;
            table.velocity = velocity;
        } else if motor + half < table.position {
            table.position = motor + half;
            table.contact = Contact::Backward;
            table.velocity = velocity;
        } else {
            if motor != before {
                table.contact = Contact::Gap;
            }
            table.velocity = 0.0;
        }
    }

    /// Checks that the cached transitions are the ones the parameters give for their step
    /// lengths (recomputed the same way, so equal to the bit), the substep count included:
    /// a restored axis must follow its parameters' dynamics, and a count from elsewhere
    /// could make a step run for ever.
    pub fn check_caches(&self) -> Result<(), String> {
        let step = match (&self.cached, &self.cached_substeps) {
            (Some(d), _) => d.step,
            (None, Some(d)) => d.step,
            (None, None) => return Ok(()),
        };
        if !(step.is_finite() && step > 0.0) {
            return Err(format!(
                "cached step length {step} s must be finite and > 0"
            ));
        }
        let matches = self
            .cached
            .is_none_or(|d| d == Discretisation::new(&self.params, d.step))
            && self
                .cached_substeps
                .is_none_or(|d| d == SubstepDiscretisation::new(&self.params, d.step));
        if matches {
            Ok(())
        } else {
            Err(format!(
                "the cached transition for steps of {step} s does not match the axis parameters"
            ))
        }
    }

    /// Checks what a restored axis's parameters cannot: the table within the play of
    /// the motor (to a rounding of its position).
    pub fn check_play(&self) -> Result<(), String> {
        let half = 0.5 * self.params.effects.backlash;
        let offset = (self.state[0] - self.table.position).abs();
        let slack = 1e-9 * (1.0 + self.state[0].abs());
        if half > 0.0 && offset > half + slack {
            return Err(format!(
                "the table is {offset} from the motor, beyond half the play ({half})"
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math;

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

    const K: f64 = 2.0 * std::f64::consts::PI / 10.0; // motor rad per mm, 10 mm lead

    fn with(effects: AxisEffects) -> AxisParams {
        AxisParams {
            effects,
            ..AxisParams::PAPER
        }
    }

    /// Velocities of an axis from rest under a command step, every 1 ms for `samples`.
    fn step_response(params: AxisParams, command: f64, samples: usize) -> Vec<f64> {
        let mut axis = ServoAxis::new(params, 0.0);
        (0..samples)
            .map(|_| {
                axis.step(command, 1e-3);
                axis.velocity()
            })
            .collect()
    }

    #[test]
    fn at_the_current_limit_the_motor_accelerates_as_the_closed_form_says() {
        // 100 mm/s asks 520 A at once and 132 A to hold: at 20 A the drive stays at the
        // limit, so J·k·ẍ = CT·Imax − B·k·ẋ: ẋ = w·(1 − e^(−t·B/J)) with w = CT·Imax/(B·k),
        // and the integral, which would push further in, holds at 0.
        let p = with(AxisEffects {
            current_max: 20.0,
            ..AxisEffects::NONE
        });
        let (b_j, w) = (
            p.friction / p.inertia,
            p.torque_constant * 20.0 / (p.friction * K),
        );
        let mut axis = ServoAxis::new(p, 0.0);
        for k in 1..=200 {
            axis.step(100.0, 1e-3);
            let t = k as f64 * 1e-3;
            let v = w * -math::expm1(-b_j * t);
            let x = w * (t + math::expm1(-b_j * t) / b_j);
            assert!((axis.velocity() - v).abs() < 1e-9 * w, "t={t}");
            assert!((axis.position() - x).abs() < 1e-9 * w, "t={t}");
            assert_eq!(axis.state[2], 0.0);
            assert_eq!(axis.current(100.0), 20.0);
        }
    }

    #[test]
    fn anti_windup_keeps_a_saturated_step_from_overshooting() {
        // The loop is first order when linear (no overshoot). Steps that saturate the
        // 60 A limit for longer and longer (10 mm/s does not, 20 and 40 do; 40 needs
        // 53 A to hold) overshoot by no more than a small step does: the integral did
        // not wind up while the current was at the limit.
        let p = with(AxisEffects {
            current_max: 60.0,
            ..AxisEffects::NONE
        });
        let overshoot = |command: f64| {
            let v = step_response(p, command, 500);
            let peak = v.iter().cloned().fold(f64::MIN, f64::max);
            assert!(
                (v[499] - command).abs() < 1e-6 * command,
                "settles at {command}"
            );
            (peak - command) / command
        };
        let small = overshoot(10.0);
        let overshoots: Vec<f64> = [20.0, 40.0].map(overshoot).into();
        for o in &overshoots {
            assert!(*o <= small + 0.002, "{overshoots:?} against {small}");
        }
        // The small step is the linear loop's (nearly first order: the paper's rounded
        // gains leave the PI zero a little off the pole).
        let linear = step_response(AxisParams::PAPER, 10.0, 500);
        let linear_peak = linear.iter().cloned().fold(f64::MIN, f64::max);
        assert!((linear_peak / 10.0 - 1.0 - small).abs() < 1e-12);
        println!("overshoot: 10 mm/s {small}, 20 and 40 mm/s {overshoots:?}");
    }

    #[test]
    fn coulomb_friction_is_held_by_the_integral_and_stiction_breaks_away_on_time() {
        // Sliding at a constant 20 mm/s the drive's current carries the viscous and the
        // Coulomb torque: i = (B·k·v + Tc)/CT.
        let friction = AxisEffects {
            coulomb: 0.5,
            stiction: 1.0,
            stribeck_velocity: 2.0,
            ..AxisEffects::NONE
        };
        let p = with(friction);
        let mut axis = ServoAxis::new(p, 0.0);
        for _ in 0..1000 {
            axis.step(20.0, 1e-3);
        }
        let want = (p.friction * K * 20.0 + 0.5) / p.torque_constant;
        assert!((axis.current(20.0) - want).abs() < 1e-6 * want);
        assert!((axis.velocity() - 20.0).abs() < 1e-6);
        // From rest with 0.1 mm/s the drive's torque CT·k·(Kvp·v + Kvi·v·t) grows with the
        // integral and passes the 1 N·m of stiction at t_b = (1/(CT·k·v) − Kvp)/Kvi; the
        // axis does not move a nanometre before.
        let v = 0.1;
        let t_b = (1.0 / (p.torque_constant * K * v) - p.kvp) / p.kvi;
        let mut axis = ServoAxis::new(p, 0.0);
        let mut t = 0.0;
        while t < t_b - MAX_SUBSTEP {
            assert_eq!(axis.position(), 0.0, "t={t}");
            axis.step(v, MAX_SUBSTEP);
            t += MAX_SUBSTEP;
        }
        for _ in 0..3 {
            axis.step(v, MAX_SUBSTEP);
        }
        assert!(axis.velocity() > 0.0, "moving after {t_b} s");
    }

    #[test]
    fn the_table_follows_the_motor_through_the_play() {
        // No friction: the motor is the linear axis; the table starts in the middle of the
        // 0.1 mm play, moves once the motor has taken up half of it, stays while the motor
        // crosses the play after a reversal, and is then b/2 ahead of it.
        let b = 0.1;
        let p = with(AxisEffects {
            backlash: b,
            ..AxisEffects::NONE
        });
        let mut axis = ServoAxis::new(p, 0.0);
        let mut motor = ServoAxis::new(AxisParams::PAPER, 0.0);
        let mut table_path = Vec::new();
        for k in 0..600 {
            let command = if k < 300 { 10.0 } else { -10.0 };
            axis.step(command, 1e-3);
            motor.step(command, 1e-3);
            assert!((axis.motor().0 - motor.position()).abs() < 1e-9, "k={k}");
            table_path.push((axis.motor().0, axis.position(), axis.contact()));
        }
        // The play operator from its definition, on the motor's samples.
        let mut table = 0.0f64;
        for &(m, got, _) in &table_path {
            table = table.clamp(m - b / 2.0, m + b / 2.0);
            // Between samples the motor turns back at its extreme, which the samples miss
            // by at most a·Δt² / 8 (a ≤ 20/0.0032 mm/s²).
            assert!((got - table).abs() < 1e-3, "{got} vs {table}");
        }
        assert_eq!(table_path[250].2, Contact::Forward);
        assert_eq!(table_path[599].2, Contact::Backward);
        assert!((table_path[599].1 - (table_path[599].0 + b / 2.0)).abs() < 1e-12);
        assert!((axis.velocity() - motor.velocity()).abs() < 1e-9);
    }

    #[test]
    fn with_effects_the_trajectory_hardly_depends_on_the_step() {
        // Steps that are whole numbers of the substep share its grid: the same run to
        // rounding. A step that is not (1/3 ms: 34 substeps of 9.8 µs) places events
        // within one substep instead: first order in the substep.
        let p = with(AxisEffects {
            coulomb: 0.3,
            stiction: 0.5,
            stribeck_velocity: 1.0,
            backlash: 0.01,
            current_max: 80.0,
        });
        let command = |t: f64| 30.0 * math::sin(2.0 * std::f64::consts::PI * t);
        let run = |step: f64, every: usize| {
            let mut axis = ServoAxis::new(p, 0.0);
            let mut samples = Vec::new();
            for k in 0..(3000 * every) {
                // The command changes only every 1 ms: the same input for every step size.
                let t = (k / every) as f64 * 1e-3;
                axis.step(command(t), step);
                if (k + 1) % every == 0 {
                    samples.push(axis.position());
                }
            }
            samples
        };
        let max_difference = |a: &[f64], b: &[f64]| {
            a.iter()
                .zip(b)
                .map(|(x, y)| (x - y).abs())
                .fold(0.0, f64::max)
        };
        let base = run(1e-3, 1);
        let quarter = run(2.5e-4, 4);
        assert!(max_difference(&base, &quarter) < 1e-9);
        let third = run(1e-3 / 3.0, 3);
        let off_grid = max_difference(&base, &third);
        assert!(off_grid < 2e-4, "{off_grid}");
        assert!(
            base.iter().cloned().fold(0.0, f64::max) > 9.0,
            "the axis moves"
        );
    }

    #[test]
    fn effects_are_validated_by_name() {
        let mut effects = AxisEffects {
            coulomb: 0.5,
            stiction: 0.4,
            ..AxisEffects::NONE
        };
        assert_eq!(
            with(effects).validate().unwrap_err(),
            "stiction (0.4) must be 0 or at least coulomb (0.5)"
        );
        effects.stiction = 0.0;
        assert!(with(effects).validate().is_ok());
        effects.backlash = -1e-3;
        assert!(with(effects)
            .validate()
            .unwrap_err()
            .starts_with("backlash"));
        effects.backlash = 0.0;
        effects.current_max = f64::NAN;
        assert!(with(effects)
            .validate()
            .unwrap_err()
            .starts_with("currentMax"));
    }

    #[test]
    fn a_restored_substep_cache_must_be_the_parameters_own() {
        // The count of substeps and the matrices, edited in a saved axis, are refused:
        // 4e9 substeps would make one step run for minutes.
        let p = with(AxisEffects {
            coulomb: 0.3,
            ..AxisEffects::NONE
        });
        let mut axis = ServoAxis::new(p, 0.0);
        axis.step(5.0, 1e-3);
        assert_eq!(axis.check_caches(), Ok(()));
        let saved = serde_json::to_value(&axis).unwrap();
        assert_eq!(saved["cached_substeps"]["substeps"], 100);
        for (field, value) in [
            ("substeps", serde_json::json!(4_000_000_000u32)),
            ("step", serde_json::json!(2e-3)),
        ] {
            let mut edited = saved.clone();
            edited["cached_substeps"][field] = value;
            let restored: ServoAxis = serde_json::from_value(edited).unwrap();
            assert!(restored
                .check_caches()
                .unwrap_err()
                .contains("does not match"));
        }
        let mut edited = saved.clone();
        edited["cached_substeps"]["linear"]["phi"][0] = serde_json::json!(0.5);
        let restored: ServoAxis = serde_json::from_value(edited).unwrap();
        assert!(restored.check_caches().is_err());
    }

    #[test]
    fn a_motor_friction_stops_in_contact_stays_in_contact() {
        // Pushing the table at 5 mm/s, then told to stop: friction stops the motor while it
        // pushes, and the drive's torque that remains is below the breakaway torque, so
        // nothing moves again: the table does not creep and the contact stays closed (a
        // stop that carried the motor back into the play used to let it go free).
        let p = with(AxisEffects {
            coulomb: 0.5,
            stiction: 1.0,
            backlash: 0.02,
            ..AxisEffects::NONE
        });
        let mut axis = ServoAxis::new(p, 0.0);
        for _ in 0..200 {
            axis.step(5.0, 1e-3);
        }
        assert_eq!(axis.contact(), Contact::Forward);
        let mut stopped = None;
        for k in 0..50_000 {
            axis.step(0.0, MAX_SUBSTEP);
            if axis.motor().1 == 0.0 && stopped.is_none() {
                stopped = Some((k, axis.position()));
            }
            if let Some((_, table)) = stopped {
                assert_eq!(axis.position(), table, "substep {k}: the table crept");
                assert_eq!(axis.contact(), Contact::Forward, "substep {k}");
            }
        }
        assert!(
            stopped.is_some(),
            "the motor never stopped: {:?} {:?} {}",
            axis.motor(),
            axis.contact(),
            axis.current(0.0)
        );
        // The torque left is below breakaway (the test's premise).
        assert!(p.torque_constant * axis.current(0.0).abs() <= 1.0);
    }
}
