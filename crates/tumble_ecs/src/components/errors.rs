//! The errors a world records: a quarantined body, a generator left out of the step, a world
//! resource left out of the step.

use bevy_ecs::prelude::*;
use thiserror::Error;
use tumble_core::error::compact;
use tumble_core::math::{REAL_NAME, Real};
use tumble_core::{InvalidInput, StepError};

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
    /// The implicit step of the body's stiff spring group failed (see [`crate::springs`]); the
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

/// The bodies refused during the current step. Their [`Rejected`] is a deferred command (a
/// schedule run applies its commands once, at its end), so the energy audit's verdict at the
/// end of the step reads them here: a refused body keeps its state, and any bad data game code
/// wrote into it, while its springs' partners move on, so its group gets no verdict that step.
/// Present while the audit is planned; the audit empties it every step.
#[derive(Resource, Debug, Default)]
pub struct StepRefusals(Vec<Entity>);

impl StepRefusals {
    /// Records that `entity` was refused.
    pub(crate) fn push(&mut self, entity: Entity) {
        self.0.push(entity);
    }

    /// The refused bodies since the last call, emptying the record.
    pub(crate) fn drain(&mut self) -> std::vec::Drain<'_, Entity> {
        self.0.drain(..)
    }
}

/// Every error raised so far, oldest first, one record per incident. Exists from the first
/// plan on ([`PhysicsPlan::for_world`](crate::schedule::PhysicsPlan::for_world)); game code
/// may drain it.
#[derive(Resource, Debug, Clone, Default, PartialEq)]
pub struct PhysicsErrors {
    /// Quarantined bodies (see [`Rejected`]).
    pub bodies: Vec<BodyError>,
    /// Force generators left out of the step (see [`crate::components`]).
    pub generators: Vec<crate::components::GeneratorError>,
    /// World resources left out of the step (see [`WorldError`]).
    pub world: Vec<WorldError>,
}

/// A world resource game code made bad (a non-finite [`Gravity`](crate::components::Gravity)),
/// left out of the step until it is valid again rather than carried into every body it
/// reaches; or one the step needs that is missing ([`PhysicsSettings`](crate::components::PhysicsSettings)),
/// put back with what the step then uses. Recorded once per incident.
#[derive(Debug, Clone, PartialEq, Error)]
#[error("{resource}: {kind}")]
pub struct WorldError {
    /// The resource, e.g. `"Gravity"`.
    pub resource: &'static str,
    /// What is wrong with it.
    pub kind: WorldErrorKind,
}

/// What is wrong with a world resource (see [`WorldError`]).
#[derive(Debug, Clone, PartialEq, Error)]
pub enum WorldErrorKind {
    /// Not valid: left out of the step until it is.
    #[error("{0}; left out of the step until it is valid")]
    Invalid(InvalidInput),
    /// Missing when a step needed it (removed after planning, or never inserted): put back
    /// with what the step uses instead, said here so that it is never a silent default.
    #[error("missing; inserted {used} (insert the resource to choose)")]
    Missing {
        /// What the step uses in its place.
        used: String,
    },
}

impl PhysicsErrors {
    /// True when nothing was recorded.
    pub fn is_empty(&self) -> bool {
        self.bodies.is_empty() && self.generators.is_empty() && self.world.is_empty()
    }
}

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
    /// A spring whose force at zero length, `k ℓ₀`, is not a finite number in the build
    /// precision: wherever its ends come closer than `ℓ₀ − Real::MAX / k`, its force overflows,
    /// and at the scale of such a rest length the precision cannot place its ends at all.
    #[error(
        "stiffness {} times rest_length {} overflows {REAL_NAME}: the spring's force at zero \
         length, k·rest_length, must be a finite number",
        compact(*.stiffness),
        compact(*.rest_length)
    )]
    ForceOverflow {
        /// The stiffness `k` (N/m).
        stiffness: Real,
        /// The rest length `ℓ₀` (m).
        rest_length: Real,
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
