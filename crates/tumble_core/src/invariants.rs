//! Invariants of free motion: kinetic energy, linear momentum, world angular momentum.

use crate::mass::MassProperties;
use crate::math::{Real, Vec3};
use crate::state::BodyState;

/// Kinetic energy `T = ½ m |v|² + ½ ωᵀ I ω` (J), with `I` the world inertia tensor.
#[inline]
pub fn kinetic_energy(state: &BodyState, mass: &MassProperties) -> Real {
    let linear = 0.5 * mass.mass() * state.linear_velocity.length_squared();
    linear + rotational_energy(state, mass)
}

/// Rotational kinetic energy `½ ωᵀ I ω` (J).
#[inline]
pub fn rotational_energy(state: &BodyState, mass: &MassProperties) -> Real {
    0.5 * state
        .angular_velocity
        .dot(mass.world_inertia_mul(state.rotation, state.angular_velocity))
}

/// Linear momentum `p = m v` (kg·m/s).
#[inline]
pub fn linear_momentum(state: &BodyState, mass: &MassProperties) -> Vec3 {
    mass.mass() * state.linear_velocity
}

/// Angular momentum about the centre of mass, world frame: `L = I ω` (kg·m²/s).
#[inline]
pub fn angular_momentum(state: &BodyState, mass: &MassProperties) -> Vec3 {
    mass.world_inertia_mul(state.rotation, state.angular_velocity)
}
