//! The forced linkage: a work–precision scene with forces where a fourth-order method shows its
//! slope, run through the ECS as a game runs it.
//!
//! Three asymmetric bodies under gravity: a spring between off-centre anchors of the first two,
//! a spring from the third to a world point, a constant world force at a point of the second and
//! a torque on the first. Every load depends on the state (the springs on positions and
//! orientations, the force's torque on the orientation), so a method that samples the loads once
//! per step is second order at best here; `yoshida4` samples them in each of its three stages.
//!
//! The reference is an f64 RK4 of the same equations (`ẋ = v`, `v̇ = F/m`, `q̇ = ½ ω q` with
//! `ω = R I⁻¹ Rᵀ L`, `L̇ = τ`) with a step far below any measured one, written here and sharing
//! no code with the engine.

use std::num::NonZeroU32;
use std::time::Instant;

use bevy_ecs::prelude::*;
use glam::{DQuat, DVec3};
use tumble_core::math::{Quat, Real, Vec3, Widen, to_f64};
use tumble_core::rotation::angle_between;
use tumble_core::{Integrator, Mass, MassProperties};
use tumble_ecs::prelude::*;

use crate::workprec::Point;

/// The scene's name in the report.
pub const NAME: &str = "linkage";
/// Horizon (s).
pub const HORIZON: f64 = 2.0;
/// RK4 steps of the reference over the horizon (h = 1e-4 s).
pub const REFERENCE_STEPS: usize = 20_000;

/// Masses (kg).
const MASSES: [f64; 3] = [1.0, 1.5, 0.8];
/// Principal moments (kg·m²).
const INERTIA: [[f64; 3]; 3] = [[0.1, 0.2, 0.3], [0.25, 0.15, 0.1], [0.08, 0.12, 0.2]];
/// Gravity (m/s²).
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

/// The scene as a world stepped by `integrator` at `dt` with `substeps` substeps (springs
/// explicit, so that every method steps them itself); its three bodies.
///
/// # Panics
///
/// On a `dt` that is not a valid time step, or `substeps == 0`.
pub fn world(integrator: Integrator, dt: Real, substeps: u32) -> (World, [Entity; 3]) {
    let mut world = World::new();
    let settings = PhysicsSettings::new(dt, integrator)
        .expect("a valid time step")
        .with_springs(SpringSolver::Explicit)
        .with_free_flow(FreeFlow::Method)
        .with_substeps(NonZeroU32::new(substeps).expect("at least one substep"))
        .expect("substeps of a step the precision can take");
    world.insert_resource(settings);
    world.insert_resource(Gravity(v3(GRAVITY)));
    let bodies = spawn(&mut world);
    (world, bodies)
}

/// Spawns one linkage (its bodies, springs, force and torque) into `world`; its three bodies.
pub fn spawn(world: &mut World) -> [Entity; 3] {
    let bodies = start();
    let e: Vec<Entity> = (0..3)
        .map(|i| {
            let (x, q, v, w) = bodies[i];
            let mass = Mass::new(MASSES[i] as Real)
                .and_then(|m| MassProperties::new(m, v3(INERTIA[i])))
                .expect("valid mass properties");
            world
                .spawn((
                    RigidBody,
                    MassProps(mass),
                    Pose {
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
    let link = SpringEnd::on_body(e[1], v3(LINK.1));
    world.spawn(Spring::new(
        e[0],
        v3(LINK.0),
        link,
        LINK.2 as Real,
        LINK.3 as Real,
    ));
    let hang = SpringEnd::World(v3(HANG.1));
    world.spawn(Spring::new(
        e[2],
        v3(HANG.0),
        hang,
        HANG.2 as Real,
        HANG.3 as Real,
    ));
    world.spawn(ConstantForce {
        body: e[1],
        force: v3(PUSH.0),
        local_point: Some(v3(PUSH.1)),
    });
    world.spawn(ConstantTorque {
        body: e[0],
        torque: v3(TWIST),
    });
    [e[0], e[1], e[2]]
}

/// One body of the reference: position, rotation, velocity, world angular momentum.
#[derive(Debug, Clone, Copy)]
pub struct Ref {
    /// Position of the centre of mass.
    pub x: DVec3,
    /// Rotation (not normalized along the way).
    pub q: DQuat,
    /// Velocity.
    pub v: DVec3,
    /// World angular momentum.
    pub l: DVec3,
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

/// The reference state of the three bodies at `horizon` (classic RK4, `steps` steps).
pub fn reference(horizon: f64, steps: usize) -> [Ref; 3] {
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

/// Largest error of one body over the three, position (m) plus orientation (rad), of `world`'s
/// bodies against the reference state `exact`.
pub fn error(world: &World, bodies: &[Entity; 3], exact: &[Ref; 3]) -> (f64, f64) {
    let mut worst = (0.0_f64, 0.0_f64);
    for (&e, r) in bodies.iter().zip(exact) {
        let t = world.get::<Pose>(e).expect("a body of the scene");
        let q = r.q.normalize();
        let position = (t.translation.widen() - r.x).length();
        let orientation = angle_between(
            t.rotation,
            Quat::from_xyzw(q.x as Real, q.y as Real, q.z as Real, q.w as Real),
        );
        worst = (worst.0.max(position), worst.1.max(orientation));
    }
    worst
}

/// Runs `copies` independent copies of the scene in one world to the horizon with `integrator`
/// at `dt` through a [`PhysicsRunner`] (the path a game runs), `repetitions` times, and
/// measures the first copy against `exact`: one work–precision point, timed per body-step
/// (best repetition; the copies spread the schedule's per-step cost as a game's many bodies
/// do).
pub fn measure(
    integrator: Integrator,
    dt: f64,
    copies: usize,
    repetitions: usize,
    exact: &[Ref; 3],
) -> Point {
    let steps = (HORIZON / dt).round() as usize;
    let dt = dt as Real;
    let mut best = f64::INFINITY;
    let mut last = None;
    for _ in 0..repetitions.max(1) {
        let (mut w, bodies) = world(integrator, dt, 1);
        for _ in 1..copies {
            spawn(&mut w);
        }
        let mut physics = PhysicsRunner::new(&mut w);
        let start = Instant::now();
        for _ in 0..steps {
            physics.step(&mut w);
            w.clear_trackers();
        }
        let body_steps = (3 * copies.max(1) * steps) as f64;
        best = best.min(start.elapsed().as_nanos() as f64 / body_steps);
        last = Some((w, bodies));
    }
    let (w, bodies) = last.expect("at least one repetition");
    let rejected = w
        .get_resource::<PhysicsErrors>()
        .is_some_and(|e| !e.is_empty());
    let (position, orientation) = error(&w, &bodies, exact);
    Point {
        scene: NAME.to_owned(),
        method: integrator.name().to_owned(),
        dt_s: to_f64(dt),
        steps,
        orientation_error_rad: orientation,
        position_error_m: position,
        energy_drift: f64::NAN,
        momentum_drift: None,
        ns_per_body_step: best,
        finite: !rejected && position.is_finite() && orientation.is_finite(),
    }
}
