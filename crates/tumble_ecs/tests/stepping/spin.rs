//! A spin about a principal axis stays a spin about that axis, at constant rate, and the pose
//! follows the exact rotation `q(t) = exp(½ t ω) q₀`.

use glam::{DQuat, DVec3};
use tumble_core::math::{Quat, Real, Vec3, Widen, to_f64};
use tumble_ecs::prelude::*;

use super::util::{run, world_with};

/// Spins a body (rotated, with a rotated principal frame) about principal axis `axis` and checks
/// rate and pose after `steps` steps.
fn check_principal_spin(integrator: Integrator, axis: Vec3, rate: Real, dt: Real, steps: usize) {
    let principal_frame = Quat::from_euler(glam::EulerRot::XYZ, 0.3, -0.7, 1.1);
    let q0 = Quat::from_euler(glam::EulerRot::ZYX, -0.4, 0.2, 0.9);
    let mass = MassProperties::new(Mass::new(3.0).unwrap(), Vec3::new(1.0, 2.0, 3.0))
        .unwrap()
        .with_principal_frame(principal_frame)
        .unwrap();
    let omega = (q0 * principal_frame * axis) * rate; // world frame
    let mut world = world_with(dt, integrator);
    let id = world
        .spawn((
            RigidBody,
            MassProps(mass),
            Pose::from_rotation(q0),
            Velocity::angular(omega),
        ))
        .id();
    run(&mut world, steps);
    let w = world.get::<Velocity>(id).unwrap().angular;
    let t = to_f64(dt) * steps as f64;
    // Round-off of one step is a few f32 ulps of |ω|; the explicit gyroscopic term amplifies
    // a perturbation at most by (1 + (c Δt)²)^(n/2) with c ≤ |ω|·max ratio, ≤ 1.05 here.
    let tol = 16.0 * Real::EPSILON * steps as Real * rate;
    assert!(
        (w - omega).length() < tol,
        "{integrator}: ω drifted by {} (tol {tol})",
        (w - omega).length()
    );
    let q = world
        .get::<tumble_ecs::components::Pose>(id)
        .unwrap()
        .rotation;
    let omega64 = omega.widen();
    let q_exact = DQuat::from_scaled_axis(omega64 * t) * q0.widen();
    // 2 atan2(|v|, |w|) of q* q_exact: exact for tiny angles, where 2 acos |⟨q, q_exact⟩| has an
    // error floor of √(2ε₆₄) ≈ 2e-8 rad that would hide the f64 engine's own accuracy.
    let r = q.widen().normalize().conjugate() * q_exact;
    let angle = 2.0 * DVec3::new(r.x, r.y, r.z).length().atan2(r.w.abs());
    // Each exact-exponential step is accurate to a few ulps; allow 16 ε per step.
    let angle_tol = 16.0 * to_f64(Real::EPSILON) * steps as f64 * (1.0 + omega64.length());
    assert!(
        angle < angle_tol,
        "{integrator}: pose off by {angle} rad (tol {angle_tol})"
    );
}

#[test]
fn spin_about_each_principal_axis_stays_put() {
    for axis in [Vec3::X, Vec3::Y, Vec3::Z] {
        check_principal_spin(Integrator::SymplecticEuler, axis, 2.0, 1.0 / 120.0, 240);
    }
}

#[test]
fn identity_frame_spin_is_bit_exact_in_rate() {
    // With identity frames ω × Iω is exactly zero in floating point: ω never changes.
    let mut world = world_with(1.0 / 60.0, Integrator::SymplecticEuler);
    let omega = Vec3::new(0.0, 7.5, 0.0);
    let id = world
        .spawn((
            RigidBody,
            super::util::mass_props(1.0, [1.0, 2.0, 3.0]),
            Velocity::angular(omega),
        ))
        .id();
    run(&mut world, 1000);
    assert_eq!(world.get::<Velocity>(id).unwrap().angular, omega);
    let q = world.get::<Pose>(id).unwrap().rotation;
    assert!((q.length() - 1.0).abs() < 1e-6);
}

#[test]
fn linearized_rotation_update_has_first_order_error() {
    // q += ½Δt ω q then normalize rotates by 2 atan(|ω|Δt/2) instead of |ω|Δt per step: the
    // angle per step is short by about (|ω|Δt)³/12, so the error of a spin grows like Δt².
    let rate = 5.0 as Real;
    let err = |dt: Real| {
        let steps = (1.0 / dt).round() as usize;
        let mut world = world_with(dt, Integrator::SymplecticEulerLinear);
        let id = world
            .spawn((RigidBody, Velocity::angular(Vec3::Z * rate)))
            .id();
        run(&mut world, steps);
        let q = world.get::<Pose>(id).unwrap().rotation;
        let exact = to_f64(rate); // angle after 1 s
        let angle = 2.0 * to_f64(q.z).atan2(to_f64(q.w));
        let per_step = 2.0 * (to_f64(rate * dt) / 2.0).atan();
        let predicted = exact - per_step * steps as f64;
        ((angle - exact).abs(), predicted.abs())
    };
    let (e1, p1) = err(1.0 / 30.0);
    let (e2, p2) = err(1.0 / 60.0);
    assert!((e1 / p1 - 1.0).abs() < 0.05, "error {e1} vs predicted {p1}");
    assert!((e2 / p2 - 1.0).abs() < 0.1, "error {e2} vs predicted {p2}");
    let ratio = e1 / e2;
    assert!(
        (ratio - 4.0).abs() < 0.4,
        "halving Δt should quarter the angle error: {ratio}"
    );
}
