//! The force stage: the systems that turn force generators and gravity into each body's
//! [`ForceAccumulator`](crate::components::ForceAccumulator), and the way game code adds its own.
//!
//! ## The force systems
//!
//! Force generators. Each generator is its own entity (a body may have any number of them) that
//! names its body; its system runs in [`PhysicsSet::Forces`](crate::schedule::PhysicsSet::Forces)
//! and adds to the body's [`ForceAccumulator`](crate::components::ForceAccumulator) (inserted automatically when a generator is
//! spawned). A generator is checked when inserted and whenever it changes, and left out of the
//! step with a [`GeneratorError`](crate::components::GeneratorError) when it is invalid or
//! its body is gone (see [`crate::components`]); a generator whose body is quarantined does
//! nothing until the body is valid again.
//!
//! ## Forces from game code
//!
//! Forces, torques and impulses from game code, in world or body coordinates, through the centre
//! of mass or any point: [`BodyForces`] in a system's query, or the same methods on an entity of
//! a bare `World` (`world.entity_mut(body).apply_force(..)`), both through the [`ApplyForces`]
//! trait.
//!
//! The semantics, in one sentence for avian and rapier users: a **force** or **torque** added
//! between two steps acts over the whole next step and is then consumed — its impulse is `F Δt`,
//! whatever the substeps or composition (see
//! [`ForceAccumulator`](crate::components::ForceAccumulator)) — as avian's `Forces` and rapier's
//! `add_force` followed by `reset_forces`; an **impulse** changes the body's momentum by exactly
//! `J` at once (`Δv = J/m`, `Δω = R I_b⁻¹ Rᵀ J`), as rapier's `apply_impulse` and avian's
//! `apply_linear_impulse`. A load that lasts over many steps is a generator entity
//! ([`ConstantForce`](crate::components::ConstantForce),
//! [`ConstantTorque`](crate::components::ConstantTorque), [`Spring`](crate::components::Spring)).
//!
//! *World* vectors are in world coordinates; *local* ones in the body's (turned by its [`Pose`](crate::components::Pose)
//! rotation). A force through a point adds the torque `(p − x) × F` about the centre of mass
//! `x`, which is taken from the body's pose and [`MassProps`](crate::components::MassProps).

mod apply;
mod body_forces;
mod push_blocks;
mod targets;

pub(crate) use apply::long_span;
pub use apply::{apply_constant_forces, apply_constant_torques, apply_gravity, apply_springs};
pub use apply::{kinetic_and_elastic_energy, spring_force};
pub use body_forces::{
    ApplyForces, BodyForces, BodyForcesItem, BodyForcesReadOnly, BodyForcesReadOnlyItem,
};
pub use targets::ForceTargets;

// System state of the force systems above, in their signatures; not for game code.
#[doc(hidden)]
pub use apply::SpringPushes;
#[doc(hidden)]
pub use targets::TargetRows;
