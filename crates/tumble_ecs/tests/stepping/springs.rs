//! A body on a spring follows the discrete map of symplectic Euler exactly, with the damper as
//! a flow for half a step on each side: `v ← decay(cΔt/2m) v`, `v' = v − Δt k x/m`,
//! `x' = x + Δt v'`, `v' ← decay(cΔt/2m) v'` — iterated here in f64.
//! Two bodies on one spring exchange equal and opposite forces.

use bevy_ecs::prelude::{Bundle, Entity, World};
use tumble_core::math::{Real, Vec3, to_f64};
use tumble_ecs::prelude::*;

use super::util::{run, spawn_body, world_with};

/// A body of mass `m` (unit moments) with `extra` (its pose, ...) on a spring `(k, c, L₀)` from
/// its centre of mass to the world origin.
fn on_spring_to_origin(
    world: &mut World,
    m: Real,
    extra: impl Bundle,
    (k, c, rest): (Real, Real, Real),
) -> Entity {
    let body = spawn_body(world, m, [1.0, 1.0, 1.0], extra);
    let origin = SpringEnd::World(Vec3::ZERO);
    world.spawn(Spring::new(body, Vec3::ZERO, origin, k, rest).with_damping(c));
    body
}

#[test]
fn anchored_spring_follows_the_discrete_map() {
    for (k, c) in [(40.0 as Real, 0.0 as Real), (40.0, 0.8)] {
        let (m, dt, x0) = (2.0 as Real, 1.0 / 60.0 as Real, 0.7 as Real);
        let mut world = world_with(dt, Integrator::SymplecticEuler);
        let at = Pose::from_translation(Vec3::new(x0, 0.0, 0.0));
        let body = on_spring_to_origin(&mut world, m, at, (k, c, 0.0));
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
        let got = world.get::<Pose>(body).unwrap().translation;
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
    let velocity = Velocity {
        linear: Vec3::new(0.0, 1.0, 0.0),
        angular: Vec3::new(0.0, 0.0, 2.0),
    };
    let at = |x: Real| Pose::from_translation(Vec3::new(x, 0.0, 0.0));
    let a = spawn_body(&mut world, ma, [0.1, 0.2, 0.3], (at(-1.0), velocity));
    let b = spawn_body(&mut world, mb, [0.3, 0.2, 0.1], at(1.0));
    let end = SpringEnd::on_body(b, Vec3::new(-0.1, 0.0, 0.3));
    world.spawn(Spring::new(a, Vec3::new(0.2, 0.1, 0.0), end, 50.0, 1.0).with_damping(0.5));
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
    // ωh = 1.5 is stiff enough for the implicit step by default: force the explicit one.
    world.resource_mut::<PhysicsSettings>().springs = SpringSolver::Explicit;
    let at = Pose::from_translation(Vec3::new(0.3, 0.0, 0.0));
    let v = Velocity::linear(Vec3::new(-1.0, 0.0, 0.0));
    let body = on_spring_to_origin(&mut world, m, (at, v), (k, 0.0, 0.0));
    let steps = 2000;
    run(&mut world, steps);
    let (w2, h) = (to_f64(k / m), to_f64(dt));
    let (mut x, mut v) = (0.3_f64, -1.0_f64);
    for _ in 0..steps {
        let half = x + 0.5 * h * v;
        v -= h * w2 * half;
        x = half + 0.5 * h * v;
    }
    let got = world.get::<Pose>(body).unwrap().translation.x;
    // Bounded orbit of amplitude ≤ 0.4 m; f32 round-off grows like n ε relative at worst.
    assert!(
        (to_f64(got) - x).abs() < 2000.0 * 4.0 * to_f64(Real::EPSILON),
        "{got} vs {x}"
    );
}

/// A body of mass `m` on a damped spring to a world anchor, moving along x (anchor at the
/// centre of mass, rest length 1 m, released 0.5 m stretched): (stretch, velocity) after every
/// step, in f64.
fn damped_oscillator(
    integrator: Integrator,
    (m, k, c): (Real, Real, Real),
    dt: Real,
    steps: usize,
) -> Vec<(f64, f64)> {
    damped_oscillator_with(integrator, SpringSolver::Explicit, (m, k, c), dt, steps)
}

/// [`damped_oscillator`] with the spring step chosen by `springs`.
fn damped_oscillator_with(
    integrator: Integrator,
    springs: SpringSolver,
    (m, k, c): (Real, Real, Real),
    dt: Real,
    steps: usize,
) -> Vec<(f64, f64)> {
    let mut world = world_with(dt, integrator);
    world.resource_mut::<PhysicsSettings>().springs = springs;
    let at = Pose::from_translation(Vec3::new(1.5, 0.0, 0.0));
    let body = on_spring_to_origin(&mut world, m, at, (k, c, 1.0));
    let mut physics = PhysicsRunner::new(&mut world);
    (0..steps)
        .map(|_| {
            physics.step(&mut world);
            world.clear_trackers();
            let x = world.get::<Pose>(body).unwrap().translation.x;
            let v = world.get::<Velocity>(body).unwrap().linear.x;
            (to_f64(x) - 1.0, to_f64(v))
        })
        .collect()
}

/// With damping, a step never adds energy, however large `cΔt`. Drift–kick–drift conserves the
/// modified energy `Ẽ = ½ m (1 − (ωΔt/2)²) v² + ½ k ξ²` of a linear spring exactly, and the
/// damper's half-step flows only shrink `v`; so `Ẽ` must not grow in any step beyond the f32
/// round-off of the state (`ε` of the position ≤ 1.5 m and of the velocity). The old damper (an
/// explicit force in the kick) diverged once `cΔt/m > 2`.
#[test]
fn damped_spring_never_gains_energy() {
    let (m, k) = (1.0 as Real, 40.0 as Real);
    let eps = to_f64(Real::EPSILON);
    for dt in [1.0 / 60.0 as Real, 0.2] {
        // c Δt / m from 1.7e-3 to 2e5.
        for c in [0.1 as Real, 2.0, 20.0, 1e3, 1e6] {
            let x = to_f64(dt) * to_f64(k / m).sqrt() / 2.0;
            let modified = |(xi, v): (f64, f64)| {
                0.5 * to_f64(m) * (1.0 - x * x) * v * v + 0.5 * to_f64(k) * xi * xi
            };
            let run = damped_oscillator(Integrator::Splitting, (m, k, c), dt, 400);
            // Round-off of the state: the position (≤ 1.5 m) to ε·1.5 m, the velocity to ε|v|;
            // the last term is the elastic energy of a stretch of `floor` (below it the state
            // is round-off only). Returns the last energy.
            let never_grows =
                |run: &[(f64, f64)], energy: &dyn Fn((f64, f64)) -> f64, floor: f64, what: &str| {
                    let mut previous = energy((0.5, 0.0));
                    for (n, &(xi, v)) in run.iter().enumerate() {
                        let e = energy((xi, v));
                        let round_off =
                            4.0 * eps * (to_f64(k) * xi.abs() * 1.5 + to_f64(m) * v * v + e)
                                + 0.5 * to_f64(k) * floor * floor;
                        assert!(
                            e.is_finite() && e <= previous + round_off,
                            "{what}dt={dt} c={c}: step {n}: {e:e} > {previous:e}"
                        );
                        previous = e;
                    }
                    previous
                };
            // A stretch of 4 ulps of the position.
            let last = never_grows(&run, &modified, 4.0 * (1.5 * eps), "Ẽ: ");
            assert!(last < modified((0.5, 0.0)), "dt={dt} c={c}: no energy lost");
            // The implicit spring step keeps the true energy `½ m v² + ½ k ξ²` of the undamped
            // spring exactly, so with the damper's flows around it that energy never grows.
            let true_energy =
                |(xi, v): (f64, f64)| 0.5 * to_f64(m) * v * v + 0.5 * to_f64(k) * xi * xi;
            let run = damped_oscillator_with(
                Integrator::Splitting,
                SpringSolver::Implicit,
                (m, k, c),
                dt,
                400,
            );
            never_grows(&run, &true_energy, 6.0 * eps, "implicit E: ");
        }
    }
}

/// At `ωΔt ≤ 0.5` a damped spring loses its energy at the physical rate: the mean decay rate
/// `ln(E₀/E(T))/T` within 10 % of the closed form's, over a horizon where the energy falls by
/// about e³. (The step-point energy of drift–kick–drift swings by up to `1/(1 − (ωΔt/2)²)` =
/// 6.7 % at ωΔt = 0.5 around its invariant: 0.065 in `ln E`, 2 % of the measured
/// `ln(E₀/E) ≈ 3`.)
///
/// The damper must be resolved too, `cΔt/m = 2ζωΔt ≤ 0.4`: the splitting error of the rate is
/// second order in `cΔt/m` (measured at ωΔt = 0.5: +11 % at ζ = 0.7, +24 % at ζ = 1, +44 % at
/// ζ = 2, i.e. cΔt/m = 0.7 … 2, where the step stops the fast overdamped mode instead of
/// following it; at ωΔt = 0.1 and ζ = 2 it is +1.7 %).
#[test]
fn damped_spring_loses_energy_at_the_physical_rate() {
    use tumble_reference::exact::DampedSpring;
    let (m, k) = (1.0_f64, 40.0_f64);
    let omega = (k / m).sqrt();
    for omega_dt in [0.1, 0.25, 0.5] {
        for zeta in [0.02, 0.1, 0.3, 0.7, 1.0, 1.5, 2.0] {
            if 2.0 * zeta * omega_dt > 0.4 {
                // cΔt/m > 0.4: the damper itself is resolved too coarsely (see above).
                continue;
            }
            let c = 2.0 * zeta * (k * m).sqrt();
            let exact = DampedSpring::new(0.5, 0.0, k, c, m).unwrap();
            // Mean energy decay rate: 2ζω underdamped; the slow mode's 2(ζ − √(ζ² − 1))ω
            // overdamped.
            let rate = if zeta < 1.0 {
                2.0 * zeta * omega
            } else {
                2.0 * (zeta - (zeta * zeta - 1.0).sqrt()) * omega
            };
            let dt = omega_dt / omega;
            let steps = (3.0 / rate / dt).round() as usize;
            let horizon = steps as f64 * dt;
            let run = damped_oscillator(
                Integrator::Splitting,
                (m as Real, k as Real, c as Real),
                dt as Real,
                steps,
            );
            let (xi, v) = run[steps - 1];
            let e = 0.5 * k * xi * xi + 0.5 * m * v * v;
            let e0 = exact.energy(0.0);
            let got = (e0 / e).ln() / horizon;
            let want = (e0 / exact.energy(horizon)).ln() / horizon;
            eprintln!(
                "ωΔt={omega_dt} ζ={zeta}: decay rate {got:.4}/s vs {want:.4}/s ({:+.3})",
                got / want - 1.0
            );
            assert!(
                (got / want - 1.0).abs() < 0.1,
                "ωΔt={omega_dt} ζ={zeta}: decay rate {got:.4}/s vs {want:.4}/s"
            );
        }
    }
}
