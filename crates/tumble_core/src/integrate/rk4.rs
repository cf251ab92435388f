//! Classic Runge–Kutta 4 on the free rotation, inside the drift–kick–drift step.
//!
//! With `L` constant in the world during the free flow, the only ODE left is
//! `Q̇ = ½ (ω, 0) ⊗ Q` with `ω = Q I_b⁻¹ Qᵀ L`; RK4 (in f64) advances the quaternion as a
//! 4-vector, normalizes it, and the body momentum is re-read as `m = Qᵀ L`. Fourth order for
//! torque-free rotation; `|L|` is exact by construction (it is not integrated), the energy drifts
//! slowly because `Q` leaves the energy ellipsoid. Cost: 4 evaluations of `ω(Q)` (two frame
//! rotations each) per drift.

use glam::{DQuat, DVec3};

use super::frame::rotate64;
use super::splitting::FreeBody;

/// `Q̇ = ½ (ω(Q), 0) ⊗ Q` with `ω(Q) = Q (r ⊙ Qᵀ L)`.
#[inline]
fn quat_rate(q: DQuat, momentum: DVec3, r: DVec3) -> DQuat {
    let w = rotate64(q, r * rotate64(q.conjugate(), momentum));
    DQuat::from_xyzw(w.x, w.y, w.z, 0.0) * q * 0.5
}

/// One RK4 step of the free rotation over `h` at constant world momentum.
#[inline]
pub(super) fn rk4_free_flow(body: &mut FreeBody, r: DVec3, h: f64) {
    let momentum = rotate64(body.q, body.m);
    let q = body.q;
    let k1 = quat_rate(q, momentum, r);
    let k2 = quat_rate(q + k1 * (0.5 * h), momentum, r);
    let k3 = quat_rate(q + k2 * (0.5 * h), momentum, r);
    let k4 = quat_rate(q + k3 * h, momentum, r);
    let q = (q + (k1 + k2 * 2.0 + k3 * 2.0 + k4) * (h / 6.0)).normalize();
    body.q = q;
    body.m = rotate64(q.conjugate(), momentum);
}
