//! Damped springs and [`Damping`] at full order, through the ECS schedule (`PhysicsRunner`).
//!
//! Damping is a flow of its own split symmetrically around the conservative step,
//! `D(Δt/2) ∘ step ∘ D(Δt/2)`, so the drift–kick–drift `splitting` stays second order. Measured
//! here against independent f64 solutions: the damped oscillator's closed form
//! ([`tumble_reference::exact::damped_spring`]) and, for a net of asymmetric bodies with off-centre
//! anchors, a tiny-step RK4 of the same equations of motion written out below.
//!
//! The observed order is the least-squares slope of log(error) against log(Δt) over a sweep at
//! a fixed horizon, and must be 2 ± 0.2. The sweeps are chosen so that every error stays far
//! above the f32 round-off floor (≈ √n ε of the amplitude after n steps: < 1e-5 here), and
//! `ωΔt ≤ 0.4`, inside the asymptotic regime.

use glam::{DQuat, DVec3};
use tumble::bevy_ecs::prelude::*;
use tumble::core::rotation::angle_between;
use tumble::math::{Quat, Real, Vec3, Widen, to_f64};
use tumble::prelude::*;
use tumble_reference::exact::DampedSpring;

/// Least-squares slope of log(error) against log(Δt).
fn observed_order(errors: &[(f64, f64)]) -> f64 {
    let pts: Vec<(f64, f64)> = errors.iter().map(|&(h, e)| (h.ln(), e.ln())).collect();
    let k = pts.len() as f64;
    let (mx, my) = pts
        .iter()
        .fold((0.0, 0.0), |(a, b), &(x, y)| (a + x / k, b + y / k));
    let num: f64 = pts.iter().map(|&(x, y)| (x - mx) * (y - my)).sum();
    let den: f64 = pts.iter().map(|&(x, _)| (x - mx) * (x - mx)).sum();
    num / den
}

fn mass_props(m: f64, inertia: [f64; 3]) -> MassProps {
    let i = DVec3::from(inertia);
    MassProps(
        MassProperties::new(
            Mass::new(m as Real).unwrap(),
            Vec3::new(i.x as Real, i.y as Real, i.z as Real),
        )
        .unwrap(),
    )
}

fn world(dt: f64, integrator: Integrator) -> World {
    let mut world = World::new();
    world.insert_resource(PhysicsSettings::new(dt as Real, integrator).unwrap());
    world
}

fn run(world: &mut World, steps: usize) {
    let mut physics = PhysicsRunner::new(world);
    for _ in 0..steps {
        physics.step(world);
        world.clear_trackers();
    }
}

// ---------------------------------------------------------------------------------------------
// The damped oscillator: a body on a damped spring to a world anchor, along x.

/// 1 kg at 1 Hz, damping ratio ζ = 0.1, released 0.5 m from rest length 1 m; 3 s (three
/// periods, the amplitude decays to e^{−ζω₀T} ≈ 0.15).
const OSC_MASS: f64 = 1.0;
const OSC_OMEGA: f64 = std::f64::consts::TAU;
const OSC_ZETA: f64 = 0.1;
const OSC_REST: f64 = 1.0;
const OSC_X0: f64 = 0.5;
const OSC_HORIZON: f64 = 3.0;

fn oscillator() -> DampedSpring {
    let k = OSC_MASS * OSC_OMEGA * OSC_OMEGA;
    let c = 2.0 * OSC_ZETA * (k * OSC_MASS).sqrt();
    DampedSpring::new(OSC_X0, 0.0, k, c, OSC_MASS).unwrap()
}

/// Runs the oscillator with `integrator` at `1/rate` for `horizon`: the final (stretch,
/// velocity) and the energy after every step.
fn run_oscillator(integrator: Integrator, rate: u32, horizon: f64) -> ((f64, f64), Vec<f64>) {
    let spring = oscillator();
    let k = OSC_MASS * OSC_OMEGA * OSC_OMEGA;
    let c = 2.0 * spring.damping_ratio() * (k * OSC_MASS).sqrt();
    let mut world = world(1.0 / f64::from(rate), integrator);
    let body = world
        .spawn((
            RigidBody,
            mass_props(OSC_MASS, [1.0, 1.0, 1.0]),
            Pose::from_translation(Vec3::new((OSC_REST + OSC_X0) as Real, 0.0, 0.0)),
        ))
        .id();
    world.spawn(Spring {
        a: body,
        anchor_a: Vec3::ZERO,
        b: SpringEnd::World(Vec3::ZERO),
        stiffness: k as Real,
        damping: c as Real,
        rest_length: OSC_REST as Real,
    });
    let steps = (horizon * f64::from(rate)).round() as usize;
    let mut physics = PhysicsRunner::new(&mut world);
    let mut energies = Vec::with_capacity(steps);
    for _ in 0..steps {
        physics.step(&mut world);
        world.clear_trackers();
        let x = to_f64(world.get::<Pose>(body).unwrap().translation.x) - OSC_REST;
        let v = to_f64(world.get::<Velocity>(body).unwrap().linear.x);
        energies.push(0.5 * k * x * x + 0.5 * OSC_MASS * v * v);
    }
    let x = to_f64(world.get::<Pose>(body).unwrap().translation.x) - OSC_REST;
    let v = to_f64(world.get::<Velocity>(body).unwrap().linear.x);
    ((x, v), energies)
}

/// Phase-space error at the horizon, `|x − x*| + |v − v*|/ω₀` (m).
fn oscillator_error(integrator: Integrator, rate: u32) -> f64 {
    let ((x, v), _) = run_oscillator(integrator, rate, OSC_HORIZON);
    let (xe, ve) = oscillator().state(OSC_HORIZON);
    (x - xe).abs() + (v - ve).abs() / OSC_OMEGA
}

const RATES: [u32; 5] = [30, 60, 120, 240, 480];

/// Asserts that the splitting's `error` at the step rates [`RATES`] (steps per second) falls
/// with an observed order within 0.2 of 2.
fn assert_second_order(name: &str, error: impl Fn(u32) -> f64) {
    let errors: Vec<(f64, f64)> = RATES
        .iter()
        .map(|&n| (1.0 / f64::from(n), error(n)))
        .collect();
    let order = observed_order(&errors);
    eprintln!("{name}, splitting: observed order {order:.3} from {errors:?}");
    assert!(
        (order - 2.0).abs() <= 0.2,
        "order {order:.3}, errors {errors:?}"
    );
}

#[test]
fn splitting_is_second_order_on_the_damped_oscillator() {
    assert_second_order("damped oscillator", |n| {
        oscillator_error(Integrator::Splitting, n)
    });
}

#[test]
fn splitting_beats_symplectic_euler_on_the_damped_oscillator() {
    for &n in &RATES {
        let split = oscillator_error(Integrator::Splitting, n);
        let euler = oscillator_error(Integrator::SymplecticEuler, n);
        eprintln!(
            "1/{n}: splitting {split:.3e}, symplectic Euler {euler:.3e}, ratio {:.1}",
            euler / split
        );
        assert!(
            split <= euler,
            "1/{n}: splitting {split:e} > symplectic Euler {euler:e}"
        );
    }
}

// ---------------------------------------------------------------------------------------------
// A damped spring net: asymmetric bodies, off-centre anchors, shared bodies, body `Damping`.

/// One body of the net (centre of mass at the body origin, principal frame = body frame).
struct NetBody {
    mass: f64,
    inertia: [f64; 3],
    position: [f64; 3],
    rotation: DQuat,
    velocity: [f64; 3],
    omega: [f64; 3],
    /// `Damping` (c_lin, c_ang) in 1/s, if any.
    damping: Option<(f64, f64)>,
}

/// One spring of the net: body `a` at a body-local anchor, and a body (index, anchor) or a
/// world point.
struct NetSpring {
    a: usize,
    anchor_a: [f64; 3],
    b: Result<(usize, [f64; 3]), [f64; 3]>,
    stiffness: f64,
    damping: f64,
    rest: f64,
}

fn net() -> (Vec<NetBody>, Vec<NetSpring>) {
    let bodies = vec![
        NetBody {
            mass: 1.0,
            inertia: [0.08, 0.12, 0.16],
            position: [0.0, 0.0, 0.0],
            rotation: DQuat::from_rotation_z(0.3),
            velocity: [0.3, -0.2, 0.1],
            omega: [0.5, -0.4, 0.9],
            damping: None,
        },
        NetBody {
            mass: 1.5,
            inertia: [0.2, 0.1, 0.25],
            position: [1.2, 0.1, 0.0],
            rotation: DQuat::from_rotation_x(-0.4),
            velocity: [0.0, 0.4, -0.2],
            omega: [-0.3, 0.8, 0.2],
            damping: Some((0.3, 0.5)),
        },
        NetBody {
            mass: 0.8,
            inertia: [0.05, 0.07, 0.04],
            position: [0.5, 1.0, 0.3],
            rotation: DQuat::from_rotation_y(0.7),
            velocity: [-0.2, 0.0, 0.3],
            omega: [0.6, 0.2, -0.7],
            damping: Some((0.2, 0.0)),
        },
    ];
    let springs = vec![
        NetSpring {
            a: 0,
            anchor_a: [-0.1, 0.15, 0.05],
            b: Err([-1.0, 0.2, 0.0]),
            stiffness: 30.0,
            damping: 0.8,
            rest: 0.8,
        },
        NetSpring {
            a: 0,
            anchor_a: [0.2, -0.05, 0.1],
            b: Ok((1, [-0.15, 0.1, -0.05])),
            stiffness: 25.0,
            damping: 0.6,
            rest: 0.7,
        },
        NetSpring {
            a: 1,
            anchor_a: [0.05, 0.2, 0.1],
            b: Ok((2, [0.1, -0.1, 0.0])),
            stiffness: 20.0,
            damping: 1.0,
            rest: 0.9,
        },
        NetSpring {
            a: 2,
            anchor_a: [-0.1, 0.0, -0.12],
            b: Ok((0, [0.0, 0.15, 0.0])),
            stiffness: 15.0,
            damping: 0.4,
            rest: 1.0,
        },
    ];
    (bodies, springs)
}

const NET_HORIZON: f64 = 2.0;

/// The net's state in f64: per body (x, v, q, ω), ω in world coordinates.
type NetState = Vec<(DVec3, DVec3, DQuat, DVec3)>;

/// Time derivative of the net's state: Newton–Euler with the spring forces
/// `−(k(|d| − L₀) + c (u·n)) n` at the anchors and `Damping` as `v̇ = −c_lin v`,
/// `ω̇ = −c_ang ω`; `q̇ = ½ (0, ω) q`, `ω̇ = I_w⁻¹ (τ − ω × I_w ω)`.
fn net_rate(bodies: &[NetBody], springs: &[NetSpring], s: &NetState) -> NetState {
    let mut force = vec![DVec3::ZERO; s.len()];
    let mut torque = vec![DVec3::ZERO; s.len()];
    // RK4's stages leave |q| ≠ 1 by O(h²): rotate with the unit quaternion, so the stages see
    // the same smooth vector field as on the unit sphere and RK4 keeps its fourth order.
    let anchor = |i: usize, local: [f64; 3]| {
        let (x, v, q, w) = s[i];
        let r = q.normalize() * DVec3::from(local);
        (x + r, v + w.cross(r), r)
    };
    for sp in springs {
        let (pa, ua, ra) = anchor(sp.a, sp.anchor_a);
        let (pb, ub, rb) = match sp.b {
            Ok((j, local)) => {
                let (p, u, r) = anchor(j, local);
                (p, u, Some((j, r)))
            }
            Err(p) => (DVec3::from(p), DVec3::ZERO, None),
        };
        let d = pa - pb;
        let n = d.normalize();
        let f = -(sp.stiffness * (d.length() - sp.rest) + sp.damping * (ua - ub).dot(n)) * n;
        force[sp.a] += f;
        torque[sp.a] += ra.cross(f);
        if let Some((j, r)) = rb {
            force[j] -= f;
            torque[j] -= r.cross(f);
        }
    }
    s.iter()
        .enumerate()
        .map(|(i, &(_, v, q, w))| {
            let b = &bodies[i];
            let inertia = DVec3::from(b.inertia);
            let (q_dot, q) = (q, q.normalize());
            let world_inertia = |x: DVec3| q * (inertia * (q.inverse() * x));
            let world_inv_inertia = |x: DVec3| q * ((q.inverse() * x) / inertia);
            let (c_lin, c_ang) = b.damping.unwrap_or((0.0, 0.0));
            let dv = force[i] / b.mass - c_lin * v;
            let dw = world_inv_inertia(torque[i] - w.cross(world_inertia(w))) - c_ang * w;
            let dq = DQuat::from_xyzw(w.x, w.y, w.z, 0.0) * q_dot * 0.5;
            (v, dv, dq, dw)
        })
        .collect()
}

/// The net at `horizon` by classic RK4 in f64 with step `h` (error ∝ h⁴).
fn net_reference(horizon: f64, h: f64) -> NetState {
    let (bodies, springs) = net();
    let mut s: NetState = bodies
        .iter()
        .map(|b| {
            (
                DVec3::from(b.position),
                DVec3::from(b.velocity),
                b.rotation,
                DVec3::from(b.omega),
            )
        })
        .collect();
    let steps = (horizon / h).round() as usize;
    let axpy = |s: &NetState, k: &NetState, a: f64| -> NetState {
        s.iter()
            .zip(k)
            .map(|(&(x, v, q, w), &(dx, dv, dq, dw))| {
                (x + a * dx, v + a * dv, q + dq * a, w + a * dw)
            })
            .collect()
    };
    for _ in 0..steps {
        let k1 = net_rate(&bodies, &springs, &s);
        let k2 = net_rate(&bodies, &springs, &axpy(&s, &k1, h / 2.0));
        let k3 = net_rate(&bodies, &springs, &axpy(&s, &k2, h / 2.0));
        let k4 = net_rate(&bodies, &springs, &axpy(&s, &k3, h));
        s = s
            .iter()
            .enumerate()
            .map(|(i, &(x, v, q, w))| {
                let sum = |f: fn(&(DVec3, DVec3, DQuat, DVec3)) -> DVec3| {
                    f(&k1[i]) + 2.0 * f(&k2[i]) + 2.0 * f(&k3[i]) + f(&k4[i])
                };
                let dq = k1[i].2 + k2[i].2 * 2.0 + k3[i].2 * 2.0 + k4[i].2;
                (
                    x + h / 6.0 * sum(|k| k.0),
                    v + h / 6.0 * sum(|k| k.1),
                    (q + dq * (h / 6.0)).normalize(),
                    w + h / 6.0 * sum(|k| k.3),
                )
            })
            .collect();
    }
    s
}

/// Runs the net through the ECS at `1/rate` to `NET_HORIZON`: each body's (position, rotation).
fn run_net(integrator: Integrator, rate: u32) -> Vec<(Vec3, Quat)> {
    let (mut world, ids) = net_world(integrator, rate, 1.0);
    run(&mut world, (NET_HORIZON * f64::from(rate)).round() as usize);
    ids.iter()
        .map(|&e| {
            (
                world.get::<Pose>(e).unwrap().translation,
                world.get::<Pose>(e).unwrap().rotation,
            )
        })
        .collect()
}

/// The net as a world stepping at `1/rate`, every damping coefficient (springs and bodies)
/// multiplied by `damping_scale`; the bodies' entities.
fn net_world(integrator: Integrator, rate: u32, damping_scale: f64) -> (World, Vec<Entity>) {
    let (bodies, springs) = net();
    let mut world = world(1.0 / f64::from(rate), integrator);
    let f = |a: [f64; 3]| Vec3::new(a[0] as Real, a[1] as Real, a[2] as Real);
    let ids: Vec<Entity> = bodies
        .iter()
        .map(|b| {
            let q = b.rotation;
            let mut e = world.spawn((
                RigidBody,
                mass_props(b.mass, b.inertia),
                Pose {
                    translation: f(b.position),
                    rotation: Quat::from_xyzw(q.x as Real, q.y as Real, q.z as Real, q.w as Real),
                },
                Velocity {
                    linear: f(b.velocity),
                    angular: f(b.omega),
                },
            ));
            if let Some((linear, angular)) = b.damping {
                e.insert(Damping {
                    linear: (linear * damping_scale) as Real,
                    angular: (angular * damping_scale) as Real,
                });
            }
            e.id()
        })
        .collect();
    for s in &springs {
        world.spawn(Spring {
            a: ids[s.a],
            anchor_a: f(s.anchor_a),
            b: match s.b {
                Ok((j, anchor)) => SpringEnd::Body {
                    body: ids[j],
                    anchor: f(anchor),
                },
                Err(p) => SpringEnd::World(f(p)),
            },
            stiffness: s.stiffness as Real,
            damping: (s.damping * damping_scale) as Real,
            rest_length: s.rest as Real,
        });
    }
    (world, ids)
}

/// Sum over the bodies of the position error (m) and the orientation error (rad, as the arc of
/// a unit lever).
fn net_error(got: &[(Vec3, Quat)], reference: &NetState) -> f64 {
    got.iter()
        .zip(reference)
        .map(|(&(x, q), &(xr, _, qr, _))| {
            let qr = Quat::from_xyzw(qr.x as Real, qr.y as Real, qr.z as Real, qr.w as Real);
            (x.widen() - xr).length() + angle_between(q, qr)
        })
        .sum()
}

#[test]
fn splitting_is_second_order_on_a_damped_spring_net() {
    // RK4 at 1e-4 s: error ≈ (ω h)⁴ ≈ 1e-12 relative, far below the f32 runs' errors.
    let reference = net_reference(NET_HORIZON, 1e-4);
    // The reference is converged: a step twice as large agrees to far below the smallest error.
    let coarse = net_reference(NET_HORIZON, 2e-4);
    let spread: f64 = reference
        .iter()
        .zip(&coarse)
        .map(|(a, b)| (a.0 - b.0).length() + a.2.angle_between(b.2))
        .sum();
    assert!(spread < 1e-9, "reference not converged: {spread:e}");
    assert_second_order("damped net", |n| {
        net_error(&run_net(Integrator::Splitting, n), &reference)
    });
}

/// Total mechanical energy of the net's world (kinetic + rotational + elastic), in f64.
fn net_energy(world: &mut World) -> f64 {
    let mut e = 0.0;
    for (t, v, m) in world
        .query_filtered::<(&Pose, &Velocity, &MassProps), With<RigidBody>>()
        .iter(world)
    {
        e += tumble::ecs::components::kinetic_energy_f64(t, v, m);
    }
    for s in world.query::<&Spring>().iter(world) {
        let anchor =
            |body: Entity, local: Vec3| world.get::<Pose>(body).unwrap().transform_point(local);
        let pb = match s.b {
            SpringEnd::World(p) => p,
            SpringEnd::Body {
                body,
                anchor: local,
            } => anchor(body, local),
        };
        e += s.elastic_energy(anchor(s.a, s.anchor_a), pb);
    }
    e
}

/// However strong the damping (springs and bodies, up to `cΔt/m ≈ 10⁴`), the net never ends a
/// step with more energy than it started with, beyond the energy swing of the conservative
/// drift–kick–drift step itself, `E ≤ E₀/(1 − x²)` with `x = ω_max Δt/2` (the swing of a
/// linear spring, the audit's bound; `ω_max² = max k/m_eff` with the effective inverse mass
/// bounded by `Σ_ends 1/m + |r|²/I_min`), and it loses energy overall.
#[test]
fn a_damped_net_never_gains_energy() {
    let (bodies, springs) = net();
    let w_max = springs
        .iter()
        .map(|s| {
            let end = |i: usize, r: [f64; 3]| {
                let b = &bodies[i];
                let i_min = b.inertia.iter().copied().fold(f64::INFINITY, f64::min);
                1.0 / b.mass + DVec3::from(r).length_squared() / i_min
            };
            let wb = s.b.map_or(0.0, |(j, r)| end(j, r));
            s.stiffness * (end(s.a, s.anchor_a) + wb)
        })
        .fold(0.0, f64::max);
    for rate in [60, 240] {
        let x = w_max.sqrt() / f64::from(rate) / 2.0;
        let bound = 1.0 / (1.0 - x * x);
        for scale in [1.0, 1e2, 1e4, 1e6] {
            let (mut world, _) = net_world(Integrator::Splitting, rate, scale);
            let e0 = net_energy(&mut world);
            let mut physics = PhysicsRunner::new(&mut world);
            let mut e = e0;
            for n in 0..(2 * rate) {
                physics.step(&mut world);
                world.clear_trackers();
                e = net_energy(&mut world);
                assert!(
                    e.is_finite() && e <= e0 * bound,
                    "1/{rate}, damping ×{scale}: step {n}: E {e} > E₀ {e0} × {bound}"
                );
            }
            assert!(e < e0, "1/{rate}, damping ×{scale}: E {e} vs E₀ {e0}");
            assert!(world.query::<&Rejected>().iter(&world).next().is_none());
        }
    }
}
