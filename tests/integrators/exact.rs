//! The `exact` integrator through the public step, in the build's precision: the thin asymmetric
//! body at every spin rate, the Dzhanibekov tumble, any step length, and second order with loads.
//!
//! Tolerances: the exact flow has no truncation error, so what is left is the rounding of the
//! stored state to the build precision, plus the f64 reference's own error (RK4 at h = 1e-4:
//! ≈ 1e-10 here). Each step rounds `q` and `ω` (ε each); a thin body re-reads its long-axis rate
//! from them, so a rounding of `ε|ω|` lands on a rate `|ω|/|ω₁|` times smaller, and the tumble
//! carries a perturbation forward with a gain that grows with time: 16ε per step bounds all of it
//! for the bodies here (measured ≤ 13ε per step in f32, on the needle spun transversely at
//! `|ω|Δt = 3`; 2ε at `|ω|Δt = 0.1`). The targets (f64:
//! 1e-5 rad and 1e-6 in energy and |L| over 10 s; f32: 1e-3 rad) are asserted as well.

use tumble::core::rotation::angle_between;
use tumble::glam::{DQuat, DVec3};
use tumble::math::{DOUBLE_PRECISION, Real, Vec3, Widen, to_f64};
use tumble::prelude::*;
use tumble_reference::exact::TorqueFreeTop;
use tumble_reference::rk4::free_body;

use super::harness::torque_free;

/// Rounding bound of `steps` steps in the build precision (16ε each, see the module docs), plus
/// the reference's error.
fn round_off_floor(steps: usize) -> f64 {
    16.0 * to_f64(Real::EPSILON) * steps as f64 + 1e-9
}

/// The target for the orientation error over 10 s.
fn orientation_target() -> f64 {
    if DOUBLE_PRECISION { 1e-5 } else { 1e-3 }
}

/// Energy and world momentum of `state` in f64 (so the measurement adds no f32 round-off).
fn invariants(state: &BodyState, inertia: DVec3) -> (f64, DVec3) {
    let q = state.rotation.widen().normalize();
    let w = q.conjugate() * state.angular_velocity.widen();
    let m = inertia * w;
    (0.5 * w.dot(m), q * m)
}

struct Drift {
    orientation: f64,
    energy: f64,
    momentum: f64,
}

/// Runs `exact` torque-free from body rates `omega0` (principal = body frame, identity start)
/// for `steps` steps of `dt`, against RK4 in f64 at every step.
fn run(inertia: Vec3, omega0: Vec3, dt: Real, steps: usize) -> Drift {
    run_with(Integrator::Exact, inertia, omega0, dt, steps)
}

/// [`run`] with `integrator`.
fn run_with(integrator: Integrator, inertia: Vec3, omega0: Vec3, dt: Real, steps: usize) -> Drift {
    let mass = MassProperties::new(Mass::new(1.0).unwrap(), inertia).unwrap();
    let mut state = BodyState {
        angular_velocity: omega0,
        ..Default::default()
    };
    let inertia64 = inertia.widen();
    let (e0, l0) = invariants(&state, inertia64);
    let times: Vec<f64> = (1..=steps).map(|k| k as f64 * to_f64(dt)).collect();
    let reference = free_body(inertia64, omega0.widen(), &times);
    let mut drift = Drift {
        orientation: 0.0,
        energy: 0.0,
        momentum: 0.0,
    };
    for (q_ref, _) in reference {
        integrator
            .try_step(&mut state, &mass, &Wrench::ZERO, dt)
            .unwrap();
        let q_ref = tumble::math::Quat::from_xyzw(
            q_ref.x as Real,
            q_ref.y as Real,
            q_ref.z as Real,
            q_ref.w as Real,
        );
        drift.orientation = drift.orientation.max(angle_between(state.rotation, q_ref));
        let (e, l) = invariants(&state, inertia64);
        drift.energy = drift.energy.max((e / e0 - 1.0).abs());
        drift.momentum = drift.momentum.max((l - l0).length() / l0.length());
    }
    drift
}

#[test]
fn the_thin_asymmetric_body_is_right_at_every_spin_rate() {
    // The thinnest asymmetric bodies there are (`I₃ − I₂ ≤ I₁`, the triangle inequality): a
    // thin plate, and a needle asymmetric by all its `I₁` allows; spun about axes tilted from
    // the long axis and from the transverse ones (both polhode cases).
    let bodies = [Vec3::new(0.01, 1.0, 1.01), Vec3::new(1e-4, 1.0, 1.0001)];
    let directions = [Vec3::new(1.0, 0.3, 0.2), Vec3::new(0.3, 1.0, 0.5)];
    for (inertia, direction) in bodies.into_iter().flat_map(|i| directions.map(|d| (i, d))) {
        let omega0 = 10.0 * direction.normalize();
        for omega_dt in [0.1f64, 0.3, 1.0, 3.0] {
            let dt = (omega_dt / 10.0) as Real;
            let steps = (100.0 / omega_dt).round() as usize;
            let drift = run(inertia, omega0, dt, steps);
            let floor = round_off_floor(steps);
            eprintln!(
                "I = {inertia}, ω̂ = {direction}, |ω|Δt = {omega_dt}: {:.1e} rad, energy {:.1e}, |L| {:.1e} (floor {floor:.1e})",
                drift.orientation, drift.energy, drift.momentum
            );
            assert!(
                drift.orientation <= floor.min(orientation_target()),
                "|ω|Δt = {omega_dt}: orientation {:e} rad",
                drift.orientation
            );
            assert!(drift.energy <= floor && drift.momentum <= floor);
        }
    }
}

#[test]
fn exact4_is_exact_torque_free_too() {
    let inertia = Vec3::new(0.01, 1.0, 1.01);
    let omega0 = 10.0 * Vec3::new(0.3, 1.0, 0.5).normalize();
    let drift = run_with(Integrator::Exact4, inertia, omega0, 0.1, 100);
    let floor = round_off_floor(100);
    assert!(drift.orientation <= floor, "{:e} rad", drift.orientation);
    assert!(drift.energy <= floor && drift.momentum <= floor);
}

#[test]
fn the_dzhanibekov_tumble_flips_on_time() {
    let inertia = Vec3::new(1.0, 2.0, 3.0);
    let omega0 = Vec3::new(1.0, 5.0, 1.0);
    let dt: Real = 1.0 / 60.0;
    let top = TorqueFreeTop::new(inertia.widen(), omega0.widen(), DQuat::IDENTITY).unwrap();
    let exact_flips = top.middle_axis_sign_changes(to_f64(dt) * 7200.0);
    assert_eq!(exact_flips, 67);
    let tumble = torque_free(Integrator::Exact, inertia, omega0, dt, 7200);
    assert_eq!(u64::from(tumble.flips), exact_flips);
    // 10 s against the reference, at 60 Hz.
    let drift = run(inertia, omega0, dt, 600);
    let floor = round_off_floor(600);
    assert!(drift.orientation <= floor.min(orientation_target()));
    assert!(drift.energy <= floor.min(1e-6) || !DOUBLE_PRECISION);
    assert!(drift.momentum <= floor);
}

#[test]
fn one_step_of_any_length_is_the_exact_motion() {
    let inertia = Vec3::new(0.02, 0.03, 0.04);
    let omega0 = Vec3::new(3.0, -2.0, 5.0);
    let top = TorqueFreeTop::new(inertia.widen(), omega0.widen(), DQuat::IDENTITY).unwrap();
    let mass = MassProperties::new(Mass::new(1.0).unwrap(), inertia).unwrap();
    for dt in [0.5, 3.0, 40.0] {
        let mut state = BodyState {
            angular_velocity: omega0,
            ..Default::default()
        };
        Integrator::Exact.step(&mut state, &mass, &Wrench::ZERO, dt);
        let q = top.orientation(to_f64(dt));
        let q = tumble::math::Quat::from_xyzw(q.x as Real, q.y as Real, q.z as Real, q.w as Real);
        let error = angle_between(state.rotation, q);
        // One rounding of the state, and the reference's ε·φ(t).
        assert!(
            error <= round_off_floor(1) + 1e-12 * to_f64(dt),
            "Δt = {dt}: {error:e} rad"
        );
    }
}

/// A load that turns with the body: a world force at a body point (its torque changes with
/// the orientation), plus the force itself.
fn point_load(state: &BodyState) -> Wrench {
    let force = Vec3::new(0.0, -2.0, 0.5);
    let arm = state.rotation * Vec3::new(0.3, 0.1, -0.2);
    Wrench {
        force,
        torque: arm.cross(force),
    }
}

/// Observed orders of `integrator` under [`point_load`] over 1 s, from the errors at `rates`
/// steps against `fine` steps of the same method.
fn observed_orders(integrator: Integrator, rates: [u32; 3], fine: u32) -> Vec<f64> {
    let inertia = Vec3::new(1e-2, 0.05, 0.06);
    let mass = MassProperties::new(Mass::new(1.0).unwrap(), inertia).unwrap();
    let start = BodyState {
        angular_velocity: Vec3::new(2.0, 1.0, -1.5),
        ..Default::default()
    };
    let run = |steps: u32| {
        let dt = 1.0 / steps as Real;
        let mut state = start;
        for _ in 0..steps {
            integrator.step_with(&mut state, &mass, dt, point_load);
        }
        state
    };
    let fine = run(fine);
    let errors: Vec<f64> = rates
        .iter()
        .map(|&n| angle_between(run(n).rotation, fine.rotation))
        .collect();
    let orders: Vec<f64> = errors.windows(2).map(|e| (e[0] / e[1]).log2()).collect();
    eprintln!("{integrator}: errors {errors:?}, orders {orders:?}");
    orders
}

#[test]
fn with_loads_exact4_is_fourth_order() {
    // 12 … 48 steps: past the pre-asymptotic 8 (slope 4.4), errors (2e-2 … 8e-5) well above
    // the f32 rounding of the 384-step reference (≈ 5e-6).
    for order in observed_orders(Integrator::Exact4, [12, 24, 48], 384) {
        assert!((order - 4.0).abs() < 0.3, "observed order {order}");
    }
}

#[test]
fn with_loads_it_is_second_order() {
    for order in observed_orders(Integrator::Exact, [16, 32, 64], 2048) {
        assert!((order - 2.0).abs() < 0.3, "observed order {order}");
    }
}
