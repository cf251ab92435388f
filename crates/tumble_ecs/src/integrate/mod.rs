//! The integrate stage: the systems that hand each table of bodies to the core's batched step,
//! and the stage cursor of steps of several stages.
//!
//! ## Steps of several stages
//!
//! Steps of several stages: substeps and `yoshida4`'s composition, run by running the physics
//! schedule once per stage.
//!
//! A step is the sequence of stages of [`PhysicsSettings::stages`](crate::components::PhysicsSettings::stages): `N` substeps, each the
//! integrator's composition (one stage, or three for `yoshida4`; see [`Stages`](tumble_core::integrate::Stages)). The schedule
//! holds the systems of *one* stage — half drift, gravity, force generators, game systems in
//! [`PhysicsSet::Forces`](crate::schedule::PhysicsSet::Forces), kick and drift — and a step runs
//! it once per stage ([`PhysicsPlan::runs_per_step`](crate::schedule::PhysicsPlan::runs_per_step)
//! times; [`PhysicsRunner`](crate::schedule::PhysicsRunner) does), so the force stage is sampled
//! afresh in every stage without rebuilding anything. The [`StageCursor`] tells each system which
//! stage it is in: its span `h`, and whether it opens or closes a substep (where the damping
//! flows run) or the step (where the energy audit opens and closes its balance).
//!
//! A plan of one stage per step (the default: one substep, any method but `yoshida4`) has
//! neither of this module's systems, and its systems see stage 0 of 1, whose span is `Δt` to the
//! bit: such a world pays nothing for stages.

mod stages;
mod systems;
mod table;

pub use stages::{StageCursor, hold_game_loads, next_stage};
pub use systems::{
    begin_stage, check_fixed_bodies, discard_fixed_body_forces, integrate_with_forces,
    integrate_without_forces,
};

// Schedule state between two systems of one stage, in their signatures; not for game code.
pub(crate) use systems::gravity_applies;
#[doc(hidden)]
pub use systems::{HalfDrifted, StageStarts};
pub(crate) use table::damp;
