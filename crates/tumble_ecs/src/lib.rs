//! # tumble_ecs
//!
//! The `bevy_ecs` layer of tumble: components ([`Transform`](components::Transform),
//! [`Velocity`](components::Velocity), [`MassProps`](components::MassProps),
//! [`ForceAccumulator`](components::ForceAccumulator), …), force generators, the integrate
//! systems, a [`PhysicsPlan`](schedule::PhysicsPlan) that builds a schedule holding only what a
//! world needs, a fixed-step [`FixedStepper`](stepper::FixedStepper) and validation that keeps bad
//! data out.

#![forbid(unsafe_code)]
#![warn(missing_docs)]
// ECS queries name their filters inline, as bevy itself does.
#![allow(clippy::type_complexity)]

pub mod audit;
pub mod checksum;
pub mod components;
pub mod damping;
pub mod forces;
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

/// Everything a game loop needs, in one import.
pub mod prelude {
    pub use crate::audit::EnergyAudit;
    pub use crate::checksum::{WorldChecksum, world_checksum};
    pub use crate::components::{
        Damping, ForceAccumulator, Gravity, GravityScale, Kinematic, MassProps, PhysicsSettings,
        RigidBody, Static, Transform, Velocity,
    };
    pub use crate::forces::{ConstantForce, ConstantTorque, Spring, SpringEnd};
    pub use crate::parallel::Parallelism;
    pub use crate::rollback::{RollbackError, RollbackSnapshot};
    pub use crate::runner::{ForceSystems, PhysicsRunner};
    pub use crate::schedule::{PhysicsPlan, PhysicsSchedule, PhysicsSet, Stage};
    pub use crate::stability::{StabilityWarning, check_stability};
    pub use crate::stepper::{FixedStepper, FrameSteps, interpolate};
    pub use crate::stiff::SpringSolver;
    pub use crate::validate::{BodyError, BodyErrorKind, PhysicsErrors, Rejected};
    pub use tumble_core::math::{Quat, Real, Vec3};
    pub use tumble_core::{Density, Integrator, Mass, MassProperties};
}
