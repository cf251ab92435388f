//! Mass properties: mass, principal moments of inertia, principal frame, centre of mass.
//!
//! [`Mass`] and [`Density`] are distinct types, so a density can never be passed where a mass is
//! expected (or the reverse).

use crate::error::{InvalidInput, check_finite_vec3, check_unit_quat};
use crate::math::{Quat, Real, Vec3};

/// A mass in kilograms, strictly positive and finite.
#[derive(Debug, Clone, Copy, PartialEq, PartialOrd)]
pub struct Mass(Real);

impl Mass {
    /// Creates a mass; rejects values that are not finite or not `> 0`.
    pub fn new(kilograms: Real) -> Result<Self, InvalidInput> {
        if kilograms.is_finite() && kilograms > 0.0 {
            Ok(Self(kilograms))
        } else {
            Err(InvalidInput::NonPositiveMass(kilograms))
        }
    }

    /// The mass in kilograms.
    #[inline]
    pub fn get(self) -> Real {
        self.0
    }
}

/// A density in kilograms per cubic metre, strictly positive and finite.
///
/// A density is not a mass: passing one where a [`Mass`] is expected does not compile.
///
/// ```compile_fail
/// use tumble_core::{Density, MassProperties};
/// let rho = Density::new(1000.0).unwrap();
/// let props = MassProperties::new(rho, tumble_core::math::Vec3::ONE); // error: expected `Mass`
/// ```
#[derive(Debug, Clone, Copy, PartialEq, PartialOrd)]
pub struct Density(Real);

impl Density {
    /// Creates a density; rejects values that are not finite or not `> 0`.
    pub fn new(kg_per_m3: Real) -> Result<Self, InvalidInput> {
        if kg_per_m3.is_finite() && kg_per_m3 > 0.0 {
            Ok(Self(kg_per_m3))
        } else {
            Err(InvalidInput::NonPositiveDensity(kg_per_m3))
        }
    }

    /// The density in kg/m³.
    #[inline]
    pub fn get(self) -> Real {
        self.0
    }
}

/// Mass properties of a rigid body, always valid once constructed.
///
/// The inertia tensor about the centre of mass, in body coordinates, is
/// `I = P diag(I_b) Pᵀ` with `P` = [`principal_frame`](Self::principal_frame) (principal → body).
/// In world coordinates it is `(R P) diag(I_b) (R P)ᵀ`; its inverse uses the stored reciprocal
/// moments, where a zero moment locks that axis (`1/0` is stored as `0`): no torque can spin the
/// body about it and every integrator holds the angular velocity about it at zero.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(
        try_from = "crate::serde_impls::MassPropertiesData",
        into = "crate::serde_impls::MassPropertiesData"
    )
)]
pub struct MassProperties {
    inv_mass: Real,
    principal_inertia: Vec3,
    inv_principal_inertia: Vec3,
    principal_frame: Quat,
    local_center_of_mass: Vec3,
}

/// Reciprocal of a principal moment, with `0` for a locked (zero-moment) axis.
#[inline]
fn locked_reciprocal(moment: Real) -> Real {
    if moment > 0.0 { 1.0 / moment } else { 0.0 }
}

impl MassProperties {
    /// Assembles already-validated parts (used by deserialization after its checks).
    #[cfg(feature = "serde")]
    pub(crate) fn from_parts(
        inv_mass: Real,
        principal_inertia: Vec3,
        inv_principal_inertia: Vec3,
        principal_frame: Quat,
        local_center_of_mass: Vec3,
    ) -> Self {
        Self {
            inv_mass,
            principal_inertia,
            inv_principal_inertia,
            principal_frame,
            local_center_of_mass,
        }
    }

    /// Mass properties from a mass and principal moments of inertia (kg·m²) about body axes,
    /// centre of mass at the body origin.
    ///
    /// Moments must be `>= 0` and finite, and not all zero. A zero moment locks that axis.
    pub fn new(mass: Mass, principal_inertia: Vec3) -> Result<Self, InvalidInput> {
        check_finite_vec3("principal inertia", principal_inertia)?;
        // `!(x >= 0)` also catches NaN.
        if !principal_inertia.cmpge(Vec3::ZERO).all() {
            return Err(InvalidInput::NegativeInertia(principal_inertia.to_array()));
        }
        if principal_inertia == Vec3::ZERO {
            return Err(InvalidInput::ZeroInertia);
        }
        Ok(Self {
            inv_mass: 1.0 / mass.get(),
            principal_inertia,
            inv_principal_inertia: Vec3::new(
                locked_reciprocal(principal_inertia.x),
                locked_reciprocal(principal_inertia.y),
                locked_reciprocal(principal_inertia.z),
            ),
            principal_frame: Quat::IDENTITY,
            local_center_of_mass: Vec3::ZERO,
        })
    }

    /// A solid sphere of the given mass and radius: `I = 2/5 m r²` on every axis.
    pub fn solid_sphere(mass: Mass, radius: Real) -> Result<Self, InvalidInput> {
        let moment = 0.4 * mass.get() * radius * radius;
        Self::new(mass, Vec3::splat(moment))
    }

    /// A solid box of the given mass and half extents `(a, b, c)`:
    /// `I = m/3 (b² + c², a² + c², a² + b²)` (full edge `2a`: `m (4b² + 4c²)/12`).
    pub fn solid_cuboid(mass: Mass, half_extents: Vec3) -> Result<Self, InvalidInput> {
        let h2 = half_extents * half_extents;
        let m3 = mass.get() / 3.0;
        Self::new(
            mass,
            Vec3::new(m3 * (h2.y + h2.z), m3 * (h2.x + h2.z), m3 * (h2.x + h2.y)),
        )
    }

    /// Sets the rotation `P` from the principal axes to body coordinates (unit quaternion).
    pub fn with_principal_frame(mut self, frame: Quat) -> Result<Self, InvalidInput> {
        check_unit_quat("principal frame", frame)?;
        self.principal_frame = frame.normalize();
        Ok(self)
    }

    /// Sets the centre of mass in body coordinates.
    pub fn with_center_of_mass(mut self, local_center_of_mass: Vec3) -> Result<Self, InvalidInput> {
        check_finite_vec3("centre of mass", local_center_of_mass)?;
        self.local_center_of_mass = local_center_of_mass;
        Ok(self)
    }

    /// Mass `m` (kg).
    #[inline]
    pub fn mass(&self) -> Real {
        1.0 / self.inv_mass
    }

    /// Inverse mass `1/m` (1/kg).
    #[inline]
    pub fn inv_mass(&self) -> Real {
        self.inv_mass
    }

    /// Principal moments of inertia `I_b` (kg·m²).
    #[inline]
    pub fn principal_inertia(&self) -> Vec3 {
        self.principal_inertia
    }

    /// Reciprocal principal moments `I_b⁻¹`, `0` on locked axes.
    #[inline]
    pub fn inv_principal_inertia(&self) -> Vec3 {
        self.inv_principal_inertia
    }

    /// Rotation `P` from principal axes to body coordinates.
    #[inline]
    pub fn principal_frame(&self) -> Quat {
        self.principal_frame
    }

    /// Centre of mass in body coordinates.
    #[inline]
    pub fn local_center_of_mass(&self) -> Vec3 {
        self.local_center_of_mass
    }

    /// True when all three principal moments are equal (and no axis is locked), so `ω × Iω = 0`
    /// for every `ω` and the gyroscopic term can be skipped exactly.
    #[inline]
    pub fn is_spherical(&self) -> bool {
        let i = self.principal_inertia;
        i.x > 0.0 && i.x == i.y && i.y == i.z
    }

    /// True when some principal moment is zero: rotation about that axis is locked (its angular
    /// velocity is held at zero by every integrator).
    #[inline]
    pub fn has_locked_axis(&self) -> bool {
        self.principal_inertia.cmpeq(Vec3::ZERO).any()
    }

    /// Applies the world inverse inertia `(R P) I_b⁻¹ (R P)ᵀ` to a world vector, where
    /// `body_rotation` is `R` (body → world).
    #[inline]
    pub fn world_inv_inertia_mul(&self, body_rotation: Quat, world: Vec3) -> Vec3 {
        let frame = body_rotation * self.principal_frame;
        frame * (self.inv_principal_inertia * (frame.inverse() * world))
    }

    /// Applies the world inertia `(R P) I_b (R P)ᵀ` to a world vector (e.g. `L = I ω`).
    #[inline]
    pub fn world_inertia_mul(&self, body_rotation: Quat, world: Vec3) -> Vec3 {
        let frame = body_rotation * self.principal_frame;
        frame * (self.principal_inertia * (frame.inverse() * world))
    }
}
