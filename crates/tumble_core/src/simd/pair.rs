//! Two lane values side by side, operation by operation: a run of `2 × WIDTH` bodies as two
//! independent dependency chains.
//!
//! The kernel's free flow is a chain of four rotations, each waiting on a sine and cosine of
//! the angle the previous one left; one run of bodies alone leaves most of the core idle
//! while it waits. Issued side by side, two runs fill those gaps (the out-of-order window is too
//! small to overlap them when they follow each other), at the price of spilling some values to
//! the stack. Lane-wise, a pair is its two halves: the same bits.

use std::ops::{Add, Div, Mul, Neg, Sub};

use super::Lane;

/// Two lane values: bodies `0 .. T::WIDTH` in `lo`, the next `T::WIDTH` in `hi`.
#[derive(Clone, Copy)]
pub(crate) struct Pair<T> {
    lo: T,
    hi: T,
}

/// A lane mask of a [`Pair`].
#[derive(Clone, Copy)]
pub(crate) struct PairMask<M> {
    lo: M,
    hi: M,
}

macro_rules! pair_op {
    ($trait:ident, $method:ident) => {
        impl<T: Lane> $trait for Pair<T> {
            type Output = Self;
            #[inline(always)]
            fn $method(self, rhs: Self) -> Self {
                Self {
                    lo: $trait::$method(self.lo, rhs.lo),
                    hi: $trait::$method(self.hi, rhs.hi),
                }
            }
        }
    };
}
pair_op!(Add, add);
pair_op!(Sub, sub);
pair_op!(Mul, mul);
pair_op!(Div, div);

impl<T: Lane> Neg for Pair<T> {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        Self {
            lo: -self.lo,
            hi: -self.hi,
        }
    }
}

impl<T: Lane> Lane for Pair<T> {
    type Mask = PairMask<T::Mask>;
    type Cpu = T::Cpu;
    const WIDTH: usize = 2 * T::WIDTH;
    #[inline(always)]
    fn splat(cpu: T::Cpu, x: f64) -> Self {
        let v = T::splat(cpu, x);
        Self { lo: v, hi: v }
    }
    #[inline(always)]
    fn load(cpu: T::Cpu, values: &[f64]) -> Self {
        Self {
            lo: T::load(cpu, values),
            hi: T::load(cpu, &values[T::WIDTH..]),
        }
    }
    #[inline(always)]
    fn store(self, out: &mut [f64]) {
        self.lo.store(out);
        self.hi.store(&mut out[T::WIDTH..]);
    }
    #[inline(always)]
    fn load_real(cpu: T::Cpu, values: &[crate::math::Real]) -> Self {
        Self {
            lo: T::load_real(cpu, values),
            hi: T::load_real(cpu, &values[T::WIDTH..]),
        }
    }
    #[inline(always)]
    fn store_real(self, out: &mut [crate::math::Real]) {
        self.lo.store_real(out);
        self.hi.store_real(&mut out[T::WIDTH..]);
    }
    #[inline(always)]
    fn cpu(self) -> T::Cpu {
        self.lo.cpu()
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        Self {
            lo: self.lo.sqrt(),
            hi: self.hi.sqrt(),
        }
    }
    #[inline(always)]
    fn gt(self, other: Self) -> Self::Mask {
        PairMask {
            lo: self.lo.gt(other.lo),
            hi: self.hi.gt(other.hi),
        }
    }
    #[inline(always)]
    fn select(mask: Self::Mask, yes: Self, no: Self) -> Self {
        Self {
            lo: T::select(mask.lo, yes.lo, no.lo),
            hi: T::select(mask.hi, yes.hi, no.hi),
        }
    }
    #[inline(always)]
    fn any(mask: Self::Mask) -> bool {
        T::any(mask.lo) || T::any(mask.hi)
    }
    #[inline(always)]
    fn beyond(self, limit: f64) -> Self::Mask {
        PairMask {
            lo: self.lo.beyond(limit),
            hi: self.hi.beyond(limit),
        }
    }
}
