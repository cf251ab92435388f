//! # tumble_reference
//!
//! What tumble is measured against, kept out of the engine (`tumble_core` holds what a step
//! runs; this crate holds what only tests, the report and `tumble compare` run):
//!
//! - [`exact`]: closed forms — the projectile, the undamped and damped spring, and the
//!   torque-free rigid body through Jacobi elliptic functions (whose machinery, `tumble_core::
//!   elliptic`, stays in the engine: the `exact` integrator's free flow runs it every step);
//! - [`rk4`]: the one tiny-step classic RK4 reference, for the torque-free body where a closed
//!   form is not the point (and to check the closed forms themselves).

#![forbid(unsafe_code)]

pub mod exact;
pub mod rk4;
