//! Straight segment from `a` to `b` in any dimension, parameter u ∈ [0, 1]
//! (C(u) = a + u·(b − a)).

use crate::math;
use serde::{Deserialize, Serialize};

use super::{clamp_param, Curve, CurvePoint, PathError};
use crate::geometry::{self, Vector};

/// A straight segment; the direction of travel is from `a` to `b`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Line<const D: usize = 2> {
    a: Vector<D>,
    b: Vector<D>,
}

impl<const D: usize> Line<D> {
    /// Segment from `a` to `b`; both finite and distinct.
    pub fn new(a: impl Into<Vector<D>>, b: impl Into<Vector<D>>) -> Result<Self, PathError> {
        let (a, b) = (a.into(), b.into());
        if !geometry::is_finite(&a) || !geometry::is_finite(&b) {
            return Err(PathError::invalid("line end points must be finite"));
        }
        if geometry::dist(&a, &b) == 0.0 {
            return Err(PathError::invalid("line end points must differ"));
        }
        Ok(Line { a, b })
    }

    /// Start point.
    pub fn start(&self) -> Vector<D> {
        self.a
    }

    /// End point.
    pub fn end(&self) -> Vector<D> {
        self.b
    }

    /// Parameter of the segment's point nearest `p` (the foot point, or an end).
    pub fn nearest_parameter(&self, p: &Vector<D>) -> f64 {
        let d = self.b - self.a;
        ((p - self.a).dot(&d) / d.dot(&d)).clamp(0.0, 1.0)
    }

    /// Unit direction of travel.
    pub fn direction(&self) -> Vector<D> {
        let d = self.b - self.a;
        d * (1.0 / geometry::norm(&d))
    }
}

impl Line<2> {
    /// Direction angle θ of travel, rad (docs/design/two-axis.md §4.1).
    pub fn angle(&self) -> f64 {
        let d = self.b - self.a;
        math::atan2(d[1], d[0])
    }
}

impl Line<2> {
    /// The mirror image about the x axis (y → −y), travelled the mirrored way.
    pub fn mirrored(&self) -> Line {
        let flip = |p: Vector<2>| Vector::<2>::new(p[0], -p[1]);
        Line::new(flip(self.a), flip(self.b)).expect("the mirror image of a valid line is valid")
    }
}

impl<const D: usize> Curve<D> for Line<D> {
    fn param_range(&self) -> (f64, f64) {
        (0.0, 1.0)
    }
    fn eval(&self, u: f64) -> CurvePoint<D> {
        let u = clamp_param(u, 0.0, 1.0);
        let d = self.b - self.a;
        CurvePoint {
            p: self.a + d * u,
            d1: d,
            d2: Vector::zeros(),
        }
    }
    fn length_between(&self, u0: f64, u1: f64) -> f64 {
        let (u0, u1) = (clamp_param(u0, 0.0, 1.0), clamp_param(u1, 0.0, 1.0));
        (u1 - u0).abs() * geometry::dist(&self.a, &self.b)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Vector2;

    #[test]
    fn rejects_degenerate_and_nonfinite() {
        assert!(Line::new(Vector2::new(1.0, 2.0), Vector2::new(1.0, 2.0)).is_err());
        assert!(Line::new(Vector2::new(f64::NAN, 0.0), Vector2::new(1.0, 2.0)).is_err());
        assert!(Line::<3>::new([0.0, 0.0, f64::INFINITY], [1.0, 2.0, 3.0]).is_err());
    }

    #[test]
    fn evaluates_3_4_5() {
        let l = Line::new(Vector2::new(1.0, 1.0), Vector2::new(4.0, 5.0)).unwrap();
        assert_eq!(l.length(), 5.0);
        assert_eq!(l.point(0.5), Vector2::new(2.5, 3.0));
        assert_eq!(l.eval(2.0).p, Vector2::new(4.0, 5.0));
        let d = l.direction();
        assert!((d[0] - 0.6).abs() < 1e-15 && (d[1] - 0.8).abs() < 1e-15);
    }

    #[test]
    fn works_in_three_dimensions() {
        let l = Line::<3>::new([0.0, 0.0, 0.0], [2.0, 3.0, 6.0]).unwrap();
        assert_eq!(l.length(), 7.0);
        assert_eq!(
            l.point(0.5),
            crate::geometry::Vector::<3>::new(1.0, 1.5, 3.0)
        );
    }
}
