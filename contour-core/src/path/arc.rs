//! Planar circular arc: centre O, radius r, start angle φ0 and signed sweep Δφ (positive =
//! counter-clockwise). Parameter u ∈ [0, 1], angle φ(u) = φ0 + u·Δφ, so the speed |C'| is
//! the constant r·|Δφ| and the feed-rate interpolator steps it exactly.

use crate::math;
use std::f64::consts::PI;

use serde::{Deserialize, Serialize};

use super::{clamp_param, Curve, CurvePoint, PathError};
use crate::geometry::{self, Vector2};

/// Circular arc (a full circle when |sweep| = 2π).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CircularArc {
    center: Vector2,
    radius: f64,
    start_angle: f64,
    sweep: f64,
}

impl CircularArc {
    /// Arc with `radius > 0`, `0 < |sweep| ≤ 2π` (sign = direction), all finite.
    pub fn new(
        center: impl Into<Vector2>,
        radius: f64,
        start_angle: f64,
        sweep: f64,
    ) -> Result<Self, PathError> {
        let center = center.into();
        if !geometry::is_finite(&center) || !radius.is_finite() || !start_angle.is_finite() {
            return Err(PathError::invalid(
                "arc centre, radius and start angle must be finite",
            ));
        }
        if radius <= 0.0 {
            return Err(PathError::invalid(format!(
                "arc radius must be > 0, got {radius}"
            )));
        }
        if !sweep.is_finite() || sweep == 0.0 || sweep.abs() > 2.0 * PI * (1.0 + 1e-12) {
            return Err(PathError::invalid(format!(
                "arc sweep must be nonzero with |sweep| <= 2*pi, got {sweep}"
            )));
        }
        Ok(CircularArc {
            center,
            radius,
            start_angle,
            sweep,
        })
    }

    /// Full circle starting at `start_angle`, counter-clockwise when `ccw`.
    pub fn circle(
        center: impl Into<Vector2>,
        radius: f64,
        start_angle: f64,
        ccw: bool,
    ) -> Result<Self, PathError> {
        CircularArc::new(
            center,
            radius,
            start_angle,
            if ccw { 2.0 * PI } else { -2.0 * PI },
        )
    }

    /// Centre O.
    pub fn center(&self) -> Vector2 {
        self.center
    }
    /// Radius r, mm.
    pub fn radius(&self) -> f64 {
        self.radius
    }
    /// Start angle φ0, rad.
    pub fn start_angle(&self) -> f64 {
        self.start_angle
    }
    /// Signed sweep Δφ, rad (positive counter-clockwise).
    pub fn sweep(&self) -> f64 {
        self.sweep
    }
    /// True when travelling counter-clockwise.
    pub fn is_ccw(&self) -> bool {
        self.sweep > 0.0
    }
    /// True when the arc is a closed circle.
    pub fn is_full_circle(&self) -> bool {
        self.sweep.abs() >= 2.0 * PI * (1.0 - 1e-12)
    }

    /// The mirror image about the x axis (y → −y): the sense of travel reverses.
    pub fn mirrored(&self) -> CircularArc {
        let c = Vector2::new(self.center[0], -self.center[1]);
        CircularArc::new(c, self.radius, -self.start_angle, -self.sweep)
            .expect("the mirror image of a valid arc is valid")
    }

    /// Parameter of the point of the arc at polar angle `phi` about the centre, if that
    /// angle lies within the sweep (used by the exact-distance code).
    pub fn param_of_angle(&self, phi: f64) -> Option<f64> {
        let d = self.sweep.signum() * (phi - self.start_angle);
        let d = d.rem_euclid(2.0 * PI);
        let u = d / self.sweep.abs();
        if u <= 1.0 {
            Some(u)
        } else {
            None
        }
    }
}

impl Curve for CircularArc {
    fn param_range(&self) -> (f64, f64) {
        (0.0, 1.0)
    }
    fn eval(&self, u: f64) -> CurvePoint {
        let u = clamp_param(u, 0.0, 1.0);
        let phi = self.start_angle + u * self.sweep;
        let (s, c) = math::sincos(phi);
        let r = self.radius;
        let w = self.sweep;
        CurvePoint {
            p: Vector2::new(self.center[0] + r * c, self.center[1] + r * s),
            d1: Vector2::new(-r * w * s, r * w * c),
            d2: Vector2::new(-r * w * w * c, -r * w * w * s),
        }
    }
    fn length_between(&self, u0: f64, u1: f64) -> f64 {
        let (u0, u1) = (clamp_param(u0, 0.0, 1.0), clamp_param(u1, 0.0, 1.0));
        (u1 - u0).abs() * self.radius * self.sweep.abs()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn validates() {
        assert!(CircularArc::new([0.0, 0.0], 0.0, 0.0, 1.0).is_err());
        assert!(CircularArc::new([0.0, 0.0], 1.0, 0.0, 0.0).is_err());
        assert!(CircularArc::new([0.0, 0.0], 1.0, 0.0, 7.0).is_err());
        assert!(CircularArc::new([0.0, f64::INFINITY], 1.0, 0.0, 1.0).is_err());
    }

    #[test]
    fn cw_quarter() {
        let a = CircularArc::new([1.0, 1.0], 2.0, 0.0, -PI / 2.0).unwrap();
        let e = a.eval(1.0);
        assert!((e.p[0] - 1.0).abs() < 1e-15 && (e.p[1] + 1.0).abs() < 1e-15);
        // Travelling clockwise at the end (bottom): direction −x.
        assert!(e.d1[0] < 0.0 && e.d1[1].abs() < 1e-12);
        assert!((a.length() - PI).abs() < 1e-15);
        assert_eq!(a.param_of_angle(-PI / 4.0), Some(0.5));
        assert_eq!(a.param_of_angle(PI / 4.0), None);
    }
}
