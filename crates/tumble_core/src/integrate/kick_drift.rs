//! The batch of the four kick–drift methods (`symplectic-euler`, `symplectic-euler-linear`,
//! `lclamp`, `implicit-gyroscopic`): each body's translation, then its rotation under its torque
//! queued for their lane kernel (`kick_drift_kernel`), eight bodies at a time.

use super::ExactSwitch;
use super::body_batch::BodyBatch;
use super::kick_drift_kernel::{KickDrift, kick_drift_translation};
use super::pending::{PendingRotations, QueuedRotation, Route, queued};
use super::stages::StepPhase;
use crate::mass::MassProperties;
use crate::math::Real;
use crate::simd::Kernel;
use crate::state::{BodyState, Wrench};

/// The kick–drift batch (`symplectic-euler*`, `lclamp`, `implicit-gyroscopic`) of `phase`
/// (`Whole` or `Finish`, the same step): each body's translation, then its rotation under its
/// torque, queued for the SIMD kernel ([`PendingRotations`]).
#[inline(always)]
pub(super) fn kick_drift_batch(
    kernel: Kernel,
    method: KickDrift,
    phase: StepPhase,
    bodies: &mut impl BodyBatch,
    h: Real,
    switch: Option<ExactSwitch>,
) {
    let pending = PendingRotations::new(h, kernel, QueuedRotation::KickDrift(method));
    let exact = |switch: ExactSwitch, s: &mut BodyState, m: &MassProperties, w: &Wrench| {
        switch.exact().stage(phase, s, m, w, h);
        false
    };
    queued(pending, bodies, switch, exact, |next, mass, wrench| {
        kick_drift_translation(next, mass, wrench.force, h);
        Route::Queue(wrench.torque)
    });
}
