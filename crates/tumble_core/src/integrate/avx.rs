//! Four f64 lanes in one 256-bit AVX register, for the kernel compiled with AVX enabled.
//!
//! `wide::f64x4` picks its AVX code at compile time, so in a portable build it runs as two SSE2
//! halves even inside a function compiled with AVX. This type calls the AVX intrinsics directly.
//! Measured (`cargo bench --bench integrators`, `many/splitting`, 1e4 bodies): see the README;
//! the gain is why this module exists.
//!
//! **Safety contract:** every method executes AVX instructions, so an `Avx4` may only be used
//! inside functions compiled with `#[target_feature(enable = "avx")]` that are called after
//! `is_x86_feature_detected!("avx")` returned true. The type is private to the kernel and only
//! [`super::symmetric_kernel`] uses it, that way. Every operation is the IEEE-754 lane-wise
//! operation (no fused multiply–add), so results equal the scalar kernel's bit for bit.
#![allow(unsafe_code)]

use std::arch::x86_64::*;
use std::ops::{Add, Div, Mul, Neg, Sub};

use super::lanes::{Lane, Run};

/// Four f64 lanes in a `__m256d`.
#[derive(Clone, Copy)]
pub struct Avx4(__m256d);

impl Avx4 {
    /// Lanes from an array.
    #[inline(always)]
    pub fn new(lanes: [f64; 4]) -> Self {
        // SAFETY: AVX is available (module contract); the load reads exactly 4 f64.
        Self(unsafe { _mm256_loadu_pd(lanes.as_ptr()) })
    }

    /// The lanes as an array.
    #[inline(always)]
    pub fn to_array(self) -> [f64; 4] {
        let mut out = [0.0; 4];
        // SAFETY: AVX is available (module contract); the store writes exactly 4 f64.
        unsafe { _mm256_storeu_pd(out.as_mut_ptr(), self.0) };
        out
    }
}

macro_rules! avx_op {
    ($trait:ident, $method:ident, $intrinsic:ident) => {
        impl $trait for Avx4 {
            type Output = Self;
            #[inline(always)]
            fn $method(self, rhs: Self) -> Self {
                // SAFETY: AVX is available (module contract).
                Self(unsafe { $intrinsic(self.0, rhs.0) })
            }
        }
    };
}
avx_op!(Add, add, _mm256_add_pd);
avx_op!(Sub, sub, _mm256_sub_pd);
avx_op!(Mul, mul, _mm256_mul_pd);
avx_op!(Div, div, _mm256_div_pd);

impl Neg for Avx4 {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        // SAFETY: AVX is available (module contract). Flipping the sign bit is IEEE negation.
        Self(unsafe { _mm256_xor_pd(self.0, _mm256_set1_pd(-0.0)) })
    }
}

impl Lane for Avx4 {
    type Mask = __m256d;
    #[inline(always)]
    fn splat(x: f64) -> Self {
        // SAFETY: AVX is available (module contract).
        Self(unsafe { _mm256_set1_pd(x) })
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        // SAFETY: AVX is available (module contract). Correctly rounded, as f64::sqrt.
        Self(unsafe { _mm256_sqrt_pd(self.0) })
    }
    #[inline(always)]
    fn gt(self, other: Self) -> __m256d {
        // SAFETY: AVX is available (module contract). Ordered, quiet: false for NaN, as `>`.
        unsafe { _mm256_cmp_pd::<_CMP_GT_OQ>(self.0, other.0) }
    }
    #[inline(always)]
    fn select(mask: __m256d, yes: Self, no: Self) -> Self {
        // SAFETY: AVX is available (module contract).
        Self(unsafe { _mm256_blendv_pd(no.0, yes.0, mask) })
    }
    #[inline(always)]
    fn any(mask: __m256d) -> bool {
        // SAFETY: AVX is available (module contract).
        unsafe { _mm256_movemask_pd(mask) != 0 }
    }
    #[inline(always)]
    fn beyond(self, limit: f64) -> __m256d {
        // SAFETY: AVX is available (module contract). |x| > limit, or NaN (unordered).
        unsafe {
            let abs = _mm256_andnot_pd(_mm256_set1_pd(-0.0), self.0);
            _mm256_cmp_pd::<_CMP_NLE_UQ>(abs, _mm256_set1_pd(limit))
        }
    }
    #[inline]
    fn platform_sin_cos(self) -> (Self, Self) {
        let lanes = self.to_array().map(f64::sin_cos);
        (Avx4::new(lanes.map(|l| l.0)), Avx4::new(lanes.map(|l| l.1)))
    }
}

impl Run for Avx4 {
    const WIDTH: usize = 4;
    #[inline(always)]
    fn load(values: &[f64]) -> Self {
        Self::new([values[0], values[1], values[2], values[3]])
    }
    #[inline(always)]
    fn store(self, out: &mut [f64]) {
        out[..4].copy_from_slice(&self.to_array());
    }
}
