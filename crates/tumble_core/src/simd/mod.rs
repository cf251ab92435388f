//! SIMD lanes for the batched free rotation: one [`Lane`] trait the kernels are written against
//! once, and one backend per instruction set supplying only what differs (its register type,
//! its intrinsics, its negation and masks).
//!
//! | path | lane type | bodies per register | module |
//! |---|---|---|---|
//! | (one body) | `f64` | 1 | `portable` |
//! | `portable` | [`F64x4`] (`wide`: SSE2 pairs) | 4 | `portable` |
//! | `avx2` | `Pair<Avx4>` (two `__m256d`, side by side: see `pair`) | 8 | `avx2` |
//! | `avx512` | `Avx8` (`__m512d`) | 8 | `avx512` |
//!
//! **Bit identity.** Every operation of a lane is lane-wise IEEE-754 arithmetic (`+ − × ÷ √`,
//! compare, select), with no fused multiply–add and no horizontal operation, so a body gets the
//! same bits whether it is stepped alone or in any lane of a batch, on any path, with any batch
//! split and on any thread. The sine and cosine are our own polynomials ([`sin_cos`]) for the
//! same reason (the platform `sin` differs between scalar and SIMD code).
//!
//! **Soundness.** The AVX2 and AVX-512 lane types execute instructions that the x86_64 baseline
//! lacks. Every value of such a type carries a zero-sized proof token of its CPU feature
//! ([`Lane::Cpu`]), every constructor ([`Lane::splat`], [`Lane::load`]) takes one, and a token
//! is obtainable only from `is_x86_feature_detected!` (through [`Kernel`]): a lane value cannot
//! exist on a CPU that cannot run it, whatever the code around it does. The tokens' private
//! fields keep them from being built anywhere else.
//!
//! Which path a batch takes is [`Kernel::selected`]: the widest the CPU has, or the one the
//! environment variable `TUMBLE_KERNEL` forces (see [`KernelPath`]).

#[cfg(target_arch = "x86_64")]
mod avx2;
#[cfg(target_arch = "x86_64")]
mod avx512;
mod counting;
pub(crate) mod dispatch;
mod pair;
mod path;
mod portable;
mod sin_cos;

#[cfg(target_arch = "x86_64")]
pub(crate) use avx2::{Avx2, Avx4};
#[cfg(target_arch = "x86_64")]
pub(crate) use avx512::{Avx8, Avx512};
pub use counting::OpCounts;
pub(crate) use counting::{Counted, counted};
pub(crate) use dispatch::{LaneKernel, run_on};
pub(crate) use pair::Pair;
pub(crate) use path::Kernel;
pub use path::{KERNEL_ENV, KernelError, KernelPath, kernel_path};
pub(crate) use portable::{F64x4, Portable};
pub(crate) use sin_cos::sin_cos;

use std::ops::{Add, Div, Mul, Neg, Sub};

use crate::math::Real;

/// Number of bodies a batch kernel steps at once: one AVX-512 register of f64, or two AVX2
/// registers side by side.
pub(crate) const LANES: usize = 8;

/// f64 lanes: `f64` itself (one body), or a SIMD type holding a run of `WIDTH` consecutive
/// bodies of a batch (the kernel steps [`LANES`] bodies as `LANES / WIDTH` runs: one run per
/// register keeps it within the register file).
pub(crate) trait Lane:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    /// A lane mask from a comparison.
    type Mask: Copy;
    /// Proof that the CPU runs this type's instructions (zero-sized).
    type Cpu: Copy;
    /// Bodies per value (divides [`LANES`]).
    const WIDTH: usize;
    /// All lanes equal to `x`.
    fn splat(cpu: Self::Cpu, x: f64) -> Self;
    /// Lanes from the first `WIDTH` values of `values` (panics if there are fewer).
    fn load(cpu: Self::Cpu, values: &[f64]) -> Self;
    /// Writes the lanes to the first `WIDTH` values of `out` (panics if there are fewer).
    fn store(self, out: &mut [f64]);
    /// Lanes from the first `WIDTH` values of `values`, widened exactly from the engine
    /// precision (one vector conversion, not one per value).
    fn load_real(cpu: Self::Cpu, values: &[Real]) -> Self;
    /// Writes the lanes, rounded to the engine precision (to nearest, as `f64 as f32`), to
    /// the first `WIDTH` values of `out`.
    fn store_real(self, out: &mut [Real]);
    /// The proof this value was built with.
    fn cpu(self) -> Self::Cpu;
    /// Lane-wise square root (correctly rounded).
    fn sqrt(self) -> Self;
    /// Lane-wise `self > other` (false for NaN).
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

    /// The platform `(sin, cos)` applied lane by lane (the same libm call for a lane alone or
    /// in a batch, so still deterministic).
    #[inline]
    fn platform_sin_cos(self) -> (Self, Self) {
        let mut x = [0.0; LANES];
        self.store(&mut x);
        let (mut sin, mut cos) = ([0.0; LANES], [0.0; LANES]);
        for i in 0..Self::WIDTH {
            (sin[i], cos[i]) = x[i].sin_cos();
        }
        (Self::load(self.cpu(), &sin), Self::load(self.cpu(), &cos))
    }
}

/// `+ − × ÷` for a lane type `$lane { v, cpu }` from its backend's four lane-wise operations on
/// the raw register `v`: `safe` functions (the portable backend) or `unsafe` intrinsics of the
/// CPU feature that the value's `cpu` token proves.
macro_rules! lane_ops {
    ($lane:ident, safe: $add:path, $sub:path, $mul:path, $div:path) => {
        lane_ops!(@impl $lane, Add, add, $add, safe);
        lane_ops!(@impl $lane, Sub, sub, $sub, safe);
        lane_ops!(@impl $lane, Mul, mul, $mul, safe);
        lane_ops!(@impl $lane, Div, div, $div, safe);
    };
    ($lane:ident, intrinsics: $add:path, $sub:path, $mul:path, $div:path) => {
        lane_ops!(@impl $lane, Add, add, $add, intrinsic);
        lane_ops!(@impl $lane, Sub, sub, $sub, intrinsic);
        lane_ops!(@impl $lane, Mul, mul, $mul, intrinsic);
        lane_ops!(@impl $lane, Div, div, $div, intrinsic);
    };
    (@impl $lane:ident, $trait:ident, $method:ident, $op:path, safe) => {
        impl std::ops::$trait for $lane {
            type Output = Self;
            #[inline(always)]
            fn $method(self, rhs: Self) -> Self {
                Self { v: $op(self.v, rhs.v), cpu: self.cpu }
            }
        }
    };
    (@impl $lane:ident, $trait:ident, $method:ident, $op:path, intrinsic) => {
        impl std::ops::$trait for $lane {
            type Output = Self;
            #[inline(always)]
            fn $method(self, rhs: Self) -> Self {
                // SAFETY: `self` exists, so its `cpu` token was made, which only happens once
                // `is_x86_feature_detected!` has confirmed the feature this intrinsic needs.
                let v = unsafe { $op(self.v, rhs.v) };
                Self { v, cpu: self.cpu }
            }
        }
    };
}
pub(crate) use lane_ops;

/// The members of [`Lane`] that both intrinsic backends write the same way around their own
/// instructions: `Cpu`, `WIDTH`, `splat`, `load` and `store` (unaligned, `WIDTH` values),
/// `load_real` and `store_real` (in an `f32` build: `WIDTH` f32 loaded with `load_f32` and
/// widened by `widen`, or rounded by `narrow` and stored by `store_f32`), `cpu`, and `sqrt`
/// (correctly rounded, as `f64::sqrt`). For a lane type `{ v, cpu }` whose `cpu` token proves
/// the feature the intrinsics need.
macro_rules! intrinsic_lane_members {
    (
        cpu: $cpu:ident,
        width: $width:literal,
        splat: $splat:path,
        load: $load:path,
        store: $store:path,
        load_f32: $load_f32:path,
        widen: $widen:path,
        narrow: $narrow:path,
        store_f32: $store_f32:path,
        sqrt: $sqrt:path $(,)?
    ) => {
        type Cpu = $cpu;
        const WIDTH: usize = $width;
        #[inline(always)]
        fn splat(cpu: $cpu, x: f64) -> Self {
            // SAFETY: the `cpu` token proves the feature the intrinsic needs.
            let v = unsafe { $splat(x) };
            Self { v, cpu }
        }
        #[inline(always)]
        fn load(cpu: $cpu, values: &[f64]) -> Self {
            let values = &values[..$width];
            // SAFETY: the `cpu` token proves the feature; `values` holds the `WIDTH` f64 the
            // load reads.
            let v = unsafe { $load(values.as_ptr()) };
            Self { v, cpu }
        }
        #[inline(always)]
        fn store(self, out: &mut [f64]) {
            let out = &mut out[..$width];
            // SAFETY: the `cpu` token proves the feature; `out` holds the `WIDTH` f64 the
            // store writes.
            unsafe { $store(out.as_mut_ptr(), self.v) };
        }
        #[inline(always)]
        fn load_real(cpu: $cpu, values: &[$crate::math::Real]) -> Self {
            let values = &values[..$width];
            // SAFETY: the `cpu` token proves the feature; `values` holds the `WIDTH` values
            // the load reads. Widening f32 to f64 is exact.
            #[cfg(not(feature = "f64"))]
            let v = unsafe { $widen($load_f32(values.as_ptr())) };
            // SAFETY: as for `load`.
            #[cfg(feature = "f64")]
            let v = unsafe { $load(values.as_ptr()) };
            Self { v, cpu }
        }
        #[inline(always)]
        fn store_real(self, out: &mut [$crate::math::Real]) {
            let out = &mut out[..$width];
            // SAFETY: the `cpu` token proves the feature; `out` holds the `WIDTH` values the
            // store writes. The conversion rounds by the MXCSR mode, round-to-nearest-even as
            // Rust leaves it: the scalar `as f32`'s rounding.
            #[cfg(not(feature = "f64"))]
            unsafe {
                $store_f32(out.as_mut_ptr(), $narrow(self.v))
            };
            // SAFETY: as for `store`.
            #[cfg(feature = "f64")]
            unsafe {
                $store(out.as_mut_ptr(), self.v)
            };
        }
        #[inline(always)]
        fn cpu(self) -> $cpu {
            self.cpu
        }
        #[inline(always)]
        fn sqrt(self) -> Self {
            // SAFETY: the `cpu` token proves the feature. Correctly rounded, as `f64::sqrt`.
            let v = unsafe { $sqrt(self.v) };
            Self { v, cpu: self.cpu }
        }
    };
}
pub(crate) use intrinsic_lane_members;

/// A zero-sized proof that the CPU runs the feature `$feature` (a literal for
/// `is_x86_feature_detected!`): its field is private, so only `detect` makes one, and a lane
/// value that carries it cannot exist on a CPU without the feature.
macro_rules! cpu_proof {
    ($(#[$doc:meta])* $name:ident, $feature:tt) => {
        $(#[$doc])*
        #[derive(Debug, Clone, Copy)]
        pub(crate) struct $name {
            _detected: (),
        }

        impl $name {
            /// The proof, if the CPU has the feature.
            #[inline]
            pub(crate) fn detect() -> Option<Self> {
                is_x86_feature_detected!($feature).then_some(Self { _detected: () })
            }
        }
    };
}
pub(crate) use cpu_proof;
