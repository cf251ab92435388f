//! What the end of an audited step measured, kept for the start of the next one.
//!
//! The start of a step measures `T + V` of the state the previous step ended with, unless game
//! code changed something in between. So the end pass keeps each body's kinetic energy and each
//! spring's elastic energy together with *every input* they were computed from, and the next
//! start reuses a value only when those inputs are the same bit for bit: a memo of two pure
//! functions, so a reused value is the value a fresh evaluation would give. No change ticks are
//! involved; whatever changed a body (game code, a quarantine putting it back, a rollback) shows
//! in its bits.

use tumble_core::math::{Real, same_bits};

use crate::components::{MassProps, Pose, Velocity, kinetic_energy_f64};

/// Every input of a body's kinetic energy ([`kinetic_energy_f64`]: rotation, velocities,
/// mass, principal moments and frame) and of its springs' anchors (translation, rotation) but
/// its pose, which the ledger keeps anyway (the end pose its springs' energies are measured at).
/// The inverse mass stands for the mass: one decides the other.
#[inline(always)]
fn rest_inputs(velocity: &Velocity, mass: &MassProps) -> [Real; 14] {
    let (v, w) = (velocity.linear, velocity.angular);
    let (i, f) = (mass.principal_inertia(), mass.principal_frame());
    [
        v.x,
        v.y,
        v.z,
        w.x,
        w.y,
        w.z,
        mass.inv_mass(),
        i.x,
        i.y,
        i.z,
        f.x,
        f.y,
        f.z,
        f.w,
    ]
}

/// The pose's inputs.
#[inline(always)]
fn pose_inputs(pose: &Pose) -> [Real; 7] {
    let (t, q) = (pose.translation, pose.rotation);
    [t.x, t.y, t.z, q.x, q.y, q.z, q.w]
}

/// A body as the end of the last step measured it, beside the pose it was measured at (the
/// ledger's end pose) and the entity it was measured for (the ledger entry's).
#[derive(Debug, Clone, Copy)]
pub(super) struct BodyMemo {
    /// The end pass that measured it (0: none).
    pass: u64,
    /// [`rest_inputs`] at the measurement.
    inputs: [Real; 14],
    kinetic: f64,
}

impl BodyMemo {
    /// No measurement.
    pub(super) const NONE: Self = Self {
        pass: 0,
        inputs: [0.0; 14],
        kinetic: 0.0,
    };

    /// The body at `pose`, moving at `velocity`, and its kinetic energy, measured by end pass
    /// `pass` (≥ 1).
    pub(super) fn measure(pass: u64, pose: &Pose, velocity: &Velocity, mass: &MassProps) -> Self {
        Self {
            pass,
            inputs: rest_inputs(velocity, mass),
            kinetic: kinetic_energy_f64(pose, velocity, mass),
        }
    }

    /// True when end pass `pass` (≥ 1) measured it.
    pub(super) fn measured_by(&self, pass: u64) -> bool {
        self.pass != 0 && self.pass == pass
    }

    /// The kinetic energy.
    pub(super) fn kinetic(&self) -> f64 {
        self.kinetic
    }

    /// True when end pass `pass` measured this body at `measured_pose`, and `pose`, `velocity`
    /// and `mass` are what it was measured with, bit for bit: its kinetic energy and its
    /// springs' anchors are unchanged. (The caller checks that the entity is the one measured.)
    #[inline]
    pub(super) fn still(
        &self,
        pass: u64,
        measured_pose: &Pose,
        pose: &Pose,
        velocity: &Velocity,
        mass: &MassProps,
    ) -> bool {
        self.measured_by(pass)
            && same_bits(pose_inputs(measured_pose), pose_inputs(pose))
            && same_bits(self.inputs, rest_inputs(velocity, mass))
    }
}
