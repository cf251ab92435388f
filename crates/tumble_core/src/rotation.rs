//! Quaternion helpers: the exponential map and its linearization (internal to the integrators),
//! and the angle between two orientations.

use crate::math::{Narrow, Quat, Real, Vec3, Widen, quat_mul, quat_normalize};
/// The unit quaternion of a rotation by the vector `θ` (axis `θ/|θ|`, angle `|θ|`):
/// `exp(½ θ) = (sin(|θ|/2) θ/|θ|, cos(|θ|/2))`, exact for every angle.
///
/// For `|θ|` below 1e-4 rad the Taylor form `(θ/2 (1 − |θ|²/24), 1 − |θ|²/8)` is used, which is
/// exact in f32 there and avoids dividing by a tiny angle.
#[inline]
pub(crate) fn exp_rotation(theta: Vec3) -> Quat {
    let angle2 = theta.length_squared();
    if angle2 < 1e-8 {
        let xyz = theta * (0.5 * (1.0 - angle2 / 24.0));
        Quat::from_xyzw(xyz.x, xyz.y, xyz.z, 1.0 - angle2 / 8.0)
    } else {
        let angle = angle2.sqrt();
        // tumble's own sine and cosine (IEEE arithmetic only, in f64, rounded once): the same
        // bits on every platform, where `f32::sin_cos` follows the platform's libm.
        let (s, c) = crate::simd::sin_cos((0.5 * angle).widen());
        let (s, c) = (s.narrow(), c.narrow());
        let xyz = theta * (s / angle);
        Quat::from_xyzw(xyz.x, xyz.y, xyz.z, c)
    }
}

/// Rotates `q` by the world angular velocity `ω` over `dt` with the exact exponential map:
/// `q ← exp(½ Δt ω) q`, then renormalizes to remove round-off.
#[inline]
pub(crate) fn rotate_exact(q: Quat, omega: Vec3, dt: Real) -> Quat {
    quat_normalize(quat_mul(exp_rotation(omega * dt), q))
}

/// Rotation angle between two orientations, in radians (0..π): the angle of `a* b`, computed as
/// `2 atan2(|v|, |w|)` in f64, which stays accurate for tiny angles where `2 acos |⟨a, b⟩|` loses
/// every digit (and returns 0 once round-off pushes the dot product past 1).
#[inline]
pub fn angle_between(a: Quat, b: Quat) -> f64 {
    let r = a.widen().normalize().conjugate() * b.widen().normalize();
    2.0 * glam::DVec3::new(r.x, r.y, r.z).length().atan2(r.w.abs())
}
