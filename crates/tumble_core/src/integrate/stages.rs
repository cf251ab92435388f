//! The stages of one step: substeps, and the fourth-order composition of `yoshida4`.
//!
//! A step of `Δt` is a sequence of *stages*, each one step of the method's basic scheme (a
//! drift–kick–drift `D(h/2) ∘ K(h) ∘ D(h/2)`, or a kick–drift) over its own span `h`, with the
//! forces sampled afresh in each stage:
//!
//! - **substeps**: `N` equal stages of `h = Δt/N`;
//! - **composition** (`yoshida4`): every substep is the symmetric triple jump of the second-order
//!   drift–kick–drift step (Yoshida 1990; Suzuki 1990),
//!
//!   ```text
//!   Ψ_h = S_{c₁h} ∘ S_{c₀h} ∘ S_{c₁h},   c₁ = 1/(2 − 2^{1/3}),   c₀ = 1 − 2c₁ = −2^{1/3} c₁
//!   ```
//!
//!   Symmetric compositions of a symmetric second-order map with these weights cancel the
//!   third-order error, so `Ψ` is fourth order for the *whole* motion — free rotation, springs,
//!   forces at body points and torques alike, because each inner step samples its own forces.
//!   It is symplectic and time-reversible wherever the forces are conservative. The middle stage
//!   runs backwards in time (`c₀ < 0`).
//!
//! The damping flows (`tumble_core::damping`) are not composed: they wrap each substep,
//! `D(h/2) ∘ Ψ_h ∘ D(h/2)`, second order (a damping flow cannot run backwards through the
//! negative stage without growing the motion). So `N` substeps of `Δt` are, bit for bit, `N`
//! steps of `Δt/N`.

use std::num::NonZeroU32;

use super::Integrator;
use super::lane_input::LaneInput;
use super::symmetric_kernel::{LaneFlow, rotate_symmetric_one};
use crate::mass::MassProperties;
use crate::math::Real;
use crate::rotation::rotate_exact;
use crate::state::BodyState;

/// `c₁ = 1/(2 − 2^{1/3})` of the triple jump.
#[allow(
    clippy::excessive_precision,
    reason = "the f64 digits, rounded once to `Real` (f32 in the default build)"
)]
const C1: Real = 1.351_207_191_959_657_8;
/// `c₀ = 1 − 2c₁`, formed in the engine precision so that the three weights sum to 1 there.
const C0: Real = 1.0 - 2.0 * C1;
/// The stage weights of `yoshida4`.
pub(super) const TRIPLE_JUMP: [Real; 3] = [C1, C0, C1];
/// The stage weights of every method that is not composed: one stage, the whole (sub)step.
pub(super) const SINGLE: [Real; 1] = [1.0];

/// The free rotation of a whole composed step of `h` without torque: the stages' symmetric-top
/// flows `Φ_{c h}` in sequence, in `f64`, rounded to the engine precision once (rounding the
/// state between the stages would add a random walk of `|L|` and of the energy, whose phase
/// error grows with time and dominates the fourth-order error in `f32`). Spherical bodies rotate
/// exactly about `ω` over `h`.
pub(super) fn rotate_composed(
    state: &mut BodyState,
    mass: &MassProperties,
    weights: &'static [Real],
    h: Real,
) {
    if mass.is_spherical() {
        state.rotation = rotate_exact(state.rotation, state.angular_velocity, h);
        return;
    }
    let input = LaneInput::new(state.rotation, state.angular_velocity, mass);
    (state.rotation, state.angular_velocity) =
        rotate_symmetric_one(&input, h, LaneFlow::Composed(weights));
}

/// Which part of a stage a batch performs (see [`Integrator::begin_stage`] and
/// [`Integrator::finish_stage`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StepPhase {
    /// The whole stage, [`Integrator::whole_stage`], under the body's constant load.
    Whole,
    /// The first phase, [`Integrator::begin_stage`]; the load is not used.
    Begin,
    /// The second phase, [`Integrator::finish_stage`], under the load sampled after
    /// [`Begin`](Self::Begin).
    Finish,
}

/// One stage of a step (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StageSpan {
    /// The stage's span `h` (s): `Δt/N` times the stage's weight; negative for the backward
    /// stage of a composition.
    pub h: Real,
    /// The span of the substep holding the stage, `Δt/N`: the damping flows run for half of it
    /// before the substep's first stage and half after its last.
    pub substep: Real,
    /// The stage opens its substep (the damping flows' first half comes before it).
    pub opens_substep: bool,
    /// The stage closes its substep (the damping flows' second half comes after it).
    pub closes_substep: bool,
    /// The stage opens the step.
    pub opens_step: bool,
    /// The stage closes the step.
    pub closes_step: bool,
}

/// The stages of a step: `substeps` repetitions of a method's composition.
///
/// ```
/// use std::num::NonZeroU32;
/// use tumble_core::Integrator;
/// use tumble_core::integrate::Stages;
///
/// let four = NonZeroU32::new(4).unwrap();
/// let stages = Stages::new(Integrator::Yoshida4, four);
/// assert_eq!(stages.count(), 12);
/// let total: f64 = stages.spans(0.1).map(|s| f64::from(s.h)).sum();
/// assert!((total - 0.1).abs() < 1e-6); // the stages cover the step once
/// assert!(stages.span(0.1, 1).h < 0.0); // the middle stage of the triple jump runs backwards
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stages {
    weights: &'static [Real],
    substeps: NonZeroU32,
}

impl Stages {
    /// The stages of `integrator`'s step split into `substeps` substeps.
    pub fn new(integrator: Integrator, substeps: NonZeroU32) -> Self {
        Self {
            weights: integrator.composition(),
            substeps,
        }
    }

    /// Number of stages, `N × (stages per substep)`; at least 1.
    pub fn count(&self) -> usize {
        self.substeps.get() as usize * self.weights.len()
    }

    /// Stage `index` (`< count()`) of a step of `dt`. The spans are formed as `(Δt/N)·c`, and
    /// `Δt/1 = Δt` exactly, so one stage of weight 1 is the whole step to the bit.
    pub fn span(&self, dt: Real, index: usize) -> StageSpan {
        let k = self.weights.len();
        let substep = dt / self.substeps.get() as Real;
        let j = index % k;
        StageSpan {
            h: substep * self.weights[j],
            substep,
            opens_substep: j == 0,
            closes_substep: j + 1 == k,
            opens_step: index == 0,
            closes_step: index + 1 == self.count(),
        }
    }

    /// Every stage of a step of `dt`, in order.
    pub fn spans(&self, dt: Real) -> impl Iterator<Item = StageSpan> + '_ {
        (0..self.count()).map(move |i| self.span(dt, i))
    }

    /// The span of one plain drift–kick–drift step with the same stability limit on a linear
    /// spring as one substep of this step: what a stability limit stated for one plain step
    /// (`ωh < 2` for an explicit spring) must be checked against. `Δt/N` for a method of one
    /// stage; for the triple jump, whose substep is stable for `ωh <` [`TRIPLE_JUMP_LIMIT`]
    /// (against 2 for one plain step), `(2 / 1.5734) Δt/N ≈ 1.271 Δt/N`.
    pub fn stability_span(&self, dt: Real) -> Real {
        self.equivalent_span(dt, 2.0 / TRIPLE_JUMP_LIMIT)
    }

    /// The span of one plain drift–kick–drift step whose explicit spring step is as accurate,
    /// at the explicit step's accuracy limit (an energy swing of 2.3 % on a linear spring, `ωh`
    /// = 0.3 for a plain step), as one substep of this step: `Δt/N` for a method of one stage;
    /// for the triple jump, which swings that much only at `ωh =` [`TRIPLE_JUMP_SWING_MATCH`],
    /// `(0.3 / 0.68) Δt/N ≈ 0.44 Δt/N`. What the choice between the explicit and the implicit
    /// spring step is judged on.
    pub fn accuracy_span(&self, dt: Real) -> Real {
        self.equivalent_span(dt, 0.3 / TRIPLE_JUMP_SWING_MATCH)
    }

    /// `Δt/N`, times `composed` for a composition.
    fn equivalent_span(&self, dt: Real, composed: Real) -> Real {
        let substep = dt / self.substeps.get() as Real;
        if self.weights.len() == 1 {
            substep
        } else {
            substep * composed
        }
    }
}

/// The `ωh` per substep at which one triple-jump substep swings a linear spring's energy as
/// much as one plain drift–kick–drift step does at `ωh = 0.3` (by 2.3 % of it; the explicit
/// spring step's accuracy limit, `tumble_core::springs::IMPLICIT_OMEGA_DT`), found numerically
/// like [`TRIPLE_JUMP_LIMIT`]; a test measures both swings.
pub const TRIPLE_JUMP_SWING_MATCH: Real = 0.68;

/// The largest `ωh` at which one triple-jump substep `S(c₁h) S(c₀h) S(c₁h)` of drift–kick–drift
/// steps keeps a linear spring `ẍ = −ω²x` bounded: the trace of its 2×2 map reaches ±2 there
/// (a root found numerically, to the digits given; a test checks both sides). One plain step's
/// limit is 2; the backward middle stage makes the composition's smaller, though less than its
/// longest stage (`c₁ h`, 1.70 h) suggests.
pub const TRIPLE_JUMP_LIMIT: Real = 1.5734;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mass::{Mass, MassProperties};
    use crate::math::{Vec3, Widen};
    use crate::state::{BodyState, Wrench};

    /// Largest `|x|` over `steps` steps of `yoshida4` on `ẍ = −x` from `x = 1` at `ωh = h`.
    fn largest_swing(h: Real, steps: usize) -> Real {
        let mass = MassProperties::new(Mass::new(1.0).unwrap(), Vec3::ONE).unwrap();
        let mut state = BodyState {
            position: Vec3::X,
            ..BodyState::default()
        };
        let mut largest: Real = 0.0;
        for _ in 0..steps {
            Integrator::Yoshida4.step_with(&mut state, &mass, h, |s| Wrench {
                force: -s.position,
                torque: Vec3::ZERO,
            });
            largest = largest.max(state.position.length());
        }
        largest
    }

    /// The triple jump keeps a linear spring bounded just below [`TRIPLE_JUMP_LIMIT`] and lets
    /// it grow just above (the root is where the limit's digits say).
    #[test]
    fn the_triple_jump_is_stable_up_to_its_limit_and_no_further() {
        let below = largest_swing(0.999 * TRIPLE_JUMP_LIMIT, 10_000);
        assert!(below < 50.0, "bounded below the limit: {below}");
        let above = largest_swing(1.001 * TRIPLE_JUMP_LIMIT, 10_000);
        assert!(above > 1e6, "grows above the limit: {above}");
    }

    /// Largest over smallest energy of `ẍ = −x` from `x = 1` under `integrator` at `ωh = h`.
    fn energy_swing(integrator: Integrator, h: Real) -> f64 {
        let mass = MassProperties::new(Mass::new(1.0).unwrap(), Vec3::ONE).unwrap();
        let mut state = BodyState {
            position: Vec3::X,
            ..BodyState::default()
        };
        let (mut low, mut high) = (f64::INFINITY, 0.0_f64);
        for _ in 0..2000 {
            integrator.step_with(&mut state, &mass, h, |s| Wrench {
                force: -s.position,
                torque: Vec3::ZERO,
            });
            let e =
                (state.position.length_squared() + state.linear_velocity.length_squared()).widen();
            (low, high) = (low.min(e), high.max(e));
        }
        high / low - 1.0
    }

    /// The triple jump at ωh = 0.68 swings a spring's energy as much as one plain step at 0.3
    /// (2.3 %), within a tenth of it.
    #[test]
    fn the_swing_match_is_where_the_swings_match() {
        let plain = energy_swing(Integrator::Splitting, 0.3);
        let composed = energy_swing(Integrator::Yoshida4, TRIPLE_JUMP_SWING_MATCH);
        assert!((plain - 0.023).abs() < 0.002, "plain: {plain}");
        assert!(
            (composed / plain - 1.0).abs() < 0.1,
            "{composed} vs {plain}"
        );
    }

    #[test]
    fn the_stages_cover_the_step_once_and_open_and_close_their_substeps() {
        let three = NonZeroU32::new(3).unwrap();
        let stages = Stages::new(Integrator::Yoshida4, three);
        let dt: Real = 0.3;
        let spans: Vec<StageSpan> = stages.spans(dt).collect();
        assert_eq!(spans.len(), 9);
        let total: Real = spans.iter().map(|s| s.h).sum();
        assert!((total - dt).abs() < 8.0 * Real::EPSILON * dt);
        for (i, s) in spans.iter().enumerate() {
            assert_eq!(s.opens_substep, i % 3 == 0);
            assert_eq!(s.closes_substep, i % 3 == 2);
            assert_eq!(s.opens_step, i == 0);
            assert_eq!(s.closes_step, i == 8);
            assert_eq!(s.substep, dt / 3.0);
        }
        // One stage of weight 1 is the whole step to the bit.
        let one = Stages::new(Integrator::Splitting, NonZeroU32::MIN);
        assert_eq!(one.count(), 1);
        assert_eq!(one.span(dt, 0).h.to_bits(), dt.to_bits());
        assert_eq!(one.stability_span(dt), dt);
        assert!(stages.stability_span(dt) > dt / 3.0);
    }
}
