//! Quaternion and vector algebra on lanes (`f64` for one body, a SIMD type for a run of
//! bodies), shared by the batched kernels: plain lane-wise `+ − × ÷`, so a body gets the same
//! bits alone or in any lane.

use crate::simd::Lane;

/// A quaternion `(x, y, z, w)` in lanes.
pub(super) type Quat4<T> = [T; 4];
/// A vector in lanes.
pub(super) type Vec3L<T> = [T; 3];

/// Hamilton product `a b`.
#[inline(always)]
pub(super) fn mul<T: Lane>(a: Quat4<T>, b: Quat4<T>) -> Quat4<T> {
    let [ax, ay, az, aw] = a;
    let [bx, by, bz, bw] = b;
    [
        aw * bx + ax * bw + (ay * bz - az * by),
        aw * by + ay * bw + (az * bx - ax * bz),
        aw * bz + az * bw + (ax * by - ay * bx),
        aw * bw - (ax * bx + ay * by + az * bz),
    ]
}

/// The rotation `v ↦ q v q* / |q|²` (a rotation even for a slightly non-unit `q`), with the
/// parts that depend on `q` alone computed once for any number of vectors.
pub(super) struct Rotor<T> {
    q: Quat4<T>,
    /// `1/|q|²`.
    inv: T,
    /// `w² − |b|²`.
    ww: T,
    /// `2w`.
    w2: T,
}

impl<T: Lane> Rotor<T> {
    #[inline(always)]
    pub(super) fn new(q: Quat4<T>) -> Self {
        let [x, y, z, w] = q;
        let cpu = w.cpu();
        let b2 = x * x + y * y + z * z;
        Self {
            q,
            inv: T::splat(cpu, 1.0) / (w * w + b2),
            ww: w * w - b2,
            w2: T::splat(cpu, 2.0) * w,
        }
    }

    /// `q v q* / |q|²`.
    #[inline(always)]
    pub(super) fn apply(&self, v: Vec3L<T>) -> Vec3L<T> {
        let [x, y, z, _] = self.q;
        let (inv, ww, w2) = (self.inv, self.ww, self.w2);
        let bv2 = T::splat(x.cpu(), 2.0) * (x * v[0] + y * v[1] + z * v[2]);
        let cross = [
            y * v[2] - z * v[1],
            z * v[0] - x * v[2],
            x * v[1] - y * v[0],
        ];
        [
            (ww * v[0] + bv2 * x + w2 * cross[0]) * inv,
            (ww * v[1] + bv2 * y + w2 * cross[1]) * inv,
            (ww * v[2] + bv2 * z + w2 * cross[2]) * inv,
        ]
    }
}

/// `q v q* / |q|²`: a rotation even for a slightly non-unit `q`.
#[inline(always)]
pub(super) fn rotate<T: Lane>(q: Quat4<T>, v: Vec3L<T>) -> Vec3L<T> {
    Rotor::new(q).apply(v)
}

#[inline(always)]
pub(super) fn conjugate<T: Lane>(q: Quat4<T>) -> Quat4<T> {
    [-q[0], -q[1], -q[2], q[3]]
}

/// `a × b`.
#[inline(always)]
pub(super) fn cross<T: Lane>(a: Vec3L<T>, b: Vec3L<T>) -> Vec3L<T> {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// `normalize(q)`.
#[inline(always)]
pub(super) fn normalize<T: Lane>(q: Quat4<T>) -> Quat4<T> {
    let [x, y, z, w] = q;
    let inv = T::splat(w.cpu(), 1.0) / (x * x + y * y + z * z + w * w).sqrt();
    [x * inv, y * inv, z * inv, w * inv]
}

/// A body as a kick–drift method's kick sees it, in its principal frame.
pub(super) struct PrincipalBody<T: Lane> {
    /// Body rates `b = Qᵀ ω`.
    pub omega: Vec3L<T>,
    /// Body torque `t = Qᵀ τ`.
    pub torque: Vec3L<T>,
    /// Principal moments `I` (0 on a locked axis).
    pub inertia: Vec3L<T>,
    /// Reciprocal moments `r` (0 on a locked axis).
    pub r: Vec3L<T>,
    /// Set in the lanes whose body is not spherical (a spherical body has no gyroscopic term,
    /// and its methods skip it exactly).
    pub gyroscopic: T::Mask,
}
