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
//! round-off.
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

use glam::{Quat, Vec3};

use super::frame::{
    axis_rotation, principal_axis, principal_orientation, set_principal_orientation,
    world_momentum, world_omega,
};
use crate::mass::MassProperties;
use crate::state::{BodyState, Wrench};

/// Exact flow of `mᵢ²/(2Iᵢ)` for time `h`: rotates `Q` about its principal axis `i` by
/// `θ = h (aᵢ·L)/Iᵢ`, with `aᵢ = Q eᵢ` the axis in the world. `L` is unchanged. `inertia` holds
/// the principal moments `I_b`.
#[inline]
fn axis_flow(q: Quat, momentum: Vec3, inertia: Vec3, axis: usize, h: f32) -> Quat {
    let moment = inertia[axis];
    if moment <= 0.0 {
        return q; // locked axis: no rotation about it
    }
    let a = principal_axis(q, axis) / q.length_squared();
    let theta = h * a.dot(momentum) / moment;
    q * axis_rotation(axis, theta)
}

/// Strang splitting 1-2-3-2-1 of the free flow over `h`, on the principal orientation `Q`
/// (`splitting-xyz`).
#[inline]
pub fn strang_free_flow(q: Quat, momentum: Vec3, inertia: Vec3, h: f32) -> Quat {
    let half = 0.5 * h;
    let q = axis_flow(q, momentum, inertia, 0, half);
    let q = axis_flow(q, momentum, inertia, 1, half);
    let q = axis_flow(q, momentum, inertia, 2, h);
    let q = axis_flow(q, momentum, inertia, 1, half);
    axis_flow(q, momentum, inertia, 0, half)
}

/// Rotation of `Q` about its principal axis `axis` by `h · coefficient · mₐ`, with
/// `mₐ = (Q eₐ)·L` the body momentum about that axis.
#[inline]
fn body_axis_flow(q: Quat, momentum: Vec3, axis: usize, coefficient: f32, h: f32) -> Quat {
    if coefficient == 0.0 {
        return q;
    }
    let m_axis = principal_axis(q, axis).dot(momentum) / q.length_squared();
    q * axis_rotation(axis, h * coefficient * m_axis)
}

/// Unit quaternion of a rotation by `angle` about the unit vector `axis`.
#[inline]
fn axis_angle(axis: Vec3, angle: f32) -> Quat {
    let (s, c) = (0.5 * angle).sin_cos();
    let v = axis * s;
    Quat::from_xyzw(v.x, v.y, v.z, c)
}

/// Reciprocal moment, `0` for a locked axis.
#[inline]
fn reciprocal(moment: f32) -> f32 {
    if moment > 0.0 { 1.0 / moment } else { 0.0 }
}

/// Symmetric + residual splitting `R(h/2) ∘ S(h) ∘ R(h/2)` of the free flow over `h`
/// (`splitting`); see the module documentation.
#[inline]
pub fn symmetric_free_flow(q: Quat, momentum: Vec3, inertia: Vec3, h: f32) -> Quat {
    let r = Vec3::new(
        reciprocal(inertia.x),
        reciprocal(inertia.y),
        reciprocal(inertia.z),
    );
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
    let half = 0.5 * h;
    let q = body_axis_flow(q, momentum, c, residual, half);
    // S(h): Casimir rotation about L, then the commuting rotation about axis a.
    let l = momentum.length();
    let q = if l > 0.0 {
        axis_angle(momentum / l, h * r[b] * l) * q
    } else {
        q
    };
    let q = body_axis_flow(q, momentum, a, r[a] - r[b], h);
    body_axis_flow(q, momentum, c, residual, half)
}

/// A free-flow approximation `Q ← Φ(Q, L, h)` at constant world momentum `L`.
pub type FreeFlow = fn(Quat, Vec3, Vec3, f32) -> Quat;

/// Drift for `h`: `x += h v` and the free rotation `Φ_h` at constant `L` (spherical bodies
/// rotate exactly about `ω`, since `ω ∥ L` for them).
#[inline]
pub fn drift(state: &mut BodyState, mass: &MassProperties, h: f32, flow: FreeFlow) {
    state.position += h * state.linear_velocity;
    if mass.is_spherical() {
        state.rotation = crate::rotation::rotate_exact(state.rotation, state.angular_velocity, h);
        return;
    }
    let q = principal_orientation(state, mass);
    let momentum = world_momentum(q, mass.principal_inertia(), state.angular_velocity);
    let q = flow(q, momentum, mass.principal_inertia(), h).normalize();
    state.angular_velocity = world_omega(q, mass.principal_inertia(), momentum);
    set_principal_orientation(state, mass, q);
}

/// Kick for `h`: `v += h F/m`, `L += h τ` (so `ω += h I⁻¹ τ` at the current pose).
#[inline]
pub fn kick(state: &mut BodyState, mass: &MassProperties, wrench: &Wrench, h: f32) {
    state.linear_velocity += (h * mass.inv_mass()) * wrench.force;
    if wrench.torque != Vec3::ZERO {
        state.angular_velocity += mass.world_inertia_mul(state.rotation, h * wrench.torque);
    }
}

/// First half of a drift–kick–drift step: `D(h/2)`, before forces are sampled.
#[inline]
pub fn begin_dkd(state: &mut BodyState, mass: &MassProperties, h: f32, flow: FreeFlow) {
    drift(state, mass, 0.5 * h, flow);
}

/// Second half of a drift–kick–drift step: `K(h)` then `D(h/2)`.
#[inline]
pub fn finish_dkd(
    state: &mut BodyState,
    mass: &MassProperties,
    wrench: &Wrench,
    h: f32,
    flow: FreeFlow,
) {
    kick(state, mass, wrench, h);
    drift(state, mass, 0.5 * h, flow);
}
