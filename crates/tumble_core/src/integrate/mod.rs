//! Time integrators: one file per method, one [`Integrator`] enum, one entry point per step.
//!
//! Every method advances a [`BodyState`] by `Δt` under a [`Wrench`] held constant over the step
//! (zero-order hold: forces are sampled once per step, as a game loop does).

mod symplectic_euler;

use std::fmt;
use std::str::FromStr;

use thiserror::Error;

use crate::mass::MassProperties;
use crate::state::{BodyState, Wrench};

pub use symplectic_euler::{explicit_gyroscopic_kick, symplectic_euler, symplectic_euler_linear};

/// A time-integration method, selectable per world.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Integrator {
    /// The textbook semi-implicit (symplectic) Euler step:
    /// `v += Δt F/m; x += Δt v; ω += Δt I⁻¹(τ − ω × Iω); q ← exp(½Δt ω) q`.
    /// First order; the explicit gyroscopic term diverges for fast asymmetric spins.
    #[default]
    SymplecticEuler,
    /// As [`SymplecticEuler`](Self::SymplecticEuler) but with the linearized rotation update
    /// `q ← normalize(q + ½Δt (ω,0) q)`, the common shortcut, kept to show its error.
    SymplecticEulerLinear,
}

impl Integrator {
    /// Every integrator, in the order the report lists them.
    pub const ALL: &'static [Integrator] = &[
        Integrator::SymplecticEuler,
        Integrator::SymplecticEulerLinear,
    ];

    /// The kebab-case name used in scene files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Integrator::SymplecticEuler => "symplectic-euler",
            Integrator::SymplecticEulerLinear => "symplectic-euler-linear",
        }
    }

    /// Nominal order of accuracy of the rotational update.
    pub fn order(self) -> u32 {
        match self {
            Integrator::SymplecticEuler | Integrator::SymplecticEulerLinear => 1,
        }
    }

    /// Advances `state` by `dt` under `wrench`. The caller checks finiteness (see
    /// [`try_step`](Self::try_step)).
    #[inline]
    pub fn step(self, state: &mut BodyState, mass: &MassProperties, wrench: &Wrench, dt: f32) {
        match self {
            Integrator::SymplecticEuler => symplectic_euler(state, mass, wrench, dt),
            Integrator::SymplecticEulerLinear => symplectic_euler_linear(state, mass, wrench, dt),
        }
    }

    /// Advances `state` by `dt` and commits the result only if it is finite; otherwise `state`
    /// is left unchanged and [`StepError::Diverged`] is returned.
    #[inline]
    pub fn try_step(
        self,
        state: &mut BodyState,
        mass: &MassProperties,
        wrench: &Wrench,
        dt: f32,
    ) -> Result<(), StepError> {
        let mut next = *state;
        self.step(&mut next, mass, wrench, dt);
        if next.is_finite() {
            *state = next;
            Ok(())
        } else {
            Err(StepError::Diverged { integrator: self })
        }
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
    /// The step produced NaN or Inf: the setting is outside the method's stable region.
    #[error("integrator `{integrator}` diverged (non-finite state); the body was left unchanged")]
    Diverged {
        /// The method that diverged.
        integrator: Integrator,
    },
}
