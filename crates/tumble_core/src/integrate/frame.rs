//! Principal-frame helpers shared by the integrators.
//!
//! The frame conversions world ↔ principal are done in f64 and rounded once (see [`rotate`]), so
//! that a conversion every step adds unbiased round-off only.

use crate::math::{Narrow, Quat, Vec3, Widen};
use glam::{DQuat, DVec3};

use crate::mass::MassProperties;
use crate::state::BodyState;

/// Reciprocal of a principal moment, `0` for a locked axis.
#[inline]
pub fn recip(moment: f64) -> f64 {
    if moment > 0.0 { 1.0 / moment } else { 0.0 }
}

/// `q v q* / |q|²` in f64: `((w² − b·b) v + 2 (b·v) b + 2w (b × v)) / (w² + b·b)`, `q = (b, w)`;
/// a rotation even when `q` is not exactly unit.
#[inline]
pub fn rotate64(q: DQuat, v: DVec3) -> DVec3 {
    let b = DVec3::new(q.x, q.y, q.z);
    let w = q.w;
    let b2 = b.dot(b);
    let inv_norm2 = 1.0 / (w * w + b2);
    ((w * w - b2) * v + (2.0 * b.dot(v)) * b + (2.0 * w) * b.cross(v)) * inv_norm2
}

/// Rotation by `q`, exact in norm for a nearly unit `q`: the sandwich `q v q* / |q|²` evaluated
/// in f64 and rounded to f32 once.
///
/// Integrators that carry `ω` in the world but work on `L` or `m` convert every step, and every
/// f32 shortcut rounds with a bias: glam's `q * v` assumes `|q| = 1`, an f32 sandwich rounds its
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
pub fn principal_orientation(state: &BodyState, mass: &MassProperties) -> Quat {
    state.rotation * mass.principal_frame()
}

/// World angular momentum `L = Q I_b Qᵀ ω`, in f64 with a single rounding.
#[inline]
pub fn world_momentum(q_principal: Quat, inertia: Vec3, omega: Vec3) -> Vec3 {
    let q = q_principal.widen();
    let body = rotate64(q.conjugate(), omega.widen());
    rotate64(q, inertia.widen() * body).narrow()
}

/// World angular velocity `ω = Q I_b⁻¹ Qᵀ L` (zero about locked axes), in f64 with a single
/// rounding (the reciprocal of `I_b` is taken in f64, not the biased f32 `fl(1/I)`).
#[inline]
pub fn world_omega(q_principal: Quat, inertia: Vec3, momentum: Vec3) -> Vec3 {
    let q = q_principal.widen();
    let body = rotate64(q.conjugate(), momentum.widen());
    let i = inertia.widen();
    let rate = body * DVec3::new(recip(i.x), recip(i.y), recip(i.z));
    rotate64(q, rate).narrow()
}

/// Removes the angular velocity about locked principal axes (zero moment ⇒ no rotation about
/// that axis), for methods that update `ω` directly rather than through `L`.
#[inline]
pub fn clear_locked_axes(state: &mut BodyState, mass: &MassProperties) {
    if !mass.has_locked_axis() {
        return;
    }
    let q_principal = principal_orientation(state, mass);
    let unlocked = mass.inv_principal_inertia().cmpgt(Vec3::ZERO);
    let body = rotate_inv(q_principal, state.angular_velocity);
    let kept = Vec3::select(unlocked, body, Vec3::ZERO);
    state.angular_velocity = rotate(q_principal, kept);
}
