//! A polyline through given points in any dimension, parameter u ∈ [0, n − 1] (vertex
//! i at u = i, straight in between): the shape of discrete five-axis references (CL
//! data, sampled built-ins).

use std::sync::Arc;

use serde::{Deserialize, Serialize};

use super::{clamp_param, Curve, CurvePoint, PathError};
use crate::geometry::{self, Vector};

/// A polyline of at least two points, consecutive points distinct. Clones share the
/// points.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Polyline<const D: usize> {
    points: Arc<[Vector<D>]>,
}

impl<const D: usize> Polyline<D> {
    /// Refuses fewer than two points, non-finite points and repeated consecutive points
    /// (a zero-length piece has no direction).
    pub fn new(points: Vec<Vector<D>>) -> Result<Self, PathError> {
        Self::shared(points.into())
    }

    /// [`Polyline::new`] on points shared with their owner (no copy).
    pub fn shared(points: Arc<[Vector<D>]>) -> Result<Self, PathError> {
        if points.len() < 2 {
            return Err(PathError::invalid(format!(
                "a polyline needs at least two points, got {}",
                points.len()
            )));
        }
        if let Some(i) = points.iter().position(|p| !geometry::is_finite(p)) {
            return Err(PathError::invalid(format!("point {i} is not finite")));
        }
        if let Some(i) = points.windows(2).position(|w| w[0] == w[1]) {
            return Err(PathError::invalid(format!(
                "points {i} and {} coincide",
                i + 1
            )));
        }
        Ok(Polyline { points })
    }

    /// The vertices.
    pub fn points(&self) -> &[Vector<D>] {
        &self.points
    }

    /// The piece holding `u` and the fraction along it.
    pub fn locate(&self, u: f64) -> (usize, f64) {
        let last = (self.points.len() - 1) as f64;
        let u = clamp_param(u, 0.0, last);
        let i = (u.floor() as usize).min(self.points.len() - 2);
        (i, u - i as f64)
    }
}

impl<const D: usize> Curve<D> for Polyline<D> {
    fn param_range(&self) -> (f64, f64) {
        (0.0, (self.points.len() - 1) as f64)
    }
    fn eval(&self, u: f64) -> CurvePoint<D> {
        let (i, t) = self.locate(u);
        let d = self.points[i + 1] - self.points[i];
        CurvePoint {
            p: self.points[i] + d * t,
            d1: d,
            d2: Vector::zeros(),
        }
    }
    fn length_between(&self, u0: f64, u1: f64) -> f64 {
        let (a, b) = if u0 <= u1 { (u0, u1) } else { (u1, u0) };
        let ((i, s), (j, t)) = (self.locate(a), self.locate(b));
        let piece = |k: usize| geometry::dist(&self.points[k + 1], &self.points[k]);
        if i == j {
            return (t - s) * piece(i);
        }
        (1.0 - s) * piece(i) + (i + 1..j).map(piece).sum::<f64>() + t * piece(j)
    }
    fn breakpoints(&self) -> Vec<f64> {
        (0..self.points.len()).map(|i| i as f64).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::path::Interpolator;

    type V3 = Vector<3>;

    #[test]
    fn evaluates_and_measures_piece_by_piece() {
        let p = Polyline::new(vec![
            V3::zeros(),
            V3::new(3.0, 4.0, 0.0),
            V3::new(3.0, 4.0, 12.0),
        ])
        .unwrap();
        assert_eq!(p.length(), 17.0);
        assert_eq!(p.length_between(0.5, 1.5), 2.5 + 6.0);
        assert_eq!(p.point(1.25), V3::new(3.0, 4.0, 3.0));
        assert_eq!(p.eval(0.5).d1, V3::new(3.0, 4.0, 0.0));
        assert_eq!(p.point(7.0), V3::new(3.0, 4.0, 12.0));
        assert!(Polyline::new(vec![V3::zeros()]).is_err());
        assert!(Polyline::new(vec![V3::zeros(), V3::zeros()]).is_err());
        assert!(Polyline::new(vec![V3::zeros(), V3::new(f64::NAN, 0.0, 0.0)]).is_err());
    }

    #[test]
    fn the_interpolator_keeps_the_chord_across_corners() {
        // A 90° corner: every chord is F·Ts (0.1 mm) to 0.01 %, except the clamped last one.
        let p = Polyline::new(vec![
            V3::zeros(),
            V3::new(1.03, 0.0, 0.0),
            V3::new(1.03, 0.0, 1.0),
        ])
        .unwrap();
        let mut it = Interpolator::new(p, 100.0, 1e-3).unwrap();
        let mut previous = it.point();
        loop {
            let s = it.step();
            let chord = geometry::dist(&s.point, &previous);
            if s.done {
                assert!(chord <= 0.1 * 1.0001);
                break;
            }
            assert!((chord / 0.1 - 1.0).abs() < 1e-4, "{chord} at u = {}", s.u);
            previous = s.point;
        }
    }
}
