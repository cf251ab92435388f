//! The planner warns of a rate about a locked principal axis (a zero moment), which every
//! integrator holds at 0, and the warning matches what a step does: the rate is gone after it.

use bevy_ecs::prelude::*;
use tumble_core::math::{Quat, Vec3, Widen};
use tumble_core::{Integrator, Mass, MassProperties};
use tumble_ecs::prelude::*;

fn spinning(inertia: Vec3, rotation: Quat, omega: Vec3) -> (World, Entity) {
    let mut world = World::new();
    world.insert_resource(PhysicsSettings::new(1.0 / 60.0, Integrator::Splitting).unwrap());
    let mass = MassProperties::new(Mass::new(1.0).unwrap(), inertia).unwrap();
    let body = world
        .spawn((
            RigidBody,
            MassProps(mass),
            Pose::from_rotation(rotation),
            Velocity::angular(omega),
        ))
        .id();
    (world, body)
}

fn locked_rate_warned(world: &mut World) -> Option<f64> {
    check_stability(world).iter().find_map(|w| match w {
        StabilityWarning::LockedAxisRate { rate, .. } => {
            assert!(!w.is_instability());
            assert!(w.to_string().contains("locked principal axis"), "{w}");
            Some(rate.widen())
        }
        _ => None,
    })
}

#[test]
fn a_rate_about_a_locked_axis_is_warned_of_and_is_what_the_step_drops() {
    let quarter = Quat::from_rotation_z(std::f32::consts::FRAC_PI_2 as _);
    // Body x (locked) points along world y; 2 rad/s about it, 3 about the free z.
    let (mut world, body) = spinning(Vec3::new(0.0, 1.0, 1.0), quarter, Vec3::new(0.0, 2.0, 3.0));
    let rate = locked_rate_warned(&mut world).expect("warned");
    assert!((rate - 2.0).abs() < 1e-5, "{rate}");
    let before = world.get::<Velocity>(body).unwrap().angular;
    PhysicsRunner::new(&mut world).step(&mut world);
    let after = world.get::<Velocity>(body).unwrap().angular;
    let dropped = (before - after).length().widen();
    assert!(
        (dropped - rate).abs() < 1e-5,
        "dropped {dropped}, warned {rate}"
    );

    // About the free axes only: no warning, and the step keeps the spin.
    let (mut world, body) = spinning(Vec3::new(0.0, 1.0, 1.0), quarter, Vec3::new(0.0, 0.0, 3.0));
    assert_eq!(locked_rate_warned(&mut world), None);
    PhysicsRunner::new(&mut world).step(&mut world);
    let kept = world.get::<Velocity>(body).unwrap().angular;
    assert!((kept - Vec3::new(0.0, 0.0, 3.0)).length() < 1e-5, "{kept}");
}
