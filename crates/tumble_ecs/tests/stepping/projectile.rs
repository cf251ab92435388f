//! Symplectic Euler under constant gravity follows the discrete formula
//! `x_n = x₀ + v₀ nΔt + g Δt² n(n+1)/2` (kick before drift), to f32 round-off.

use bevy_ecs::prelude::*;
use glam::DVec3;
use tumble_core::math::{Real, Vec3, Widen, to_f64};
use tumble_ecs::prelude::*;

use super::util::{mass_props, rel, run, world_with};

fn discrete_position(x0: DVec3, v0: DVec3, g: DVec3, dt: f64, n: f64) -> DVec3 {
    x0 + v0 * (n * dt) + g * (dt * dt * n * (n + 1.0) / 2.0)
}

fn check_projectile(with_accumulator: bool) {
    let dt = 1.0 / 60.0 as Real;
    let g = Vec3::new(0.3, -9.81, 0.1);
    let x0 = Vec3::new(1.0, 100.0, -2.0);
    let v0 = Vec3::new(3.0, 20.0, -1.5);
    let mut world = world_with(dt, Integrator::SymplecticEuler);
    world.insert_resource(Gravity(g));
    let mut body = world.spawn((
        RigidBody,
        mass_props(2.5, [1.0, 2.0, 3.0]),
        Pose::from_translation(x0),
        Velocity::linear(v0),
    ));
    if with_accumulator {
        body.insert(ForceAccumulator::default());
    }
    let id = body.id();
    let mut physics = PhysicsRunner::new(&mut world);
    for n in 1..=600u32 {
        physics.step(&mut world);
        world.clear_trackers();
        if n % 50 == 0 {
            let x = world.get::<Pose>(id).unwrap().translation.widen();
            let exact = discrete_position(x0.widen(), v0.widen(), g.widen(), to_f64(dt), to_f64(n));
            // f32 round-off: ~n ε per coordinate in the worst case, far below 1e-5.
            let err = (x - exact).length() / exact.length();
            assert!(err < 1e-5, "step {n}: |x − x_exact|/|x_exact| = {err:e}");
            let v = world.get::<Velocity>(id).unwrap().linear.widen();
            let v_exact = v0.widen() + g.widen() * (to_f64(dt) * to_f64(n));
            assert!(rel(v.y, v_exact.y) < 1e-5, "vy {} vs {}", v.y, v_exact.y);
        }
    }
}

#[test]
fn projectile_matches_discrete_formula_with_accumulator() {
    check_projectile(true);
}

#[test]
fn projectile_matches_discrete_formula_without_accumulator() {
    check_projectile(false);
}

#[test]
fn gravity_scale_scales_the_fall() {
    let dt = 0.01;
    let mut world = world_with(dt, Integrator::SymplecticEuler);
    world.insert_resource(Gravity(Vec3::new(0.0, -10.0, 0.0)));
    let half = world
        .spawn((RigidBody, GravityScale(0.5), ForceAccumulator::default()))
        .id();
    let none = world.spawn((RigidBody, GravityScale(0.0))).id();
    let full = world.spawn(RigidBody).id();
    run(&mut world, 100);
    let y = |e: Entity| to_f64(world.get::<Pose>(e).unwrap().translation.y);
    let full_y = -10.0 * 0.01 * 0.01 * 100.0 * 101.0 / 2.0;
    assert!(rel(y(full), full_y) < 1e-5);
    assert!(rel(y(half), 0.5 * full_y) < 1e-5);
    assert_eq!(y(none), 0.0);
}

#[test]
fn drift_kick_drift_is_exact_for_constant_gravity() {
    // splitting samples forces at the midpoint: x_n = x₀ + v₀ t + ½ g t² with no Δt bias.
    for integrator in [Integrator::Splitting, Integrator::Yoshida4, Integrator::Rk4] {
        let dt = 1.0 / 60.0 as Real;
        let g = Vec3::new(0.0, -9.81, 0.0);
        let (x0, v0) = (Vec3::new(0.0, 50.0, 0.0), Vec3::new(4.0, 10.0, 0.0));
        let mut world = world_with(dt, integrator);
        world.insert_resource(Gravity(g));
        let with_acc = world
            .spawn((
                RigidBody,
                Pose::from_translation(x0),
                Velocity::linear(v0),
                ForceAccumulator::default(),
            ))
            .id();
        let without_acc = world
            .spawn((RigidBody, Pose::from_translation(x0), Velocity::linear(v0)))
            .id();
        let mut physics = PhysicsRunner::new(&mut world);
        let plan = physics.plan();
        assert!(
            plan.contains(PhysicsSystem::BeginStage),
            "{integrator}: {plan}"
        );
        let n = 600;
        for _ in 0..n {
            physics.step(&mut world);
        }
        let t = to_f64(dt) * to_f64(n);
        let exact = x0.widen() + v0.widen() * t + 0.5 * g.widen() * t * t;
        for id in [with_acc, without_acc] {
            let x = world.get::<Pose>(id).unwrap().translation.widen();
            let err = (x - exact).length() / exact.length();
            assert!(
                err < 1e-5,
                "{integrator}: relative error {err:e} at {x} vs {exact}"
            );
        }
    }
}
