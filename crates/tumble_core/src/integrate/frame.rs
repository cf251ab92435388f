//! Principal-frame helpers shared by the integrators.
//!
//! The frame conversions world ↔ principal are done in f64 and rounded once (see [`rotate`]), so
//! that a conversion every step adds unbiased round-off only.

use glam::{DVec3, Quat, Vec3};

use crate::mass::MassProperties;
use crate::state::BodyState;

/// `q v q* / |q|²` in f64: `((w² − b·b) v + 2 (b·v) b + 2w (b × v)) / (w² + b·b)`, `q = (b, w)`.
#[inline]
fn rotate64(q: Quat, v: DVec3) -> DVec3 {
    let b = DVec3::new(f64::from(q.x), f64::from(q.y), f64::from(q.z));
    let w = f64::from(q.w);
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
    rotate64(q, v.as_dvec3()).as_vec3()
}

/// `q* v q / |q|²`: the inverse rotation (see [`rotate`]).
#[inline]
pub fn rotate_inv(q: Quat, v: Vec3) -> Vec3 {
    rotate64(q.conjugate(), v.as_dvec3()).as_vec3()
}

/// Orientation of the principal axes in the world: `Q = q P`.
#[inline]
pub fn principal_orientation(state: &BodyState, mass: &MassProperties) -> Quat {
    state.rotation * mass.principal_frame()
}

/// Writes back a principal orientation `Q` as the body orientation `q = Q P*`, normalized.
#[inline]
pub fn set_principal_orientation(state: &mut BodyState, mass: &MassProperties, q_principal: Quat) {
    let p = mass.principal_frame();
    let q = if p == Quat::IDENTITY {
        q_principal
    } else {
        q_principal * p.conjugate()
    };
    state.rotation = q.normalize();
}

/// World angular momentum `L = Q I_b Qᵀ ω`, in f64 with a single rounding.
#[inline]
pub fn world_momentum(q_principal: Quat, inertia: Vec3, omega: Vec3) -> Vec3 {
    let body = rotate64(q_principal.conjugate(), omega.as_dvec3());
    rotate64(q_principal, inertia.as_dvec3() * body).as_vec3()
}

/// World angular velocity `ω = Q I_b⁻¹ Qᵀ L` (zero about locked axes), in f64 with a single
/// rounding (the reciprocal of `I_b` is taken in f64, not the biased f32 `fl(1/I)`).
#[inline]
pub fn world_omega(q_principal: Quat, inertia: Vec3, momentum: Vec3) -> Vec3 {
    let body = rotate64(q_principal.conjugate(), momentum.as_dvec3());
    let i = inertia.as_dvec3();
    let inv = |moment: f64| if moment > 0.0 { 1.0 / moment } else { 0.0 };
    let rate = body * DVec3::new(inv(i.x), inv(i.y), inv(i.z));
    rotate64(q_principal, rate).as_vec3()
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

/// Quaternion of a rotation by `angle` about principal axis `axis` (0, 1 or 2).
#[inline]
pub fn axis_rotation(axis: usize, angle: f32) -> Quat {
    let (s, c) = (0.5 * angle).sin_cos();
    match axis {
        0 => Quat::from_xyzw(s, 0.0, 0.0, c),
        1 => Quat::from_xyzw(0.0, s, 0.0, c),
        _ => Quat::from_xyzw(0.0, 0.0, s, c),
    }
}

/// World direction of principal axis `axis` for the orientation `Q` (a column of its matrix,
/// scaled by `|Q|²`).
#[inline]
pub fn principal_axis(q: Quat, axis: usize) -> Vec3 {
    let (x, y, z, w) = (q.x, q.y, q.z, q.w);
    match axis {
        0 => Vec3::new(
            w * w + x * x - y * y - z * z,
            2.0 * (x * y + w * z),
            2.0 * (x * z - w * y),
        ),
        1 => Vec3::new(
            2.0 * (x * y - w * z),
            w * w - x * x + y * y - z * z,
            2.0 * (y * z + w * x),
        ),
        _ => Vec3::new(
            2.0 * (x * z + w * y),
            2.0 * (y * z - w * x),
            w * w - x * x - y * y + z * z,
        ),
    }
}
