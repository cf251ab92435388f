//! Bodies made from parry3d shapes and a density: mass properties are computed by parry,
//! then each body is spun about its middle principal axis and stepped for 1 s.
// Only `main` differs in an `f64` build with parry3d's `f32` shapes, which leaves these unused.
#![cfg_attr(
    all(feature = "f64", not(feature = "parry-f64")),
    allow(unused_imports)
)]

use tumble::bevy_ecs::prelude::World;
use tumble::math::{Quat, Real, Vec3};

use tumble::parry::shape::{Ball, Capsule, Cone, ConvexPolyhedron, Cuboid, Cylinder, Shape};
use tumble::prelude::*;

#[cfg(all(feature = "f64", not(feature = "parry-f64")))]
fn main() {
    eprintln!("this example builds shapes from tumble's vectors: run it in f32 or with parry-f64");
}

#[cfg(any(not(feature = "f64"), feature = "parry-f64"))]
fn main() -> Result<(), Box<dyn std::error::Error>> {
    let steel = Density::new(7850.0)?;
    let hull = ConvexPolyhedron::from_convex_hull(&[
        Vec3::ZERO,
        Vec3::X,
        Vec3::Y,
        Vec3::Z,
        Vec3::new(0.3, 0.3, 0.3),
    ])
    .ok_or("degenerate hull")?;
    let shapes: Vec<(&str, Box<dyn Shape>)> = vec![
        ("ball", Box::new(Ball::new(0.1))),
        ("cuboid", Box::new(Cuboid::new(Vec3::new(0.2, 0.05, 0.02)))),
        ("capsule", Box::new(Capsule::new_y(0.1, 0.05))),
        ("cylinder", Box::new(Cylinder::new(0.1, 0.05))),
        ("cone", Box::new(Cone::new(0.1, 0.05))),
        ("hull", Box::new(hull)),
    ];
    let mut world = World::new();
    world.insert_resource(PhysicsSettings::new(
        1.0 / 120.0,
        Integrator::SymplecticEuler,
    )?);
    let mut bodies = Vec::new();
    for (i, (name, shape)) in shapes.iter().enumerate() {
        let mass = mass_properties_of(shape.as_ref(), steel)?;
        println!(
            "{name:>8}: m = {:8.3} kg  I_b = {:.5}  com = {:.3}",
            mass.mass(),
            mass.principal_inertia(),
            mass.local_center_of_mass()
        );
        // Spin about the middle principal axis (world frame): a Dzhanibekov-style tumble.
        let axis = mass.principal_frame() * Vec3::Y;
        let entity = world
            .spawn((RigidBody, MassProps(mass)))
            .insert(Pose::from_translation(Vec3::new(i as Real, 0.0, 0.0)))
            .insert(Velocity::angular(axis * 6.0 + Vec3::splat(0.01)))
            .id();
        bodies.push((name, entity));
    }
    let mut physics = PhysicsRunner::new(&mut world);
    for _ in 0..120 {
        physics.step(&mut world);
        world.clear_trackers();
    }
    for (name, entity) in bodies {
        let t = world.get::<Pose>(entity).ok_or("body vanished")?;
        let angle = t.rotation.angle_between(Quat::IDENTITY);
        println!(
            "{name:>8}: x = {:.3}  rotated by {:.3} rad",
            t.translation, angle
        );
    }
    Ok(())
}
