//! Points and vectors of any dimension (`nalgebra::SVector`), and the few operations the
//! path, contour and control code needs beyond nalgebra's own.
//!
//! Lengths go through [`norm`] (a fold of `hypot`) rather than nalgebra's `norm()`
//! (√Σx²): `hypot` neither overflows nor underflows for extreme coordinates, and it is
//! what the planar code has always used, so results stay bit-identical across the move
//! to generic dimensions. clippy.toml forbids the nalgebra method to keep it that way.

use crate::math;
use nalgebra::SVector;

/// A point or vector in `D` dimensions, mm (or mm and rad for machine joints).
pub type Vector<const D: usize> = SVector<f64, D>;

/// A planar point or vector.
pub type Vector2 = Vector<2>;

/// Euclidean length, never overflowing: in one and two dimensions `hypot` (exact for
/// D = 1, equal to `math::hypot(x, y)` for D = 2); from three on the square root of the sum of
/// squares — a fifth of the cost of folding `hypot`, within 2 ulp — when that sum is a
/// normal number far from overflow, else the `hypot` fold.
#[inline]
pub fn norm<const D: usize>(v: &Vector<D>) -> f64 {
    if D >= 3 {
        let sum = v.norm_squared();
        if sum.is_normal() && sum < 1e300 {
            return sum.sqrt();
        }
    }
    // Starting from |v₀| rather than hypot(0, v₀) saves a libm call per length: in the
    // plane one hypot, as before.
    match v.as_slice().split_first() {
        Some((first, rest)) => rest.iter().fold(first.abs(), |acc, &x| math::hypot(acc, x)),
        None => 0.0,
    }
}

/// Distance between two points.
#[inline]
pub fn dist<const D: usize>(a: &Vector<D>, b: &Vector<D>) -> f64 {
    norm(&(a - b))
}

/// Squared distance: cheaper than [`dist`] where only comparisons matter.
#[inline]
pub fn dist2<const D: usize>(a: &Vector<D>, b: &Vector<D>) -> f64 {
    (a - b).norm_squared()
}

/// True when every component is finite.
#[inline]
pub fn is_finite<const D: usize>(v: &Vector<D>) -> bool {
    v.iter().all(|x| x.is_finite())
}

/// `v / |v|`, or `None` for a zero (or non-finite) vector.
#[inline]
pub fn unit<const D: usize>(v: &Vector<D>) -> Option<Vector<D>> {
    let len = norm(v);
    (len > 0.0 && len.is_finite()).then(|| v * (1.0 / len))
}

/// Left perpendicular of a planar vector (rotation by +90°).
#[inline]
pub fn perp(a: &Vector2) -> Vector2 {
    Vector2::new(-a[1], a[0])
}

/// z-component of the planar cross product; positive when `b` is left of `a`.
#[inline]
pub fn cross(a: &Vector2, b: &Vector2) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}

/// Angle between two vectors, rad (0 when either is zero).
pub fn angle_between(u: &Vector<3>, v: &Vector<3>) -> f64 {
    let cross = norm(&u.cross(v));
    let dot = u.dot(v);
    if cross == 0.0 && dot == 0.0 {
        0.0
    } else {
        math::atan2(cross, dot)
    }
}

/// Spherical interpolation of unit vectors: the unit vector a fraction `t` of the way
/// from `a` to `b` along the great circle; `None` for opposite vectors (no unique way).
pub fn slerp(a: &Vector<3>, b: &Vector<3>, t: f64) -> Option<Vector<3>> {
    let angle = angle_between(a, b);
    if angle > std::f64::consts::PI - 1e-9 {
        return None;
    }
    if angle < 1e-9 {
        // sin θ ≈ θ: the linear blend, normalised, is exact to rounding here.
        return unit(&(a * (1.0 - t) + b * t));
    }
    let s = math::sin(angle);
    Some(a * (math::sin((1.0 - t) * angle) / s) + b * (math::sin(t * angle) / s))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slerp_follows_the_great_circle() {
        let (z, x) = (Vector::<3>::z(), Vector::<3>::x());
        for t in [0.0, 0.25, 0.5, 0.9, 1.0] {
            let v = slerp(&z, &x, t).unwrap();
            let a = t * std::f64::consts::FRAC_PI_2;
            assert!(
                (v - Vector::<3>::new(math::sin(a), 0.0, math::cos(a))).amax() < 1e-15,
                "t={t}"
            );
        }
        assert!(slerp(&z, &-z, 0.5).is_none());
        assert_eq!(slerp(&z, &z, 0.3), Some(z));
    }

    #[test]
    fn norm_is_hypot_in_the_plane_and_robust_in_any_dimension() {
        let v = Vector2::new(3.0, 4.0);
        assert_eq!(norm(&v), 5.0);
        // Bit-identical to hypot (what the planar code used before generic dimensions).
        let w = Vector2::new(0.1, 0.7);
        assert_eq!(norm(&w).to_bits(), math::hypot(0.1f64, 0.7).to_bits());
        // No overflow where Σx² would be infinite.
        let big = Vector::<3>::new(1e200, 1e200, 1e200);
        assert!((norm(&big) / (1e200 * 3f64.sqrt()) - 1.0).abs() < 1e-15);
        assert_eq!(norm(&Vector::<5>::zeros()), 0.0);
        assert_eq!(norm(&Vector::<1>::new(-2.5)), 2.5);
        assert_eq!(norm(&Vector::<0>::zeros()), 0.0);
        assert_eq!(
            norm(&Vector2::new(-0.1, -0.7)).to_bits(),
            math::hypot(0.1f64, 0.7).to_bits()
        );
    }

    #[test]
    fn plane_helpers() {
        let a = Vector2::new(1.0, 0.0);
        assert_eq!(perp(&a), Vector2::new(0.0, 1.0));
        assert_eq!(cross(&a, &perp(&a)), 1.0);
        assert_eq!(unit(&Vector2::zeros()), None);
        assert_eq!(unit(&Vector2::new(0.0, 2.0)), Some(Vector2::new(0.0, 1.0)));
        assert!(!is_finite(&Vector::<3>::new(0.0, f64::NAN, 0.0)));
    }
}
