//! Rigid-body state and the external load applied over one step.

use crate::error::{
    InvalidInput, UNIT_QUATERNION_TOLERANCE, check_finite_vec3, check_unit_quat, is_clearly_unit,
};
use crate::math::{Quat, Vec3};

/// Kinematic state of one rigid body.
///
/// `position` is the world position of the centre of mass, `rotation` maps body coordinates to
/// world coordinates, `angular_velocity` is in world coordinates.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct BodyState {
    /// World position of the centre of mass `x` (m).
    pub position: Vec3,
    /// Orientation `q`, body → world, unit quaternion.
    pub rotation: Quat,
    /// Linear velocity of the centre of mass `v` (m/s).
    pub linear_velocity: Vec3,
    /// Angular velocity `ω` in world coordinates (rad/s).
    pub angular_velocity: Vec3,
}

impl Default for BodyState {
    fn default() -> Self {
        Self {
            position: Vec3::ZERO,
            rotation: Quat::IDENTITY,
            linear_velocity: Vec3::ZERO,
            angular_velocity: Vec3::ZERO,
        }
    }
}

impl BodyState {
    /// Every byte zero (even the rotation, so this is not a valid state): for scratch buffers
    /// that are overwritten field by field before use.
    pub const ZEROED: Self = Self {
        position: Vec3::ZERO,
        rotation: Quat::from_xyzw(0.0, 0.0, 0.0, 0.0),
        linear_velocity: Vec3::ZERO,
        angular_velocity: Vec3::ZERO,
    };

    /// Copies `from`'s fields into `self` one by one, leaving `self`'s padding bytes as they
    /// are (zero in a [`ZEROED`](Self::ZEROED) scratch value). A whole-struct copy may carry
    /// stale padding bytes along, and vectorized code reads them as a fourth lane: when they
    /// form a subnormal float, every operation on that lane takes a microcode assist.
    #[inline(always)]
    pub fn copy_fields_from(&mut self, from: &BodyState) {
        self.position = from.position;
        self.rotation = from.rotation;
        self.linear_velocity = from.linear_velocity;
        self.angular_velocity = from.angular_velocity;
    }

    /// True when every component is finite.
    #[inline]
    pub fn is_finite(&self) -> bool {
        // Branch-free: `0 · x` is 0 for finite x and NaN for ±Inf and NaN, and one NaN makes
        // the sum NaN.
        let (p, v, w, q) = (
            self.position,
            self.linear_velocity,
            self.angular_velocity,
            self.rotation,
        );
        let vectors = p * 0.0 + v * 0.0 + w * 0.0;
        let quat = crate::math::Vec4::from(q) * 0.0;
        (vectors.x + vectors.y + vectors.z + quat.x + quat.y + quat.z + quat.w) == 0.0
    }

    /// True when every component is finite and the rotation is a unit quaternion within
    /// [`UNIT_QUATERNION_TOLERANCE`]: the test [`validate`](Self::validate) makes, as a `bool`
    /// (no allocation), which a step's result must pass to be committed.
    #[inline]
    pub fn is_valid(&self) -> bool {
        // `is_finite` first: the length of a non-finite quaternion is NaN or Inf anyway, but
        // a finite state is the common case and the cheap test is branch-free. Then the squared
        // norm, without a square root: `|q|² − 1 = (|q| − 1)(|q| + 1)`, so
        // `||q|² − 1| ≤ tol` implies `||q| − 1| ≤ tol` (with room for the rounding of the root);
        // only a quaternion in between takes the exact test.
        self.is_finite()
            && (is_clearly_unit(self.rotation)
                || (self.rotation.length() - 1.0).abs() <= UNIT_QUATERNION_TOLERANCE)
    }

    /// Checks that every component is finite and the rotation is a unit quaternion.
    pub fn validate(&self) -> Result<(), InvalidInput> {
        check_finite_vec3("position", self.position)?;
        check_unit_quat("rotation", self.rotation)?;
        check_finite_vec3("linear velocity", self.linear_velocity)?;
        check_finite_vec3("angular velocity", self.angular_velocity)
    }
}

/// Net external load on a body, held constant over one step (zero-order hold).
///
/// `torque` is about the centre of mass, in world coordinates.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Wrench {
    /// Net force `F` (N), world frame.
    pub force: Vec3,
    /// Net torque `τ` about the centre of mass (N·m), world frame.
    pub torque: Vec3,
}

impl Wrench {
    /// No force, no torque.
    pub const ZERO: Self = Self {
        force: Vec3::ZERO,
        torque: Vec3::ZERO,
    };

    /// Checks that force and torque are finite.
    pub fn validate(&self) -> Result<(), InvalidInput> {
        check_finite_vec3("force", self.force)?;
        check_finite_vec3("torque", self.torque)
    }

    /// True when both force and torque are finite.
    #[inline]
    pub fn is_finite(&self) -> bool {
        self.force.is_finite() && self.torque.is_finite()
    }
}
