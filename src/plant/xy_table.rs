//! The two-axis test table: two independent servo axes (X and Y).

use serde::{Deserialize, Serialize};

use super::servo_axis::{AxisParams, ServoAxis};

/// Parameters of both axes.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct XyTableParams {
    pub x: AxisParams,
    pub y: AxisParams,
}

impl XyTableParams {
    /// The paper's plant: identical axes.
    pub const PAPER: XyTableParams = XyTableParams {
        x: AxisParams::PAPER,
        y: AxisParams::PAPER,
    };

    /// Mismatched axes (Y carries 1.5× the inertia, its drive left as tuned for X): the
    /// classic source of contour error that cross coupling is meant to remove.
    pub fn mismatched() -> Self {
        let mut y = AxisParams::PAPER;
        y.inertia *= 1.5;
        XyTableParams {
            x: AxisParams::PAPER,
            y,
        }
    }

    pub fn validate(&self) -> Result<(), String> {
        self.x.validate().map_err(|e| format!("x.{e}"))?;
        self.y.validate().map_err(|e| format!("y.{e}"))
    }
}

/// Two servo axes driven by velocity commands.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct XyTable {
    pub x: ServoAxis,
    pub y: ServoAxis,
}

impl XyTable {
    /// Both axes at rest at `position` (mm).
    pub fn new(params: XyTableParams, position: [f64; 2]) -> Self {
        XyTable {
            x: ServoAxis::new(params.x, position[0]),
            y: ServoAxis::new(params.y, position[1]),
        }
    }

    /// Advances by `step` seconds with the velocity commands (mm/s) held.
    pub fn step(&mut self, command: [f64; 2], step: f64) {
        self.x.step(command[0], step);
        self.y.step(command[1], step);
    }

    /// Position, mm.
    pub fn position(&self) -> [f64; 2] {
        [self.x.position(), self.y.position()]
    }

    /// Velocity, mm/s.
    pub fn velocity(&self) -> [f64; 2] {
        [self.x.velocity(), self.y.velocity()]
    }
}
