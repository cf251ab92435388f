//! Classic Runge–Kutta 4 on the free rotation, inside the drift–kick–drift step.
//!
//! With `L` constant in the world during the free flow, the only ODE left is
//! `Q̇ = ½ (ω, 0) ⊗ Q` with `ω = Q I_b⁻¹ Qᵀ L`; RK4 advances the quaternion as a 4-vector and the
//! result is normalized. Fourth order for torque-free rotation; `|L|` is exact by construction
//! (it is not integrated), the energy drifts slowly because `Q` leaves the energy ellipsoid.
//! Cost: 4 evaluations of `ω(Q)` (two frame rotations each) per drift, two drifts per step.

use glam::{Quat, Vec3};

use super::frame::world_omega;

/// `Q̇ = ½ (ω(Q), 0) ⊗ Q`.
#[inline]
fn quat_rate(q: Quat, momentum: Vec3, inertia: Vec3) -> Quat {
    let w = world_omega(q, inertia, momentum);
    Quat::from_xyzw(w.x, w.y, w.z, 0.0) * q * 0.5
}

/// One RK4 step of the free rotation over `h` at constant world momentum `L`.
#[inline]
pub fn rk4_free_flow(q: Quat, momentum: Vec3, inertia: Vec3, h: f32) -> Quat {
    let k1 = quat_rate(q, momentum, inertia);
    let k2 = quat_rate(q + k1 * (0.5 * h), momentum, inertia);
    let k3 = quat_rate(q + k2 * (0.5 * h), momentum, inertia);
    let k4 = quat_rate(q + k3 * h, momentum, inertia);
    q + (k1 + k2 * 2.0 + k3 * 2.0 + k4) * (h / 6.0)
}
