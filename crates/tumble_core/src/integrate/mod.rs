//! Time integrators: one file per method, one [`Integrator`] enum, one entry point per step.
//!
//! A step of `Δt` is a sequence of *stages* ([`Stages`]): one for most methods, three for
//! `yoshida4`'s composition, and `N` times as many with `N` substeps. Each stage advances a
//! [`BodyState`] over its span `h` under a [`Wrench`] held constant over the stage (sampled once
//! per stage). A stage has two phases so that the ECS can sample forces where each method wants
//! them:
//!
//! - [`Integrator::begin_stage`] — before the forces are computed. The drift–kick–drift methods
//!   (`splitting`, `yoshida4`, `rk4`) drift half a stage here, so forces are sampled at the
//!   midpoint (exact for constant forces, symplectic second order for springs). The kick–drift
//!   methods (`symplectic-euler*`, `lclamp`, `implicit-gyroscopic`) sample at the start and do
//!   nothing here.
//! - [`Integrator::finish_stage`] — after the forces: kick, then the rest of the drift.
//!
//! [`Integrator::step`] runs a whole step under a given constant wrench;
//! [`Integrator::step_with`] samples a state-dependent load in every stage.
//!
//! | method | rotation | order (torque-free) | order (with loads) | `\|L\|` | energy |
//! |---|---|---|---|---|---|
//! | `symplectic-euler` | explicit `ω × Iω`, exact `exp` | 1 | 1 | grows | grows, diverges for fast spins |
//! | `symplectic-euler-linear` | as above, `q += ½Δt ω q` | 1 | 1 | grows | grows |
//! | `lclamp` | explicit, `\|L\|` rescaled | 1 | 1 | kept | drifts (stable spins tumble) |
//! | `implicit-gyroscopic` | one Newton step, backward Euler | 1 | 1 | decays | decays |
//! | `splitting` | Lie–Poisson, exact symmetric top + residual | 2 | 2 | round-off | bounded |
//! | `splitting-xyz` | Lie–Poisson Strang 1-2-3-2-1 | 2 | 2 | round-off | bounded (poorly for rods) |
//! | `yoshida4` | triple jump of `splitting`'s whole step | 4 | 4 | round-off | bounded |
//! | `rk4` | RK4 on `Q̇ = ½ ω(Q) Q` at constant `L` | 4 | 2 | exact | slow drift |
//! | `exact` | exact torque-free flow (Jacobi elliptic functions, Carlson `R_J`) | exact | 2 | round-off | round-off torque-free |
//! | `exact4` | triple jump of `exact`'s whole step | exact | 4 | round-off | round-off torque-free |

mod batch;
mod body_batch;
mod drift_kick_drift;
mod exact_flow;
pub use body_batch::BodyBatch;
mod frame;
mod free_flow;
pub use free_flow::{
    ACCURACY_HORIZON, COMPOSED_SPLIT_ERROR_LIMIT, ExactSwitch, FreeFlow, SPLIT_DRIFT_TOLERANCE,
    SPLIT_ERROR_LIMIT, split_orbit_error, split_rotation_drift, split_rotation_error,
};
mod implicit_gyroscopic;
mod kick_drift;
mod kick_drift_kernel;
mod lane_input;
mod lanes;
mod lclamp;
mod momentum_flow;
mod pending;
pub(crate) use momentum_flow::free_turn;
mod rk4;
mod splitting;
mod stages;
pub use stages::{StageSpan, Stages, StepPhase, TRIPLE_JUMP_LIMIT, TRIPLE_JUMP_SWING_MATCH};
mod symmetric_kernel;
mod symplectic_euler;
#[cfg(test)]
mod tests;

use crate::math::{Real, Vec3};
use std::fmt;
use std::str::FromStr;

use thiserror::Error;

use crate::mass::MassProperties;
use crate::state::{BodyState, Wrench};

// The public surface is the `Integrator` enum, the batch interface, the kernel path (and its
// operation count) and the two frame rotations the tests and reports measure with; each
// method's functions are internal.
pub use crate::simd::{KERNEL_ENV, KernelError, KernelPath, OpCounts, kernel_path};
use drift_kick_drift::{Rotation, drift_kick_drift, drift_kick_drift_translation, kick_angular};
use exact_flow::rotate_exactly;
pub use frame::{rotate, rotate_inv};
use kick_drift_kernel::{KickDrift, kick_drift_step};
use splitting::{rotate_kicked_on_kernel, rotate_symmetric_kicked};
use symmetric_kernel::LaneFlow;
pub use symmetric_kernel::symmetric_rotation_flops;

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
    /// Yoshida's fourth-order triple jump of [`Splitting`](Self::Splitting)'s whole
    /// drift–kick–drift step (three stages, forces sampled in each; see [`Stages`]): fourth
    /// order with forces, springs and torques, symplectic and time-reversible.
    Yoshida4,
    /// Classic RK4 on the free rotation at constant `L`, in a drift–kick–drift step: fourth
    /// order torque-free only; with any load the step is second order (the forces are sampled
    /// once per step, at its midpoint: it is not an RK4 of the whole motion).
    ///
    /// Its equation `q̇ = ½ ω(q) q`, `ω(q) = R I⁻¹ Rᵀ L`, is stiff with rate `|L|/I_min`: a trial
    /// orientation off the path by `δ` tilts `L` into the thinnest axis and spins it at
    /// `|L|δ/I_min`. Accurate only for `|L|Δt/I_min ≲ 0.5` (3 rad off over 10 s at 1.0 on a box,
    /// 0.3 rad at 110 on a slow rod); the planner warns beyond.
    Rk4,
    /// Drift–kick–drift with the *exact* torque-free rotation as its free flow (Jacobi's
    /// elliptic functions for the body momentum, an elliptic integral of the third kind for the
    /// attitude; see `exact_flow`): torque-free bodies of any inertia are exact to round-off at
    /// any `Δt` and any spin rate, thin asymmetric bodies included; with loads it is second
    /// order, like `splitting`, whose step it shares.
    Exact,
    /// Yoshida's fourth-order triple jump of [`Exact`](Self::Exact)'s whole drift–kick–drift
    /// step (three stages, forces sampled in each, as [`Yoshida4`](Self::Yoshida4) composes
    /// `splitting`): torque-free bodies exact to round-off, fourth order with forces, springs
    /// and torques.
    Exact4,
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
        Integrator::Exact,
        Integrator::Exact4,
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
            Integrator::Exact => "exact",
            Integrator::Exact4 => "exact4",
        }
    }

    /// Nominal order of accuracy of the torque-free rotational motion (with loads: 4 for
    /// `yoshida4`, at most 2 for the others). `exact` is exact torque-free (see
    /// [`is_exact_torque_free`](Self::is_exact_torque_free)); its order here is the one it has
    /// with loads, 2.
    pub fn order(self) -> u32 {
        match self {
            Integrator::Exact => 2,
            Integrator::Exact4 => 4,
            Integrator::SymplecticEuler
            | Integrator::SymplecticEulerLinear
            | Integrator::Lclamp
            | Integrator::ImplicitGyroscopic => 1,
            Integrator::Splitting | Integrator::SplittingXyz => 2,
            Integrator::Yoshida4 | Integrator::Rk4 => 4,
        }
    }

    /// True when the torque-free motion is exact to round-off at any step (`exact`, `exact4`).
    pub fn is_exact_torque_free(self) -> bool {
        matches!(self, Integrator::Exact | Integrator::Exact4)
    }

    /// The method with this one's drift–kick–drift step and composition and the exact free
    /// flow in place of its split one (`splitting`, `splitting-xyz` → `exact`; `yoshida4` →
    /// `exact4`): what [`FreeFlow::Auto`] steps a fast-spinning body with. `None` for a method
    /// whose free rotation is not split.
    pub fn exact_counterpart(self) -> Option<Integrator> {
        match self {
            Integrator::Splitting | Integrator::SplittingXyz => Some(Integrator::Exact),
            Integrator::Yoshida4 => Some(Integrator::Exact4),
            _ => None,
        }
    }

    /// True when the method turns a body by a torque-free flow that keeps the world momentum
    /// (the drift–kick–drift methods: `splitting`, `splitting-xyz`, `yoshida4`, `rk4`, `exact`,
    /// `exact4`): the methods the implicit spring step can run inside a stiff spring group (see
    /// [`crate::springs::implicit`]). The first-order methods update `ω` with a gyroscopic
    /// term instead.
    pub fn turns_at_constant_momentum(self) -> bool {
        self.samples_forces_at_midpoint()
    }

    /// True when the method drifts half a stage before forces are sampled (see
    /// [`begin_stage`](Self::begin_stage)); false when it samples forces at the start.
    pub fn samples_forces_at_midpoint(self) -> bool {
        !matches!(
            self,
            Integrator::SymplecticEuler
                | Integrator::SymplecticEulerLinear
                | Integrator::Lclamp
                | Integrator::ImplicitGyroscopic
        )
    }

    /// The weights of the stages one step (or substep) is made of, summing to 1: the
    /// triple jump `(c₁, c₀, c₁)` for `yoshida4` (see [`Stages`]), a single stage of weight 1 for
    /// every other method.
    pub fn composition(self) -> &'static [Real] {
        match self {
            Integrator::Yoshida4 | Integrator::Exact4 => &stages::TRIPLE_JUMP,
            _ => &stages::SINGLE,
        }
    }

    /// True when the batched step runs the method's free rotation on the lane kernel of
    /// `symmetric_kernel` (`splitting`, `splitting-xyz`, `rk4`, and `yoshida4`, a composition
    /// of `splitting`): see [`lane_flow`](Self::lane_flow).
    fn rotates_on_symmetric_kernel(self) -> bool {
        self.lane_flow().is_some()
    }

    /// The free flow the lane kernel of `symmetric_kernel` runs for this method, without its
    /// kick (`yoshida4`'s stages are `splitting`'s flow).
    fn lane_flow(self) -> Option<LaneFlow> {
        match self {
            Integrator::Splitting | Integrator::Yoshida4 => {
                Some(LaneFlow::Symmetric { kicks: false })
            }
            Integrator::SplittingXyz => Some(LaneFlow::Xyz { kicks: false }),
            Integrator::Rk4 => Some(LaneFlow::Rk4 { kicks: false }),
            _ => None,
        }
    }

    /// The SIMD path the batched step rotates the method's bodies on: the
    /// [`kernel_path`] for every method with a lane kernel (the free-flow kernel of
    /// `symmetric_kernel`, or the four kick–drift methods' own), the portable one (unused) for
    /// `exact` and `exact4`, which need none.
    fn lane_kernel(self) -> crate::simd::Kernel {
        if self.rotates_on_symmetric_kernel() || KickDrift::of(self).is_some() {
            crate::simd::Kernel::selected()
        } else {
            crate::simd::Kernel::Portable
        }
    }

    /// The free rotation of a drift–kick–drift method, after the kick's angular impulse:
    /// `splitting`'s folds it into its body momentum, the others kick `ω` first.
    fn free_rotation(self) -> Rotation {
        match self {
            Integrator::Rk4 => |s, m, h, j| {
                rotate_kicked_on_kernel(s, m, h, j, LaneFlow::Rk4 { kicks: true });
            },
            Integrator::Exact | Integrator::Exact4 => |s, m, h, j| {
                kick_angular(s, m, j);
                rotate_exactly(s, m, h);
            },
            Integrator::SplittingXyz => |s, m, h, j| {
                rotate_kicked_on_kernel(s, m, h, j, LaneFlow::Xyz { kicks: true });
            },
            _ => rotate_symmetric_kicked,
        }
    }

    /// First phase of one stage of span `h`, before forces are sampled: half a drift for the
    /// drift–kick–drift methods, nothing for the others. A whole step is the stages of
    /// [`composition`](Self::composition) (see [`step_with`](Self::step_with)).
    #[inline]
    pub fn begin_stage(self, state: &mut BodyState, mass: &MassProperties, h: Real) {
        if self.samples_forces_at_midpoint() {
            let rotation = self.free_rotation();
            drift_kick_drift(StepPhase::Begin, state, mass, &Wrench::ZERO, h, rotation);
        }
    }

    /// Second phase of one stage of span `h`, with the load sampled after
    /// [`begin_stage`](Self::begin_stage): kick, then the rest of the drift.
    #[inline]
    pub fn finish_stage(
        self,
        state: &mut BodyState,
        mass: &MassProperties,
        wrench: &Wrench,
        h: Real,
    ) {
        match self {
            Integrator::SymplecticEuler => {
                kick_drift_step(state, mass, wrench, h, KickDrift::Explicit);
            }
            Integrator::SymplecticEulerLinear => {
                kick_drift_step(state, mass, wrench, h, KickDrift::ExplicitLinear);
            }
            Integrator::Lclamp => kick_drift_step(state, mass, wrench, h, KickDrift::Clamped),
            Integrator::ImplicitGyroscopic => {
                kick_drift_step(state, mass, wrench, h, KickDrift::Implicit);
            }
            Integrator::Splitting
            | Integrator::SplittingXyz
            | Integrator::Yoshida4
            | Integrator::Rk4
            | Integrator::Exact
            | Integrator::Exact4 => {
                let rotation = self.free_rotation();
                drift_kick_drift(StepPhase::Finish, state, mass, wrench, h, rotation);
            }
        }
    }

    /// One whole stage of span `h` under a constant `wrench`.
    ///
    /// For the drift–kick–drift methods a torque-free stage takes its rotation as one free flow
    /// over `h` instead of two halves (nothing is kicked between them): half the cost, same
    /// order. The ECS takes this path for bodies without a `ForceAccumulator`.
    #[inline]
    pub fn whole_stage(
        self,
        state: &mut BodyState,
        mass: &MassProperties,
        wrench: &Wrench,
        h: Real,
    ) {
        if self.samples_forces_at_midpoint() {
            let rotation = self.free_rotation();
            drift_kick_drift(StepPhase::Whole, state, mass, wrench, h, rotation);
        } else {
            // The kick–drift methods do nothing before the forces: the stage is its second phase.
            self.finish_stage(state, mass, wrench, h);
        }
    }

    /// `phase` of one stage of span `h`: [`whole_stage`](Self::whole_stage),
    /// [`begin_stage`](Self::begin_stage) (the load is not used) or
    /// [`finish_stage`](Self::finish_stage).
    #[inline]
    fn stage(
        self,
        phase: StepPhase,
        state: &mut BodyState,
        mass: &MassProperties,
        wrench: &Wrench,
        h: Real,
    ) {
        match phase {
            StepPhase::Whole => self.whole_stage(state, mass, wrench, h),
            StepPhase::Begin => self.begin_stage(state, mass, h),
            StepPhase::Finish => self.finish_stage(state, mass, wrench, h),
        }
    }

    /// A whole step of `dt` under a constant `wrench`: the stages of
    /// [`composition`](Self::composition), each a [`whole_stage`](Self::whole_stage) of span
    /// `c dt`. The caller checks the result (see [`try_step`](Self::try_step)).
    ///
    /// Without torque a composed step's translation and rotation do not interact: under the
    /// constant force every drift–kick–drift translation is exact, so the stages' translations
    /// are one over `dt`, and their free rotations are composed in `f64` and rounded once (the
    /// ECS takes this path for bodies without a `ForceAccumulator`).
    #[inline]
    pub fn step(self, state: &mut BodyState, mass: &MassProperties, wrench: &Wrench, dt: Real) {
        let weights = self.composition();
        if weights.len() > 1 && wrench.torque == Vec3::ZERO {
            drift_kick_drift_translation(StepPhase::Whole, state, mass, wrench, dt);
            if self.is_exact_torque_free() {
                // Exact flows compose exactly: the stages' rotations are one flow over `dt`.
                (self.free_rotation())(state, mass, dt, Vec3::ZERO);
            } else {
                stages::rotate_composed(state, mass, weights, dt);
            }
            return;
        }
        for &c in weights {
            self.whole_stage(state, mass, wrench, c * dt);
        }
    }

    /// A whole step of `dt` with a state-dependent load, sampled afresh in every stage of the
    /// [`composition`](Self::composition), where the method wants it (after
    /// [`begin_stage`](Self::begin_stage)): `yoshida4` is then fourth order with any smooth
    /// load, the other drift–kick–drift methods second order.
    #[inline]
    pub fn step_with(
        self,
        state: &mut BodyState,
        mass: &MassProperties,
        dt: Real,
        mut load: impl FnMut(&BodyState) -> Wrench,
    ) {
        for &c in self.composition() {
            let h = c * dt;
            self.begin_stage(state, mass, h);
            let wrench = load(state);
            self.finish_stage(state, mass, &wrench, h);
        }
    }

    /// Advances `state` by `dt` ([`step`](Self::step)) and commits the result only if it is
    /// valid (finite, with a unit rotation: [`BodyState::is_valid`]); otherwise `state` is left
    /// unchanged and [`StepError::Diverged`] is returned.
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

    /// [`finish_stage`](Self::finish_stage) that commits only a valid result (see
    /// [`try_step`](Self::try_step)).
    #[inline]
    pub fn try_finish_stage(
        self,
        state: &mut BodyState,
        mass: &MassProperties,
        wrench: &Wrench,
        h: Real,
    ) -> Result<(), StepError> {
        self.commit_if_valid(state, |next| self.finish_stage(next, mass, wrench, h))
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

    /// [`begin_stage`](Self::begin_stage) that commits only a valid result (see
    /// [`try_step`](Self::try_step)).
    #[inline]
    pub fn try_begin_stage(
        self,
        state: &mut BodyState,
        mass: &MassProperties,
        h: Real,
    ) -> Result<(), StepError> {
        self.commit_if_valid(state, |next| self.begin_stage(next, mass, h))
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

/// Saved by name, as scene files and the command line name it (feature `serde`).
#[cfg(feature = "serde")]
impl serde::Serialize for Integrator {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.name())
    }
}

#[cfg(feature = "serde")]
impl<'de> serde::Deserialize<'de> for Integrator {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let name = <String as serde::Deserialize>::deserialize(d)?;
        name.parse().map_err(serde::de::Error::custom)
    }
}
