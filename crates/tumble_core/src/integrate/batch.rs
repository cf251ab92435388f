//! Stepping many bodies at once: the entry points the ECS systems and the raw benchmark loop
//! share.
//!
//! A batch reads each body from a [`BodyBatch`] (plain arrays, or an ECS table without an
//! intermediate copy), steps it and writes it back. For the drift–kick–drift methods
//! `splitting` (the default), `splitting-xyz` and `rk4` the free rotations of up to eight
//! non-spherical bodies are computed together in SIMD lanes by the kernel of `symmetric_kernel`,
//! on the [`kernel_path`](super::kernel_path), and so are the three stages' flows of a torque-free
//! `yoshida4` step; the translation, the kicks and spherical bodies stay scalar. The four
//! kick–drift methods rotate eight bodies at a time on their own kernel (`kick_drift_kernel`),
//! spherical ones included. `exact` and `exact4` rotate two bodies at a time, in scalar code run
//! stage by stage so that their long dependency chains overlap. Either way each body's result is
//! bit-identical to [`Integrator::try_step`] and the stage functions on that body alone,
//! whatever the batch, its order, the kernel path or the thread that runs it.

use crate::math::Real;
use std::borrow::Borrow;

use super::body_batch::{BodyBatch, PREFETCH_AHEAD, Slices, commit};
use super::exact_flow::exact_flow_batch;
use super::kick_drift::kick_drift_batch;
use super::kick_drift_kernel::KickDrift;
use super::splitting::{composed_step_batch, drift_kick_drift_batch};
use super::stages::StepPhase;
use super::{ExactSwitch, Integrator};
use crate::mass::MassProperties;
use crate::state::{BodyState, Wrench};

/// The methods without a batched kernel: every body steps alone with `single`.
fn each_alone(
    bodies: &mut impl BodyBatch,
    mut single: impl FnMut(&mut BodyState, &MassProperties, &Wrench, Real),
) {
    let mut next = BodyState::ZEROED;
    for i in 0..bodies.len() {
        bodies.prefetch(i + PREFETCH_AHEAD);
        let Some(wrench) = bodies.take(i, &mut next) else {
            continue;
        };
        single(
            &mut next,
            bodies.mass(i),
            &wrench,
            bodies.spring_turn_rate(i),
        );
        commit(bodies, i, &next);
    }
}

impl Integrator {
    /// Steps every body of `bodies` through `phase` of one stage of span `h` (each body's load
    /// held constant), reading and writing through the [`BodyBatch`]. For a method of one stage
    /// per step (every method but `yoshida4`, see [`Integrator::composition`]) a
    /// [`Whole`](StepPhase::Whole) stage of `Δt` is the whole step. A body whose result is not
    /// valid ([`BodyState::is_valid`]) keeps its state and is reported to
    /// [`BodyBatch::diverged`]; no other body is affected. Does not allocate.
    ///
    /// Every method but `exact` and `exact4` rotates its bodies in SIMD lanes on the
    /// [`kernel_path`](super::kernel_path) (every path gives the same bits).
    ///
    /// # Panics
    ///
    /// For those methods, when the environment variable
    /// [`KERNEL_ENV`](super::KERNEL_ENV) names a kernel path this CPU cannot run (see
    /// [`KernelPath::selected`](super::KernelPath::selected)).
    pub fn stage_batch(self, phase: StepPhase, bodies: &mut impl BodyBatch, h: Real) {
        self.stage_batch_switched(phase, bodies, h, None);
    }

    /// [`stage_batch`](Self::stage_batch) with the bodies `switch` applies to stepped by its
    /// exact counterpart ([`FreeFlow::Auto`](super::FreeFlow::Auto), judged body by body on the
    /// state each stage starts from). The method's batch loop runs here, its rotations on the
    /// [`kernel_path`](super::kernel_path).
    pub fn stage_batch_switched(
        self,
        phase: StepPhase,
        bodies: &mut impl BodyBatch,
        h: Real,
        switch: Option<ExactSwitch>,
    ) {
        let kernel = self.lane_kernel();
        let alone = |s: &mut BodyState, m: &MassProperties, w: &Wrench, turn: Real| match switch {
            Some(switch) if switch.applies_turned(s, m, turn) => {
                switch.exact().stage(phase, s, m, w, h)
            }
            _ => self.stage(phase, s, m, w, h),
        };
        if self.is_exact_torque_free() {
            return match phase {
                StepPhase::Whole => exact_flow_batch(StepPhase::Whole, bodies, h, alone),
                StepPhase::Begin => exact_flow_batch(StepPhase::Begin, bodies, h, alone),
                StepPhase::Finish => exact_flow_batch(StepPhase::Finish, bodies, h, alone),
            };
        }
        if let Some(method) = KickDrift::of(self) {
            // The kick–drift methods do nothing before the forces (see `begin_stage`).
            return match phase {
                StepPhase::Begin => each_alone(bodies, alone),
                _ => kick_drift_batch(kernel, method, phase, bodies, h, switch),
            };
        }
        let Some(flow) = self.lane_flow() else {
            return each_alone(bodies, alone);
        };
        // One loop per phase, each with its phase a constant, as if written out three times.
        let (k, b, s) = (kernel, bodies, switch);
        match phase {
            StepPhase::Whole => drift_kick_drift_batch(k, flow, StepPhase::Whole, b, h, s, alone),
            StepPhase::Begin => drift_kick_drift_batch(k, flow, StepPhase::Begin, b, h, s, alone),
            StepPhase::Finish => drift_kick_drift_batch(k, flow, StepPhase::Finish, b, h, s, alone),
        }
    }

    /// One whole step of `dt` for every body of `bodies` under its constant load
    /// ([`step`](Self::step) for each: the stages of the [`composition`](Self::composition));
    /// for a method of one stage, [`stage_batch`](Self::stage_batch) of the
    /// [`Whole`](StepPhase::Whole) stage. The same contract as `stage_batch`; a composed step is
    /// checked once, at its end.
    pub fn step_batch(self, bodies: &mut impl BodyBatch, dt: Real) {
        self.step_batch_switched(bodies, dt, None);
    }

    /// [`step_batch`](Self::step_batch) with the bodies `switch` applies to stepped by its exact
    /// counterpart (see [`stage_batch_switched`](Self::stage_batch_switched)).
    pub fn step_batch_switched(
        self,
        bodies: &mut impl BodyBatch,
        dt: Real,
        switch: Option<ExactSwitch>,
    ) {
        if let [c] = self.composition() {
            return self.stage_batch_switched(StepPhase::Whole, bodies, c * dt, switch);
        }
        let alone = |s: &mut BodyState, m: &MassProperties, w: &Wrench, turn: Real| match switch {
            Some(switch) if switch.applies_turned(s, m, turn) => switch.exact().step(s, m, w, dt),
            _ => self.step(s, m, w, dt),
        };
        if self == Integrator::Exact4 {
            // Without torque its composed step is the translation of a whole stage over `dt`
            // and one exact rotation over `dt` (see `Integrator::step`): a whole stage's work.
            return exact_flow_batch(StepPhase::Whole, bodies, dt, alone);
        }
        if self.rotates_on_symmetric_kernel() {
            let own = |s: &mut BodyState, m: &MassProperties, w: &Wrench| self.step(s, m, w, dt);
            let (kernel, weights) = (self.lane_kernel(), self.composition());
            return composed_step_batch(kernel, weights, bodies, dt, switch, own);
        }
        each_alone(bodies, alone);
    }

    /// Runs [`stage_batch`](Self::stage_batch) over plain arrays; returns the diverged indices
    /// in increasing order.
    fn stage_slices<M: Borrow<MassProperties>>(
        self,
        phase: StepPhase,
        states: &mut [BodyState],
        masses: &[M],
        wrenches: Option<&[Wrench]>,
        h: Real,
    ) -> Vec<usize> {
        let mut slices = Slices::new(states, masses, wrenches);
        self.stage_batch(phase, &mut slices, h);
        slices.sorted_diverged()
    }

    /// [`try_step`](Self::try_step) for every body: `states[i]` advances by `dt` under
    /// `wrenches[i]` with mass `masses[i]`. A body whose result is not valid keeps its state and
    /// its index is returned (in increasing order); no other body is affected. Allocates only
    /// when a body diverges.
    pub fn try_step_many<M: Borrow<MassProperties>>(
        self,
        states: &mut [BodyState],
        masses: &[M],
        wrenches: &[Wrench],
        dt: Real,
    ) -> Vec<usize> {
        self.try_step_many_switched(states, masses, wrenches, dt, None)
    }

    /// [`try_step_many`](Self::try_step_many) with the bodies `switch` applies to stepped by its
    /// exact counterpart (see [`stage_batch_switched`](Self::stage_batch_switched)).
    pub fn try_step_many_switched<M: Borrow<MassProperties>>(
        self,
        states: &mut [BodyState],
        masses: &[M],
        wrenches: &[Wrench],
        dt: Real,
        switch: Option<ExactSwitch>,
    ) -> Vec<usize> {
        let mut slices = Slices::new(states, masses, Some(wrenches));
        self.step_batch_switched(&mut slices, dt, switch);
        slices.sorted_diverged()
    }

    /// [`try_begin_stage`](Self::try_begin_stage) for every body (see
    /// [`try_step_many`](Self::try_step_many) for the contract).
    pub fn try_begin_stage_many<M: Borrow<MassProperties>>(
        self,
        states: &mut [BodyState],
        masses: &[M],
        h: Real,
    ) -> Vec<usize> {
        self.stage_slices(StepPhase::Begin, states, masses, None, h)
    }

    /// [`try_finish_stage`](Self::try_finish_stage) for every body (see
    /// [`try_step_many`](Self::try_step_many) for the contract).
    pub fn try_finish_stage_many<M: Borrow<MassProperties>>(
        self,
        states: &mut [BodyState],
        masses: &[M],
        wrenches: &[Wrench],
        h: Real,
    ) -> Vec<usize> {
        self.stage_slices(StepPhase::Finish, states, masses, Some(wrenches), h)
    }
}
