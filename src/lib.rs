//! # tumble
//!
//! Rigid-body dynamics for headless game loops, on `bevy_ecs`, `glam` and `parry3d`.
//!
//! Spawn bodies with components, step the world once per fixed step with a
//! [`PhysicsRunner`](prelude::PhysicsRunner) (it plans the step from the world and plans again
//! whenever the world changes: bodies, force generators, settings, gravity), read the poses back:
//!
//! ```
//! use tumble::prelude::*;
//! use tumble::{bevy_ecs::prelude::World, math::Vec3};
//!
//! let mut world = World::new();
//! world.insert_resource(PhysicsSettings::new(1.0 / 60.0, Integrator::SymplecticEuler).unwrap());
//! world.insert_resource(Gravity(Vec3::new(0.0, -9.81, 0.0)));
//! let mass = MassProperties::solid_sphere(Mass::new(1.0).unwrap(), 0.5).unwrap();
//! let ball = world
//!     .spawn((RigidBody, MassProps(mass), ForceAccumulator::default()))
//!     .id();
//! let mut physics = PhysicsRunner::new(&mut world);
//! for _ in 0..60 {
//!     physics.step(&mut world);
//!     world.clear_trackers();
//! }
//! let y = world.get::<Pose>(ball).unwrap().translation.y;
//! assert!((y - (-9.81 * 61.0 / 120.0)).abs() < 1e-3); // x_n = g Δt² n(n+1)/2
//! ```
//!
//! Game code adds loads with the [`ApplyForces`](prelude::ApplyForces) methods — on an entity
//! (`world.entity_mut(body).apply_force(..)`) or on the items of a `Query<BodyForces>` in a
//! system: forces and torques in world or body coordinates, at world or body points (the centre
//! of mass is taken from the body), consumed by the next step; linear and angular impulses,
//! which change the momentum by exactly `J` at once.
//!
//! To `#[derive(Component)]` (or `Resource`, `SystemSet`, …) in your own code, add `bevy_ecs`
//! as a direct dependency, at the version tumble re-exports as [`bevy_ecs`] (0.20): bevy's
//! derive macros name the crate `bevy_ecs` in the code they generate, so the re-export alone
//! does not satisfy them.
//!
//! The guide (stepping, forces, springs, integrators, precision, determinism, the CLI, coming
//! from avian or bevy_rapier, architecture) is in the repository's `docs/` directory, starting
//! at `docs/README.md`.
//!
//! The surface: [`prelude`] (a game loop's one import), [`math`] (the precision's scalar,
//! vectors and quaternion), [`core`] (ECS-free math: state, mass properties, integrators and
//! their batch interface, invariants) and [`ecs`] (components, forces, the plan and runner,
//! state, stability). Each is a curated list: the systems a step runs, their scratch memory
//! and the checks they share stay inside `tumble_core` and `tumble_ecs`, so they can change
//! without changing tumble's API. `glam`, `bevy_ecs` (and `parry3d` with the `parry` feature)
//! are re-exported so versions always match.
//!
//! Features (a build pays only for what it enables):
//!
//! | feature | default | adds |
//! |---|---|---|
//! | `parry` | yes | mass properties from parry3d shapes |
//! | `parallel` | yes | big tables split over bevy's compute pool (bit-identical results) |
//! | `scene` | no | `tumble::scene`: TOML scene files, CSV trajectories |
//! | `serde` | no | serde for every component and resource; `ecs::state::Snapshot` save / resume |
//! | `bevy_app` | no | `ecs::schedule::TumblePlugin`: the step in a Bevy app's `FixedUpdate` |
//! | `f64` | no | double precision throughout: [`math::Real`] = `f64`, `Vec3` = `DVec3`, … |
//! | `parry-f64` | no | shapes from parry3d-f64 (implies `f64`) |
//! | `enhanced-determinism` | no | glam's `scalar-math`: no SIMD lane order anywhere (the default build already gives the same bits; pinned checksums hold in both) |
//!
//! `--no-default-features` is the bare integrator layer on `bevy_ecs` and `glam` only.

// docs.rs builds with `--cfg docsrs` on nightly: feature-gated items are marked with the
// features they need.
#![cfg_attr(docsrs, feature(doc_cfg))]
#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub mod core;
pub mod ecs;

pub use bevy_ecs;
pub use glam;
pub use tumble_core::math;
/// The parry crate of the shapes: `parry3d`, or `parry3d-f64` with the feature `parry-f64`.
#[cfg(any(feature = "parry", feature = "parry-f64"))]
pub use tumble_core::shapes::parry;
/// Scene files and trajectories (feature `scene`).
#[cfg(feature = "scene")]
pub use tumble_scene as scene;

/// Everything a game loop needs, in one import.
pub mod prelude {
    #[cfg(any(feature = "parry", feature = "parry-f64"))]
    pub use tumble_core::shapes::mass_properties_of;
    pub use tumble_core::{BodyBatch, BodyState, Integrator, StepPhase, Wrench};
    pub use tumble_ecs::prelude::*;
}

/// The README's code blocks, compiled and run as doc tests so the front door never rots.
#[doc = include_str!("../README.md")]
#[cfg(doctest)]
pub struct ReadmeDoctests;

/// The guide's pages (`docs/`), their code blocks compiled and run as doc tests as the README's.
#[cfg(doctest)]
pub mod guide {
    #[doc = include_str!("../docs/README.md")]
    pub struct Index;
    #[doc = include_str!("../docs/getting-started.md")]
    pub struct GettingStarted;
    #[doc = include_str!("../docs/stepping.md")]
    pub struct Stepping;
    #[doc = include_str!("../docs/forces.md")]
    pub struct Forces;
    #[doc = include_str!("../docs/springs.md")]
    pub struct Springs;
    #[doc = include_str!("../docs/integrators.md")]
    pub struct Integrators;
    #[doc = include_str!("../docs/precision.md")]
    pub struct Precision;
    #[doc = include_str!("../docs/determinism.md")]
    pub struct Determinism;
    #[doc = include_str!("../docs/cli.md")]
    pub struct Cli;
    #[doc = include_str!("../docs/performance.md")]
    pub struct Performance;
    #[doc = include_str!("../docs/coming-from.md")]
    pub struct ComingFrom;
    #[doc = include_str!("../docs/architecture.md")]
    pub struct Architecture;
}
