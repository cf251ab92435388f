//! Helpers shared by the integration tests of `tumble_ecs`.

use bevy_ecs::prelude::*;
use tumble_core::math::{Quat, Real, Vec3};
use tumble_core::{Mass, MassProperties};
use tumble_ecs::prelude::*;

/// Ties `bodies` into a chain of springs of stiffness `k`: the first from its point
/// `(-0.1, 0.05, 0)` to the world point `wall` (rest length 0.8 m), then each from its point
/// `(0.1, 0.05, 0)` to the point `next_anchor` of the next (rest length `rest`).
pub(crate) fn tie_chain(
    world: &mut World,
    bodies: &[Entity],
    wall: Vec3,
    k: Real,
    (next_anchor, rest): (Vec3, Real),
) {
    let wall = SpringEnd::World(wall);
    world.spawn(Spring::new(
        bodies[0],
        Vec3::new(-0.1, 0.05, 0.0),
        wall,
        k,
        0.8,
    ));
    for pair in bodies.windows(2) {
        let next = SpringEnd::on_body(pair[1], next_anchor);
        world.spawn(Spring::new(
            pair[0],
            Vec3::new(0.1, 0.05, 0.0),
            next,
            k,
            rest,
        ));
    }
}

/// Spawns a body of unit mass with principal moments `inertia` at `position` and `rotation`,
/// moving at `v` and turning at `w`.
pub(crate) fn unit_body(
    world: &mut World,
    position: Vec3,
    rotation: Quat,
    inertia: Vec3,
    v: Vec3,
    w: Vec3,
) -> Entity {
    let mass = MassProperties::new(Mass::new(1.0).unwrap(), inertia).unwrap();
    world
        .spawn((
            RigidBody,
            MassProps(mass),
            Pose {
                translation: position,
                rotation,
            },
            Velocity {
                linear: v,
                angular: w,
            },
        ))
        .id()
}
