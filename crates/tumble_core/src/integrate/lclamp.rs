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
//! reference point of what other engines do. The rotation runs on the kick–drift kernel
//! (`kick_drift_kernel`).

use super::lanes::PrincipalBody;
use super::lanes::{Vec3L, cross};
use crate::simd::Lane;

/// The `lclamp` kick of the body rates: the explicit kick `n = b + h r ⊙ (t − b × I b)`,
/// rescaled so that `|I n| = |I b + h t|` (unless `|I n| = 0` or the target is not finite);
/// returns `n − b`.
#[inline(always)]
pub(super) fn clamped_kick<T: Lane>(body: &PrincipalBody<T>, h: T) -> Vec3L<T> {
    let (b, i, r, t) = (body.omega, body.inertia, body.r, body.torque);
    let cpu = h.cpu();
    let (zero, one) = (T::splat(cpu, 0.0), T::splat(cpu, 1.0));
    let momentum = [i[0] * b[0], i[1] * b[1], i[2] * b[2]];
    let kicked = [
        momentum[0] + h * t[0],
        momentum[1] + h * t[1],
        momentum[2] + h * t[2],
    ];
    let target = (kicked[0] * kicked[0] + kicked[1] * kicked[1] + kicked[2] * kicked[2]).sqrt();
    let gyro = cross(b, momentum);
    let next = [
        b[0] + h * r[0] * (t[0] - gyro[0]),
        b[1] + h * r[1] * (t[1] - gyro[1]),
        b[2] + h * r[2] * (t[2] - gyro[2]),
    ];
    let l = [i[0] * next[0], i[1] * next[1], i[2] * next[2]];
    let length = (l[0] * l[0] + l[1] * l[1] + l[2] * l[2]).sqrt();
    let scale = T::select(length.gt(zero), target / length, one);
    let scale = T::select(target.beyond(f64::MAX), one, scale);
    [
        next[0] * scale - b[0],
        next[1] * scale - b[1],
        next[2] * scale - b[2],
    ]
}
