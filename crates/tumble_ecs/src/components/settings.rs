//! The world's settings: the step, its method, how springs step, gravity.

use std::num::NonZeroU32;

use bevy_ecs::prelude::*;
use tumble_core::integrate::{FreeFlow, Stages};
use tumble_core::math::{Real, Vec3};
use tumble_core::{Integrator, InvalidInput};

/// Uniform gravitational acceleration `g` (m/s²). Absent resource ⇒ no gravity system at all.
#[derive(Resource, Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Gravity(pub Vec3);

impl Gravity {
    /// Earth gravity along −y: `(0, −9.81, 0)`.
    pub const EARTH_Y_DOWN: Self = Self(Vec3::new(0.0, -9.81, 0.0));

    /// The acceleration the step applies: `None` where it is not finite (game code wrote a bad
    /// value), so that the step leaves gravity out instead of quarantining every body it would
    /// reach; [`PhysicsRunner`](crate::schedule::PhysicsRunner) records a
    /// [`WorldError`](crate::components::WorldError) for it.
    #[inline]
    pub fn field(&self) -> Option<Vec3> {
        self.0.is_finite().then_some(self.0)
    }
}

/// The step size and integrator of a world. The time step and the substeps are validated on
/// construction and their fields are private, so a world never holds a `Δt` (or a substep
/// `Δt/N`) that is not a positive, finite step the precision can take.
#[derive(Resource, Debug, Clone, Copy, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(try_from = "PhysicsSettingsData", into = "PhysicsSettingsData")
)]
pub struct PhysicsSettings {
    dt: Real,
    /// The integration method for every body of the world.
    pub integrator: Integrator,
    /// How springs are stepped: [`SpringSolver::Auto`] (the default) steps the spring groups
    /// that are stiff for `dt` with the energy-conserving implicit step and the others with the
    /// integrator (see [`crate::springs`]).
    pub springs: SpringSolver,
    /// Substeps per step, `N`: see [`PhysicsSettings::substeps`]. Private, like `dt`, so that
    /// `Δt/N` is always a step the precision can take.
    substeps: NonZeroU32,
    /// Which free rotation a split method (`splitting`, `splitting-xyz`, `yoshida4`) gives each
    /// body: under [`FreeFlow::Auto`] (the default) a body whose split free rotation would err by
    /// more than [`SPLIT_ERROR_LIMIT`](tumble_core::integrate::SPLIT_ERROR_LIMIT) in a stage
    /// (a fast spin, a thin body) takes the exact free flow of the same step for that stage
    /// (`exact`, `exact4`), and the planner says which bodies do; [`FreeFlow::Method`] keeps
    /// the method's own flow for every body (see [`tumble_core::integrate::FreeFlow`]).
    pub free_flow: FreeFlow,
}

impl PhysicsSettings {
    /// Settings with time step `dt` (s) and the given integrator; rejects `dt ≤ 0` and NaN/Inf.
    pub fn new(dt: Real, integrator: Integrator) -> Result<Self, InvalidInput> {
        tumble_core::error::check_time_step(dt)?;
        Ok(Self {
            dt,
            integrator,
            springs: SpringSolver::Auto,
            substeps: NonZeroU32::MIN,
            free_flow: FreeFlow::Auto,
        })
    }

    /// The same settings with `substeps` substeps per step (see
    /// [`substeps`](Self::substeps)); rejects a count that makes `Δt/N` too short for the
    /// precision to step ([`InvalidInput::SubstepOutOfRange`]).
    pub fn with_substeps(mut self, substeps: NonZeroU32) -> Result<Self, InvalidInput> {
        self.set_substeps(substeps)?;
        Ok(self)
    }

    /// Substeps per step, `N` (default 1): every step is `N` substeps of `Δt/N`, each running
    /// the force stage afresh (see [`Stages`]); `N` substeps of `Δt` are bit for bit `N` steps of
    /// `Δt/N`, except that a load game code added before the step is held over all of them
    /// (see [`ForceAccumulator`](super::ForceAccumulator)). Costs `N` times the step; use it
    /// when a force changes faster than the step resolves (a stiff contact-like spring, a
    /// control loop), not for accuracy alone — `yoshida4` is the cheaper way to a small error.
    #[inline]
    pub fn substeps(&self) -> NonZeroU32 {
        self.substeps
    }

    /// Changes the substeps per step; rejects a count that makes `Δt/N` too short for the
    /// precision to step ([`InvalidInput::SubstepOutOfRange`]) and then leaves the settings
    /// unchanged.
    pub fn set_substeps(&mut self, substeps: NonZeroU32) -> Result<(), InvalidInput> {
        tumble_core::error::check_substeps(self.dt, substeps)?;
        self.substeps = substeps;
        Ok(())
    }

    /// The stages of one step: the substeps times the integrator's composition.
    #[inline]
    pub fn stages(&self) -> Stages {
        Stages::new(self.integrator, self.substeps)
    }

    /// The same settings with split methods' free rotation chosen as `free_flow` says.
    pub fn with_free_flow(mut self, free_flow: FreeFlow) -> Self {
        self.free_flow = free_flow;
        self
    }

    /// The same settings with springs stepped as `springs` says.
    pub fn with_springs(mut self, springs: SpringSolver) -> Self {
        self.springs = springs;
        self
    }

    /// The fixed time step `Δt` (s).
    #[inline]
    pub fn dt(&self) -> Real {
        self.dt
    }

    /// Changes the time step; rejects `dt ≤ 0`, NaN/Inf, a step outside
    /// [`TIME_STEP_RANGE`](tumble_core::error::TIME_STEP_RANGE) and one whose substeps would be
    /// too short ([`InvalidInput::SubstepOutOfRange`]), and then leaves the settings unchanged.
    pub fn set_dt(&mut self, dt: Real) -> Result<(), InvalidInput> {
        tumble_core::error::check_substeps(dt, self.substeps)?;
        self.dt = dt;
        Ok(())
    }
}

/// The saved form of [`PhysicsSettings`], checked on load.
#[cfg(feature = "serde")]
#[derive(serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct PhysicsSettingsData {
    dt: Real,
    integrator: Integrator,
    #[serde(default)]
    springs: SpringSolver,
    #[serde(default = "one_substep")]
    substeps: NonZeroU32,
    #[serde(default)]
    free_flow: FreeFlow,
}

#[cfg(feature = "serde")]
fn one_substep() -> NonZeroU32 {
    NonZeroU32::MIN
}

#[cfg(feature = "serde")]
impl TryFrom<PhysicsSettingsData> for PhysicsSettings {
    type Error = InvalidInput;
    fn try_from(d: PhysicsSettingsData) -> Result<Self, InvalidInput> {
        Ok(PhysicsSettings::new(d.dt, d.integrator)?
            .with_springs(d.springs)
            .with_substeps(d.substeps)?
            .with_free_flow(d.free_flow))
    }
}

#[cfg(feature = "serde")]
impl From<PhysicsSettings> for PhysicsSettingsData {
    fn from(s: PhysicsSettings) -> Self {
        Self {
            dt: s.dt,
            integrator: s.integrator,
            springs: s.springs,
            substeps: s.substeps,
            free_flow: s.free_flow,
        }
    }
}

impl Default for PhysicsSettings {
    /// 60 Hz with the default integrator.
    fn default() -> Self {
        Self {
            dt: 1.0 / 60.0,
            integrator: Integrator::default(),
            springs: SpringSolver::Auto,
            substeps: NonZeroU32::MIN,
            free_flow: FreeFlow::Auto,
        }
    }
}

/// How a world steps its springs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(rename_all = "lowercase")
)]
pub enum SpringSolver {
    /// Implicit for the groups that can reach `ωΔt ≥` [`IMPLICIT_OMEGA_DT`](tumble_core::springs::IMPLICIT_OMEGA_DT), explicit for the
    /// others (the default).
    #[default]
    Auto,
    /// Every spring explicit (drift–kick–drift force): cheapest; diverges at `ωΔt ≥ 2`.
    Explicit,
    /// Every spring group implicit: energy-conserving at any stiffness.
    Implicit,
}

impl SpringSolver {
    /// Every setting, in declaration order.
    pub const ALL: [SpringSolver; 3] = [
        SpringSolver::Auto,
        SpringSolver::Explicit,
        SpringSolver::Implicit,
    ];

    /// The name used in scene files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            SpringSolver::Auto => "auto",
            SpringSolver::Explicit => "explicit",
            SpringSolver::Implicit => "implicit",
        }
    }
}

impl std::fmt::Display for SpringSolver {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for SpringSolver {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        SpringSolver::ALL
            .into_iter()
            .find(|m| m.name() == s)
            .ok_or_else(|| "expected one of `auto`, `explicit`, `implicit`".to_owned())
    }
}
