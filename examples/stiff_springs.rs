//! A spring far too stiff for the step (√(k/μ)Δt = 50 at 60 Hz) between two asymmetric bodies
//! at off-centre anchors: the default settings step it with the energy-conserving implicit
//! spring step, and the explicit step is shown failing (predicted, then quarantined).
//!
//! `cargo run --release --example stiff_springs`
use tumble::bevy_ecs::prelude::World;
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
            Transform {
                translation: Vec3::new(1.2, 0.0, 0.0),
                rotation: Quat::from_rotation_z(0.3),
            },
        ))
        .id();
    world.spawn(Spring {
        a,
        anchor_a: Vec3::new(0.1, 0.05, 0.0),
        b: SpringEnd::Body {
            body: b,
            anchor: Vec3::new(-0.1, 0.0, 0.05),
        },
        // √(k/μ)Δt = 50 with μ = ½.
        stiffness: 0.5 * (50.0 / DT).powi(2),
        damping: 0.0,
        rest_length: 0.8,
    });
    Ok(world)
}

/// Kinetic + elastic energy (J).
fn energy(world: &mut World) -> f64 {
    let kinetic: f64 = world
        .query::<(&Transform, &Velocity, &MassProps)>()
        .iter(world)
        .map(|(t, v, m)| tumble::ecs::components::kinetic_energy_f64(t, v, m))
        .sum();
    let springs: Vec<Spring> = world.query::<&Spring>().iter(world).copied().collect();
    let mut poses = world.query::<&Transform>();
    let elastic: f64 = springs
        .iter()
        .filter_map(|s| {
            let pa = poses.get(world, s.a).ok()?.transform_point(s.anchor_a);
            let SpringEnd::Body { body, anchor } = s.b else {
                return None;
            };
            let pb = poses.get(world, body).ok()?.transform_point(anchor);
            Some(s.elastic_energy(pa, pb))
        })
        .sum();
    kinetic + elastic
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
