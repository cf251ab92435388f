//! The lanes every CPU runs: `f64` (one body) and [`F64x4`] (`wide::f64x4`: SSE2 pairs on the
//! x86_64 baseline, NEON or scalar elsewhere).

use std::ops::{Add, Div, Mul, Sub};

use super::{Lane, lane_ops};
use crate::math::{Narrow, Real, Widen};

/// Proof that the CPU runs the portable lanes: every CPU does, so anyone may make one.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Portable;

impl Lane for f64 {
    type Mask = bool;
    type Cpu = Portable;
    const WIDTH: usize = 1;
    #[inline(always)]
    fn splat(_: Portable, x: f64) -> Self {
        x
    }
    #[inline(always)]
    fn load(_: Portable, values: &[f64]) -> Self {
        values[0]
    }
    #[inline(always)]
    fn store(self, out: &mut [f64]) {
        out[0] = self;
    }
    #[inline(always)]
    fn load_real(_: Portable, values: &[Real]) -> Self {
        values[0].widen()
    }
    #[inline(always)]
    fn store_real(self, out: &mut [Real]) {
        out[0] = self.narrow();
    }
    #[inline(always)]
    fn cpu(self) -> Portable {
        Portable
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
}

/// Four f64 lanes (`wide::f64x4`).
#[derive(Debug, Clone, Copy)]
pub(crate) struct F64x4 {
    v: wide::f64x4,
    cpu: Portable,
}

lane_ops!(F64x4, safe: Add::add, Sub::sub, Mul::mul, Div::div);

impl std::ops::Neg for F64x4 {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        Self {
            v: -self.v,
            cpu: self.cpu,
        }
    }
}

impl Lane for F64x4 {
    type Mask = wide::f64x4;
    type Cpu = Portable;
    const WIDTH: usize = 4;
    #[inline(always)]
    fn splat(cpu: Portable, x: f64) -> Self {
        Self {
            v: wide::f64x4::splat(x),
            cpu,
        }
    }
    #[inline(always)]
    fn load(cpu: Portable, values: &[f64]) -> Self {
        Self {
            v: wide::f64x4::new([values[0], values[1], values[2], values[3]]),
            cpu,
        }
    }
    #[inline(always)]
    fn store(self, out: &mut [f64]) {
        out[..4].copy_from_slice(&self.v.to_array());
    }
    #[inline(always)]
    fn load_real(cpu: Portable, values: &[Real]) -> Self {
        let v = [values[0], values[1], values[2], values[3]];
        Self::load(cpu, &v.map(Widen::widen))
    }
    #[inline(always)]
    fn store_real(self, out: &mut [Real]) {
        let v = self.v.to_array();
        out[..4].copy_from_slice(&v.map(Narrow::narrow));
    }
    #[inline(always)]
    fn cpu(self) -> Portable {
        self.cpu
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        Self {
            v: self.v.sqrt(),
            cpu: self.cpu,
        }
    }
    #[inline(always)]
    fn gt(self, other: Self) -> wide::f64x4 {
        self.v.simd_gt(other.v)
    }
    #[inline(always)]
    fn select(mask: wide::f64x4, yes: Self, no: Self) -> Self {
        Self {
            v: mask.bitselect(yes.v, no.v),
            cpu: yes.cpu,
        }
    }
    #[inline(always)]
    fn any(mask: wide::f64x4) -> bool {
        mask.any()
    }
    #[inline(always)]
    fn beyond(self, limit: f64) -> wide::f64x4 {
        self.v.abs().simd_gt(wide::f64x4::splat(limit)) | self.v.is_nan()
    }
}
