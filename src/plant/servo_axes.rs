//! A machine's axes as one plant: `D` independent servo axes driven by velocity commands,
//! in axis order. The two-axis test table of the paper is [`XyTable`].

use serde::{Deserialize, Serialize};
use serde_big_array::BigArray;

use super::servo_axis::{AxisParams, ServoAxis};
use crate::geometry::Vector;

/// Parameters of every axis, in axis order.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ServoAxesParams<const D: usize> {
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

/// `D` servo axes driven by velocity commands.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ServoAxes<const D: usize> {
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
    use crate::plant::Transmission;

    #[test]
    fn a_rotary_axis_follows_the_same_law_in_its_own_units() {
        // Same drive, 10 mm lead vs a 50:1 gearbox: positions (mm vs rad) evolve alike,
        // the motor current scales with motor angle per axis unit.
        let linear = AxisParams::PAPER;
        let rotary = AxisParams {
            transmission: Transmission::Rotary { ratio: 50.0 },
            ..AxisParams::PAPER
        };
        let mut axes = ServoAxes::new(
            ServoAxesParams {
                axes: [linear, rotary, linear],
            },
            Vector::<3>::new(1.0, 1.0, -2.0),
        );
        for k in 0..200 {
            let v = (k as f64 * 0.01).sin();
            axes.step(Vector::<3>::new(v, v, 2.0 * v), 1e-3);
        }
        let p = axes.position();
        assert_eq!(p[0], p[1]);
        assert!((p[2] + 2.0 - 2.0 * (p[0] - 1.0)).abs() < 1e-12);
        let (i_lin, i_rot) = (axes.axes[0].current(1.0), axes.axes[1].current(1.0));
        assert!((i_rot / i_lin - 50.0 * 10.0 / (2.0 * std::f64::consts::PI)).abs() < 1e-9);
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
