//! Two f64 computed side by side: the shape of a vector register on every platform the FMUs
//! ship for (SSE2 on x86-64, NEON on aarch64), written as plain lane-by-lane Rust that the
//! compiler turns into one vector instruction per operation. Each lane gets exactly the
//! IEEE operation its scalar code would, so results keep their bits. The fuzzy engine
//! computes two centroids at once with it.

use std::ops::{Add, Div, Mul, Sub};

/// Two lanes.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C, align(16))]
pub(crate) struct F64x2(pub [f64; 2]);

impl F64x2 {
    #[inline(always)]
    pub fn splat(x: f64) -> Self {
        F64x2([x, x])
    }

    #[inline(always)]
    fn map2(self, other: Self, f: impl Fn(f64, f64) -> f64) -> Self {
        F64x2([f(self.0[0], other.0[0]), f(self.0[1], other.0[1])])
    }

    /// The smaller lane by lane, for lanes that are not NaN (where it is `f64::min`, which
    /// also checks for NaN); between +0 and −0 the first.
    #[inline(always)]
    pub fn lesser(self, other: Self) -> Self {
        self.map2(other, |a, b| if b < a { b } else { a })
    }

    /// `self` in the lanes where `test` is > 0, +0 in the others.
    #[inline(always)]
    pub fn where_positive(self, test: Self) -> Self {
        self.map2(test, |x, t| if t > 0.0 { x } else { 0.0 })
    }
}

impl Add for F64x2 {
    type Output = Self;
    #[inline(always)]
    fn add(self, other: Self) -> Self {
        self.map2(other, |a, b| a + b)
    }
}

impl Sub for F64x2 {
    type Output = Self;
    #[inline(always)]
    fn sub(self, other: Self) -> Self {
        self.map2(other, |a, b| a - b)
    }
}

impl Mul for F64x2 {
    type Output = Self;
    #[inline(always)]
    fn mul(self, other: Self) -> Self {
        self.map2(other, |a, b| a * b)
    }
}

impl Div for F64x2 {
    type Output = Self;
    #[inline(always)]
    fn div(self, other: Self) -> Self {
        self.map2(other, |a, b| a / b)
    }
}
