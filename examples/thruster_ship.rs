//! A thruster ship on a spring tether, in a variable-rate game loop with a fixed physics step.
//!
//! Frames arrive at an uneven rate (a 144 Hz display with an occasional 50 ms hitch); a
//! `FixedStepper` turns each frame's time into whole 1/60 s physics steps; game code fires the
//! ship's thruster (a force in the ship's own frame, at its tail) and, once, a sideways impulse;
//! a damped spring tethers the ship to a post; the renderer draws each body between the last two
//! physics states with `interpolate`. Run: `cargo run --release --example thruster_ship`.

use tumble::bevy_ecs::prelude::{Entity, World};
use tumble::math::{Real, Vec3, to_f64};
use tumble::prelude::*;

/// What the renderer needs of a body: its last two physics poses.
struct Rendered {
    body: Entity,
    previous: Pose,
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let dt: Real = 1.0 / 60.0;
    let mut world = World::new();
    world.insert_resource(PhysicsSettings::new(dt, Integrator::default())?);

    // A 500 kg ship, 4 m × 1 m × 1 m, tethered by its nose to a post at the origin.
    let mass = MassProperties::solid_cuboid(Mass::new(500.0)?, Vec3::new(2.0, 0.5, 0.5))?;
    let ship = world
        .spawn((
            RigidBody,
            MassProps(mass),
            Pose::from_translation(Vec3::new(10.0, 0.0, 0.0)),
            ForceAccumulator::default(),
        ))
        .id();
    world.spawn(
        Spring::new(
            ship,
            Vec3::new(2.0, 0.0, 0.0),
            SpringEnd::World(Vec3::ZERO),
            400.0,
            8.0,
        )
        .with_damping(300.0),
    );

    let mut physics = PhysicsRunner::new(&mut world);
    let mut stepper = FixedStepper::new(8)?;
    let mut rendered = Rendered {
        body: ship,
        previous: *world.get::<Pose>(ship).ok_or("no ship")?,
    };
    let (mut elapsed, mut sim_time, mut kicked) = (0.0_f64, 0.0_f64, false);
    let mut frame = 0_u32;
    while elapsed < 10.0 {
        // A 144 Hz display, with a 50 ms hitch every 200 frames.
        let frame_time = if frame % 200 == 199 {
            0.05
        } else {
            1.0 / 144.0
        };
        elapsed += frame_time;
        frame += 1;
        // Whole steps of the world's time step (its `PhysicsSettings`), however long the frame.
        let steps = stepper.advance(frame_time, world.resource::<PhysicsSettings>())?;
        for _ in 0..steps.steps {
            // Game code, once per physics step: the thruster pushes along the ship's own −x
            // axis from its tail for the first 6 s; one sideways kick at 3 s.
            let mut ship_entity = world.entity_mut(ship);
            if sim_time < 6.0 {
                ship_entity
                    .apply_local_force_at_local_point(Vec3::new(-900.0, 0.0, 0.0), Vec3::X * -2.0);
            }
            if sim_time >= 3.0 && !kicked {
                ship_entity.apply_linear_impulse(Vec3::new(0.0, 0.0, 250.0));
                kicked = true;
            }
            rendered.previous = *world.get::<Pose>(ship).ok_or("no ship")?;
            physics.step(&mut world);
            world.clear_trackers();
            sim_time += to_f64(world.resource::<PhysicsSettings>().dt());
        }
        // The renderer: between the last two physics states.
        let current = *world.get::<Pose>(rendered.body).ok_or("no ship")?;
        let drawn = interpolate(&rendered.previous, &current, steps.alpha);
        if frame.is_multiple_of(180) {
            println!(
                "t = {elapsed:5.2} s (physics {sim_time:5.2} s)  ship at {:.2}  (α = {:.2}, {} step(s))",
                drawn.translation, steps.alpha, steps.steps
            );
        }
    }
    let errors = world.resource::<PhysicsErrors>();
    if !errors.is_empty() {
        return Err(format!("physics errors: {errors:?}").into());
    }
    println!(
        "dropped by the step cap: {:.3} s; tether length now {:.2} m",
        stepper.dropped_time(),
        (world
            .get::<Pose>(ship)
            .ok_or("no ship")?
            .transform_point(Vec3::X * 2.0))
        .length()
    );
    Ok(())
}
