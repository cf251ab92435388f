//! A headless game loop: a plain `World`, one tumbling box under gravity, 2 s at 60 Hz.
use tumble::bevy_ecs::prelude::World;
use tumble::math::{Real, Vec3};

use tumble::prelude::*;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut world = World::new();
    world.insert_resource(PhysicsSettings::new(1.0 / 60.0, Integrator::default())?);
    world.insert_resource(Gravity(Vec3::new(0.0, -9.81, 0.0)));
    let mass = MassProperties::solid_cuboid(Mass::new(2.0)?, Vec3::new(0.5, 0.1, 0.02))?;
    let body = world
        .spawn((RigidBody, MassProps(mass), ForceAccumulator::default()))
        .insert(Velocity {
            linear: Vec3::new(3.0, 5.0, 0.0),
            angular: Vec3::new(0.1, 4.0, 0.1),
        })
        .id();
    let mut physics = PhysicsRunner::new(&mut world);
    for step in 1..=120 {
        physics.step(&mut world);
        world.clear_trackers();
        if step % 30 == 0 {
            let t = world.get::<Pose>(body).ok_or("body vanished")?;
            println!(
                "t = {:.2} s  x = {:.3}  q = {:.3}",
                step as Real / 60.0,
                t.translation,
                t.rotation
            );
        }
    }
    Ok(())
}
