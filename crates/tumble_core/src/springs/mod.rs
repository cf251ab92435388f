//! Springs between rigid bodies, on plain data: the energy-conserving implicit step for stiff
//! spring groups ([`implicit`]) and the frequency bound that decides which springs need it.
//!
//! The explicit (drift–kick–drift) spring step keeps a linear spring's energy only to
//! `≈ (ωΔt)²/4` of it and diverges at `ωΔt ≥ 2`. The implicit step here conserves the total
//! energy of a spring group exactly (to the solver's tolerance) at any `ωΔt`, without the numerical
//! damping that implicit Euler, XPBD compliance or soft constraints use to stay stable.

pub mod implicit;
mod linear;
mod sparse;

pub use implicit::{
    GroupBody, GroupRotation, GroupSpring, ImplicitSpringError, ImplicitSpringSolver, LinkEnd,
};

use glam::DVec3;

use crate::mass::MassProperties;
use crate::math::{Narrow, Real, Vec3, Widen};

/// `ωΔt` above which a spring group is stepped implicitly by default.
///
/// The explicit drift–kick–drift step moves a linear spring's energy by about `(ωΔt)²/4` of it
/// (its modified energy differs from the true one by that factor): 2.3 % at 0.3, 6 % at 0.5.
/// Below this bound the explicit step is cheaper and accurate enough; above it the implicit
/// step keeps the energy exact.
pub const IMPLICIT_OMEGA_DT: Real = 0.3;

/// The coarsest step `auto` judges a spring group's stiffness at (s): `Δt`, or 1/60 s where `Δt`
/// is finer. `auto` steps a group implicitly where `ωΔt ≥` [`IMPLICIT_OMEGA_DT`]; judged at the
/// world's own `Δt`, a group stiff at 1/60 s would turn explicit at 1/240 s, and a `Δt` sweep
/// under the defaults would mix two discretisations (the implicit midpoint's phase error has the
/// opposite sign of position Verlet's, twice as large), so the order measured across it would
/// mean nothing. Judged at `max(Δt, 1/60 s)`, refining the step below a game's 60 Hz never
/// changes the spring step; coarser steps are judged as they are (stability needs it), and
/// `--plan` says which groups are implicit at every step.
pub const AUTO_REFERENCE_DT: Real = 1.0 / 60.0;

/// `ω_turn` (rad/s) below which a body of an implicit group is turned by the world's integrator
/// rather than the implicit midpoint (see [`GroupRotation`]): springs that turn it by less than
/// 0.03 rad in a game's step of 1/60 s. Then the energy they exchange with its rotation is kept
/// to about `(ω_turn Δt)²/4 ≈ 2e-4` of it at 60 Hz, where the midpoint would lag its spin's
/// phase by `(|ω|Δt)²/12` per step (4e-2 rad over 10 s at 5 rad/s). A rate, not an `ωΔt`: the
/// choice must not change as a user refines `Δt`, or a convergence study would mix two
/// discretisations. (It also needs `ω_turn Δt <` [`IMPLICIT_OMEGA_DT`], which binds only at
/// steps over 1/6 s.)
pub const METHOD_TURN_RATE: Real = 0.03 * 60.0;

/// An upper bound of `1/m_eff` for a force along any direction at a body-local `anchor`:
/// `1/m + |r|² max(I⁻¹)`, with `r` the anchor relative to the centre of mass.
///
/// The true inverse effective mass `1/m + (r × n)ᵀ I⁻¹ (r × n)` depends on the orientation and
/// on the direction `n`; the bound holds for all of them, so a spring classified by it is never
/// stiffer than predicted. Zero for a locked or infinite body is the caller's business (pass no
/// body).
pub fn inverse_effective_mass_bound(mass: &MassProperties, anchor: Vec3) -> Real {
    let r = anchor - mass.local_center_of_mass();
    let inv = mass.inv_principal_inertia();
    mass.inv_mass() + r.length_squared() * inv.x.max(inv.y).max(inv.z)
}

/// How far a unit force at a body-local `anchor` can turn the body: the largest
/// `(r × n)ᵀ I⁻¹ (r × n)` over unit directions `n` (1/kg), with `r` the anchor relative
/// to the centre of mass in the principal frame. Independent of the orientation (both `r` and
/// `I` are fixed in the body), and tighter than the `|r|² max(I⁻¹)` of
/// [`inverse_effective_mass_bound`] for a thin body pulled along its thin axis. With
/// `M = Σᵢ rᵢ uᵢuᵢᵀ`, `uᵢ = eᵢ × r` (`rᵢ = 1/Iᵢ`, 0 on a locked axis), the two eigenvalues of
/// rank-2 `M` have the sum `tr M = Σᵢ rᵢ (|r|² − rᵢ'²)` and the product
/// `Σ_k rᵢ rⱼ |r|² r_k'²` (`r'` the arm's components, `(i, j, k)` cyclic); the result is the
/// larger. `√(k · Σ_springs this) Δt` is the `ωΔt` at which its springs turn the body (see
/// [`GroupRotation`]).
pub fn turning_compliance(mass: &MassProperties, anchor: Vec3) -> Real {
    let arm = mass.principal_frame().inverse() * (anchor - mass.local_center_of_mass());
    let (a, r) = (arm.widen(), mass.inv_principal_inertia().widen());
    let a2 = a * a;
    let length2 = a2.element_sum();
    let trace = (r * (DVec3::splat(length2) - a2)).element_sum();
    let product = length2 * (r.y * r.z * a2.x + r.z * r.x * a2.y + r.x * r.y * a2.z);
    let discriminant = (trace * trace - 4.0 * product).max(0.0);
    (0.5 * (trace + discriminant.sqrt())).narrow()
}

/// `√(k (1/m_eff,a + 1/m_eff,b)) Δt`, the largest `ωΔt` a spring of stiffness `k` can reach
/// between ends with the given inverse effective mass bounds (see
/// [`inverse_effective_mass_bound`]; `0` for a fixed end).
pub fn omega_dt_bound(stiffness: Real, inverse_masses: [Real; 2], dt: Real) -> Real {
    (stiffness * (inverse_masses[0] + inverse_masses[1])).sqrt() * dt
}

#[cfg(test)]
mod tests;
