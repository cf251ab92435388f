//! Steps of several stages through the ECS: `yoshida4`'s composition with forces sampled in
//! every stage, substeps, and the rule for loads game code adds before a step.
//!
//! The scene of the order test: three asymmetric bodies, a spring between off-centre anchors of
//! two of them, a spring from the third to a world point, a constant force at a body point and
//! a torque, under gravity. Its reference is an f64 RK4 of the same equations (`ẋ = v`,
//! `v̇ = F/m`, `q̇ = ½ ω q` with `ω = R I⁻¹ Rᵀ L`, `L̇ = τ`) with a step 250 times below the finest
//! tested one, written here and sharing no code with the engine.

use std::num::NonZeroU32;

use glam::{DQuat, DVec3};
use tumble::bevy_ecs::prelude::*;
use tumble::math::{Quat, Real, Vec3, Widen, to_f64};
use tumble::prelude::*;

const MASSES: [f64; 3] = [1.0, 1.5, 0.8];
const INERTIA: [[f64; 3]; 3] = [[0.1, 0.2, 0.3], [0.25, 0.15, 0.1], [0.08, 0.12, 0.2]];
const GRAVITY: [f64; 3] = [0.0, -9.81, 0.0];
/// Spring between bodies 0 and 1: anchors, stiffness, rest length.
const LINK: ([f64; 3], [f64; 3], f64, f64) = ([0.2, 0.1, 0.0], [-0.1, 0.0, 0.15], 30.0, 0.8);
/// Spring from body 2 to a world point: anchor, world point, stiffness, rest length.
const HANG: ([f64; 3], [f64; 3], f64, f64) = ([0.0, 0.15, 0.05], [1.5, 1.0, 0.0], 20.0, 0.5);
/// Constant world force on body 1 at a body point.
const PUSH: ([f64; 3], [f64; 3]) = ([1.0, 2.0, -0.5], [0.1, -0.2, 0.05]);
/// Torque on body 0.
const TWIST: [f64; 3] = [0.05, -0.1, 0.2];

fn v3(a: [f64; 3]) -> Vec3 {
    Vec3::new(a[0] as Real, a[1] as Real, a[2] as Real)
}

fn d3(a: [f64; 3]) -> DVec3 {
    DVec3::from_array(a)
}

/// Start: positions, rotations, velocities, world angular velocities (engine precision, so the
/// reference starts from exactly the stored values).
fn start() -> [(Vec3, Quat, Vec3, Vec3); 3] {
    [
        (
            Vec3::new(0.0, 0.0, 0.0),
            Quat::from_rotation_z(0.3),
            Vec3::new(0.1, 0.2, 0.0),
            Vec3::new(0.5, 1.2, -0.4),
        ),
        (
            Vec3::new(1.0, 0.2, 0.1),
            Quat::from_rotation_x(-0.4),
            Vec3::new(0.0, -0.1, 0.3),
            Vec3::new(-0.8, 0.3, 1.0),
        ),
        (
            Vec3::new(1.4, 0.4, -0.2),
            Quat::from_rotation_y(0.7),
            Vec3::ZERO,
            Vec3::new(0.2, -0.6, 0.9),
        ),
    ]
}

/// The scene as a world: `integrator`, `dt`, `substeps`.
fn world(integrator: Integrator, dt: Real, substeps: u32) -> (World, [Entity; 3]) {
    let mut world = World::new();
    let settings = PhysicsSettings::new(dt, integrator)
        .unwrap()
        .with_springs(SpringSolver::Explicit)
        .with_substeps(NonZeroU32::new(substeps).unwrap());
    world.insert_resource(settings);
    world.insert_resource(Gravity(v3(GRAVITY)));
    let bodies = start();
    let e: Vec<Entity> = (0..3)
        .map(|i| {
            let (x, q, v, w) = bodies[i];
            let mass =
                MassProperties::new(Mass::new(MASSES[i] as Real).unwrap(), v3(INERTIA[i])).unwrap();
            world
                .spawn((
                    RigidBody,
                    MassProps(mass),
                    Transform {
                        translation: x,
                        rotation: q,
                    },
                    Velocity {
                        linear: v,
                        angular: w,
                    },
                    ForceAccumulator::default(),
                ))
                .id()
        })
        .collect();
    world.spawn(Spring {
        a: e[0],
        anchor_a: v3(LINK.0),
        b: SpringEnd::Body {
            body: e[1],
            anchor: v3(LINK.1),
        },
        stiffness: LINK.2 as Real,
        damping: 0.0,
        rest_length: LINK.3 as Real,
    });
    world.spawn(Spring {
        a: e[2],
        anchor_a: v3(HANG.0),
        b: SpringEnd::World(v3(HANG.1)),
        stiffness: HANG.2 as Real,
        damping: 0.0,
        rest_length: HANG.3 as Real,
    });
    world.spawn(ConstantForce {
        body: e[1],
        force: v3(PUSH.0),
        local_point: Some(v3(PUSH.1)),
    });
    world.spawn(ConstantTorque {
        body: e[0],
        torque: v3(TWIST),
    });
    (world, [e[0], e[1], e[2]])
}

/// One body of the reference: position, rotation, velocity, world angular momentum.
#[derive(Clone, Copy)]
struct Ref {
    x: DVec3,
    q: DQuat,
    v: DVec3,
    l: DVec3,
}

fn omega(i: usize, q: DQuat, l: DVec3) -> DVec3 {
    let q = q.normalize();
    q * ((q.conjugate() * l) / d3(INERTIA[i]))
}

/// Time derivative of the whole reference state.
fn derivative(s: &[Ref; 3]) -> [Ref; 3] {
    let mut force = [
        d3(GRAVITY) * MASSES[0],
        d3(GRAVITY) * MASSES[1],
        d3(GRAVITY) * MASSES[2],
    ];
    let mut torque = [DVec3::ZERO; 3];
    let mut push = |i: usize, f: DVec3, point: DVec3, s: &[Ref; 3]| {
        force[i] += f;
        torque[i] += (point - s[i].x).cross(f);
    };
    let spring = |pa: DVec3, pb: DVec3, k: f64, rest: f64| {
        let d = pa - pb;
        -k * (d.length() - rest) * d.normalize()
    };
    let pa = s[0].x + s[0].q.normalize() * d3(LINK.0);
    let pb = s[1].x + s[1].q.normalize() * d3(LINK.1);
    let f = spring(pa, pb, LINK.2, LINK.3);
    push(0, f, pa, s);
    push(1, -f, pb, s);
    let p = s[2].x + s[2].q.normalize() * d3(HANG.0);
    push(2, spring(p, d3(HANG.1), HANG.2, HANG.3), p, s);
    let p = s[1].x + s[1].q.normalize() * d3(PUSH.1);
    push(1, d3(PUSH.0), p, s);
    torque[0] += d3(TWIST);
    std::array::from_fn(|i| {
        let w = omega(i, s[i].q, s[i].l);
        Ref {
            x: s[i].v,
            q: DQuat::from_xyzw(w.x, w.y, w.z, 0.0) * s[i].q * 0.5,
            v: force[i] / MASSES[i],
            l: torque[i],
        }
    })
}

fn axpy(s: &[Ref; 3], k: &[Ref; 3], h: f64) -> [Ref; 3] {
    std::array::from_fn(|i| Ref {
        x: s[i].x + k[i].x * h,
        q: s[i].q + k[i].q * h,
        v: s[i].v + k[i].v * h,
        l: s[i].l + k[i].l * h,
    })
}

/// The reference state at `horizon` (classic RK4, `steps` steps).
fn reference(horizon: f64, steps: usize) -> [Ref; 3] {
    let bodies = start();
    let mut s: [Ref; 3] = std::array::from_fn(|i| {
        let (x, q, v, w) = bodies[i];
        let q = q.widen();
        Ref {
            x: x.widen(),
            q,
            v: v.widen(),
            l: q * ((q.conjugate() * w.widen()) * d3(INERTIA[i])),
        }
    });
    let h = horizon / steps as f64;
    for _ in 0..steps {
        let k1 = derivative(&s);
        let k2 = derivative(&axpy(&s, &k1, 0.5 * h));
        let k3 = derivative(&axpy(&s, &k2, 0.5 * h));
        let k4 = derivative(&axpy(&s, &k3, h));
        s = std::array::from_fn(|i| Ref {
            x: s[i].x + (k1[i].x + 2.0 * k2[i].x + 2.0 * k3[i].x + k4[i].x) * (h / 6.0),
            q: s[i].q + (k1[i].q + k2[i].q * 2.0 + k3[i].q * 2.0 + k4[i].q) * (h / 6.0),
            v: s[i].v + (k1[i].v + 2.0 * k2[i].v + 2.0 * k3[i].v + k4[i].v) * (h / 6.0),
            l: s[i].l + (k1[i].l + 2.0 * k2[i].l + 2.0 * k3[i].l + k4[i].l) * (h / 6.0),
        });
    }
    s
}

/// Largest position error (m) plus orientation error (rad) over the bodies at `horizon`.
fn error(integrator: Integrator, steps: u32, horizon: f64, exact: &[Ref; 3]) -> f64 {
    let dt = (horizon / f64::from(steps)) as Real;
    let (mut w, bodies) = world(integrator, dt, 1);
    let mut physics = PhysicsRunner::new(&mut w);
    for _ in 0..steps {
        physics.step(&mut w);
        w.clear_trackers();
    }
    assert!(
        w.get_resource::<PhysicsErrors>()
            .is_none_or(|e| e.0.is_empty())
    );
    bodies
        .iter()
        .zip(exact)
        .map(|(&e, r)| {
            let t = w.get::<Transform>(e).unwrap();
            let dx = (t.translation.widen() - r.x).length();
            let dq = tumble::core::rotation::angle_between(
                t.rotation,
                Quat::from_xyzw(r.q.x as Real, r.q.y as Real, r.q.z as Real, r.q.w as Real)
                    .normalize(),
            );
            dx + dq
        })
        .fold(0.0, f64::max)
}

/// `yoshida4` re-samples springs, forces at points and torques in each of its three stages,
/// so it is fourth order on the whole motion: the observed order over Δt = 1/20 … 1/80 s must
/// be 4 ± 0.3 (`splitting` on the same scene: 2 ± 0.2).
#[test]
fn yoshida4_is_fourth_order_with_springs_forces_at_points_and_torques() {
    let horizon = 2.0;
    let exact = reference(horizon, 20_000);
    let order = |integrator, rates: &[u32]| {
        let e: Vec<f64> = rates
            .iter()
            .map(|&n| error(integrator, n, horizon, &exact))
            .collect();
        let slopes: Vec<f64> = e.windows(2).map(|w| (w[0] / w[1]).log2()).collect();
        eprintln!("{integrator}: errors {e:?}, slopes {slopes:?}");
        (e, slopes)
    };
    let rates = [20, 40, 80];
    let (y, y_slopes) = order(Integrator::Yoshida4, &rates);
    let (s, s_slopes) = order(Integrator::Splitting, &rates);
    // The errors (2e-2 … 9e-5 for yoshida4) stay far above the f32 storage floor, so the
    // slopes hold in both builds.
    for slope in y_slopes {
        assert!((slope - 4.0).abs() <= 0.3, "yoshida4 slope {slope}: {y:?}");
    }
    for slope in s_slopes {
        assert!((slope - 2.0).abs() <= 0.2, "splitting slope {slope}: {s:?}");
    }
}

/// The bits of every body's state.
fn bits(world: &World, bodies: &[Entity]) -> Vec<u64> {
    bodies
        .iter()
        .flat_map(|&e| {
            let t = world.get::<Transform>(e).unwrap();
            let v = world.get::<Velocity>(e).unwrap();
            [t.translation, v.linear, v.angular]
                .into_iter()
                .flat_map(|v| v.to_array())
                .chain(t.rotation.to_array())
                .map(|x| x.widen().to_bits())
                .collect::<Vec<_>>()
        })
        .collect()
}

/// With only conservative forces (springs, gravity) the composition is time-reversible:
/// forward, flip the velocities, forward again, and the start comes back to round-off.
#[test]
fn the_composition_is_time_reversible_with_conservative_forces() {
    let steps = 200;
    let (mut w, bodies) = world(Integrator::Yoshida4, 1.0 / 30.0, 1);
    // Only the springs and gravity: drop the constant force and torque (not conservative in
    // the body frame: reversing time does not reverse them).
    let loads: Vec<Entity> = w
        .query_filtered::<Entity, Or<(With<ConstantForce>, With<ConstantTorque>)>>()
        .iter(&w)
        .collect();
    for e in loads {
        w.despawn(e);
    }
    let before: Vec<(Transform, Velocity)> = bodies
        .iter()
        .map(|&e| {
            (
                *w.get::<Transform>(e).unwrap(),
                *w.get::<Velocity>(e).unwrap(),
            )
        })
        .collect();
    let mut physics = PhysicsRunner::new(&mut w);
    let mut run = |w: &mut World| {
        for _ in 0..steps {
            physics.step(w);
            w.clear_trackers();
        }
    };
    let flip = |w: &mut World| {
        for &e in &bodies {
            let mut v = w.get_mut::<Velocity>(e).unwrap();
            v.linear = -v.linear;
            v.angular = -v.angular;
        }
    };
    run(&mut w);
    let moved =
        (w.get::<Transform>(bodies[2]).unwrap().translation - before[2].0.translation).length();
    assert!(moved > 0.1, "the bodies moved: {moved}");
    flip(&mut w);
    run(&mut w);
    flip(&mut w);
    // Round-off: a few ulps per stage, growing at most linearly over the 3 × 400 stages.
    let tolerance = to_f64(Real::EPSILON) * 3.0 * 400.0 * 20.0;
    for (&e, (t0, v0)) in bodies.iter().zip(&before) {
        let t = w.get::<Transform>(e).unwrap();
        let v = w.get::<Velocity>(e).unwrap();
        let dx = to_f64((t.translation - t0.translation).length());
        let dq = tumble::core::rotation::angle_between(t.rotation, t0.rotation);
        let dv = to_f64((v.linear - v0.linear).length() + (v.angular - v0.angular).length());
        assert!(
            dx < tolerance && dq < tolerance && dv < 10.0 * tolerance,
            "back at the start to round-off: dx {dx:e}, dq {dq:e}, dv {dv:e} (tolerance {tolerance:e})"
        );
    }
}

/// `N` substeps of `Δt` are, bit for bit, `N` steps of `Δt/N`: with springs (one damped, one
/// stiff enough to be stepped implicitly), `Damping`, a force at a point, a torque and gravity,
/// for a one-stage method and for the composition.
#[test]
fn substeps_are_steps_of_the_substep_bit_for_bit() {
    for integrator in [
        Integrator::Splitting,
        Integrator::SymplecticEuler,
        Integrator::Yoshida4,
    ] {
        let build = |dt: Real, substeps: u32| {
            let (mut w, bodies) = world(integrator, dt, substeps);
            w.resource_mut::<PhysicsSettings>().springs = SpringSolver::Auto;
            w.entity_mut(bodies[1]).insert(Damping {
                linear: 0.3,
                angular: 0.2,
            });
            let mut springs = w.query::<&mut Spring>();
            for mut s in springs.iter_mut(&mut w) {
                if matches!(s.b, SpringEnd::World(_)) {
                    s.damping = 0.4;
                }
            }
            // A stiff pair: ωΔt ≈ 30 at Δt/3 = 1/90 s, stepped implicitly.
            let stiff: Vec<Entity> = (0..2)
                .map(|i| {
                    w.spawn((
                        RigidBody,
                        MassProps(
                            MassProperties::new(Mass::new(1.0).unwrap(), v3(INERTIA[i])).unwrap(),
                        ),
                        Transform::from_translation(Vec3::new(5.0 + i as Real, 0.0, 0.0)),
                        Velocity {
                            linear: Vec3::new(0.0, i as Real, 0.0),
                            angular: Vec3::new(0.3, -0.2, i as Real),
                        },
                        ForceAccumulator::default(),
                    ))
                    .id()
                })
                .collect();
            w.spawn(Spring {
                a: stiff[0],
                anchor_a: Vec3::new(0.1, 0.0, 0.05),
                b: SpringEnd::Body {
                    body: stiff[1],
                    anchor: Vec3::new(-0.1, 0.02, 0.0),
                },
                stiffness: 4e6,
                damping: 0.0,
                rest_length: 0.8,
            });
            let all: Vec<Entity> = bodies.iter().copied().chain(stiff).collect();
            (w, all)
        };
        let (mut sub, bodies) = build(1.0 / 30.0, 3);
        let (mut fine, _) = build(1.0 / 90.0, 1);
        assert_eq!(
            sub.resource::<PhysicsSettings>()
                .stages()
                .span(1.0 / 30.0, 0)
                .substep,
            fine.resource::<PhysicsSettings>().dt(),
            "the premise: Δt/3 is the same number both ways"
        );
        let mut a = PhysicsRunner::new(&mut sub);
        let mut b = PhysicsRunner::new(&mut fine);
        for _ in 0..60 {
            a.step(&mut sub);
            sub.clear_trackers();
            for _ in 0..3 {
                b.step(&mut fine);
                fine.clear_trackers();
            }
        }
        assert!(
            a.plan().contains(Stage::SolveImplicitSprings),
            "{}",
            a.plan()
        );
        assert_eq!(bits(&sub, &bodies), bits(&fine, &bodies), "{integrator}");
        assert!(
            sub.get_resource::<PhysicsErrors>()
                .is_none_or(|e| e.0.is_empty())
        );
    }
}

/// A load game code adds before a step of several stages is held over the whole step: its
/// impulse is `F Δt` (not `F Δt` per stage, nor only the first stage's share), and drift–kick–
/// drift integrates a constant force exactly, so `x = ½ (F/m) Δt²`.
#[test]
fn a_load_added_before_a_step_of_several_stages_is_applied_once() {
    for (integrator, substeps) in [
        (Integrator::Splitting, 4),
        (Integrator::Yoshida4, 1),
        (Integrator::Yoshida4, 3),
    ] {
        let dt: Real = 0.1;
        let mut w = World::new();
        w.insert_resource(
            PhysicsSettings::new(dt, integrator)
                .unwrap()
                .with_substeps(NonZeroU32::new(substeps).unwrap()),
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
        let t = *w.get::<Transform>(body).unwrap();
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
fn sample(mut samples: ResMut<Samples>, mut bodies: Query<(&Transform, &mut ForceAccumulator)>) {
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
            .with_substeps(NonZeroU32::new(4).unwrap()),
    );
    w.init_resource::<Samples>();
    let body = w
        .spawn((
            RigidBody,
            Velocity::linear(Vec3::X),
            ForceAccumulator::default(),
        ))
        .id();
    let plan = PhysicsPlan::for_world(&mut w);
    assert_eq!(plan.runs_per_step(), 4);
    let mut schedule = plan.build_schedule();
    schedule.add_systems(sample.in_set(PhysicsSet::Forces));
    plan.run_step(&mut schedule, &mut w);
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
            .with_substeps(NonZeroU32::new(2).unwrap()),
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
