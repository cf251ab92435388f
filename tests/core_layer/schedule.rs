//! The schedule holds only the systems a world needs.

use tumble::bevy_ecs::prelude::*;
use tumble::glam::Vec3;
use tumble::prelude::*;

use super::util::world_with;

fn system_count(world: &mut World, plan: &PhysicsPlan) -> usize {
    let mut schedule = plan.build_schedule();
    schedule.initialize(world).unwrap();
    schedule.systems_len()
}

#[test]
fn gravity_free_world_has_no_gravity_system() {
    let mut world = world_with(0.01, Integrator::SymplecticEuler);
    let body = world.spawn((RigidBody, ForceAccumulator::default())).id();
    let plan = PhysicsPlan::for_world(&mut world);
    assert!(!plan.contains(Stage::Gravity));
    assert_eq!(
        plan.stages(),
        &[Stage::IntegrateWithForces, Stage::IntegrateWithoutForces]
    );
    assert_eq!(system_count(&mut world, &plan), 2);
    let mut schedule = plan.build_schedule();
    for _ in 0..10 {
        schedule.run(&mut world);
    }
    assert_eq!(
        world.get::<Transform>(body).unwrap().translation,
        Vec3::ZERO
    );
}

#[test]
fn each_generator_kind_adds_exactly_its_system() {
    let mut world = world_with(0.01, Integrator::SymplecticEuler);
    world.insert_resource(Gravity::EARTH_Y_DOWN);
    let body = world.spawn(RigidBody).id();
    world.spawn(ConstantForce {
        body,
        force: Vec3::X,
        local_point: None,
    });
    let plan = PhysicsPlan::for_world(&mut world);
    assert_eq!(
        plan.stages(),
        &[
            Stage::Gravity,
            Stage::ConstantForces,
            Stage::IntegrateWithForces,
            Stage::IntegrateWithoutForces
        ]
    );
    assert_eq!(system_count(&mut world, &plan), 4);
    assert_eq!(
        plan.to_string(),
        "apply_gravity → apply_constant_forces → integrate_with_forces → integrate_without_forces"
    );
    world.spawn(Spring {
        a: body,
        anchor_a: Vec3::ZERO,
        b: SpringEnd::World(Vec3::ZERO),
        stiffness: 1.0,
        damping: 0.0,
        rest_length: 0.0,
    });
    world.spawn(ConstantTorque {
        body,
        torque: Vec3::Y,
    });
    let plan = PhysicsPlan::for_world(&mut world);
    assert_eq!(plan.stages().len(), 6);
    assert!(plan.contains(Stage::Springs) && plan.contains(Stage::ConstantTorques));
    assert_eq!(system_count(&mut world, &plan), 6);
}

#[test]
fn non_body_entities_are_never_touched() {
    let mut world = world_with(0.01, Integrator::SymplecticEuler);
    world.insert_resource(Gravity::EARTH_Y_DOWN);
    // A Transform + Velocity on an entity that is not a RigidBody (say, a camera).
    let camera = world
        .spawn((Transform::IDENTITY, Velocity::linear(Vec3::X)))
        .id();
    let mut schedule = PhysicsPlan::for_world(&mut world).build_schedule();
    for _ in 0..10 {
        schedule.run(&mut world);
    }
    assert_eq!(
        *world.get::<Transform>(camera).unwrap(),
        Transform::IDENTITY
    );
}

#[test]
fn user_force_system_in_forces_set_runs_before_integration() {
    #[derive(Component)]
    struct Thruster;
    fn thrust(mut q: Query<&mut ForceAccumulator, With<Thruster>>) {
        for mut acc in &mut q {
            acc.add_force(Vec3::new(0.0, 0.0, 3.0));
        }
    }
    let mut world = world_with(0.5, Integrator::SymplecticEuler);
    let body = world
        .spawn((RigidBody, Thruster, ForceAccumulator::default()))
        .id();
    let mut schedule = PhysicsPlan::for_world(&mut world).build_schedule();
    schedule.add_systems(thrust.in_set(PhysicsSet::Forces));
    schedule.run(&mut world);
    assert_eq!(
        world.get::<Velocity>(body).unwrap().linear,
        Vec3::new(0.0, 0.0, 1.5)
    );
}
