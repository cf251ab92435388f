//! The engine's scalar, vector and rotation types: single precision by default, double precision
//! with the cargo feature `f64`.
//!
//! | feature   | [`Real`] | [`Vec3`]       | [`Quat`]       | [`Mat3`]       |
//! |-----------|----------|----------------|----------------|----------------|
//! | (default) | `f32`    | `glam::Vec3`   | `glam::Quat`   | `glam::Mat3`   |
//! | `f64`     | `f64`    | `glam::DVec3`  | `glam::DQuat`  | `glam::DMat3`  |
//!
//! Every component, resource, state and parameter of tumble uses these aliases, so one feature
//! switches the whole engine (the ECS layer, scene files, the CLI) to double precision. The
//! internal kernels that already work in `f64` (frame changes, the splitting rotations, the exact
//! references) read and write through [`Widen`] / [`Narrow`], which are the identity in an `f64`
//! build and one rounding in the default build.
//!
//! ```
//! use tumble_core::math::{Real, Vec3};
//! let v = Vec3::new(1.0, 2.0, 2.0);
//! let length: Real = v.length();
//! assert_eq!(length, 3.0);
//! ```

use glam::{DMat3, DQuat, DVec3};

#[cfg(not(feature = "f64"))]
mod precision {
    /// The engine's scalar: `f32` (enable the feature `f64` for `f64`).
    pub type Real = f32;
    pub use glam::{Mat3, Quat, Vec3, Vec4};
}

#[cfg(feature = "f64")]
mod precision {
    /// The engine's scalar: `f64` (the feature `f64` is on).
    pub type Real = f64;
    /// A 3-vector of [`Real`]: `glam::DVec3` (the feature `f64` is on).
    pub type Vec3 = glam::DVec3;
    /// A rotation quaternion of [`Real`]: `glam::DQuat` (the feature `f64` is on).
    pub type Quat = glam::DQuat;
    /// A 3×3 matrix of [`Real`]: `glam::DMat3` (the feature `f64` is on).
    pub type Mat3 = glam::DMat3;
    /// A 4-vector of [`Real`]: `glam::DVec4` (the feature `f64` is on).
    pub type Vec4 = glam::DVec4;
}

pub use precision::{Mat3, Quat, Real, Vec3, Vec4};

/// The name of [`Real`], for messages: `"f32"`, or `"f64"` with the feature `f64`.
pub const REAL_NAME: &str = if DOUBLE_PRECISION { "f64" } else { "f32" };

/// `true` when the engine runs in double precision (feature `f64`).
pub const DOUBLE_PRECISION: bool = cfg!(feature = "f64");

/// Any number that converts to `f64` exactly (`Real`, `f32`, `u32`, `i32`, …), as `f64`.
///
/// For code that must read the same in both precisions: `f64::from(x)` on an `f64` is flagged
/// as a useless conversion, this is not.
#[inline(always)]
#[must_use]
pub fn to_f64(x: impl Into<f64>) -> f64 {
    x.into()
}

/// True when `a` and `b` have the same bits: equal bits are equal inputs to any function (`==`
/// on floats would call `−0` and `+0` equal and a NaN unequal to itself). One OR of the
/// differences rather than an array comparison, which compiles to a call to `memcmp` per check
/// (the energy audit runs these for every body and spring every step).
#[inline(always)]
pub fn same_bits<const N: usize>(a: [Real; N], b: [Real; N]) -> bool {
    let mut differ = 0;
    for k in 0..N {
        differ |= a[k].to_bits() ^ b[k].to_bits();
    }
    differ == 0
}

/// Conversion to `f64` (exact): `Real → f64`, `Vec3 → DVec3`, `Quat → DQuat`.
///
/// The identity in an `f64` build; one exact widening in the default build.
pub trait Widen {
    /// The `f64` counterpart.
    type Wide;
    /// `self` in `f64`, exactly.
    fn widen(self) -> Self::Wide;
}

/// Conversion from `f64` to the engine's precision, rounding to nearest component-wise (the
/// identity in an `f64` build; quaternions are not renormalized).
pub trait Narrow {
    /// The engine-precision counterpart.
    type Narrow;
    /// `self` rounded to the engine's precision.
    fn narrow(self) -> Self::Narrow;
}

impl Widen for Real {
    type Wide = f64;
    #[inline(always)]
    fn widen(self) -> f64 {
        #[cfg(not(feature = "f64"))]
        {
            f64::from(self)
        }
        #[cfg(feature = "f64")]
        {
            self
        }
    }
}

impl Narrow for f64 {
    type Narrow = Real;
    #[inline(always)]
    fn narrow(self) -> Real {
        self as Real
    }
}

/// [`Widen`] and [`Narrow`] between a glam type of [`Real`]s and its `f64` counterpart, one
/// named component at a time (trait impls for several types: a function cannot write them;
/// the components are spelled out rather than mapped over an array, which the batch loops'
/// code generation does not see through as well).
macro_rules! widen_and_narrow {
    ($($real:ident => $wide:ident via $make:ident ($($c:ident),*)),*) => {$(
        impl Widen for $real {
            type Wide = $wide;
            #[inline(always)]
            fn widen(self) -> $wide {
                $wide::$make($(self.$c.widen()),*)
            }
        }

        impl Narrow for $wide {
            type Narrow = $real;
            #[inline(always)]
            fn narrow(self) -> $real {
                $real::$make($(self.$c.narrow()),*)
            }
        }
    )*};
}

widen_and_narrow!(Vec3 => DVec3 via new(x, y, z), Quat => DQuat via from_xyzw(x, y, z, w));

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn widen_then_narrow_is_the_identity() {
        let values: [Real; 8] = [
            0.0,
            -0.0,
            1.0,
            0.1,
            -3.5e7,
            Real::MIN_POSITIVE,
            Real::MAX,
            Real::EPSILON,
        ];
        for x in values {
            assert_eq!(x.widen().narrow().to_bits(), x.to_bits());
        }
        let v = Vec3::new(0.1, -0.2, 0.3);
        assert_eq!(v.widen().narrow(), v);
        let q = Quat::from_xyzw(0.1, 0.2, 0.3, 0.9);
        assert_eq!(q.widen().narrow(), q);
    }

    #[test]
    fn same_bits_tells_every_bit() {
        let a: [Real; 5] = [1.0, -0.0, Real::NAN, Real::INFINITY, 3.5];
        assert!(same_bits(a, a), "a NaN is the same bits as itself");
        let mut zero = a;
        zero[1] = 0.0;
        assert!(!same_bits(a, zero), "−0 and +0 differ");
        for k in 0..a.len() {
            let mut b = a;
            b[k] = Real::from_bits(b[k].to_bits() ^ 1);
            assert!(!same_bits(a, b), "the last bit of value {k}");
        }
    }

    #[test]
    fn narrow_rounds_to_the_engine_precision() {
        let third = (1.0_f64 / 3.0).narrow();
        let expected: Real = 1.0 / 3.0;
        assert_eq!(third, expected);
        assert!(Real::EPSILON.widen() > 1e-17);
        assert_eq!(DOUBLE_PRECISION, Real::EPSILON < 1e-10);
    }
}

/// `a b` (apply `b`, then `a`), computed in f64 and rounded once: the same bits whether glam
/// runs its SIMD or its scalar `Quat` code (the `enhanced-determinism` feature), whose `f32`
/// products sum in different orders. In `f64` it is glam's `DQuat` product, scalar either way.
#[inline]
pub fn quat_mul(a: Quat, b: Quat) -> Quat {
    (a.widen() * b.widen()).narrow()
}

/// `q v` (the rotation of `v` by the unit quaternion `q`), as [`quat_mul`]: f64, one rounding.
#[inline]
pub fn quat_rotate(q: Quat, v: Vec3) -> Vec3 {
    (q.widen() * v.widen()).narrow()
}

/// `q / |q|`, as [`quat_mul`]: f64, one rounding.
#[inline]
pub fn quat_normalize(q: Quat) -> Quat {
    q.widen().normalize().narrow()
}

/// The axial vector of a 3×3 matrix `X`, `Tₖ = εₖₐᵦ Xₐᵦ`: `(X₂₃ − X₃₂, X₃₁ − X₁₃, X₁₂ − X₂₁)`
/// (twice the axial vector of its antisymmetric part). For `X = Σ aᵢ Fᵢᵀ` it is `Σ aᵢ × Fᵢ`: the
/// torque of forces `Fᵢ` at arms `aᵢ`.
#[inline]
pub fn axial_vector(x: DMat3) -> DVec3 {
    DVec3::new(
        x.z_axis.y - x.y_axis.z,
        x.x_axis.z - x.z_axis.x,
        x.y_axis.x - x.x_axis.y,
    )
}

#[cfg(test)]
mod axial_tests {
    use glam::{DMat3, DVec3};

    #[test]
    fn axial_vector_of_an_outer_product_is_the_cross_product() {
        let (a, f) = (DVec3::new(0.3, -1.2, 2.0), DVec3::new(-0.7, 0.4, 1.1));
        let x = DMat3::from_cols(a * f.x, a * f.y, a * f.z);
        assert!((super::axial_vector(x) - a.cross(f)).length() < 1e-15);
    }
}
