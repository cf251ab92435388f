//! Force generators are checked, never trusted: their values when they are inserted and whenever
//! game code changes them, their bodies when they are inserted and whenever a body goes away.
//!
//! A generator that fails a check is left out of the step: its generator component is removed
//! (so no system, plan or audit sees it), a [`RejectedGenerator`] marker names why, the error is
//! logged with `tracing` and recorded once in [`PhysicsErrors`]. Inserting a valid generator on
//! the entity again lifts the marker. The checks never blame a body for its generator's values.
//!
//! When each check runs:
//! - on insert, a component hook checks the values, that a spring does not join a body to
//!   itself and that every body it names exists;
//! - before every step, [`PhysicsRunner`](crate::runner::PhysicsRunner) checks the values of
//!   every generator changed since the last change-tracker clear, and, if bodies were removed
//!   or despawned since the last step, which generators named them.

use bevy_ecs::lifecycle::HookContext;
use bevy_ecs::prelude::*;
use bevy_ecs::world::{DeferredWorld, WorldId};
use thiserror::Error;
use tumble_core::math::{Real, Vec3};

use crate::forces::{ConstantForce, ConstantLocalForce, ConstantTorque, Spring, SpringEnd};
use crate::validate::PhysicsErrors;

/// What is wrong with a force generator.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum GeneratorErrorKind {
    /// A value that must be finite is NaN or infinite.
    #[error("{field} is not finite ({value})")]
    NonFinite {
        /// The field, e.g. `"stiffness"`.
        field: &'static str,
        /// The offending value, formatted.
        value: String,
    },
    /// A value that must be `>= 0` is negative.
    #[error("{field} must be >= 0, got {value}")]
    Negative {
        /// The field, e.g. `"rest_length"`.
        field: &'static str,
        /// The offending value.
        value: Real,
    },
    /// A spring whose two ends are on the same body.
    #[error("both ends are on body {0}: a spring joins two bodies, or a body and a world point")]
    SelfSpring(Entity),
    /// A body the generator names does not exist (never did, or was despawned), or is no
    /// longer a rigid body.
    #[error("its body {body} (field `{field}`) does not exist or is not a rigid body")]
    MissingBody {
        /// The field naming the body: `"body"`, `"a"` or `"b"`.
        field: &'static str,
        /// The missing body.
        body: Entity,
    },
}

/// A force generator left out of the step, naming the generator's entity and type.
#[derive(Debug, Clone, PartialEq, Error)]
#[error("{generator} {entity}: {kind}; the generator is left out of the step")]
pub struct GeneratorError {
    /// The generator's entity.
    pub entity: Entity,
    /// The generator's type: `"Spring"`, `"ConstantForce"`, `"ConstantLocalForce"` or
    /// `"ConstantTorque"`.
    pub generator: &'static str,
    /// What is wrong.
    pub kind: GeneratorErrorKind,
}

/// Marks an entity whose force generator was left out of the step (its generator component was
/// removed), with the reason. Inserting a valid generator lifts it.
#[derive(Component, Debug, Clone, PartialEq)]
pub struct RejectedGenerator(pub GeneratorError);

/// A force generator's checks.
pub(crate) trait Generator: Component + Copy {
    /// The type's name, as errors print it.
    const NAME: &'static str;

    /// Checks the values (finite, non-negative where the docs say so, distinct ends).
    fn check_values(&self) -> Result<(), GeneratorErrorKind>;

    /// The bodies the generator names, with the field that names each.
    fn bodies(&self) -> impl Iterator<Item = (&'static str, Entity)>;
}

fn finite(field: &'static str, value: Real) -> Result<(), GeneratorErrorKind> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(GeneratorErrorKind::NonFinite {
            field,
            value: value.to_string(),
        })
    }
}

fn finite_vec3(field: &'static str, value: Vec3) -> Result<(), GeneratorErrorKind> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(GeneratorErrorKind::NonFinite {
            field,
            value: value.to_string(),
        })
    }
}

fn non_negative(field: &'static str, value: Real) -> Result<(), GeneratorErrorKind> {
    finite(field, value)?;
    if value >= 0.0 {
        Ok(())
    } else {
        Err(GeneratorErrorKind::Negative { field, value })
    }
}

/// The values of a force through an optional body point (world or body frame alike).
fn force_at_point(force: Vec3, local_point: Option<Vec3>) -> Result<(), GeneratorErrorKind> {
    finite_vec3("force", force)?;
    match local_point {
        Some(p) => finite_vec3("local_point", p),
        None => Ok(()),
    }
}

impl Generator for ConstantForce {
    const NAME: &'static str = "ConstantForce";

    fn check_values(&self) -> Result<(), GeneratorErrorKind> {
        force_at_point(self.force, self.local_point)
    }

    fn bodies(&self) -> impl Iterator<Item = (&'static str, Entity)> {
        std::iter::once(("body", self.body))
    }
}

impl Generator for ConstantLocalForce {
    const NAME: &'static str = "ConstantLocalForce";

    fn check_values(&self) -> Result<(), GeneratorErrorKind> {
        force_at_point(self.force, self.local_point)
    }

    fn bodies(&self) -> impl Iterator<Item = (&'static str, Entity)> {
        std::iter::once(("body", self.body))
    }
}

impl Generator for ConstantTorque {
    const NAME: &'static str = "ConstantTorque";

    fn check_values(&self) -> Result<(), GeneratorErrorKind> {
        finite_vec3("torque", self.torque)
    }

    fn bodies(&self) -> impl Iterator<Item = (&'static str, Entity)> {
        std::iter::once(("body", self.body))
    }
}

impl Generator for Spring {
    const NAME: &'static str = "Spring";

    fn check_values(&self) -> Result<(), GeneratorErrorKind> {
        finite_vec3("anchor_a", self.anchor_a)?;
        match self.b {
            SpringEnd::World(p) => finite_vec3("b", p)?,
            SpringEnd::Body { body, anchor } => {
                finite_vec3("b.anchor", anchor)?;
                if body == self.a {
                    return Err(GeneratorErrorKind::SelfSpring(body));
                }
            }
        }
        non_negative("stiffness", self.stiffness)?;
        non_negative("damping", self.damping)?;
        non_negative("rest_length", self.rest_length)
    }

    fn bodies(&self) -> impl Iterator<Item = (&'static str, Entity)> {
        let b = match self.b {
            SpringEnd::Body { body, .. } => Some(("b", body)),
            SpringEnd::World(_) => None,
        };
        std::iter::once(("a", self.a)).chain(b)
    }
}

/// The generator `g` of `entity` checked as on insert: values, then that its bodies exist
/// (`exists`).
fn check_inserted<G: Generator>(
    g: &G,
    exists: impl Fn(Entity) -> bool,
) -> Result<(), GeneratorErrorKind> {
    g.check_values()?;
    for (field, body) in g.bodies() {
        if !exists(body) {
            return Err(GeneratorErrorKind::MissingBody { field, body });
        }
    }
    Ok(())
}

/// Component hook of every generator: checks it, and either leaves it out of the step or
/// (valid) lifts an earlier rejection and gives its bodies accumulators.
pub(crate) fn generator_inserted<G: Generator>(mut world: DeferredWorld, ctx: HookContext) {
    let entity = ctx.entity;
    let Some(g) = world.get::<G>(entity).copied() else {
        return;
    };
    let result = check_inserted(&g, |body| world.get_entity(body).is_ok());
    let rejected = world.get::<RejectedGenerator>(entity).is_some();
    let mut commands = world.commands();
    match result {
        Err(kind) => {
            let error = GeneratorError {
                entity,
                generator: G::NAME,
                kind,
            };
            commands.queue(move |world: &mut World| reject_generator::<G>(world, error));
        }
        Ok(()) => {
            if rejected {
                commands.entity(entity).remove::<RejectedGenerator>();
            }
            crate::forces::ensure_accumulators(&mut commands, g.bodies().map(|(_, b)| b));
        }
    }
}

/// Leaves the generator `G` of `error.entity` out of the step: removes it, marks the entity,
/// logs the error and records it once.
fn reject_generator<G: Generator>(world: &mut World, error: GeneratorError) {
    let Ok(mut entity) = world.get_entity_mut(error.entity) else {
        return;
    };
    if entity.get::<G>().is_none() {
        return; // already left out (or replaced) since the check
    }
    entity.remove::<G>();
    entity.insert(RejectedGenerator(error.clone()));
    tracing::warn!(entity = %error.entity, "{error}");
    world
        .get_resource_or_init::<PhysicsErrors>()
        .generators
        .push(error);
}

/// Bodies that lost their [`RigidBody`](crate::components::RigidBody) marker (removed or
/// despawned) since the runner last looked: their generators are left out before the next step.
#[derive(Resource, Debug, Default)]
pub(crate) struct RemovedBodies(Vec<Entity>);

/// Component hook of [`RigidBody`](crate::components::RigidBody): remembers the body for the
/// runner's next check.
pub(crate) fn body_removed(mut world: DeferredWorld, ctx: HookContext) {
    let entity = ctx.entity;
    world.commands().queue(move |world: &mut World| {
        world.get_resource_or_init::<RemovedBodies>().0.push(entity);
    });
}

/// A query of the generators of type `G` changed since the world's last change-tracker clear,
/// with the world it was built for.
type ChangedQuery<G> = (WorldId, QueryState<(Entity, &'static G), Changed<G>>);

/// The runner's checks of the generators before each step (see the module docs). Keeps its
/// queries between steps, so checking allocates nothing in a world whose generators are valid.
#[derive(Default)]
pub(crate) struct GeneratorWatch {
    forces: Option<ChangedQuery<ConstantForce>>,
    local_forces: Option<ChangedQuery<ConstantLocalForce>>,
    torques: Option<ChangedQuery<ConstantTorque>>,
    springs: Option<ChangedQuery<Spring>>,
}

impl GeneratorWatch {
    /// Leaves out every generator whose values turned bad since the last check, or whose body
    /// went away.
    pub(crate) fn check(&mut self, world: &mut World) {
        let removed = world
            .get_resource_mut::<RemovedBodies>()
            .map(|mut r| std::mem::take(&mut r.0))
            .unwrap_or_default();
        let orphans = if removed.is_empty() {
            None
        } else {
            let removed: bevy_ecs::entity::EntityHashSet = removed
                .into_iter()
                .filter(|&e| {
                    !world
                        .get_entity(e)
                        .is_ok_and(|e| e.contains::<crate::components::RigidBody>())
                })
                .collect();
            Some(removed)
        };
        let mut errors = Vec::new();
        check_changed(&mut self.forces, world, orphans.as_ref(), &mut errors);
        check_changed(&mut self.local_forces, world, orphans.as_ref(), &mut errors);
        check_changed(&mut self.torques, world, orphans.as_ref(), &mut errors);
        check_changed(&mut self.springs, world, orphans.as_ref(), &mut errors);
        for (reject, error) in errors {
            reject(world, error);
        }
    }
}

/// A generator to leave out, with the function that does it for its type.
type Rejection = (fn(&mut World, GeneratorError), GeneratorError);

/// Checks the generators of type `G`: the changed ones' values, and, when bodies went away
/// (`orphans`), every one's bodies.
fn check_changed<G: Generator>(
    query: &mut Option<ChangedQuery<G>>,
    world: &World,
    orphans: Option<&bevy_ecs::entity::EntityHashSet>,
    errors: &mut Vec<Rejection>,
) {
    if query.as_ref().is_none_or(|(id, _)| *id != world.id()) {
        *query = world
            .try_query_filtered::<(Entity, &G), Changed<G>>()
            .map(|q| (world.id(), q));
    }
    let Some((_, query)) = query.as_mut() else {
        return;
    };
    let mut push = |entity, kind| {
        let error = GeneratorError {
            entity,
            generator: G::NAME,
            kind,
        };
        errors.push((
            reject_generator::<G> as fn(&mut World, GeneratorError),
            error,
        ));
    };
    for (entity, g) in query.iter(world) {
        if let Err(kind) = g.check_values() {
            push(entity, kind);
        }
    }
    let Some(orphans) = orphans else {
        return;
    };
    let mut all = world.try_query::<(Entity, &G)>().expect("registered above");
    for (entity, g) in all.iter(world) {
        if let Some((field, body)) = g.bodies().find(|(_, b)| orphans.contains(b)) {
            push(entity, GeneratorErrorKind::MissingBody { field, body });
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spring() -> Spring {
        Spring::new(
            Entity::from_raw_u32(1).unwrap(),
            Vec3::ZERO,
            SpringEnd::World(Vec3::X),
            10.0,
            0.5,
        )
    }

    #[test]
    fn each_bad_spring_value_names_its_field() {
        let cases: [(fn(&mut Spring), &str); 6] = [
            (|s| s.stiffness = -1.0, "stiffness"),
            (|s| s.stiffness = Real::NAN, "stiffness"),
            (|s| s.damping = -0.5, "damping"),
            (|s| s.rest_length = Real::INFINITY, "rest_length"),
            (|s| s.anchor_a = Vec3::NAN, "anchor_a"),
            (|s| s.b = SpringEnd::World(Vec3::INFINITY), "b"),
        ];
        for (spoil, field) in cases {
            let mut s = spring();
            assert_eq!(s.check_values(), Ok(()));
            spoil(&mut s);
            match s.check_values() {
                Err(GeneratorErrorKind::NonFinite { field: f, .. })
                | Err(GeneratorErrorKind::Negative { field: f, .. }) => assert_eq!(f, field),
                other => panic!("{field}: {other:?}"),
            }
        }
        let mut s = spring();
        s.b = SpringEnd::on_body(s.a, Vec3::X);
        assert_eq!(s.check_values(), Err(GeneratorErrorKind::SelfSpring(s.a)));
    }
}
