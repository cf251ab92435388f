//! With `free_flow = method` the planner names `exact` for spins the split free rotation
//! integrates badly, by the rule `Δt² |ω_b ω_c| |I_b − I_c| / I_a > 1 %` (see
//! `tumble_core::integrate::FreeFlow`), and the rule matches what a run measures: the
//! orientation error of `splitting` against `exact` over 10 s. (Under the default, `auto`,
//! such bodies take the exact flow: `tests/free_flow.rs`.)

use bevy_ecs::prelude::*;
use tumble_core::math::Widen;
use tumble_core::math::{Real, Vec3};
use tumble_core::rotation::angle_between;
use tumble_core::{BodyState, Integrator, Mass, MassProperties, Wrench};
use tumble_ecs::prelude::*;
use tumble_ecs::stability::{
    FIRST_ORDER_DRIFT_LIMIT, SPLIT_ERROR_LIMIT, first_order_drift, split_rotation_error,
};

/// A thin asymmetric plate, as asymmetric as the triangle inequality allows.
const PLATE: Vec3 = Vec3::new(0.01, 1.0, 1.01);

/// A world of one body, its split methods keeping their own free flow.
fn world_with(inertia: Vec3, omega: Vec3, dt: Real, integrator: Integrator) -> World {
    let mut world = World::new();
    world.insert_resource(
        PhysicsSettings::new(dt, integrator)
            .unwrap()
            .with_free_flow(FreeFlow::Method),
    );
    let mass = MassProperties::new(Mass::new(1.0).unwrap(), inertia).unwrap();
    world.spawn((RigidBody, MassProps(mass), Velocity::angular(omega)));
    world
}

fn warned_rk4(world: &mut World) -> bool {
    check_stability(world).iter().any(|w| {
        matches!(w, StabilityWarning::StiffRk4Rotation { .. })
            && !w.is_instability()
            && w.to_string().contains("`exact`")
    })
}

/// Orientation error of `integrator` against `exact` after 10 s.
fn error_of(integrator: Integrator, inertia: Vec3, omega: Vec3, dt: Real) -> f64 {
    let mass = MassProperties::new(Mass::new(1.0).unwrap(), inertia).unwrap();
    let start = BodyState {
        angular_velocity: omega,
        ..Default::default()
    };
    let (mut other, mut exact) = (start, start);
    for _ in 0..(10.0 / dt).round() as usize {
        integrator.step(&mut other, &mass, &Wrench::ZERO, dt);
        Integrator::Exact.step(&mut exact, &mass, &Wrench::ZERO, dt);
    }
    angle_between(other.rotation, exact.rotation)
}

#[test]
fn rk4_is_warned_about_where_its_rotation_is_stiff() {
    let dt = 1.0 / 60.0;
    // A slowly turning rod: |L|Δt/I_min ≈ 110 at 2 rad/s.
    let rod = Vec3::new(1e-4, 1.0, 1.0);
    let slow = 2.0 * Vec3::new(0.3, 1.0, 0.5).normalize();
    assert!(warned_rk4(&mut world_with(rod, slow, dt, Integrator::Rk4)));
    let error = error_of(Integrator::Rk4, rod, slow, dt);
    assert!(error > 0.1, "warned, but rk4 is off by only {error:e} rad");
    assert!(error_of(Integrator::Splitting, rod, slow, dt) < 1e-3);
    // A box at 2 rad/s: |L|Δt/I_min ≈ 0.07, not warned, and accurate.
    let box_inertia = Vec3::new(1.0, 2.0, 3.0);
    let spin = 2.0 * Vec3::new(1.0, 5.0, 1.0).normalize();
    assert!(!warned_rk4(&mut world_with(
        box_inertia,
        spin,
        dt,
        Integrator::Rk4
    )));
    assert!(error_of(Integrator::Rk4, box_inertia, spin, dt) < 1e-4);
    // Other methods are not warned about by this rule.
    assert!(!warned_rk4(&mut world_with(
        rod,
        slow,
        dt,
        Integrator::Splitting
    )));
}

fn warned(world: &mut World) -> bool {
    check_stability(world).iter().any(|w| {
        matches!(w, StabilityWarning::InexactFreeRotation { .. })
            && !w.is_instability()
            && w.to_string().contains("`exact`")
    })
}

/// Orientation error of `splitting` against `exact` after 10 s.
fn split_error(inertia: Vec3, omega: Vec3, dt: Real) -> f64 {
    error_of(Integrator::Splitting, inertia, omega, dt)
}

#[test]
fn a_fast_thin_plate_is_warned_about_and_its_error_is_real() {
    let omega = 15.0 * Vec3::new(0.3, 1.0, 0.5).normalize();
    let dt = 1.0 / 60.0;
    let e = split_rotation_error(PLATE.widen(), omega.widen(), dt.widen());
    assert!(e > SPLIT_ERROR_LIMIT.widen(), "e = {e}");
    assert!(warned(&mut world_with(
        PLATE,
        omega,
        dt,
        Integrator::Splitting
    )));
    // Measured ≈ 0.4–0.7 e T rad; at e > 1 % that is well over 0.02 rad in 10 s.
    let error = split_error(PLATE, omega, dt);
    assert!(
        error > 0.02,
        "warned, but splitting is off by only {error:e} rad"
    );
    // `exact` is not warned about.
    assert!(!warned(&mut world_with(
        PLATE,
        omega,
        dt,
        Integrator::Exact
    )));
}

#[test]
fn the_same_spin_at_a_shorter_step_or_an_ordinary_spin_is_not() {
    let omega = 15.0 * Vec3::new(0.3, 1.0, 0.5).normalize();
    // 240 Hz: e falls 16-fold, under the limit, and so does the error.
    let dt = 1.0 / 240.0;
    assert!(
        split_rotation_error(PLATE.widen(), omega.widen(), dt.widen()) < SPLIT_ERROR_LIMIT.widen()
    );
    assert!(!warned(&mut world_with(
        PLATE,
        omega,
        dt,
        Integrator::Splitting
    )));
    let error = split_error(PLATE, omega, dt);
    assert!(error < 0.02, "not warned, but off by {error:e} rad");
    // An ordinary box tumbling at 3 rad/s and 60 Hz.
    let box_inertia = Vec3::new(1.0, 2.0, 3.0);
    let slow = Vec3::new(1.0, 2.5, 1.0);
    assert!(!warned(&mut world_with(
        box_inertia,
        slow,
        1.0 / 60.0,
        Integrator::Splitting
    )));
}

#[test]
fn the_rule_takes_the_odd_axis_whatever_the_order() {
    let plate = PLATE.widen();
    let omega = glam::DVec3::new(1.0, 2.0, 3.0);
    let e = split_rotation_error(plate, omega, 0.1);
    // a = x (the thin axis), b, c = y, z: 0.01 · |2 · 3| · 0.01 / 0.01 (the moments as rounded
    // to the engine's precision).
    assert!((e - 0.06).abs() < 1e-6, "{e}");
    let permuted = split_rotation_error(
        glam::DVec3::new(plate.z, plate.x, plate.y),
        glam::DVec3::new(omega.z, omega.x, omega.y),
        0.1,
    );
    assert!((permuted - e).abs() < 1e-12);
    // A symmetric body: no error at all.
    assert_eq!(
        split_rotation_error(glam::DVec3::new(0.01, 1.0, 1.0), omega, 0.1),
        0.0
    );
}

fn warned_of(world: &mut World, integrator: Integrator) -> bool {
    check_stability(world).iter().any(|w| {
        let named = match w {
            StabilityWarning::InexactFreeRotation { integrator: i, .. }
            | StabilityWarning::FirstOrderGyroscopic { integrator: i, .. } => *i == integrator,
            _ => false,
        };
        named && !w.is_instability() && w.to_string().contains("`exact`")
    })
}

/// `yoshida4` is judged by the split error of its largest stage, against a looser limit: warned
/// where it is off by more than the budget over 10 s, silent where it is far inside it.
#[test]
fn yoshida4_is_warned_about_on_a_fast_thin_plate_only() {
    let dt = 1.0 / 60.0;
    let direction = Vec3::new(0.3, 1.0, 0.5).normalize();
    let fast = 32.0 * direction;
    assert!(warned_of(
        &mut world_with(PLATE, fast, dt, Integrator::Yoshida4),
        Integrator::Yoshida4
    ));
    let error = error_of(Integrator::Yoshida4, PLATE, fast, dt);
    assert!(
        error > 0.02,
        "warned, but yoshida4 is off by only {error:e} rad"
    );
    // Half the spin: a quarter of the per-stage error, and the composition holds.
    let moderate = 16.0 * direction;
    assert!(!warned_of(
        &mut world_with(PLATE, moderate, dt, Integrator::Yoshida4),
        Integrator::Yoshida4
    ));
    let error = error_of(Integrator::Yoshida4, PLATE, moderate, dt);
    assert!(error < 0.02, "not warned, but off by {error:e} rad");
}

/// `lclamp` and `implicit-gyroscopic` are warned about where their first-order drift over 10 s
/// exceeds the budget, and the prediction is of the size a run measures.
#[test]
fn first_order_gyroscopic_methods_are_warned_about_where_they_drift() {
    let dt = 1.0 / 60.0;
    let box_inertia = Vec3::new(1.0, 2.0, 3.0);
    let direction = Vec3::new(0.3, 1.0, 0.5).normalize();
    for integrator in [Integrator::Lclamp, Integrator::ImplicitGyroscopic] {
        for (inertia, speed) in [(box_inertia, 1.0), (PLATE, 2.0), (box_inertia, 4.0)] {
            let omega = speed * direction;
            assert!(
                warned_of(&mut world_with(inertia, omega, dt, integrator), integrator),
                "{integrator} at {speed} rad/s"
            );
            let predicted = first_order_drift(integrator, inertia, omega, dt).unwrap();
            let error = error_of(integrator, inertia, omega, dt);
            assert!(
                error > 0.01 && error < 10.0 * predicted.widen(),
                "{integrator} at {speed} rad/s: predicted {predicted:e}, measured {error:e}"
            );
        }
        // A slow spin: not warned, and the error is within the budget.
        let slow = 0.5 * direction;
        assert!(!warned_of(
            &mut world_with(box_inertia, slow, dt, integrator),
            integrator
        ));
        let error = error_of(integrator, box_inertia, slow, dt);
        assert!(
            error < FIRST_ORDER_DRIFT_LIMIT.widen(),
            "{integrator}: {error:e}"
        );
    }
    // `splitting` is not warned about by this rule at the same spins.
    assert!(!warned_of(
        &mut world_with(box_inertia, direction, dt, Integrator::Splitting),
        Integrator::Splitting
    ));
}
