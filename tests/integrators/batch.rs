//! The batched entry points (`try_*_many`, SIMD lanes for `splitting`) give every body exactly
//! the bits it gets when stepped alone, whatever its neighbours, their order or the batch size.

use tumble::math::{Quat, Real, Vec3};
use tumble::prelude::*;

/// A mixed population: every odd-axis choice, spherical bodies, locked axes, a rotated
/// principal frame, fast and slow spins, forces and torques.
fn population(n: usize) -> (Vec<BodyState>, Vec<MassProperties>, Vec<Wrench>) {
    let mut states = Vec::new();
    let mut masses = Vec::new();
    let mut wrenches = Vec::new();
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
        let mut mass = MassProperties::new(Mass::new(0.5 + f).unwrap(), inertia).unwrap();
        if i % 5 == 0 {
            mass = mass
                .with_principal_frame(Quat::from_rotation_z(0.3 + f))
                .unwrap();
        }
        masses.push(mass);
        states.push(BodyState {
            position: Vec3::new(f, -f, 2.0 * f),
            rotation: Quat::from_rotation_y(7.0 * f) * Quat::from_rotation_x(f),
            linear_velocity: Vec3::new(1.0, f, 0.0),
            angular_velocity: Vec3::new(0.3 + 40.0 * f * f, 1.0 - f, 0.3) * (1 + i % 3) as Real,
        });
        let torque = if i % 4 == 1 {
            Vec3::new(0.0, 0.1, -0.2)
        } else {
            Vec3::ZERO
        };
        wrenches.push(Wrench {
            force: Vec3::new(0.0, -9.81 * (0.5 + f), 0.0),
            torque,
        });
    }
    (states, masses, wrenches)
}

fn same_bits(a: &BodyState, b: &BodyState) -> bool {
    let bits = |s: &BodyState| {
        let mut v = Vec::new();
        v.extend(s.position.to_array().map(Real::to_bits));
        v.extend(s.rotation.to_array().map(Real::to_bits));
        v.extend(s.linear_velocity.to_array().map(Real::to_bits));
        v.extend(s.angular_velocity.to_array().map(Real::to_bits));
        v
    };
    bits(a) == bits(b)
}

#[test]
fn batched_steps_equal_single_steps_bit_for_bit() {
    let dt = 1.0 / 60.0;
    for &integrator in Integrator::ALL {
        let (mut batched, masses, wrenches) = population(61);
        let mut single = batched.clone();
        for _ in 0..50 {
            // Whole steps, then split steps (begin / finish) as the ECS takes them. The
            // explicit methods blow up on the fast thin rods: the same bodies must be reported.
            let diverged_batched = vec![
                integrator.try_step_many(&mut batched, &masses, &wrenches, dt),
                integrator.try_begin_stage_many(&mut batched, &masses, dt),
                integrator.try_finish_stage_many(&mut batched, &masses, &wrenches, dt),
            ];
            let mut diverged_single = vec![Vec::new(), Vec::new(), Vec::new()];
            for (i, state) in single.iter_mut().enumerate() {
                let (mass, wrench) = (&masses[i], &wrenches[i]);
                if integrator.try_step(state, mass, wrench, dt).is_err() {
                    diverged_single[0].push(i);
                }
                if integrator.try_begin_stage(state, mass, dt).is_err() {
                    diverged_single[1].push(i);
                }
                if integrator
                    .try_finish_stage(state, mass, wrench, dt)
                    .is_err()
                {
                    diverged_single[2].push(i);
                }
            }
            assert_eq!(diverged_batched, diverged_single, "{integrator}");
        }
        for (i, (a, b)) in batched.iter().zip(&single).enumerate() {
            assert!(
                same_bits(a, b),
                "{integrator}: body {i} differs: {a:?} vs {b:?}"
            );
        }
    }
}

#[test]
fn batch_results_do_not_depend_on_order_or_batch_size() {
    let dt = 1.0 / 30.0;
    let integrator = Integrator::Splitting;
    let (states, masses, wrenches) = population(37);
    let mut whole = states.clone();
    for _ in 0..20 {
        integrator.try_step_many(&mut whole, &masses, &wrenches, dt);
    }
    // Reversed order, stepped in chunks of 3 (never a full lane set of 4 in the same place).
    let mut reversed: Vec<BodyState> = states.iter().rev().copied().collect();
    let masses_rev: Vec<MassProperties> = masses.iter().rev().copied().collect();
    let wrenches_rev: Vec<Wrench> = wrenches.iter().rev().copied().collect();
    for _ in 0..20 {
        for start in (0..reversed.len()).step_by(3) {
            let end = (start + 3).min(reversed.len());
            integrator.try_step_many(
                &mut reversed[start..end],
                &masses_rev[start..end],
                &wrenches_rev[start..end],
                dt,
            );
        }
    }
    for (a, b) in whole.iter().zip(reversed.iter().rev()) {
        assert!(same_bits(a, b));
    }
}

#[test]
fn a_diverging_body_in_a_batch_is_reported_and_harms_no_neighbour() {
    let dt = 1.0 / 60.0;
    let integrator = Integrator::Splitting;
    let (mut states, masses, mut wrenches) = population(9);
    let reference = {
        let mut s = states.clone();
        integrator.try_step_many(&mut s, &masses, &wrenches, dt);
        s
    };
    // Body 5 gets an overflowing kick: its step is not finite.
    wrenches[5].force = Vec3::splat(Real::MAX);
    states[5].linear_velocity = Vec3::splat(Real::MAX);
    let before = states[5];
    let diverged = integrator.try_step_many(&mut states, &masses, &wrenches, dt);
    assert_eq!(diverged, vec![5]);
    assert!(
        same_bits(&states[5], &before),
        "diverged body must keep its state"
    );
    for i in (0..9).filter(|&i| i != 5) {
        assert!(
            same_bits(&states[i], &reference[i]),
            "body {i} was disturbed"
        );
    }
}

/// A [`BodyBatch`] over arrays that skips every third body and records every call.
struct Recording {
    states: Vec<BodyState>,
    masses: Vec<MassProperties>,
    wrenches: Vec<Wrench>,
    reads: Vec<usize>,
    written: Vec<usize>,
    diverged: Vec<usize>,
}

impl BodyBatch for Recording {
    fn len(&self) -> usize {
        self.states.len()
    }

    fn take(&mut self, i: usize, state: &mut BodyState) -> Option<Wrench> {
        self.reads.push(i);
        if i % 3 == 2 {
            return None;
        }
        state.copy_fields_from(&self.states[i]);
        Some(self.wrenches[i])
    }

    fn mass(&self, i: usize) -> &MassProperties {
        &self.masses[i]
    }

    fn write(&mut self, i: usize, state: &BodyState) {
        self.written.push(i);
        self.states[i] = *state;
    }

    fn diverged(&mut self, i: usize) {
        self.diverged.push(i);
    }
}

#[test]
fn stage_batch_keeps_the_body_batch_contract() {
    let dt = 1.0 / 60.0;
    for &integrator in Integrator::ALL {
        for phase in [StepPhase::Whole, StepPhase::Begin, StepPhase::Finish] {
            let (states, masses, mut wrenches) = population(23);
            // Body 4 diverges (an overflowing kick in every phase that kicks).
            wrenches[4].force = Vec3::splat(Real::MAX);
            let mut batch = Recording {
                states: states.clone(),
                masses: masses.clone(),
                wrenches: wrenches.clone(),
                reads: Vec::new(),
                written: Vec::new(),
                diverged: Vec::new(),
            };
            let mut start = states.clone();
            start[4].linear_velocity = Vec3::splat(Real::MAX);
            batch.states[4] = start[4];
            integrator.stage_batch(phase, &mut batch, dt);
            let label = format!("{integrator} {phase:?}");
            assert_eq!(batch.reads, (0..23).collect::<Vec<_>>(), "{label}");
            let mut touched: Vec<usize> = batch
                .written
                .iter()
                .chain(&batch.diverged)
                .copied()
                .collect();
            touched.sort_unstable();
            let stepped: Vec<usize> = (0..23).filter(|i| i % 3 != 2).collect();
            assert_eq!(
                touched, stepped,
                "{label}: one write or divergence per body read"
            );
            for i in 0..23 {
                let mut alone = start[i];
                let result = match phase {
                    StepPhase::Whole => {
                        // One whole stage (the whole step unless the method is a composition).
                        let mut next = alone;
                        integrator.whole_stage(&mut next, &masses[i], &wrenches[i], dt);
                        if next.is_valid() {
                            alone = next;
                            Ok(())
                        } else {
                            Err(tumble::core::StepError::Diverged { integrator })
                        }
                    }
                    StepPhase::Begin => integrator.try_begin_stage(&mut alone, &masses[i], dt),
                    StepPhase::Finish => {
                        integrator.try_finish_stage(&mut alone, &masses[i], &wrenches[i], dt)
                    }
                };
                if i % 3 == 2 {
                    assert!(
                        same_bits(&batch.states[i], &start[i]),
                        "{label}: skipped body {i} moved"
                    );
                    continue;
                }
                assert_eq!(
                    batch.diverged.contains(&i),
                    result.is_err(),
                    "{label}: body {i}"
                );
                assert!(
                    same_bits(&batch.states[i], &alone),
                    "{label}: body {i} differs"
                );
            }
            if phase != StepPhase::Begin {
                assert!(batch.diverged.contains(&4), "{label}: body 4 must diverge");
            }
        }
    }
}
