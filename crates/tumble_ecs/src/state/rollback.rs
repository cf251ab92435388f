//! `RollbackSnapshot`: save and restore what the next step depends on.

use bevy_ecs::component::Mutable;
use bevy_ecs::prelude::*;
use thiserror::Error;

use crate::audit::{EnergyAudit, EnergyLedger, LedgerState};
use crate::components::Rejected;
use crate::components::{ConstantForce, ConstantLocalForce, ConstantTorque, Spring};
use crate::components::{
    Damping, ForceAccumulator, Gravity, GravityScale, HeldLoad, Kinematic, MassProps,
    PhysicsSettings, Pose, RigidBody, Static, Velocity,
};
use crate::integrate::HalfDrifted;
use crate::integrate::StageCursor;

use super::record::{BodyRecord, Parts};

/// What the next step depends on (see the module docs). Capture with
/// [`capture`](Self::capture) (or [`capture_into`](Self::capture_into) to reuse the buffers),
/// put back with [`restore`](Self::restore).
///
/// ```
/// use bevy_ecs::prelude::World;
/// use tumble_core::math::Vec3;
/// use tumble_ecs::state::world_checksum;
/// use tumble_ecs::prelude::*;
/// use tumble_ecs::state::RollbackSnapshot;
///
/// let mut world = World::new();
/// world.insert_resource(Gravity::EARTH_Y_DOWN);
/// let body = world.spawn((RigidBody, Velocity::linear(Vec3::X), ForceAccumulator::default())).id();
/// let mut physics = PhysicsRunner::new(&mut world);
/// physics.step(&mut world);
///
/// let saved = RollbackSnapshot::capture(&mut world);
/// let before = world_checksum(&world);
/// for _ in 0..8 {
///     world.get_mut::<ForceAccumulator>(body).unwrap().add_force(Vec3::Y); // a mispredicted input
///     physics.step(&mut world);
/// }
/// saved.restore(&mut world).unwrap();
/// assert_eq!(world_checksum(&world), before);
/// assert_eq!(physics.replans(), 0); // nothing to re-plan: the schedule is kept
/// ```
#[derive(Debug, Clone, Default, PartialEq)]
pub struct RollbackSnapshot {
    settings: PhysicsSettings,
    gravity: Option<Gravity>,
    audit: Option<EnergyAudit>,
    cursor: StageCursor,
    half_drifted: HalfDrifted,
    ledger: Option<LedgerState>,
    bodies: Vec<BodyRecord>,
    /// The quarantined bodies' reasons (rare, so kept out of the records).
    rejections: Vec<(Entity, Rejected)>,
    constant_forces: Vec<(Entity, ConstantForce)>,
    constant_local_forces: Vec<(Entity, ConstantLocalForce)>,
    constant_torques: Vec<(Entity, ConstantTorque)>,
    springs: Vec<(Entity, Spring)>,
}

/// A restore that would not give back the captured world. Nothing is written when it is
/// returned.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Error)]
pub enum RollbackError {
    /// Bodies were spawned or despawned since the capture.
    #[error(
        "the world has {found} rigid bodies and the snapshot {saved}: a rollback restores \
         state, not entities (respawn or despawn bodies in the game's own rollback)"
    )]
    BodyCountChanged {
        /// Bodies in the snapshot.
        saved: usize,
        /// Bodies in the world.
        found: usize,
    },
    /// A captured body is gone (despawned, or no longer a [`RigidBody`]).
    #[error("body {0} of the snapshot is not a rigid body of this world")]
    MissingBody(Entity),
    /// Force generators of one kind were added or removed since the capture.
    #[error("the world has {found} {kind} generators and the snapshot {saved}")]
    GeneratorCountChanged {
        /// `ConstantForce`, `ConstantTorque` or `Spring`.
        kind: &'static str,
        /// Generators of that kind in the snapshot.
        saved: usize,
        /// Generators of that kind in the world.
        found: usize,
    },
    /// A captured generator is gone.
    #[error("{kind} generator {entity} of the snapshot is not in this world")]
    MissingGenerator {
        /// `ConstantForce`, `ConstantTorque` or `Spring`.
        kind: &'static str,
        /// The generator.
        entity: Entity,
    },
}

/// The body query of capture and restore: the always-present parts by reference, the optional
/// ones as options, the markers as flags.
type BodyParts<T, V, A, H, G, D> = (
    Entity,
    T,
    V,
    &'static MassProps,
    Option<A>,
    Option<H>,
    Option<G>,
    Option<D>,
    Has<Static>,
    Has<Kinematic>,
    Has<Rejected>,
);

/// One body of the restore's query.
type BodyItem<'a> = (
    Entity,
    Mut<'a, Pose>,
    Mut<'a, Velocity>,
    &'a MassProps,
    Option<Mut<'a, ForceAccumulator>>,
    Option<Mut<'a, HeldLoad>>,
    Option<Mut<'a, GravityScale>>,
    Option<Mut<'a, Damping>>,
    bool,
    bool,
    bool,
);

impl RollbackSnapshot {
    /// Captures `world` (see the module docs).
    pub fn capture(world: &mut World) -> Self {
        let mut snapshot = Self::default();
        snapshot.capture_into(world);
        snapshot
    }

    /// Captures `world` into `self`, reusing its record buffers (the body and generator
    /// queries are still built afresh on each call, a few small allocations).
    pub fn capture_into(&mut self, world: &mut World) {
        crate::components::assume_missing_masses(world);
        self.settings = world
            .get_resource::<PhysicsSettings>()
            .copied()
            .unwrap_or_default();
        self.gravity = world.get_resource::<Gravity>().copied();
        self.audit = world.get_resource::<EnergyAudit>().copied();
        self.cursor = world
            .get_resource::<StageCursor>()
            .copied()
            .unwrap_or_default();
        self.half_drifted = world
            .get_resource::<HalfDrifted>()
            .copied()
            .unwrap_or_default();
        match (world.get_resource::<EnergyLedger>(), &mut self.ledger) {
            (Some(ledger), Some(state)) => ledger.save_state(state),
            (Some(ledger), slot @ None) => {
                let mut state = LedgerState::default();
                ledger.save_state(&mut state);
                *slot = Some(state);
            }
            (None, slot) => *slot = None,
        }
        self.bodies.clear();
        self.rejections.clear();
        let mut query = world.query_filtered::<BodyParts<
            &'static Pose,
            &'static Velocity,
            &'static ForceAccumulator,
            &'static HeldLoad,
            &'static GravityScale,
            &'static Damping,
        >, With<RigidBody>>();
        for (entity, t, v, m, acc, held, scale, damping, fixed, kinematic, rejected) in
            query.iter(world)
        {
            self.bodies.push(BodyRecord::new(
                entity,
                (t, v, m),
                (acc, held, scale, damping),
                (fixed, kinematic, rejected),
            ));
        }
        for record in &self.bodies {
            if record.parts.contains(Parts::REJECTED)
                && let Some(reason) = world.get::<Rejected>(record.entity)
            {
                self.rejections.push((record.entity, reason.clone()));
            }
        }
        save_generators(world, &mut self.constant_forces);
        save_generators(world, &mut self.constant_local_forces);
        save_generators(world, &mut self.constant_torques);
        save_generators(world, &mut self.springs);
    }

    /// Writes the captured state back into `world`, in place. Fails, writing nothing, when the
    /// world's bodies or generators are not the captured ones.
    pub fn restore(&self, world: &mut World) -> Result<(), RollbackError> {
        self.check(world)?;
        put(world, Some(self.settings));
        put(world, self.gravity);
        put(world, self.audit);
        put(world, Some(self.cursor));
        put(world, Some(self.half_drifted));
        let empty = LedgerState::default();
        let ledger = self.ledger.as_ref().unwrap_or(&empty);
        if self.ledger.is_some() || world.contains_resource::<EnergyLedger>() {
            world
                .get_resource_or_init::<EnergyLedger>()
                .load_state(ledger);
        }
        let structural = self.restore_bodies(world);
        for record in structural {
            self.restore_parts(world, record);
        }
        restore_generators(world, &self.constant_forces);
        restore_generators(world, &self.constant_local_forces);
        restore_generators(world, &self.constant_torques);
        restore_generators(world, &self.springs);
        world.flush();
        Ok(())
    }

    /// The captured bodies, in the world's iteration order at the capture.
    pub fn bodies(&self) -> &[BodyRecord] {
        &self.bodies
    }

    /// Bytes the snapshot holds, on the stack and the heap (buffers at their capacity).
    pub fn bytes(&self) -> usize {
        std::mem::size_of::<Self>()
            + self.bodies.capacity() * std::mem::size_of::<BodyRecord>()
            + self.rejections.capacity() * std::mem::size_of::<(Entity, Rejected)>()
            + self.constant_forces.capacity() * std::mem::size_of::<(Entity, ConstantForce)>()
            + self.constant_local_forces.capacity()
                * std::mem::size_of::<(Entity, ConstantLocalForce)>()
            + self.constant_torques.capacity() * std::mem::size_of::<(Entity, ConstantTorque)>()
            + self.springs.capacity() * std::mem::size_of::<(Entity, Spring)>()
            + self.ledger.as_ref().map_or(0, LedgerState::heap_bytes)
    }

    /// Whether `world` holds exactly the captured bodies and generators.
    fn check(&self, world: &mut World) -> Result<(), RollbackError> {
        let found = world
            .query_filtered::<(), With<RigidBody>>()
            .iter(world)
            .count();
        if found != self.bodies.len() {
            return Err(RollbackError::BodyCountChanged {
                saved: self.bodies.len(),
                found,
            });
        }
        for record in &self.bodies {
            if !world
                .get_entity(record.entity)
                .is_ok_and(|e| e.contains::<RigidBody>())
            {
                return Err(RollbackError::MissingBody(record.entity));
            }
        }
        check_generators(world, "ConstantForce", &self.constant_forces)?;
        check_generators(world, "ConstantLocalForce", &self.constant_local_forces)?;
        check_generators(world, "ConstantTorque", &self.constant_torques)?;
        check_generators(world, "Spring", &self.springs)
    }

    /// Writes every body's values in one pass (by iteration order when the layout is the
    /// captured one, else by entity) and returns the records whose components must be inserted
    /// or removed.
    fn restore_bodies(&self, world: &mut World) -> Vec<&BodyRecord> {
        let mut query = world.query_filtered::<BodyParts<
            &'static mut Pose,
            &'static mut Velocity,
            &'static mut ForceAccumulator,
            &'static mut HeldLoad,
            &'static mut GravityScale,
            &'static mut Damping,
        >, With<RigidBody>>();
        let mut structural = Vec::new();
        let mut in_order = true;
        let mut items = query.iter_mut(world);
        for record in &self.bodies {
            match items.next() {
                Some(item) if item.0 == record.entity => {
                    if write_body(record, item) {
                        structural.push(record);
                    }
                }
                _ => {
                    in_order = false;
                    break;
                }
            }
        }
        if !in_order {
            structural.clear();
            for record in &self.bodies {
                let item = query
                    .get_mut(world, record.entity)
                    .expect("checked: every captured body is a rigid body");
                if write_body(record, item) {
                    structural.push(record);
                }
            }
        }
        structural
    }

    /// Inserts or removes the components of `record`'s body that differ from the capture. The
    /// quarantine goes last: the insertion hooks re-check (and may release) a body.
    fn restore_parts(&self, world: &mut World, record: &BodyRecord) {
        let parts = record.parts;
        let mut body = world.entity_mut(record.entity);
        if body.get::<MassProps>() != Some(&record.mass) {
            body.insert(record.mass);
        }
        toggle(
            &mut body,
            parts.contains(Parts::ACCUMULATOR),
            record.accumulator,
        );
        toggle(&mut body, parts.contains(Parts::HELD_LOAD), record.held);
        toggle(
            &mut body,
            parts.contains(Parts::GRAVITY_SCALE),
            GravityScale(record.gravity_scale),
        );
        toggle(&mut body, parts.contains(Parts::DAMPING), record.damping);
        toggle(&mut body, parts.contains(Parts::STATIC), Static);
        toggle(&mut body, parts.contains(Parts::KINEMATIC), Kinematic);
        world.flush();
        let mut body = world.entity_mut(record.entity);
        if parts.contains(Parts::REJECTED) {
            let reason = self
                .rejections
                .iter()
                .find(|(e, _)| *e == record.entity)
                .map(|(_, r)| r.clone());
            if let Some(reason) = reason {
                body.insert(reason);
            }
        } else {
            body.remove::<Rejected>();
        }
    }
}

/// Writes `record` into a body's components; true when a component must be inserted or removed
/// (an optional part, a marker or the mass properties differ from the capture).
fn write_body(
    record: &BodyRecord,
    (_, mut t, mut v, m, acc, held, scale, damping, fixed, kinematic, rejected): BodyItem<'_>,
) -> bool {
    // Whole, so that a part added to the record cannot be left out here.
    let BodyRecord {
        entity: _,
        transform,
        velocity,
        mass,
        accumulator,
        held: held_load,
        gravity_scale,
        damping: body_damping,
        parts,
    } = *record;
    *t = transform;
    *v = velocity;
    let mut structural = *m != mass
        || fixed != parts.contains(Parts::STATIC)
        || kinematic != parts.contains(Parts::KINEMATIC)
        || rejected != parts.contains(Parts::REJECTED);
    structural |= write_part(acc, parts.contains(Parts::ACCUMULATOR), accumulator);
    structural |= write_part(held, parts.contains(Parts::HELD_LOAD), held_load);
    structural |= write_part(
        scale,
        parts.contains(Parts::GRAVITY_SCALE),
        GravityScale(gravity_scale),
    );
    structural |= write_part(damping, parts.contains(Parts::DAMPING), body_damping);
    structural
}

/// Writes an optional part the body has and had; true when it has it and had not, or the
/// other way round.
fn write_part<C: Component + Copy>(now: Option<Mut<C>>, had: bool, value: C) -> bool {
    match now {
        Some(mut c) if had => {
            *c = value;
            false
        }
        Some(_) => true,
        None => had,
    }
}

/// Inserts `value` if the body should have it and does not, removes it if it should not.
fn toggle<C: Component>(body: &mut EntityWorldMut, had: bool, value: C) {
    match (had, body.contains::<C>()) {
        (true, false) => {
            body.insert(value);
        }
        (false, true) => {
            body.remove::<C>();
        }
        _ => {}
    }
}

/// Inserts a resource whose value differs, removes one the snapshot did not have (so that a
/// restore that changes nothing triggers no change detection and no re-plan).
fn put<R: Resource + Copy + PartialEq>(world: &mut World, saved: Option<R>) {
    match saved {
        Some(value) => {
            if world.get_resource::<R>() != Some(&value) {
                world.insert_resource(value);
            }
        }
        None => {
            world.remove_resource::<R>();
        }
    }
}

fn save_generators<C: Component + Copy>(world: &mut World, out: &mut Vec<(Entity, C)>) {
    out.clear();
    let mut query = world.query::<(Entity, &C)>();
    out.extend(query.iter(world).map(|(e, c)| (e, *c)));
}

fn check_generators<C: Component>(
    world: &mut World,
    kind: &'static str,
    saved: &[(Entity, C)],
) -> Result<(), RollbackError> {
    let found = world.query::<&C>().iter(world).count();
    if found != saved.len() {
        return Err(RollbackError::GeneratorCountChanged {
            kind,
            saved: saved.len(),
            found,
        });
    }
    for (entity, _) in saved {
        if !world.get_entity(*entity).is_ok_and(|e| e.contains::<C>()) {
            return Err(RollbackError::MissingGenerator {
                kind,
                entity: *entity,
            });
        }
    }
    Ok(())
}

/// Writes back the generators that changed (unchanged ones are not touched, so their change
/// ticks stay).
fn restore_generators<C: Component<Mutability = Mutable> + Copy + PartialEq>(
    world: &mut World,
    saved: &[(Entity, C)],
) {
    let mut query = world.query::<&mut C>();
    for (entity, value) in saved {
        let mut current = query
            .get_mut(world, *entity)
            .expect("checked: every captured generator is in the world");
        current.set_if_neq(*value);
    }
}
