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
//! up, but it damps spins about the middle axis strongly. First order. The rotation runs on the
//! kick–drift kernel (`kick_drift_kernel`); `J⁻¹` is applied by Cramer's rule,
//! `J⁻¹ = [b×c | c×a | a×b] / (a · b×c)` for the rows `a, b, c` of `J`.

use super::lanes::PrincipalBody;
use super::lanes::{Vec3L, cross};
use crate::simd::Lane;

/// `a · b`.
#[inline(always)]
fn dot<T: Lane>(a: Vec3L<T>, b: Vec3L<T>) -> T {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// The `implicit-gyroscopic` kick of the body rates: the torque kick `w = b + h r ⊙ t`, then
/// (for a body that is not spherical) one Newton step `w ← w − J(w)⁻¹ h (w × I w)`, skipped
/// where `J` is singular or not finite (a locked axis makes it singular: then no correction is
/// the safe choice); returns `w − b`.
#[inline(always)]
pub(super) fn implicit_kick<T: Lane>(body: &PrincipalBody<T>, h: T) -> Vec3L<T> {
    let (b, i, r, t) = (body.omega, body.inertia, body.r, body.torque);
    let w = [
        b[0] + h * r[0] * t[0],
        b[1] + h * r[1] * t[1],
        b[2] + h * r[2] * t[2],
    ];
    let m = [i[0] * w[0], i[1] * w[1], i[2] * w[2]];
    let g = cross(w, m);
    let residual = [h * g[0], h * g[1], h * g[2]];
    // Rows of J = diag(I) + h([w]× diag(I) − [m]×), with [v]× = [[0, −v₂, v₁], [v₂, 0, −v₀],
    // [−v₁, v₀, 0]].
    let rows = [
        [i[0], h * (m[2] - w[2] * i[1]), h * (w[1] * i[2] - m[1])],
        [h * (w[2] * i[0] - m[2]), i[1], h * (m[0] - w[0] * i[2])],
        [h * (m[1] - w[1] * i[0]), h * (w[0] * i[1] - m[0]), i[2]],
    ];
    let [bc, ca, ab] = [
        cross(rows[1], rows[2]),
        cross(rows[2], rows[0]),
        cross(rows[0], rows[1]),
    ];
    let det = dot(rows[0], bc);
    let step = [
        (bc[0] * residual[0] + ca[0] * residual[1] + ab[0] * residual[2]) / det,
        (bc[1] * residual[0] + ca[1] * residual[1] + ab[1] * residual[2]) / det,
        (bc[2] * residual[0] + ca[2] * residual[1] + ab[2] * residual[2]) / det,
    ];
    // Written out, not a closure: inside a `#[target_feature]` function a closure is compiled
    // without the feature.
    [
        corrected(body, det, w[0], step[0]) - b[0],
        corrected(body, det, w[1], step[1]) - b[1],
        corrected(body, det, w[2], step[2]) - b[2],
    ]
}

/// `w − step` where the Newton step applies (a body that is not spherical, `J` regular and
/// finite), else `w`.
#[inline(always)]
fn corrected<T: Lane>(body: &PrincipalBody<T>, det: T, w: T, step: T) -> T {
    let newton = T::select(det.beyond(f64::MIN_POSITIVE), w - step, w);
    let newton = T::select(det.beyond(f64::MAX), w, newton);
    T::select(body.gyroscopic, newton, w)
}
