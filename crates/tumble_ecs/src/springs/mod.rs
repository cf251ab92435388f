//! Springs stepped by the world itself: the implicit step of stiff spring groups and the
//! spring dampers' flow.
//!
//! ## Stiff springs
//!
//! Stiff springs: which spring groups the implicit step takes, and the system that steps them.
//!
//! The explicit (drift–kick–drift) spring step is cheap but keeps a spring's energy only to about
//! `(ωΔt)²/4` of it and diverges at `ωΔt ≥ 2`. A group of bodies joined by springs (a connected
//! component of the spring graph over dynamic bodies) that can vibrate at
//! `ωΔt ≥` [`IMPLICIT_OMEGA_DT`](tumble_core::springs::IMPLICIT_OMEGA_DT) is stepped instead by the energy-conserving implicit step of
//! [`tumble_core::springs::implicit`], as a whole: stable at any stiffness, momenta kept
//! exactly, no numerical damping, and kinetic plus elastic energy conserved exactly where the
//! bodies turn by the implicit midpoint (below). `ω` is bounded above per body, over
//! all of its springs and with the anchors' lever arms:
//! `ω² ≤ max_bodies Σ_(its springs) k (ι_a + ι_b)`, `ι = 1/m + |r|² max I⁻¹` per end (a
//! Gershgorin-style bound on the group's stiffness matrix, exact for the top mode of a uniform
//! chain; one spring's own `k (ι_a + ι_b)` misses that a body pulled by several springs vibrates
//! faster, by up to √degree). So a group is never stiffer than the classification assumed. Soft
//! groups pay nothing: their bodies stay on the explicit path. `Δt` here is the world's step, or
//! [`AUTO_REFERENCE_DT`](tumble_core::springs::AUTO_REFERENCE_DT) (1/60 s) where that is finer,
//! so that refining the step never switches a group from implicit to explicit (a `Δt` sweep
//! under the defaults keeps one discretisation below 1/60 s), as the span of the plain
//! step whose explicit spring step is as accurate as one substep (`Stages::accuracy_span`:
//! `Δt/N` with `N` substeps; `0.44 Δt/N` with `yoshida4`'s composition, whose explicit step
//! swings a spring's energy by 2.3 % only at `ωh = 0.68`, and is stable up to 1.57); in a step
//! of several stages the implicit step runs once per stage, over the
//! stage's span (the backward stage of the composition included: implicit midpoint is
//! symmetric, so the composition keeps its order).
//!
//! [`PhysicsSettings::springs`](crate::components::PhysicsSettings::springs) overrides the choice
//! for a world ([`SpringSolver`](crate::components::SpringSolver)). The classification is made when the schedule is planned and
//! redone when the time step, the setting or the number of springs changes (a
//! [`PhysicsRunner`](crate::schedule::PhysicsRunner) notices); after changing a spring's stiffness
//! or a body's mass in place, re-insert the spring (or plan again) to re-classify.
//!
//! ### Which rotation the implicit step runs
//!
//! The implicit step solves each body's translation together with the springs (implicit
//! midpoint, the springs' discrete gradient), and turns it one of two ways
//! ([`GroupRotation`](tumble_core::springs::GroupRotation)):
//!
//! - **By the world's integrator** — its torque-free flow (`splitting`'s split, `exact`'s
//!   elliptic functions, …) at the step's mean world momentum, with the springs' torques solved
//!   with it. Torque-free this is that integrator's own step; with springs, momenta are kept
//!   exactly and the energy to the method's accuracy, about `(ω_turn Δt)²/4` of the energy the
//!   springs exchange with the body's rotation. `splitting`, `splitting-xyz` and `yoshida4`
//!   switch a fast thin body to `exact`/`exact4` here as everywhere
//!   ([`FreeFlow`](tumble_core::integrate::FreeFlow)). A body takes this turn where its
//!   springs turn it slowly, `ω_turn <` [`METHOD_TURN_RATE`](tumble_core::springs::METHOD_TURN_RATE)
//!   (1.8 rad/s: 0.03 rad in a step of 1/60 s, the energy they exchange with its rotation kept
//!   to ≈ 2e-4 of it there): a wheel or a rotor on stiff springs at its axle, a light spinning
//!   body hung by its centre. There the implicit midpoint would lag a spin's phase by
//!   `(|ω|Δt)²/12` a step, 4e-2 rad over 10 s at 5 rad/s and 60 Hz. A rate, not an `ωΔt`, so
//!   that refining `Δt` never changes the choice (a convergence study would mix two
//!   discretisations); only steps over 1/6 s, where `ω_turn Δt` would reach
//!   [`IMPLICIT_OMEGA_DT`](tumble_core::springs::IMPLICIT_OMEGA_DT), fall back to the midpoint.
//! - **By the implicit midpoint** (Cayley rotation by the mean body rate, Euler's equations at
//!   the midpoint) otherwise: kinetic plus elastic energy kept exactly at any stiffness. Where
//!   springs turn a body stiffly, the method's free flow with stiff torques between its turns
//!   is an explicit rotation under them, as unstable as the explicit spring step (measured: a
//!   free net's energy grows eighteenfold in 300 steps at `ωΔt` 10), and its spin is mostly
//!   theirs (a swinging chain link).
//!
//! `ω_turn² = Σ_(its spring ends) k c`, `c` the end's
//! [`turning_compliance`](tumble_core::springs::turning_compliance) (the largest
//! `(r × n)ᵀ I⁻¹ (r × n)` over directions, `r` the anchor's arm from the centre of mass), is
//! fixed when the springs are classified, as the choice is: the same for every stage of a run
//! (a composition stays symmetric), it changes only with the springs, the masses or the setting
//! (and steps over 1/6 s), and `--plan` says it.
//!
//! The first-order methods (`symplectic-euler`, `symplectic-euler-linear`, `lclamp`,
//! `implicit-gyroscopic`) have no torque-free flow at constant momentum to combine: an implicit
//! group under them is refused — the planner warns
//! ([`StabilityWarning::CannotCombine`](crate::stability::StabilityWarning::CannotCombine), which
//! the CLI refuses to run) and the step records
//! [`ImplicitSpringError::CannotCombine`](tumble_core::springs::ImplicitSpringError::CannotCombine)
//! for each body of the group, which keeps its state. Use springs = `explicit` with a time step
//! small enough for the springs, or a drift–kick–drift method. `tumble run --plan` and the
//! run's warnings say which bodies turn which way.
//!
//! Bodies of an implicit group are marked [`ImplicitBody`](crate::components::ImplicitBody) and their springs [`ImplicitSpring`](crate::components::ImplicitSpring):
//! the half drift and the explicit integrate systems skip them, `apply_springs` skips their
//! springs, and [`solve_implicit_springs`] steps them, reading every other load (gravity,
//! constant forces, game forces) from their accumulators, held constant over the stage.
//!
//! ## Spring dampers
//!
//! Spring dampers as a velocity flow of their own, half a step before the step and half a step
//! after it (see [`tumble_core::damping`] for why that keeps the step second order).
//!
//! The damper of one [`Spring`](crate::components::Spring) (coefficient `c`, axis `n` from the second end to the first)
//! acts on the relative anchor velocity along the axis, `u = J v = (ṗ_a − ṗ_b)·n` with
//! `ṗ = v + ω × r` (`r` the anchor's lever arm from the centre of mass). Alone, at fixed
//! positions, it obeys `m_eff u̇ = −c u` with the effective mass
//!
//! ```text
//! 1/m_eff = J M⁻¹ Jᵀ = 1/m_a + (r_a × n)·I_a⁻¹ (r_a × n) + 1/m_b + (r_b × n)·I_b⁻¹ (r_b × n)
//! ```
//!
//! (world inverse inertia; a world anchor, a [`Static`](crate::components::Static) or a [`Kinematic`](crate::components::Kinematic) end is infinitely
//! massive and contributes 0), whose flow over `τ` is `u(τ) = e^{−cτ/m_eff} u`. It is applied as
//! the impulse `P = m_eff (e^{−cτ/m_eff} − 1) u` along `n` at anchor `a` and `−P n` at anchor `b`
//! (with the torques `r × (±P n)`), the exponential replaced by [`decrement`](tumble_core::damping::decrement) (`1 − e^{−x}` to
//! `O(x⁴)`, never above 1, no platform `exp`). The kinetic energy changes by `½ m_eff u² (f² − 1) ≤ 0`, `f ∈ [0, 1]` the
//! decay factor: a damper never adds energy, however large `cΔt`.
//!
//! Springs that share a body are swept one after another: at the start of the step in entity
//! order ([`damp_springs_start`]), at the end in the reverse order ([`damp_springs_end`]), so the
//! end sweep is the adjoint of the start sweep and the whole step stays symmetric. Entity order
//! (the order the springs were spawned in) rather than the order a query visits the tables in,
//! which depends on what else the world made before the system's query (as do the sums of an
//! implicit group, over its bodies and springs in entity order).

mod classify;
mod damping;
mod implicit_step;

pub use classify::{
    Classification, ClassifiedSpring, SpringClassification, classification_is_stale, classify,
    classify_springs,
};
pub(crate) use classify::{ClassifiedInputs, classification_is_stale_with};
pub use damping::{damp_springs_end, damp_springs_start};
pub use implicit_step::solve_implicit_springs;

pub(crate) use classify::classification_span;

pub(crate) use damping::is_damped;

// Scratch memory of `solve_implicit_springs`, in its signature; not for game code.
#[doc(hidden)]
pub use implicit_step::ImplicitScratch;
