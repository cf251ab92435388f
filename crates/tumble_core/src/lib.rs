//! # tumble_core
//!
//! The ECS-free math of tumble, what a step runs: rigid-body state, mass properties,
//! integrators (with the elliptic functions of the exact free flow), the implicit spring solve
//! and invariants. (What tumble is measured against lives in `tumble_reference`.) Everything
//! here is a plain function on plain data, so every integrator can be tested and benchmarked
//! without an ECS, and the ECS layer (`tumble_ecs`) is a thin loop over queries that calls
//! these functions.
//!
//! Conventions:
//! - `BodyState::position` is the world position of the **centre of mass**.
//! - Angular velocity `ω` is in **world** coordinates (`Ṙ = [ω]× R`).
//! - Inertia is stored as principal moments `I_b` in a principal frame; the world inverse inertia
//!   `R I_b⁻¹ Rᵀ` is applied by rotating into the principal frame, never inverted numerically.
//! - A zero principal moment locks that axis (its inverse is 0), never NaN.

// docs.rs builds with `--cfg docsrs` on nightly: feature-gated items are marked with the
// features they need.
#![cfg_attr(docsrs, feature(doc_cfg))]

pub mod damping;
pub mod elliptic;
pub mod error;
pub mod integrate;
pub mod invariants;
pub mod mass;
pub mod math;
// Plumbing of the ECS layer's batch loops, public only so that `tumble_ecs` can reach it.
#[doc(hidden)]
pub mod prefetch;
pub mod rotation;
#[cfg(any(feature = "parry", feature = "parry-f64"))]
pub mod shapes;
mod simd;
pub mod springs;
pub mod state;

pub use error::{InvalidInput, UNIT_QUATERNION_TOLERANCE};
pub use integrate::{BodyBatch, Integrator, KernelPath, StepError, StepPhase, kernel_path};
pub use mass::{Density, Mass, MassProperties};
pub use state::{BodyState, Wrench};
