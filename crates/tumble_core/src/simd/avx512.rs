//! Eight f64 lanes in one 512-bit register, for the kernel compiled with AVX-512F enabled:
//! twice the lanes of `Avx4` per instruction. Every operation is the IEEE-754 lane-wise
//! operation (no fused multiply–add), so results equal the scalar kernel's bit for bit.
#![expect(
    unsafe_code,
    reason = "AVX-512F intrinsics; every `Avx8` carries an `Avx512` token, which proves the CPU runs them"
)]

use std::arch::x86_64::*;

use super::{Lane, cpu_proof, intrinsic_lane_members, lane_ops};

cpu_proof!(
    /// Proof that the CPU runs AVX-512F: made only by [`Avx512::detect`].
    Avx512,
    "avx512f"
);

/// Eight f64 lanes in a `__m512d`.
#[derive(Clone, Copy)]
pub(crate) struct Avx8 {
    v: __m512d,
    cpu: Avx512,
}

lane_ops!(Avx8, intrinsics: _mm512_add_pd, _mm512_sub_pd, _mm512_mul_pd, _mm512_div_pd);

impl std::ops::Neg for Avx8 {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        // SAFETY: the `cpu` token proves AVX-512F. `0 − x` would turn +0 into +0, not −0;
        // flipping the sign bit (integer xor, AVX-512F) is IEEE negation.
        let v = unsafe {
            _mm512_castsi512_pd(_mm512_xor_si512(
                _mm512_castpd_si512(self.v),
                _mm512_set1_epi64(i64::MIN),
            ))
        };
        Self { v, cpu: self.cpu }
    }
}

impl Lane for Avx8 {
    /// A bit per lane: a plain integer, so no proof is needed to test it.
    type Mask = __mmask8;
    intrinsic_lane_members!(
        cpu: Avx512,
        width: 8,
        splat: _mm512_set1_pd,
        load: _mm512_loadu_pd,
        store: _mm512_storeu_pd,
        load_f32: _mm256_loadu_ps,
        widen: _mm512_cvtps_pd,
        narrow: _mm512_cvtpd_ps,
        store_f32: _mm256_storeu_ps,
        sqrt: _mm512_sqrt_pd,
    );
    #[inline(always)]
    fn gt(self, other: Self) -> __mmask8 {
        // SAFETY: the `cpu` token proves AVX-512F. Ordered, quiet: false for NaN, as `>`.
        unsafe { _mm512_cmp_pd_mask::<_CMP_GT_OQ>(self.v, other.v) }
    }
    #[inline(always)]
    fn select(mask: __mmask8, yes: Self, no: Self) -> Self {
        // SAFETY: the `cpu` token proves AVX-512F. Lanes with the mask bit set take `yes`.
        let v = unsafe { _mm512_mask_blend_pd(mask, no.v, yes.v) };
        Self { v, cpu: yes.cpu }
    }
    #[inline(always)]
    fn any(mask: __mmask8) -> bool {
        mask != 0
    }
    #[inline(always)]
    fn beyond(self, limit: f64) -> __mmask8 {
        // SAFETY: the `cpu` token proves AVX-512F. |x| > limit, or NaN (unordered).
        unsafe {
            let abs = _mm512_abs_pd(self.v);
            _mm512_cmp_pd_mask::<_CMP_NLE_UQ>(abs, _mm512_set1_pd(limit))
        }
    }
}
