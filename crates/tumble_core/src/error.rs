//! Typed errors for invalid physical input.

use crate::math::{Quat, Real, Vec3};
use thiserror::Error;

/// Largest accepted deviation `||q| − 1|` of a rotation quaternion.
///
/// Quaternions built with glam's constructors are unit to about 1e-7; the integrators renormalize
/// every step. Anything beyond this tolerance is a bug in the caller, not round-off.
pub const UNIT_QUATERNION_TOLERANCE: Real = 1e-4;

/// Why a piece of physical input was rejected.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum InvalidInput {
    /// A value that must be finite is NaN or infinite.
    #[error("{field} is not finite ({value})")]
    NonFinite {
        /// Which quantity, e.g. `"linear velocity"`.
        field: &'static str,
        /// The offending value, formatted.
        value: String,
    },
    /// Mass must be strictly positive and finite.
    #[error("mass must be > 0 and finite, got {0}")]
    NonPositiveMass(Real),
    /// Density must be strictly positive and finite.
    #[error("density must be > 0 and finite, got {0}")]
    NonPositiveDensity(Real),
    /// A principal moment of inertia is negative (or NaN).
    #[error("principal inertia must be >= 0 on every axis, got [{}, {}, {}]", .0[0], .0[1], .0[2])]
    NegativeInertia([Real; 3]),
    /// All principal moments are zero: the body could not rotate at all and has no inertia tensor.
    #[error("principal inertia is zero on every axis; give at least one axis a positive moment")]
    ZeroInertia,
    /// A rotation quaternion is not of unit length.
    #[error(
        "{field} is not a unit quaternion: |q| = {norm} (tolerance {UNIT_QUATERNION_TOLERANCE})"
    )]
    NonUnitQuaternion {
        /// Which quaternion, e.g. `"rotation"`.
        field: &'static str,
        /// Its length.
        norm: Real,
    },
    /// The time step must be strictly positive and finite.
    #[error("time step must be > 0 and finite, got {0}")]
    NonPositiveTimeStep(Real),
    /// Saved data whose parts disagree (e.g. moments and their stored reciprocals).
    #[error("inconsistent saved data: {0}")]
    Inconsistent(&'static str),
}

/// Checks that `value` is finite.
pub fn check_finite_vec3(field: &'static str, value: Vec3) -> Result<(), InvalidInput> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(InvalidInput::NonFinite {
            field,
            value: format!("{value}"),
        })
    }
}

/// Checks that `q` is finite and of unit length within [`UNIT_QUATERNION_TOLERANCE`].
pub fn check_unit_quat(field: &'static str, q: Quat) -> Result<(), InvalidInput> {
    if !q.is_finite() {
        return Err(InvalidInput::NonFinite {
            field,
            value: format!("{q}"),
        });
    }
    let norm = q.length();
    if (norm - 1.0).abs() > UNIT_QUATERNION_TOLERANCE {
        return Err(InvalidInput::NonUnitQuaternion { field, norm });
    }
    Ok(())
}

/// Checks that a time step is strictly positive and finite.
pub fn check_time_step(dt: Real) -> Result<(), InvalidInput> {
    if dt.is_finite() && dt > 0.0 {
        Ok(())
    } else {
        Err(InvalidInput::NonPositiveTimeStep(dt))
    }
}
