//! Analytic reference solutions in f64: projectile, undamped harmonic spring, and the
//! torque-free asymmetric top through Jacobi elliptic functions (Landau & Lifshitz §37).

pub mod elliptic;
pub mod linear;
pub mod top;

use thiserror::Error;

pub use elliptic::{complete_k, incomplete_f, jacobi_sn_cn_dn};
pub use linear::{harmonic_spring, projectile};
pub use top::TorqueFreeTop;

/// Invalid input to an exact solution.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum ExactError {
    /// Principal moments must be finite and > 0.
    #[error("principal moments must be finite and > 0, got {0:?}")]
    BadInertia([f64; 3]),
    /// Two principal moments are (nearly) equal: use the symmetric-top closed form instead.
    #[error("principal moments {0:?} are not distinct (relative gap < 1e-9)")]
    NotAsymmetric([f64; 3]),
    /// Initial rates or orientation not finite, or the quaternion is not unit.
    #[error("initial state is not finite or the orientation is not a unit quaternion")]
    BadState,
    /// Stiffness and mass must be finite and > 0.
    #[error("stiffness and mass must be finite and > 0")]
    BadSpring,
}
