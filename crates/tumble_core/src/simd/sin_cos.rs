//! `(sin x, cos x)` in lane-wise IEEE arithmetic only, so that a lane's result is the same bits
//! on every path and alone or in a batch (the platform `sin` differs between scalar libm and
//! SIMD code).

use super::Lane;

/// `1.5 · 2⁵²`: adding and subtracting it rounds an f64 below 2⁵¹ in magnitude to the nearest
/// integer (ties to even), with plain IEEE additions.
const ROUNDING_MAGIC: f64 = 6_755_399_441_055_744.0;

/// `π/2` in three parts of 33, 33 and 53 significant bits (Cody–Waite), so that `k · part` is
/// exact for `|k| < 2²⁰` and the reduction `x − k π/2` keeps full precision there.
const PIO2_HI: f64 = 1.570_796_326_734_125_6;
const PIO2_MID: f64 = 6.077_100_506_303_966e-11;
const PIO2_LO: f64 = 2.022_266_248_795_950_6e-21;

/// Above this magnitude the reduction above is no longer exact: the platform `sin_cos` is used
/// lane by lane (still deterministic, as that path is the same for a lane alone or in a batch).
const REDUCTION_LIMIT: f64 = 1.0e5;

/// Round to the nearest integer (ties to even) for `|x| < 2⁵¹`, in plain IEEE additions.
#[inline(always)]
fn round_nearest<T: Lane>(x: T) -> T {
    let cpu = x.cpu();
    (x + T::splat(cpu, ROUNDING_MAGIC)) - T::splat(cpu, ROUNDING_MAGIC)
}

/// `(sin x, cos x)`: Cody–Waite reduction to `r = x − k π/2`, `|r| ≤ π/4`, Taylor polynomials
/// through `r¹⁵` and `r¹⁶` (truncation below 5e-17 there), and the quadrant `k mod 4` applied
/// with selects. Error ≲ 2 ulp for `|x| ≤ 1e5`; beyond that (and for NaN) the platform
/// function is used. Each lane's result depends on that lane alone: the shortcuts taken for the
/// whole register give the same bits as the general path.
#[inline(always)]
pub(crate) fn sin_cos<T: Lane>(x: T) -> (T, T) {
    if !x.any_beyond(SMALL_ANGLE) {
        // k = 0 in every lane: the reduction and the quadrant below would be exact no-ops.
        return sin_cos_reduced(x);
    }
    let (sin, cos) = sin_cos_reduced_quadrant(x);
    if x.any_beyond(REDUCTION_LIMIT) {
        // Only the lanes beyond the limit take the platform values, so a neighbour that
        // diverged (NaN) or spins absurdly fast changes no other lane's bits.
        let far = x.beyond(REDUCTION_LIMIT);
        let (platform_sin, platform_cos) = x.platform_sin_cos();
        return (
            T::select(far, platform_sin, sin),
            T::select(far, platform_cos, cos),
        );
    }
    (sin, cos)
}

/// [`sin_cos`] by reduction and quadrant, for `|x| ≤` [`REDUCTION_LIMIT`].
#[inline(always)]
fn sin_cos_reduced_quadrant<T: Lane>(x: T) -> (T, T) {
    let cpu = x.cpu();
    let k = round_nearest(x * T::splat(cpu, std::f64::consts::FRAC_2_PI));
    let r = ((x - k * T::splat(cpu, PIO2_HI)) - k * T::splat(cpu, PIO2_MID))
        - k * T::splat(cpu, PIO2_LO);
    let (s, c) = sin_cos_reduced(r);
    // Quadrant j = k mod 4 ∈ {0,1,2,3}; sin is negative for j ∈ {2,3}, cos for j ∈ {1,2}
    // (that is, (j + 1) mod 4 ∈ {2,3}); sin and cos swap for odd j.
    let j = modulo_4(k);
    let j_next = modulo_4(j + T::splat(cpu, 1.0));
    let (upper, odd) = quadrant_bits(j);
    let (cos_negative, _) = quadrant_bits(j_next);
    let (sin_r, cos_r) = (T::select(odd, c, s), T::select(odd, s, c));
    let sin = T::select(upper, -sin_r, sin_r);
    let cos = T::select(cos_negative, -cos_r, cos_r);
    (sin, cos)
}

/// Below this magnitude `round(x · 2/π) = 0` (`0.78 · 2/π < 0.4966`): no reduction needed.
const SMALL_ANGLE: f64 = 0.78;

/// `(sin r, cos r)` for `|r| ≤ π/4`: `sin r = r − r z S(z)`, `cos r = 1 − z (½ − z C(z))` with
/// `z = r²` and the Taylor tails `S(z) = 1/3! − z/5! + … + z⁶/15!`,
/// `C(z) = 1/4! − z/6! + … + z⁶/16!`. Each tail is evaluated by Estrin's scheme,
/// `(a₀ + a₁z) + z²(a₂ + a₃z) + z⁴((a₄ + a₅z) + z²a₆)`: three levels of independent
/// multiply–adds instead of Horner's six in a row, which the kernel's chain of four
/// rotations waits on.
#[inline(always)]
fn sin_cos_reduced<T: Lane>(r: T) -> (T, T) {
    let cpu = r.cpu();
    let z = r * r;
    let z2 = z * z;
    let z4 = z2 * z2;
    let s01 = T::splat(cpu, 1.0 / 6.0) - z * T::splat(cpu, 1.0 / 120.0);
    let s23 = T::splat(cpu, 1.0 / 5_040.0) - z * T::splat(cpu, 1.0 / 362_880.0);
    let s45 = T::splat(cpu, 1.0 / 39_916_800.0) - z * T::splat(cpu, 1.0 / 6_227_020_800.0);
    let s6 = T::splat(cpu, 1.0 / 1_307_674_368_000.0);
    let sp = (s01 + z2 * s23) + z4 * (s45 + z2 * s6);
    let s = r - (r * z) * sp;
    let c01 = T::splat(cpu, 1.0 / 24.0) - z * T::splat(cpu, 1.0 / 720.0);
    let c23 = T::splat(cpu, 1.0 / 40_320.0) - z * T::splat(cpu, 1.0 / 3_628_800.0);
    let c45 = T::splat(cpu, 1.0 / 479_001_600.0) - z * T::splat(cpu, 1.0 / 87_178_291_200.0);
    let c6 = T::splat(cpu, 1.0 / 20_922_789_888_000.0);
    let cp = (c01 + z2 * c23) + z4 * (c45 + z2 * c6);
    let cos = T::splat(cpu, 1.0) - z * (T::splat(cpu, 0.5) - z * cp);
    (s, cos)
}

/// `k mod 4` for an integral `k`, exactly: `floor(k/4) = round(k/4 − 3/8)`.
#[inline(always)]
fn modulo_4<T: Lane>(k: T) -> T {
    let cpu = k.cpu();
    k - T::splat(cpu, 4.0) * round_nearest(k * T::splat(cpu, 0.25) - T::splat(cpu, 0.375))
}

/// For `j ∈ {0,1,2,3}`: the masks `j ≥ 2` and `j odd` (`⌊j/2⌋ = round(j/2 − 1/4)`).
#[inline(always)]
fn quadrant_bits<T: Lane>(j: T) -> (T::Mask, T::Mask) {
    let cpu = j.cpu();
    let half = T::splat(cpu, 0.5);
    let upper = round_nearest(j * half - T::splat(cpu, 0.25));
    (upper.gt(half), (j - T::splat(cpu, 2.0) * upper).gt(half))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::simd::{F64x4, Portable};

    /// Our sin/cos agree with the platform's to 2 ulp-ish (4e-16 absolute) over many periods,
    /// and F64x4 lanes agree with the scalar path bit for bit.
    #[test]
    fn sin_cos_matches_platform_and_lanes_match_scalar() {
        let mut worst: f64 = 0.0;
        for i in -200_000..=200_000 {
            let x = i as f64 * 1.234_567e-3 + 1e-9 * i as f64;
            let (s, c) = sin_cos(x);
            let (ps, pc) = x.sin_cos();
            worst = worst.max((s - ps).abs()).max((c - pc).abs());
            let lanes = F64x4::load(Portable, &[x, -x, 0.5 * x, 3.0 * x]);
            let (ls, lc) = sin_cos(lanes);
            let (mut ls_array, mut lc_array) = ([0.0; 4], [0.0; 4]);
            ls.store(&mut ls_array);
            lc.store(&mut lc_array);
            for (lane, xi) in [x, -x, 0.5 * x, 3.0 * x].into_iter().enumerate() {
                let (ss, sc) = sin_cos(xi);
                assert_eq!(ls_array[lane].to_bits(), ss.to_bits());
                assert_eq!(lc_array[lane].to_bits(), sc.to_bits());
            }
        }
        assert!(worst < 4.5e-16, "worst abs error {worst:e}");
        // Exact values where it matters: rotations by zero are the identity.
        assert_eq!(sin_cos(0.0_f64), (0.0, 1.0));
        // Beyond the reduction range the platform function is used; NaN stays NaN.
        assert_eq!(sin_cos(1e7_f64), 1e7_f64.sin_cos());
        assert!(sin_cos(f64::NAN).0.is_nan());
    }
}
