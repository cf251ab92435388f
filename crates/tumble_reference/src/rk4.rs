//! High-accuracy numerical references in f64, for checking the f32 integrators where a closed
//! form is not at hand: classic RK4 with a tiny step. [`step`] is the one RK4 step every
//! reference of the project takes (this free body, the closed-form top's own tests, the
//! report's pendulum).

use glam::{DQuat, DVec3};

/// Step of the reference integrations (s). RK4's error `≈ h⁴ |ω|⁵ T` is below 1e-12 rad for
/// `|ω| ≤ 10 rad/s` over 100 s, far below any f32 integrator's.
pub const REFERENCE_STEP: f64 = 1e-4;

/// One classic RK4 step of span `h` for an attitude `q` and a vector `l` (a momentum) whose
/// rates are `rate(q, l) = (q̇, l̇)`: the new attitude (normalized) and the increment of `l`
/// (returned rather than added, so that a caller may sum it compensated).
pub fn step(
    q: DQuat,
    l: DVec3,
    h: f64,
    rate: impl Fn(DQuat, DVec3) -> (DQuat, DVec3),
) -> (DQuat, DVec3) {
    let (a1, b1) = rate(q, l);
    let (a2, b2) = rate(q + a1 * (h / 2.0), l + b1 * (h / 2.0));
    let (a3, b3) = rate(q + a2 * (h / 2.0), l + b2 * (h / 2.0));
    let (a4, b4) = rate(q + a3 * h, l + b3 * h);
    (
        (q + (a1 + a2 * 2.0 + a3 * 2.0 + a4) * (h / 6.0)).normalize(),
        (b1 + b2 * 2.0 + b3 * 2.0 + b4) * (h / 6.0),
    )
}

/// Torque-free rigid body in the principal frame: orientation `q` (principal → world, starting
/// at identity) and body rates `ω_b` at each of the increasing `times` (s), from classic RK4 on
/// `q̇ = ½ q ⊗ (0, ω_b)`, `ṁ = m × ω_b`, `ω_b = I_b⁻¹ m` with step [`REFERENCE_STEP`].
pub fn free_body(inertia: DVec3, body_omega0: DVec3, times: &[f64]) -> Vec<(DQuat, DVec3)> {
    let rate = |q: DQuat, m: DVec3| {
        let w = m / inertia;
        (q * DQuat::from_xyzw(w.x, w.y, w.z, 0.0) * 0.5, m.cross(w))
    };
    let (mut q, mut m, mut t) = (DQuat::IDENTITY, inertia * body_omega0, 0.0);
    let mut out = Vec::with_capacity(times.len());
    for &target in times {
        let steps = ((target - t) / REFERENCE_STEP).ceil().max(0.0) as usize;
        if steps > 0 {
            let h = (target - t) / steps as f64;
            for _ in 0..steps {
                let (next, dm) = step(q, m, h, rate);
                q = next;
                m += dm;
            }
            t = target;
        }
        out.push((q, m / inertia));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn conserves_energy_and_world_momentum_and_spins_exactly_about_an_axis() {
        let inertia = DVec3::new(1.0, 2.0, 3.0);
        let w0 = DVec3::new(1.0, 5.0, 1.0);
        let l0 = inertia * w0;
        let e0 = 0.5 * w0.dot(l0);
        for (q, w) in free_body(inertia, w0, &[1.0, 5.0, 20.0]) {
            let l = q * (inertia * w);
            assert!((l - l0).length() < 1e-10 * l0.length(), "L {l} vs {l0}");
            assert!((0.5 * w.dot(inertia * w) / e0 - 1.0).abs() < 1e-10);
        }
        // A spin about a principal axis is a rotation at constant rate.
        let spin = DVec3::new(0.0, 0.0, 2.0);
        let (q, w) = free_body(inertia, spin, &[3.0])[0];
        assert!((w - spin).length() < 1e-12);
        assert!(q.angle_between(DQuat::from_rotation_z(6.0)) < 1e-10);
    }
}
