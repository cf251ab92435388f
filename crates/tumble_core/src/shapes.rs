//! Mass properties of parry3d shapes (feature `parry`).
//!
//! parry computes the volume integrals (ball, cuboid, capsule, cylinder, cone, convex hull,
//! compound, …); this module turns them into validated [`MassProperties`] given a [`Density`].
//! parry and tumble share glam 0.33, so no conversion of vectors or quaternions is needed.

use parry3d::shape::Shape;

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
    from_parry(&shape.mass_properties(density.get()))
}

/// Converts parry's mass properties into tumble's, validating them.
///
/// parry stores inverse moments with `0` meaning "infinite inertia"; tumble stores moments with
/// `0` meaning "locked axis". Both describe an axis that torques cannot spin up, so a zero inverse
/// maps to a zero moment.
pub fn from_parry(
    props: &parry3d::mass_properties::MassProperties,
) -> Result<MassProperties, InvalidInput> {
    let mass = Mass::new(props.mass())?;
    MassProperties::new(mass, props.principal_inertia())?
        .with_principal_frame(props.principal_inertia_local_frame)?
        .with_center_of_mass(props.local_com)
}
