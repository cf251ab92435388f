//! Time integrators: one file per method, one [`Integrator`] enum, one entry point per step.
//!
//! Every method advances a [`BodyState`] by `Δt` under a [`Wrench`] held constant over the step
//! (zero-order hold: forces are sampled once per step, as a game loop does). A step has two
//! phases so that the ECS can sample forces where each method wants them:
//!
//! - [`Integrator::begin_step`] — before the forces are computed. The drift–kick–drift methods
//!   (`splitting`, `yoshida4`, `rk4`) drift half a step here, so forces are sampled at the
//!   midpoint (exact for constant forces, symplectic second order for springs). The kick–drift
//!   methods (`symplectic-euler*`, `lclamp`, `implicit-gyroscopic`) sample at the start and do
//!   nothing here.
//! - [`Integrator::finish_step`] — after the forces: kick, then the rest of the drift.
//!
//! [`Integrator::step`] runs both with a given constant wrench; [`Integrator::step_with`] samples
//! a state-dependent load between them.
//!
//! | method | rotation | order (torque-free) | `\|L\|` | energy |
//! |---|---|---|---|---|
//! | `symplectic-euler` | explicit `ω × Iω`, exact `exp` | 1 | grows | grows, diverges for fast spins |
//! | `symplectic-euler-linear` | as above, `q += ½Δt ω q` | 1 | grows | grows |
//! | `lclamp` | explicit, `\|L\|` rescaled | 1 | kept | drifts (stable spins tumble) |
//! | `implicit-gyroscopic` | one Newton step, backward Euler | 1 | decays | decays |
//! | `splitting` | Lie–Poisson, exact symmetric top + residual | 2 | round-off | bounded |
//! | `splitting-xyz` | Lie–Poisson Strang 1-2-3-2-1 | 2 | round-off | bounded (poorly for rods) |
//! | `yoshida4` | Yoshida composition of `splitting` | 4 | round-off | bounded |
//! | `rk4` | RK4 on `Q̇ = ½ ω(Q) Q` at constant `L` | 4 | exact | slow drift |

mod batch;
pub use batch::{BodyBatch, StepPhase};
mod frame;
mod implicit_gyroscopic;
mod lclamp;
mod rk4;
mod simd;
mod splitting;
mod symmetric_kernel;
mod symplectic_euler;
#[cfg(test)]
mod tests;
mod yoshida;

use crate::math::Real;
use std::fmt;
use std::str::FromStr;

use thiserror::Error;

use crate::mass::MassProperties;
use crate::state::{BodyState, Wrench};

// The public surface is the `Integrator` enum, the batch interface, the kernel path and the two
// frame rotations the tests and reports measure with; each method's functions are internal.
pub use frame::{rotate, rotate_inv};
use implicit_gyroscopic::implicit_gyroscopic;
use lclamp::lclamp;
use rk4::rk4_free_flow;
pub use simd::{KERNEL_ENV, KernelError, KernelPath, kernel_path};
use splitting::{
    Rotation, drift_kick_drift, rotate_freely, rotate_symmetric, rotate_yoshida, strang_free_flow,
};
use symplectic_euler::{symplectic_euler, symplectic_euler_linear};

/// A time-integration method, selectable per world.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Integrator {
    /// The textbook semi-implicit (symplectic) Euler step:
    /// `v += Δt F/m; x += Δt v; ω += Δt I⁻¹(τ − ω × Iω); q ← exp(½Δt ω) q`.
    /// First order; the explicit gyroscopic term diverges for fast asymmetric spins.
    SymplecticEuler,
    /// As [`SymplecticEuler`](Self::SymplecticEuler) but with the linearized rotation update
    /// `q ← normalize(q + ½Δt (ω,0) q)`, the common shortcut, kept to show its error.
    SymplecticEulerLinear,
    /// The explicit step with `|L|` rescaled to its expected length, as rapier (default), avian
    /// and Jolt do. First order; kept as the reference point.
    Lclamp,
    /// Catto's implicit gyroscopic step: one Newton iteration of backward Euler on
    /// `I(ω' − ω) + Δt ω' × Iω' = 0`. First order, dissipative.
    ImplicitGyroscopic,
    /// Lie–Poisson splitting into an exact symmetric top plus a residual axis rotation (Strang
    /// `R(h/2) S(h) R(h/2)`), in a drift–kick–drift step. Second order, symplectic,
    /// time-reversible, `|L|` kept to round-off, exact for symmetric bodies.
    #[default]
    Splitting,
    /// Lie–Poisson splitting one principal axis at a time (Strang 1-2-3-2-1), in a
    /// drift–kick–drift step. Second order, symplectic; unstable in energy for fast thin rods.
    SplittingXyz,
    /// Yoshida's fourth-order composition of [`Splitting`](Self::Splitting)'s free flow.
    Yoshida4,
    /// Classic RK4 on the free rotation at constant `L`, in a drift–kick–drift step.
    Rk4,
}

impl Integrator {
    /// Every integrator, in the order the report lists them.
    pub const ALL: &'static [Integrator] = &[
        Integrator::SymplecticEuler,
        Integrator::SymplecticEulerLinear,
        Integrator::Lclamp,
        Integrator::ImplicitGyroscopic,
        Integrator::Splitting,
        Integrator::SplittingXyz,
        Integrator::Yoshida4,
        Integrator::Rk4,
    ];

    /// The kebab-case name used in scene files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Integrator::SymplecticEuler => "symplectic-euler",
            Integrator::SymplecticEulerLinear => "symplectic-euler-linear",
            Integrator::Lclamp => "lclamp",
            Integrator::ImplicitGyroscopic => "implicit-gyroscopic",
            Integrator::Splitting => "splitting",
            Integrator::SplittingXyz => "splitting-xyz",
            Integrator::Yoshida4 => "yoshida4",
            Integrator::Rk4 => "rk4",
        }
    }

    /// Nominal order of accuracy of the torque-free rotational motion.
    pub fn order(self) -> u32 {
        match self {
            Integrator::SymplecticEuler
            | Integrator::SymplecticEulerLinear
            | Integrator::Lclamp
            | Integrator::ImplicitGyroscopic => 1,
            Integrator::Splitting | Integrator::SplittingXyz => 2,
            Integrator::Yoshida4 | Integrator::Rk4 => 4,
        }
    }

    /// True when the method drifts half a step before forces are sampled (see
    /// [`begin_step`](Self::begin_step)); false when it samples forces at the start of the step.
    pub fn samples_forces_at_midpoint(self) -> bool {
        !matches!(
            self,
            Integrator::SymplecticEuler
                | Integrator::SymplecticEulerLinear
                | Integrator::Lclamp
                | Integrator::ImplicitGyroscopic
        )
    }

    /// The free rotation of a drift–kick–drift method.
    fn free_rotation(self) -> Rotation {
        match self {
            Integrator::Yoshida4 => rotate_yoshida,
            Integrator::Rk4 => |s, m, h| rotate_freely(s, m, h, rk4_free_flow),
            Integrator::SplittingXyz => |s, m, h| rotate_freely(s, m, h, strang_free_flow),
            _ => rotate_symmetric,
        }
    }

    /// First phase of a step, before forces are sampled: half a drift for the drift–kick–drift
    /// methods, nothing for the others.
    #[inline]
    pub fn begin_step(self, state: &mut BodyState, mass: &MassProperties, dt: Real) {
        if self.samples_forces_at_midpoint() {
            let rotation = self.free_rotation();
            drift_kick_drift(StepPhase::Begin, state, mass, &Wrench::ZERO, dt, rotation);
        }
    }

    /// Second phase of a step, with the load sampled after [`begin_step`](Self::begin_step).
    #[inline]
    pub fn finish_step(
        self,
        state: &mut BodyState,
        mass: &MassProperties,
        wrench: &Wrench,
        dt: Real,
    ) {
        match self {
            Integrator::SymplecticEuler => symplectic_euler(state, mass, wrench, dt),
            Integrator::SymplecticEulerLinear => symplectic_euler_linear(state, mass, wrench, dt),
            Integrator::Lclamp => lclamp(state, mass, wrench, dt),
            Integrator::ImplicitGyroscopic => implicit_gyroscopic(state, mass, wrench, dt),
            Integrator::Splitting
            | Integrator::SplittingXyz
            | Integrator::Yoshida4
            | Integrator::Rk4 => {
                let rotation = self.free_rotation();
                drift_kick_drift(StepPhase::Finish, state, mass, wrench, dt, rotation);
            }
        }
    }

    /// A whole step under a constant `wrench`. The caller checks the result (see
    /// [`try_step`](Self::try_step)).
    ///
    /// For the drift–kick–drift methods a torque-free step takes its rotation as one free flow
    /// over `Δt` instead of two halves (nothing is kicked between them): half the cost, same
    /// order. The ECS takes this path for bodies without a `ForceAccumulator`.
    #[inline]
    pub fn step(self, state: &mut BodyState, mass: &MassProperties, wrench: &Wrench, dt: Real) {
        if self.samples_forces_at_midpoint() {
            let rotation = self.free_rotation();
            drift_kick_drift(StepPhase::Whole, state, mass, wrench, dt, rotation);
        } else {
            // The kick–drift methods do nothing before the forces: the step is its second phase.
            self.finish_step(state, mass, wrench, dt);
        }
    }

    /// `phase` of a step: [`step`](Self::step), [`begin_step`](Self::begin_step) (the load is
    /// not used) or [`finish_step`](Self::finish_step).
    #[inline]
    fn step_phase(
        self,
        phase: StepPhase,
        state: &mut BodyState,
        mass: &MassProperties,
        wrench: &Wrench,
        dt: Real,
    ) {
        match phase {
            StepPhase::Whole => self.step(state, mass, wrench, dt),
            StepPhase::Begin => self.begin_step(state, mass, dt),
            StepPhase::Finish => self.finish_step(state, mass, wrench, dt),
        }
    }

    /// A whole step with a state-dependent load, sampled where the method wants it (after
    /// [`begin_step`](Self::begin_step)).
    #[inline]
    pub fn step_with(
        self,
        state: &mut BodyState,
        mass: &MassProperties,
        dt: Real,
        load: impl FnOnce(&BodyState) -> Wrench,
    ) {
        self.begin_step(state, mass, dt);
        let wrench = load(state);
        self.finish_step(state, mass, &wrench, dt);
    }

    /// Advances `state` by `dt` and commits the result only if it is valid (finite, with a unit
    /// rotation: [`BodyState::is_valid`]); otherwise `state` is left unchanged and
    /// [`StepError::Diverged`] is returned.
    #[inline]
    pub fn try_step(
        self,
        state: &mut BodyState,
        mass: &MassProperties,
        wrench: &Wrench,
        dt: Real,
    ) -> Result<(), StepError> {
        self.commit_if_valid(state, |next| self.step(next, mass, wrench, dt))
    }

    /// [`finish_step`](Self::finish_step) that commits only a valid result (see
    /// [`try_step`](Self::try_step)).
    #[inline]
    pub fn try_finish_step(
        self,
        state: &mut BodyState,
        mass: &MassProperties,
        wrench: &Wrench,
        dt: Real,
    ) -> Result<(), StepError> {
        self.commit_if_valid(state, |next| self.finish_step(next, mass, wrench, dt))
    }

    /// Runs `advance` on a copy of `state` and commits the copy only if it is valid.
    #[inline]
    fn commit_if_valid(
        self,
        state: &mut BodyState,
        advance: impl FnOnce(&mut BodyState),
    ) -> Result<(), StepError> {
        let mut next = *state;
        advance(&mut next);
        if next.is_valid() {
            *state = next;
            Ok(())
        } else {
            Err(StepError::Diverged { integrator: self })
        }
    }

    /// [`begin_step`](Self::begin_step) that commits only a valid result (see
    /// [`try_step`](Self::try_step)).
    #[inline]
    pub fn try_begin_step(
        self,
        state: &mut BodyState,
        mass: &MassProperties,
        dt: Real,
    ) -> Result<(), StepError> {
        self.commit_if_valid(state, |next| self.begin_step(next, mass, dt))
    }
}

impl fmt::Display for Integrator {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// An integrator name that is not known.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
#[error("unknown integrator `{name}`; expected one of: {}", Integrator::ALL.iter().map(|i| i.name()).collect::<Vec<_>>().join(", "))]
pub struct UnknownIntegrator {
    /// The name that was given.
    pub name: String,
}

impl FromStr for Integrator {
    type Err = UnknownIntegrator;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Integrator::ALL
            .iter()
            .copied()
            .find(|i| i.name() == s)
            .ok_or_else(|| UnknownIntegrator { name: s.to_owned() })
    }
}

/// A step that could not be taken.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Error)]
pub enum StepError {
    /// The step produced NaN or Inf, or a rotation that is no longer a unit quaternion (see
    /// [`BodyState::is_valid`]): the setting is outside the method's stable region.
    #[error(
        "integrator `{integrator}` diverged (non-finite state or non-unit rotation); the body was left unchanged"
    )]
    Diverged {
        /// The method that diverged.
        integrator: Integrator,
    },
}
