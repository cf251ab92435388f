//! A spring far too stiff for the step (√(k/μ)Δt = 50 at 60 Hz) between two asymmetric bodies
//! at off-centre anchors: the default settings step it with the energy-conserving implicit
//! spring step, and the explicit step is shown failing (predicted, then quarantined).
//!
//! `cargo run --release --example stiff_springs`
use tumble::bevy_ecs::prelude::World;
use tumble::ecs::forces::kinetic_and_elastic_energy as energy;
use tumble::math::{Quat, Real, Vec3};

use tumble::prelude::*;

const DT: Real = 1.0 / 60.0;

/// Two unit masses joined by the spring, the spring stretched 20 %.
fn world(springs: SpringSolver) -> Result<World, Box<dyn std::error::Error>> {
    let mut world = World::new();
    world.insert_resource(PhysicsSettings::new(DT, Integrator::default())?.with_springs(springs));
    let mass = MassProperties::new(Mass::new(1.0)?, Vec3::new(0.02, 0.03, 0.04))?;
    let a = world.spawn((RigidBody, MassProps(mass))).id();
    let b = world
        .spawn((
            RigidBody,
            MassProps(mass),
            Pose {
                translation: Vec3::new(1.2, 0.0, 0.0),
                rotation: Quat::from_rotation_z(0.3),
            },
        ))
        .id();
    // √(k/μ)Δt = 50 with μ = ½.
    let k = 0.5 * (50.0 / DT).powi(2);
    let end = SpringEnd::on_body(b, Vec3::new(-0.1, 0.0, 0.05));
    world.spawn(Spring::new(a, Vec3::new(0.1, 0.05, 0.0), end, k, 0.8));
    Ok(world)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    for springs in [SpringSolver::Auto, SpringSolver::Explicit] {
        let mut world = world(springs)?;
        let warnings = check_stability(&mut world);
        println!(
            "springs = {springs}: {} stability warning(s)",
            warnings.len()
        );
        for warning in &warnings {
            println!("  {warning}");
        }
        let e0 = energy(&mut world);
        let mut physics = PhysicsRunner::new(&mut world);
        println!("  plan: {}", physics.plan());
        for step in 1..=600 {
            physics.step(&mut world);
            world.clear_trackers();
            if step % 150 == 0 {
                let rejected = world.query::<&Rejected>().iter(&world).count();
                let e = energy(&mut world);
                println!(
                    "  t = {:4.1} s  E/E₀ − 1 = {:+.2e}  rejected bodies: {rejected}",
                    step as Real * DT,
                    (e - e0) / e0
                );
            }
        }
    }
    Ok(())
}
