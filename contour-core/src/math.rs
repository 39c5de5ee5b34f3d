//! The transcendental f64 functions, from one pure-Rust implementation (the `libm` crate)
//! that every platform shares.
//!
//! std's `f64::sin`, `atan2`, `exp`, … call the platform's C math library (glibc, msvcrt,
//! aarch64 glibc), and those differ in the last bits. Computed here instead, the FMUs'
//! outputs and saved states are bit-identical on linux64, win64 and aarch64. Clippy
//! (`disallowed-methods` in the root `clippy.toml`) refuses the std methods.
//!
//! `sqrt`, `abs`, `powi`, `floor` and the like stay std methods: `sqrt` is correctly rounded
//! (IEEE 754) everywhere, and `powi` is compiler-builtins code, the same on every platform.
//! Argument order is the C one: `atan2(y, x)`, `hypot(a, b)`, `pow(x, y)`; `sincos(x)`
//! returns `(sin, cos)` like `f64::sin_cos`, `expm1` is `f64::exp_m1` and `log` is `f64::ln`.

pub use libm::{acos, asin, atan2, cbrt, cos, cosh, exp, expm1, log, pow, sin, sincos, tan};

/// `atan2(y, x)` for an angle of 0 to 90°, faster where it is below 45° (0 ≤ y < x): there
/// libm's `atan2` is `atan(y / x)` after its checks for zeros, infinities and NaN, which
/// cannot apply, so the bits are `atan2`'s (a test compares them). The five-axis mapping
/// takes the angle of every segment of its window at every sample.
#[inline]
pub fn atan2_quadrant(y: f64, x: f64) -> f64 {
    if 0.0 <= y && y < x {
        libm::atan(y / x)
    } else {
        libm::atan2(y, x)
    }
}

/// `libm::hypot`, kept out of line: inlined, it made `geometry::norm` too large to inline
/// into the five-axis planner's loops (planning 100 k poses took 1.24× as long; out of
/// line, 1.06×, as glibc's external call was). The bits are libm's.
#[inline(never)]
pub fn hypot(a: f64, b: f64) -> f64 {
    libm::hypot(a, b)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::rngs::StdRng;
    use rand::{RngExt, SeedableRng};

    /// The circle estimators turn a chord both ways with one `sincos`: that needs
    /// sin(−x) = −sin x and cos(−x) = cos x bit for bit, over the reduction's branches.
    #[test]
    fn sincos_is_odd_and_even_bit_for_bit() {
        let mut rng = StdRng::seed_from_u64(3);
        // Zero, subnormal, tiny, around π/4, 3π/4 and 5π/4 (where the reduction changes).
        let quarter = std::f64::consts::FRAC_PI_4;
        let special = [
            0.0,
            1e-320,
            1e-9,
            0.785,
            quarter,
            3.0 * quarter,
            5.0 * quarter,
        ];
        let random = (0..1_000_000).map(|i| match i % 3 {
            0 => rng.random_range(0.0..1.6),
            1 => rng.random_range(0.0..100.0),
            _ => pow(10.0, rng.random_range(-300.0..300.0)),
        });
        for x in special.into_iter().chain(random) {
            let (s, c) = sincos(x);
            let (sn, cn) = sincos(-x);
            assert_eq!(
                (sn.to_bits(), cn.to_bits()),
                ((-s).to_bits(), c.to_bits()),
                "{x}"
            );
        }
    }

    #[test]
    fn the_quadrant_angle_is_atan2_bit_for_bit() {
        let mut rng = StdRng::seed_from_u64(7);
        let special = [
            0.0,
            -0.0,
            1.0,
            f64::MIN_POSITIVE,
            5e-324,
            1e300,
            f64::INFINITY,
            f64::NAN,
        ];
        for &y in &special {
            for &x in &special {
                assert_eq!(
                    atan2_quadrant(y, x).to_bits(),
                    atan2(y, x).to_bits(),
                    "{y} {x}"
                );
            }
        }
        for _ in 0..1_000_000 {
            // Magnitudes from 1e-300 to 1e300, ratios from 1e-20 to 1e20, equal values.
            let x = pow(10.0, rng.random_range(-300.0..300.0));
            let y = match rng.random_range(0..4) {
                0 => x,
                1 => x * pow(10.0, rng.random_range(-20.0..20.0)),
                2 => x * rng.random_range(0.0..1.0),
                _ => f64::from_bits(x.to_bits() - rng.random_range(0..4)),
            };
            assert_eq!(
                atan2_quadrant(y, x).to_bits(),
                atan2(y, x).to_bits(),
                "{y} {x}"
            );
        }
    }
}
