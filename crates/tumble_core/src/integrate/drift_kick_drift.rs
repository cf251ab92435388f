//! The drift–kick–drift step `D(h/2) ∘ K(h) ∘ D(h/2)` that the split and exact methods share:
//! its phases' translation and kicks, the span of each phase's free rotation, and the free
//! body (`Q`, `m`) a free flow advances. `D` moves `x += ½h v` and turns the body by the
//! method's free flow at constant world `L`; `K` kicks `v += h F/m` and `L += h τ`. Forces are
//! sampled once, between the two drifts, so constant forces are integrated exactly and springs
//! get the second-order, symplectic position-Verlet scheme.

use glam::{DQuat, DVec3};

use super::StepPhase;
use super::frame::{reciprocal, rotate64};
use crate::mass::MassProperties;
use crate::math::{Narrow, Real, Vec3, Widen};
use crate::rotation::rotate_exact;
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
