//! `ApplyForces`: forces, torques and impulses from game code.

use bevy_ecs::prelude::*;
use bevy_ecs::query::QueryData;
use tumble_core::math::{Vec3, quat_rotate};

use crate::components::{
    ForceAccumulator, Kinematic, MassProps, Pose, RigidBody, Static, Velocity,
};

/// The loads and impulses of one body, for a game system's query: `Query<BodyForces>`, with the
/// methods of [`ApplyForces`].
///
/// It matches rigid bodies with a [`ForceAccumulator`] (the component that carries loads into
/// the step). A body spawned without one does not match: spawn it with
/// `ForceAccumulator::default()`, or apply loads through an entity
/// (`world.entity_mut(body).apply_force(..)`), which inserts the accumulator when missing.
///
/// ```
/// use bevy_ecs::prelude::*;
/// use tumble_core::math::Vec3;
/// use tumble_ecs::prelude::*;
///
/// /// A thruster at the tail of a ship, pushing along the ship's own +z axis.
/// fn thrust(mut ships: Query<BodyForces>) {
///     for mut ship in &mut ships {
///         ship.apply_local_force_at_local_point(Vec3::Z * 10.0, Vec3::new(0.0, 0.0, -1.0));
///     }
/// }
/// ```
#[derive(QueryData)]
#[query_data(mutable)]
pub struct BodyForces {
    accumulator: &'static mut ForceAccumulator,
    velocity: &'static mut Velocity,
    pose: &'static Pose,
    mass: &'static MassProps,
    /// A [`Static`] or [`Kinematic`] body: its loads are discarded by the step, its impulses here.
    fixed: Has<Static>,
    kinematic: Has<Kinematic>,
}

/// Loads on a rigid body, in world or body coordinates, through the centre of mass or a point.
/// Implemented by [`BodyForces`]' items (in a system) and by `EntityWorldMut` (on a bare
/// `World`, where it inserts the body's [`ForceAccumulator`] when missing, and warns and drops
/// the load when the entity is not a rigid body). An impulse on a [`Static`] or [`Kinematic`]
/// body is discarded, as the step discards their loads: the one never moves, the other moves
/// as game code sets it.
pub trait ApplyForces {
    /// The body's accumulator, pose and mass properties (`None`: not a rigid body). Plumbing
    /// for implementors; game code calls the `apply_*` methods.
    #[doc(hidden)]
    fn accumulator_and_body(&mut self) -> Option<(&mut ForceAccumulator, Pose, MassProps)>;

    /// The body's velocity, pose and mass properties (`None`: not a rigid body). Plumbing for
    /// implementors; game code calls the `apply_*` methods.
    #[doc(hidden)]
    fn velocity_and_body(&mut self) -> Option<(&mut Velocity, Pose, MassProps)>;

    /// Adds a force `F` (N, world frame) through the centre of mass for the next step.
    fn apply_force(&mut self, force: Vec3) {
        if let Some((acc, _, _)) = self.accumulator_and_body() {
            acc.add_force(force);
        }
    }

    /// Adds a force `F` (N, world frame) at the world point `p`: `F`, and the torque
    /// `(p − x) × F` about the body's centre of mass `x`.
    fn apply_force_at_point(&mut self, force: Vec3, world_point: Vec3) {
        if let Some((acc, pose, mass)) = self.accumulator_and_body() {
            acc.add_force_at_point(force, world_point, pose.center_of_mass(&mass));
        }
    }

    /// Adds a world-frame force at a point given in body coordinates (it turns with the body).
    fn apply_force_at_local_point(&mut self, force: Vec3, local_point: Vec3) {
        if let Some((acc, pose, mass)) = self.accumulator_and_body() {
            let point = pose.transform_point(local_point);
            acc.add_force_at_point(force, point, pose.center_of_mass(&mass));
        }
    }

    /// Adds a force given in body coordinates (`R f` in the world) through the centre of mass.
    fn apply_local_force(&mut self, local_force: Vec3) {
        if let Some((acc, pose, _)) = self.accumulator_and_body() {
            acc.add_force(quat_rotate(pose.rotation, local_force));
        }
    }

    /// Adds a force given in body coordinates at a point given in body coordinates: a thruster
    /// fixed to the hull, both turning with the body.
    fn apply_local_force_at_local_point(&mut self, local_force: Vec3, local_point: Vec3) {
        if let Some((acc, pose, mass)) = self.accumulator_and_body() {
            let force = quat_rotate(pose.rotation, local_force);
            let point = pose.transform_point(local_point);
            acc.add_force_at_point(force, point, pose.center_of_mass(&mass));
        }
    }

    /// Adds a torque `τ` (N·m, world frame) for the next step.
    fn apply_torque(&mut self, torque: Vec3) {
        if let Some((acc, _, _)) = self.accumulator_and_body() {
            acc.add_torque(torque);
        }
    }

    /// Adds a torque given in body coordinates (`R τ` in the world).
    fn apply_local_torque(&mut self, local_torque: Vec3) {
        if let Some((acc, pose, _)) = self.accumulator_and_body() {
            acc.add_torque(quat_rotate(pose.rotation, local_torque));
        }
    }

    /// Changes the momentum by the impulse `J` (N·s, world frame) now: `v += J/m`.
    fn apply_linear_impulse(&mut self, impulse: Vec3) {
        if let Some((velocity, _, mass)) = self.velocity_and_body() {
            velocity.linear += impulse * mass.inv_mass();
        }
    }

    /// Changes the angular momentum by `J` (N·m·s, world frame) now: `ω += R I_b⁻¹ Rᵀ J`
    /// (nothing on a locked axis).
    fn apply_angular_impulse(&mut self, impulse: Vec3) {
        if let Some((velocity, pose, mass)) = self.velocity_and_body() {
            velocity.angular += mass.world_inv_inertia_mul(pose.rotation, impulse);
        }
    }

    /// An impulse `J` (world frame) at the world point `p`: `v += J/m` and
    /// `ω += R I_b⁻¹ Rᵀ ((p − x) × J)`, `x` the centre of mass.
    fn apply_impulse_at_point(&mut self, impulse: Vec3, world_point: Vec3) {
        if let Some((velocity, pose, mass)) = self.velocity_and_body() {
            let arm = world_point - pose.center_of_mass(&mass);
            velocity.linear += impulse * mass.inv_mass();
            velocity.angular += mass.world_inv_inertia_mul(pose.rotation, arm.cross(impulse));
        }
    }
}

impl ApplyForces for BodyForcesItem<'_, '_> {
    fn accumulator_and_body(&mut self) -> Option<(&mut ForceAccumulator, Pose, MassProps)> {
        Some((self.accumulator.as_mut(), *self.pose, *self.mass))
    }

    fn velocity_and_body(&mut self) -> Option<(&mut Velocity, Pose, MassProps)> {
        if self.fixed || self.kinematic {
            return None;
        }
        Some((self.velocity.as_mut(), *self.pose, *self.mass))
    }
}

/// The pose and mass of `entity` if it is a rigid body; warns (once per call) otherwise.
fn body_of(entity: &EntityWorldMut) -> Option<(Pose, MassProps)> {
    let body = entity.contains::<RigidBody>().then(|| {
        entity
            .get::<Pose>()
            .copied()
            .zip(entity.get::<MassProps>().copied())
    });
    let found = body.flatten();
    if found.is_none() {
        tracing::warn!(
            entity = %entity.id(),
            "a load applied to entity {} was dropped: it is not a rigid body",
            entity.id()
        );
    }
    found
}

impl ApplyForces for EntityWorldMut<'_> {
    fn accumulator_and_body(&mut self) -> Option<(&mut ForceAccumulator, Pose, MassProps)> {
        let (pose, mass) = body_of(self)?;
        if !self.contains::<ForceAccumulator>() {
            self.insert(ForceAccumulator::default());
        }
        let acc = self.get_mut::<ForceAccumulator>()?.into_inner();
        Some((acc, pose, mass))
    }

    fn velocity_and_body(&mut self) -> Option<(&mut Velocity, Pose, MassProps)> {
        let (pose, mass) = body_of(self)?;
        // Static bodies never move and kinematic ones move as game code sets them: an
        // impulse is discarded, as their loads are by the step.
        if self.contains::<Static>() || self.contains::<Kinematic>() {
            return None;
        }
        let velocity = self.get_mut::<Velocity>()?.into_inner();
        Some((velocity, pose, mass))
    }
}
