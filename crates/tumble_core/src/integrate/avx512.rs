//! Eight f64 lanes in one 512-bit AVX-512 register, for the kernel compiled with AVX-512F.
//!
//! Twice the lanes of [`super::avx::Avx4`] per instruction; on a CPU with two 512-bit FMA units
//! the batched free rotation costs about half as much per body (measured with the
//! `ecs_vs_raw` example of `tumble_bench`; numbers in the README).
//!
//! **Safety contract:** every method executes AVX-512F instructions, so an `Avx8` may only be
//! used inside functions compiled with `#[target_feature(enable = "avx512f")]` that are called
//! after `is_x86_feature_detected!("avx512f")` returned true. The type is private to the kernel
//! and only [`super::symmetric_kernel`] uses it, that way. Every operation is the IEEE-754
//! lane-wise operation (no fused multiply–add), so results equal the scalar kernel's bit for bit.
#![allow(unsafe_code)]

use std::arch::x86_64::*;
use std::ops::{Add, Div, Mul, Neg, Sub};

use super::lanes::{Lane, Run};

/// Eight f64 lanes in a `__m512d`.
#[derive(Clone, Copy)]
pub struct Avx8(__m512d);

impl Avx8 {
    /// Lanes from an array.
    #[inline(always)]
    pub fn new(lanes: [f64; 8]) -> Self {
        // SAFETY: AVX-512F is available (module contract); the load reads exactly 8 f64.
        Self(unsafe { _mm512_loadu_pd(lanes.as_ptr()) })
    }

    /// The lanes as an array.
    #[inline(always)]
    pub fn to_array(self) -> [f64; 8] {
        let mut out = [0.0; 8];
        // SAFETY: AVX-512F is available (module contract); the store writes exactly 8 f64.
        unsafe { _mm512_storeu_pd(out.as_mut_ptr(), self.0) };
        out
    }
}

macro_rules! avx512_op {
    ($trait:ident, $method:ident, $intrinsic:ident) => {
        impl $trait for Avx8 {
            type Output = Self;
            #[inline(always)]
            fn $method(self, rhs: Self) -> Self {
                // SAFETY: AVX-512F is available (module contract).
                Self(unsafe { $intrinsic(self.0, rhs.0) })
            }
        }
    };
}
avx512_op!(Add, add, _mm512_add_pd);
avx512_op!(Sub, sub, _mm512_sub_pd);
avx512_op!(Mul, mul, _mm512_mul_pd);
avx512_op!(Div, div, _mm512_div_pd);

impl Neg for Avx8 {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        // SAFETY: AVX-512F is available (module contract). 0 − x would turn +0 into +0, not
        // −0; flipping the sign bit (integer xor, AVX-512F) is IEEE negation.
        Self(unsafe {
            _mm512_castsi512_pd(_mm512_xor_si512(
                _mm512_castpd_si512(self.0),
                _mm512_set1_epi64(i64::MIN),
            ))
        })
    }
}

impl Lane for Avx8 {
    type Mask = __mmask8;
    #[inline(always)]
    fn splat(x: f64) -> Self {
        // SAFETY: AVX-512F is available (module contract).
        Self(unsafe { _mm512_set1_pd(x) })
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        // SAFETY: AVX-512F is available (module contract). Correctly rounded, as f64::sqrt.
        Self(unsafe { _mm512_sqrt_pd(self.0) })
    }
    #[inline(always)]
    fn gt(self, other: Self) -> __mmask8 {
        // SAFETY: AVX-512F is available (module contract). Ordered, quiet: false for NaN, as `>`.
        unsafe { _mm512_cmp_pd_mask::<_CMP_GT_OQ>(self.0, other.0) }
    }
    #[inline(always)]
    fn select(mask: __mmask8, yes: Self, no: Self) -> Self {
        // SAFETY: AVX-512F is available (module contract). Lanes with the mask bit set take
        // `yes`.
        Self(unsafe { _mm512_mask_blend_pd(mask, no.0, yes.0) })
    }
    #[inline(always)]
    fn any(mask: __mmask8) -> bool {
        mask != 0
    }
    #[inline(always)]
    fn beyond(self, limit: f64) -> __mmask8 {
        // SAFETY: AVX-512F is available (module contract). |x| > limit, or NaN (unordered).
        unsafe {
            let abs = _mm512_abs_pd(self.0);
            _mm512_cmp_pd_mask::<_CMP_NLE_UQ>(abs, _mm512_set1_pd(limit))
        }
    }
    #[inline]
    fn platform_sin_cos(self) -> (Self, Self) {
        let lanes = self.to_array().map(f64::sin_cos);
        (Avx8::new(lanes.map(|l| l.0)), Avx8::new(lanes.map(|l| l.1)))
    }
}

impl Run for Avx8 {
    const WIDTH: usize = 8;
    #[inline(always)]
    fn load(values: &[f64]) -> Self {
        Self::new([
            values[0], values[1], values[2], values[3], values[4], values[5], values[6], values[7],
        ])
    }
    #[inline(always)]
    fn store(self, out: &mut [f64]) {
        out[..8].copy_from_slice(&self.to_array());
    }
}
