//! Straight segment from `a` to `b`, parameter u ∈ [0, 1] (C(u) = a + u·(b − a)).

use serde::{Deserialize, Serialize};

use super::{clamp_param, v2, Curve, CurvePoint, PathError};

/// A straight segment; the direction of travel is from `a` to `b`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Line {
    a: [f64; 2],
    b: [f64; 2],
}

impl Line {
    /// Segment from `a` to `b`; both finite and distinct.
    pub fn new(a: [f64; 2], b: [f64; 2]) -> Result<Self, PathError> {
        if !v2::finite(a) || !v2::finite(b) {
            return Err(PathError::invalid("line end points must be finite"));
        }
        if v2::dist(a, b) == 0.0 {
            return Err(PathError::invalid("line end points must differ"));
        }
        Ok(Line { a, b })
    }

    /// Start point.
    pub fn start(&self) -> [f64; 2] {
        self.a
    }

    /// End point.
    pub fn end(&self) -> [f64; 2] {
        self.b
    }

    /// Unit direction of travel.
    pub fn direction(&self) -> [f64; 2] {
        let d = v2::sub(self.b, self.a);
        v2::scale(d, 1.0 / v2::norm(d))
    }

    /// Direction angle θ of travel, rad (docs/design.md §4.1).
    pub fn angle(&self) -> f64 {
        let d = v2::sub(self.b, self.a);
        d[1].atan2(d[0])
    }
}

impl Curve for Line {
    fn param_range(&self) -> (f64, f64) {
        (0.0, 1.0)
    }
    fn eval(&self, u: f64) -> CurvePoint {
        let u = clamp_param(u, 0.0, 1.0);
        let d = v2::sub(self.b, self.a);
        CurvePoint {
            p: v2::add(self.a, v2::scale(d, u)),
            d1: d,
            d2: [0.0, 0.0],
        }
    }
    fn length_between(&self, u0: f64, u1: f64) -> f64 {
        let (u0, u1) = (clamp_param(u0, 0.0, 1.0), clamp_param(u1, 0.0, 1.0));
        (u1 - u0).abs() * v2::dist(self.a, self.b)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rejects_degenerate_and_nonfinite() {
        assert!(Line::new([1.0, 2.0], [1.0, 2.0]).is_err());
        assert!(Line::new([f64::NAN, 0.0], [1.0, 2.0]).is_err());
    }

    #[test]
    fn evaluates_3_4_5() {
        let l = Line::new([1.0, 1.0], [4.0, 5.0]).unwrap();
        assert_eq!(l.length(), 5.0);
        assert_eq!(l.point(0.5), [2.5, 3.0]);
        assert_eq!(l.eval(2.0).p, [4.0, 5.0]);
        let d = l.direction();
        assert!((d[0] - 0.6).abs() < 1e-15 && (d[1] - 0.8).abs() < 1e-15);
    }
}
