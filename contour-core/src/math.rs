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

/// `libm::hypot`, kept out of line: inlined, it made `geometry::norm` too large to inline
/// into the five-axis planner's loops (planning 100 k poses took 1.24× as long; out of
/// line, 1.06×, as glibc's external call was). The bits are libm's.
#[inline(never)]
pub fn hypot(a: f64, b: f64) -> f64 {
    libm::hypot(a, b)
}
