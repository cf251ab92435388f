//! Typed errors for invalid physical input.

use crate::math::{Quat, REAL_NAME, Real, Vec3};
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
    #[error("mass must be > 0 and finite, got {}", compact(*.0))]
    NonPositiveMass(Real),
    /// Density must be strictly positive and finite.
    #[error("density must be > 0 and finite, got {}", compact(*.0))]
    NonPositiveDensity(Real),
    /// A principal moment of inertia is negative (or NaN).
    #[error("principal inertia must be >= 0 on every axis, got [{}, {}, {}]", compact(.0[0]), compact(.0[1]), compact(.0[2]))]
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
    #[error("time step must be > 0 and finite, got {}", compact(*.0))]
    NonPositiveTimeStep(Real),
    /// A positive time step too small or too large for the build precision ([`Real`]) to
    /// step: see [`check_time_step`].
    #[error(
        "time step {} s cannot be stepped in {REAL_NAME}: the parts of a step, from a third of \
         it to 1.7 times it, must be normal, finite numbers; expected a value between {} and {}",
        compact(*.0),
        compact(TIME_STEP_RANGE.0),
        compact(TIME_STEP_RANGE.1)
    )]
    TimeStepOutOfRange(Real),
    /// Substeps that divide a valid time step into parts too short for the build precision
    /// ([`Real`]) to step: `Δt / N` is below [`TIME_STEP_RANGE`] (see [`check_substeps`]).
    #[error(
        "{substeps} substeps of a {} s step are {} s each, too short to step in {REAL_NAME}: \
         expected at least {} s a substep",
        compact(*.dt),
        compact(*.dt / *.substeps as Real),
        compact(TIME_STEP_RANGE.0)
    )]
    SubstepOutOfRange {
        /// The time step `Δt` (s).
        dt: Real,
        /// The number of substeps `N`.
        substeps: u32,
    },
    /// A mass or principal moment whose reciprocal is not a finite, normal number in the build
    /// precision ([`Real`]): the engine stores `1/m` and `1/I`, so such a body would be
    /// quarantined at its first step (or move with a garbage inverse).
    #[error(
        "{field} {} has no usable reciprocal in {REAL_NAME}; expected a value between {} and {}",
        compact(*.value),
        compact(*.min),
        compact(*.max)
    )]
    ReciprocalOutOfRange {
        /// Which quantity, e.g. `"mass"`.
        field: &'static str,
        /// The offending value.
        value: Real,
        /// The smallest accepted value.
        min: Real,
        /// The largest accepted value.
        max: Real,
    },
    /// Principal moments that violate the triangle inequality `I_a ≤ I_b + I_c`, which every
    /// rigid body satisfies (see [`crate::MassProperties::new`]).
    #[error(
        "principal inertia [{}, {}, {}] violates the triangle inequality: {} > {} + {}; no rigid \
         body has such moments (each must be at most the sum of the other two)",
        compact(.moments[0]),
        compact(.moments[1]),
        compact(.moments[2]),
        compact(.moments[*.axis]),
        compact(.moments[(*.axis + 1) % 3]),
        compact(.moments[(*.axis + 2) % 3])
    )]
    TriangleInequality {
        /// The principal moments.
        moments: [Real; 3],
        /// The axis whose moment is too large.
        axis: usize,
    },
    /// Saved data whose parts disagree (e.g. moments and their stored reciprocals).
    #[error("inconsistent saved data: {0}")]
    Inconsistent(&'static str),
    /// A coefficient that must be finite and `>= 0` (e.g. a damping rate) is negative or NaN.
    #[error("{field} must be >= 0 and finite, got {}", compact(*.value))]
    Negative {
        /// Which quantity, e.g. `"linear"` (of `Damping`).
        field: &'static str,
        /// The offending value.
        value: Real,
    },
}

/// Checks that the coefficient `value` is finite and `>= 0` (NaN fails).
pub fn check_non_negative(field: &'static str, value: Real) -> Result<(), InvalidInput> {
    if value >= 0.0 && value.is_finite() {
        Ok(())
    } else {
        Err(InvalidInput::Negative { field, value })
    }
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

/// The fast half of the unit-quaternion test: `||q|² − 1| ≤` [`UNIT_QUATERNION_TOLERANCE`],
/// without a square root. `|q|² − 1 = (|q| − 1)(|q| + 1)`, so it implies `||q| − 1| ≤ tol`; a
/// quaternion it rejects may still pass the exact test of [`check_unit_quat`] (the rare one in
/// between). False for a non-finite quaternion.
#[inline(always)]
pub fn is_clearly_unit(q: Quat) -> bool {
    (q.length_squared() - 1.0).abs() <= UNIT_QUATERNION_TOLERANCE
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

/// The time steps every integrator can step, `[8 MIN_POSITIVE, MAX / 4]` of [`Real`]: a step
/// takes stages of up to `1.71 Δt` in size (the middle stage of `yoshida4`, negative) and
/// parts of stages down to `0.34 Δt` (a drift of half an outer stage of `yoshida4`, `1.35 Δt`,
/// is `0.68 Δt`, and a splitting's half-flows halve that), and each must be a normal, finite
/// number: a part that underflows to zero (or to a subnormal, most of its digits gone) leaves
/// a body where it was while its velocity says it moves, and a stage that overflows sends every
/// moving body to infinity. The range keeps a factor of two beyond both.
pub const TIME_STEP_RANGE: (Real, Real) = (8.0 * Real::MIN_POSITIVE, Real::MAX / 4.0);

/// Checks that a time step is strictly positive and finite, and within [`TIME_STEP_RANGE`].
pub fn check_time_step(dt: Real) -> Result<(), InvalidInput> {
    if !(dt.is_finite() && dt > 0.0) {
        Err(InvalidInput::NonPositiveTimeStep(dt))
    } else if !(TIME_STEP_RANGE.0..=TIME_STEP_RANGE.1).contains(&dt) {
        Err(InvalidInput::TimeStepOutOfRange(dt))
    } else {
        Ok(())
    }
}

/// Checks that `substeps` substeps of the valid time step `dt` are each a step the precision
/// can take: `Δt / N` within [`TIME_STEP_RANGE`] (a step is `N` substeps of `Δt / N`, each with
/// the stages [`TIME_STEP_RANGE`] describes). Checks `dt` itself first.
pub fn check_substeps(dt: Real, substeps: std::num::NonZeroU32) -> Result<(), InvalidInput> {
    check_time_step(dt)?;
    if check_time_step(dt / substeps.get() as Real).is_err() {
        Err(InvalidInput::SubstepOutOfRange {
            dt,
            substeps: substeps.get(),
        })
    } else {
        Ok(())
    }
}

/// A number formatted compactly for messages: plain decimals between `1e-4` and `1e6`, the
/// shortest exponent form (`1e-50`, `3.4028235e38`) outside that range, so that a tiny or huge
/// value never prints as hundreds of digits. The digits are the shortest that read back as the
/// same value in the number's own type (`f32` or `f64`).
pub fn compact<T>(x: T) -> String
where
    T: Copy + Into<f64> + std::fmt::Display + std::fmt::LowerExp,
{
    let magnitude = x.into().abs();
    if magnitude == 0.0 || !magnitude.is_finite() || (1e-4..1e6).contains(&magnitude) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}
