//! Lie–Poisson splittings of the free rigid body, the drift–kick–drift step built on them, and
//! its batch loops (`drift_kick_drift_batch` for `splitting`, `splitting-xyz` and `rk4`;
//! `composed_step_batch` for `yoshida4`'s torque-free steps).
//!
//! The free-body Hamiltonian is `H = ½ Σᵢ rᵢ mᵢ²` with body momentum `m = Qᵀ L` and reciprocal
//! moments `rᵢ = 1/Iᵢ` (`0` on a locked axis). Two splittings into exactly integrable pieces:
//!
//! **`splitting` (symmetric + residual, Fassò 2003).** Pick the pair of axes `b, c` whose
//! reciprocal moments are closest and call the third `a`:
//!
//! ```text
//! H = ½ r_b |m|²  +  ½ (r_a − r_b) m_a²  +  ½ (r_c − r_b) m_c²
//!     └── S: symmetric top, exact ──────┘    └── R: residual ──┘
//! ```
//!
//! `½ r_b |m|²` is a Casimir: its flow rotates the body about the fixed world `L` by `t r_b |L|`;
//! `½ (r_a − r_b) m_a²` rotates it about its own axis `a` by `t (r_a − r_b) m_a`. The two commute,
//! so `S` is the exact motion of a symmetric top. The residual `R` is a rotation about axis `c`
//! by `t (r_c − r_b) m_c`. The Strang composition `R(h/2) ∘ S(h) ∘ R(h/2)` is symplectic,
//! time-reversible and second order, its error is proportional to `r_c − r_b` — zero for every
//! symmetric body (thin rods, discs, spheres are integrated exactly) — and it costs four axis
//! rotations per free flow.
//!
//! **`splitting-xyz` (McLachlan 1993; Touma & Wisdom 1994).** `H = Σ ½ rᵢ mᵢ²`, one axis at a
//! time, Strang 1-2-3-2-1. Same properties, five rotations, but its error does not vanish for
//! symmetric bodies: on a thin rod (I = (1e-4, 1, 1)) spinning at |ω|Δt = 1 about a tilted axis it
//! pumps energy up a thousandfold (bounded only by `|L|²/(2 I_min)`).
//!
//! In every sub-flow the world momentum `L` is fixed, so `|L|` of a torque-free body is kept to
//! round-off. The flows run in f64 on the body momentum `m` and the principal orientation `Q`,
//! each sub-flow a body-frame rotation `Q ← Q exp(θ e)` with `m ← exp(−θ e) m`; only the final
//! `ω` and `q` are rounded to the engine's precision.
//!
//! **Known limit.** A thin body that is *not* symmetric (e.g. I = (1e-4, 1, 1.02)) spinning fast
//! about a tilted axis: the residual rotation mixes the large transverse momentum into the tiny
//! long-axis momentum `m_a = I_a ω_a`, and an absolute error of `h² ω_a (r_c − r_b) m_b m_c` per
//! step is a huge relative error in `ω_a`. Every method here (and every splitting we know of)
//! then pumps energy toward the long axis, up to the bound `|L|²/(2 I_min)`; the state stays
//! finite and `|L|` stays exact. An exact torque-free step (elliptic functions for `m`) is the
//! cure; symmetric rods, discs and spheres are already exact.
//!
//! **Where the code is.** The `splitting` flow is written once, lane-generic, in
//! `symmetric_kernel` (`Flowing::symmetric_flow`): one body runs it in `f64`, a batch in SIMD
//! lanes (`yoshida4` is a composition of whole `splitting` steps, see `stages`). `splitting-xyz`'s
//! axis-by-axis flow and `rk4`'s run on the same lanes; `exact`'s advances a [`FreeBody`].
//!
//! With external load the step is the symmetric drift–kick–drift `D(h/2) ∘ K(h) ∘ D(h/2)` of
//! `drift_kick_drift` (its translation and kicks, shared with `exact`), the method's free
//! rotation completing each drift, on both the scalar and the batched paths. In the batch, the
//! bodies [`FreeFlow::Auto`](super::FreeFlow::Auto) gives the exact flow take `exact`'s
//! rotation two at a time (`ExactPairs`), with the bits of stepping each alone.

use crate::math::{Real, Vec3};
use glam::{DQuat, DVec3};

use super::body_batch::{BodyBatch, PREFETCH_AHEAD, commit};
use super::drift_kick_drift::{
    FreeBody, drift_kick_drift_linear, drift_kick_drift_translation, free_rotation_span,
    kick_angular,
};
use super::exact_flow::ExactPairs;
use super::lane_input::LaneInput;
use super::pending::{PendingRotations, QueuedRotation, Route, queued};
use super::symmetric_kernel::{LaneFlow, rotate_symmetric_one};
use super::{ExactSwitch, Integrator, StepPhase};
use crate::mass::MassProperties;
use crate::rotation::rotate_exact;
use crate::simd::Kernel;
use crate::state::{BodyState, Wrench};

/// The free rotation `flow` over `h` on the lane kernel of the module `symmetric_kernel` (the
/// same code the batched step runs, so one body gets the same bits alone or in a batch), after
/// the kick `L += J` of the angular impulse `impulse` (world frame): the kernel folds `J` into
/// the body momentum (see `symmetric_kernel`), and without an impulse runs the flow unkicked. A
/// spherical body takes the kick as `ω += I⁻¹ J`, as every other method does, and turns exactly
/// about `ω` (`ω ∥ L` for it).
#[inline]
pub(super) fn rotate_kicked_on_kernel(
    state: &mut BodyState,
    mass: &MassProperties,
    h: Real,
    impulse: Vec3,
    flow: LaneFlow,
) {
    if mass.is_spherical() {
        kick_angular(state, mass, impulse);
        state.rotation = rotate_exact(state.rotation, state.angular_velocity, h);
        return;
    }
    let flow = flow.with_kick(impulse != Vec3::ZERO);
    let input = LaneInput::for_flow(
        state.rotation,
        state.angular_velocity,
        mass,
        flow.relabels(),
    )
    .with_impulse(impulse);
    (state.rotation, state.angular_velocity) = rotate_symmetric_one(&input, h, flow);
}

/// `splitting`'s free rotation after the kick of `impulse` ([`rotate_kicked_on_kernel`]).
#[inline]
pub(super) fn rotate_symmetric_kicked(
    state: &mut BodyState,
    mass: &MassProperties,
    h: Real,
    impulse: Vec3,
) {
    rotate_kicked_on_kernel(state, mass, h, impulse, LaneFlow::Symmetric { kicks: true });
}

impl FreeBody {
    /// Exact flow of the Casimir `½ k |m|²` for time `h`: rotation about the body momentum by
    /// `h k |m|` (`Q ← Q exp(θ m̂)`; `m` lies on the axis and is unchanged).
    #[inline]
    fn momentum_flow(&mut self, k: f64, h: f64) {
        let length = self.m.length();
        if length > 0.0 && k != 0.0 {
            let (s, c) = crate::simd::sin_cos(0.5 * h * k * length);
            let axis = self.m * (s / length);
            self.q *= DQuat::from_xyzw(axis.x, axis.y, axis.z, c);
        }
    }
}

/// `splitting`'s free flow over `h` on a [`FreeBody`], in `f64`: `R(h/2) ∘ S(h) ∘ R(h/2)` with
/// `odd` the axis `a` and `(b, c) = (a + 1, a + 2)` the symmetric pair, the sequence the lane
/// kernel runs on its relabelled axes (see `symmetric_kernel`). The same method as the batched
/// step, not the same bits (the kernel rounds its input to the engine's precision first).
pub(super) fn symmetric_free_flow(body: &mut FreeBody, r: DVec3, odd: usize, h: f64) {
    let (a, b, c) = (odd, (odd + 1) % 3, (odd + 2) % 3);
    let residual = r[c] - r[b];
    body.axis_flow(c, residual, 0.5 * h);
    body.momentum_flow(r[b], h);
    body.axis_flow(a, r[a] - r[b], h);
    body.axis_flow(c, residual, 0.5 * h);
}

/// The `splitting` batch: each body's drift–kick–drift translation and linear kick, then its
/// free rotation (which takes the angular kick, in `Finish`), queued for the SIMD kernel
/// ([`PendingRotations`]), or stepped whole by `alone` when its translation cannot run first
/// (a whole step under a torque). A body `switch` gives the exact flow takes `exact`'s stage:
/// its rotation two bodies at a time ([`ExactPairs`]) where its translation runs first.
#[inline(always)]
pub(super) fn drift_kick_drift_batch(
    kernel: Kernel,
    flow: LaneFlow,
    phase: StepPhase,
    bodies: &mut impl BodyBatch,
    dt: Real,
    switch: Option<ExactSwitch>,
    mut alone: impl FnMut(&mut BodyState, &MassProperties, &Wrench, Real),
) {
    let h = free_rotation_span(phase, dt);
    let flow = flow.with_kick(phase == StepPhase::Finish);
    let mut pending = PendingRotations::new(h, kernel, QueuedRotation::Free(flow));
    // The bodies the switch gives `exact`, whose translation is the same drift–kick–drift.
    let mut exact = ExactPairs::new(h);
    let mut next = BodyState::ZEROED;
    for i in 0..bodies.len() {
        bodies.prefetch(i + PREFETCH_AHEAD);
        let Some(wrench) = bodies.take(i, &mut next) else {
            continue;
        };
        let mass = bodies.mass(i);
        if let Some(switch) = switch
            && switch.applies_turned(&next, mass, bodies.spring_turn_rate(i))
        {
            let mut single = next;
            if switch.exact() == Integrator::Exact
                && !mass.is_spherical()
                && drift_kick_drift_translation(phase, &mut single, mass, &wrench, dt)
            {
                exact.rotate(i, single, bodies);
            } else {
                switch.exact().stage(phase, &mut single, mass, &wrench, dt);
                commit(bodies, i, &single);
            }
            continue;
        }
        match drift_kick_drift_linear(phase, &mut next, mass, &wrench, dt) {
            Some(impulse) if mass.is_spherical() => {
                kick_angular(&mut next, mass, impulse);
                next.rotation = rotate_exact(next.rotation, next.angular_velocity, h);
                commit(bodies, i, &next);
            }
            Some(impulse) => {
                if pending.queue(i, &next, mass, impulse) {
                    pending.flush(bodies);
                }
            }
            None => {
                // A copy, so that `next` never escapes into the (not inlined) scalar step and
                // stays in registers on the hot path.
                let mut single = next;
                alone(&mut single, mass, &wrench, bodies.spring_turn_rate(i));
                commit(bodies, i, &single);
            }
        }
    }
    pending.flush(bodies);
    exact.finish(bodies);
}

/// The batch of whole composed steps (`yoshida4`): a body without torque takes the exact
/// translation over `dt` and its stages' free rotations in sequence, queued for the SIMD kernel
/// (as [`Integrator::step`] does alone); a spherical body turns exactly; a body under a torque
/// is stepped whole by `own` (the method's single-body step), stage by stage.
#[inline(always)]
pub(super) fn composed_step_batch(
    kernel: Kernel,
    weights: &'static [Real],
    bodies: &mut impl BodyBatch,
    dt: Real,
    switch: Option<ExactSwitch>,
    mut own: impl FnMut(&mut BodyState, &MassProperties, &Wrench),
) {
    let flow = LaneFlow::Composed(weights);
    let pending = PendingRotations::new(dt, kernel, QueuedRotation::Free(flow));
    // A torque-free `exact4` step is the exact translation and one exact flow over `dt` (exact
    // flows compose exactly; see `Integrator::step`): its rotation pairs with another's.
    let exact = |switch: ExactSwitch, s: &mut BodyState, m: &MassProperties, w: &Wrench| {
        if switch.exact() == Integrator::Exact4 && w.torque == Vec3::ZERO && !m.is_spherical() {
            drift_kick_drift_translation(StepPhase::Whole, s, m, w, dt);
            return true;
        }
        switch.exact().step(s, m, w, dt);
        false
    };
    queued(pending, bodies, switch, exact, |next, mass, wrench| {
        if wrench.torque != Vec3::ZERO {
            // A copy, so that `next` never escapes into the (not inlined) scalar step.
            let mut single = *next;
            own(&mut single, mass, wrench);
            *next = single;
            return Route::Done;
        }
        drift_kick_drift_translation(StepPhase::Whole, next, mass, wrench, dt);
        if mass.is_spherical() {
            next.rotation = rotate_exact(next.rotation, next.angular_velocity, dt);
            Route::Done
        } else {
            Route::Queue(Vec3::ZERO)
        }
    });
}
