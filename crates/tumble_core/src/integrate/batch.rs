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

use crate::math::{Real, Vec3};
use std::borrow::Borrow;

use super::body_batch::{BodyBatch, PREFETCH_AHEAD, Slices, commit};
use super::exact_flow::{rotate_exactly, rotate_exactly_pair};
use super::kick_drift_kernel::{KickDrift, kick_drift_translation};
use super::lane_input::LaneInputs;
use super::pending::{KickDriftQueue, PendingRotations, QueuedLanes, SymmetricQueue};
use super::splitting::{
    drift_kick_drift_linear, drift_kick_drift_translation, free_rotation_span, kick_angular,
};
use super::stages::StepPhase;
use super::symmetric_kernel::LaneFlow;
use super::{ExactSwitch, Integrator};
use crate::mass::MassProperties;
use crate::rotation::rotate_exact;
use crate::simd::Kernel;
use crate::state::{BodyState, Wrench};

/// The methods without a batched kernel: every body steps alone with `single`.
fn each_alone(
    bodies: &mut impl BodyBatch,
    mut single: impl FnMut(&mut BodyState, &MassProperties, &Wrench, Real),
) {
    let mut next = BodyState::ZEROED;
    for i in 0..bodies.len() {
        bodies.prefetch(i + PREFETCH_AHEAD);
        let Some(wrench) = bodies.read(i, &mut next) else {
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

/// The `splitting` batch: each body's drift–kick–drift translation and linear kick, then its
/// free rotation (which takes the angular kick, in `Finish`), queued for the SIMD kernel
/// ([`PendingRotations`]), or stepped whole by `alone` when its translation cannot run first
/// (a whole step under a torque).
#[inline(always)]
fn batched(
    kernel: Kernel,
    flow: LaneFlow,
    phase: StepPhase,
    bodies: &mut impl BodyBatch,
    dt: Real,
    switch: Option<ExactSwitch>,
    mut alone: impl FnMut(&mut BodyState, &MassProperties, &Wrench, Real),
) {
    let h = free_rotation_span(phase, dt);
    let flow = flow.with_kick(phase == StepPhase::Finish);
    let inputs = LaneInputs::default();
    let mut pending = PendingRotations::new(h, kernel, SymmetricQueue { inputs, flow });
    let mut next = BodyState::ZEROED;
    for i in 0..bodies.len() {
        bodies.prefetch(i + PREFETCH_AHEAD);
        let Some(wrench) = bodies.read(i, &mut next) else {
            continue;
        };
        let mass = bodies.mass(i);
        if let Some(switch) = switch
            && switch.applies_turned(&next, mass, bodies.spring_turn_rate(i))
        {
            let mut single = next;
            switch.exact().stage(phase, &mut single, mass, &wrench, dt);
            commit(bodies, i, &single);
            continue;
        }
        match drift_kick_drift_linear(phase, &mut next, mass, &wrench, dt) {
            Some(impulse) if mass.is_spherical() => {
                kick_angular(&mut next, mass, impulse);
                next.rotation = rotate_exact(next.rotation, next.angular_velocity, h);
                commit(bodies, i, &next);
            }
            Some(impulse) => {
                if pending.queue(i, &next, mass, impulse) {
                    pending.flush(bodies);
                }
            }
            None => {
                // A copy, so that `next` never escapes into the (not inlined) scalar step and
                // stays in registers on the hot path.
                let mut single = next;
                alone(&mut single, mass, &wrench, bodies.spring_turn_rate(i));
                commit(bodies, i, &single);
            }
        }
    }
    pending.flush(bodies);
}

/// Where a queued batch puts a body once `route` has advanced what runs first (see
/// [`queued`]).
enum Route {
    /// It is stepped and ready to commit.
    Done,
    /// Queue its rotation under this load (see [`QueuedLanes::set`]).
    Queue(Vec3),
}

/// The loop of a batch whose rotations run in lanes: reads each body, steps it by `exact` where
/// the exact switch applies to it (judged once), else lets `route` advance what runs first and
/// say where the body goes; queued rotations are flushed eight (`LANES`) at a time.
#[inline(always)]
fn queued<L: QueuedLanes>(
    mut pending: PendingRotations<L>,
    bodies: &mut impl BodyBatch,
    switch: Option<ExactSwitch>,
    mut exact: impl FnMut(ExactSwitch, &mut BodyState, &MassProperties, &Wrench),
    mut route: impl FnMut(&mut BodyState, &MassProperties, &Wrench) -> Route,
) {
    let mut next = BodyState::ZEROED;
    for i in 0..bodies.len() {
        bodies.prefetch(i + PREFETCH_AHEAD);
        let Some(wrench) = bodies.read(i, &mut next) else {
            continue;
        };
        let mass = bodies.mass(i);
        if let Some(switch) = switch
            && switch.applies_turned(&next, mass, bodies.spring_turn_rate(i))
        {
            let mut single = next;
            exact(switch, &mut single, mass, &wrench);
            commit(bodies, i, &single);
            continue;
        }
        match route(&mut next, mass, &wrench) {
            Route::Done => commit(bodies, i, &next),
            Route::Queue(load) => {
                if pending.queue(i, &next, mass, load) {
                    pending.flush(bodies);
                }
            }
        }
    }
    pending.flush(bodies);
}

/// The batch of whole composed steps (`yoshida4`): a body without torque takes the exact
/// translation over `dt` and its stages' free rotations in sequence, queued for the SIMD kernel
/// (as [`Integrator::step`] does alone); a spherical body turns exactly; a body under a torque
/// is stepped whole by `own` (the method's single-body step), stage by stage.
#[inline(always)]
fn composed(
    kernel: Kernel,
    weights: &'static [Real],
    bodies: &mut impl BodyBatch,
    dt: Real,
    switch: Option<ExactSwitch>,
    mut own: impl FnMut(&mut BodyState, &MassProperties, &Wrench),
) {
    let flow = LaneFlow::Composed(weights);
    let inputs = LaneInputs::default();
    let pending = PendingRotations::new(dt, kernel, SymmetricQueue { inputs, flow });
    let exact = |switch: ExactSwitch, s: &mut BodyState, m: &MassProperties, w: &Wrench| {
        switch.exact().step(s, m, w, dt);
    };
    queued(pending, bodies, switch, exact, |next, mass, wrench| {
        if wrench.torque != Vec3::ZERO {
            // A copy, so that `next` never escapes into the (not inlined) scalar step.
            let mut single = *next;
            own(&mut single, mass, wrench);
            *next = single;
            return Route::Done;
        }
        drift_kick_drift_translation(StepPhase::Whole, next, mass, wrench, dt);
        if mass.is_spherical() {
            next.rotation = rotate_exact(next.rotation, next.angular_velocity, dt);
            Route::Done
        } else {
            Route::Queue(Vec3::ZERO)
        }
    });
}

/// The kick–drift batch (`symplectic-euler*`, `lclamp`, `implicit-gyroscopic`) of `phase`
/// (`Whole` or `Finish`, the same step): each body's translation, then its rotation under its
/// torque, queued for the SIMD kernel ([`PendingRotations`]).
#[inline(always)]
fn kick_drifted(
    kernel: Kernel,
    method: KickDrift,
    phase: StepPhase,
    bodies: &mut impl BodyBatch,
    h: Real,
    switch: Option<ExactSwitch>,
) {
    let inputs = LaneInputs::default();
    let pending = PendingRotations::new(h, kernel, KickDriftQueue { inputs, method });
    let exact = |switch: ExactSwitch, s: &mut BodyState, m: &MassProperties, w: &Wrench| {
        switch.exact().stage(phase, s, m, w, h);
    };
    queued(pending, bodies, switch, exact, |next, mass, wrench| {
        kick_drift_translation(next, mass, wrench.force, h);
        Route::Queue(wrench.torque)
    });
}

/// The `exact` batch: each body's drift–kick–drift translation, then its free rotation, two
/// bodies at a time ([`rotate_exactly_pair`]: their long dependency chains overlap), or stepped
/// whole by `alone` when it is spherical or its translation cannot run first (a whole step
/// under a torque).
#[inline(always)]
fn paired(
    phase: StepPhase,
    bodies: &mut impl BodyBatch,
    dt: Real,
    mut alone: impl FnMut(&mut BodyState, &MassProperties, &Wrench, Real),
) {
    let h = free_rotation_span(phase, dt);
    let mut next = BodyState::ZEROED;
    // A translated body waiting for a partner.
    let mut waiting: Option<(usize, BodyState)> = None;
    for i in 0..bodies.len() {
        bodies.prefetch(i + PREFETCH_AHEAD);
        let Some(wrench) = bodies.read(i, &mut next) else {
            continue;
        };
        let mass = bodies.mass(i);
        if mass.is_spherical() || !drift_kick_drift_translation(phase, &mut next, mass, &wrench, dt)
        {
            let mut single = next;
            alone(&mut single, mass, &wrench, bodies.spring_turn_rate(i));
            commit(bodies, i, &single);
            continue;
        }
        match waiting.take() {
            None => waiting = Some((i, next)),
            Some((j, mut first)) => {
                let mut second = next;
                rotate_exactly_pair([&mut first, &mut second], [bodies.mass(j), mass], h);
                commit(bodies, j, &first);
                commit(bodies, i, &second);
            }
        }
    }
    if let Some((j, mut last)) = waiting {
        rotate_exactly(&mut last, bodies.mass(j), h);
        commit(bodies, j, &last);
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
    /// state each stage starts from).
    pub fn stage_batch_switched(
        self,
        phase: StepPhase,
        bodies: &mut impl BodyBatch,
        h: Real,
        switch: Option<ExactSwitch>,
    ) {
        let kernel = self.lane_kernel();
        self.stage_batch_on(kernel, phase, bodies, h, switch);
    }

    /// [`stage_batch`](Self::stage_batch) with the SIMD lanes of the symmetric-top flow on
    /// `kernel`.
    pub(crate) fn stage_batch_on(
        self,
        kernel: Kernel,
        phase: StepPhase,
        bodies: &mut impl BodyBatch,
        h: Real,
        switch: Option<ExactSwitch>,
    ) {
        let alone = |s: &mut BodyState, m: &MassProperties, w: &Wrench, turn: Real| match switch {
            Some(switch) if switch.applies_turned(s, m, turn) => {
                switch.exact().stage(phase, s, m, w, h)
            }
            _ => self.stage(phase, s, m, w, h),
        };
        if self.is_exact_torque_free() {
            return match phase {
                StepPhase::Whole => paired(StepPhase::Whole, bodies, h, alone),
                StepPhase::Begin => paired(StepPhase::Begin, bodies, h, alone),
                StepPhase::Finish => paired(StepPhase::Finish, bodies, h, alone),
            };
        }
        if let Some(method) = KickDrift::of(self) {
            // The kick–drift methods do nothing before the forces (see `begin_stage`).
            return match phase {
                StepPhase::Begin => each_alone(bodies, alone),
                _ => kick_drifted(kernel, method, phase, bodies, h, switch),
            };
        }
        // One loop per phase, each with its phase a constant, as if written out three times.
        let Some(flow) = self.lane_flow() else {
            return each_alone(bodies, alone);
        };
        match phase {
            StepPhase::Whole => batched(kernel, flow, StepPhase::Whole, bodies, h, switch, alone),
            StepPhase::Begin => batched(kernel, flow, StepPhase::Begin, bodies, h, switch, alone),
            StepPhase::Finish => batched(kernel, flow, StepPhase::Finish, bodies, h, switch, alone),
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
        let kernel = self.lane_kernel();
        self.step_batch_on(kernel, bodies, dt, switch);
    }

    /// [`step_batch_switched`](Self::step_batch_switched) with the SIMD lanes on `kernel`.
    pub(crate) fn step_batch_on(
        self,
        kernel: Kernel,
        bodies: &mut impl BodyBatch,
        dt: Real,
        switch: Option<ExactSwitch>,
    ) {
        if let [c] = self.composition() {
            return self.stage_batch_on(kernel, StepPhase::Whole, bodies, c * dt, switch);
        }
        let alone = |s: &mut BodyState, m: &MassProperties, w: &Wrench, turn: Real| match switch {
            Some(switch) if switch.applies_turned(s, m, turn) => switch.exact().step(s, m, w, dt),
            _ => self.step(s, m, w, dt),
        };
        if self == Integrator::Exact4 {
            // Without torque its composed step is the translation of a whole stage over `dt`
            // and one exact rotation over `dt` (see `Integrator::step`): a whole stage's work.
            return paired(StepPhase::Whole, bodies, dt, alone);
        }
        if self.rotates_on_symmetric_kernel() {
            let own = |s: &mut BodyState, m: &MassProperties, w: &Wrench| self.step(s, m, w, dt);
            return composed(kernel, self.composition(), bodies, dt, switch, own);
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
