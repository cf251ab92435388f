//! Principal-frame helpers shared by the integrators.
//!
//! The frame conversions world ↔ principal are done in f64 and rounded once (see [`rotate`]), so
//! that a conversion every step adds unbiased round-off only.

use crate::math::{Narrow, Quat, Vec3, Widen};
use glam::{DQuat, DVec3};

use crate::mass::MassProperties;
use crate::simd::Lane;
use crate::state::BodyState;

/// Reciprocal of a principal moment, `0` for a locked axis, in lanes (`f64` for one body).
#[inline(always)]
pub(crate) fn reciprocal<T: Lane>(moment: T) -> T {
    let cpu = moment.cpu();
    let zero = T::splat(cpu, 0.0);
    T::select(moment.gt(zero), T::splat(cpu, 1.0) / moment, zero)
}

/// `q v q* / |q|²` in f64: `((w² − b·b) v + 2 (b·v) b + 2w (b × v)) / (w² + b·b)`, `q = (b, w)`;
/// a rotation even when `q` is not exactly unit.
#[inline]
pub(super) fn rotate64(q: DQuat, v: DVec3) -> DVec3 {
    let b = DVec3::new(q.x, q.y, q.z);
    let w = q.w;
    let b2 = b.dot(b);
    let inv_norm2 = 1.0 / (w * w + b2);
    ((w * w - b2) * v + (2.0 * b.dot(v)) * b + (2.0 * w) * b.cross(v)) * inv_norm2
}

/// Rotation by `q`, exact in norm for a nearly unit `q`: the sandwich `q v q* / |q|²` evaluated
/// in f64 and rounded to the engine's precision ([`Real`](crate::math::Real)) once.
///
/// Integrators that carry `ω` in the world but work on `L` or `m` convert every step, and in the
/// default f32 build every shortcut rounds with a bias: glam's `q * v` assumes `|q| = 1`, an f32
/// sandwich rounds its
/// numerator and denominator differently, and `I · fl(1/I)` is not 1 (`3 · fl(1/3) = 1 + 3e-8`).
/// Over 7200 steps at 60 Hz those biases grew `|L|` by 1e-3 and turned 44 near-separatrix
/// Dzhanibekov flips into 56. With one final rounding per conversion the error stays unbiased.
#[inline]
pub fn rotate(q: Quat, v: Vec3) -> Vec3 {
    rotate64(q.widen(), v.widen()).narrow()
}

/// `q* v q / |q|²`: the inverse rotation (see [`rotate`]).
#[inline]
pub fn rotate_inv(q: Quat, v: Vec3) -> Vec3 {
    rotate64(q.conjugate().widen(), v.widen()).narrow()
}

/// Orientation of the principal axes in the world: `Q = q P`.
#[inline]
pub(super) fn principal_orientation(state: &BodyState, mass: &MassProperties) -> Quat {
    crate::math::quat_mul(state.rotation, mass.principal_frame())
}
