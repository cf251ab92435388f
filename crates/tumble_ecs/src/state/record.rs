//! The record of one rigid body's state that rollback, the checksum and snapshots share.

use bevy_ecs::prelude::*;
use tumble_core::math::Real;

use crate::components::{
    Damping, ForceAccumulator, GravityScale, HeldLoad, MassProps, Pose, Velocity,
};

/// Which optional parts a body has (one bit each).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Parts(u8);

impl Parts {
    /// A [`ForceAccumulator`].
    pub const ACCUMULATOR: Self = Self(1);
    /// A [`HeldLoad`] (comes with every accumulator).
    pub const HELD_LOAD: Self = Self(1 << 1);
    /// A [`GravityScale`].
    pub const GRAVITY_SCALE: Self = Self(1 << 2);
    /// [`Damping`].
    pub const DAMPING: Self = Self(1 << 3);
    /// The [`Static`](crate::components::Static) marker.
    pub const STATIC: Self = Self(1 << 4);
    /// The [`Kinematic`](crate::components::Kinematic) marker.
    pub const KINEMATIC: Self = Self(1 << 5);
    /// Quarantined ([`Rejected`](crate::components::Rejected)).
    pub const REJECTED: Self = Self(1 << 6);

    /// Whether every bit of `part` is set.
    pub fn contains(self, part: Self) -> bool {
        self.0 & part.0 == part.0
    }

    fn with(self, part: Self, present: bool) -> Self {
        if present { Self(self.0 | part.0) } else { self }
    }
}

/// One rigid body's state: everything of a body the next step depends on. Absent optional
/// parts hold their defaults.
///
/// The one record of a body for every consumer: a [`RollbackSnapshot`](super::RollbackSnapshot)
/// keeps these, [`world_checksum`](super::world_checksum) hashes them and a serde
/// [`Snapshot`](super::Snapshot) saves them, each reading the record whole (exhaustive
/// destructuring), so a part added here is a compile error in each until it is covered.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodyRecord {
    /// The body (the same entity is written back).
    pub entity: Entity,
    /// Pose.
    pub transform: Pose,
    /// Velocity.
    pub velocity: Velocity,
    /// Mass properties.
    pub mass: MassProps,
    /// Pending loads.
    pub accumulator: ForceAccumulator,
    /// Loads held over a step of several stages.
    pub held: HeldLoad,
    /// Gravity scale.
    pub gravity_scale: Real,
    /// Damping.
    pub damping: Damping,
    /// Which optional parts the body had.
    pub parts: Parts,
}

impl BodyRecord {
    /// The record of `entity` from its components: the required ones, the optional ones
    /// (`None` when absent) and its markers (static, kinematic, quarantined).
    pub fn new(
        entity: Entity,
        (transform, velocity, mass): (&Pose, &Velocity, &MassProps),
        (accumulator, held, gravity_scale, damping): (
            Option<&ForceAccumulator>,
            Option<&HeldLoad>,
            Option<&GravityScale>,
            Option<&Damping>,
        ),
        (fixed, kinematic, rejected): (bool, bool, bool),
    ) -> Self {
        let parts = Parts::default()
            .with(Parts::ACCUMULATOR, accumulator.is_some())
            .with(Parts::HELD_LOAD, held.is_some())
            .with(Parts::GRAVITY_SCALE, gravity_scale.is_some())
            .with(Parts::DAMPING, damping.is_some())
            .with(Parts::STATIC, fixed)
            .with(Parts::KINEMATIC, kinematic)
            .with(Parts::REJECTED, rejected);
        Self {
            entity,
            transform: *transform,
            velocity: *velocity,
            mass: *mass,
            accumulator: accumulator.copied().unwrap_or_default(),
            held: held.copied().unwrap_or_default(),
            gravity_scale: gravity_scale.copied().unwrap_or_default().0,
            damping: damping.copied().unwrap_or_default(),
            parts,
        }
    }

    /// The part `value` if the body has `part`, else `None`.
    pub fn part<T>(&self, part: Parts, value: T) -> Option<T> {
        self.parts.contains(part).then_some(value)
    }
}
