//! A body on a spring follows the discrete map of symplectic Euler exactly, with the damper as
//! a flow for half a step on each side: `v ← decay(cΔt/2m) v`, `v' = v − Δt k x/m`,
//! `x' = x + Δt v'`, `v' ← decay(cΔt/2m) v'` — iterated here in f64.
//! Two bodies on one spring exchange equal and opposite forces.

use tumble::math::{Real, Vec3, to_f64};
use tumble::prelude::*;

use super::util::{mass_props, run, world_with};

#[test]
fn anchored_spring_follows_the_discrete_map() {
    for (k, c) in [(40.0 as Real, 0.0 as Real), (40.0, 0.8)] {
        let (m, dt, x0) = (2.0 as Real, 1.0 / 60.0 as Real, 0.7 as Real);
        let mut world = world_with(dt, Integrator::SymplecticEuler);
        let body = world
            .spawn((
                RigidBody,
                mass_props(m, [1.0, 1.0, 1.0]),
                Transform::from_translation(Vec3::new(x0, 0.0, 0.0)),
            ))
            .id();
        world.spawn(Spring {
            a: body,
            anchor_a: Vec3::ZERO,
            b: SpringEnd::World(Vec3::ZERO),
            stiffness: k,
            damping: c,
            rest_length: 0.0,
        });
        let steps = 300;
        run(&mut world, steps);
        let (mut x, mut v) = (to_f64(x0), 0.0_f64);
        let (k, c, m, h) = (to_f64(k), to_f64(c), to_f64(m), to_f64(dt));
        let mut amplitude = x.abs();
        // The damper's half-step decay 1/(1 + y + y²/2 + y³/6), y = c (Δt/2) / m_eff, with
        // m_eff = m for an anchor at the centre of mass.
        let y = c * 0.5 * h / m;
        let decay = 1.0 / (1.0 + y + y * y / 2.0 + y * y * y / 6.0);
        for _ in 0..steps {
            v *= decay;
            v -= h * k * x / m;
            x += h * v;
            v *= decay;
            amplitude = amplitude.max(x.abs());
        }
        let got = world.get::<Transform>(body).unwrap().translation;
        // f32 round-off accumulates about n ε of the amplitude.
        let tol = 300.0 * 4.0 * to_f64(Real::EPSILON) * amplitude;
        assert!(
            (to_f64(got.x) - x).abs() < tol,
            "k={k} c={c}: x {} vs {x}",
            got.x
        );
        assert!(got.y.abs() < 1e-6 && got.z.abs() < 1e-6);
    }
}

#[test]
fn two_body_spring_conserves_linear_momentum() {
    let dt = 1.0 / 120.0;
    let mut world = world_with(dt, Integrator::SymplecticEuler);
    let (ma, mb) = (1.0 as Real, 3.0 as Real);
    let a = world
        .spawn((
            RigidBody,
            mass_props(ma, [0.1, 0.2, 0.3]),
            Transform::from_translation(Vec3::new(-1.0, 0.0, 0.0)),
            Velocity {
                linear: Vec3::new(0.0, 1.0, 0.0),
                angular: Vec3::new(0.0, 0.0, 2.0),
            },
        ))
        .id();
    let b = world
        .spawn((
            RigidBody,
            mass_props(mb, [0.3, 0.2, 0.1]),
            Transform::from_translation(Vec3::new(1.0, 0.0, 0.0)),
        ))
        .id();
    world.spawn(Spring {
        a,
        anchor_a: Vec3::new(0.2, 0.1, 0.0),
        b: SpringEnd::Body {
            body: b,
            anchor: Vec3::new(-0.1, 0.0, 0.3),
        },
        stiffness: 50.0,
        damping: 0.5,
        rest_length: 1.0,
    });
    let p0 = Vec3::new(0.0, 1.0, 0.0) * ma;
    run(&mut world, 240);
    let va = world.get::<Velocity>(a).unwrap().linear;
    let vb = world.get::<Velocity>(b).unwrap().linear;
    let p = va * ma + vb * mb;
    assert!(
        (p - p0).length() < 1e-4 * (va.length() * ma + vb.length() * mb),
        "p {p} vs {p0}"
    );
    assert!(vb.length() > 0.1, "the spring must have moved b");
}

#[test]
fn default_integrator_spring_is_position_verlet() {
    // Forces sampled at the midpoint: x_{½} = x + ½h v; v' = v + h a(x_{½}); x' = x_{½} + ½h v'.
    // Symplectic and second order: stable for ω h < 2, here ω h = 1.5.
    let (m, k, dt) = (0.5 as Real, 4050.0 as Real, 1.0 / 60.0 as Real);
    let mut world = world_with(dt, Integrator::Splitting);
    let body = world
        .spawn((
            RigidBody,
            mass_props(m, [1.0, 1.0, 1.0]),
            Transform::from_translation(Vec3::new(0.3, 0.0, 0.0)),
            Velocity::linear(Vec3::new(-1.0, 0.0, 0.0)),
        ))
        .id();
    world.spawn(Spring {
        a: body,
        anchor_a: Vec3::ZERO,
        b: SpringEnd::World(Vec3::ZERO),
        stiffness: k,
        damping: 0.0,
        rest_length: 0.0,
    });
    let steps = 2000;
    run(&mut world, steps);
    let (w2, h) = (to_f64(k / m), to_f64(dt));
    let (mut x, mut v) = (0.3_f64, -1.0_f64);
    for _ in 0..steps {
        let half = x + 0.5 * h * v;
        v -= h * w2 * half;
        x = half + 0.5 * h * v;
    }
    let got = world.get::<Transform>(body).unwrap().translation.x;
    // Bounded orbit of amplitude ≤ 0.4 m; f32 round-off grows like n ε relative at worst.
    assert!(
        (to_f64(got) - x).abs() < 2000.0 * 4.0 * to_f64(Real::EPSILON),
        "{got} vs {x}"
    );
}
