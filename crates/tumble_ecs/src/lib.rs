//! # tumble_ecs
//!
//! The `bevy_ecs` layer of tumble: components ([`Pose`](components::Pose),
//! [`Velocity`](components::Velocity), [`MassProps`](components::MassProps),
//! [`ForceAccumulator`](components::ForceAccumulator), …), force generators, the integrate
//! systems, a [`PhysicsRunner`](runner::PhysicsRunner) that steps a world by a
//! [`PhysicsPlan`](schedule::PhysicsPlan) holding only what the world needs and plans again
//! whenever the world changes, a fixed-step [`FixedStepper`](stepper::FixedStepper) and
//! validation that keeps bad data out.

// docs.rs builds with `--cfg docsrs` on nightly: feature-gated items are marked with the
// features they need.
#![cfg_attr(docsrs, feature(doc_cfg))]
#![forbid(unsafe_code)]
#![warn(missing_docs)]
// ECS queries name their filters inline, as bevy itself does.
#![allow(clippy::type_complexity)]

pub mod audit;
pub mod body_forces;
pub mod checksum;
pub mod components;
pub mod damping;
pub mod forces;
pub mod generator_check;
pub mod parallel;
#[cfg(feature = "bevy_app")]
pub mod plugin;
pub mod rollback;
pub mod runner;
pub mod schedule;
#[cfg(feature = "serde")]
pub mod snapshot;
pub mod stability;
pub mod stages;
pub mod stepper;
pub mod stiff;
pub mod systems;
mod table;
mod targets;
pub mod validate;

/// Everything a game loop needs, in one import. It holds no name of the preludes of the Bevy
/// crates a game uses beside tumble (`bevy_ecs`, `bevy_app`, `bevy_math`, `bevy_time`,
/// `bevy_transform`), so both glob imports live together; the scalar and vector types are in
/// `tumble_core::math` (`Real`, `Vec3` and `Quat` follow the feature `f64`, where Bevy's stay
/// `f32`).
pub mod prelude {
    pub use crate::audit::EnergyAudit;
    pub use crate::body_forces::{ApplyForces, BodyForces};
    pub use crate::checksum::{WorldChecksum, world_checksum};
    pub use crate::components::{
        AssumedMass, Damping, ForceAccumulator, Gravity, GravityScale, Kinematic, MassProps,
        PhysicsSettings, Pose, RigidBody, Static, Velocity,
    };
    pub use crate::forces::{ConstantForce, ConstantLocalForce, ConstantTorque, Spring, SpringEnd};
    pub use crate::generator_check::{GeneratorError, GeneratorErrorKind, RejectedGenerator};
    pub use crate::parallel::Parallelism;
    pub use crate::rollback::{RollbackError, RollbackSnapshot};
    pub use crate::runner::{ForceSystems, PhysicsRunner};
    pub use crate::schedule::{PhysicsPlan, PhysicsSet, Stage};
    pub use crate::stability::{StabilityWarning, check_stability};
    pub use crate::stepper::{FixedStepper, FrameSteps, interpolate};
    pub use crate::stiff::SpringSolver;
    pub use crate::validate::{BodyError, BodyErrorKind, PhysicsErrors, Rejected};
    pub use tumble_core::integrate::FreeFlow;
    pub use tumble_core::{Density, Integrator, Mass, MassProperties};
}
