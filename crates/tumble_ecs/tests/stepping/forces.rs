//! Forces at points produce the torque `(p − x) × F` about the centre of mass, and generators
//! deliver their load in the step they run, exactly once.

use glam::DMat3;
use tumble_core::math::{Quat, Real, Vec3, Widen, to_f64};
use tumble_ecs::prelude::*;

use super::util::{run, world_with};

#[test]
fn accumulator_force_at_point_torque() {
    let mut acc = ForceAccumulator::default();
    // F = ẑ at p = x̂ about the origin: τ = x̂ × ẑ = −ŷ.
    acc.add_force_at_point(Vec3::Z, Vec3::X, Vec3::ZERO);
    assert_eq!(acc.force, Vec3::Z);
    assert_eq!(acc.torque, -Vec3::Y);
    // Far from the origin the lever arm is formed first: no cancellation.
    let mut far = ForceAccumulator::default();
    let com = Vec3::new(1e5, -1e5, 1e5);
    far.add_force_at_point(
        Vec3::new(0.0, 0.0, 2.0),
        com + Vec3::new(0.25, 0.0, 0.0),
        com,
    );
    assert_eq!(far.torque, Vec3::new(0.0, -0.5, 0.0));
    let wrench = far.take();
    assert_eq!(wrench.torque, Vec3::new(0.0, -0.5, 0.0));
    assert_eq!(
        far,
        ForceAccumulator::default(),
        "take() consumes the accumulator"
    );
}

#[test]
fn constant_force_at_body_point_gives_right_linear_and_angular_kick() {
    let dt = 1e-3 as Real;
    let m = 2.0 as Real;
    let inertia = Vec3::new(0.5, 1.5, 2.0);
    let frame = Quat::from_rotation_x(0.4) * Quat::from_rotation_z(0.3);
    let com = Vec3::new(0.1, -0.2, 0.05);
    let q = Quat::from_rotation_y(0.8);
    let t0 = Vec3::new(3.0, 1.0, -2.0);
    let mass = MassProperties::new(Mass::new(m).unwrap(), inertia)
        .unwrap()
        .with_principal_frame(frame)
        .unwrap()
        .with_center_of_mass(com)
        .unwrap();
    let force = Vec3::new(0.5, 2.0, -1.0);
    let point = Vec3::new(0.6, 0.3, -0.4);
    let mut world = world_with(dt, Integrator::SymplecticEuler);
    let body = world
        .spawn((
            RigidBody,
            MassProps(mass),
            Pose {
                translation: t0,
                rotation: q,
            },
        ))
        .id();
    world.spawn(ConstantForce {
        body,
        force,
        local_point: Some(point),
    });
    run(&mut world, 1);

    // Expected, in f64: τ = R (p − c) × F; Δω = Δt I_w⁻¹ τ with I_w = (RP) diag(I) (RP)ᵀ.
    let r = q.widen();
    let tau = (r * (point - com).widen()).cross(force.widen());
    let rp = DMat3::from_quat(r * frame.widen());
    let i_world = rp * DMat3::from_diagonal(inertia.widen()) * rp.transpose();
    let domega = i_world.inverse() * tau * to_f64(dt);
    let v = world.get::<Velocity>(body).unwrap();
    let dv = force.widen() * to_f64(dt / m);
    assert!((v.linear.widen() - dv).length() < 1e-6 * dv.length());
    assert!(
        (v.angular.widen() - domega).length() < 1e-5 * domega.length(),
        "Δω = {} expected {domega}",
        v.angular
    );
    // The centre of mass moved by Δt·Δv (kick then drift); the origin follows it rigidly.
    let t = world.get::<Pose>(body).unwrap();
    let com_world = t
        .center_of_mass(world.get::<MassProps>(body).unwrap())
        .widen();
    let com_expected = (t0 + q * com).widen() + dv * to_f64(dt);
    assert!((com_world - com_expected).length() < 1e-5);
}

#[test]
fn game_force_is_applied_exactly_once() {
    let dt = 0.1;
    let mut world = world_with(dt, Integrator::SymplecticEuler);
    let body = world.spawn((RigidBody, ForceAccumulator::default())).id();
    let mut physics = PhysicsRunner::new(&mut world);
    world
        .get_mut::<ForceAccumulator>(body)
        .unwrap()
        .add_force(Vec3::X * 10.0);
    world
        .get_mut::<ForceAccumulator>(body)
        .unwrap()
        .add_torque(Vec3::Y * 2.0);
    physics.step(&mut world);
    physics.step(&mut world);
    let v = world.get::<Velocity>(body).unwrap();
    assert_eq!(v.linear, Vec3::X * (10.0 * dt)); // one kick of F Δt / m, not two
    assert!((v.angular - Vec3::Y * (2.0 * dt)).length() < 4.0 * Real::EPSILON); // unit inertia
    assert_eq!(
        *world.get::<ForceAccumulator>(body).unwrap(),
        ForceAccumulator::default()
    );
}

#[test]
fn constant_torque_generator_spins_up_linearly() {
    let dt = 0.01;
    let mut world = world_with(dt, Integrator::SymplecticEuler);
    let body = world
        .spawn((RigidBody, super::util::mass_props(1.0, [2.0, 2.0, 2.0])))
        .id();
    world.spawn(ConstantTorque {
        body,
        torque: Vec3::Z * 4.0,
    });
    let mut physics = PhysicsRunner::new(&mut world);
    assert!(physics.plan().contains(PhysicsSystem::ConstantTorques));
    assert!(
        world.get::<ForceAccumulator>(body).is_some(),
        "generator inserts the accumulator"
    );
    super::util::run_steps(&mut world, &mut physics, 100);
    let w = world.get::<Velocity>(body).unwrap().angular;
    assert!((w.z - 2.0).abs() < 1e-5, "ω = τ t / I = 4·1/2 = 2, got {w}");
}

#[test]
fn locked_axis_never_spins_and_never_goes_nan() {
    let dt = 0.01;
    let mut world = world_with(dt, Integrator::SymplecticEuler);
    let mass = MassProperties::new(Mass::new(1.0).unwrap(), Vec3::new(0.0, 1.0, 1.0)).unwrap();
    assert_eq!(mass.inv_principal_inertia(), Vec3::new(0.0, 1.0, 1.0));
    let body = world.spawn((RigidBody, MassProps(mass))).id();
    world.spawn(ConstantTorque {
        body,
        torque: Vec3::new(5.0, 0.0, 0.0),
    });
    run(&mut world, 50);
    let w = world.get::<Velocity>(body).unwrap().angular;
    assert_eq!(w, Vec3::ZERO, "a torque about the locked axis does nothing");
    let q = world.get::<Pose>(body).unwrap().rotation;
    assert_eq!(q, Quat::IDENTITY);
}
