//! Analytic reference solutions in f64, for measuring the integrators against:
//!
//! - [`projectile`]: uniform acceleration, `x = x₀ + v₀t + ½gt²`;
//! - [`harmonic_spring`] / [`HarmonicSpring`]: undamped spring, `x = x₀ cos ωt + (v₀/ω) sin ωt`,
//!   `ω = √(k/m)`;
//! - [`damped_spring`] / [`DampedSpring`]: damped oscillator `m ẍ + c ẋ + k x = 0`, under-,
//!   critically and over-damped, `x = e^{−γt}(x₀ C(t) + (v₀ + γx₀) S(t))`, `γ = c/(2m)`;
//! - [`TorqueFreeTop`]: the torque-free rigid body through Jacobi elliptic functions (Landau &
//!   Lifshitz, *Mechanics*, §37), with the symmetric top and steady spins in closed form;
//! - [`elliptic`] (re-exported from the crate root, where the exact free flow uses it): the
//!   Jacobi functions `sn, cn, dn` and the integrals `K(m)`, `F(φ | m)` it rests on.

pub mod linear;
pub mod top;

use thiserror::Error;

pub use linear::{
    DampedSpring, DampingRegime, HarmonicSpring, damped_spring, harmonic_spring, projectile,
};
pub use top::{TopMotion, TorqueFreeTop};
pub use tumble_core::elliptic;
pub use tumble_core::elliptic::{complete_k, incomplete_f, jacobi_amplitude, jacobi_sn_cn_dn};

/// Largest accepted `||q₀| − 1|` of an initial orientation; it is renormalized on input.
///
/// Same as the crate-wide [`tumble_core::UNIT_QUATERNION_TOLERANCE`], so any state the engine
/// accepts can seed a reference.
pub const ORIENTATION_TOLERANCE: f64 = 1e-4;

/// Why an exact solution could not be built from its input.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum ExactError {
    /// Every principal moment must be finite and `> 0`.
    #[error("principal moments must be finite and > 0, got {0:?}")]
    BadInertia([f64; 3]),
    /// An initial value (rate, position, velocity, orientation) is NaN or infinite.
    #[error("{0} is not finite")]
    NonFinite(&'static str),
    /// The initial orientation is not a unit quaternion within [`ORIENTATION_TOLERANCE`].
    #[error("initial orientation is not a unit quaternion: |q| = {0}")]
    NonUnitQuaternion(f64),
    /// Spring stiffness and mass must be finite and `> 0`.
    #[error("spring stiffness and mass must be finite and > 0, got k = {stiffness}, m = {mass}")]
    BadSpring {
        /// The stiffness given (N/m).
        stiffness: f64,
        /// The mass given (kg).
        mass: f64,
    },
    /// Spring damping must be finite and `>= 0`.
    #[error("spring damping must be finite and >= 0, got c = {0}")]
    BadDamping(f64),
}

#[cfg(test)]
mod tolerance_tests {
    use tumble_core::math::Narrow;

    #[test]
    fn orientation_tolerance_is_the_engine_tolerance() {
        assert_eq!(
            super::ORIENTATION_TOLERANCE.narrow(),
            tumble_core::UNIT_QUATERNION_TOLERANCE
        );
    }
}
