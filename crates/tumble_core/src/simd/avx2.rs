//! Four f64 lanes in one 256-bit register, for the kernel compiled with AVX2 enabled.
//!
//! `wide::f64x4` picks its AVX code at compile time, so in a portable build it runs as two SSE2
//! halves even inside a function compiled with AVX2; this type calls the intrinsics directly.
//! Every operation is the IEEE-754 lane-wise operation (no fused multiply–add), so results
//! equal the scalar kernel's bit for bit.
#![expect(
    unsafe_code,
    reason = "AVX intrinsics; every `Avx4` carries an `Avx2` token, which proves the CPU runs them"
)]

use std::arch::x86_64::*;

use super::{Lane, cpu_proof, intrinsic_lane_members, lane_ops};

cpu_proof!(
    /// Proof that the CPU runs AVX2: made only by [`Avx2::detect`].
    Avx2,
    "avx2"
);

/// Four f64 lanes in a `__m256d`.
#[derive(Clone, Copy)]
pub(crate) struct Avx4 {
    v: __m256d,
    cpu: Avx2,
}

/// A lane mask of [`Avx4`] (all bits set in a true lane).
#[derive(Clone, Copy)]
pub(crate) struct Mask4 {
    m: __m256d,
    cpu: Avx2,
}

lane_ops!(Avx4, intrinsics: _mm256_add_pd, _mm256_sub_pd, _mm256_mul_pd, _mm256_div_pd);

impl std::ops::Neg for Avx4 {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        // SAFETY: the `cpu` token proves AVX. Flipping the sign bit is IEEE negation.
        let v = unsafe { _mm256_xor_pd(self.v, _mm256_set1_pd(-0.0)) };
        Self { v, cpu: self.cpu }
    }
}

impl Lane for Avx4 {
    type Mask = Mask4;
    intrinsic_lane_members!(
        cpu: Avx2,
        width: 4,
        splat: _mm256_set1_pd,
        load: _mm256_loadu_pd,
        store: _mm256_storeu_pd,
        load_f32: _mm_loadu_ps,
        widen: _mm256_cvtps_pd,
        narrow: _mm256_cvtpd_ps,
        store_f32: _mm_storeu_ps,
        sqrt: _mm256_sqrt_pd,
    );
    #[inline(always)]
    fn gt(self, other: Self) -> Mask4 {
        // SAFETY: the `cpu` token proves AVX. Ordered, quiet: false for NaN, as `>`.
        let m = unsafe { _mm256_cmp_pd::<_CMP_GT_OQ>(self.v, other.v) };
        Mask4 { m, cpu: self.cpu }
    }
    #[inline(always)]
    fn select(mask: Mask4, yes: Self, no: Self) -> Self {
        // SAFETY: the `cpu` token proves AVX.
        let v = unsafe { _mm256_blendv_pd(no.v, yes.v, mask.m) };
        Self { v, cpu: mask.cpu }
    }
    #[inline(always)]
    fn any(mask: Mask4) -> bool {
        // SAFETY: the mask's `cpu` token proves AVX.
        unsafe { _mm256_movemask_pd(mask.m) != 0 }
    }
    #[inline(always)]
    fn beyond(self, limit: f64) -> Mask4 {
        // SAFETY: the `cpu` token proves AVX. |x| > limit, or NaN (unordered).
        let m = unsafe {
            let abs = _mm256_andnot_pd(_mm256_set1_pd(-0.0), self.v);
            _mm256_cmp_pd::<_CMP_NLE_UQ>(abs, _mm256_set1_pd(limit))
        };
        Mask4 { m, cpu: self.cpu }
    }
}
