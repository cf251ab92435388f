//! The predicted stable region agrees with what actually happens: a warning where the run
//! diverges, none where it stays bounded.

use tumble::bevy_ecs::prelude::*;
use tumble::math::{Real, Vec3};

use tumble::core::springs::ImplicitSpringError;
use tumble::prelude::*;

fn spring_world(omega_dt: Real, integrator: Integrator, springs: SpringSolver) -> (World, Entity) {
    let (dt, m) = (1.0 / 60.0 as Real, 2.0 as Real);
    let k = m * (omega_dt / dt).powi(2);
    let mut world = World::new();
    world.insert_resource(
        PhysicsSettings::new(dt, integrator)
            .unwrap()
            .with_springs(springs),
    );
    let body = world
        .spawn((
            RigidBody,
            MassProps(MassProperties::solid_sphere(Mass::new(m).unwrap(), 0.1).unwrap()),
            Pose::from_translation(Vec3::new(1.0, 0.0, 0.0)),
        ))
        .id();
    world.spawn(Spring::new(
        body,
        Vec3::ZERO,
        SpringEnd::World(Vec3::ZERO),
        k,
        0.0,
    ));
    (world, body)
}

fn diverges(world: &mut World, body: Entity, steps: usize) -> bool {
    let mut physics = PhysicsRunner::new(world);
    for _ in 0..steps {
        physics.step(world);
        let x = world.get::<Pose>(body).unwrap().translation.length();
        if world.get::<Rejected>(body).is_some() || x > 1e3 {
            return true;
        }
    }
    false
}

#[test]
fn spring_warning_matches_divergence() {
    for integrator in [
        Integrator::SymplecticEuler,
        Integrator::Splitting,
        Integrator::Lclamp,
    ] {
        for omega_dt in [0.5 as Real, 1.5, 1.95, 2.05, 2.5] {
            let (mut world, body) = spring_world(omega_dt, integrator, SpringSolver::Explicit);
            let warned = check_stability(&mut world)
                .iter()
                .any(|w| matches!(w, StabilityWarning::StiffSpring { .. }));
            let blew_up = diverges(&mut world, body, 2000);
            assert_eq!(
                warned, blew_up,
                "{integrator} at ωΔt = {omega_dt}: warned {warned}, diverged {blew_up}"
            );
            assert_eq!(warned, omega_dt >= 2.0);
            // By default the stiff ones take the implicit step: no instability, no divergence,
            // and one warning that says the implicit solve steps them. A first-order method
            // cannot be combined with it: one refusal, and the step refuses the group (the body
            // is quarantined, with its state kept).
            let (mut world, body) = spring_world(omega_dt, integrator, SpringSolver::Auto);
            let warnings = check_stability(&mut world);
            if integrator.turns_at_constant_momentum() {
                assert!(warnings.iter().all(|w| !w.is_instability()), "{warnings:?}");
                let implicit = warnings.iter().any(|w| {
                    matches!(w, StabilityWarning::ImplicitGroups { integrator: i, .. } if *i == integrator)
                });
                assert_eq!(implicit, !warnings.is_empty(), "{warnings:?}");
                assert!(
                    !diverges(&mut world, body, 2000),
                    "{integrator} at ωΔt = {omega_dt}"
                );
            } else {
                assert!(
                    matches!(
                        warnings[..],
                        [StabilityWarning::CannotCombine { integrator: i, bodies: 1, .. }]
                            if i == integrator
                    ),
                    "{warnings:?}"
                );
                assert!(warnings[0].is_instability());
                let start = *world.get::<Pose>(body).unwrap();
                PhysicsRunner::new(&mut world).step(&mut world);
                let errors = world.resource::<PhysicsErrors>();
                assert!(
                    errors.bodies.iter().any(|e| e.entity == body
                        && e.kind
                            == BodyErrorKind::ImplicitSprings(
                                ImplicitSpringError::CannotCombine { integrator }
                            )),
                    "{errors:?}"
                );
                assert_eq!(*world.get::<Pose>(body).unwrap(), start);
            }
        }
    }
}

#[test]
fn explicit_gyroscopic_warning_matches_divergence() {
    let mass = MassProperties::new(Mass::new(1.0).unwrap(), Vec3::new(1.0, 2.0, 3.0)).unwrap();
    for (rate, integrator) in [
        (20.0, Integrator::SymplecticEuler),
        (20.0, Integrator::SymplecticEulerLinear),
        (0.5, Integrator::SymplecticEuler),
        (20.0, Integrator::Splitting),
    ] {
        let mut world = World::new();
        world.insert_resource(PhysicsSettings::new(1.0 / 60.0, integrator).unwrap());
        let body = world
            .spawn((
                RigidBody,
                MassProps(mass),
                Velocity::angular(Vec3::new(0.1, 0.1, rate)),
            ))
            .id();
        let warnings = check_stability(&mut world);
        let predicted = warnings.iter().find_map(|w| match *w {
            StabilityWarning::ExplicitGyroscopic {
                body: b, seconds, ..
            } if b == body => Some(seconds),
            _ => None,
        });
        // Run for 60 s of game time.
        let blew_up = diverges(&mut world, body, 3600);
        match predicted {
            Some(seconds) => {
                assert!(
                    blew_up,
                    "{integrator} {rate}: predicted {seconds} s, stayed finite"
                );
                assert!(seconds < 60.0, "{integrator} {rate}: predicted {seconds} s");
                let text = warnings[0].to_string();
                assert!(text.contains(integrator.name()) && text.contains(&body.to_string()));
            }
            None => assert!(!blew_up, "{integrator} {rate}: diverged without a warning"),
        }
    }
}
