//! # tumble_ecs
//!
//! The `bevy_ecs` layer of tumble: components ([`Pose`](components::Pose),
//! [`Velocity`](components::Velocity), [`MassProps`](components::MassProps),
//! [`ForceAccumulator`](components::ForceAccumulator), …), force generators, the integrate
//! systems, a [`PhysicsRunner`](schedule::PhysicsRunner) that steps a world by a
//! [`PhysicsPlan`](schedule::PhysicsPlan) holding only what the world needs and plans again
//! whenever the world changes, a fixed-step [`FixedStepper`](schedule::FixedStepper) and
//! validation that keeps bad data out.

// docs.rs builds with `--cfg docsrs` on nightly: feature-gated items are marked with the
// features they need.
#![cfg_attr(docsrs, feature(doc_cfg))]
#![forbid(unsafe_code)]
#![warn(missing_docs)]
// ECS queries name their filters inline, as bevy itself does.
#![allow(clippy::type_complexity)]

// Folders read bottom-up: `components` and `parallel` are leaves; `forces`, `integrate`,
// `springs`, `audit`, `stability` and `state` build on them; `schedule` ties them together.
pub mod audit;
pub mod components;
pub mod forces;
pub mod integrate;
pub mod parallel;
pub mod schedule;
pub mod springs;
pub mod stability;
pub mod state;

/// Everything a game loop needs, in one import. It holds no name of the preludes of the Bevy
/// crates a game uses beside tumble (`bevy_ecs`, `bevy_app`, `bevy_math`, `bevy_time`,
/// `bevy_transform`), so both glob imports live together; the scalar and vector types are in
/// `tumble_core::math` (`Real`, `Vec3` and `Quat` follow the feature `f64`, where Bevy's stay
/// `f32`).
pub mod prelude {
    pub use crate::audit::EnergyAudit;
    pub use crate::components::{
        AssumedMass, BodyError, BodyErrorKind, ConstantForce, ConstantLocalForce, ConstantTorque,
        Damping, ForceAccumulator, GeneratorError, GeneratorErrorKind, Gravity, GravityScale,
        Kinematic, MassProps, PhysicsErrors, PhysicsSettings, Pose, Rejected, RejectedGenerator,
        RigidBody, Spring, SpringEnd, SpringSolver, Static, Velocity,
    };
    pub use crate::forces::{ApplyForces, BodyForces};
    pub use crate::parallel::Parallelism;
    pub use crate::schedule::{
        FixedStepper, ForceSystems, FrameSteps, PhysicsPlan, PhysicsRunner, PhysicsSet,
        PhysicsSystem, interpolate,
    };
    pub use crate::stability::{StabilityWarning, check_stability};
    pub use crate::state::{RollbackError, RollbackSnapshot, WorldChecksum, world_checksum};
    pub use tumble_core::integrate::FreeFlow;
    pub use tumble_core::{Density, Integrator, Mass, MassProperties};
}
