//! Mass properties: mass, principal moments of inertia, principal frame, centre of mass.
//!
//! [`Mass`] and [`Density`] are distinct types, so a density can never be passed where a mass is
//! expected (or the reverse).

use crate::error::{InvalidInput, check_finite_vec3, check_unit_quat};
use crate::math::{Quat, Real, Vec3, Widen, quat_mul, quat_normalize, quat_rotate, to_f64};

/// Smallest accepted mass or nonzero principal moment: the smallest normal [`Real`]
/// (`2⁻¹²⁶ ≈ 1.2e-38` in `f32`, `2⁻¹⁰²² ≈ 2.2e-308` in `f64`). Below it the reciprocal the
/// engine stores (`1/m`, `1/I`) overflows or loses its precision.
pub const MIN_RECIPROCABLE: Real = Real::MIN_POSITIVE;

/// Largest accepted mass or principal moment: `1 / MIN_RECIPROCABLE` (`2¹²⁶ ≈ 8.5e37` in `f32`,
/// `2¹⁰²² ≈ 4.5e307` in `f64`). Above it the stored reciprocal would be subnormal, and `1/(1/m)`
/// would no longer give the mass back.
pub const MAX_RECIPROCABLE: Real = 1.0 / Real::MIN_POSITIVE;

/// Slack of the triangle inequality `I_a ≤ I_b + I_c + slack·(I_a + I_b + I_c)`, in units of
/// [`Real::EPSILON`]. A flat plate has `I₃ = I₁ + I₂` exactly, and a thin body is close to it:
/// moments computed in floating point (an eigen-decomposition, the sum over a hull's triangles)
/// carry a few ulps of round-off, so the exact inequality would reject valid thin bodies.
pub const TRIANGLE_INEQUALITY_SLACK_ULPS: Real = 16.0;

/// Whether `x` is in `[MIN_RECIPROCABLE, MAX_RECIPROCABLE]` (false for NaN).
fn reciprocable(x: Real) -> bool {
    (MIN_RECIPROCABLE..=MAX_RECIPROCABLE).contains(&x)
}

/// [`InvalidInput::ReciprocalOutOfRange`] for `field`.
fn out_of_range(field: &'static str, value: Real) -> InvalidInput {
    InvalidInput::ReciprocalOutOfRange {
        field,
        value,
        min: MIN_RECIPROCABLE,
        max: MAX_RECIPROCABLE,
    }
}

/// A mass in kilograms, strictly positive and finite.
#[derive(Debug, Clone, Copy, PartialEq, PartialOrd)]
pub struct Mass(Real);

impl Mass {
    /// Creates a mass; rejects values that are not finite or not `> 0`
    /// ([`InvalidInput::NonPositiveMass`]), and masses outside
    /// [`MIN_RECIPROCABLE`]`..=`[`MAX_RECIPROCABLE`], whose reciprocal is not a finite normal
    /// number in the build precision ([`InvalidInput::ReciprocalOutOfRange`]; e.g. `1e-39` in
    /// `f32`, where `1/m` is infinite).
    pub fn new(kilograms: Real) -> Result<Self, InvalidInput> {
        if !(kilograms.is_finite() && kilograms > 0.0) {
            return Err(InvalidInput::NonPositiveMass(kilograms));
        }
        if !reciprocable(kilograms) {
            return Err(out_of_range("mass", kilograms));
        }
        Ok(Self(kilograms))
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
        try_from = "crate::mass::MassPropertiesData",
        into = "crate::mass::MassPropertiesData"
    )
)]
pub struct MassProperties {
    inv_mass: Real,
    principal_inertia: Vec3,
    inv_principal_inertia: Vec3,
    principal_frame: Quat,
    local_center_of_mass: Vec3,
    /// What the batched step asks of every body on every step, decided once when the moments
    /// or the centre of mass are set (it fits in the struct's padding in `f32`).
    hints: StepHints,
}

/// What the batched step asks of every body on every step, decided once.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct StepHints {
    /// All three moments equal (no axis locked): see [`MassProperties::is_spherical`].
    spherical: bool,
    /// The `splitting` kernel's odd axis: see [`MassProperties::odd_axis`].
    odd_axis: u8,
    /// The centre of mass is not the body origin: see
    /// [`MassProperties::has_center_of_mass_offset`].
    offset: bool,
}

impl StepHints {
    fn of(principal_inertia: Vec3, inv_principal_inertia: Vec3, center_of_mass: Vec3) -> Self {
        let i = principal_inertia;
        let r = inv_principal_inertia;
        let gaps = [(r.y - r.z).abs(), (r.x - r.z).abs(), (r.x - r.y).abs()];
        let odd_axis = if gaps[0] <= gaps[1] && gaps[0] <= gaps[2] {
            0
        } else if gaps[1] <= gaps[2] {
            1
        } else {
            2
        };
        Self {
            spherical: i.x > 0.0 && i.x == i.y && i.y == i.z,
            odd_axis,
            offset: center_of_mass != Vec3::ZERO,
        }
    }
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
            hints: StepHints::of(
                principal_inertia,
                inv_principal_inertia,
                local_center_of_mass,
            ),
        }
    }

    /// Mass properties from a mass and principal moments of inertia (kg·m²) about body axes,
    /// centre of mass at the body origin.
    ///
    /// Moments must be `>= 0` and finite, and not all zero. A zero moment locks that axis.
    ///
    /// Also rejected:
    /// - a nonzero moment outside [`MIN_RECIPROCABLE`]`..=`[`MAX_RECIPROCABLE`]: its reciprocal,
    ///   which the engine stores, would not be a finite normal number
    ///   ([`InvalidInput::ReciprocalOutOfRange`]);
    /// - moments that violate the triangle inequality `I_a ≤ I_b + I_c` on some axis `a`
    ///   ([`InvalidInput::TriangleInequality`]): `I_a = ∫ (r_b² + r_c²) dm ≤ I_b + I_c =
    ///   ∫ (r_a² + r_b² + r_a² + r_c²) dm` for every mass distribution, with equality for a flat
    ///   plate normal to `a`. The check allows [`TRIANGLE_INEQUALITY_SLACK_ULPS`] ulps of the sum
    ///   of the moments for round-off, so computed moments of a thin plate pass.
    ///
    /// A zero moment means a locked axis, i.e. an infinite moment: the inequality then cannot
    /// be violated on any axis and is not checked (the other moments may be anything).
    pub fn new(mass: Mass, principal_inertia: Vec3) -> Result<Self, InvalidInput> {
        check_finite_vec3("principal inertia", principal_inertia)?;
        // `!(x >= 0)` also catches NaN.
        if !principal_inertia.cmpge(Vec3::ZERO).all() {
            return Err(InvalidInput::NegativeInertia(principal_inertia.to_array()));
        }
        if principal_inertia == Vec3::ZERO {
            return Err(InvalidInput::ZeroInertia);
        }
        let moments = principal_inertia.to_array();
        if let Some(&bad) = moments.iter().find(|&&m| m != 0.0 && !reciprocable(m)) {
            return Err(out_of_range("principal moment", bad));
        }
        if !principal_inertia.cmpeq(Vec3::ZERO).any() {
            // In f64, so that neither the sums nor the slack round.
            let m = moments.map(to_f64);
            let slack = to_f64(TRIANGLE_INEQUALITY_SLACK_ULPS)
                * to_f64(Real::EPSILON)
                * (m[0] + m[1] + m[2]);
            if let Some(axis) = (0..3).find(|&a| m[a] > m[(a + 1) % 3] + m[(a + 2) % 3] + slack) {
                return Err(InvalidInput::TriangleInequality { moments, axis });
            }
        }
        let inv_principal_inertia = Vec3::new(
            locked_reciprocal(principal_inertia.x),
            locked_reciprocal(principal_inertia.y),
            locked_reciprocal(principal_inertia.z),
        );
        Ok(Self {
            inv_mass: 1.0 / mass.get(),
            principal_inertia,
            inv_principal_inertia,
            principal_frame: Quat::IDENTITY,
            local_center_of_mass: Vec3::ZERO,
            hints: StepHints::of(principal_inertia, inv_principal_inertia, Vec3::ZERO),
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
        self.principal_frame = quat_normalize(frame);
        Ok(self)
    }

    /// Sets the centre of mass in body coordinates.
    pub fn with_center_of_mass(mut self, local_center_of_mass: Vec3) -> Result<Self, InvalidInput> {
        check_finite_vec3("centre of mass", local_center_of_mass)?;
        self.local_center_of_mass = local_center_of_mass;
        self.hints = StepHints::of(
            self.principal_inertia,
            self.inv_principal_inertia,
            local_center_of_mass,
        );
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

    /// True when the centre of mass is not the body origin (`c ≠ 0`; `−0` counts as 0), so
    /// that poses and centre-of-mass positions differ by `R c`. Decided when the centre is set.
    #[inline]
    pub fn has_center_of_mass_offset(&self) -> bool {
        self.hints.offset
    }

    /// True when all three principal moments are equal (and no axis is locked), so `ω × Iω = 0`
    /// for every `ω` and the gyroscopic term can be skipped exactly.
    #[inline]
    pub fn is_spherical(&self) -> bool {
        self.hints.spherical
    }

    /// The axis (0, 1, 2 for x, y, z) whose reciprocal moment stands apart from the other
    /// two, so that those two are the most nearly symmetric pair: the `splitting` kernel
    /// relabels the axes to make it `x` (see `integrate::symmetric_kernel`). Decided once, when
    /// the moments are set: the batched step asks it of every body on every step.
    #[inline]
    pub(crate) fn odd_axis(&self) -> usize {
        usize::from(self.hints.odd_axis)
    }

    /// True when some principal moment is zero: rotation about that axis is locked (its angular
    /// velocity is held at zero by every integrator).
    #[inline]
    pub fn has_locked_axis(&self) -> bool {
        self.principal_inertia.cmpeq(Vec3::ZERO).any()
    }

    /// The rates of a world angular velocity `ω` about the locked principal axes: `b = (R P)ᵀ ω`
    /// with the components of unlocked axes set to 0. Every integrator holds these at 0, so
    /// callers that take `ω` from outside (a scene file) refuse a nonzero one rather than let
    /// the first step drop it.
    pub fn locked_axis_rates(&self, body_rotation: Quat, world: Vec3) -> Vec3 {
        let frame = quat_mul(body_rotation, self.principal_frame);
        let b = quat_rotate(frame.inverse(), world);
        Vec3::select(self.principal_inertia.cmpeq(Vec3::ZERO), b, Vec3::ZERO)
    }

    /// Applies the world inverse inertia `(R P) I_b⁻¹ (R P)ᵀ` to a world vector, where
    /// `body_rotation` is `R` (body → world).
    #[inline]
    pub fn world_inv_inertia_mul(&self, body_rotation: Quat, world: Vec3) -> Vec3 {
        self.world_diagonal_mul(body_rotation, self.inv_principal_inertia, world)
    }

    /// The quadratic form of the world inertia, `ωᵀ (R P) I_b (R P)ᵀ ω = Σᵢ Iᵢ bᵢ²` with
    /// `b = (R P)ᵀ ω` (twice the rotational kinetic energy), summed in `f64`: one rotation
    /// instead of the two of [`world_inertia_mul`](Self::world_inertia_mul).
    #[inline]
    pub fn world_inertia_quadratic_f64(&self, body_rotation: Quat, world: Vec3) -> f64 {
        let frame = quat_mul(body_rotation, self.principal_frame);
        let b = quat_rotate(frame.inverse(), world).widen();
        let i = self.principal_inertia.widen();
        i.x * b.x * b.x + i.y * b.y * b.y + i.z * b.z * b.z
    }

    /// Applies the world inertia `(R P) I_b (R P)ᵀ` to a world vector (e.g. `L = I ω`).
    #[inline]
    pub fn world_inertia_mul(&self, body_rotation: Quat, world: Vec3) -> Vec3 {
        self.world_diagonal_mul(body_rotation, self.principal_inertia, world)
    }

    /// Applies `(R P) D (R P)ᵀ` to a world vector, `D` the diagonal matrix of `diagonal` in the
    /// principal frame.
    #[inline(always)]
    fn world_diagonal_mul(&self, body_rotation: Quat, diagonal: Vec3, world: Vec3) -> Vec3 {
        let frame = quat_mul(body_rotation, self.principal_frame);
        quat_rotate(frame, diagonal * quat_rotate(frame.inverse(), world))
    }
}

/// The stored fields of a [`MassProperties`], as saved (feature `serde`): a checked mirror, so a
/// loaded value is exactly the saved one (bit for bit) and never an invalid one.
#[cfg(feature = "serde")]
#[derive(serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct MassPropertiesData {
    pub inv_mass: Real,
    pub principal_inertia: Vec3,
    pub inv_principal_inertia: Vec3,
    pub principal_frame: Quat,
    pub local_center_of_mass: Vec3,
}

#[cfg(feature = "serde")]
impl TryFrom<MassPropertiesData> for MassProperties {
    type Error = crate::error::InvalidInput;

    /// Accepts the saved fields only if they are what the constructors would have produced:
    /// positive finite inverse mass, valid moments with their exact reciprocals, a unit frame,
    /// a finite centre of mass. Nothing is recomputed, so the value is restored bit for bit.
    fn try_from(d: MassPropertiesData) -> Result<Self, crate::error::InvalidInput> {
        if !(d.inv_mass.is_finite() && d.inv_mass > 0.0) {
            return Err(crate::error::InvalidInput::NonPositiveMass(
                1.0 / d.inv_mass,
            ));
        }
        crate::error::check_unit_quat("principal frame", d.principal_frame)?;
        crate::error::check_finite_vec3("centre of mass", d.local_center_of_mass)?;
        let rebuilt =
            MassProperties::new(crate::Mass::new(1.0 / d.inv_mass)?, d.principal_inertia)?;
        if rebuilt.inv_principal_inertia() != d.inv_principal_inertia {
            return Err(crate::error::InvalidInput::Inconsistent(
                "reciprocal principal moments",
            ));
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

#[cfg(feature = "serde")]
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The hints the batched step reads instead of recomputing them per body and step follow
    /// the moments and the centre of mass through every way of setting them.
    #[test]
    fn step_hints_follow_the_moments_and_the_centre_of_mass() {
        // The hints live in what was padding.
        #[cfg(not(feature = "f64"))]
        assert_eq!(size_of::<MassProperties>(), 64);
        let m = Mass::new(2.0).unwrap();
        for (moments, odd) in [
            (Vec3::new(0.01, 1.0, 1.0), 0),
            (Vec3::new(1.0, 0.01, 1.0), 1),
            (Vec3::new(1.0, 1.0, 0.01), 2),
            (Vec3::new(1.0, 2.0, 3.0), 0),
            (Vec3::new(3.0, 2.0, 1.2), 2),
            (Vec3::new(0.0, 1.0, 1.5), 0),
        ] {
            let props = MassProperties::new(m, moments).unwrap();
            assert_eq!(props.odd_axis(), odd, "{moments}");
            assert!(!props.is_spherical());
        }
        assert!(
            MassProperties::new(m, Vec3::splat(0.4))
                .unwrap()
                .is_spherical()
        );
        let body = MassProperties::new(m, Vec3::new(1.0, 2.0, 3.0)).unwrap();
        assert!(!body.has_center_of_mass_offset());
        let shifted = body.with_center_of_mass(Vec3::new(0.0, 0.1, 0.0)).unwrap();
        assert!(shifted.has_center_of_mass_offset());
        let negative_zero = shifted
            .with_center_of_mass(Vec3::new(-0.0, 0.0, -0.0))
            .unwrap();
        assert!(!negative_zero.has_center_of_mass_offset());
        assert!(
            shifted
                .with_principal_frame(Quat::from_rotation_z(0.3))
                .unwrap()
                .has_center_of_mass_offset()
        );
    }

    fn one() -> Mass {
        Mass::new(1.0).unwrap()
    }

    /// `1/m` and `1/I` are stored: values whose reciprocal is not a finite normal number in the
    /// build precision are rejected at construction, not quarantined at step 1.
    #[test]
    fn masses_and_moments_without_a_usable_reciprocal_are_rejected() {
        for bad in [Real::MIN_POSITIVE / 2.0, MAX_RECIPROCABLE * 2.0] {
            assert!(
                matches!(
                    Mass::new(bad),
                    Err(InvalidInput::ReciprocalOutOfRange { field: "mass", .. })
                ),
                "mass {bad}"
            );
            let e = MassProperties::new(one(), Vec3::new(bad, bad, bad)).unwrap_err();
            assert!(
                matches!(e, InvalidInput::ReciprocalOutOfRange { .. }),
                "{e}"
            );
        }
        if !crate::math::DOUBLE_PRECISION {
            // The case of the issue: 1e-39 kg is a valid f32 but its reciprocal overflows.
            let e = Mass::new((1e-39_f64) as Real).unwrap_err();
            let shown = e.to_string();
            assert!(shown.contains("f32") && shown.contains("1e-39"), "{shown}");
            assert!(shown.len() < 200, "compact numbers: {shown}");
        }
        for ok in [MIN_RECIPROCABLE, MAX_RECIPROCABLE] {
            let m = Mass::new(ok).unwrap();
            let props = MassProperties::new(m, Vec3::splat(ok)).unwrap();
            assert!(props.inv_mass().is_normal() && props.mass().is_finite());
            assert!(props.inv_principal_inertia().x.is_normal());
        }
    }

    #[test]
    fn moments_must_satisfy_the_triangle_inequality() {
        for (moments, axis) in [
            (Vec3::new(3.0, 1.0, 1.0), 0),
            (Vec3::new(1.0, 5.0, 1.0), 1),
            (Vec3::new(0.2, 0.3, 0.6), 2),
        ] {
            assert_eq!(
                MassProperties::new(one(), moments),
                Err(InvalidInput::TriangleInequality {
                    moments: moments.to_array(),
                    axis
                })
            );
        }
        let e = MassProperties::new(one(), Vec3::new(1.0, 5.0, 1.0)).unwrap_err();
        assert!(e.to_string().contains("5 > 1 + 1"), "{e}");
        // The flat plate is the boundary case: equality holds and is accepted, also a few
        // ulps past it (round-off of computed moments).
        MassProperties::new(one(), Vec3::new(1.0, 2.0, 3.0)).unwrap();
        let past = 3.0 * (1.0 + 4.0 * Real::EPSILON);
        MassProperties::new(one(), Vec3::new(1.0, 2.0, past)).unwrap();
        // A thin plate built from its formula passes.
        MassProperties::solid_cuboid(one(), Vec3::new(1.0, 0.5, 1e-6)).unwrap();
    }

    #[test]
    fn locked_axis_rates_are_the_body_rates_about_zero_moments() {
        let props = MassProperties::new(Mass::new(1.0).unwrap(), Vec3::new(0.0, 0.0, 1.0)).unwrap();
        let w = Vec3::new(1.0, 2.0, 3.0);
        assert_eq!(
            props.locked_axis_rates(Quat::IDENTITY, w),
            Vec3::new(1.0, 2.0, 0.0)
        );
        // A quarter turn about z takes body x to world y: the body's rate about x is ω_y.
        let quarter = Quat::from_rotation_z(core::f64::consts::FRAC_PI_2 as Real);
        let rates = props.locked_axis_rates(quarter, w);
        let expected = Vec3::new(2.0, -1.0, 0.0);
        assert!((rates - expected).length() < 8.0 * Real::EPSILON, "{rates}");
        let free = MassProperties::new(Mass::new(1.0).unwrap(), Vec3::ONE).unwrap();
        assert_eq!(free.locked_axis_rates(quarter, w), Vec3::ZERO);
    }

    /// A zero moment is a locked axis, i.e. an infinite moment: the inequality is not checked.
    #[test]
    fn a_locked_axis_skips_the_triangle_inequality() {
        let props = MassProperties::new(one(), Vec3::new(0.0, 1.0, 5.0)).unwrap();
        assert!(props.has_locked_axis());
        MassProperties::new(one(), Vec3::new(7.0, 0.0, 0.0)).unwrap();
    }
}
