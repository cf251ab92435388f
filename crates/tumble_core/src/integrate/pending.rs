//! Bodies waiting for their rotation in SIMD lanes: a batch translates each body, queues its
//! rotation, and flushes [`LANES`] of them at a time through a lane kernel (the free-flow
//! kernel, or the kick–drift one), committing each result; and `queued`, the batch loop that
//! the composed and kick–drift batches route their bodies through.

use crate::mass::MassProperties;
use crate::math::{Quat, Real, Vec3};
use crate::simd::{Kernel, LANES, run_on};
use crate::state::{BodyState, Wrench};

use super::ExactSwitch;
use super::body_batch::{BodyBatch, PREFETCH_AHEAD, commit};
use super::exact_flow::ExactPairs;
use super::kick_drift_kernel::{
    CLAMPED, EXPLICIT, EXPLICIT_LINEAR, IMPLICIT, KickDrift, KickDriftLanes, kick_drift_one,
};
use super::lane_input::{LaneInput, LaneInputs};
use super::symmetric_kernel::{
    COMPOSED, LaneFlow, QueuedInputs, RK4, SYMMETRIC, SymmetricLanes, XYZ, rotate_symmetric_one,
};

/// The rotation a batch's queued bodies wait for.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum QueuedRotation {
    /// A free flow: `splitting`'s, `splitting-xyz`'s or `rk4`'s (after the kick of each body's
    /// angular impulse, for a flow that kicks), or a composed step's.
    Free(LaneFlow),
    /// A kick–drift method's rotation under each body's torque.
    KickDrift(KickDrift),
}

impl QueuedRotation {
    /// True when the kernel works in the relabelled frame (see [`LaneFlow::relabels`]).
    #[inline(always)]
    fn relabels(self) -> bool {
        match self {
            QueuedRotation::Free(flow) => flow.relabels(),
            QueuedRotation::KickDrift(_) => false,
        }
    }

    /// One body's rotation through the kernel on `f64` (the bits of its lane): its new `(q, ω)`.
    #[inline(always)]
    fn one(self, input: &LaneInput, h: Real) -> (Quat, Vec3) {
        match self {
            QueuedRotation::Free(flow) => rotate_symmetric_one(input, h, flow),
            QueuedRotation::KickDrift(method) => kick_drift_one(input, h, method),
        }
    }
}

/// Bodies waiting for their rotation over the same `h`, flushed [`LANES`] at a time: each
/// body's translated position and velocity, and its kernel inputs component by component so
/// that the kernel loads them as vectors. (`h` is written once, not per body: scalar stores
/// read back at once by a vector load stall store forwarding.)
pub(super) struct PendingRotations {
    index: [usize; LANES],
    /// Each queued body's `(position, linear_velocity)`: the rest of its state is the kernel's.
    translated: [(Vec3, Vec3); LANES],
    /// Each queued body's rotation, orientation, inertia and load.
    inputs: LaneInputs,
    rotation: QueuedRotation,
    h: [Real; LANES],
    len: usize,
    kernel: Kernel,
}

impl PendingRotations {
    /// No bodies yet; all of them will take `rotation` over `h`, `LANES` at a time on `kernel`.
    pub(super) fn new(h: Real, kernel: Kernel, rotation: QueuedRotation) -> Self {
        Self {
            index: [0; LANES],
            translated: [(Vec3::ZERO, Vec3::ZERO); LANES],
            inputs: LaneInputs::default(),
            rotation,
            h: [h; LANES],
            len: 0,
            kernel,
        }
    }

    /// Queues body `index` (already translated, as `state`) for its rotation under `load` (the
    /// angular impulse of its kick for a free flow, its torque for a kick–drift method);
    /// returns true when the batch is full and must be flushed.
    #[inline(always)]
    pub(super) fn queue(
        &mut self,
        index: usize,
        state: &BodyState,
        mass: &MassProperties,
        load: Vec3,
    ) -> bool {
        let lane = self.len;
        let relabels = self.rotation.relabels();
        let (rotation, omega) = (state.rotation, state.angular_velocity);
        self.inputs.set(lane, rotation, omega, mass, load, relabels);
        self.index[lane] = index;
        self.translated[lane] = (state.position, state.linear_velocity);
        self.len = lane + 1;
        self.len == LANES
    }

    /// Rotates the queued bodies and commits each result. A batch of one goes through the
    /// scalar kernel; a partial batch fills its empty lanes with copies of its first body
    /// (lanes are independent, so the results are the same bits either way).
    #[inline(always)]
    pub(super) fn flush(&mut self, bodies: &mut impl BodyBatch) {
        match self.len {
            0 => {}
            1 => {
                let (rotation, omega) = self.rotation.one(&self.inputs.get(0), self.h[0]);
                self.finish(0, rotation, omega, bodies);
            }
            len => {
                self.inputs.fill_from_first(len);
                let (kernel, inputs, h) = (self.kernel, &self.inputs, self.h);
                // Every lane at once on the kernel path, through the compilation of the
                // kernel for the queued rotation's kind (a constant in each).
                let rotated = match self.rotation {
                    QueuedRotation::Free(flow) => {
                        let queued = QueuedInputs { inputs, h };
                        match flow {
                            LaneFlow::Symmetric { .. } => {
                                run_on!(kernel, SymmetricLanes::<_, SYMMETRIC>::new(queued, flow))
                            }
                            LaneFlow::Composed(_) => {
                                run_on!(kernel, SymmetricLanes::<_, COMPOSED>::new(queued, flow))
                            }
                            LaneFlow::Xyz { .. } => {
                                run_on!(kernel, SymmetricLanes::<_, XYZ>::new(queued, flow))
                            }
                            LaneFlow::Rk4 { .. } => {
                                run_on!(kernel, SymmetricLanes::<_, RK4>::new(queued, flow))
                            }
                        }
                    }
                    QueuedRotation::KickDrift(method) => match method {
                        KickDrift::Explicit => {
                            run_on!(kernel, KickDriftLanes::<EXPLICIT> { inputs, h })
                        }
                        KickDrift::ExplicitLinear => {
                            run_on!(kernel, KickDriftLanes::<EXPLICIT_LINEAR> { inputs, h })
                        }
                        KickDrift::Clamped => {
                            run_on!(kernel, KickDriftLanes::<CLAMPED> { inputs, h })
                        }
                        KickDrift::Implicit => {
                            run_on!(kernel, KickDriftLanes::<IMPLICIT> { inputs, h })
                        }
                    },
                };
                for lane in 0..len {
                    let (rotation, omega) = rotated.lane(lane);
                    self.finish(lane, rotation, omega, bodies);
                }
            }
        }
        self.len = 0;
    }

    /// Commits lane `lane`'s rotated body.
    #[inline(always)]
    fn finish(&self, lane: usize, rotation: Quat, omega: Vec3, bodies: &mut impl BodyBatch) {
        // A fresh value rather than an update of the queued one in place: stores of the new
        // fields followed by the wide loads of `is_finite` across field boundaries would stall
        // store forwarding.
        let (position, linear_velocity) = self.translated[lane];
        let next = BodyState {
            position,
            rotation,
            linear_velocity,
            angular_velocity: omega,
        };
        commit(bodies, self.index[lane], &next);
    }
}

/// Where a queued batch puts a body once `route` has advanced what runs first (see
/// [`queued`]).
pub(super) enum Route {
    /// It is stepped and ready to commit.
    Done,
    /// Queue its rotation under this load (see [`PendingRotations::queue`]).
    Queue(Vec3),
}

/// The loop of a batch whose rotations run in lanes: reads each body, steps it by `exact` where
/// the exact switch applies to it (judged once), else lets `route` advance what runs first and
/// say where the body goes; queued rotations are flushed eight (`LANES`) at a time. `exact`
/// returns true when it only translated the body, leaving its exact free rotation over the
/// queue's span to be run two bodies at a time ([`ExactPairs`]), false when it stepped the body
/// whole.
#[inline(always)]
pub(super) fn queued(
    mut pending: PendingRotations,
    bodies: &mut impl BodyBatch,
    switch: Option<ExactSwitch>,
    mut exact: impl FnMut(ExactSwitch, &mut BodyState, &MassProperties, &Wrench) -> bool,
    mut route: impl FnMut(&mut BodyState, &MassProperties, &Wrench) -> Route,
) {
    let mut pairs = ExactPairs::new(pending.h[0]);
    let mut next = BodyState::ZEROED;
    for i in 0..bodies.len() {
        bodies.prefetch(i + PREFETCH_AHEAD);
        let Some(wrench) = bodies.take(i, &mut next) else {
            continue;
        };
        let mass = bodies.mass(i);
        if let Some(switch) = switch
            && switch.applies_turned(&next, mass, bodies.spring_turn_rate(i))
        {
            let mut single = next;
            if exact(switch, &mut single, mass, &wrench) {
                pairs.rotate(i, single, bodies);
            } else {
                commit(bodies, i, &single);
            }
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
    pairs.finish(bodies);
}
