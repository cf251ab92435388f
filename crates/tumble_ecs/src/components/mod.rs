//! The data model of a tumble world: body components, force generators, markers, settings,
//! and the errors and checks that keep bad data out of a step.
//!
//! ## Bad data is quarantined
//!
//! Rejection of bad component data: typed errors that name the entity, and a quarantine marker
//! so that one bad body never harms another.
//!
//! Bad data is caught in two places:
//! - **on insert**: a component hook on [`Pose`], [`Velocity`] and [`ForceAccumulator`]
//!   re-checks the whole body; [`MassProps`] and
//!   [`PhysicsSettings`] cannot hold bad values at all;
//! - **on change**: the integrate systems check each body's input before stepping it (game code
//!   may have written NaN into a `&mut Pose`) and its output after (a method outside its
//!   stable region).
//!
//! A rejected body gets the [`Rejected`] marker, keeps its last valid data untouched and is skipped
//! by every physics system; the error is logged with `tracing` and appended to [`PhysicsErrors`].
//! Inserting valid data again lifts the quarantine.
//!
//! ## Force generators are checked
//!
//! Force generators are checked, never trusted: their values when they are inserted and whenever
//! game code changes them, their bodies when they are inserted and whenever a body goes away.
//!
//! A generator that fails a check is left out of the step: its generator component is removed
//! (so no system, plan or audit sees it), a [`RejectedGenerator`] marker names why, the error is
//! logged with `tracing` and recorded once in [`PhysicsErrors`]. Inserting a valid generator on
//! the entity again lifts the marker. The checks never blame a body for its generator's values.
//!
//! When each check runs:
//! - on insert, a component hook checks the values, that a spring does not join a body to
//!   itself and that every body it names exists;
//! - before every step, [`PhysicsRunner`](crate::schedule::PhysicsRunner) checks the values of
//!   every generator changed since the last change-tracker clear, and, if bodies were removed
//!   or despawned since the last step, which generators named them.

mod body;
mod errors;
mod generators;
mod markers;
mod order;
mod settings;

pub(crate) use body::check_rotation;
pub use body::{
    AssumedMass, Damping, ForceAccumulator, GravityScale, HeldLoad, Kinematic, MassProps, Pose,
    RigidBody, Static, Velocity, assume_missing_masses, bodies_without_mass, body_state,
    check_accumulator, check_body, kinetic_energy_f64, write_body_state,
};
pub use errors::{
    BodyError, BodyErrorKind, GeneratorError, GeneratorErrorKind, PhysicsErrors, Rejected,
    RejectedGenerator, WorldError, WorldErrorKind,
};
pub use generators::{ConstantForce, ConstantLocalForce, ConstantTorque, Spring, SpringEnd};
pub use markers::{Dynamic, ImplicitBody, ImplicitSpring, SpringTurn};
pub use settings::{Gravity, PhysicsSettings, SpringSolver};

pub(crate) use body::{RemovedBodies, reject};
pub(crate) use generators::{Generator, check_inserted, ensure_accumulators, reject_generator};
pub(crate) use markers::{Stepped, dense};
pub(crate) use order::IndexedQuery;
// Scratch memory of the systems that visit generators in entity order, in their signatures;
// not for game code.
#[doc(hidden)]
pub use order::IndexOrder;
// How the step's systems refuse bodies, in their signatures; not for game code.
#[doc(hidden)]
pub use body::Refusals;
#[doc(hidden)]
pub use errors::StepRefusals;
