//! The schedule holds only the systems a world needs.

use bevy_ecs::prelude::*;
use tumble_core::math::Vec3;

use tumble_ecs::prelude::*;

use super::util::world_with;

#[test]
fn gravity_free_world_has_no_gravity_system() {
    let mut world = world_with(0.01, Integrator::SymplecticEuler);
    let body = world.spawn((RigidBody, ForceAccumulator::default())).id();
    let plan = PhysicsPlan::for_world(&mut world);
    assert!(!plan.contains(PhysicsSystem::Gravity));
    // One body, with an accumulator: nothing but its integrate system.
    assert_eq!(plan.systems(), &[PhysicsSystem::IntegrateWithForces]);
    let mut physics = PhysicsRunner::new(&mut world);
    for _ in 0..10 {
        physics.step(&mut world);
    }
    assert_eq!(world.get::<Pose>(body).unwrap().translation, Vec3::ZERO);
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
        plan.systems(),
        &[
            PhysicsSystem::Gravity,
            PhysicsSystem::ConstantForces,
            PhysicsSystem::IntegrateWithForces,
        ]
    );
    assert_eq!(
        plan.to_string(),
        "apply_gravity → apply_constant_forces → integrate_with_forces"
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
    // Springs bring the energy audit along: its start, its load reading and its balance.
    assert_eq!(plan.systems().len(), 5 + 3);
    assert!(plan.contains(PhysicsSystem::Springs) && plan.contains(PhysicsSystem::ConstantTorques));
    assert!(plan.contains(PhysicsSystem::AuditEnergy));
}

#[test]
fn static_and_kinematic_bodies_are_never_integrated() {
    let mut world = world_with(0.01, Integrator::Splitting);
    world.insert_resource(Gravity::EARTH_Y_DOWN);
    let moving = Velocity {
        linear: Vec3::X,
        angular: Vec3::new(0.0, 2.0, 1.0),
    };
    let wall = world.spawn((RigidBody, Static, moving)).id();
    let platform = world.spawn((RigidBody, Kinematic, moving)).id();
    // Only fixed bodies: nothing to integrate, no system at all.
    assert!(PhysicsPlan::for_world(&mut world).systems().is_empty());
    // A dynamic body hanging from the static one by a spring: the spring pulls on both ends, the
    // static end's share is discarded every step.
    let ball = world
        .spawn((RigidBody, Pose::from_translation(Vec3::new(0.0, -1.0, 0.0))))
        .id();
    world.spawn(Spring {
        a: ball,
        anchor_a: Vec3::ZERO,
        b: SpringEnd::Body {
            body: wall,
            anchor: Vec3::ZERO,
        },
        stiffness: 50.0,
        damping: 0.0,
        rest_length: 0.5,
    });
    let plan = PhysicsPlan::for_world(&mut world);
    assert_eq!(
        plan.to_string(),
        "audit_energy_start → check_fixed_bodies → begin_stage → apply_gravity → \
         audit_external_loads → apply_springs → integrate_with_forces → \
         discard_fixed_body_forces → audit_energy"
    );
    let mut physics = PhysicsRunner::new(&mut world);
    assert_eq!(physics.plan(), &plan);
    for _ in 0..100 {
        physics.step(&mut world);
        world.clear_trackers();
    }
    for fixed in [wall, platform] {
        assert_eq!(*world.get::<Pose>(fixed).unwrap(), Pose::IDENTITY);
        assert_eq!(*world.get::<Velocity>(fixed).unwrap(), moving);
    }
    assert_eq!(
        *world.get::<ForceAccumulator>(wall).unwrap(),
        ForceAccumulator::default()
    );
    let y = world.get::<Pose>(ball).unwrap().translation.y;
    assert!(
        y < -0.5 && y > -2.0,
        "the ball oscillates on its spring: y = {y}"
    );
}

#[test]
fn the_runner_replans_when_the_world_changes() {
    let mut world = world_with(0.01, Integrator::SymplecticEuler);
    let body = world.spawn(RigidBody).id();
    let mut physics = PhysicsRunner::new(&mut world);
    assert_eq!(physics.plan().to_string(), "integrate_without_forces");
    physics.step(&mut world);
    assert_eq!(physics.replans(), 0);
    // Gravity for a body without accumulator needs no extra system: same plan.
    world.insert_resource(Gravity::EARTH_Y_DOWN);
    physics.step(&mut world);
    assert_eq!(physics.replans(), 0);
    // A torque generator: an accumulator appears, the plan changes.
    let torque = world
        .spawn(ConstantTorque {
            body,
            torque: Vec3::Y,
        })
        .id();
    physics.step(&mut world);
    assert_eq!(
        physics.plan().to_string(),
        "apply_gravity → apply_constant_torques → integrate_with_forces"
    );
    assert_eq!(physics.replans(), 1);
    assert!(world.get::<Velocity>(body).unwrap().angular.y > 0.0);
    // The generator goes away: its system goes too.
    world.despawn(torque);
    physics.step(&mut world);
    assert_eq!(
        physics.plan().to_string(),
        "apply_gravity → integrate_with_forces"
    );
    // Switching to a drift–kick–drift integrator adds the first half-drift.
    world.resource_mut::<PhysicsSettings>().integrator = Integrator::Splitting;
    physics.step(&mut world);
    assert!(physics.plan().contains(PhysicsSystem::BeginStage));
    assert_eq!(physics.replans(), 3);
    assert_eq!(format!("{physics}"), physics.plan().to_string());
}

#[test]
fn non_body_entities_are_never_touched() {
    let mut world = world_with(0.01, Integrator::SymplecticEuler);
    world.insert_resource(Gravity::EARTH_Y_DOWN);
    // A Pose + Velocity on an entity that is not a RigidBody (say, a camera).
    let camera = world
        .spawn((Pose::IDENTITY, Velocity::linear(Vec3::X)))
        .id();
    let mut physics = PhysicsRunner::new(&mut world);
    for _ in 0..10 {
        physics.step(&mut world);
    }
    assert_eq!(*world.get::<Pose>(camera).unwrap(), Pose::IDENTITY);
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
    let mut forces = ForceSystems::default();
    forces.add(thrust);
    world.insert_resource(forces);
    PhysicsRunner::new(&mut world).step(&mut world);
    assert_eq!(
        world.get::<Velocity>(body).unwrap().linear,
        Vec3::new(0.0, 0.0, 1.5)
    );
}

/// A world that needs every stage gets all of them, once each, in `PhysicsSystem::ALL` order (so the
/// plan's inline capacity, `PhysicsSystem::COUNT`, always suffices).
#[test]
fn a_world_needing_everything_plans_every_stage_in_order() {
    let mut world = world_with(0.01, Integrator::Splitting);
    // Substeps: the stage cursor's two systems.
    world
        .resource_mut::<PhysicsSettings>()
        .set_substeps(std::num::NonZeroU32::new(2).unwrap())
        .unwrap();
    world.insert_resource(Gravity::EARTH_Y_DOWN);
    let wall = world
        .spawn((RigidBody, Static, ForceAccumulator::default()))
        .id();
    let pulled = world.spawn((RigidBody, ForceAccumulator::default())).id();
    world.spawn(RigidBody);
    world.spawn(Spring {
        a: pulled,
        anchor_a: Vec3::ZERO,
        b: SpringEnd::Body {
            body: wall,
            anchor: Vec3::ZERO,
        },
        stiffness: 10.0,
        damping: 0.5,
        rest_length: 1.0,
    });
    world.spawn(ConstantForce {
        body: pulled,
        force: Vec3::X,
        local_point: None,
    });
    world.spawn(ConstantTorque {
        body: pulled,
        torque: Vec3::Y,
    });
    // A spring far too stiff for the step: its group takes the implicit step.
    let stiff = [world.spawn(RigidBody).id(), world.spawn(RigidBody).id()];
    world.spawn(Spring {
        a: stiff[0],
        anchor_a: Vec3::ZERO,
        b: SpringEnd::Body {
            body: stiff[1],
            anchor: Vec3::ZERO,
        },
        stiffness: 1e8,
        damping: 0.0,
        rest_length: 1.0,
    });
    let plan = PhysicsPlan::for_world(&mut world);
    assert_eq!(plan.systems(), &PhysicsSystem::ALL[..]);
    assert_eq!(PhysicsSystem::ALL.len(), PhysicsSystem::COUNT);
}

/// The spring dampers' two stages are planned only while some spring has `damping > 0`, and the
/// runner notices a damper switched on or off in place.
#[test]
fn damper_stages_only_with_a_damped_spring() {
    let mut world = world_with(0.01, Integrator::Splitting);
    let body = world.spawn((RigidBody, ForceAccumulator::default())).id();
    let spring = |damping| Spring {
        a: body,
        anchor_a: Vec3::ZERO,
        b: SpringEnd::World(Vec3::X),
        stiffness: 10.0,
        damping,
        rest_length: 0.5,
    };
    let undamped = world.spawn(spring(0.0)).id();
    let damper = [
        PhysicsSystem::DampSpringsStart,
        PhysicsSystem::DampSpringsEnd,
    ];
    let mut physics = PhysicsRunner::new(&mut world);
    physics.step(&mut world);
    assert!(damper.iter().all(|&s| !physics.plan().contains(s)));
    world.get_mut::<Spring>(undamped).unwrap().damping = 0.2;
    physics.step(&mut world);
    assert_eq!(
        physics.plan().to_string(),
        "audit_energy_start → damp_springs_start → begin_stage → audit_external_loads → \
         apply_springs → integrate_with_forces → damp_springs_end → audit_energy"
    );
    assert_eq!(physics.replans(), 1);
    world.get_mut::<Spring>(undamped).unwrap().damping = 0.0;
    physics.step(&mut world);
    assert!(damper.iter().all(|&s| !physics.plan().contains(s)));
    assert_eq!(physics.replans(), 2);
}
