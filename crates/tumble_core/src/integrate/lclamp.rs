//! Explicit gyroscopic step with the angular momentum rescaled to its expected length: the
//! fix rapier (its default), avian and Jolt apply to the textbook step.
//!
//! ```text
//! ω' = ω + Δt I⁻¹(τ − ω × Iω)           (explicit, in the principal frame)
//! ω' ← ω' · |I ω + Δt τ| / |I ω'|         (|L| rescaled)
//! v' = v + Δt F/m;  x' = x + Δt v';  q' = exp(½Δt ω') q
//! ```
//!
//! It never blows up, but the direction error of the explicit step is kept: a stable spin about
//! the largest axis drifts toward the middle axis and gains energy. First order; kept as the
//! reference point of what other engines do.

use super::frame::{clear_locked_axes, principal_orientation, rotate, rotate_inv};
use crate::mass::MassProperties;
use crate::math::Real;
use crate::rotation::rotate_exact;
use crate::state::{BodyState, Wrench};

/// One step of the `lclamp` method.
#[inline]
pub(super) fn lclamp(state: &mut BodyState, mass: &MassProperties, wrench: &Wrench, dt: Real) {
    state.linear_velocity += (dt * mass.inv_mass()) * wrench.force;
    state.position += dt * state.linear_velocity;
    let q = principal_orientation(state, mass);
    let inertia = mass.principal_inertia();
    let omega = rotate_inv(q, state.angular_velocity);
    let torque = rotate_inv(q, wrench.torque);
    let momentum = inertia * omega;
    let target = (momentum + dt * torque).length();
    let mut next = omega + dt * mass.inv_principal_inertia() * (torque - omega.cross(momentum));
    let length = (inertia * next).length();
    if length > 0.0 && target.is_finite() {
        next *= target / length;
    }
    state.angular_velocity = rotate(q, next);
    clear_locked_axes(state, mass);
    state.rotation = rotate_exact(state.rotation, state.angular_velocity, dt);
}
