//! Lane-generic f64 arithmetic: the free-flow kernels are written once over [`Lane`] and run
//! either on one body (`f64`) or on several bodies at once ([`F64x4`], or the AVX and AVX-512
//! types of the kernel, SIMD).
//!
//! Every operation used here is lane-wise IEEE-754 arithmetic (`+ − × ÷ √`, compare, select),
//! with no fused multiply–add and no horizontal operation, so a body gets **bit-identical**
//! results whether it is stepped alone or in any lane of a batch, with any batch split and on any
//! thread. The sine and cosine are our own polynomials for the same reason (the platform `sin`
//! differs between the scalar libm and SIMD code paths).

use std::ops::{Add, Div, Mul, Neg, Sub};

/// Number of bodies a batch kernel steps at once: one AVX-512 register of f64, or two runs of
/// four.
pub const LANES: usize = 8;

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

/// f64 lanes: `f64` itself (one body), or a SIMD type holding several bodies ([`F64x4`], and
/// the AVX and AVX-512 types of the kernel).
pub trait Lane:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    /// A lane mask from a comparison.
    type Mask: Copy;
    /// All lanes equal to `x`.
    fn splat(x: f64) -> Self;
    /// Lane-wise square root (correctly rounded).
    fn sqrt(self) -> Self;
    /// Lane-wise `self > other`.
    fn gt(self, other: Self) -> Self::Mask;
    /// Lane-wise `if mask { yes } else { no }`.
    fn select(mask: Self::Mask, yes: Self, no: Self) -> Self;
    /// True when any lane of `mask` is set.
    fn any(mask: Self::Mask) -> bool;
    /// Lane-wise: the magnitude exceeds `limit`, or the lane is NaN.
    fn beyond(self, limit: f64) -> Self::Mask;
    /// True when any lane's magnitude exceeds `limit` or is NaN.
    #[inline(always)]
    fn any_beyond(self, limit: f64) -> bool {
        Self::any(self.beyond(limit))
    }
    /// The platform `(sin, cos)` applied lane by lane.
    fn platform_sin_cos(self) -> (Self, Self);
}

impl Lane for f64 {
    type Mask = bool;
    #[inline(always)]
    fn splat(x: f64) -> Self {
        x
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        f64::sqrt(self)
    }
    #[inline(always)]
    fn gt(self, other: Self) -> bool {
        self > other
    }
    #[inline(always)]
    fn select(mask: bool, yes: Self, no: Self) -> Self {
        if mask { yes } else { no }
    }
    #[inline(always)]
    fn any(mask: bool) -> bool {
        mask
    }
    #[inline(always)]
    fn beyond(self, limit: f64) -> bool {
        self.abs() > limit || self.is_nan()
    }
    #[inline]
    fn platform_sin_cos(self) -> (Self, Self) {
        self.sin_cos()
    }
}

/// Four f64 lanes (`wide::f64x4`: SSE2 pairs, or one AVX register where available).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct F64x4(pub wide::f64x4);

macro_rules! lane_op {
    ($trait:ident, $method:ident, $op:tt) => {
        impl $trait for F64x4 {
            type Output = Self;
            #[inline(always)]
            fn $method(self, rhs: Self) -> Self {
                Self(self.0 $op rhs.0)
            }
        }
    };
}
lane_op!(Add, add, +);
lane_op!(Sub, sub, -);
lane_op!(Mul, mul, *);
lane_op!(Div, div, /);

impl Neg for F64x4 {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        Self(-self.0)
    }
}

impl F64x4 {
    /// Lanes from an array.
    #[inline(always)]
    pub fn new(lanes: [f64; 4]) -> Self {
        Self(wide::f64x4::new(lanes))
    }
    /// The lanes as an array.
    #[inline(always)]
    pub fn to_array(self) -> [f64; 4] {
        self.0.to_array()
    }
}

impl Lane for F64x4 {
    type Mask = wide::f64x4;
    #[inline(always)]
    fn splat(x: f64) -> Self {
        Self(wide::f64x4::splat(x))
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        Self(self.0.sqrt())
    }
    #[inline(always)]
    fn gt(self, other: Self) -> wide::f64x4 {
        self.0.simd_gt(other.0)
    }
    #[inline(always)]
    fn select(mask: wide::f64x4, yes: Self, no: Self) -> Self {
        Self(mask.bitselect(yes.0, no.0))
    }
    #[inline(always)]
    fn any(mask: wide::f64x4) -> bool {
        mask.any()
    }
    #[inline(always)]
    fn beyond(self, limit: f64) -> wide::f64x4 {
        self.0.abs().simd_gt(wide::f64x4::splat(limit)) | self.0.is_nan()
    }
    #[inline]
    fn platform_sin_cos(self) -> (Self, Self) {
        let lanes = self.to_array().map(f64::sin_cos);
        (
            F64x4::new(lanes.map(|l| l.0)),
            F64x4::new(lanes.map(|l| l.1)),
        )
    }
}

/// A [`Lane`] type that holds a run of `WIDTH` consecutive bodies of a batch: the kernel steps a
/// batch of [`LANES`] bodies as `LANES / WIDTH` runs (two runs of four with AVX, one run of
/// eight with AVX-512: one run per register keeps the kernel within the register file).
pub trait Run: Lane {
    /// Bodies per run (divides [`LANES`]).
    const WIDTH: usize;
    /// Lanes from the first `WIDTH` values of `values`.
    fn load(values: &[f64]) -> Self;
    /// Writes the lanes to the first `WIDTH` values of `out`.
    fn store(self, out: &mut [f64]);
}

impl Run for F64x4 {
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

/// Round to the nearest integer (ties to even) for `|x| < 2⁵¹`, in plain IEEE additions.
#[inline(always)]
fn round_nearest<T: Lane>(x: T) -> T {
    (x + T::splat(ROUNDING_MAGIC)) - T::splat(ROUNDING_MAGIC)
}

/// `(sin x, cos x)`: Cody–Waite reduction to `r = x − k π/2`, `|r| ≤ π/4`, Taylor polynomials
/// through `r¹⁵` and `r¹⁶` (truncation below 5e-17 there), and the quadrant `k mod 4` applied
/// with selects. Error ≲ 2 ulp for `|x| ≤ 1e5`; beyond that (and for NaN) the platform
/// function is used. Each lane's result depends on that lane alone: the shortcuts taken for the
/// whole register give the same bits as the general path.
#[inline(always)]
pub fn sin_cos<T: Lane>(x: T) -> (T, T) {
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
    let k = round_nearest(x * T::splat(std::f64::consts::FRAC_2_PI));
    let r = ((x - k * T::splat(PIO2_HI)) - k * T::splat(PIO2_MID)) - k * T::splat(PIO2_LO);
    let (s, c) = sin_cos_reduced(r);
    // Quadrant j = k mod 4 ∈ {0,1,2,3}; sin is negative for j ∈ {2,3}, cos for j ∈ {1,2}
    // (that is, (j + 1) mod 4 ∈ {2,3}); sin and cos swap for odd j.
    let j = modulo_4(k);
    let j_next = modulo_4(j + T::splat(1.0));
    let (upper, odd) = quadrant_bits(j);
    let (cos_negative, _) = quadrant_bits(j_next);
    let (sin_r, cos_r) = (T::select(odd, c, s), T::select(odd, s, c));
    let sin = T::select(upper, -sin_r, sin_r);
    let cos = T::select(cos_negative, -cos_r, cos_r);
    (sin, cos)
}

/// Below this magnitude `round(x · 2/π) = 0` (`0.78 · 2/π < 0.4966`): no reduction needed.
const SMALL_ANGLE: f64 = 0.78;

/// `(sin r, cos r)` for `|r| ≤ π/4`: `sin r = r (1 − z/3! + z²/5! − …)`,
/// `cos r = 1 − z/2! + z²/4! − …` with `z = r²`, Horner in `z`.
#[inline(always)]
fn sin_cos_reduced<T: Lane>(r: T) -> (T, T) {
    let z = r * r;
    let sp = T::splat(-1.0 / 1_307_674_368_000.0);
    let sp = T::splat(1.0 / 6_227_020_800.0) + z * sp;
    let sp = T::splat(-1.0 / 39_916_800.0) + z * sp;
    let sp = T::splat(1.0 / 362_880.0) + z * sp;
    let sp = T::splat(-1.0 / 5_040.0) + z * sp;
    let sp = T::splat(1.0 / 120.0) + z * sp;
    let sp = T::splat(1.0 / 6.0) - z * sp;
    let s = r - (r * z) * sp;
    let cp = T::splat(1.0 / 20_922_789_888_000.0);
    let cp = T::splat(-1.0 / 87_178_291_200.0) + z * cp;
    let cp = T::splat(1.0 / 479_001_600.0) + z * cp;
    let cp = T::splat(-1.0 / 3_628_800.0) + z * cp;
    let cp = T::splat(1.0 / 40_320.0) + z * cp;
    let cp = T::splat(-1.0 / 720.0) + z * cp;
    let cp = T::splat(1.0 / 24.0) + z * cp;
    let c = T::splat(1.0) - z * (T::splat(0.5) - z * cp);
    (s, c)
}

/// `k mod 4` for an integral `k`, exactly: `floor(k/4) = round(k/4 − 3/8)`.
#[inline(always)]
fn modulo_4<T: Lane>(k: T) -> T {
    k - T::splat(4.0) * round_nearest(k * T::splat(0.25) - T::splat(0.375))
}

/// For `j ∈ {0,1,2,3}`: the masks `j ≥ 2` and `j odd` (`⌊j/2⌋ = round(j/2 − 1/4)`).
#[inline(always)]
fn quadrant_bits<T: Lane>(j: T) -> (T::Mask, T::Mask) {
    let half = T::splat(0.5);
    let upper = round_nearest(j * half - T::splat(0.25));
    (upper.gt(half), (j - T::splat(2.0) * upper).gt(half))
}

#[cfg(test)]
mod tests {
    use super::*;

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
            let lanes = F64x4::new([x, -x, 0.5 * x, 3.0 * x]);
            let (ls, lc) = sin_cos(lanes);
            for (lane, xi) in [x, -x, 0.5 * x, 3.0 * x].into_iter().enumerate() {
                let (ss, sc) = sin_cos(xi);
                assert_eq!(ls.to_array()[lane].to_bits(), ss.to_bits());
                assert_eq!(lc.to_array()[lane].to_bits(), sc.to_bits());
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
