//! Lie–Poisson splittings of the free rigid body, and the drift–kick–drift step built on them.
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
//! With external load the step is the symmetric drift–kick–drift
//! `D(h/2) ∘ K(h) ∘ D(h/2)`: `D` moves `x += ½h v` and applies the free flow, `K` kicks
//! `v += h F/m` and `L += h τ`. Forces are sampled once, between the two drifts (the ECS runs the
//! first drift before the force systems), so constant forces are integrated exactly and springs
//! get the second-order, symplectic position-Verlet scheme.

use crate::math::{Narrow, Real, Vec3, Widen};
use glam::{DQuat, DVec3};

use super::frame::{recip, rotate64};
use super::symmetric_kernel::{SymmetricInput, rotate_symmetric_one};
use crate::mass::MassProperties;
use crate::rotation::rotate_exact;
use crate::state::{BodyState, Wrench};

/// The state a free flow advances: principal orientation `Q` (principal → world) and body
/// momentum `m = Qᵀ L`, both f64.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FreeBody {
    /// Principal orientation `Q`.
    pub q: DQuat,
    /// Body momentum `m` in the principal frame.
    pub m: DVec3,
}

impl FreeBody {
    /// Rotates the body by `angle` about its principal axis `axis` (0, 1, 2): `Q ← Q exp(θ eₐ)`,
    /// and the body momentum the opposite way, `m ← exp(−θ eₐ) m`, so `L = Q m` is unchanged.
    #[inline]
    pub fn rotate_about_axis(&mut self, axis: usize, angle: f64) {
        let (s, c) = (0.5 * angle).sin_cos();
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
    pub fn axis_flow(&mut self, axis: usize, k: f64, h: f64) {
        if k != 0.0 {
            self.rotate_about_axis(axis, h * k * self.m[axis]);
        }
    }

    /// Exact flow of the Casimir `½ k |m|²` for time `h`: rotation about `m` itself by
    /// `h k |m|` (so `m` is unchanged).
    #[inline]
    pub fn casimir_flow(&mut self, k: f64, h: f64) {
        let length = self.m.length();
        if length > 0.0 && k != 0.0 {
            let (s, c) = (0.5 * h * k * length).sin_cos();
            let v = self.m * (s / length);
            self.q *= DQuat::from_xyzw(v.x, v.y, v.z, c);
        }
    }
}

/// A free-flow approximation over `h`, given the reciprocal principal moments `r = 1/I_b`
/// (0 on locked axes).
pub type FreeFlow = fn(&mut FreeBody, DVec3, f64);

/// Strang splitting 1-2-3-2-1 of the free flow over `h` (`splitting-xyz`).
#[inline]
pub fn strang_free_flow(body: &mut FreeBody, r: DVec3, h: f64) {
    let half = 0.5 * h;
    body.axis_flow(0, r.x, half);
    body.axis_flow(1, r.y, half);
    body.axis_flow(2, r.z, h);
    body.axis_flow(1, r.y, half);
    body.axis_flow(0, r.x, half);
}

/// Symmetric + residual splitting `R(h/2) ∘ S(h) ∘ R(h/2)` of the free flow over `h`
/// (`splitting`); see the module documentation.
#[inline]
pub fn symmetric_free_flow(body: &mut FreeBody, r: DVec3, h: f64) {
    // The pair (b, c) with the closest reciprocals; a is the remaining axis.
    let gaps = [(r.y - r.z).abs(), (r.x - r.z).abs(), (r.x - r.y).abs()];
    let a = if gaps[0] <= gaps[1] && gaps[0] <= gaps[2] {
        0
    } else if gaps[1] <= gaps[2] {
        1
    } else {
        2
    };
    let (b, c) = ((a + 1) % 3, (a + 2) % 3);
    let residual = r[c] - r[b];
    body.axis_flow(c, residual, 0.5 * h);
    // S(h): the Casimir rotation about m and the commuting rotation about axis a.
    body.casimir_flow(r[b], h);
    body.axis_flow(a, r[a] - r[b], h);
    body.axis_flow(c, residual, 0.5 * h);
}

/// The rotational part of a drift over `h` at constant world `L`: a method's free rotation.
pub type Rotation = fn(&mut BodyState, &MassProperties, Real);

/// Drift for `h`: `x += h v` and the free rotation over `h` at constant `L`.
#[inline]
pub fn drift(state: &mut BodyState, mass: &MassProperties, h: Real, rotation: Rotation) {
    state.position += h * state.linear_velocity;
    rotation(state, mass, h);
}

/// The free rotation of the `splitting` method over `h`: spherical bodies exactly about `ω`
/// (`ω ∥ L` for them), the others through the lane kernel of
/// the module `symmetric_kernel` — the same code the batched step runs, so one
/// body gets the same bits alone or in a batch.
#[inline]
pub fn rotate_symmetric(state: &mut BodyState, mass: &MassProperties, h: Real) {
    if mass.is_spherical() {
        state.rotation = rotate_exact(state.rotation, state.angular_velocity, h);
        return;
    }
    let input = SymmetricInput::new(state.rotation, state.angular_velocity, mass);
    (state.rotation, state.angular_velocity) = rotate_symmetric_one(&input, h);
}

/// The rotational part of a drift: the free flow over `h` at constant world `L`.
#[inline]
pub fn rotate_freely(state: &mut BodyState, mass: &MassProperties, h: Real, flow: FreeFlow) {
    if mass.is_spherical() {
        state.rotation = rotate_exact(state.rotation, state.angular_velocity, h);
        return;
    }
    let frame = mass.principal_frame().widen();
    let q = state.rotation.widen() * frame;
    let inertia = mass.principal_inertia().widen();
    let r = DVec3::new(recip(inertia.x), recip(inertia.y), recip(inertia.z));
    let mut body = FreeBody {
        q,
        m: inertia * rotate64(q.conjugate(), state.angular_velocity.widen()),
    };
    flow(&mut body, r, h.widen());
    let q = body.q.normalize();
    state.angular_velocity = rotate64(q, r * body.m).narrow();
    state.rotation = (q * frame.conjugate()).narrow().normalize();
}

/// Kick for `h`: `v += h F/m`, `L += h τ` (so `ω += h I⁻¹ τ` at the current pose).
#[inline]
pub fn kick(state: &mut BodyState, mass: &MassProperties, wrench: &Wrench, h: Real) {
    state.linear_velocity += (h * mass.inv_mass()) * wrench.force;
    if wrench.torque != Vec3::ZERO {
        state.angular_velocity += mass.world_inv_inertia_mul(state.rotation, h * wrench.torque);
    }
}

/// First half of a drift–kick–drift step: `D(h/2)`, before forces are sampled.
#[inline]
pub fn begin_dkd(state: &mut BodyState, mass: &MassProperties, h: Real, rotation: Rotation) {
    drift(state, mass, 0.5 * h, rotation);
}

/// Second half of a drift–kick–drift step: `K(h)` then `D(h/2)`.
#[inline]
pub fn finish_dkd(
    state: &mut BodyState,
    mass: &MassProperties,
    wrench: &Wrench,
    h: Real,
    rotation: Rotation,
) {
    kick(state, mass, wrench, h);
    drift(state, mass, 0.5 * h, rotation);
}

/// A whole drift–kick–drift step under a torque-free `wrench`: the translation is
/// `x += ½h v; v += h F/m; x += ½h v` (exact for constant `F`) and, with no torque to kick
/// between them, the two rotational half drifts are taken as one free flow over `h`.
#[inline]
pub fn torque_free_dkd(
    state: &mut BodyState,
    mass: &MassProperties,
    wrench: &Wrench,
    h: Real,
    rotation: Rotation,
) {
    translate_dkd(state, mass, wrench, h);
    rotation(state, mass, h);
}

/// The translational part of a whole drift–kick–drift step:
/// `x += ½h v; v += h F/m; x += ½h v` (exact for a constant force).
#[inline]
pub fn translate_dkd(state: &mut BodyState, mass: &MassProperties, wrench: &Wrench, h: Real) {
    state.position += (0.5 * h) * state.linear_velocity;
    state.linear_velocity += (h * mass.inv_mass()) * wrench.force;
    state.position += (0.5 * h) * state.linear_velocity;
}
