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
//! axis-by-axis flow and `rk4`'s run on the same lanes; `exact`'s advances a [`FreeBody`]. The drift–kick–drift phases are
//! [`drift_kick_drift_translation`] plus the method's free rotation, on both the scalar and the
//! batched paths.
//!
//! With external load the step is the symmetric drift–kick–drift
//! `D(h/2) ∘ K(h) ∘ D(h/2)`: `D` moves `x += ½h v` and applies the free flow, `K` kicks
//! `v += h F/m` and `L += h τ`. Forces are sampled once, between the two drifts (the ECS runs the
//! first drift before the force systems), so constant forces are integrated exactly and springs
//! get the second-order, symplectic position-Verlet scheme.

use crate::math::{Narrow, Real, Vec3, Widen};
use glam::{DQuat, DVec3};

use super::body_batch::{BodyBatch, PREFETCH_AHEAD, commit};
use super::frame::{reciprocal, rotate64};
use super::lane_input::LaneInput;
use super::pending::{PendingRotations, QueuedRotation, Route, queued};
use super::symmetric_kernel::{LaneFlow, rotate_symmetric_one};
use super::{ExactSwitch, StepPhase};
use crate::mass::MassProperties;
use crate::rotation::rotate_exact;
use crate::simd::Kernel;
use crate::state::{BodyState, Wrench};

/// The state a free flow advances: principal orientation `Q` (principal → world) and body
/// momentum `m = Qᵀ L`, both f64.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct FreeBody {
    /// Principal orientation `Q`.
    pub q: DQuat,
    /// Body momentum `m` in the principal frame.
    pub m: DVec3,
}

impl FreeBody {
    /// Rotates the body by `angle` about its principal axis `axis` (0, 1, 2): `Q ← Q exp(θ eₐ)`,
    /// and the body momentum the opposite way, `m ← exp(−θ eₐ) m`, so `L = Q m` is unchanged.
    #[inline]
    pub(super) fn rotate_about_axis(&mut self, axis: usize, angle: f64) {
        // tumble's own sine and cosine: the same bits on every platform.
        let (s, c) = crate::simd::sin_cos(0.5 * angle);
        // cos θ and sin θ from the half angle: one sin_cos per rotation.
        let (cos, sin) = (c * c - s * s, 2.0 * s * c);
        let m = self.m;
        match axis {
            0 => {
                self.q *= DQuat::from_xyzw(s, 0.0, 0.0, c);
                self.m = DVec3::new(m.x, cos * m.y + sin * m.z, cos * m.z - sin * m.y);
            }
            1 => {
                self.q *= DQuat::from_xyzw(0.0, s, 0.0, c);
                self.m = DVec3::new(cos * m.x - sin * m.z, m.y, cos * m.z + sin * m.x);
            }
            _ => {
                self.q *= DQuat::from_xyzw(0.0, 0.0, s, c);
                self.m = DVec3::new(cos * m.x + sin * m.y, cos * m.y - sin * m.x, m.z);
            }
        }
    }

    /// Exact flow of `½ k mₐ²` for time `h`: rotation about axis `a` by `h k mₐ`.
    #[inline]
    pub(super) fn axis_flow(&mut self, axis: usize, k: f64, h: f64) {
        if k != 0.0 {
            self.rotate_about_axis(axis, h * k * self.m[axis]);
        }
    }
}

/// A free-flow approximation over `h`, given the reciprocal principal moments `r = 1/I_b`
/// (0 on locked axes).
pub(super) type FreeFlow = fn(&mut FreeBody, DVec3, f64);

/// The rotational part of a drift over `h` at constant world `L`, after the kick `L += J` of the
/// angular impulse `J` (world frame; zero in a phase without a kick): a method's free rotation.
pub(super) type Rotation = fn(&mut BodyState, &MassProperties, Real, Vec3);

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

/// The rotational part of a drift: the free flow over `h` at constant world `L`.
#[inline]
pub(super) fn rotate_freely(state: &mut BodyState, mass: &MassProperties, h: Real, flow: FreeFlow) {
    if mass.is_spherical() {
        state.rotation = rotate_exact(state.rotation, state.angular_velocity, h);
        return;
    }
    let mut free = FreeState::new(state, mass);
    flow(&mut free.body, free.r, h.widen());
    free.write(state);
}

/// A non-spherical body's state as a free flow advances it: the [`FreeBody`], its reciprocal
/// principal moments and its principal frame (see [`rotate_freely`]).
pub(crate) struct FreeState {
    pub(crate) body: FreeBody,
    pub(crate) r: DVec3,
    frame: DQuat,
}

impl FreeState {
    /// The free body of `state`.
    #[inline(always)]
    pub(crate) fn new(state: &BodyState, mass: &MassProperties) -> Self {
        let frame = mass.principal_frame().widen();
        let q = state.rotation.widen() * frame;
        let inertia = mass.principal_inertia().widen();
        let r = DVec3::new(
            reciprocal(inertia.x),
            reciprocal(inertia.y),
            reciprocal(inertia.z),
        );
        let body = FreeBody {
            q,
            m: inertia * rotate64(q.conjugate(), state.angular_velocity.widen()),
        };
        Self { body, r, frame }
    }

    /// Writes the flowed body back into `state`, rounded to the engine's precision.
    #[inline(always)]
    pub(crate) fn write(&self, state: &mut BodyState) {
        let q = self.body.q.normalize();
        state.angular_velocity = rotate64(q, self.r * self.body.m).narrow();
        state.rotation = crate::math::quat_normalize((q * self.frame.conjugate()).narrow());
    }
}

/// The angular kick `L += J` as `ω += I⁻¹ J` at the current pose (nothing for `J = 0`).
#[inline(always)]
pub(crate) fn kick_angular(state: &mut BodyState, mass: &MassProperties, impulse: Vec3) {
    if impulse != Vec3::ZERO {
        state.angular_velocity += mass.world_inv_inertia_mul(state.rotation, impulse);
    }
}

/// The span of free rotation that completes `phase` of a drift–kick–drift step over `dt`: `½Δt`
/// for either half, `Δt` for a whole torque-free step (see [`drift_kick_drift_translation`]).
#[inline(always)]
pub(crate) fn free_rotation_span(phase: StepPhase, dt: Real) -> Real {
    match phase {
        StepPhase::Whole => dt,
        StepPhase::Begin | StepPhase::Finish => 0.5 * dt,
    }
}

/// The translational part of `phase` of the drift–kick–drift step `D(Δt/2) ∘ K(Δt) ∘ D(Δt/2)`,
/// the one sequence the scalar and the batched paths both run; a free rotation over
/// [`free_rotation_span`] completes the phase:
///
/// - `Begin`, before forces are sampled: the first half drift's `x += ½Δt v`.
/// - `Finish`: the kick `v += Δt F/m`, `L += Δt τ`, then the second half drift's `x += ½Δt v`.
/// - `Whole` without torque: `x += ½Δt v; v += Δt F/m; x += ½Δt v` (exact for a constant force);
///   with nothing to kick between them, the two half rotations are one, over `Δt`.
///
/// Returns false, leaving `state` untouched, for `Whole` under a torque: the torque must be
/// kicked between the two half rotations, so that step is `Begin` then `Finish`.
#[inline(always)]
pub(crate) fn drift_kick_drift_translation(
    phase: StepPhase,
    state: &mut BodyState,
    mass: &MassProperties,
    wrench: &Wrench,
    dt: Real,
) -> bool {
    let Some(impulse) = drift_kick_drift_linear(phase, state, mass, wrench, dt) else {
        return false;
    };
    kick_angular(state, mass, impulse);
    true
}

/// [`drift_kick_drift_translation`] without the angular kick: returns the angular impulse
/// `J = Δt τ` that the phase's free rotation must take (zero outside `Finish`), or `None` for
/// `Whole` under a torque.
#[inline(always)]
pub(crate) fn drift_kick_drift_linear(
    phase: StepPhase,
    state: &mut BodyState,
    mass: &MassProperties,
    wrench: &Wrench,
    dt: Real,
) -> Option<Vec3> {
    let half = 0.5 * dt;
    match phase {
        StepPhase::Begin => state.position += half * state.linear_velocity,
        StepPhase::Finish => {
            state.linear_velocity += (dt * mass.inv_mass()) * wrench.force;
            state.position += half * state.linear_velocity;
            if wrench.torque != Vec3::ZERO {
                return Some(dt * wrench.torque);
            }
        }
        StepPhase::Whole if wrench.torque == Vec3::ZERO => {
            state.position += half * state.linear_velocity;
            state.linear_velocity += (dt * mass.inv_mass()) * wrench.force;
            state.position += half * state.linear_velocity;
        }
        StepPhase::Whole => return None,
    }
    Some(Vec3::ZERO)
}

/// `phase` of the drift–kick–drift step with a method's free `rotation`.
#[inline]
pub(crate) fn drift_kick_drift(
    phase: StepPhase,
    state: &mut BodyState,
    mass: &MassProperties,
    wrench: &Wrench,
    dt: Real,
    rotation: Rotation,
) {
    if let Some(impulse) = drift_kick_drift_linear(phase, state, mass, wrench, dt) {
        rotation(state, mass, free_rotation_span(phase, dt), impulse);
        return;
    }
    for half in [StepPhase::Begin, StepPhase::Finish] {
        let impulse = drift_kick_drift_linear(half, state, mass, wrench, dt).unwrap_or(Vec3::ZERO);
        rotation(state, mass, free_rotation_span(half, dt), impulse);
    }
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
/// (a whole step under a torque).
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
            switch.exact().stage(phase, &mut single, mass, &wrench, dt);
            commit(bodies, i, &single);
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
    let exact = |switch: ExactSwitch, s: &mut BodyState, m: &MassProperties, w: &Wrench| {
        switch.exact().step(s, m, w, dt);
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
