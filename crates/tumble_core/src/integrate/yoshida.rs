//! Fourth-order composition of the symmetric + residual Strang free flow (Yoshida 1990; Suzuki 1990):
//!
//! ```text
//! Ψ_h = Φ_{c₁h} ∘ Φ_{c₀h} ∘ Φ_{c₁h},   c₁ = 1/(2 − 2^{1/3}),   c₀ = 1 − 2c₁ = −2^{1/3} c₁
//! ```
//!
//! Symmetric compositions of a symmetric second-order map with these weights cancel the third-
//! order error: `Ψ` is fourth order, still symplectic and time-reversible, and keeps `|L|` to
//! round-off like the Strang flow it is built from. Used inside the drift–kick–drift step, it is
//! fourth order for torque-free rotation and exact for constant forces; a torque sampled once per
//! step makes the coupled motion second order. Cost: three Strang flows per drift.

use glam::DVec3;

use super::splitting::{FreeBody, symmetric_free_flow};

/// `c₁ = 1/(2 − 2^{1/3})`.
pub const C1: f64 = 1.351_207_191_959_657_8;
/// `c₀ = 1 − 2c₁`.
pub const C0: f64 = 1.0 - 2.0 * C1;

/// The fourth-order free flow `Ψ_h = Φ_{c₁h} ∘ Φ_{c₀h} ∘ Φ_{c₁h}`.
#[inline]
pub fn yoshida_free_flow(body: &mut FreeBody, r: DVec3, h: f64) {
    symmetric_free_flow(body, r, C1 * h);
    symmetric_free_flow(body, r, C0 * h);
    symmetric_free_flow(body, r, C1 * h);
}
