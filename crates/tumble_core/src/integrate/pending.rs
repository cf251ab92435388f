//! Bodies waiting for their rotation in SIMD lanes: a batch translates each body, queues its
//! rotation, and flushes [`LANES`] of them at a time through a lane kernel (the free-flow
//! kernel, or the kick–drift one), committing each result.

use crate::mass::MassProperties;
use crate::math::{Quat, Real, Vec3};
use crate::simd::{Kernel, LANES};
use crate::state::BodyState;

use super::BodyBatch;
use super::body_batch::commit;
use super::kick_drift_kernel::{KickDrift, kick_drift_lanes, kick_drift_one};
use super::lane_input::{LaneInputs, RotatedLanes};
use super::symmetric_kernel::{LaneFlow, rotate_symmetric_lanes, rotate_symmetric_one};

/// A lane kernel's inputs for [`LANES`] bodies, as a batch queues them: the rotation each of
/// them is waiting for.
pub(super) trait QueuedLanes {
    /// The inputs.
    fn inputs(&mut self) -> &mut LaneInputs;
    /// True when the kernel works in the relabelled frame (see [`LaneFlow::relabels`]).
    fn relabels(&self) -> bool;
    /// Lane `lane` rotated alone, through the kernel on `f64`: its new `(q, ω)`.
    fn one(&mut self, lane: usize, h: Real) -> (Quat, Vec3);
    /// Every lane rotated at once on `kernel`'s instruction set (the same bits as [`one`](Self::one)).
    fn all(&mut self, kernel: Kernel, h: [Real; LANES]) -> RotatedLanes;

    /// Puts the body `state` (already translated) into lane `lane`, under `load`: the angular
    /// impulse of its kick for a free flow, its torque for a kick–drift method.
    #[inline(always)]
    fn set(&mut self, lane: usize, state: &BodyState, mass: &MassProperties, load: Vec3) {
        let relabels = self.relabels();
        self.inputs().set(
            lane,
            state.rotation,
            state.angular_velocity,
            mass,
            load,
            relabels,
        );
    }
}

/// The free flows of `splitting`, `splitting-xyz`, `rk4` (after their kicks) or of a composed
/// step.
pub(super) struct SymmetricQueue {
    pub(super) inputs: LaneInputs,
    pub(super) flow: LaneFlow,
}

impl QueuedLanes for SymmetricQueue {
    #[inline(always)]
    fn inputs(&mut self) -> &mut LaneInputs {
        &mut self.inputs
    }
    #[inline(always)]
    fn relabels(&self) -> bool {
        self.flow.relabels()
    }
    #[inline(always)]
    fn one(&mut self, lane: usize, h: Real) -> (Quat, Vec3) {
        rotate_symmetric_one(&self.inputs.get(lane), h, self.flow)
    }
    #[inline(always)]
    fn all(&mut self, kernel: Kernel, h: [Real; LANES]) -> RotatedLanes {
        rotate_symmetric_lanes(kernel, &self.inputs, h, self.flow)
    }
}

/// The rotations of a kick–drift method.
pub(super) struct KickDriftQueue {
    pub(super) inputs: LaneInputs,
    pub(super) method: KickDrift,
}

impl QueuedLanes for KickDriftQueue {
    #[inline(always)]
    fn inputs(&mut self) -> &mut LaneInputs {
        &mut self.inputs
    }
    #[inline(always)]
    fn relabels(&self) -> bool {
        false
    }
    #[inline(always)]
    fn one(&mut self, lane: usize, h: Real) -> (Quat, Vec3) {
        kick_drift_one(&self.inputs.get(lane), h, self.method)
    }
    #[inline(always)]
    fn all(&mut self, kernel: Kernel, h: [Real; LANES]) -> RotatedLanes {
        kick_drift_lanes(kernel, &self.inputs, h, self.method)
    }
}

/// Bodies waiting for their rotation over the same `h`, flushed [`LANES`] at a time: each
/// body's translated position and velocity, and its kernel inputs component by component so
/// that the kernel loads them as vectors. (`h` is written once, not per body: scalar stores
/// read back at once by a vector load stall store forwarding.)
pub(super) struct PendingRotations<L> {
    index: [usize; LANES],
    /// Each queued body's `(position, linear_velocity)`: the rest of its state is the kernel's.
    translated: [(Vec3, Vec3); LANES],
    lanes: L,
    h: [Real; LANES],
    len: usize,
    kernel: Kernel,
}

impl<L: QueuedLanes> PendingRotations<L> {
    /// No bodies yet; all of them will rotate over `h`, `LANES` at a time on `kernel`.
    pub(super) fn new(h: Real, kernel: Kernel, lanes: L) -> Self {
        Self {
            index: [0; LANES],
            translated: [(Vec3::ZERO, Vec3::ZERO); LANES],
            lanes,
            h: [h; LANES],
            len: 0,
            kernel,
        }
    }

    /// Queues body `index` (already translated, as `state`) for its rotation under `load` (see
    /// [`QueuedLanes::set`]); returns true when the batch is full and must be flushed.
    #[inline(always)]
    pub(super) fn queue(
        &mut self,
        index: usize,
        state: &BodyState,
        mass: &MassProperties,
        load: Vec3,
    ) -> bool {
        let lane = self.len;
        self.lanes.set(lane, state, mass, load);
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
                let (rotation, omega) = self.lanes.one(0, self.h[0]);
                self.finish(0, rotation, omega, bodies);
            }
            len => {
                self.lanes.inputs().fill_from_first(len);
                let rotated = self.lanes.all(self.kernel, self.h);
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
