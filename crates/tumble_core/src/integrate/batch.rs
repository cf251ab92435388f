//! Stepping many bodies at once: the entry points the ECS systems and the raw benchmark loop
//! share.
//!
//! For `splitting` (the default) the free rotations of up to [`LANES`] non-spherical bodies are
//! computed together in SIMD lanes by the kernel of [`super::symmetric_kernel`]; the translation,
//! the kicks and spherical bodies stay scalar. Every other method steps body by body. Either way
//! each body's result is bit-identical to [`Integrator::try_step`] and friends on that body
//! alone, whatever the batch, its order or the thread that runs it.

use crate::math::{Quat, Real, Vec3};
use std::borrow::Borrow;

use super::lanes::LANES;
use super::splitting::{kick, translate_dkd};
use super::symmetric_kernel::{SymmetricInput, rotate_symmetric_lanes, rotate_symmetric_one};
use super::{Integrator, StepError};
use crate::mass::MassProperties;
use crate::rotation::rotate_exact;
use crate::state::{BodyState, Wrench};

/// Bodies waiting for their free rotation, flushed [`LANES`] at a time: each body's translated
/// state and its kernel inputs. (Inputs stored as structure of arrays were slower: four scalar
/// stores then one vector load of the same bytes stalls store forwarding.)
struct PendingRotations {
    index: [usize; LANES],
    state: [BodyState; LANES],
    input: [SymmetricInput; LANES],
    h: [Real; LANES],
    len: usize,
}

impl PendingRotations {
    fn new() -> Self {
        Self {
            index: [0; LANES],
            state: [BodyState::default(); LANES],
            input: [SymmetricInput::default(); LANES],
            h: [0.0; LANES],
            len: 0,
        }
    }

    /// Queues body `index` (already translated, as `state`) for a free rotation over `h`;
    /// spherical bodies rotate at once, exactly about `ω`.
    #[inline(always)]
    fn push(
        &mut self,
        index: usize,
        mut state: BodyState,
        mass: &MassProperties,
        h: Real,
        done: &mut impl FnMut(usize, &BodyState),
    ) {
        if mass.is_spherical() {
            state.rotation = rotate_exact(state.rotation, state.angular_velocity, h);
            done(index, &state);
            return;
        }
        let lane = self.len;
        self.input[lane] = SymmetricInput::new(state.rotation, state.angular_velocity, mass);
        self.index[lane] = index;
        self.state[lane] = state;
        self.h[lane] = h;
        self.len = lane + 1;
        if self.len == LANES {
            self.flush(done);
        }
    }

    /// Rotates the queued bodies (a partial batch goes through the scalar kernel, which gives
    /// the same bits) and hands each result to `done`.
    #[inline(always)]
    fn flush(&mut self, done: &mut impl FnMut(usize, &BodyState)) {
        if self.len == LANES {
            let rotated = rotate_symmetric_lanes(&self.input, self.h);
            for (lane, (rotation, omega)) in rotated.into_iter().enumerate() {
                self.finish(lane, rotation, omega, done);
            }
        } else {
            for lane in 0..self.len {
                let (rotation, omega) = rotate_symmetric_one(&self.input[lane], self.h[lane]);
                self.finish(lane, rotation, omega, done);
            }
        }
        self.len = 0;
    }

    /// Hands lane `lane`'s rotated body to `done`.
    #[inline(always)]
    fn finish(
        &self,
        lane: usize,
        rotation: Quat,
        omega: Vec3,
        done: &mut impl FnMut(usize, &BodyState),
    ) {
        let mut state = self.state[lane];
        state.rotation = rotation;
        state.angular_velocity = omega;
        done(self.index[lane], &state);
    }
}

/// Commits `next` into `states[index]` if it is finite, else records the divergence.
#[inline]
fn commit(states: &mut [BodyState], diverged: &mut Vec<usize>, index: usize, next: &BodyState) {
    if next.is_finite() {
        states[index] = *next;
    } else {
        diverged.push(index);
    }
}

/// Steps every body alone with `single` (the methods without a batched kernel); returns the
/// indices of the bodies that diverged.
fn each_alone<M: Borrow<MassProperties>>(
    states: &mut [BodyState],
    masses: &[M],
    mut single: impl FnMut(usize, &mut BodyState, &MassProperties) -> Result<(), StepError>,
) -> Vec<usize> {
    let mut diverged = Vec::new();
    for (i, state) in states.iter_mut().enumerate() {
        if single(i, state, masses[i].borrow()).is_err() {
            diverged.push(i);
        }
    }
    diverged
}

/// The `splitting` batch: `translate(i, next, mass)` does a body's scalar part on a copy and
/// returns the time over which it then rotates freely (queued for the SIMD kernel), or `None` if
/// the body needs the whole scalar step `alone` instead. Returns the diverged indices, sorted.
fn batched<M: Borrow<MassProperties>>(
    states: &mut [BodyState],
    masses: &[M],
    mut translate: impl FnMut(usize, &mut BodyState, &MassProperties) -> Option<Real>,
    mut alone: impl FnMut(usize, &mut BodyState, &MassProperties) -> Result<(), StepError>,
) -> Vec<usize> {
    let mut diverged = Vec::new();
    let mut pending = PendingRotations::new();
    for i in 0..states.len() {
        let mass = masses[i].borrow();
        let mut next = states[i];
        match translate(i, &mut next, mass) {
            Some(h) => pending.push(i, next, mass, h, &mut |j, s| {
                commit(states, &mut diverged, j, s)
            }),
            None => {
                if alone(i, &mut states[i], mass).is_err() {
                    diverged.push(i);
                }
            }
        }
    }
    pending.flush(&mut |j, s| commit(states, &mut diverged, j, s));
    diverged.sort_unstable();
    diverged
}

impl Integrator {
    /// [`try_step`](Self::try_step) for every body: `states[i]` advances by `dt` under
    /// `wrenches[i]` with mass `masses[i]`. A body whose result is not finite keeps its state and
    /// its index is returned (in increasing order); no other body is affected. Allocates only
    /// when a body diverges.
    pub fn try_step_many<M: Borrow<MassProperties>>(
        self,
        states: &mut [BodyState],
        masses: &[M],
        wrenches: &[Wrench],
        dt: Real,
    ) -> Vec<usize> {
        assert!(states.len() == masses.len() && states.len() == wrenches.len());
        let alone =
            |i: usize, s: &mut BodyState, m: &MassProperties| self.try_step(s, m, &wrenches[i], dt);
        if self != Integrator::Splitting {
            return each_alone(states, masses, alone);
        }
        let translate = |i: usize, next: &mut BodyState, m: &MassProperties| {
            let wrench = &wrenches[i];
            // A torque must be kicked between two half rotations: that body steps alone.
            (wrench.torque == Vec3::ZERO).then(|| {
                translate_dkd(next, m, wrench, dt);
                dt
            })
        };
        batched(states, masses, translate, alone)
    }

    /// [`try_begin_step`](Self::try_begin_step) for every body (see
    /// [`try_step_many`](Self::try_step_many) for the contract).
    pub fn try_begin_step_many<M: Borrow<MassProperties>>(
        self,
        states: &mut [BodyState],
        masses: &[M],
        dt: Real,
    ) -> Vec<usize> {
        assert!(states.len() == masses.len());
        let alone = |_: usize, s: &mut BodyState, m: &MassProperties| self.try_begin_step(s, m, dt);
        if self != Integrator::Splitting {
            return each_alone(states, masses, alone);
        }
        let h = 0.5 * dt;
        let translate = |_: usize, next: &mut BodyState, _: &MassProperties| {
            next.position += h * next.linear_velocity;
            Some(h)
        };
        batched(states, masses, translate, alone)
    }

    /// [`try_finish_step`](Self::try_finish_step) for every body (see
    /// [`try_step_many`](Self::try_step_many) for the contract).
    pub fn try_finish_step_many<M: Borrow<MassProperties>>(
        self,
        states: &mut [BodyState],
        masses: &[M],
        wrenches: &[Wrench],
        dt: Real,
    ) -> Vec<usize> {
        assert!(states.len() == masses.len() && states.len() == wrenches.len());
        let alone = |i: usize, s: &mut BodyState, m: &MassProperties| {
            self.try_finish_step(s, m, &wrenches[i], dt)
        };
        if self != Integrator::Splitting {
            return each_alone(states, masses, alone);
        }
        let h = 0.5 * dt;
        let translate = |i: usize, next: &mut BodyState, m: &MassProperties| {
            kick(next, m, &wrenches[i], dt);
            next.position += h * next.linear_velocity;
            Some(h)
        };
        batched(states, masses, translate, alone)
    }
}
