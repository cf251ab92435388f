//! `serde` support (feature `serde`): plain state types derive it; types that are valid by
//! construction go through a checked mirror, so a deserialized value is exactly the saved one
//! (bit for bit, for an exact resume) and never an invalid one.

use crate::math::{Quat, Real, Vec3};
use serde::{Deserialize, Serialize};

use crate::error::{InvalidInput, check_finite_vec3, check_unit_quat};
use crate::integrate::Integrator;
use crate::mass::MassProperties;

/// The stored fields of a [`MassProperties`], as saved.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct MassPropertiesData {
    pub inv_mass: Real,
    pub principal_inertia: Vec3,
    pub inv_principal_inertia: Vec3,
    pub principal_frame: Quat,
    pub local_center_of_mass: Vec3,
}

impl TryFrom<MassPropertiesData> for MassProperties {
    type Error = InvalidInput;

    /// Accepts the saved fields only if they are what the constructors would have produced:
    /// positive finite inverse mass, valid moments with their exact reciprocals, a unit frame,
    /// a finite centre of mass. Nothing is recomputed, so the value is restored bit for bit.
    fn try_from(d: MassPropertiesData) -> Result<Self, InvalidInput> {
        if !(d.inv_mass.is_finite() && d.inv_mass > 0.0) {
            return Err(InvalidInput::NonPositiveMass(1.0 / d.inv_mass));
        }
        check_unit_quat("principal frame", d.principal_frame)?;
        check_finite_vec3("centre of mass", d.local_center_of_mass)?;
        let rebuilt =
            MassProperties::new(crate::Mass::new(1.0 / d.inv_mass)?, d.principal_inertia)?;
        if rebuilt.inv_principal_inertia() != d.inv_principal_inertia {
            return Err(InvalidInput::Inconsistent("reciprocal principal moments"));
        }
        Ok(MassProperties::from_parts(
            d.inv_mass,
            d.principal_inertia,
            d.inv_principal_inertia,
            d.principal_frame,
            d.local_center_of_mass,
        ))
    }
}

impl From<MassProperties> for MassPropertiesData {
    fn from(m: MassProperties) -> Self {
        Self {
            inv_mass: m.inv_mass(),
            principal_inertia: m.principal_inertia(),
            inv_principal_inertia: m.inv_principal_inertia(),
            principal_frame: m.principal_frame(),
            local_center_of_mass: m.local_center_of_mass(),
        }
    }
}

impl Serialize for Integrator {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.name())
    }
}

impl<'de> Deserialize<'de> for Integrator {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let name = String::deserialize(d)?;
        name.parse().map_err(serde::de::Error::custom)
    }
}
