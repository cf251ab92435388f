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
//! `I = (R P) diag(I_b) (R P)ᵀ` is applied in the principal frame, never inverted; the rotation
//! runs on the kick–drift kernel (`kick_drift_kernel`), one body or eight at a time. Cost: about
//! 3 quaternion–vector rotations, one cross product and one sine and cosine per body-step.
//! Under constant force the position carries the known bias `½ F/m Δt t`:
//! `x_n = x₀ + v₀ nΔt + F/m Δt² n(n+1)/2`.

use super::lanes::PrincipalBody;
use super::lanes::{Vec3L, cross};
use crate::simd::Lane;

/// The explicit gyroscopic kick of the body rates, `Δ = h r ⊙ (t − b × I b)` (the gyroscopic
/// term only for a body that is not spherical: for a spherical one it vanishes, and is skipped
/// so that it does not leave round-off).
#[inline(always)]
pub(super) fn explicit_kick<T: Lane>(body: &PrincipalBody<T>, h: T) -> Vec3L<T> {
    let (b, i, r, t) = (body.omega, body.inertia, body.r, body.torque);
    let zero = T::splat(h.cpu(), 0.0);
    let gyro = cross(b, [i[0] * b[0], i[1] * b[1], i[2] * b[2]]);
    let rate = [
        t[0] - T::select(body.gyroscopic, gyro[0], zero),
        t[1] - T::select(body.gyroscopic, gyro[1], zero),
        t[2] - T::select(body.gyroscopic, gyro[2], zero),
    ];
    [h * r[0] * rate[0], h * r[1] * rate[1], h * r[2] * rate[2]]
}
