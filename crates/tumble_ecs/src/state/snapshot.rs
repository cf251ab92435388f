//! `Snapshot`: every physics component and resource, for serde.

use std::collections::HashMap;

use bevy_ecs::prelude::*;
use serde::{Deserialize, Serialize};
use thiserror::Error;

use crate::audit::{EnergyLedger, SavedAccount};
use crate::components::{BodyError, BodyErrorKind, PhysicsErrors, Rejected};
use crate::components::{ConstantForce, ConstantLocalForce, ConstantTorque, Spring, SpringEnd};
use crate::components::{
    Damping, ForceAccumulator, Gravity, GravityScale, HeldLoad, Kinematic, MassProps,
    PhysicsSettings, Pose, RigidBody, Static, Velocity,
};
use crate::integrate::HalfDrifted;

use super::record::{BodyRecord, Parts};
use crate::parallel::Parallelism;

/// How tumble treats a body.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum BodyKind {
    /// Integrated.
    Dynamic,
    /// [`Static`]: never moves.
    Static,
    /// [`Kinematic`]: moved by game code.
    Kinematic,
}

/// One rigid body as saved.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BodySnapshot {
    /// The entity in the saved world (generators refer to bodies by it).
    pub entity: Entity,
    /// How tumble treats it.
    pub kind: BodyKind,
    /// Pose.
    pub transform: Pose,
    /// Velocity.
    pub velocity: Velocity,
    /// Mass properties.
    pub mass: MassProps,
    /// Pending forces, if the body has an accumulator.
    pub accumulator: Option<ForceAccumulator>,
    /// The load held over a step of several stages, if the body has an accumulator (absent in
    /// snapshots saved before it was saved; between steps it only matters to a snapshot taken
    /// mid-step).
    #[serde(default)]
    pub held: Option<HeldLoad>,
    /// Gravity scale, if set.
    pub gravity_scale: Option<GravityScale>,
    /// Damping, if set.
    pub damping: Option<Damping>,
    /// Why the body is quarantined, if it is.
    pub rejected: Option<String>,
}

impl BodySnapshot {
    /// The saved form of `record`, with the quarantine's reason `rejected`.
    fn of(record: &BodyRecord, rejected: Option<&Rejected>) -> Self {
        let BodyRecord {
            entity,
            transform,
            velocity,
            mass,
            accumulator,
            held,
            gravity_scale,
            damping,
            parts,
        } = *record;
        let kind = if parts.contains(Parts::STATIC) {
            BodyKind::Static
        } else if parts.contains(Parts::KINEMATIC) {
            BodyKind::Kinematic
        } else {
            BodyKind::Dynamic
        };
        Self {
            entity,
            kind,
            transform,
            velocity,
            mass,
            accumulator: record.part(Parts::ACCUMULATOR, accumulator),
            held: record.part(Parts::HELD_LOAD, held),
            gravity_scale: record.part(Parts::GRAVITY_SCALE, GravityScale(gravity_scale)),
            damping: record.part(Parts::DAMPING, damping),
            rejected: rejected.map(|r| r.0.kind.to_string()),
        }
    }
}

/// Every physics component and resource of a world.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Snapshot {
    /// Format version.
    pub version: u32,
    /// Time step and integrator.
    pub settings: PhysicsSettings,
    /// Gravity, if the world has it.
    pub gravity: Option<Gravity>,
    /// Threading policy, if set.
    pub parallelism: Option<Parallelism>,
    /// Whether a drift–kick–drift step is half done (false between steps).
    pub half_drifted: bool,
    /// Bodies, in the world's iteration order.
    pub bodies: Vec<BodySnapshot>,
    /// Constant forces, in iteration order (their `body` is a saved entity).
    pub constant_forces: Vec<ConstantForce>,
    /// Body-frame constant forces, in iteration order (absent in snapshots saved before they
    /// existed).
    #[serde(default)]
    pub constant_local_forces: Vec<ConstantLocalForce>,
    /// Constant torques, in iteration order.
    pub constant_torques: Vec<ConstantTorque>,
    /// Springs, in iteration order.
    pub springs: Vec<Spring>,
    /// The error log, as messages.
    pub errors: Vec<String>,
    /// The energy audit's running accounts (their `member` is a saved entity): a resumed world
    /// quarantines a diverging group at the same step as the world it was saved from.
    #[serde(default)]
    pub energy_accounts: Vec<SavedAccount>,
}

/// A snapshot that cannot be restored.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum SnapshotError {
    /// The format version is not one this build reads.
    #[error("snapshot version {0} is not supported (this build reads version {SNAPSHOT_VERSION})")]
    Version(u32),
    /// A generator names a body that is not in the snapshot.
    #[error("a force generator names entity {0}, which is not a body of the snapshot")]
    UnknownBody(Entity),
    /// Two bodies were saved under the same entity.
    #[error("entity {0} appears twice among the bodies")]
    DuplicateBody(Entity),
}

/// The snapshot format this build writes and reads.
pub const SNAPSHOT_VERSION: u32 = 1;

impl Snapshot {
    /// Captures every physics component and resource of `world`.
    pub fn capture(world: &mut World) -> Self {
        crate::components::assume_missing_masses(world);
        let mut bodies = Vec::new();
        let mut query = world.query_filtered::<(
            Entity,
            (&Pose, &Velocity, &MassProps),
            (
                Option<&ForceAccumulator>,
                Option<&HeldLoad>,
                Option<&GravityScale>,
                Option<&Damping>,
            ),
            (Has<Static>, Has<Kinematic>, Option<&Rejected>),
        ), With<RigidBody>>();
        for (entity, required, optional, (fixed, kinematic, rejected)) in query.iter(world) {
            let record = BodyRecord::new(
                entity,
                required,
                optional,
                (fixed, kinematic, rejected.is_some()),
            );
            bodies.push(BodySnapshot::of(&record, rejected));
        }
        Self {
            version: SNAPSHOT_VERSION,
            settings: world
                .get_resource::<PhysicsSettings>()
                .copied()
                .unwrap_or_default(),
            gravity: world.get_resource::<Gravity>().copied(),
            parallelism: world.get_resource::<Parallelism>().copied(),
            half_drifted: world.get_resource::<HalfDrifted>().is_some_and(|h| h.0),
            bodies,
            constant_forces: all::<ConstantForce>(world),
            constant_local_forces: all::<ConstantLocalForce>(world),
            constant_torques: all::<ConstantTorque>(world),
            springs: all::<Spring>(world),
            errors: world
                .get_resource::<PhysicsErrors>()
                .map(|e| e.bodies.iter().map(ToString::to_string).collect())
                .unwrap_or_default(),
            energy_accounts: world
                .get_resource::<EnergyLedger>()
                .map(EnergyLedger::saved_accounts)
                .unwrap_or_default(),
        }
    }

    /// Spawns the snapshot into `world` (normally a new one) and inserts its resources; returns
    /// the map from saved to new entities. Plan the schedule afterwards, as for any world.
    pub fn restore(&self, world: &mut World) -> Result<HashMap<Entity, Entity>, SnapshotError> {
        let mut map = self.check_references()?;
        world.insert_resource(self.settings);
        match self.gravity {
            Some(g) => world.insert_resource(g),
            None => {
                world.remove_resource::<Gravity>();
            }
        }
        if let Some(p) = self.parallelism {
            world.insert_resource(p);
        }
        world.insert_resource(HalfDrifted(self.half_drifted));
        for b in &self.bodies {
            let id = spawn_body(world, b);
            map.insert(b.entity, id);
        }
        self.spawn_generators(world, &map);
        // Accumulators were inserted by the generators' hooks where missing; put back the saved
        // values (a snapshot between steps holds zeros or what game code added).
        // Written in place, not inserted: an insert re-runs the body check, and valid data
        // lifts a quarantine, which must survive the round trip.
        world.flush();
        for b in &self.bodies {
            if let Some(acc) = b.accumulator {
                let id = map[&b.entity];
                match world.get_mut::<ForceAccumulator>(id) {
                    Some(mut slot) => *slot = acc,
                    None => {
                        world.entity_mut(id).insert(acc);
                    }
                }
            }
        }
        let accounts: Vec<SavedAccount> = self
            .energy_accounts
            .iter()
            .filter_map(|a| {
                map.get(&a.member)
                    .map(|&member| SavedAccount { member, ..*a })
            })
            .collect();
        world
            .get_resource_or_init::<EnergyLedger>()
            .restore_accounts(accounts);
        if !self.errors.is_empty() {
            let errors = self
                .errors
                .iter()
                .map(|message| BodyError {
                    entity: Entity::PLACEHOLDER,
                    kind: BodyErrorKind::Restored(message.clone()),
                })
                .collect();
            world.insert_resource(PhysicsErrors {
                bodies: errors,
                ..PhysicsErrors::default()
            });
        }
        Ok(map)
    }

    /// The saved bodies, each mapped to a placeholder, after checking the version, that no body
    /// is saved twice and that every generator names a saved body.
    fn check_references(&self) -> Result<HashMap<Entity, Entity>, SnapshotError> {
        if self.version != SNAPSHOT_VERSION {
            return Err(SnapshotError::Version(self.version));
        }
        let mut map = HashMap::with_capacity(self.bodies.len());
        for b in &self.bodies {
            if map.insert(b.entity, Entity::PLACEHOLDER).is_some() {
                return Err(SnapshotError::DuplicateBody(b.entity));
            }
        }
        let body = |saved: Entity| {
            map.get(&saved)
                .copied()
                .ok_or(SnapshotError::UnknownBody(saved))
        };
        for generator in &self.springs {
            body(generator.a)?;
            if let SpringEnd::Body { body: b, .. } = generator.b {
                body(b)?;
            }
        }
        for f in &self.constant_forces {
            body(f.body)?;
        }
        for f in &self.constant_local_forces {
            body(f.body)?;
        }
        for t in &self.constant_torques {
            body(t.body)?;
        }
        Ok(map)
    }

    /// Spawns the saved force generators, their bodies renamed by `map` (saved → spawned).
    fn spawn_generators(&self, world: &mut World, map: &HashMap<Entity, Entity>) {
        let remap = |saved: Entity| map[&saved];
        for f in &self.constant_forces {
            world.spawn(ConstantForce {
                body: remap(f.body),
                ..*f
            });
        }
        for f in &self.constant_local_forces {
            world.spawn(ConstantLocalForce {
                body: remap(f.body),
                ..*f
            });
        }
        for t in &self.constant_torques {
            world.spawn(ConstantTorque {
                body: remap(t.body),
                ..*t
            });
        }
        for s in &self.springs {
            let b = match s.b {
                SpringEnd::Body { body, anchor } => SpringEnd::Body {
                    body: remap(body),
                    anchor,
                },
                end => end,
            };
            world.spawn(Spring {
                a: remap(s.a),
                b,
                ..*s
            });
        }
    }
}

/// Every `C` in iteration order.
fn all<C: Component + Copy>(world: &mut World) -> Vec<C> {
    world.query::<&C>().iter(world).copied().collect()
}

/// Spawns one saved body with its components, quarantined again if it was.
fn spawn_body(world: &mut World, b: &BodySnapshot) -> Entity {
    let mut e = world.spawn((RigidBody, b.mass, b.transform, b.velocity));
    if let Some(acc) = b.accumulator {
        e.insert(acc);
    }
    if let Some(held) = b.held {
        e.insert(held);
    }
    if let Some(s) = b.gravity_scale {
        e.insert(s);
    }
    if let Some(d) = b.damping {
        e.insert(d);
    }
    match b.kind {
        BodyKind::Dynamic => {}
        BodyKind::Static => {
            e.insert(Static);
        }
        BodyKind::Kinematic => {
            e.insert(Kinematic);
        }
    }
    let id = e.id();
    if let Some(reason) = &b.rejected {
        let error = BodyError {
            entity: id,
            kind: BodyErrorKind::Restored(reason.clone()),
        };
        world.entity_mut(id).insert(Rejected(error));
    }
    id
}
