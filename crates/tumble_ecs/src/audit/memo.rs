//! What the end of an audited step measured, kept for the start of the next one.
//!
//! The start of a step measures `T + V` of the state the previous step ended with, unless game
//! code changed something in between. So the end pass keeps each body's kinetic energy and each
//! spring's elastic energy together with *every input* they were computed from, and the next
//! start reuses a value only when those inputs are the same bit for bit: a memo of two pure
//! functions, so a reused value is the value a fresh evaluation would give. No change ticks are
//! involved; whatever changed a body (game code, a quarantine putting it back, a rollback) shows
//! in its bits.

use bevy_ecs::entity::Entity;
use tumble_core::math::Real;

use crate::components::{MassProps, Pose, Velocity, kinetic_energy_f64};

/// The bits of `values`: equal bits are equal inputs to the energy functions (`==` on floats
/// would call `−0` and `+0` equal and a NaN unequal to itself).
#[inline(always)]
fn same_bits<const N: usize>(a: [Real; N], b: [Real; N]) -> bool {
    a.map(Real::to_bits) == b.map(Real::to_bits)
}

/// Every input of a body's kinetic energy ([`kinetic_energy_f64`]: rotation, velocities,
/// mass, principal moments and frame) and of its springs' anchors (translation, rotation).
/// The inverse mass stands for the mass: one decides the other.
#[inline(always)]
fn body_inputs(pose: &Pose, velocity: &Velocity, mass: &MassProps) -> [Real; 21] {
    let (t, q, v, w) = (
        pose.translation,
        pose.rotation,
        velocity.linear,
        velocity.angular,
    );
    let (i, f) = (mass.principal_inertia(), mass.principal_frame());
    [
        t.x,
        t.y,
        t.z,
        q.x,
        q.y,
        q.z,
        q.w,
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

/// A body as the end of the last step measured it.
#[derive(Debug, Clone, Copy)]
pub(super) struct BodyMemo {
    /// The end pass that measured it.
    pub(super) pass: u64,
    entity: Entity,
    /// [`body_inputs`] at the measurement.
    inputs: [Real; 21],
    kinetic: f64,
}

impl BodyMemo {
    /// The body `entity` at `pose`, moving at `velocity`, and its kinetic energy, measured by
    /// end pass `pass`.
    pub(super) fn measure(
        pass: u64,
        entity: Entity,
        pose: &Pose,
        velocity: &Velocity,
        mass: &MassProps,
    ) -> Self {
        Self {
            pass,
            entity,
            inputs: body_inputs(pose, velocity, mass),
            kinetic: kinetic_energy_f64(pose, velocity, mass),
        }
    }

    /// The kinetic energy.
    pub(super) fn kinetic(&self) -> f64 {
        self.kinetic
    }

    /// True when `entity` is this body and `pose`, `velocity` and `mass` are what it was
    /// measured with, bit for bit: its kinetic energy and its springs' anchors are unchanged.
    #[inline]
    pub(super) fn still(
        &self,
        entity: Entity,
        pose: &Pose,
        velocity: &Velocity,
        mass: &MassProps,
    ) -> bool {
        self.entity == entity && same_bits(self.inputs, body_inputs(pose, velocity, mass))
    }
}
