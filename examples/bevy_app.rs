//! tumble in a Bevy app: `TumblePlugin` in `FixedUpdate` on Bevy's fixed clock (60 Hz), a
//! thruster system in `PhysicsSet::Forces`, and the poses written, interpolated between fixed
//! steps, into Bevy's `Transform` for rendering. Headless and deterministic: each frame advances
//! game time by a fixed 7 ms (`TimeUpdateStrategy::ManualDuration`), as a 144 Hz display would.
//! Run: `cargo run --release --features bevy_app --example bevy_app`.

use std::time::Duration;

use bevy_app::{App, FixedUpdate, Update};
use bevy_ecs::prelude::*;
use bevy_time::{Fixed, Time, TimePlugin, TimeUpdateStrategy};
use bevy_transform::components::Transform;
use tumble::ecs::schedule::{TumblePlugin, TumbleStep};
use tumble::math::{Quat, Real, Vec3, to_f64};
use tumble::prelude::*;

/// A ship's thruster: a force along the ship's own +z axis, at its tail.
#[derive(Component)]
struct Thruster(Real);

/// The pose before the last fixed step, kept for rendering between steps.
#[derive(Component, Default, Clone, Copy)]
struct PreviousPose(Pose);

fn fire_thrusters(mut ships: Query<(BodyForces, &Thruster)>) {
    for (mut ship, thruster) in &mut ships {
        let force = Vec3::Z * thruster.0;
        ship.apply_local_force_at_local_point(force, Vec3::new(0.0, 0.0, -1.0));
    }
}

/// Runs in `FixedUpdate` before the step: the pose the renderer interpolates from.
fn remember_poses(mut bodies: Query<(&Pose, &mut PreviousPose)>) {
    for (pose, mut previous) in &mut bodies {
        previous.0 = *pose;
    }
}

/// Runs in `Update`: Bevy's `Transform` between the last two physics poses, by how far game
/// time has run past the last fixed step.
fn write_transforms(
    time: Res<Time<Fixed>>,
    mut bodies: Query<(&Pose, &PreviousPose, &mut Transform)>,
) {
    let alpha = Real::from(time.overstep_fraction());
    for (pose, previous, mut transform) in &mut bodies {
        let drawn = interpolate(&previous.0, pose, alpha);
        let t = drawn.translation;
        transform.translation =
            bevy_math::Vec3::new(to_f64(t.x) as f32, to_f64(t.y) as f32, to_f64(t.z) as f32);
        let q = drawn.rotation;
        transform.rotation = bevy_math::Quat::from_xyzw(
            to_f64(q.x) as f32,
            to_f64(q.y) as f32,
            to_f64(q.z) as f32,
            to_f64(q.w) as f32,
        );
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut app = App::new();
    app.add_plugins((TimePlugin, TumblePlugin::default()))
        .insert_resource(Time::<Fixed>::from_hz(60.0))
        .insert_resource(TimeUpdateStrategy::ManualDuration(Duration::from_millis(7)))
        .add_systems(
            FixedUpdate,
            (
                remember_poses.before(TumbleStep),
                fire_thrusters.in_set(PhysicsSet::Forces),
            ),
        )
        .add_systems(Update, write_transforms);
    let mass = MassProperties::solid_cuboid(Mass::new(200.0)?, Vec3::new(0.5, 0.5, 2.0))?;
    let ship = app
        .world_mut()
        .spawn((
            RigidBody,
            MassProps(mass),
            Pose::from_rotation(Quat::from_rotation_y(0.3)),
            ForceAccumulator::default(),
            PreviousPose::default(),
            Thruster(400.0),
            Transform::default(),
        ))
        .id();
    for frame in 1..=429_u32 {
        app.update();
        if frame.is_multiple_of(143) {
            let world = app.world();
            let game_time = world.resource::<Time<Fixed>>().elapsed_secs_f64();
            let drawn = world.get::<Transform>(ship).ok_or("no ship")?.translation;
            println!("fixed clock {game_time:.3} s: ship drawn at {drawn:.3}");
        }
    }
    // Drift–kick–drift is exact for a constant force along the ship's fixed axis: the ship's
    // centre is at ½ (F/m) t² along it, t the fixed clock's time.
    let world = app.world();
    let t = world.resource::<Time<Fixed>>().elapsed_secs_f64();
    let x = world.get::<Pose>(ship).ok_or("no ship")?.translation;
    let expected = 0.5 * (400.0 / 200.0) * t * t;
    let travelled = to_f64(x.length());
    if (travelled - expected).abs() > 1e-3 * expected {
        return Err(format!("travelled {travelled} m, expected {expected} m").into());
    }
    if !world.resource::<PhysicsErrors>().is_empty() {
        return Err("physics errors".into());
    }
    println!(
        "after {t:.3} s of fixed clock: {travelled:.4} m travelled (½ a t² = {expected:.4} m)"
    );
    Ok(())
}
