//! Stepping a world: the plan of systems a world needs, the runner that keeps it in step with
//! the world, a fixed-step clock for variable frame rates, and the Bevy plugin.
//!
//! ## The physics schedule
//!
//! The physics schedule, built from what a world needs and nothing more.
//!
//! One run of the schedule is one *stage* of the step (see [`crate::integrate`]): a step of one
//! stage (the default) is one run; with substeps or `yoshida4`'s composition the schedule runs
//! [`PhysicsPlan::runs_per_step`] times per step, and the force stage with it. One run goes
//! through these sets in order:
//!
//! 0. [`PhysicsSet::Prepare`] — in a plan of several stages, `hold_game_loads` (the load game
//!    code added before the step, held over all stages); in audited worlds, the energy audit's
//!    start (see [`crate::audit`]); with damped springs, at the start of each substep, the first
//!    half of the spring dampers' flow (`damp_springs_start`, see [`crate::springs`]); for
//!    drift–kick–drift integrators (`splitting`, `yoshida4`, `rk4`), the first half of the
//!    [`Damping`] flow (at the start of a substep) and half a drift, so forces are sampled at
//!    the midpoint of the stage.
//! 1. [`PhysicsSet::Gravity`] — `m g s` into each accumulator; only if a [`Gravity`](crate::components::Gravity) resource
//!    exists.
//! 2. [`PhysicsSet::Forces`] — force generators that exist in the world (constant forces,
//!    torques, springs), and any game system placed in this set (it runs after the half drift,
//!    on the state the forces are sampled at). In an audited world the springs move to the
//!    start of the next set, right after the audit has read every other load.
//! 3. [`PhysicsSet::Integrate`] — the selected integrator. It *consumes* each accumulator (reads
//!    and zeroes it in the same pass, so there is no separate "clear forces" pass and a force
//!    added before a step is applied exactly once) and renormalizes each quaternion as part of
//!    the rotation update (so there is no separate "renormalize" pass either), with the
//!    [`Damping`] flow for half a step after (and, for a whole step, before). Then, with damped
//!    springs, the second half-step of the spring dampers' flow (`damp_springs_end`, the springs
//!    in reverse order). In audited worlds the audit reads the loads (all but the springs')
//!    first, then the springs add theirs, and the audit closes the energy balance at the very
//!    end of the step. In a plan of several stages,
//!    `next_stage` moves the stage cursor on, last.
//!
//! Damping is thus a flow of its own, split symmetrically around the conservative step,
//! `D(Δt/2) ∘ step ∘ D(Δt/2)`: second order with the drift–kick–drift methods, and never a gain
//! of energy (see [`tumble_core::damping`]).
//!
//! [`Damping`]: crate::components::Damping
//!
//! ## The runner
//!
//! A physics step that keeps its schedule in step with the world.
//!
//! ## A fixed step for a variable frame rate
//!
//! A fixed time step for a variable-rate game loop.
//!
//! Frame times are added to an accumulator; every whole `Δt` in it is one physics step. A cap on
//! steps per frame stops the "spiral of death" (a slow frame causing more steps, causing a slower
//! frame): time beyond the cap is dropped and counted. The remainder gives the interpolation
//! factor `α = accumulator / Δt ∈ [0, 1)` for rendering between the last two states.
//!
//! ## Inside a Bevy app
//!
//! `TumblePlugin` (feature `bevy_app`): tumble inside a Bevy app, one physics step per run of a
//! schedule of the app's choosing (`FixedUpdate` by default), on Bevy's fixed clock.

mod generator_watch;
mod plan;
#[cfg(feature = "bevy_app")]
mod plugin;
mod runner;
mod stepper;

pub use plan::{PhysicsPlan, PhysicsSet, PhysicsSystem};
#[cfg(feature = "bevy_app")]
pub use plugin::{TumblePlugin, TumbleStep, physics_step};
pub use runner::{ForceSystems, PhysicsRunner};
pub use stepper::{FixedStepper, FrameSteps, StepperError, interpolate};
