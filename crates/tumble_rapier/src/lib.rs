//! # tumble_rapier
//!
//! The one crate of the workspace that links `rapier3d` (0.36). It builds the rapier equivalent of
//! a [`ComparisonScene`] (free bodies, gravity, gravity scale, constant forces and torques, forces
//! at body points, damping, damped springs; rapier's gyroscopic term on or off), steps both
//! engines with the same `Δt` in the same process, and reports per-body differences over time, the
//! total energy of each engine ([`ComparisonScene::total_energy`]) and the time per step of each.
//! Nothing a `tumble` user links by default depends on this crate.
//!
//! ## How the conventions are mapped
//!
//! - **Mass properties**: rapier bodies get no colliders; their mass comes entirely from
//!   `additional_mass_properties` built with the same mass, principal moments, principal frame and
//!   local centre of mass as tumble's [`MassProperties`](tumble_core::MassProperties).
//! - **Poses**: tumble's [`BodyState::position`](tumble_core::BodyState) is the centre of mass;
//!   the rapier body origin is placed at `x − R c` so both centres of mass coincide. Linear
//!   velocity is the centre-of-mass velocity and angular velocity is world-frame in both.
//! - **Damping**: tumble's `Damping` maps to rapier's linear and angular damping, same
//!   coefficients. They are integrated differently (see below).
//! - **Forces**: rapier's user forces persist until reset and a force at a point is turned into a
//!   torque when it is added, so every step the loads are reset and re-added at the current pose,
//!   which matches tumble's generators (sampled once per step).
//! - **Springs**: tumble's `Spring` component, stepped as `PhysicsSettings::springs` says
//!   ([`ComparisonOptions::springs`]); in rapier two ways ([`RapierSprings`]): its
//!   `SpringJoint` with its default `MotorModel::ForceBased` (`k` and `c` are the physical
//!   constants), or the force `−(k (ℓ − L₀) + c u·n) n` added by hand with `add_force_at_point`
//!   every step. Anchors are relative to the body origin in both engines (not the centre of
//!   mass), so they are passed as they are; a spring to a world point is a joint to a fixed
//!   rapier body there.
//! - **Rapier settings**: sleeping off (`can_sleep(false)`), the angular-speed cap off
//!   (`allow_fast_rotation(true)`), and `num_solver_iterations` chosen by the caller (rapier's
//!   default is 4 substeps; 1 makes it a plain symplectic Euler step).
//!
//! ## Where the engines differ by design
//!
//! - **Gyroscopic term**: rapier applies an explicit `−Δt ω × Iω` and rescales `|L|` to its value
//!   before the correction (the `lclamp` method); tumble's default is a Lie–Poisson splitting.
//!   A stable spin about the largest axis drifts toward the middle axis in rapier.
//! - **Rotation update**: rapier 0.36 advances orientations with the linearized
//!   `q ← normalize((1 + ½Δt ω) q)` (tumble's `symplectic-euler-linear`), which rotates by
//!   `2 atan(|ω|Δt/2)` instead of `|ω|Δt`; tumble's methods use exact rotations.
//! - **Substeps**: rapier integrates velocities and positions once per substep; with gravity
//!   and 4 substeps its projectile is closer to the exact parabola than one symplectic Euler step.
//! - **Force sampling**: tumble's drift–kick–drift methods sample forces at mid-step; rapier at
//!   the start of the (sub)step.
//! - **Damping**: rapier applies the Padé form `v ← v / (1 + Δt c)` once per (sub)step, after
//!   the velocity update (first order); tumble applies the flow `v ← e^{−cΔt/2} v` (a rational
//!   approximation of it) half a step before and half a step after its step (second order, see
//!   `tumble_core::damping`). Per step they agree to `O(c²Δt²)`: after a time `t` a damped
//!   velocity differs by about `c²Δt t/2` relative.
//! - **Springs**: rapier's joint is a soft constraint, implicit Euler in the spring per
//!   substep: stable at any stiffness, but it loses about `(ωΔt)²/4` of the spring's energy per
//!   step (4 substeps) even undamped, as its docs say. The hand-written force is held over the
//!   four substeps: it gains about `(3/8)(ωΔt)²` per step (rapier issue #241) and diverges
//!   for stiff springs. tumble's explicit step keeps the energy to `O((ωΔt)²)` without drift
//!   below `ωΔt = 2`; its implicit step conserves it at any `ωΔt`.
//! - **Quarantine**: rapier 0.36 resets a body whose state went non-finite to its last valid
//!   pose, zeroes and disables it ([`RapierScene::is_quarantined`]); the comparison reports it
//!   like tumble's own quarantine, never as a frozen number.
//! - **Velocity caps**: rapier clamps linear velocity to `normalized_max_linear_velocity` (scaled
//!   by the length unit); tumble never clamps. Scenes here stay far below the cap.

#![forbid(unsafe_code)]
#![warn(missing_docs)]

mod compare;
pub mod presets;
mod rapier_side;
mod rapier_springs;
mod scene;
mod tumble_side;

pub use compare::{BodyDifference, Comparison, ComparisonOptions, compare};
pub use rapier_side::RapierScene;
pub use rapier_springs::{RapierSprings, UnknownRapierSprings};
pub use scene::{ComparisonBody, ComparisonScene, ComparisonSpring, ComparisonSpringEnd, Load};
pub use tumble_side::TumbleScene;
