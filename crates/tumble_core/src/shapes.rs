//! Mass properties of parry shapes (feature `parry`, or `parry-f64` for double precision).
//!
//! parry computes the volume integrals (ball, cuboid, capsule, cylinder, cone, convex hull,
//! compound, …); this module turns them into validated [`MassProperties`] given a [`Density`].
//! parry and tumble share glam 0.33, so vectors and quaternions pass without conversion.
//!
//! The backend, re-exported as [`parry`]: `parry3d` in the default build, `parry3d-f64` with
//! `parry-f64`. An `f64` build with only `parry` keeps the `f32` shapes of `parry3d` and widens
//! their mass properties exactly (the integrals themselves then carry `f32` round-off).

#[cfg(all(feature = "parry", not(feature = "parry-f64")))]
pub use parry3d as parry;
#[cfg(feature = "parry-f64")]
pub use parry3d_f64 as parry;

use parry::shape::Shape;

use crate::error::InvalidInput;
use crate::mass::{Density, Mass, MassProperties};

/// Mass properties of `shape` made of a uniform material of the given `density`.
///
/// The mass is `ρ V`, the centre of mass and principal frame are parry's, in shape coordinates.
/// A shape without volume (e.g. a flat triangle) yields [`InvalidInput::NonPositiveMass`].
pub fn mass_properties_of(
    shape: &dyn Shape,
    density: Density,
) -> Result<MassProperties, InvalidInput> {
    from_parry(&shape.mass_properties(parry_density(density)))
}

/// Converts parry's mass properties into tumble's, validating them.
///
/// parry stores inverse moments with `0` meaning "infinite inertia"; tumble stores moments with
/// `0` meaning "locked axis". Both describe an axis that torques cannot spin up, so a zero inverse
/// maps to a zero moment.
pub fn from_parry(
    props: &parry::mass_properties::MassProperties,
) -> Result<MassProperties, InvalidInput> {
    let mass = Mass::new(to_real(props.mass()))?;
    MassProperties::new(mass, to_real(props.principal_inertia()))?
        .with_principal_frame(to_real(props.principal_inertia_local_frame))?
        .with_center_of_mass(to_real(props.local_com))
}

/// parry's numbers in the engine's precision: the identity unless an `f64` engine reads `f32`
/// shapes, which widens exactly.
#[cfg(any(not(feature = "f64"), feature = "parry-f64"))]
#[inline]
fn to_real<T>(value: T) -> T {
    value
}

/// parry's numbers in the engine's precision: an `f64` engine reading `f32` shapes widens exactly.
#[cfg(all(feature = "f64", not(feature = "parry-f64")))]
#[inline]
fn to_real<T: WidenParry>(value: T) -> T::Wide {
    value.widen_parry()
}

/// The density handed to parry, in parry's precision.
#[cfg(any(not(feature = "f64"), feature = "parry-f64"))]
#[inline]
fn parry_density(density: Density) -> crate::math::Real {
    density.get()
}

/// The density handed to parry3d's `f32` shapes from an `f64` engine (one rounding).
#[cfg(all(feature = "f64", not(feature = "parry-f64")))]
#[inline]
fn parry_density(density: Density) -> f32 {
    density.get() as f32
}

/// parry3d's `f32` numbers widened exactly for an `f64` engine.
#[cfg(all(feature = "f64", not(feature = "parry-f64")))]
trait WidenParry {
    /// The `f64` counterpart.
    type Wide;
    /// `self` in `f64`, exactly.
    fn widen_parry(self) -> Self::Wide;
}

#[cfg(all(feature = "f64", not(feature = "parry-f64")))]
impl WidenParry for f32 {
    type Wide = f64;
    fn widen_parry(self) -> f64 {
        f64::from(self)
    }
}

#[cfg(all(feature = "f64", not(feature = "parry-f64")))]
impl WidenParry for glam::Vec3 {
    type Wide = glam::DVec3;
    fn widen_parry(self) -> glam::DVec3 {
        self.as_dvec3()
    }
}

#[cfg(all(feature = "f64", not(feature = "parry-f64")))]
impl WidenParry for glam::Quat {
    type Wide = glam::DQuat;
    fn widen_parry(self) -> glam::DQuat {
        self.as_dquat()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::{Real, to_f64};

    /// A ball against `m = ρ 4/3 π r³`, `I = 2/5 m r²` in every precision combination (parry
    /// integrates in its own precision: a few ulps of `f32` at worst).
    #[test]
    fn ball_mass_properties_match_the_closed_form() {
        let (rho, r) = (1000.0, 0.5);
        let props = mass_properties_of(
            &parry::shape::Ball::new(0.5),
            Density::new(rho as Real).unwrap(),
        )
        .unwrap();
        let m = rho * 4.0 / 3.0 * std::f64::consts::PI * r * r * r;
        let tolerance = 1e-5;
        assert!((to_f64(props.mass()) / m - 1.0).abs() < tolerance);
        let inertia = props.principal_inertia();
        for moment in [inertia.x, inertia.y, inertia.z] {
            assert!((to_f64(moment) / (0.4 * m * r * r) - 1.0).abs() < tolerance);
        }
    }
}
