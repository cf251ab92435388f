//! The interface between a batch loop and the bodies it steps: [`BodyBatch`], and plain arrays
//! as one.

use std::borrow::Borrow;

use crate::mass::MassProperties;
use crate::math::Real;
use crate::prefetch::prefetch;
use crate::state::{BodyState, Wrench};

/// Where a batched step finds its bodies and puts them back.
///
/// [`Integrator::stage_batch`](super::Integrator::stage_batch) calls [`take`](Self::take) once
/// for every index in `0..len()`, in increasing order, then exactly one of
/// [`write`](Self::write) (the new state is valid: finite, with a unit rotation,
/// [`BodyState::is_valid`]) or [`diverged`](Self::diverged) (it is not: the body keeps its old
/// state) for every body that `take` returned, not necessarily in order.
///
/// Bodies kept in your own layout, here one struct per body with a frozen flag:
///
/// ```
/// use tumble_core::math::Vec3;
/// use tumble_core::{BodyBatch, BodyState, Integrator, Mass, MassProperties, StepPhase, Wrench};
///
/// struct Crate { state: BodyState, mass: MassProperties, frozen: bool }
/// struct Crates(Vec<Crate>);
///
/// impl BodyBatch for Crates {
///     fn len(&self) -> usize { self.0.len() }
///     fn take(&mut self, i: usize, state: &mut BodyState) -> Option<Wrench> {
///         let c = &self.0[i];
///         if c.frozen { return None; }
///         state.copy_fields_from(&c.state);
///         Some(Wrench { force: Vec3::new(0.0, -9.81, 0.0) * c.mass.mass(), torque: Vec3::ZERO })
///     }
///     fn mass(&self, i: usize) -> &MassProperties { &self.0[i].mass }
///     fn write(&mut self, i: usize, state: &BodyState) { self.0[i].state = *state; }
///     fn diverged(&mut self, i: usize) { self.0[i].frozen = true; }
/// }
///
/// let mass = MassProperties::new(Mass::new(2.0).unwrap(), Vec3::new(1.0, 2.0, 3.0)).unwrap();
/// let body = |frozen| Crate { state: BodyState::default(), mass, frozen };
/// let mut crates = Crates(vec![body(false), body(true)]);
/// Integrator::Splitting.stage_batch(StepPhase::Whole, &mut crates, 0.5);
/// // Drift–kick–drift is exact under constant gravity: y = −g t²/2.
/// assert!((crates.0[0].state.position.y + 9.81 * 0.125).abs() < 1e-5);
/// assert_eq!(crates.0[1].state.position.y, 0.0); // frozen: never read, never written
/// ```
pub trait BodyBatch {
    /// Number of bodies.
    fn len(&self) -> usize;
    /// True when there are no bodies.
    fn is_empty(&self) -> bool {
        self.len() == 0
    }
    /// Takes body `i` for its step: writes its state into `state` and hands over its load for
    /// the stage, once — the place a batch over game data consumes the forces it was given
    /// (tumble's ECS table reads and zeroes each body's `ForceAccumulator` here). Returns
    /// `None` when the body must not be stepped (the implementation records why). `state` is a
    /// scratch value whose padding bytes are zero: assign it with
    /// [`BodyState::copy_fields_from`], not as a whole struct (see there why).
    fn take(&mut self, i: usize, state: &mut BodyState) -> Option<Wrench>;
    /// Body `i`'s mass properties.
    fn mass(&self, i: usize) -> &MassProperties;
    /// Stores body `i`'s new, valid state.
    fn write(&mut self, i: usize, state: &BodyState);
    /// Body `i`'s step did not give a valid state (non-finite, or a non-unit rotation); it keeps
    /// its old one.
    fn diverged(&mut self, i: usize);
    /// How fast body `i`'s springs can turn it (rad/s; 0 for a body without springs): where
    /// they turn it fast enough that their own error outweighs the split free rotation's, the
    /// exact switch leaves the body on the method's flow (see
    /// [`ExactSwitch::applies_turned`](super::ExactSwitch::applies_turned)). Default: 0.
    #[inline(always)]
    fn spring_turn_rate(&self, i: usize) -> Real {
        let _ = i;
        0.0
    }
    /// A hint: body `i` (possibly beyond the last) will be taken soon; fetch its memory with
    /// [`prefetch`](crate::prefetch::prefetch). The batch loops call it a few dozen bodies
    /// ahead, far enough for the memory to arrive before the body is read. Default: nothing.
    #[inline(always)]
    fn prefetch(&self, i: usize) {
        let _ = i;
    }
}

/// How many bodies ahead of the one being read the batch loops call [`BodyBatch::prefetch`]:
/// it pays in worlds that outgrow the caches (see `report/bench-avx512.md`); smaller worlds,
/// where the hardware prefetchers keep up, are unchanged.
pub(super) const PREFETCH_AHEAD: usize = 32;

/// Hands `next` to `bodies` as body `i`'s new state if it is valid, else reports divergence.
#[inline(always)]
pub(super) fn commit(bodies: &mut impl BodyBatch, i: usize, next: &BodyState) {
    if next.is_valid() {
        bodies.write(i, next);
    } else {
        bodies.diverged(i);
    }
}

/// Plain arrays as a [`BodyBatch`]; divergent indices are collected in order of discovery.
pub(super) struct Slices<'a, M> {
    states: &'a mut [BodyState],
    masses: &'a [M],
    wrenches: Option<&'a [Wrench]>,
    diverged: Vec<usize>,
}

impl<'a, M> Slices<'a, M> {
    /// The batch of `states[i]` with `masses[i]` (and `wrenches[i]`); panics if the lengths
    /// differ.
    pub(super) fn new(
        states: &'a mut [BodyState],
        masses: &'a [M],
        wrenches: Option<&'a [Wrench]>,
    ) -> Self {
        assert!(states.len() == masses.len());
        assert!(wrenches.is_none_or(|w| w.len() == states.len()));
        Self {
            states,
            masses,
            wrenches,
            diverged: Vec::new(),
        }
    }

    /// The indices of the bodies that diverged, in increasing order.
    pub(super) fn sorted_diverged(self) -> Vec<usize> {
        let mut diverged = self.diverged;
        diverged.sort_unstable();
        diverged
    }
}

impl<M: Borrow<MassProperties>> BodyBatch for Slices<'_, M> {
    fn len(&self) -> usize {
        self.states.len()
    }

    #[inline(always)]
    fn take(&mut self, i: usize, state: &mut BodyState) -> Option<Wrench> {
        state.copy_fields_from(&self.states[i]);
        Some(self.wrenches.map_or(Wrench::ZERO, |w| w[i]))
    }

    #[inline(always)]
    fn mass(&self, i: usize) -> &MassProperties {
        self.masses[i].borrow()
    }

    #[inline(always)]
    fn write(&mut self, i: usize, state: &BodyState) {
        self.states[i] = *state;
    }

    #[inline(always)]
    fn prefetch(&self, i: usize) {
        if i < self.states.len() {
            prefetch(&self.states[i]);
            prefetch(self.masses[i].borrow());
            if let Some(wrenches) = self.wrenches {
                prefetch(&wrenches[i]);
            }
        }
    }

    fn diverged(&mut self, i: usize) {
        self.diverged.push(i);
    }
}
