//! Unit tests of the step's contract that need no ECS: what counts as a diverged step.

use super::*;
use crate::error::UNIT_QUATERNION_TOLERANCE;
use crate::mass::Mass;
use crate::math::Quat;

/// A ball spinning so fast that the linearized rotation update `q + ½Δt (ω, 0) q` overflows
/// `|q|²`: `normalize` then scales by `1/√∞ = 0` and returns the zero quaternion, a finite
/// state that is no rotation at all.
fn overspun_ball() -> (BodyState, MassProperties) {
    let mass = MassProperties::new(Mass::new(1.0).unwrap(), Vec3::ONE).unwrap();
    let state = BodyState {
        angular_velocity: Vec3::new(1.0, -0.5, 0.25) * (Real::MAX.sqrt() * 1e3),
        ..BodyState::default()
    };
    (state, mass)
}

/// A body with an ordinary spin, which every method steps to a valid state.
fn calm_body(i: usize) -> BodyState {
    BodyState {
        position: Vec3::new(i as Real, 0.0, 0.0),
        rotation: Quat::from_rotation_y(0.3 * i as Real),
        linear_velocity: Vec3::X,
        angular_velocity: Vec3::new(0.5, 1.0, -0.2),
    }
}

#[test]
fn the_overspun_ball_steps_to_a_finite_zero_quaternion() {
    // The premise of the tests below: the old check (finite only) would commit this state.
    let (mut state, mass) = overspun_ball();
    Integrator::SymplecticEulerLinear.step(&mut state, &mass, &Wrench::ZERO, 1.0 / 60.0);
    assert!(state.is_finite());
    assert_eq!(state.rotation.length(), 0.0);
    assert!(!state.is_valid());
}

#[test]
fn a_non_unit_rotation_after_a_step_is_a_divergence_on_the_scalar_path() {
    let dt = 1.0 / 60.0;
    let (before, mass) = overspun_ball();
    let integrator = Integrator::SymplecticEulerLinear;
    let mut state = before;
    assert_eq!(
        integrator.try_step(&mut state, &mass, &Wrench::ZERO, dt),
        Err(StepError::Diverged { integrator })
    );
    assert_eq!(state, before, "a diverged body keeps its old state");
    assert_eq!(
        integrator.try_finish_step(&mut state, &mass, &Wrench::ZERO, dt),
        Err(StepError::Diverged { integrator })
    );
    assert_eq!(state, before);
}

#[test]
fn a_non_unit_rotation_after_a_step_is_a_divergence_on_the_batched_path() {
    let dt = 1.0 / 60.0;
    let (overspun, ball) = overspun_ball();
    let integrator = Integrator::SymplecticEulerLinear;
    let mut states: Vec<BodyState> = (0..5).map(calm_body).collect();
    states[2] = overspun;
    let masses = vec![ball; 5];
    let wrenches = vec![Wrench::ZERO; 5];
    let mut alone = states.clone();
    let diverged = integrator.try_step_many(&mut states, &masses, &wrenches, dt);
    assert_eq!(diverged, vec![2]);
    assert_eq!(states[2], overspun, "a diverged body keeps its old state");
    for i in [0, 1, 3, 4] {
        integrator
            .try_step(&mut alone[i], &masses[i], &wrenches[i], dt)
            .unwrap();
        assert_eq!(states[i], alone[i], "body {i} must be stepped as if alone");
    }
    let diverged = integrator.try_finish_step_many(&mut states, &masses, &wrenches, dt);
    assert_eq!(diverged, vec![2]);
    assert_eq!(states[2], overspun);
}

#[test]
fn is_valid_agrees_with_validate() {
    let (overspun, _) = overspun_ball();
    let mut cases = vec![
        BodyState::default(),
        calm_body(3),
        overspun,
        BodyState::ZEROED,
    ];
    for scale in [
        0.5,
        1.0 - 2.0 * UNIT_QUATERNION_TOLERANCE,
        1.0 + 0.5 * UNIT_QUATERNION_TOLERANCE,
    ] {
        let mut state = calm_body(1);
        state.rotation = state.rotation * scale;
        cases.push(state);
    }
    let mut non_finite = calm_body(2);
    non_finite.linear_velocity.y = Real::NAN;
    cases.push(non_finite);
    for state in cases {
        assert_eq!(state.is_valid(), state.validate().is_ok(), "{state:?}");
    }
}
