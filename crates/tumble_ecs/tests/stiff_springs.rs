//! Stiff springs through the whole step (default settings): a two-body spring and a chain of
//! asymmetric bodies at off-centre anchors keep their total energy at every `ωΔt` from 0.5 to
//! 100, without numerical damping; the choice of method is the planner's, and can be forced.

mod common;
#[path = "common/stages.rs"]
mod stages;

use bevy_ecs::prelude::*;
use tumble_core::math::{Quat, Real, Vec3, to_f64};
use tumble_core::{Mass, MassProperties};
use tumble_ecs::components::SpringTurn;
use tumble_ecs::forces::kinetic_and_elastic_energy as energy;
use tumble_ecs::prelude::*;

const DT: Real = 1.0 / 60.0;

use common::unit_body as body;

/// Two unit masses (asymmetric, off-centre anchors), stiffness from the nominal
/// `√(k/μ)Δt = omega_dt` with `μ = ½`, stretched 20 % past the rest length and spinning.
fn two_bodies(world: &mut World, omega_dt: Real) {
    let inertia = Vec3::new(0.02, 0.03, 0.04);
    let a = body(
        world,
        Vec3::ZERO,
        Quat::IDENTITY,
        inertia,
        Vec3::ZERO,
        Vec3::new(0.3, 0.2, 0.1),
    );
    let b = body(
        world,
        Vec3::new(1.2, 0.0, 0.0),
        Quat::from_rotation_z(0.2),
        inertia,
        Vec3::new(0.0, 0.1, 0.0),
        Vec3::new(-0.1, 0.0, 0.4),
    );
    let b = SpringEnd::on_body(b, Vec3::new(-0.1, 0.0, 0.05));
    let k = 0.5 * (omega_dt / DT).powi(2);
    world.spawn(Spring::new(a, Vec3::new(0.1, 0.05, 0.0), b, k, 0.8));
}

/// A chain of `n` asymmetric bodies at off-centre anchors, the first tied to the world, each
/// spring stretched 10 %.
fn chain(world: &mut World, n: usize, omega_dt: Real) {
    let inertia = Vec3::new(0.02, 0.03, 0.04);
    let k = 0.5 * (omega_dt / DT).powi(2);
    let bodies: Vec<Entity> = (0..n)
        .map(|i| {
            let x = i as Real;
            body(
                world,
                Vec3::new(x, 0.02 * x, 0.0),
                Quat::from_rotation_z(0.1 * x),
                inertia,
                Vec3::new(0.0, 0.05, 0.0),
                Vec3::new(0.2, -0.1, 0.3),
            )
        })
        .collect();
    let next = (Vec3::new(-0.1, -0.05, 0.02), 0.72);
    common::tie_chain(world, &bodies, Vec3::new(-1.0, 0.0, 0.0), k, next);
}

/// Runs `steps` steps with default settings; returns (max |E − E₀|/E₀, final (E − E₀)/E₀, plan).
fn run(build: impl Fn(&mut World), steps: usize) -> (f64, f64, String) {
    let mut world = World::new();
    world.insert_resource(Parallelism::SINGLE_THREAD);
    build(&mut world);
    let e0 = energy(&mut world);
    let mut physics = PhysicsRunner::new(&mut world);
    let mut worst: f64 = 0.0;
    let mut last = 0.0;
    for _ in 0..steps {
        physics.step(&mut world);
        let e = energy(&mut world);
        assert!(e.is_finite());
        last = (e - e0) / e0;
        worst = worst.max(last.abs());
    }
    let errors = world
        .get_resource::<PhysicsErrors>()
        .map(|e| e.bodies.clone());
    assert!(errors.as_ref().is_none_or(Vec::is_empty), "{errors:?}");
    for t in world.query::<&Pose>().iter(&world) {
        assert!((t.rotation.length() - 1.0).abs() < 1e-5);
    }
    (worst, last, physics.plan().to_string())
}

/// The bound: energy within 5 % at every step and at the end, at every `ωΔt`.
#[test]
fn stiff_springs_keep_their_energy_at_every_omega_dt() {
    for omega_dt in [0.5, 1.0, 2.0, 5.0, 10.0, 30.0, 100.0] {
        // Fewer steps where each step needs many Newton iterations (debug build).
        let steps = if omega_dt >= 30.0 { 60 } else { 300 };
        for (name, n) in [("two bodies", 0), ("chain", 6)] {
            let (worst, last, plan) = if n == 0 {
                run(|w| two_bodies(w, omega_dt), steps)
            } else {
                run(|w| chain(w, n, omega_dt), steps)
            };
            eprintln!("{name} ωΔt {omega_dt}: max {worst:.2e}, final {last:.2e}, plan {plan}");
            assert!(
                plan.contains("solve_implicit_springs"),
                "{name} ωΔt {omega_dt}: {plan}"
            );
            assert!(
                !plan.contains("begin_stage"),
                "nothing is left for the explicit path: {plan}"
            );
            assert!(
                worst <= 0.05 && last.abs() <= 0.05,
                "{name} ωΔt {omega_dt}: {worst} {last}"
            );
        }
    }
}

/// The implicit spring step composes with substeps and with `yoshida4`'s composition (its
/// backward stage included): a stiff chain keeps its energy within the same 5 %.
#[test]
fn stiff_springs_keep_their_energy_in_steps_of_several_stages() {
    for (integrator, substeps) in stages::SEVERAL_STAGES {
        for omega_dt in [10.0, 100.0] {
            let settings = PhysicsSettings::new(DT, integrator)
                .unwrap()
                .with_substeps(std::num::NonZeroU32::new(substeps).unwrap())
                .unwrap();
            let (worst, last, plan) = run(
                |w| {
                    w.insert_resource(settings);
                    chain(w, 6, omega_dt);
                },
                60,
            );
            eprintln!(
                "{integrator} × {substeps}, ωΔt {omega_dt}: max {worst:.2e}, final {last:.2e}"
            );
            assert!(plan.contains("solve_implicit_springs"), "{plan}");
            assert!(
                worst <= 0.05 && last.abs() <= 0.05,
                "{integrator} × {substeps}, ωΔt {omega_dt}: {worst} {last}"
            );
        }
    }
}

/// Soft springs stay on the explicit path (they pay nothing), `explicit` forces it and is then
/// predicted unstable where it is, and `implicit` forces the implicit step.
#[test]
fn the_planner_picks_the_spring_method_and_can_be_overridden() {
    let plan = |omega_dt: Real, springs: SpringSolver| {
        let mut world = World::new();
        world.insert_resource(PhysicsSettings::default().with_springs(springs));
        two_bodies(&mut world, omega_dt);
        let plan = PhysicsPlan::for_world(&mut world);
        let warned = check_stability(&mut world)
            .iter()
            .any(|w| matches!(w, StabilityWarning::StiffSpring { .. }));
        (
            plan.contains(PhysicsSystem::SolveImplicitSprings),
            plan.contains(PhysicsSystem::Springs),
            warned,
        )
    };
    // The soft spring: nominal 0.05, with the lever arms still below the threshold.
    assert_eq!(plan(0.05, SpringSolver::Auto), (false, true, false));
    // An implicit world plans no explicit spring system at all.
    assert_eq!(plan(0.05, SpringSolver::Implicit), (true, false, false));
    assert_eq!(plan(5.0, SpringSolver::Auto), (true, false, false));
    assert_eq!(plan(5.0, SpringSolver::Explicit), (false, true, true));
}

/// A body pulled by many springs vibrates faster than any one of them: a point mass held by
/// `n` springs to world points, each soft on its own (`√(k/m)Δt = 0.2`, below the 0.3 threshold),
/// moves at `√n` times that along their common axis. The planner counts a body's springs
/// together: one spring stays explicit, eight make the group implicit.
/// A spring too stiff for the precision (`k/μ` past its largest number on light bodies) is
/// still predicted, from `f64`, and its warning gives a number, never `inf`.
#[test]
fn a_spring_past_the_precision_is_predicted_with_a_number() {
    let mut world = World::new();
    world.insert_resource(PhysicsSettings::default().with_springs(SpringSolver::Explicit));
    let tiny = Real::MIN_POSITIVE * 16.0;
    let mass = MassProperties::new(Mass::new(tiny).unwrap(), Vec3::splat(1.0)).unwrap();
    let spawn = |world: &mut World, x: Real| {
        world
            .spawn((
                RigidBody,
                MassProps(mass),
                Pose::from_translation(Vec3::new(x, 0.0, 0.0)),
                Velocity::default(),
            ))
            .id()
    };
    let (a, b) = (spawn(&mut world, 0.0), spawn(&mut world, 1.0));
    let stiffness = Real::MAX / 2.0;
    world.spawn(Spring::new(
        a,
        Vec3::ZERO,
        SpringEnd::on_body(b, Vec3::ZERO),
        stiffness,
        1.0,
    ));
    let warnings = check_stability(&mut world);
    let stiff = warnings
        .iter()
        .find(|w| matches!(w, StabilityWarning::StiffSpring { .. }))
        .expect("predicted");
    let text = stiff.to_string();
    assert!(!text.contains("inf") && !text.contains("NaN"), "{text}");
    if tumble_core::math::DOUBLE_PRECISION {
        // `k/μ` past even f64's largest number.
        assert!(text.contains("or more"), "{text}");
    } else {
        // √(k/μ)Δt ≈ 7.1e35 (in f32, `k/μ` alone overflowed): a short number, not 36 digits.
        assert!(text.contains("= 7.089e35 ≥"), "{text}");
    }
    // A step so long that even that product passes the precision's largest number says so.
    let past = StabilityWarning::StiffSpring {
        spring: Entity::PLACEHOLDER,
        omega_dt: Real::MAX,
    };
    assert!(past.to_string().contains("or more"), "{past}");
}

#[test]
fn the_planner_counts_every_spring_on_a_body() {
    let implicit_with = |n: usize| {
        let mut world = World::new();
        world.insert_resource(PhysicsSettings::default());
        let hub = body(
            &mut world,
            Vec3::ZERO,
            Quat::IDENTITY,
            Vec3::splat(0.4),
            Vec3::ZERO,
            Vec3::ZERO,
        );
        let k = (0.2 / DT).powi(2);
        for i in 0..n {
            let angle = i as Real * 0.7;
            let end = SpringEnd::World(Vec3::new(angle.cos(), angle.sin(), 0.0));
            world.spawn(Spring::new(hub, Vec3::ZERO, end, k, 0.5));
        }
        PhysicsPlan::for_world(&mut world).contains(PhysicsSystem::SolveImplicitSprings)
    };
    assert!(!implicit_with(1), "one soft spring stays explicit");
    assert!(
        implicit_with(8),
        "eight of them on one body are stiff together"
    );
}

/// A small cloth (a grid joined by springs to its neighbours, two corners held) falling under
/// gravity at `ωΔt = 10`: finite, and its total energy (kinetic + elastic + gravity potential)
/// does not grow: the implicit step conserves it, so only round-off may add to it.
#[test]
fn a_stiff_cloth_falls_without_making_energy() {
    let (n, spacing, m) = (6, 0.1 as Real, 0.01 as Real);
    let k = 0.5 * m * (10.0 / DT).powi(2);
    let mut world = World::new();
    world.insert_resource(Parallelism::SINGLE_THREAD);
    world.insert_resource(Gravity::EARTH_Y_DOWN);
    let inertia = Vec3::splat(0.4 * m * 0.02 * 0.02);
    let mut grid = Vec::new();
    for i in 0..n {
        for j in 0..n {
            let mass = MassProperties::new(Mass::new(m).unwrap(), inertia).unwrap();
            grid.push(
                world
                    .spawn((
                        RigidBody,
                        MassProps(mass),
                        Pose::from_translation(Vec3::new(
                            i as Real * spacing,
                            0.0,
                            j as Real * spacing,
                        )),
                    ))
                    .id(),
            );
        }
    }
    let link = |world: &mut World, a: Entity, b: SpringEnd, rest: Real| {
        world.spawn(Spring::new(a, Vec3::ZERO, b, k, rest));
    };
    let node = |c: usize| SpringEnd::on_body(grid[c], Vec3::ZERO);
    for (c, &here) in grid.iter().enumerate() {
        // Node (i, j) = c: to (i + 1, j), then to (i, j + 1).
        if c / n + 1 < n {
            link(&mut world, here, node(c + n), spacing);
        }
        if c % n + 1 < n {
            link(&mut world, here, node(c + 1), spacing);
        }
    }
    for i in [0, n - 1] {
        let p = Vec3::new(i as Real * spacing, 0.0, 0.0);
        link(&mut world, grid[i * n], SpringEnd::World(p), 0.0);
    }
    let total = |world: &mut World| {
        let g = world.resource::<Gravity>().0;
        let potential: f64 = world
            .query::<(&Pose, &MassProps)>()
            .iter(world)
            .map(|(t, mp)| -to_f64(mp.mass()) * to_f64(g.dot(t.translation)))
            .sum();
        energy(world) + potential
    };
    let e0 = total(&mut world);
    let mut physics = PhysicsRunner::new(&mut world);
    assert!(physics.plan().contains(PhysicsSystem::SolveImplicitSprings));
    let mut lowest: Real = 0.0;
    for _ in 0..60 {
        physics.step(&mut world);
        let e = total(&mut world);
        // Round-off: the f32 state rounds positions by ε|x| per step; the springs' energy moves
        // by k |stretch| ε |x| for each, far below 1e-6 J here.
        assert!(e <= e0 + 1e-6, "energy grew: {e} > {e0}");
        for t in world.query::<&Pose>().iter(&world) {
            assert!(t.translation.is_finite());
            lowest = lowest.min(t.translation.y);
        }
    }
    assert!(lowest < -0.1, "the cloth fell: lowest y {lowest}");
}

/// The classification puts on each body how fast its springs can turn it,
/// `ω_turn = √(Σ k c)` with `c` each end's turning compliance, and nothing on a body held at its
/// centre of mass; the rate follows a spring added later.
#[test]
fn each_body_carries_how_fast_its_springs_turn_it() {
    let mut world = World::new();
    world.insert_resource(PhysicsSettings::new(DT, Integrator::Splitting).unwrap());
    let inertia = Vec3::new(0.02, 0.03, 0.04);
    let off = body(
        &mut world,
        Vec3::ZERO,
        Quat::IDENTITY,
        inertia,
        Vec3::ZERO,
        Vec3::ZERO,
    );
    let centred = body(
        &mut world,
        Vec3::new(1.0, 0.0, 0.0),
        Quat::IDENTITY,
        inertia,
        Vec3::ZERO,
        Vec3::ZERO,
    );
    let arm = Vec3::new(0.1, 0.05, 0.0);
    let k = 200.0;
    world.spawn(Spring::new(
        off,
        arm,
        SpringEnd::World(Vec3::new(-0.5, 0.0, 0.0)),
        k,
        0.0,
    ));
    world.spawn(Spring::new(
        centred,
        Vec3::ZERO,
        SpringEnd::World(Vec3::new(2.0, 0.0, 0.0)),
        k,
        0.0,
    ));
    let mut physics = PhysicsRunner::new(&mut world);
    physics.step(&mut world);
    let mass = world.get::<MassProps>(off).unwrap().0;
    let expected = (k * tumble_core::springs::turning_compliance(&mass, arm)).sqrt();
    let rate = world.get::<SpringTurn>(off).unwrap().rate();
    assert!(
        (rate - expected).abs() <= 1e-5 * expected,
        "{rate} against {expected}"
    );
    assert!(world.get::<SpringTurn>(centred).is_none());
    // A second spring on the same body: the rates add in quadrature.
    let other = Vec3::new(-0.1, 0.0, 0.05);
    world.spawn(Spring::new(
        off,
        other,
        SpringEnd::World(Vec3::new(0.5, 0.0, 0.0)),
        k,
        0.0,
    ));
    physics.step(&mut world);
    let both = (k * tumble_core::springs::turning_compliance(&mass, arm)
        + k * tumble_core::springs::turning_compliance(&mass, other))
    .sqrt();
    let rate = world.get::<SpringTurn>(off).unwrap().rate();
    assert!((rate - both).abs() <= 1e-5 * both, "{rate} against {both}");
}
