//! Game loads through `ApplyForces`: forces and torques in world or body coordinates, at points
//! (the centre of mass taken from the body), and impulses that change momentum by exactly `J`
//! once, whatever the stages of a step — each against its closed form.

use std::num::NonZeroU32;

use bevy_ecs::prelude::*;
use tumble_core::math::{Quat, Real, Vec3, Widen, quat_rotate, to_f64};
use tumble_core::{Mass, MassProperties};
use tumble_ecs::prelude::*;

fn world(integrator: Integrator) -> World {
    let mut world = World::new();
    world.insert_resource(PhysicsSettings::new(0.01, integrator).unwrap());
    world
}

/// A 2 kg body with moments (1, 2, 3), its centre of mass 0.5 m along its local x, turned a
/// quarter turn about z (so local x is world y), at (1, 2, 3).
fn offset_body(world: &mut World) -> Entity {
    let mass = MassProperties::new(Mass::new(2.0).unwrap(), Vec3::new(1.0, 2.0, 3.0))
        .unwrap()
        .with_center_of_mass(Vec3::new(0.5, 0.0, 0.0))
        .unwrap();
    let rotation = Quat::from_rotation_z(std::f64::consts::FRAC_PI_2 as Real);
    world
        .spawn((
            RigidBody,
            MassProps(mass),
            Pose::new(Vec3::new(1.0, 2.0, 3.0), rotation),
        ))
        .id()
}

fn close(a: Vec3, b: Vec3) -> bool {
    (a - b).length() <= 8.0 * Real::EPSILON * (1.0 + b.length())
}

#[test]
fn forces_at_points_take_the_centre_of_mass_from_the_body() {
    let mut world = world(Integrator::SymplecticEuler);
    let body = offset_body(&mut world);
    let pose = *world.get::<Pose>(body).unwrap();
    let com = pose.translation + quat_rotate(pose.rotation, Vec3::new(0.5, 0.0, 0.0));
    assert!(close(com, Vec3::new(1.0, 2.5, 3.0)));
    let f = Vec3::new(0.0, 0.0, 4.0);
    let p = Vec3::new(2.0, 2.5, 3.0);
    world.entity_mut(body).apply_force_at_point(f, p);
    let acc = *world
        .get::<ForceAccumulator>(body)
        .expect("inserted on first use");
    assert_eq!(acc.force, f);
    assert!(close(acc.torque, (p - com).cross(f)), "{}", acc.torque);

    // The same load through body coordinates: local x is world y, local z is world z.
    world.entity_mut(body).insert(ForceAccumulator::default());
    let local_point = Vec3::new(0.5, -1.0, 0.0); // world (1, 2.5, 3) + (1, 0, 0) = p
    world
        .entity_mut(body)
        .apply_local_force_at_local_point(Vec3::new(0.0, 0.0, 4.0), local_point);
    let local = *world.get::<ForceAccumulator>(body).unwrap();
    assert!(
        close(local.force, f) && close(local.torque, acc.torque),
        "{local:?}"
    );

    world.entity_mut(body).insert(ForceAccumulator::default());
    let mut e = world.entity_mut(body);
    e.apply_local_force(Vec3::X);
    e.apply_local_torque(Vec3::X * 2.0);
    e.apply_torque(Vec3::Z);
    e.apply_force(Vec3::Z);
    e.apply_force_at_local_point(Vec3::Z, Vec3::new(0.5, 0.0, 0.0)); // at the centre of mass
    let loads = *world.get::<ForceAccumulator>(body).unwrap();
    assert!(
        close(loads.force, Vec3::new(0.0, 1.0, 2.0)),
        "{}",
        loads.force
    );
    assert!(
        close(loads.torque, Vec3::new(0.0, 2.0, 1.0)),
        "{}",
        loads.torque
    );
}

/// An impulse changes the momentum by exactly `J` once, then the body coasts: the same under
/// symplectic Euler and under `yoshida4` with three substeps (nine stages per step).
#[test]
fn impulses_change_momentum_by_exactly_j_once() {
    for (integrator, substeps) in [(Integrator::SymplecticEuler, 1), (Integrator::Yoshida4, 3)] {
        let mut world = world(integrator);
        world
            .resource_mut::<PhysicsSettings>()
            .set_substeps(NonZeroU32::new(substeps).unwrap())
            .unwrap();
        let body = offset_body(&mut world);
        world.spawn((RigidBody, ForceAccumulator::default())); // a second body, with forces
        let j = Vec3::new(3.0, -1.0, 0.5);
        let l = Vec3::new(0.2, 0.1, -0.3);
        let mut e = world.entity_mut(body);
        e.apply_linear_impulse(j);
        e.apply_angular_impulse(l);
        let pose = *world.get::<Pose>(body).unwrap();
        let mass = *world.get::<MassProps>(body).unwrap();
        let v = *world.get::<Velocity>(body).unwrap();
        assert!(close(v.linear * 2.0, j), "{integrator}: p = m v = J");
        let angular_momentum = mass.world_inertia_mul(pose.rotation, v.angular);
        assert!(close(angular_momentum, l), "{integrator}: L = I ω = J");
        let mut physics = PhysicsRunner::new(&mut world);
        for _ in 0..50 {
            physics.step(&mut world);
            world.clear_trackers();
        }
        let v_after = world.get::<Velocity>(body).unwrap().linear;
        assert_eq!(v_after, v.linear, "{integrator}: no impulse repeats");
        let x = world.get::<Pose>(body).unwrap().center_of_mass(&mass);
        let start = pose.center_of_mass(&mass);
        let expected = start.widen() + j.widen() / 2.0 * 0.5;
        // Rounding only: one rounding of each coordinate per stage (50 steps of
        // `runs_per_step` stages), half an ulp each at worst.
        let stages = 50.0 * physics.plan().runs_per_step() as f64;
        let tol = stages * to_f64(Real::EPSILON) * (1.0 + expected.length());
        assert!(
            (x.widen() - expected).length() < tol,
            "{integrator}: {x} vs {expected} (tolerance {tol:e})"
        );
    }
}

/// An impulse at a point: `v += J/m`, `ω += I⁻¹ ((p − x) × J)`.
#[test]
fn an_impulse_at_a_point_also_spins() {
    let mut world = world(Integrator::Splitting);
    let body = offset_body(&mut world);
    let pose = *world.get::<Pose>(body).unwrap();
    let mass = *world.get::<MassProps>(body).unwrap();
    let com = pose.center_of_mass(&mass);
    let j = Vec3::new(0.0, 0.0, 1.0);
    let p = com + Vec3::X;
    world.entity_mut(body).apply_impulse_at_point(j, p);
    let v = *world.get::<Velocity>(body).unwrap();
    assert!(close(v.linear, j / 2.0));
    let l = mass.world_inertia_mul(pose.rotation, v.angular);
    assert!(close(l, Vec3::X.cross(j)), "{l}");
}

/// A system with `Query<BodyForces>` in the runner's force systems pushes along the ship's own
/// axis in every stage; a torque-free ship moves as `½ a t²` along it.
#[test]
fn a_thruster_system_pushes_along_the_body_axis() {
    fn thrust(mut ships: Query<BodyForces>) {
        for mut ship in &mut ships {
            ship.apply_local_force(Vec3::Z * 2.0);
        }
    }
    let mut world = world(Integrator::Splitting);
    let turned = Quat::from_rotation_y(std::f64::consts::FRAC_PI_2 as Real); // local z → world x
    let ship = world
        .spawn((
            RigidBody,
            Pose::from_rotation(turned),
            ForceAccumulator::default(),
        ))
        .id();
    let mut forces = ForceSystems::default();
    forces.add(thrust);
    world.insert_resource(forces);
    let mut physics = PhysicsRunner::new(&mut world);
    for _ in 0..100 {
        physics.step(&mut world);
        world.clear_trackers();
    }
    let x = world.get::<Pose>(ship).unwrap().translation;
    // Drift–kick–drift is exact for a constant force: x = ½ (2 N / 1 kg) (1 s)² = 1 m.
    assert!(
        (to_f64(x.x) - 1.0).abs() < 1e-5 && x.y.abs() < 1e-5 && x.z.abs() < 1e-5,
        "{x}"
    );
}

#[test]
fn a_load_on_an_entity_that_is_not_a_body_is_dropped() {
    let mut world = world(Integrator::Splitting);
    let not_a_body = world.spawn(Velocity::ZERO).id();
    world.entity_mut(not_a_body).apply_force(Vec3::X);
    world.entity_mut(not_a_body).apply_linear_impulse(Vec3::X);
    assert!(world.get::<ForceAccumulator>(not_a_body).is_none());
    assert_eq!(*world.get::<Velocity>(not_a_body).unwrap(), Velocity::ZERO);
}

/// A body-frame force turns with the body: on a sphere spinning at ω about z, a force `f`
/// along the body's x gives `v(t) = f/(m ω) (sin ωt, 1 − cos ωt, 0)` (a world-frame force would
/// give `f t / m` along x). Second order under `splitting`: `(ωΔt)²` = 1e-4 of the speed at
/// most over the run, far above f32 rounding.
#[test]
fn a_constant_local_force_turns_with_the_body() {
    let mut world = world(Integrator::Splitting);
    let (m, omega, f) = (2.0, 1.0, 3.0);
    let sphere = MassProperties::new(Mass::new(m).unwrap(), Vec3::ONE).unwrap();
    let body = world
        .spawn((
            RigidBody,
            MassProps(sphere),
            Velocity::angular(Vec3::Z * omega),
        ))
        .id();
    let thruster = world
        .spawn(ConstantLocalForce {
            body,
            force: Vec3::X * f,
            local_point: None,
        })
        .id();
    let mut physics = PhysicsRunner::new(&mut world);
    assert!(physics.plan().contains(PhysicsSystem::ConstantForces));
    for _ in 0..100 {
        physics.step(&mut world);
        world.clear_trackers();
    }
    let t = 1.0_f64;
    let (m, omega, f) = (to_f64(m), to_f64(omega), to_f64(f));
    let expected = [
        f / (m * omega) * (omega * t).sin(),
        f / (m * omega) * (1.0 - (omega * t).cos()),
    ];
    let v = world.get::<Velocity>(body).unwrap().linear;
    let err = (to_f64(v.x) - expected[0]).hypot(to_f64(v.y) - expected[1]);
    assert!(err < 1e-4, "v = {v}, expected {expected:?}");

    // The checksum covers it, and a rollback puts a changed one back.
    let saved = RollbackSnapshot::capture(&mut world);
    let before = world_checksum(&world);
    world.get_mut::<ConstantLocalForce>(thruster).unwrap().force = Vec3::Y;
    assert_ne!(world_checksum(&world), before);
    saved.restore(&mut world).unwrap();
    assert_eq!(world_checksum(&world), before);

    // A bad value is left out, as for every generator.
    world.get_mut::<ConstantLocalForce>(thruster).unwrap().force = Vec3::NAN;
    physics.step(&mut world);
    assert!(world.get::<ConstantLocalForce>(thruster).is_none());
    let errors = &world.resource::<PhysicsErrors>().generators;
    assert_eq!(errors.len(), 1);
    assert_eq!(errors[0].generator, "ConstantLocalForce");
}

/// A `Static` body never moves and a `Kinematic` one moves as game code sets it: an impulse
/// (an explosion reaching everything in range) leaves their velocity as it was, through an
/// entity and through `BodyForces`. And a damped spring to a static anchor whose `Velocity`
/// holds a speed anyway (the one it had when game code made it static) does not drag the body
/// it holds: the damper takes a static end's velocity as zero (it dragged the body away).
#[test]
fn fixed_bodies_take_no_impulse_and_lend_no_velocity_to_dampers() {
    let mass = MassProperties::new(Mass::new(1.0).unwrap(), Vec3::ONE).unwrap();
    let mut world = world(Integrator::Splitting);
    let anchor = world
        .spawn((
            RigidBody,
            Static,
            MassProps(mass),
            Pose::from_translation(Vec3::X * 2.0),
        ))
        .id();
    let moved = world
        .spawn((
            RigidBody,
            Kinematic,
            MassProps(mass),
            Pose::IDENTITY,
            ForceAccumulator::default(),
        ))
        .id();
    world
        .entity_mut(anchor)
        .apply_linear_impulse(Vec3::X * 10.0);
    world
        .entity_mut(moved)
        .apply_angular_impulse(Vec3::Z * 10.0);
    let mut state = bevy_ecs::system::SystemState::<Query<BodyForces>>::new(&mut world);
    let mut bodies = state.get_mut(&mut world).expect("no resources needed");
    for mut body in bodies.iter_mut() {
        body.apply_linear_impulse(Vec3::Y * 10.0);
    }
    state.apply(&mut world);
    for e in [anchor, moved] {
        assert_eq!(
            world.get::<Velocity>(e).copied().unwrap_or(Velocity::ZERO),
            Velocity::ZERO
        );
    }
    // The anchor made static while moving: its velocity stays in the component.
    world
        .entity_mut(anchor)
        .insert(Velocity::linear(Vec3::X * 10.0));
    let held = world
        .spawn((
            RigidBody,
            MassProps(mass),
            Pose::IDENTITY,
            ForceAccumulator::default(),
        ))
        .id();
    world.spawn(
        Spring::new(
            held,
            Vec3::ZERO,
            SpringEnd::on_body(anchor, Vec3::ZERO),
            10.0,
            2.0,
        )
        .with_damping(5.0),
    );
    let mut physics = PhysicsRunner::new(&mut world);
    for _ in 0..100 {
        physics.step(&mut world);
    }
    let pose = world.get::<Pose>(held).unwrap();
    let velocity = world.get::<Velocity>(held).unwrap();
    assert_eq!(pose.translation, Vec3::ZERO, "the held body was dragged");
    assert_eq!(velocity.linear, Vec3::ZERO);
    assert!(world.resource::<PhysicsErrors>().is_empty());
}
