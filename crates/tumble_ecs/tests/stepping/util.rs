//! Helpers shared by the stepping tests (and the root crate's cross-crate tests, which include
//! this file).

use bevy_ecs::prelude::*;
use tumble_core::math::Real;
use tumble_ecs::prelude::*;

/// A world with the given step and integrator.
pub(crate) fn world_with(dt: Real, integrator: Integrator) -> World {
    let mut world = World::new();
    world.insert_resource(PhysicsSettings::new(dt, integrator).expect("valid dt"));
    world
}

/// Plans the step of `world` and runs `steps` steps; returns the runner to step on.
pub(crate) fn run(world: &mut World, steps: usize) -> PhysicsRunner {
    let mut physics = PhysicsRunner::new(world);
    run_steps(world, &mut physics, steps);
    physics
}

/// Runs `steps` more steps with `physics`, clearing the change trackers after each.
pub(crate) fn run_steps(world: &mut World, physics: &mut PhysicsRunner, steps: usize) {
    for _ in 0..steps {
        physics.step(world);
        world.clear_trackers();
    }
}

/// Mass properties from a mass and principal moments.
pub(crate) fn mass_props(m: Real, inertia: [Real; 3]) -> MassProps {
    MassProps(MassProperties::new(Mass::new(m).unwrap(), inertia.into()).unwrap())
}

/// Spawns a rigid body of mass `m` and principal moments `inertia`, with `extra` (its pose,
/// velocity, ...).
pub(crate) fn spawn_body(
    world: &mut World,
    m: Real,
    inertia: [Real; 3],
    extra: impl Bundle,
) -> Entity {
    world.spawn((RigidBody, mass_props(m, inertia), extra)).id()
}

/// Relative difference `|a − b| / |b|` in f64.
pub(crate) fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}
