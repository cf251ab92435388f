//! Steps of several stages through the ECS: the rule for loads game code adds before a step,
//! and game force systems sampled in every stage. (The composition's order, reversibility and
//! the substeps' bit identity are measured on the report's forced linkage, in
//! `crates/tumble_report/tests/linkage.rs`.)

use std::num::NonZeroU32;

use tumble::bevy_ecs::prelude::*;
use tumble::math::{Real, Vec3};
use tumble::prelude::*;

/// A load game code adds before a step of several stages is held over the whole step: its
/// impulse is `F Δt` (not `F Δt` per stage, nor only the first stage's share), and drift–kick–
/// drift integrates a constant force exactly, so `x = ½ (F/m) Δt²`.
#[test]
fn a_load_added_before_a_step_of_several_stages_is_applied_once() {
    for (integrator, substeps) in crate::several_stages::SEVERAL_STAGES {
        let dt: Real = 0.1;
        let mut w = World::new();
        w.insert_resource(
            PhysicsSettings::new(dt, integrator)
                .unwrap()
                .with_substeps(NonZeroU32::new(substeps).unwrap())
                .unwrap(),
        );
        let mass = MassProperties::new(Mass::new(2.0).unwrap(), Vec3::new(1.0, 2.0, 3.0)).unwrap();
        let body = w
            .spawn((RigidBody, MassProps(mass), ForceAccumulator::default()))
            .id();
        let mut physics = PhysicsRunner::new(&mut w);
        let (force, torque) = (Vec3::new(4.0, 0.0, -2.0), Vec3::new(0.0, 0.6, 0.0));
        let mut acc = w.get_mut::<ForceAccumulator>(body).unwrap();
        acc.add_force(force);
        acc.add_torque(torque);
        physics.step(&mut w);
        let label = format!("{integrator} × {substeps}");
        let v = w.get::<Velocity>(body).unwrap();
        let tol = 16.0 * Real::EPSILON;
        assert!(
            (v.linear - force * dt / 2.0).length() < tol,
            "{label}: {v:?}"
        );
        // L = τ Δt (the rotation under way turns ω, not L).
        let t = *w.get::<Pose>(body).unwrap();
        let l = mass.world_inertia_mul(t.rotation, v.angular);
        assert!((l - torque * dt).length() < tol, "{label}: L = {l}");
        let x = t.translation;
        assert!(
            (x - force / 2.0 * dt * dt / 2.0).length() < tol,
            "{label}: x = {x}"
        );
        assert_eq!(
            *w.get::<ForceAccumulator>(body).unwrap(),
            ForceAccumulator::default()
        );
        // The next step has no load: the velocity stays.
        physics.step(&mut w);
        let v2 = w.get::<Velocity>(body).unwrap().linear;
        assert!((v2 - force * dt / 2.0).length() < tol, "{label}: {v2}");
    }
}

#[derive(Resource, Default)]
struct Samples(Vec<Real>);

/// Game code's own force system, in `PhysicsSet::Forces`: records the time it is sampled at
/// (from the body's position, which moves at 1 m/s) and pushes.
fn sample(mut samples: ResMut<Samples>, mut bodies: Query<(&Pose, &mut ForceAccumulator)>) {
    for (t, mut acc) in &mut bodies {
        samples.0.push(t.translation.x);
        acc.add_force(Vec3::Y);
    }
}

/// The force stage, game systems in `PhysicsSet::Forces` included, runs in every stage, on the
/// state of that stage: at the midpoint of each of the `N` substeps.
#[test]
fn game_force_systems_run_in_every_stage_on_its_state() {
    let dt: Real = 0.4;
    let mut w = World::new();
    w.insert_resource(
        PhysicsSettings::new(dt, Integrator::Splitting)
            .unwrap()
            .with_substeps(NonZeroU32::new(4).unwrap())
            .unwrap(),
    );
    w.init_resource::<Samples>();
    let body = w
        .spawn((
            RigidBody,
            Velocity::linear(Vec3::X),
            ForceAccumulator::default(),
        ))
        .id();
    let mut forces = ForceSystems::default();
    forces.add(sample);
    w.insert_resource(forces);
    let mut physics = PhysicsRunner::new(&mut w);
    assert_eq!(physics.plan().runs_per_step(), 4);
    physics.step(&mut w);
    let samples = &w.resource::<Samples>().0;
    let midpoints = [0.05, 0.15, 0.25, 0.35];
    assert_eq!(samples.len(), 4, "{samples:?}");
    for (x, m) in samples.iter().zip(midpoints) {
        assert!((x - m).abs() < 1e-6, "{samples:?}");
    }
    // The pushes act for their stage only: Σ h F = Δt F in total.
    let v = w.get::<Velocity>(body).unwrap().linear;
    assert!((v.y - dt).abs() < 1e-6, "{v}");
}

/// Through [`PhysicsRunner`], game force systems live in the [`ForceSystems`] resource: they
/// run in every stage, and a re-plan (the world gains gravity) keeps them.
#[test]
fn the_runner_keeps_game_force_systems_across_re_plans() {
    let mut w = World::new();
    w.insert_resource(
        PhysicsSettings::new(0.4, Integrator::Yoshida4)
            .unwrap()
            .with_substeps(NonZeroU32::new(2).unwrap())
            .unwrap(),
    );
    w.init_resource::<Samples>();
    let mut forces = ForceSystems::default();
    forces.add(sample);
    w.insert_resource(forces);
    w.spawn((
        RigidBody,
        Velocity::linear(Vec3::X),
        ForceAccumulator::default(),
    ));
    let mut physics = PhysicsRunner::new(&mut w);
    physics.step(&mut w);
    w.clear_trackers();
    assert_eq!(w.resource::<Samples>().0.len(), 6, "2 substeps × 3 stages");
    w.insert_resource(Gravity::EARTH_Y_DOWN);
    physics.step(&mut w);
    assert_eq!(physics.replans(), 1);
    assert_eq!(w.resource::<Samples>().0.len(), 12);
}
