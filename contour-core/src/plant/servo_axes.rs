//! A machine's axes as one plant: `D` independent servo axes driven by velocity commands,
//! in axis order. The two-axis test table of the paper is [`XyTable`].

use serde::{Deserialize, Serialize};
use serde_big_array::BigArray;

use super::servo_axis::{AxisParams, ServoAxis};
use crate::geometry::Vector;

/// Parameters of every axis, in axis order.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ServoAxesParams<const D: usize> {
    /// One per axis.
    #[serde(with = "BigArray")]
    pub axes: [AxisParams; D],
}

/// The two-axis table's parameters (X, Y).
pub type XyTableParams = ServoAxesParams<2>;

impl<const D: usize> ServoAxesParams<D> {
    /// Every axis alike.
    pub const fn uniform(axis: AxisParams) -> Self {
        ServoAxesParams { axes: [axis; D] }
    }

    /// Checks every axis; the error names the axis (0-based) and the field.
    pub fn validate(&self) -> Result<(), String> {
        for (i, axis) in self.axes.iter().enumerate() {
            axis.validate().map_err(|e| format!("axis {i}: {e}"))?;
        }
        Ok(())
    }
}

impl ServoAxesParams<2> {
    /// The paper's plant: identical axes.
    pub const PAPER: XyTableParams = ServoAxesParams::uniform(AxisParams::PAPER);

    /// Mismatched axes (Y carries 1.5× the inertia, its drive left as tuned for X): the
    /// classic source of contour error that cross coupling is meant to remove.
    pub fn mismatched() -> Self {
        let mut params = Self::PAPER;
        params.axes[1].inertia *= 1.5;
        params
    }
}

impl ServoAxesParams<5> {
    /// A small five-axis machine: X, Y, Z as the paper's axis, A and C on a trunnion
    /// table ([`AxisParams::TRUNNION_A`], [`AxisParams::TRUNNION_C`]).
    pub const TRUNNION: ServoAxesParams<5> = ServoAxesParams {
        axes: [
            AxisParams::PAPER,
            AxisParams::PAPER,
            AxisParams::PAPER,
            AxisParams::TRUNNION_A,
            AxisParams::TRUNNION_C,
        ],
    };
}

/// `D` servo axes driven by velocity commands.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ServoAxes<const D: usize> {
    /// One per axis.
    #[serde(with = "BigArray")]
    pub axes: [ServoAxis; D],
}

/// The two-axis test table (X, Y).
pub type XyTable = ServoAxes<2>;

impl<const D: usize> ServoAxes<D> {
    /// Every axis at rest at its coordinate of `position` (mm or rad).
    pub fn new(params: ServoAxesParams<D>, position: Vector<D>) -> Self {
        ServoAxes {
            axes: std::array::from_fn(|i| ServoAxis::new(params.axes[i], position[i])),
        }
    }

    /// Advances by `step` seconds with the velocity commands held.
    pub fn step(&mut self, command: Vector<D>, step: f64) {
        for (axis, &v) in self.axes.iter_mut().zip(command.iter()) {
            axis.step(v, step);
        }
    }

    /// Positions.
    pub fn position(&self) -> Vector<D> {
        Vector::from_fn(|i, _| self.axes[i].position())
    }

    /// Velocities.
    pub fn velocity(&self) -> Vector<D> {
        Vector::from_fn(|i, _| self.axes[i].velocity())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math;
    use crate::plant::Transmission;

    #[test]
    fn each_axis_is_its_own_servo_and_a_rotary_one_follows_the_same_law() {
        // Axis by axis, the group equals a lone ServoAxis driven with that axis's command
        // (so no command goes to the wrong axis); a 50:1 gearbox instead of the 10 mm
        // screw gives the same trajectory in rad as in mm and scales the motor current
        // by the motor angle per axis unit, 50 / (2π/10).
        let linear = AxisParams::PAPER;
        let rotary = AxisParams {
            transmission: Transmission::Rotary { ratio: 50.0 },
            ..AxisParams::PAPER
        };
        let start = Vector::<3>::new(1.0, 1.0, -2.0);
        let params = [linear, rotary, linear];
        let mut axes = ServoAxes::new(ServoAxesParams { axes: params }, start);
        let mut alone: [ServoAxis; 3] =
            std::array::from_fn(|i| ServoAxis::new(params[i], start[i]));
        let mut linear_twin = ServoAxis::new(linear, start[1]);
        let command = |k: usize| {
            let v = math::sin(k as f64 * 0.01);
            Vector::<3>::new(v, 3.0 * v, -2.0 * v)
        };
        for k in 0..200 {
            let u = command(k);
            axes.step(u, 1e-3);
            for (i, axis) in alone.iter_mut().enumerate() {
                axis.step(u[i], 1e-3);
            }
            linear_twin.step(u[1], 1e-3);
        }
        for (i, axis) in alone.iter().enumerate() {
            assert_eq!(axes.position()[i], axis.position());
            assert_eq!(axes.velocity()[i], axis.velocity());
        }
        assert!((axes.position() - start).amax() > 0.01, "the axes moved");
        assert_eq!(axes.position()[1], linear_twin.position());
        let (i_lin, i_rot) = (linear_twin.current(1.0), axes.axes[1].current(1.0));
        assert!((i_rot / i_lin - 50.0 * 10.0 / (2.0 * std::f64::consts::PI)).abs() < 1e-9);
    }

    #[test]
    fn the_trunnion_axes_have_a_first_order_50_hz_velocity_loop() {
        // With the PI zero on the mechanical pole the velocity loop is exactly
        // 1/(1 + s/314): from rest a unit velocity step gives v(t) = 1 − e^(−314·t) and
        // x(t) = t − (1 − e^(−314·t))/314, in rad for A and C. (The paper's linear axis,
        // with its rounded gains, is the same law to 0.1 %.)
        let params = ServoAxesParams::<5>::TRUNNION;
        params.validate().unwrap();
        let mut axes = ServoAxes::new(params, Vector::<5>::zeros());
        for k in 1..=50 {
            axes.step(Vector::<5>::repeat(1.0), 2e-4);
            let t = k as f64 * 2e-4;
            let v = 1.0 - math::exp(-314.0 * t);
            let x = t - v / 314.0;
            for i in 0..5 {
                let tolerance = if i < 3 { 1e-3 } else { 1e-9 };
                assert!((axes.velocity()[i] - v).abs() < tolerance, "axis {i} t={t}");
                assert!(
                    (axes.position()[i] - x).abs() < tolerance * t,
                    "axis {i} t={t}"
                );
            }
        }
    }

    #[test]
    fn validation_names_axis_and_field() {
        let mut params = ServoAxesParams::<3>::uniform(AxisParams::PAPER);
        params.axes[2].transmission = Transmission::Rotary { ratio: 0.0 };
        assert_eq!(
            params.validate().unwrap_err(),
            "axis 2: ratio must be finite and > 0 (got 0)"
        );
        params.axes[2].transmission = Transmission::Rotary { ratio: 80.0 };
        params.axes[0].inertia = f64::NAN;
        assert!(params
            .validate()
            .unwrap_err()
            .starts_with("axis 0: inertia"));
    }
}
