//! Unit tests of the step's contract that need no ECS: what counts as a diverged step.

use super::*;
use crate::error::UNIT_QUATERNION_TOLERANCE;
use crate::mass::Mass;
use crate::math::{Quat, Vec3, Widen};

/// A ball flying so fast from so far out that one step carries its position past the largest
/// finite number: the step's result is not finite.
fn overspun_ball() -> (BodyState, MassProperties) {
    let mass = MassProperties::new(Mass::new(1.0).unwrap(), Vec3::ONE).unwrap();
    let state = BodyState {
        position: Vec3::splat(Real::MAX),
        linear_velocity: Vec3::splat(Real::MAX),
        angular_velocity: Vec3::new(1.0, -0.5, 0.25),
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
fn the_overspun_ball_steps_to_an_invalid_state_and_a_zero_quaternion_is_invalid() {
    // The premise of the tests below: stepped without the check, the state is not valid.
    let (mut state, mass) = overspun_ball();
    Integrator::SymplecticEulerLinear.step(&mut state, &mass, &Wrench::ZERO, 1.0 / 60.0);
    assert!(!state.is_finite() && !state.is_valid());
    // A finite state whose rotation is no rotation at all is invalid too (the linearized update
    // used to produce one by overflowing `|q|²` in f32; its products are now formed in f64).
    let zero = BodyState {
        rotation: Quat::from_xyzw(0.0, 0.0, 0.0, 0.0),
        ..BodyState::default()
    };
    assert!(zero.is_finite() && !zero.is_valid());
}

#[test]
fn an_invalid_state_after_a_step_is_a_divergence_on_the_scalar_path() {
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
        integrator.try_finish_stage(&mut state, &mass, &Wrench::ZERO, dt),
        Err(StepError::Diverged { integrator })
    );
    assert_eq!(state, before);
}

#[test]
fn an_invalid_state_after_a_step_is_a_divergence_on_the_batched_path() {
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
    let diverged = integrator.try_finish_stage_many(&mut states, &masses, &wrenches, dt);
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
        state.rotation *= scale;
        cases.push(state);
    }
    let mut non_finite = calm_body(2);
    non_finite.linear_velocity.y = Real::NAN;
    cases.push(non_finite);
    for state in cases {
        assert_eq!(state.is_valid(), state.validate().is_ok(), "{state:?}");
    }
}

/// Plain vectors as a [`BodyBatch`], recording diverged bodies.
struct Bodies {
    states: Vec<BodyState>,
    masses: Vec<MassProperties>,
    wrenches: Vec<Wrench>,
    /// How fast each body's springs turn it (rad/s; see [`BodyBatch::spring_turn_rate`]).
    turns: Vec<Real>,
    diverged: Vec<usize>,
}

impl BodyBatch for Bodies {
    fn len(&self) -> usize {
        self.states.len()
    }
    fn take(&mut self, i: usize, state: &mut BodyState) -> Option<Wrench> {
        state.copy_fields_from(&self.states[i]);
        Some(self.wrenches[i])
    }
    fn mass(&self, i: usize) -> &MassProperties {
        &self.masses[i]
    }
    fn spring_turn_rate(&self, i: usize) -> Real {
        self.turns[i]
    }
    fn write(&mut self, i: usize, state: &BodyState) {
        self.states[i] = *state;
    }
    fn diverged(&mut self, i: usize) {
        self.diverged.push(i);
    }
}

/// 37 bodies (four full batches of eight and a partial one): every odd axis, spherical bodies,
/// a locked axis, rotated principal frames, slow and fast spins, some torques.
fn population() -> Bodies {
    let n = 37;
    let mut bodies = Bodies {
        states: Vec::new(),
        masses: Vec::new(),
        wrenches: Vec::new(),
        turns: Vec::new(),
        diverged: Vec::new(),
    };
    for i in 0..n {
        let f = i as Real / n as Real;
        let inertia = match i % 6 {
            0 => Vec3::new(1.0, 2.0 + f, 3.0),
            1 => Vec3::new(2.0, 1.0, 2.05),
            2 => Vec3::new(3.0, 3.1, 0.2),
            3 => Vec3::splat(0.4),
            4 => Vec3::new(0.0, 1.0, 1.5),
            _ => Vec3::new(1e-4, 1.0, 1.0001),
        };
        let mass = MassProperties::new(Mass::new(0.5 + f).unwrap(), inertia)
            .unwrap()
            .with_principal_frame(Quat::from_rotation_z(f))
            .unwrap();
        bodies.masses.push(mass);
        bodies.turns.push(0.0);
        bodies.states.push(BodyState {
            position: Vec3::new(f, -f, 2.0 * f),
            rotation: Quat::from_rotation_y(7.0 * f) * Quat::from_rotation_x(f),
            linear_velocity: Vec3::new(1.0, f, 0.0),
            angular_velocity: Vec3::new(0.3 + 40.0 * f * f, 1.0 - f, 0.3) * (1 + i % 3) as Real,
        });
        bodies.wrenches.push(Wrench {
            force: Vec3::new(0.0, -9.81, 0.0),
            torque: if i % 7 == 3 { Vec3::Y } else { Vec3::ZERO },
        });
    }
    bodies
}

/// The bits of every state, in order.
fn bits(states: &[BodyState]) -> Vec<u64> {
    states
        .iter()
        .flat_map(|s| {
            [s.position, s.linear_velocity, s.angular_velocity]
                .into_iter()
                .flat_map(|v| v.to_array())
                .chain(s.rotation.to_array())
                .map(|x| x.widen().to_bits())
        })
        .collect()
}

use crate::simd::Kernel;

/// The population after `rounds` rounds of a whole step and a stage in two phases, one body at
/// a time on the scalar path: the reference the batches must match bit for bit. A body whose
/// step diverges keeps its state, as in a batch.
fn scalar_rounds(integrator: Integrator, dt: Real, rounds: usize) -> Bodies {
    let mut scalar = population();
    for _ in 0..rounds {
        for (i, state) in scalar.states.iter_mut().enumerate() {
            let (mass, wrench) = (&scalar.masses[i], &scalar.wrenches[i]);
            let whole = integrator.try_step(state, mass, wrench, dt);
            let begin = integrator.try_begin_stage(state, mass, dt);
            let finish = integrator.try_finish_stage(state, mass, wrench, dt);
            if whole.is_err() || begin.is_err() || finish.is_err() {
                scalar.diverged.push(i);
            }
        }
    }
    scalar
}

/// Every integrator, batched on every kernel path the CPU has (whole steps, and stages in two
/// phases), gives each body the bits of its scalar step: the population mixes every relabelling,
/// a spherical body, a locked axis, a thin rod, fast spins and torques, in batches that leave
/// partial runs of lanes.
#[test]
fn every_kernel_path_the_cpu_has_gives_the_same_bits_as_the_scalar_step() {
    let dt = 1.0 / 60.0;
    let kernels = Kernel::available();
    assert!(!kernels.is_empty());
    for &integrator in Integrator::ALL {
        let scalar = scalar_rounds(integrator, dt, 20);
        for &kernel in &kernels {
            let mut batch = population();
            kernel.forced(|| {
                for _ in 0..20 {
                    integrator.step_batch(&mut batch, dt);
                    integrator.stage_batch(StepPhase::Begin, &mut batch, dt);
                    integrator.stage_batch(StepPhase::Finish, &mut batch, dt);
                }
            });
            let mut diverged = batch.diverged.clone();
            diverged.sort_unstable();
            diverged.dedup();
            let mut expected = scalar.diverged.clone();
            expected.sort_unstable();
            expected.dedup();
            assert_eq!(diverged, expected, "{integrator} on {}", kernel.path());
            let differ: Vec<usize> = (0..batch.states.len())
                .filter(|&i| bits(&batch.states[i..=i]) != bits(&scalar.states[i..=i]))
                .collect();
            assert!(
                differ.is_empty(),
                "{integrator} on {}: bodies {differ:?} differ",
                kernel.path()
            );
        }
    }
}

#[test]
fn exact_batches_give_the_same_bits_as_the_scalar_step() {
    // The batch rotates two bodies at a time (an odd count leaves one alone); spherical bodies,
    // a locked axis and torques take the single-body step.
    let dt = 1.0 / 60.0;
    for integrator in [Integrator::Exact, Integrator::Exact4] {
        let scalar = scalar_rounds(integrator, dt, 20);
        let mut batch = population();
        for _ in 0..20 {
            integrator.step_batch(&mut batch, dt);
            integrator.stage_batch(StepPhase::Begin, &mut batch, dt);
            integrator.stage_batch(StepPhase::Finish, &mut batch, dt);
        }
        assert!(batch.diverged.is_empty());
        assert_eq!(bits(&batch.states), bits(&scalar.states), "{integrator}");
    }
}

/// Under the free-flow switch every body steps as its own choice would step it alone (the exact
/// counterpart where the switch applies, the method elsewhere), on every kernel path, in every
/// phase and in a composed step: the choice is one per body and stage, and the batch does not
/// change its bits. The population spins from slow to fast (rods among them), so both choices
/// occur.
#[test]
fn the_free_flow_switch_steps_each_body_as_its_choice_on_every_kernel_path() {
    // Without springs, and with every other body turned by springs at 200 rad/s (which leaves
    // some of them on the split flow: the batch asks each body's rate).
    for turn in [0.0, 200.0] {
        switch_steps_each_body_as_its_choice(turn);
    }
}

fn with_turns(mut bodies: Bodies, turn: Real) -> Bodies {
    for (i, t) in bodies.turns.iter_mut().enumerate() {
        if i % 2 == 0 {
            *t = turn;
        }
    }
    bodies
}

fn switch_steps_each_body_as_its_choice(turn: Real) {
    let dt = 1.0 / 60.0;
    for integrator in [
        Integrator::Splitting,
        Integrator::SplittingXyz,
        Integrator::Yoshida4,
    ] {
        let switch = ExactSwitch::new(integrator, FreeFlow::Auto, dt).unwrap();
        let mut scalar = with_turns(population(), turn);
        let (mut exact, mut split, mut kept) = (0, 0, 0);
        for _ in 0..20 {
            for (i, state) in scalar.states.iter_mut().enumerate() {
                let (mass, wrench) = (&scalar.masses[i], &scalar.wrenches[i]);
                let rate = scalar.turns[i];
                let stage = |s: &BodyState| {
                    if switch.applies_turned(s, mass, rate) {
                        switch.exact()
                    } else {
                        integrator
                    }
                };
                let chosen = stage(state);
                if switch.applies(state, mass) && chosen == integrator {
                    kept += 1;
                }
                if chosen == integrator {
                    split += 1;
                } else {
                    exact += 1;
                }
                chosen.try_step(state, mass, wrench, dt).unwrap();
                if let [c] = integrator.composition() {
                    let h = c * dt;
                    stage(state).try_begin_stage(state, mass, h).unwrap();
                    stage(state)
                        .try_finish_stage(state, mass, wrench, h)
                        .unwrap();
                }
            }
        }
        assert!(
            exact > 0 && split > 0 && (turn == 0.0) == (kept == 0),
            "{integrator}: {exact} exact, {split} split, {kept} kept on the split by springs"
        );
        for kernel in Kernel::available() {
            let mut batch = with_turns(population(), turn);
            kernel.forced(|| {
                for _ in 0..20 {
                    integrator.step_batch_switched(&mut batch, dt, Some(switch));
                    if let [c] = integrator.composition() {
                        for phase in [StepPhase::Begin, StepPhase::Finish] {
                            let h = c * dt;
                            integrator.stage_batch_switched(phase, &mut batch, h, Some(switch));
                        }
                    }
                }
            });
            assert!(batch.diverged.is_empty());
            assert_eq!(
                bits(&batch.states),
                bits(&scalar.states),
                "{integrator} on {}",
                kernel.path()
            );
        }
    }
}

/// The switch gives way only where the split is judged to cost more than the limit, and
/// `FreeFlow::Method` or a method that is not split never switches.
#[test]
fn the_free_flow_switch_is_none_where_nothing_would_switch() {
    for integrator in Integrator::ALL.iter().copied() {
        assert!(ExactSwitch::new(integrator, FreeFlow::Method, 0.01).is_none());
        assert_eq!(
            ExactSwitch::new(integrator, FreeFlow::Auto, 0.01).is_some(),
            integrator.exact_counterpart().is_some()
        );
        if let Some(exact) = integrator.exact_counterpart() {
            // The counterpart shares the step's structure: its stages and where it samples.
            assert_eq!(exact.composition(), integrator.composition());
            assert_eq!(
                exact.samples_forces_at_midpoint(),
                integrator.samples_forces_at_midpoint()
            );
            assert!(exact.is_exact_torque_free());
        }
    }
}

/// A body under springs keeps the split flow where the springs' error per step,
/// `(ω_turn h)³/24`, outweighs the split's, `e_orbit |ω| h`: the switch leaves it exactly above
/// the rate where they are equal, and takes it below, for every body the switch applies to.
#[test]
fn springs_that_outweigh_the_split_keep_the_split_flow() {
    let dt: Real = 1.0 / 60.0;
    let bodies = population();
    let mut checked = 0;
    for integrator in [Integrator::Splitting, Integrator::Yoshida4] {
        let switch = ExactSwitch::new(integrator, FreeFlow::Auto, dt).unwrap();
        let largest = integrator
            .composition()
            .iter()
            .fold(0.0, |m: Real, c| m.max(c.abs()))
            .widen()
            * dt.widen();
        for (state, mass) in bodies.states.iter().zip(&bodies.masses) {
            if !switch.applies(state, mass) {
                assert!(!switch.applies_turned(state, mass, 1e3));
                continue;
            }
            assert!(switch.applies_turned(state, mass, 0.0));
            let principal = (state.rotation * mass.principal_frame()).widen();
            let omega = principal.conjugate() * state.angular_velocity.widen();
            let split = split_orbit_error(mass.principal_inertia().widen(), omega, largest)
                * omega.length();
            let even = (24.0 * split / (largest * largest)).cbrt();
            assert!(switch.applies_turned(state, mass, (0.99 * even) as Real));
            assert!(!switch.applies_turned(state, mass, (1.01 * even) as Real));
            checked += 1;
        }
    }
    assert!(checked > 0);
}
