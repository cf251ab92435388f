//! Conservation for a torque-free body under the textbook integrator.
//!
//! Linear momentum is untouched by a zero force (bit-exact). For the explicit gyroscopic step the
//! body-frame kick `L_b' = L_b + Δt (L_b × ω_b)` is orthogonal to `L_b`, so
//! `|L'|² = |L|² + Δt² |L_b × ω_b|²`: each step raises `|L|` by at most `½ (Δt |ω|)²` relative,
//! and over `n` steps by at most `n ½ (Δt |ω|)²` (first order). Energy and `|L|` drift must
//! therefore shrink about 2× per halving of Δt.

use tumble_core::BodyState;
use tumble_core::math::{Real, Vec3, to_f64};
use tumble_ecs::prelude::*;

use super::util::{mass_props, run, world_with};

fn angular_momentum_drift(dt: Real, seconds: Real) -> (f64, f64) {
    let omega0 = Vec3::new(1.0, 2.0, 3.0);
    let mass = mass_props(2.0, [1.0, 2.0, 3.0]);
    let state = |t: &Pose, v: &Velocity| BodyState {
        position: t.translation,
        rotation: t.rotation,
        linear_velocity: v.linear,
        angular_velocity: v.angular,
    };
    let mut world = world_with(dt, Integrator::SymplecticEuler);
    let id = world
        .spawn((
            RigidBody,
            mass,
            Velocity {
                linear: Vec3::new(1.0, -2.0, 0.5),
                angular: omega0,
            },
        ))
        .id();
    let l0 = tumble_core::invariants::angular_momentum(
        &state(&Pose::IDENTITY, world.get::<Velocity>(id).unwrap()),
        &mass,
    );
    let steps = (seconds / dt).round() as usize;
    run(&mut world, steps);
    let v = world.get::<Velocity>(id).unwrap();
    assert_eq!(
        v.linear,
        Vec3::new(1.0, -2.0, 0.5),
        "linear momentum must be exact"
    );
    let l =
        tumble_core::invariants::angular_momentum(&state(world.get::<Pose>(id).unwrap(), v), &mass);
    let bound = steps as f64 * 0.5 * to_f64(dt * omega0.length()).powi(2);
    let drift = to_f64((l.length() - l0.length()) / l0.length());
    (drift, bound)
}

#[test]
fn angular_momentum_norm_drift_is_bounded_and_first_order() {
    let (d1, b1) = angular_momentum_drift(1.0 / 240.0, 1.0);
    let (d2, b2) = angular_momentum_drift(1.0 / 480.0, 1.0);
    assert!(d1 >= 0.0 && d1 <= b1, "drift {d1} outside [0, {b1}]");
    assert!(d2 >= 0.0 && d2 <= b2, "drift {d2} outside [0, {b2}]");
    let ratio = d1 / d2;
    assert!(
        (1.6..2.5).contains(&ratio),
        "first order: halving Δt halves drift, got {ratio}"
    );
}
