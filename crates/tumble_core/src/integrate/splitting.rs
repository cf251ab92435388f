//! Lie–Poisson splitting of the free rigid body, and the kick–drift steps built on it.
//!
//! The free-body Hamiltonian `H = Σᵢ mᵢ²/(2Iᵢ)` (body momentum `m = Qᵀ L`) splits into three
//! terms, each integrable exactly: the flow of `mᵢ²/(2Iᵢ)` rotates the body about its principal
//! axis `i` by the angle `θ = t mᵢ/Iᵢ`, with the world momentum `L` fixed. The Strang composition
//!
//! ```text
//! Φ_h = A₁(h/2) ∘ A₂(h/2) ∘ A₃(h) ∘ A₂(h/2) ∘ A₁(h/2)
//! ```
//!
//! is symplectic (Lie–Poisson), time-reversible and second order (McLachlan 1993; Touma &
//! Wisdom 1994; Dullweber, Leimkuhler & McLachlan 1997). `L` never changes inside the free flow,
//! so `|L|` of a torque-free body is kept to round-off; the energy error stays bounded.
//!
//! With external load the step is the symmetric drift–kick–drift
//! `D(h/2) ∘ K(h) ∘ D(h/2)`: `D` moves `x += ½h v` and applies the free flow `Φ_{h/2}`, `K` kicks
//! `v += h F/m` and `L += h τ`. Forces are sampled once, between the two drifts (the ECS runs the
//! first drift before the force systems), so constant forces are integrated exactly and springs
//! get the second-order, symplectic position-Verlet scheme.
//! Cost per step: 10 axis rotations (one `sin_cos` each) and 4 frame conversions.

use glam::{Quat, Vec3};

use super::frame::{
    axis_rotation, principal_axis, principal_orientation, set_principal_orientation,
    world_momentum, world_omega,
};
use crate::mass::MassProperties;
use crate::state::{BodyState, Wrench};

/// Exact flow of `mᵢ²/(2Iᵢ)` for time `h`: rotates `Q` about its principal axis `i` by
/// `θ = h (aᵢ·L)/Iᵢ`, with `aᵢ = Q eᵢ` the axis in the world. `L` is unchanged. `inertia` holds
/// the principal moments `I_b`.
#[inline]
fn axis_flow(q: Quat, momentum: Vec3, inertia: Vec3, axis: usize, h: f32) -> Quat {
    let moment = inertia[axis];
    if moment <= 0.0 {
        return q; // locked axis: no rotation about it
    }
    let a = principal_axis(q, axis) / q.length_squared();
    let theta = h * a.dot(momentum) / moment;
    q * axis_rotation(axis, theta)
}

/// Strang splitting 1-2-3-2-1 of the free flow over `h`, on the principal orientation `Q`.
#[inline]
pub fn strang_free_flow(q: Quat, momentum: Vec3, inertia: Vec3, h: f32) -> Quat {
    let half = 0.5 * h;
    let q = axis_flow(q, momentum, inertia, 0, half);
    let q = axis_flow(q, momentum, inertia, 1, half);
    let q = axis_flow(q, momentum, inertia, 2, h);
    let q = axis_flow(q, momentum, inertia, 1, half);
    axis_flow(q, momentum, inertia, 0, half)
}

/// A free-flow approximation `Q ← Φ(Q, L, h)` at constant world momentum `L`.
pub type FreeFlow = fn(Quat, Vec3, Vec3, f32) -> Quat;

/// Drift for `h`: `x += h v` and the free rotation `Φ_h` at constant `L` (spherical bodies
/// rotate exactly about `ω`, since `ω ∥ L` for them).
#[inline]
pub fn drift(state: &mut BodyState, mass: &MassProperties, h: f32, flow: FreeFlow) {
    state.position += h * state.linear_velocity;
    if mass.is_spherical() {
        state.rotation = crate::rotation::rotate_exact(state.rotation, state.angular_velocity, h);
        return;
    }
    let q = principal_orientation(state, mass);
    let momentum = world_momentum(q, mass.principal_inertia(), state.angular_velocity);
    let q = flow(q, momentum, mass.principal_inertia(), h).normalize();
    state.angular_velocity = world_omega(q, mass.principal_inertia(), momentum);
    set_principal_orientation(state, mass, q);
}

/// Kick for `h`: `v += h F/m`, `L += h τ` (so `ω += h I⁻¹ τ` at the current pose).
#[inline]
pub fn kick(state: &mut BodyState, mass: &MassProperties, wrench: &Wrench, h: f32) {
    state.linear_velocity += (h * mass.inv_mass()) * wrench.force;
    if wrench.torque != Vec3::ZERO {
        state.angular_velocity += mass.world_inertia_mul(state.rotation, h * wrench.torque);
    }
}

/// First half of a drift–kick–drift step: `D(h/2)`, before forces are sampled.
#[inline]
pub fn begin_dkd(state: &mut BodyState, mass: &MassProperties, h: f32, flow: FreeFlow) {
    drift(state, mass, 0.5 * h, flow);
}

/// Second half of a drift–kick–drift step: `K(h)` then `D(h/2)`.
#[inline]
pub fn finish_dkd(
    state: &mut BodyState,
    mass: &MassProperties,
    wrench: &Wrench,
    h: f32,
    flow: FreeFlow,
) {
    kick(state, mass, wrench, h);
    drift(state, mass, 0.5 * h, flow);
}
