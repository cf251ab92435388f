//! The textbook semi-implicit Euler step and its linearized-rotation variant.
//!
//! Velocities are kicked first with the forces sampled at the start of the step, then poses
//! drift with the new velocities (symplectic Euler, "kick then drift"):
//!
//! ```text
//! v' = v + Δt m⁻¹ F                x' = x + Δt v'
//! ω' = ω + Δt I⁻¹ (τ − ω × I ω)    q' = exp(½ Δt ω') q
//! ```
//!
//! `I = (R P) diag(I_b) (R P)ᵀ` is applied in the principal frame, never inverted. Cost: about
//! 3 quaternion–vector rotations, one cross product and one `sin_cos` per body-step.
//! Under constant force the position carries the known bias `½ F/m Δt t`:
//! `x_n = x₀ + v₀ nΔt + F/m Δt² n(n+1)/2`.

use super::frame::clear_locked_axes;
use crate::mass::MassProperties;
use crate::math::{Real, Vec3, quat_mul, quat_rotate};
use crate::rotation::{rotate_exact, rotate_linearized};
use crate::state::{BodyState, Wrench};

/// Explicit angular-velocity kick with the gyroscopic term:
/// `ω ← ω + Δt I⁻¹(τ − ω × Iω)`, evaluated in the principal frame. For spherical inertia the
/// gyroscopic term vanishes and is skipped.
///
/// Only the increment is rotated back to the world frame, so the rotation round trip (which
/// scales a vector by `|q|²`, one ulp off unity) never touches `ω` itself: a torque-free spin
/// about a principal axis keeps its rate to the bit.
#[inline]
pub(super) fn explicit_gyroscopic_kick(
    state: &mut BodyState,
    mass: &MassProperties,
    torque: Vec3,
    dt: Real,
) {
    let frame = quat_mul(state.rotation, mass.principal_frame());
    let to_principal = frame.conjugate();
    let mut rate = quat_rotate(to_principal, torque);
    if !mass.is_spherical() {
        let omega = quat_rotate(to_principal, state.angular_velocity);
        rate -= omega.cross(mass.principal_inertia() * omega);
    }
    state.angular_velocity += quat_rotate(frame, dt * mass.inv_principal_inertia() * rate);
}

#[inline]
fn linear_kick_drift(state: &mut BodyState, mass: &MassProperties, force: Vec3, dt: Real) {
    state.linear_velocity += (dt * mass.inv_mass()) * force;
    state.position += dt * state.linear_velocity;
}

/// One step of the textbook symplectic Euler method with the exact rotation update.
#[inline]
pub(super) fn symplectic_euler(
    state: &mut BodyState,
    mass: &MassProperties,
    wrench: &Wrench,
    dt: Real,
) {
    linear_kick_drift(state, mass, wrench.force, dt);
    explicit_gyroscopic_kick(state, mass, wrench.torque, dt);
    clear_locked_axes(state, mass);
    state.rotation = rotate_exact(state.rotation, state.angular_velocity, dt);
}

/// One step of symplectic Euler with the linearized rotation update `q += ½Δt (ω,0) q`.
#[inline]
pub(super) fn symplectic_euler_linear(
    state: &mut BodyState,
    mass: &MassProperties,
    wrench: &Wrench,
    dt: Real,
) {
    linear_kick_drift(state, mass, wrench.force, dt);
    explicit_gyroscopic_kick(state, mass, wrench.torque, dt);
    clear_locked_axes(state, mass);
    state.rotation = rotate_linearized(state.rotation, state.angular_velocity, dt);
}
