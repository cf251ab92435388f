//! Classic Runge–Kutta 4 on the free rotation, inside the drift–kick–drift step.
//!
//! With `L` constant in the world during the free flow, the only ODE left is
//! `Q̇ = ½ (ω, 0) ⊗ Q` with `ω = Q I_b⁻¹ Qᵀ L`; RK4 (in f64) advances the quaternion as a
//! 4-vector, normalizes it, and the body momentum is re-read as `m = Qᵀ L`. Fourth order for
//! torque-free rotation; `|L|` is exact by construction (it is not integrated), the energy drifts
//! slowly because `Q` leaves the energy ellipsoid. Cost: 4 evaluations of `ω(Q)` (two frame
//! rotations each) per drift. Written once on lanes: one body runs it in `f64`, a batch in SIMD
//! lanes (see `symmetric_kernel`).

use super::lanes::{Quat4, Vec3L, conjugate, mul, normalize, rotate};
use crate::simd::Lane;

/// `Q̇ = ½ (ω(Q), 0) ⊗ Q` with `ω(Q) = Q (r ⊙ Qᵀ L)`.
#[inline(always)]
fn quat_rate<T: Lane>(q: Quat4<T>, momentum: Vec3L<T>, r: Vec3L<T>) -> Quat4<T> {
    let b = rotate(conjugate(q), momentum);
    let w = rotate(q, [r[0] * b[0], r[1] * b[1], r[2] * b[2]]);
    let half = T::splat(q[0].cpu(), 0.5);
    let [x, y, z, s] = mul([w[0], w[1], w[2], T::splat(q[0].cpu(), 0.0)], q);
    [x * half, y * half, z * half, s * half]
}

/// `q + k t`, component by component.
#[inline(always)]
fn advanced<T: Lane>(q: Quat4<T>, k: Quat4<T>, t: T) -> Quat4<T> {
    [
        q[0] + k[0] * t,
        q[1] + k[1] * t,
        q[2] + k[2] * t,
        q[3] + k[3] * t,
    ]
}

/// One RK4 step over `h` of the principal orientation `q` with body momentum `m` at constant
/// world momentum `L = q m q*`; `m` is re-read from the new orientation.
#[inline(always)]
pub(super) fn rk4_flow<T: Lane>(q: &mut Quat4<T>, m: &mut Vec3L<T>, r: Vec3L<T>, h: T) {
    let cpu = h.cpu();
    let momentum = rotate(*q, *m);
    let half = T::splat(cpu, 0.5) * h;
    let k1 = quat_rate(*q, momentum, r);
    let k2 = quat_rate(advanced(*q, k1, half), momentum, r);
    let k3 = quat_rate(advanced(*q, k2, half), momentum, r);
    let k4 = quat_rate(advanced(*q, k3, h), momentum, r);
    let two = T::splat(cpu, 2.0);
    let sum = [
        k1[0] + k2[0] * two + k3[0] * two + k4[0],
        k1[1] + k2[1] * two + k3[1] * two + k4[1],
        k1[2] + k2[2] * two + k3[2] * two + k4[2],
        k1[3] + k2[3] * two + k3[3] * two + k4[3],
    ];
    let next = normalize(advanced(*q, sum, h / T::splat(cpu, 6.0)));
    *q = next;
    *m = rotate(conjugate(next), momentum);
}
