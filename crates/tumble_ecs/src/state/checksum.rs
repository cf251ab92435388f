//! `WorldChecksum`: one hash of everything the next step depends on.

use bevy_ecs::prelude::*;
use tumble_core::integrate::FreeFlow;
use tumble_core::math::{Quat, Real, Vec3};
use xxhash_rust::xxh3::Xxh3;

use crate::components::Rejected;
use crate::components::{ConstantForce, ConstantLocalForce, ConstantTorque, Spring, SpringEnd};
use crate::components::{
    Damping, ForceAccumulator, Gravity, GravityScale, HeldLoad, Kinematic, MassProps,
    PhysicsSettings, Pose, RigidBody, Static, Velocity,
};
use crate::integrate::StageCursor;

use super::record::{BodyRecord, Parts};

/// The checksum of a world's step-affecting state (module docs): print it as 32 hex digits
/// (`{}`), or take the number.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct WorldChecksum(pub u128);

impl std::fmt::Display for WorldChecksum {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{:032x}", self.0)
    }
}

/// The byte stream of the module docs, fed to XXH3.
struct Stream(Xxh3);

impl Stream {
    fn bytes(&mut self, bytes: &[u8]) {
        self.0.update(bytes);
    }

    fn real(&mut self, x: Real) {
        self.bytes(&x.to_bits().to_le_bytes());
    }

    fn vec3(&mut self, v: Vec3) {
        for x in v.to_array() {
            self.real(x);
        }
    }

    fn quat(&mut self, q: Quat) {
        for x in q.to_array() {
            self.real(x);
        }
    }

    fn entity(&mut self, e: Entity) {
        self.bytes(&e.to_bits().to_le_bytes());
    }

    fn flag(&mut self, present: bool) {
        self.bytes(&[u8::from(present)]);
    }

    fn text(&mut self, s: &str) {
        self.bytes(&(s.len() as u64).to_le_bytes());
        self.bytes(s.as_bytes());
    }
}

/// The checksum of `world` (see the module docs). A rigid body counts from when it has
/// [`MassProps`] (a body spawned without one gets it before its first step: see
/// [`assume_missing_masses`](crate::components::assume_missing_masses)).
pub fn world_checksum(world: &World) -> WorldChecksum {
    let mut out = Stream(Xxh3::new());
    out.text("tumble-checksum-1");
    settings(world, &mut out);
    bodies(world, &mut out);
    generators(world, &mut out);
    WorldChecksum(out.0.digest128())
}

fn settings(world: &World, out: &mut Stream) {
    let settings = world.get_resource::<PhysicsSettings>();
    out.flag(settings.is_some());
    if let Some(s) = settings {
        out.real(s.dt());
        out.text(s.integrator.name());
        out.text(s.springs.name());
        out.bytes(&s.substeps().get().to_le_bytes());
        // Only when not the default, so that the checksums of worlds that never set it stay
        // what they were before the setting existed.
        if s.free_flow != FreeFlow::default() {
            out.text(s.free_flow.name());
        }
    }
    let cursor = world
        .get_resource::<StageCursor>()
        .copied()
        .unwrap_or_default();
    out.bytes(&(cursor.index() as u64).to_le_bytes());
    let gravity = world.get_resource::<Gravity>();
    out.flag(gravity.is_some());
    if let Some(g) = gravity {
        out.vec3(g.0);
    }
}

/// Sorted by entity bits, so that archetype and table order (which follow insertion history)
/// do not enter the checksum.
fn sorted<T>(mut items: Vec<(Entity, T)>) -> Vec<(Entity, T)> {
    items.sort_unstable_by_key(|(e, _)| e.to_bits());
    items
}

/// `(entity, item)` of every match of a read-only query, in increasing entity order; empty
/// when a component of the query was never registered (no entity can have it).
fn rows<D, F, T>(world: &World, item: impl Fn(D::Item<'_, '_>) -> (Entity, T)) -> Vec<(Entity, T)>
where
    D: bevy_ecs::query::ReadOnlyQueryData,
    F: bevy_ecs::query::QueryFilter,
{
    let Some(mut query) = world.try_query_filtered::<D, F>() else {
        return Vec::new();
    };
    sorted(query.iter(world).map(item).collect())
}

fn bodies(world: &World, out: &mut Stream) {
    // The optional parts by entity lookup: a query naming a component no entity ever had finds
    // nothing at all (`try_query` needs every component registered).
    let rows = rows::<(Entity, &Pose, &Velocity, &MassProps), With<RigidBody>, _>(
        world,
        |(e, t, v, m)| {
            let entity = world.entity(e);
            let record = BodyRecord::new(
                e,
                (t, v, m),
                (
                    entity.get::<ForceAccumulator>(),
                    entity.get::<HeldLoad>(),
                    entity.get::<GravityScale>(),
                    entity.get::<Damping>(),
                ),
                (
                    entity.contains::<Static>(),
                    entity.contains::<Kinematic>(),
                    entity.contains::<Rejected>(),
                ),
            );
            (e, record)
        },
    );
    out.bytes(&(rows.len() as u64).to_le_bytes());
    for (_, record) in rows {
        body(out, &record);
    }
}

/// One body's bytes: every field of its record, optional parts behind a presence flag.
fn body(out: &mut Stream, record: &BodyRecord) {
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
    out.entity(entity);
    out.vec3(transform.translation);
    out.quat(transform.rotation);
    out.vec3(velocity.linear);
    out.vec3(velocity.angular);
    out.real(mass.mass());
    out.vec3(mass.principal_inertia());
    out.quat(mass.principal_frame());
    out.vec3(mass.local_center_of_mass());
    out.flag(parts.contains(Parts::ACCUMULATOR));
    if parts.contains(Parts::ACCUMULATOR) {
        out.vec3(accumulator.force);
        out.vec3(accumulator.torque);
    }
    out.flag(parts.contains(Parts::HELD_LOAD));
    if parts.contains(Parts::HELD_LOAD) {
        out.vec3(held.force);
        out.vec3(held.torque);
    }
    out.flag(parts.contains(Parts::GRAVITY_SCALE));
    if parts.contains(Parts::GRAVITY_SCALE) {
        out.real(gravity_scale);
    }
    out.flag(parts.contains(Parts::DAMPING));
    if parts.contains(Parts::DAMPING) {
        out.real(damping.linear);
        out.real(damping.angular);
    }
    out.flag(parts.contains(Parts::STATIC));
    out.flag(parts.contains(Parts::KINEMATIC));
    out.flag(parts.contains(Parts::REJECTED));
}

fn generators(world: &World, out: &mut Stream) {
    components::<ConstantForce>(world, out, |out, f| {
        force_at_point(out, f.body, f.force, f.local_point);
    });
    components::<ConstantTorque>(world, out, |out, t| {
        out.entity(t.body);
        out.vec3(t.torque);
    });
    components::<Spring>(world, out, |out, s| {
        out.entity(s.a);
        out.vec3(s.anchor_a);
        match s.b {
            SpringEnd::World(point) => {
                out.flag(false);
                out.vec3(point);
            }
            SpringEnd::Body { body, anchor } => {
                out.flag(true);
                out.entity(body);
                out.vec3(anchor);
            }
        }
        out.real(s.stiffness);
        out.real(s.damping);
        out.real(s.rest_length);
    });
    // Body-frame forces came later: their section is in the stream only when the world has
    // some, behind a name, so that the checksums of worlds without them stay what they were.
    let local = rows::<(Entity, &ConstantLocalForce), (), _>(world, |(e, c)| (e, *c));
    if !local.is_empty() {
        out.text("ConstantLocalForce");
        section(out, local, |out, f| {
            force_at_point(out, f.body, f.force, f.local_point);
        });
    }
}

/// A force generator's fields: its body, its force and its optional point.
fn force_at_point(out: &mut Stream, body: Entity, force: Vec3, point: Option<Vec3>) {
    out.entity(body);
    out.vec3(force);
    out.flag(point.is_some());
    out.vec3(point.unwrap_or(Vec3::ZERO));
}

/// One section of the stream: how many entities hold a `C`, then each (in entity order) as its
/// entity and what `write` writes of its `C`.
fn components<C: Component + Copy>(
    world: &World,
    out: &mut Stream,
    write: impl Fn(&mut Stream, C),
) {
    section(
        out,
        rows::<(Entity, &C), (), _>(world, |(e, c)| (e, *c)),
        write,
    );
}

/// A section of the stream from its rows: their count, then each as its entity and what
/// `write` writes of its value.
fn section<C>(out: &mut Stream, rows: Vec<(Entity, C)>, write: impl Fn(&mut Stream, C)) {
    out.bytes(&(rows.len() as u64).to_le_bytes());
    for (e, c) in rows {
        out.entity(e);
        write(out, c);
    }
}
