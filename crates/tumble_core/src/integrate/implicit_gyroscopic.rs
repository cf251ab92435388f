//! Implicit gyroscopic step, one Newton iteration (Catto, "Numerical Methods", GDC 2015).
//!
//! After the explicit torque kick `ω ← ω + Δt I⁻¹ τ`, the gyroscopic part is solved backward in
//! the principal frame:
//!
//! ```text
//! f(ω') = I(ω' − ω) + Δt ω' × Iω' = 0,   J = ∂f/∂ω' = I + Δt ([ω']× I − [Iω']×)
//! ω' ≈ ω − J(ω)⁻¹ f(ω) = ω − J(ω)⁻¹ Δt (ω × Iω)
//! ```
//!
//! then `q' = exp(½Δt ω') q`. Backward Euler dissipates: it never gains energy and never blows
//! up, but it damps spins about the middle axis strongly. First order.

use super::frame::{clear_locked_axes, principal_orientation, rotate, rotate_inv};
use crate::mass::MassProperties;
use crate::math::{Mat3, Real, Vec3};
use crate::rotation::rotate_exact;
use crate::state::{BodyState, Wrench};

/// Skew-symmetric cross-product matrix `[a]×`, so that `[a]× b = a × b`.
#[inline]
fn skew(a: Vec3) -> Mat3 {
    Mat3::from_cols(
        Vec3::new(0.0, a.z, -a.y),
        Vec3::new(-a.z, 0.0, a.x),
        Vec3::new(a.y, -a.x, 0.0),
    )
}

/// One Newton step of the implicit gyroscopic update, in the principal frame.
#[inline]
pub(super) fn implicit_gyroscopic_rate(omega: Vec3, inertia: Vec3, dt: Real) -> Vec3 {
    let momentum = inertia * omega;
    let residual = dt * omega.cross(momentum);
    let jacobian = Mat3::from_diagonal(inertia)
        + (skew(omega) * Mat3::from_diagonal(inertia) - skew(momentum)) * dt;
    let det = jacobian.determinant();
    // A locked axis can make J singular; then no correction is the safe choice.
    if !det.is_finite() || det.abs() <= Real::MIN_POSITIVE {
        return omega;
    }
    omega - jacobian.inverse() * residual
}

/// One step of the `implicit-gyroscopic` method.
#[inline]
pub(super) fn implicit_gyroscopic(
    state: &mut BodyState,
    mass: &MassProperties,
    wrench: &Wrench,
    dt: Real,
) {
    state.linear_velocity += (dt * mass.inv_mass()) * wrench.force;
    state.position += dt * state.linear_velocity;
    let q = principal_orientation(state, mass);
    let mut omega = rotate_inv(q, state.angular_velocity);
    omega += dt * mass.inv_principal_inertia() * rotate_inv(q, wrench.torque);
    if !mass.is_spherical() {
        omega = implicit_gyroscopic_rate(omega, mass.principal_inertia(), dt);
    }
    state.angular_velocity = rotate(q, omega);
    clear_locked_axes(state, mass);
    state.rotation = rotate_exact(state.rotation, state.angular_velocity, dt);
}
