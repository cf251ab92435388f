//! Force generators are checked, never trusted: a bad value, a spring from a body to itself or a
//! body that does not exist (or goes away) leaves the generator out of the step with one record
//! naming the generator and the field, and never blames or moves a body.

use bevy_ecs::prelude::*;
use tumble_core::math::{Real, Vec3};
use tumble_ecs::prelude::*;

fn world() -> World {
    let mut world = World::new();
    world.insert_resource(PhysicsSettings::new(0.01, Integrator::Splitting).unwrap());
    world
}

fn step(world: &mut World, physics: &mut PhysicsRunner, steps: usize) {
    for _ in 0..steps {
        physics.step(world);
        world.clear_trackers();
    }
}

fn generator_errors(world: &World) -> Vec<GeneratorError> {
    world.resource::<PhysicsErrors>().generators.clone()
}

fn anchored(body: Entity, stiffness: Real) -> Spring {
    Spring::new(
        body,
        Vec3::ZERO,
        SpringEnd::World(Vec3::ZERO),
        stiffness,
        0.0,
    )
}

/// A body at x = 1 that only a spring could move.
fn resting_body(world: &mut World) -> Entity {
    world
        .spawn((RigidBody, Pose::from_translation(Vec3::X)))
        .id()
}

fn assert_left_out(world: &World, spring: Entity, field: &str) {
    let errors = generator_errors(world);
    assert_eq!(errors.len(), 1, "{errors:?}");
    let error = &errors[0];
    assert_eq!((error.entity, error.generator), (spring, "Spring"));
    match &error.kind {
        GeneratorErrorKind::NonFinite { field: f, .. }
        | GeneratorErrorKind::Negative { field: f, .. }
        | GeneratorErrorKind::MissingBody { field: f, .. } => assert_eq!(*f, field),
        other => panic!("{other:?}"),
    }
    assert!(
        world.get::<Spring>(spring).is_none(),
        "the spring is removed"
    );
    assert_eq!(
        world.get::<RejectedGenerator>(spring).map(|r| &r.0),
        Some(error)
    );
    assert!(
        world.resource::<PhysicsErrors>().bodies.is_empty(),
        "no body is blamed"
    );
    let message = error.to_string();
    assert!(
        message.contains(field) && message.contains("left out"),
        "{message}"
    );
}

#[test]
fn a_negative_stiffness_is_left_out_when_inserted() {
    let mut world = world();
    let body = resting_body(&mut world);
    let spring = world.spawn(anchored(body, -100.0)).id();
    let mut physics = PhysicsRunner::new(&mut world);
    step(&mut world, &mut physics, 50);
    assert_left_out(&world, spring, "stiffness");
    assert!(!physics.plan().contains(PhysicsSystem::Springs));
    assert_eq!(world.get::<Pose>(body).unwrap().translation, Vec3::X);
}

#[test]
fn a_value_spoiled_in_place_is_left_out_before_the_next_step() {
    let mut world = world();
    let body = resting_body(&mut world);
    let spring = world.spawn(anchored(body, 1.0)).id();
    let mut physics = PhysicsRunner::new(&mut world);
    step(&mut world, &mut physics, 10);
    let moved = world.get::<Pose>(body).unwrap().translation;
    assert!(moved.x < 1.0, "the valid spring pulls: {moved}");
    world.get_mut::<Spring>(spring).unwrap().stiffness = Real::NAN;
    step(&mut world, &mut physics, 40);
    assert_left_out(&world, spring, "stiffness");
    // Left out before the step that would have used it: the body coasts on, never NaN.
    let pose = world.get::<Pose>(body).unwrap();
    assert!(pose.translation.is_finite());
    assert!(world.get::<Rejected>(body).is_none());
}

#[test]
fn a_spring_to_a_body_that_never_existed_is_left_out() {
    let mut world = world();
    let body = resting_body(&mut world);
    let ghost = world.spawn_empty().id();
    world.despawn(ghost);
    let spring = world
        .spawn(Spring::new(
            body,
            Vec3::ZERO,
            SpringEnd::on_body(ghost, Vec3::ZERO),
            5.0,
            0.0,
        ))
        .id();
    let force = world
        .spawn(ConstantForce {
            body: ghost,
            force: Vec3::X,
            local_point: None,
        })
        .id();
    let mut physics = PhysicsRunner::new(&mut world);
    step(&mut world, &mut physics, 3);
    let errors = generator_errors(&world);
    assert_eq!(errors.len(), 2, "{errors:?}");
    assert_eq!(
        errors[0].kind,
        GeneratorErrorKind::MissingBody {
            field: "b",
            body: ghost
        }
    );
    assert_eq!((errors[0].entity, errors[1].entity), (spring, force));
    assert_eq!(errors[1].generator, "ConstantForce");
    assert_eq!(world.get::<Pose>(body).unwrap().translation, Vec3::X);
}

#[test]
fn a_generator_whose_body_is_despawned_is_reported_once() {
    let mut world = world();
    let kept = resting_body(&mut world);
    let gone = world.spawn(RigidBody).id();
    let spring = world
        .spawn(Spring::new(
            kept,
            Vec3::ZERO,
            SpringEnd::on_body(gone, Vec3::ZERO),
            5.0,
            0.0,
        ))
        .id();
    let mut physics = PhysicsRunner::new(&mut world);
    step(&mut world, &mut physics, 5);
    assert!(physics.plan().contains(PhysicsSystem::Springs));
    world.despawn(gone);
    step(&mut world, &mut physics, 20);
    assert_left_out(&world, spring, "b");
    assert!(!physics.plan().contains(PhysicsSystem::Springs));
}

#[test]
fn a_spring_from_a_body_to_itself_is_left_out() {
    let mut world = world();
    let body = resting_body(&mut world);
    let spring = world
        .spawn(Spring::new(
            body,
            Vec3::ZERO,
            SpringEnd::on_body(body, Vec3::Y),
            5.0,
            0.0,
        ))
        .id();
    world.flush();
    let errors = generator_errors(&world);
    assert_eq!(errors.len(), 1);
    assert_eq!(errors[0].kind, GeneratorErrorKind::SelfSpring(body));
    assert!(world.get::<Spring>(spring).is_none());
}

#[test]
fn a_valid_generator_inserted_again_lifts_the_rejection() {
    let mut world = world();
    let body = resting_body(&mut world);
    let spring = world.spawn(anchored(body, -1.0)).id();
    let mut physics = PhysicsRunner::new(&mut world);
    step(&mut world, &mut physics, 2);
    assert!(world.get::<RejectedGenerator>(spring).is_some());
    world.entity_mut(spring).insert(anchored(body, 1.0));
    step(&mut world, &mut physics, 10);
    assert!(world.get::<RejectedGenerator>(spring).is_none());
    assert!(
        world.get::<Pose>(body).unwrap().translation.x < 1.0,
        "pulls again"
    );
    assert_eq!(
        generator_errors(&world).len(),
        1,
        "the old record stays, no new one"
    );
}

/// One bad insertion seen by several hooks (velocity, accumulator) is one incident.
#[test]
fn one_incident_is_one_record() {
    let mut world = world();
    let body = world
        .spawn((
            RigidBody,
            Velocity::linear(Vec3::new(Real::NAN, 0.0, 0.0)),
            ForceAccumulator::default(),
        ))
        .id();
    let mut physics = PhysicsRunner::new(&mut world);
    step(&mut world, &mut physics, 5);
    let errors = &world.resource::<PhysicsErrors>().bodies;
    assert_eq!(errors.len(), 1, "{errors:?}");
    assert_eq!(errors[0].entity, body);
}
