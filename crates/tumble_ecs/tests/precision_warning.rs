//! The planner warns when a body is so far from the origin that rounding of its stored position
//! eats a visible part of each step's motion, and the warning matches what a run measures.

use bevy_ecs::prelude::*;
use tumble_core::Integrator;
use tumble_core::math::{DOUBLE_PRECISION, Real, Vec3, Widen};
use tumble_ecs::prelude::*;

const DT: Real = 1.0 / 60.0;
const STEPS: usize = 600;

fn moving_body_at(distance: Real) -> (World, Entity) {
    let mut world = World::new();
    world.insert_resource(PhysicsSettings::new(DT, Integrator::Splitting).unwrap());
    let body = world
        .spawn((
            RigidBody,
            Pose::from_translation(Vec3::new(distance, 0.0, 0.0)),
            Velocity::linear(Vec3::new(1.0, 0.0, 0.0)),
        ))
        .id();
    (world, body)
}

fn warned(world: &mut World) -> bool {
    check_stability(world)
        .iter()
        .any(|w| matches!(w, StabilityWarning::CoarsePosition { .. }) && !w.is_instability())
}

/// Relative error of the distance travelled in `STEPS` steps at 1 m/s.
fn measured_error(world: &mut World, body: Entity, distance: Real) -> f64 {
    let mut physics = PhysicsRunner::new(world);
    for _ in 0..STEPS {
        physics.step(world);
        world.clear_trackers();
    }
    let x = world.get::<Pose>(body).unwrap().translation.x.widen();
    let travelled = x - distance.widen();
    let exact = STEPS as f64 * DT.widen();
    (travelled / exact - 1.0).abs()
}

#[test]
fn far_bodies_are_warned_about_exactly_where_rounding_shows() {
    for distance in [10.0 as Real, 100.0, 1e4, 1e5] {
        let (mut world, body) = moving_body_at(distance);
        let warned = warned(&mut world);
        let error = measured_error(&mut world, body, distance);
        // The rule: r ε / (2 s Δt) > 1e-3, i.e. beyond ~280 m at 1 m/s and 60 Hz in f32.
        let expected = !DOUBLE_PRECISION && distance > 280.0;
        assert_eq!(warned, expected, "{distance} m: warned {warned}");
        if warned {
            assert!(
                error > 1e-3,
                "{distance} m: warned, but the error is {error:e}"
            );
        } else {
            assert!(
                error < 1e-3,
                "{distance} m: not warned, but the error is {error:e}"
            );
        }
    }
}

#[test]
fn a_body_at_rest_far_away_loses_nothing_and_is_not_warned() {
    let (mut world, body) = moving_body_at(1e6);
    world.get_mut::<Velocity>(body).unwrap().linear = Vec3::ZERO;
    assert!(!warned(&mut world));
}

#[test]
fn a_body_farther_than_the_precision_can_count_is_warned_with_its_distance() {
    // Each coordinate finite, the distance beyond what `f32` can hold (|x|² overflows it).
    let far = Real::MAX / 2.0;
    let mut world = World::new();
    world.insert_resource(PhysicsSettings::new(DT, Integrator::Splitting).unwrap());
    world.spawn((
        RigidBody,
        Pose::from_translation(Vec3::new(far, far, far)),
        Velocity::linear(Vec3::new(1.0, 0.0, 0.0)),
    ));
    let warnings = check_stability(&mut world);
    let Some(StabilityWarning::CoarsePosition {
        distance,
        relative_error,
        ..
    }) = warnings
        .iter()
        .find(|w| matches!(w, StabilityWarning::CoarsePosition { .. }))
    else {
        panic!("no position warning: {warnings:?}");
    };
    let exact = far.widen() * 3f64.sqrt();
    assert!(
        (distance / exact - 1.0).abs() < 1e-12,
        "distance {distance:e}, expected {exact:e}"
    );
    assert!(relative_error.is_finite() && *relative_error > 1.0);
    let text = warnings
        .iter()
        .map(ToString::to_string)
        .collect::<Vec<_>>()
        .join("\n");
    assert!(!text.contains("inf") && !text.contains("NaN"), "{text}");
    assert!(text.contains("a whole step can be lost"), "{text}");
}

/// A rod `I = (1, 1, r)` spinning at `w` rad/s about its axis, tipped by 1 rad/s: its `|L|`
/// relative drift over `STEPS` steps, and whether the planner warned of its angular velocity's
/// rounding.
fn spinning_rod(r: Real, w: Real) -> (bool, f64) {
    let mut world = World::new();
    world.insert_resource(PhysicsSettings::new(DT, Integrator::Splitting).unwrap());
    let inertia = Vec3::new(1.0, 1.0, r);
    let mass = MassProperties::new(Mass::new(1.0).unwrap(), inertia).unwrap();
    let angular = Vec3::new(1.0, 1.0, w);
    let body = world
        .spawn((
            RigidBody,
            MassProps(mass),
            Pose::IDENTITY,
            Velocity::angular(angular),
        ))
        .id();
    let warned = check_stability(&mut world).iter().any(|w| {
        matches!(w, StabilityWarning::CoarseAngularVelocity { .. }) && !w.is_instability()
    });
    let momentum = |world: &World| {
        let v = world.get::<Velocity>(body).unwrap().angular;
        let q = world.get::<Pose>(body).unwrap().rotation;
        mass.world_inertia_mul(q, v).widen().length()
    };
    let start = momentum(&world);
    let mut physics = PhysicsRunner::new(&mut world);
    let mut worst: f64 = 0.0;
    for _ in 0..STEPS {
        physics.step(&mut world);
        world.clear_trackers();
        worst = worst.max((momentum(&world) / start - 1.0).abs());
    }
    (warned, worst)
}

/// The rule `I_max ε |ω| / |L| > 1e-3` warns of a fast spin about an axis of small moment,
/// whose `|L|` then wanders by more than 1e-3 (`f32`: `r = 1e-12`, `|ω| = 1e8`, about 8× `|L|`
/// per step; `r = 1e-6`, `|ω| = 1e5`, 0.8 %), and stays quiet where rounding moves `|L|` by
/// far less (`r = 1e-2`, `|ω| = 100`: 9e-6), as it does for every case in `f64`.
#[test]
fn fast_spins_about_a_small_moment_are_warned_where_rounding_moves_l() {
    for (r, w, warn_in_f32) in [(1e-12, 1e8, true), (1e-6, 1e5, true), (1e-2, 100.0, false)] {
        let (warned, drift) = spinning_rod(r, w);
        let expected = warn_in_f32 && !DOUBLE_PRECISION;
        assert_eq!(warned, expected, "r = {r}, |ω| = {w}: warned {warned}");
        if warned {
            assert!(drift > 1e-3, "r = {r}: warned, but |L| drifts by {drift:e}");
        } else {
            assert!(
                drift < 1e-3,
                "r = {r}: not warned, but |L| drifts by {drift:e}"
            );
        }
    }
}
