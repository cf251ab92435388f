//! Linear damping as a flow of its own, Strang-split around the conservative step.
//!
//! A damping term `u̇ = −λ u` (the `Damping` component of `tumble_ecs`, `v̇ = −c v`, or a
//! spring's damper along its axis) is integrated as the flow
//! `u(τ) = e^{−λτ} u`, applied for half a step before the integrator's conservative step and
//! half a step after it:
//!
//! ```text
//! step(h) = D(h/2) ∘ Φ(h) ∘ D(h/2)
//! ```
//!
//! The composition is symmetric, so with a second-order `Φ` (drift–kick–drift) the damped step
//! is second order; applying the damping inside the kick (a force `−c u` at the start-of-step
//! velocity) or once after the step (the Padé form `v ← v / (1 + Δt c)` that rapier and avian
//! use) is a first-order splitting. Every `D` only shrinks a velocity, so it never adds energy,
//! for any `λ Δt`.

use crate::math::Real;

/// The decay factor `e^{−x}` of the damping flow over a dimensionless time `x = λτ ≥ 0`, by the
/// rational approximation
///
/// ```text
/// decay(x) = 1 / (1 + x + x²/2 + x³/6)      (= e^{−x} + O(x⁴))
/// ```
///
/// (the reciprocal of the cubic Taylor polynomial of `eˣ`). It lies in `(0, 1]` for every
/// `x ≥ 0`, tends to 0 as `x → ∞` (a huge `λΔt` stops the motion instead of reversing it) and is
/// exact enough for a second-order step: its error `O(x⁴)` per half step is below the step's own
/// `O(Δt³)`. It deliberately avoids the platform `exp`, whose last bits differ between libms:
/// a step must give the same bits on every platform (the remaining platform transcendentals on
/// the step path are a separate issue). Negative or NaN `x` (a negative damping coefficient,
/// which the components document as invalid) is treated as 0: no decay, never growth.
#[inline]
pub fn decay(x: Real) -> Real {
    1.0 / (1.0 + growth(x))
}

/// `1 − decay(x)`: the fraction of the velocity the flow removes over `x = λτ`, computed without
/// the cancellation of `1 − decay(x)` at small `x` (in `f32`, `x = 10⁻⁴` would lose three
/// digits of the decrement, a bias in the damping rate rather than round-off):
///
/// ```text
/// decrement(x) = p / (1 + p),    p = x + x²/2 + x³/6
/// ```
///
/// In `[0, 1)` for finite `x ≥ 0`, 1 at `x = +∞`, 0 for negative or NaN `x`. Apply a damping
/// flow as `u ← u − decrement(λτ) u` (the same value as `decay(λτ) u`, rounded better).
#[inline]
pub fn decrement(x: Real) -> Real {
    let p = growth(x);
    if p < 1.0 {
        p / (1.0 + p)
    } else {
        // No cancellation once decay ≤ ½, and p = +∞ gives 1 instead of ∞/∞.
        1.0 - 1.0 / (1.0 + p)
    }
}

/// `p = x + x²/2 + x³/6` (the cubic Taylor polynomial of `eˣ` minus 1) for `x ≥ 0`; negative
/// and NaN `x` count as 0. Overflows to `+∞` beyond `x ≈ 10¹³` in `f32` (decay 0).
#[inline]
fn growth(x: Real) -> Real {
    let x = x.max(0.0);
    x * (1.0 + x * (0.5 + x * (1.0 / 6.0)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::to_f64;

    #[test]
    fn decay_is_a_third_order_contraction() {
        assert_eq!(decay(0.0), 1.0);
        assert_eq!(decay(-1.0), 1.0);
        assert_eq!(decay(Real::NAN), 1.0);
        assert_eq!(decay(Real::INFINITY), 0.0);
        assert_eq!(decay(Real::MAX), 0.0);
        let mut previous = 1.0;
        for k in 0..200 {
            let x = 1e-4 * (1.12 as Real).powi(k);
            let d = decay(x);
            assert!(d > 0.0 && d <= 1.0 && d <= previous, "decay({x}) = {d}");
            previous = d;
        }
        for x in [0.0, 1e-6, 1e-3, 0.7, 5.0, 1e20, Real::INFINITY] {
            let (d, r) = (decay(x), decrement(x));
            assert!((0.0..=1.0).contains(&r), "decrement({x}) = {r}");
            assert!((d + r - 1.0).abs() <= Real::EPSILON, "x = {x}: {d} + {r}");
        }
        // The decrement keeps its relative accuracy where 1 − decay(x) cancels: within a few
        // ε of 1 − e^{−x}, plus the approximation's own x⁴/24 (relative x³/24).
        let x: Real = 1e-4;
        let exact = -(-to_f64(x)).exp_m1();
        let tolerance = 4.0 * to_f64(Real::EPSILON) + to_f64(x).powi(3) / 24.0;
        assert!((to_f64(decrement(x)) / exact - 1.0).abs() < tolerance);
        // Error ≈ x⁴/24 for small x (the next Taylor term): check the order, above round-off.
        for x in [0.05_f64, 0.1, 0.2] {
            let err = (to_f64(decay(x as Real)) - (-x).exp()).abs();
            let leading = x.powi(4) / 24.0;
            assert!(
                err < 1.5 * leading + 4.0 * to_f64(Real::EPSILON),
                "x = {x}: error {err:e} vs x⁴/24 = {leading:e}"
            );
        }
    }
}
