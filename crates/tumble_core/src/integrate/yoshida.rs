//! Fourth-order composition of the symmetric + residual Strang free flow (Yoshida 1990;
//! Suzuki 1990):
//!
//! ```text
//! Ψ_h = Φ_{c₁h} ∘ Φ_{c₀h} ∘ Φ_{c₁h},   c₁ = 1/(2 − 2^{1/3}),   c₀ = 1 − 2c₁ = −2^{1/3} c₁
//! ```
//!
//! Symmetric compositions of a symmetric second-order map with these weights cancel the third-
//! order error: `Ψ` is fourth order, still symplectic and time-reversible, and keeps `|L|` to
//! round-off like the Strang flow it is built from. Used inside the drift–kick–drift step, it is
//! fourth order for torque-free rotation and exact for constant forces; a torque sampled once per
//! step makes the coupled motion second order. Cost: three Strang flows per drift, each the very
//! flow `splitting` runs (`symmetric_kernel`), in one start-to-finish pass.

use super::symmetric_kernel::{Flowing, SymmetricInput, to_real};
use crate::math::{Quat, Real, Vec3, Widen};

/// `c₁ = 1/(2 − 2^{1/3})`.
const C1: f64 = 1.351_207_191_959_657_8;
/// `c₀ = 1 − 2c₁`.
const C0: f64 = 1.0 - 2.0 * C1;

/// The fourth-order free rotation `Ψ_h = Φ_{c₁h} ∘ Φ_{c₀h} ∘ Φ_{c₁h}` of one body: the new
/// `(q, ω)`, rounded to the engine precision once.
#[inline]
pub(super) fn rotate_yoshida_one(input: &SymmetricInput, h: Real) -> (Quat, Vec3) {
    let h = h.widen();
    let mut flowing = Flowing::<f64>::start(input);
    flowing.symmetric_flow(C1 * h);
    flowing.symmetric_flow(C0 * h);
    flowing.symmetric_flow(C1 * h);
    let (q, w) = flowing.finish();
    to_real(q, w)
}
