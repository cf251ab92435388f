//! Rejection of bad component data: typed errors that name the entity, and a quarantine marker
//! so that one bad body never harms another.
//!
//! Bad data is caught in two places:
//! - **on insert**: a component hook on [`Pose`], [`Velocity`] and [`ForceAccumulator`]
//!   re-checks the whole body; [`MassProps`](crate::components::MassProps) and
//!   [`PhysicsSettings`](crate::components::PhysicsSettings) cannot hold bad values at all;
//! - **on change**: the integrate systems check each body's input before stepping it (game code
//!   may have written NaN into a `&mut Pose`) and its output after (a method outside its
//!   stable region).
//!
//! A rejected body gets the [`Rejected`] marker, keeps its last valid data untouched and is skipped
//! by every physics system; the error is logged with `tracing` and appended to [`PhysicsErrors`].
//! Inserting valid data again lifts the quarantine.

use bevy_ecs::lifecycle::HookContext;
use bevy_ecs::prelude::*;
use bevy_ecs::world::DeferredWorld;
use thiserror::Error;
use tumble_core::{InvalidInput, StepError};

use crate::components::{ForceAccumulator, Pose, RigidBody, Velocity};

/// Why a body was rejected.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum BodyErrorKind {
    /// A component holds invalid data.
    #[error("invalid {component}: {source}")]
    Invalid {
        /// The component type, e.g. `"Pose"`.
        component: &'static str,
        /// What is wrong with it.
        source: InvalidInput,
    },
    /// The integrator produced a non-finite state or a non-unit rotation; the body keeps its last
    /// valid state.
    #[error(transparent)]
    Diverged(#[from] StepError),
    /// The integrator created energy: the body's spring group (see [`crate::audit`]) gained more
    /// than the work of its external loads allows. The body was put back to its state at the
    /// start of the step.
    #[error(
        "energy grew: the integrator created {created:.3e} J in a group of {group} bodies that \
         should hold {should:.3e} J (allowed {bound:.3e} J); the step is outside the method's \
         stable region"
    )]
    EnergyGrew {
        /// Energy the group should hold (J): at the start of the step, less what the integrator
        /// created before.
        should: f64,
        /// Energy the integrator created in the group so far, this step included (J).
        created: f64,
        /// The largest creation the audit allows (J).
        bound: f64,
        /// Bodies in the group.
        group: usize,
    },
    /// The implicit step of the body's stiff spring group failed (see [`crate::stiff`]); the
    /// group keeps its state at the start of the step.
    #[error("stiff spring group: {0}")]
    ImplicitSprings(tumble_core::springs::ImplicitSpringError),
    /// The body was already quarantined in a restored snapshot, for this reason.
    #[error("quarantined before the snapshot: {0}")]
    Restored(String),
}

/// A body-level error, naming the entity.
#[derive(Debug, Clone, PartialEq, Error)]
#[error("rigid body {entity}: {kind}")]
pub struct BodyError {
    /// The rejected entity.
    pub entity: Entity,
    /// What went wrong.
    pub kind: BodyErrorKind,
}

/// Quarantine marker: the body is skipped by every physics system until valid data is inserted.
#[derive(Component, Debug, Clone, PartialEq)]
pub struct Rejected(pub BodyError);

/// Every error raised so far, oldest first, one record per incident. Exists from the first
/// plan on ([`PhysicsPlan::for_world`](crate::schedule::PhysicsPlan::for_world)); game code
/// may drain it.
#[derive(Resource, Debug, Clone, Default, PartialEq)]
pub struct PhysicsErrors {
    /// Quarantined bodies (see [`Rejected`]).
    pub bodies: Vec<BodyError>,
    /// Force generators left out of the step (see [`crate::generator_check`]).
    pub generators: Vec<crate::generator_check::GeneratorError>,
}

impl PhysicsErrors {
    /// True when nothing was recorded.
    pub fn is_empty(&self) -> bool {
        self.bodies.is_empty() && self.generators.is_empty()
    }
}

/// Checks the body data of a [`Pose`], [`Velocity`] and optional [`ForceAccumulator`].
///
/// Runs for every body every step, so valid data takes an inlined fast test (finite values, unit
/// quaternion within [`UNIT_QUATERNION_TOLERANCE`](tumble_core::error::UNIT_QUATERNION_TOLERANCE));
/// only bad data goes through the detailed checks that build the error.
#[inline]
pub fn check_body(
    transform: &Pose,
    velocity: &Velocity,
    forces: Option<&ForceAccumulator>,
) -> Result<(), BodyErrorKind> {
    // Branch-free, as `BodyState::is_finite`: `0 · x` is 0 for finite x and NaN otherwise, and
    // one NaN makes the sum NaN. (The rotation's finiteness is part of the unit test below.)
    let mut zeros = transform.translation * 0.0 + velocity.linear * 0.0 + velocity.angular * 0.0;
    if let Some(acc) = forces {
        zeros += acc.force * 0.0 + acc.torque * 0.0;
    }
    let finite = zeros.x + zeros.y + zeros.z == 0.0;
    // The squared norm needs no square root: `|q|² − 1 = (|q| − 1)(|q| + 1)`, so
    // `||q|² − 1| ≤ tol` implies `||q| − 1| ≤ tol`; the rare quaternion in between goes
    // through the exact test in the detailed checks. NaN or Inf makes this false as well.
    let unit = (transform.rotation.length_squared() - 1.0).abs()
        <= tumble_core::error::UNIT_QUATERNION_TOLERANCE;
    if finite && unit {
        return Ok(());
    }
    check_body_in_detail(transform, velocity, forces)
}

/// The detailed checks behind [`check_body`], naming the component and field at fault.
#[cold]
fn check_body_in_detail(
    transform: &Pose,
    velocity: &Velocity,
    forces: Option<&ForceAccumulator>,
) -> Result<(), BodyErrorKind> {
    use tumble_core::error::{check_finite_vec3, check_unit_quat};
    let invalid = |component| move |source| BodyErrorKind::Invalid { component, source };
    check_finite_vec3("translation", transform.translation).map_err(invalid("Pose"))?;
    check_unit_quat("rotation", transform.rotation).map_err(invalid("Pose"))?;
    check_finite_vec3("linear velocity", velocity.linear).map_err(invalid("Velocity"))?;
    check_finite_vec3("angular velocity", velocity.angular).map_err(invalid("Velocity"))?;
    match forces {
        Some(acc) => check_accumulator_in_detail(acc),
        None => Ok(()),
    }
}

/// Checks that a [`ForceAccumulator`] holds finite values (an inlined test; only bad values go
/// through the checks that build the error).
#[inline]
pub fn check_accumulator(acc: &ForceAccumulator) -> Result<(), BodyErrorKind> {
    if acc.force.is_finite() && acc.torque.is_finite() {
        return Ok(());
    }
    check_accumulator_in_detail(acc)
}

/// The detailed checks behind [`check_accumulator`], naming the field at fault.
#[cold]
fn check_accumulator_in_detail(acc: &ForceAccumulator) -> Result<(), BodyErrorKind> {
    use tumble_core::error::check_finite_vec3;
    let invalid = |source| BodyErrorKind::Invalid {
        component: "ForceAccumulator",
        source,
    };
    check_finite_vec3("force", acc.force).map_err(invalid)?;
    check_finite_vec3("torque", acc.torque).map_err(invalid)
}

/// Quarantines `entity`: logs the error, records it in [`PhysicsErrors`] and inserts
/// [`Rejected`]. Used by the hooks and the integrate systems.
///
/// One incident is one record: a body already quarantined for the same reason (several hooks
/// of one insertion see the same bad data) is neither logged nor recorded again.
pub fn reject(commands: &mut Commands, error: BodyError) {
    commands.queue(move |world: &mut World| {
        let Ok(mut entity) = world.get_entity_mut(error.entity) else {
            return;
        };
        if entity.get::<Rejected>().is_some_and(|r| r.0 == error) {
            return;
        }
        tracing::warn!(entity = %error.entity, "{error}");
        entity.insert(Rejected(error.clone()));
        world
            .get_resource_or_init::<PhysicsErrors>()
            .bodies
            .push(error);
    });
}

/// Component hook: re-checks the whole body whenever one of its state components is inserted.
pub fn revalidate_body_hook(mut world: DeferredWorld, ctx: HookContext) {
    let entity = ctx.entity;
    if world.get::<RigidBody>(entity).is_none() {
        return;
    }
    let (Some(transform), Some(velocity)) =
        (world.get::<Pose>(entity), world.get::<Velocity>(entity))
    else {
        return; // the rest of the bundle is still being inserted; its own hook will check.
    };
    let result = check_body(transform, velocity, world.get::<ForceAccumulator>(entity));
    let was_rejected = world.get::<Rejected>(entity).is_some();
    let mut commands = world.commands();
    match result {
        Err(kind) => reject(&mut commands, BodyError { entity, kind }),
        Ok(()) if was_rejected => {
            commands.entity(entity).remove::<Rejected>();
        }
        Ok(()) => {}
    }
}
