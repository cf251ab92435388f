//! The exact torque-free rotation of a rigid body over any span: the free rotation of the
//! `exact` integrator.
//!
//! **Body momentum** (Jacobi; Landau & Lifshitz §37), in reciprocal moments so that nothing
//! divides by a moment. Sort the principal axes so that `r₁ ≥ r₂ ≥ r₃ > 0` (`rᵢ = 1/Iᵢ`; one axis
//! is negated when the sort is an odd permutation, so the frame stays right-handed), write
//! `m` for the body momentum, `2E = Σ rᵢmᵢ²`, `M² = Σ mᵢ²`, `dᵢⱼ = rᵢ − rⱼ ≥ 0`, and form the
//! three invariants without cancellation:
//!
//! ```text
//! P = 2E − r₃M² = d₁₃m₁² + d₂₃m₂²,   R = r₁M² − 2E = d₁₂m₂² + d₁₃m₃²,   D = 2E − r₂M² = d₁₂m₁² − d₂₃m₃².
//! ```
//!
//! Euler's equations `ṁ = m × (r ∘ m)` are solved with `τ = λt + τ₀` by
//!
//! ```text
//! D ≤ 0 (circles axis 3): m = (a₁ cn τ, a₂ sn τ, a₃ dn τ),  λ² = R d₂₃,  m = P d₁₂ / (R d₂₃),
//!                          a₁² = P/d₁₃, a₂² = P/d₂₃, a₃² = R/d₁₃,  1 − m = d₁₃(−D)/(R d₂₃);
//! D > 0 (circles axis 1): m = (a₁ dn τ, a₂ sn τ, a₃ cn τ),  λ² = P d₁₂,  m = R d₂₃ / (P d₁₂),
//!                          a₁² = P/d₁₃, a₂² = R/d₁₂, a₃² = R/d₁₃,  1 − m = d₁₃ D/(P d₁₂),
//! ```
//!
//! (substitute into `ṁ₁ = d₂₃·(−m₂m₃)`, `ṁ₂ = d₁₃ m₃m₁`, `ṁ₃ = −d₁₂ m₁m₂` and compare
//! coefficients). The coefficient of `cn` takes the sign of its initial momentum, so `cn τ₀ ≥ 0`
//! and `τ₀ = F(φ₀ | m)` on the principal branch, with `(sin φ₀, cos φ₀) = (sn τ₀, cn τ₀)` read
//! off the momentum directly; `dn`'s takes the sign of its own (it never changes sign), and
//! `sign a₂ = sign a₁ · sign a₃` makes time run forward for `λ > 0`. `D = 0` is the separatrix
//! (`m = 1`: `sn = tanh`, `cn = dn = sech`). After the span `h`: `τ₁ = τ₀ + λh` is reduced by the
//! half-period `2K(m)` to `|τ₁ − 2jK| ≤ K`, where `(sn, cn, dn)` come from the Landen
//! transformation, and `sn, cn` change sign with `j`.
//!
//! **Attitude.** Take Euler angles `(φ, θ, ψ)` of the body axes `(a, b, c) = (2, 3, 1)` about
//! the constant `L` (body → L-frame `= R_z(φ) R_x(θ) R_z(ψ)`, so `m_a = M sin θ sin ψ`,
//! `m_b = M sin θ cos ψ`, `m_c = M cos θ`). Then `B(m) = R_x(θ) R_z(ψ)` is a function of the body
//! momentum alone, built from `cos θ = m_c/M` and `tan ψ = m_a/m_b` without any angle, and the
//! orientation moves as `Q(t + h) = Q(t) B(m₀)ᵀ R_z(Δφ) B(m₁)`, where (Landau & Lifshitz 37.17,
//! with `c` the axis of *smallest* moment in both cases so the rate stays between `Mr₃` and
//! `Mr₂`, and `m₂² + m₃²` never vanishes off a steady spin)
//!
//! ```text
//! φ̇ = M (r₂m₂² + r₃m₃²)/(m₂² + m₃²) = M r₃ + M d₂₃ g,   g = m₂²/(m₂² + m₃²) = κ sn²τ/(1 + ν sn²τ),
//! D ≤ 0: κ = P d₁₃/(R d₂₃), ν = P/R;    D > 0: κ = d₁₃/d₁₂, ν = d₂₃/d₁₂,
//! Δφ = M r₃ h + (M d₂₃ κ/λ) ∫_{τ₀}^{τ₁} sn²/(1 + ν sn²) dτ.
//! ```
//!
//! The integral is an elliptic integral of the third kind, `G(am τ)` with
//! `G(φ) = (sin³φ/3) R_J(cos²φ, 1 − m sin²φ, 1, 1 + ν sin²φ)` on `|φ| ≤ π/2` (Carlson; every term
//! positive, so a thin body's huge `ν` costs no digits) and `G(φ + π) = G(φ) + 2G(π/2)`:
//! `∫ = 2jG(π/2) + G(am(τ₁ − 2jK)) − G(am τ₀)`. Every piece is closed-form, so the flow is exact
//! to round-off for any span `h` and any spin rate.
//!
//! **Short spans** (`|λh| < π/2` and a branch condition, the usual case) skip `τ₀`, `K` and one
//! `R_J`: the momentum at `τ₀ + λh` comes from Jacobi's addition theorem and the integral from the
//! addition theorem of the third kind (`Polhode::advance_short`). Every transcendental on the
//! path is tumble's own (square roots are IEEE; sine, cosine and arctangent are written in IEEE
//! arithmetic), so a flow gives the same bits on every platform, except exactly on the
//! separatrix, whose `tanh`/`sech` are the platform's.
//!
//! **Degenerate bodies.** A steady spin (`ṁ = 0`: `m` along a principal axis, or in the plane of
//! two equal moments, or a spherical body) rotates about its fixed axis by `h |r ∘ m|`. Two equal
//! moments give `m = 0` above (`sn = sin`, the symmetric top's regular precession). A locked axis
//! (`r = 0`) holds no rotation about it: the constraint torque about that body axis cancels the
//! gyroscopic torque, so the body rates are constant and the body turns steadily about the
//! fixed `ω` — that is the exact motion (it is also what every splitting tends to as `h → 0`).

use std::f64::consts::FRAC_PI_2;

use glam::{DQuat, DVec3};

use super::StepPhase;
use super::body_batch::{BodyBatch, PREFETCH_AHEAD, commit};
use super::drift_kick_drift::{
    FreeBody, FreeState, drift_kick_drift_translation, free_rotation_span, rotate_freely,
};
use crate::elliptic::{
    complete_k_complement, incomplete_f_sin_cos, integral_sn2_over, jacobi_sn_cn_dn_complement,
    jacobi_sn_cn_dn_complement_pair, norm2, sign,
};
use crate::mass::MassProperties;
use crate::math::{Real, Widen};
use crate::simd::sin_cos;
use crate::state::{BodyState, Wrench};

/// `atan x`: the series `x − x³/3 + x⁵/5 − x⁷/7` below `|x| = 10⁻³` (the first term left out,
/// `x⁹/9`, is below `10⁻¹⁸ |x|`), tumble's own `atan` above.
#[inline]
fn small_atan(x: f64) -> f64 {
    if x.abs() < 1e-3 {
        let x2 = x * x;
        x * (1.0 - x2 * (1.0 / 3.0 - x2 * (1.0 / 5.0 - x2 / 7.0)))
    } else {
        crate::elliptic::atan(x)
    }
}

/// The rotation by the body-frame rotation vector `v`: `exp(½ v)` as a unit quaternion.
#[inline]
fn exp_body(v: DVec3) -> DQuat {
    let angle = v.length();
    if angle == 0.0 {
        return DQuat::IDENTITY;
    }
    let (s, c) = sin_cos(0.5 * angle);
    let axis = v * (s / angle);
    DQuat::from_xyzw(axis.x, axis.y, axis.z, c)
}

/// Unit quaternion of the rotation by the angle with cosine `c` and sine `s` (`c² + s² = 1`)
/// about the unit vector `axis`: half-angle values without the cancellation of `1 + c` near
/// `c = −1` (the larger of `cos ½α = √((1 + c)/2)` and `|sin ½α| = √((1 − c)/2)` is taken from
/// its root, the other as `s / (2 · that)`).
#[inline]
fn rotation_from_cos_sin(axis: DVec3, c: f64, s: f64) -> DQuat {
    let (half_sin, half_cos) = if c >= 0.0 {
        let half_cos = (0.5 * (1.0 + c)).sqrt();
        (s / (2.0 * half_cos), half_cos)
    } else {
        let half_sin = (0.5 * (1.0 - c)).sqrt().copysign(s);
        (half_sin, s / (2.0 * half_sin))
    };
    let v = axis * half_sin;
    DQuat::from_xyzw(v.x, v.y, v.z, half_cos)
}

/// `B(μ) = R_x(θ) R_z(ψ)` for the momentum `μ = (m_a, m_b, m_c)` in the Euler frame: it maps `μ`
/// to `|μ| ẑ`. `m_a² + m_b² > 0`.
#[inline]
fn to_momentum_frame(mu: DVec3, magnitude: f64) -> DQuat {
    let rho = norm2(mu.x, mu.y);
    let rz = rotation_from_cos_sin(DVec3::Z, mu.y / rho, mu.x / rho);
    let rx = rotation_from_cos_sin(DVec3::X, mu.z / magnitude, rho / magnitude);
    rx * rz
}

/// The principal axes sorted by decreasing reciprocal moment, as a right-handed frame: axis `k`
/// of the sorted frame is `sign[k] · e_{index[k]}`.
#[derive(Debug, Clone, Copy)]
struct SortedAxes {
    index: [usize; 3],
    sign: [f64; 3],
}

impl SortedAxes {
    fn new(r: DVec3) -> Self {
        // Three compare-and-swaps (a library sort costs more than the rest of this).
        let mut index = [0, 1, 2];
        for (i, j) in [(0, 1), (1, 2), (0, 1)] {
            if r[index[j]] > r[index[i]] {
                index.swap(i, j);
            }
        }
        // An odd permutation of a right-handed frame is left-handed: negate the middle axis.
        let even = matches!(index, [0, 1, 2] | [1, 2, 0] | [2, 0, 1]);
        let sign = if even { [1.0; 3] } else { [1.0, -1.0, 1.0] };
        Self { index, sign }
    }

    /// Principal components → sorted components.
    fn to_sorted(self, v: DVec3) -> DVec3 {
        DVec3::new(
            self.sign[0] * v[self.index[0]],
            self.sign[1] * v[self.index[1]],
            self.sign[2] * v[self.index[2]],
        )
    }

    /// Sorted components → principal components.
    fn to_principal(self, v: DVec3) -> DVec3 {
        let mut out = DVec3::ZERO;
        for k in 0..3 {
            out[self.index[k]] = self.sign[k] * v[k];
        }
        out
    }
}

/// The elliptic motion of the body momentum in the sorted frame (see the module docs).
#[derive(Debug, Clone, Copy)]
struct Polhode {
    /// `D > 0`: the momentum circles axis 1 (`m₁ ∝ dn`, `m₃ ∝ cn`).
    about_smallest: bool,
    /// Signed coefficients `(a₁, a₂, a₃)`.
    coeff: DVec3,
    lambda: f64,
    m: f64,
    m1: f64,
    /// `κ` and `ν` of the phase rate `g = κ sn²/(1 + ν sn²)`.
    kappa: f64,
    nu: f64,
}

/// [`Polhode::advance_short`] up to the elliptic functions of the phase advance `δ = λh`.
struct ShortStart {
    delta: f64,
    /// `C = √(ν (m + ν)(1 + ν))`.
    c: f64,
    /// `(sn, cn, dn)` at the start.
    phase: (f64, f64, f64),
}

impl Polhode {
    /// The motion through the sorted momentum `s` with sorted reciprocal moments `r`, not a
    /// steady spin (`P > 0` and `R > 0`).
    fn new(s: DVec3, r: DVec3) -> Self {
        let (d12, d13, d23) = (r.x - r.y, r.x - r.z, r.y - r.z);
        let (s1, s2, s3) = (s.x * s.x, s.y * s.y, s.z * s.z);
        let p = d13 * s1 + d23 * s2;
        let big_r = d12 * s2 + d13 * s3;
        let d = d12 * s1 - d23 * s3;
        let (sign1, sign3) = (sign(s.x), sign(s.z));
        // The two cases are one formula with the roles of `(P, d₁₂)` and `(R, d₂₃)` exchanged
        // (`λ² = a d_a`, `m = b d_b / λ²`, `m₁ = d₁₃ |D| / λ²`); only the phase rate's `κ`, `ν`
        // take different forms.
        let about_smallest = d > 0.0;
        let (a, da, b, db, gap) = if about_smallest {
            (p, d12, big_r, d23, d)
        } else {
            (big_r, d23, p, d12, -d)
        };
        let (kappa, nu) = if about_smallest {
            (d13 / d12, d23 / d12)
        } else {
            (p * d13 / (big_r * d23), p / big_r)
        };
        Self {
            about_smallest,
            coeff: DVec3::new(
                sign1 * (p / d13).sqrt(),
                sign1 * sign3 * (b / da).sqrt(),
                sign3 * (big_r / d13).sqrt(),
            ),
            lambda: (a * da).sqrt(),
            m: b * db / (a * da),
            m1: d13 * gap / (a * da),
            kappa,
            nu,
        }
    }

    /// `(sn, cn, dn)` of the momentum `s` on this motion.
    fn phase_of(&self, s: DVec3) -> (f64, f64, f64) {
        let a = self.coeff;
        if self.about_smallest {
            (s.y / a.y, s.z / a.z, s.x / a.x)
        } else {
            (s.y / a.y, s.x / a.x, s.z / a.z)
        }
    }

    /// The momentum at phase `(sn, cn, dn)`.
    fn momentum_at(&self, sn: f64, cn: f64, dn: f64) -> DVec3 {
        let a = self.coeff;
        if self.about_smallest {
            DVec3::new(a.x * dn, a.y * sn, a.z * cn)
        } else {
            DVec3::new(a.x * cn, a.y * sn, a.z * dn)
        }
    }

    /// `G(φ)` of the module docs for `(sin φ, cos φ)`, normalized here.
    fn phase_integral(&self, sn: f64, cn: f64) -> f64 {
        let norm = norm2(sn, cn);
        integral_sn2_over(sn / norm, cn / norm, self.m1, self.nu)
    }

    /// Advances the sorted momentum `s` by `h`: the new momentum and
    /// `∫ sn²/(1 + ν sn²) dτ` over the span.
    fn advance(&self, s: DVec3, h: f64) -> (DVec3, f64) {
        self.advance_short(s, h)
            .unwrap_or_else(|| self.advance_any(s, h))
    }

    /// [`advance`](Self::advance) by the addition theorems, for a phase advance `δ = λh` short
    /// enough (see below); `None` otherwise.
    ///
    /// With `(sn, cn, dn)` at `τ₀` read off the momentum and at `δ` from the Landen
    /// transformation, `τ₁ = τ₀ + δ` follows from Jacobi's addition theorem
    /// (`sn(u + v) = (sn u cn v dn v + sn v cn u dn u)/(1 − m sn²u sn²v)` and its companions),
    /// and the phase integral `J(u) = ∫₀^u sn²/(1 + ν sn²)` from the addition theorem of the third
    /// kind (Jacobi's `Π(u, a)` at the imaginary `a` with `m sn²a = −ν`; the logarithm of a
    /// ratio of conjugates is an angle):
    ///
    /// ```text
    /// J(u + v) − J(u) = J(v) + atan2(C sn u sn v sn w, 1 + ν sn²w − ν sn u sn v cn w dn w) / C,
    /// w = u + v,   C = √(ν (m + ν)(1 + ν)).
    /// ```
    ///
    /// `J(v) = G(am v)` needs `|v| ≤ K`, which `|δ| < π/2 ≤ K` guarantees; and the angle is on the
    /// principal branch when the correction is below `π/(2C)` in size: it is bounded by
    /// `|δ|/(1 + ν)` (the integrand lies in `[0, 1/(1 + ν)]`), hence the second condition
    /// `|δ| C/(1 + ν) < π/2`. This saves `F(φ₀)`, `K` and one `R_J` against
    /// [`advance_any`](Self::advance_any).
    fn advance_short(&self, s: DVec3, h: f64) -> Option<(DVec3, f64)> {
        let start = self.short_start(s, h)?;
        let (snd, cnd, dnd) = jacobi_sn_cn_dn_complement(start.delta, self.m, self.m1);
        Some(self.short_end(&start, snd, cnd, dnd))
    }

    /// The part of [`advance_short`](Self::advance_short) before `(sn, cn, dn)` of `δ`: `None`
    /// when the span is not short.
    #[inline(always)]
    fn short_start(&self, s: DVec3, h: f64) -> Option<ShortStart> {
        let delta = self.lambda * h;
        let nu = self.nu;
        let c = (nu * (self.m + nu) * (1.0 + nu)).sqrt();
        if delta.abs() >= FRAC_PI_2 || delta.abs() * c >= FRAC_PI_2 * (1.0 + nu) {
            return None;
        }
        Some(ShortStart {
            delta,
            c,
            phase: self.phase_of(s),
        })
    }

    /// The part of [`advance_short`](Self::advance_short) after `(sn, cn, dn)` of `δ`.
    #[inline(always)]
    fn short_end(&self, start: &ShortStart, snd: f64, cnd: f64, dnd: f64) -> (DVec3, f64) {
        let (nu, c) = (self.nu, start.c);
        let (sn0, cn0, dn0) = start.phase;
        let product = sn0 * snd;
        let denominator = 1.0 - self.m * product * product;
        let sn = (sn0 * cnd * dnd + snd * cn0 * dn0) / denominator;
        let cn = (cn0 * cnd - product * dn0 * dnd) / denominator;
        let dn = (dn0 * dnd - self.m * product * cn0 * cnd) / denominator;
        let mut integral = self.phase_integral(snd, cnd);
        if c > 0.0 {
            // The real part is positive under the conditions above: `atan` of the ratio, by its
            // series where it is small (the usual case: the correction is O(δ³)).
            let ratio = c * product * sn / (1.0 + nu * (sn * sn - product * cn * dn));
            integral += small_atan(ratio) / c;
        }
        (self.momentum_at(sn, cn, dn), integral)
    }

    /// [`advance`](Self::advance) for any span: `τ₀ = F(φ₀ | m)`, `τ₁ = τ₀ + λh` reduced by
    /// half-periods `2K`, and `J` from `G` at both ends plus `2G(π/2)` per half-period.
    fn advance_any(&self, s: DVec3, h: f64) -> (DVec3, f64) {
        let (sn0, cn0, _) = self.phase_of(s);
        let tau0 = incomplete_f_sin_cos(sn0, cn0, self.m, self.m1);
        let tau1 = tau0 + self.lambda * h;
        let quarter = complete_k_complement(self.m1);
        let half_periods = if quarter.is_finite() {
            (tau1 / (2.0 * quarter)).round()
        } else {
            0.0
        };
        let reduced = if half_periods == 0.0 {
            tau1
        } else {
            tau1 - 2.0 * half_periods * quarter
        };
        let (sn, cn, dn) = jacobi_sn_cn_dn_complement(reduced, self.m, self.m1);
        let mut integral = self.phase_integral(sn, cn) - self.phase_integral(sn0, cn0);
        if half_periods != 0.0 {
            integral += 2.0 * half_periods * integral_sn2_over(1.0, 0.0, self.m1, self.nu);
        }
        let parity = if half_periods.rem_euclid(2.0) == 0.0 {
            1.0
        } else {
            -1.0
        };
        (self.momentum_at(parity * sn, parity * cn, dn), integral)
    }
}

/// True when the body momentum `m` does not move under the reciprocal moments `r`: `ṁ = m × (r ∘
/// m) = 0` (principal-axis spins, spheres, the plane of two equal moments), or a locked axis
/// (the constraint holds the body rates).
#[inline(always)]
fn is_steady(m: DVec3, r: DVec3) -> bool {
    m.cross(r * m) == DVec3::ZERO || r.min_element() == 0.0
}

/// A steady body's flow: a rotation about its fixed axis by `h |r ∘ m|`.
#[inline(always)]
fn steady_flow(body: &mut FreeBody, r: DVec3, h: f64) {
    body.q = (body.q * exp_body(h * (r * body.m))).normalize();
}

/// Sorted components → the Euler frame `(a, b, c)` = sorted `(2, 3, 1)`.
#[inline(always)]
fn euler(s: DVec3) -> DVec3 {
    DVec3::new(s.y, s.z, s.x)
}

/// A moving body in the sorted frame, before its momentum advances.
struct Moving {
    axes: SortedAxes,
    /// Sorted reciprocal moments.
    rs: DVec3,
    /// Sorted momentum at the start.
    s0: DVec3,
    /// `|m|`.
    magnitude: f64,
    /// The momentum frame at the start, `B(m₀)` of the module docs.
    before: DQuat,
    polhode: Polhode,
}

impl Moving {
    #[inline(always)]
    fn new(m: DVec3, r: DVec3) -> Self {
        let axes = SortedAxes::new(r);
        let (rs, s0) = (axes.to_sorted(r).abs(), axes.to_sorted(m));
        let magnitude = s0.length();
        Self {
            axes,
            rs,
            s0,
            magnitude,
            // Not needed before the end, but independent of the flow: here it overlaps the flow's
            // long chain instead of lengthening the end's.
            before: to_momentum_frame(euler(s0), magnitude),
            polhode: Polhode::new(s0, rs),
        }
    }

    /// Writes the flow's end into `body`, from the sorted momentum `s1` at the end and the
    /// phase integral over the span `h`.
    #[inline(always)]
    fn finish(&self, body: &mut FreeBody, s1: DVec3, integral: f64, h: f64) {
        let (rs, magnitude, polhode) = (self.rs, self.magnitude, &self.polhode);
        let d23 = rs.y - rs.z;
        let delta_phi =
            magnitude * rs.z * h + magnitude * d23 * polhode.kappa / polhode.lambda * integral;
        let (sin_half, cos_half) = sin_cos(0.5 * delta_phi);
        let spin = DQuat::from_xyzw(0.0, 0.0, sin_half, cos_half);
        let after = to_momentum_frame(euler(s1), magnitude);
        let turn = self.before.conjugate() * spin * after;
        // The turn's axis from Euler-frame to principal components: (a, b, c) → sorted (y, z, x).
        let axis = self.axes.to_principal(DVec3::new(turn.z, turn.x, turn.y));
        let turn = DQuat::from_xyzw(axis.x, axis.y, axis.z, turn.w);
        body.q = (body.q * turn).normalize();
        body.m = self.axes.to_principal(s1);
    }
}

/// The exact torque-free flow over `h` of the principal orientation `Q` and body momentum `m` of
/// `body`, given the reciprocal principal moments `r` (`0` on a locked axis); see the module docs.
/// `L = Q m` is unchanged, and so are `E` and `|m|`, to round-off.
pub(super) fn exact_free_flow(body: &mut FreeBody, r: DVec3, h: f64) {
    if is_steady(body.m, r) {
        return steady_flow(body, r, h);
    }
    let moving = Moving::new(body.m, r);
    let (s1, integral) = moving.polhode.advance(moving.s0, h);
    moving.finish(body, s1, integral, h);
}

/// [`exact_free_flow`] of two bodies over the same `h`, the same bits as two calls: the two
/// flows run stage by stage, so that the processor overlaps their long dependency chains
/// (square roots, divisions, the Landen levels; see
/// [`jacobi_sn_cn_dn_complement_pair`]). Bodies off the common path (steady, or a span that is
/// not short) take it one by one.
pub(super) fn exact_free_flow_pair(bodies: [&mut FreeBody; 2], r: [DVec3; 2], h: f64) {
    let [a, b] = bodies;
    if is_steady(a.m, r[0]) || is_steady(b.m, r[1]) {
        exact_free_flow(a, r[0], h);
        exact_free_flow(b, r[1], h);
        return;
    }
    let moving = [Moving::new(a.m, r[0]), Moving::new(b.m, r[1])];
    let (Some(start_a), Some(start_b)) = (
        moving[0].polhode.short_start(moving[0].s0, h),
        moving[1].polhode.short_start(moving[1].s0, h),
    ) else {
        for (body, moving) in [a, b].into_iter().zip(&moving) {
            let (s1, integral) = moving.polhode.advance(moving.s0, h);
            moving.finish(body, s1, integral, h);
        }
        return;
    };
    let [pa, pb] = [&moving[0].polhode, &moving[1].polhode];
    let [(sa, ca, da), (sb, cb, db)] = jacobi_sn_cn_dn_complement_pair(
        [start_a.delta, start_b.delta],
        [pa.m, pb.m],
        [pa.m1, pb.m1],
    );
    let (s1a, integral_a) = pa.short_end(&start_a, sa, ca, da);
    let (s1b, integral_b) = pb.short_end(&start_b, sb, cb, db);
    moving[0].finish(a, s1a, integral_a, h);
    moving[1].finish(b, s1b, integral_b, h);
}

/// The free rotation of `exact` over `h`: [`rotate_freely`] with [`exact_free_flow`].
#[inline]
pub(crate) fn rotate_exactly(state: &mut BodyState, mass: &MassProperties, h: Real) {
    rotate_freely(state, mass, h, exact_free_flow);
}

/// The exact free rotation over `h` of two non-spherical bodies ([`rotate_freely`] with
/// [`exact_free_flow`] for each), through [`exact_free_flow_pair`]: the same bits as one by one.
#[inline]
pub(crate) fn rotate_exactly_pair(
    states: [&mut BodyState; 2],
    masses: [&MassProperties; 2],
    h: Real,
) {
    let [a, b] = states;
    let mut free = [FreeState::new(a, masses[0]), FreeState::new(b, masses[1])];
    let r = [free[0].r, free[1].r];
    let [fa, fb] = &mut free;
    exact_free_flow_pair([&mut fa.body, &mut fb.body], r, h.widen());
    fa.write(a);
    fb.write(b);
}

/// Bodies translated for their exact free rotation over the same `h`, rotated two at a time
/// ([`rotate_exactly_pair`]: their long dependency chains overlap) and committed; the same bits
/// as [`rotate_exactly`] one by one.
pub(super) struct ExactPairs {
    h: Real,
    /// A translated body waiting for a partner.
    waiting: Option<(usize, BodyState)>,
}

impl ExactPairs {
    /// No body waiting yet; rotations over `h`.
    #[inline(always)]
    pub(super) fn new(h: Real) -> Self {
        Self { h, waiting: None }
    }

    /// Takes body `i` of `bodies`, translated as `state` (not spherical): it waits for a
    /// partner, or rotates with the one waiting and both are committed.
    #[inline(always)]
    pub(super) fn rotate(&mut self, i: usize, state: BodyState, bodies: &mut impl BodyBatch) {
        match self.waiting.take() {
            None => self.waiting = Some((i, state)),
            Some((j, mut first)) => {
                let mut second = state;
                rotate_exactly_pair(
                    [&mut first, &mut second],
                    [bodies.mass(j), bodies.mass(i)],
                    self.h,
                );
                commit(bodies, j, &first);
                commit(bodies, i, &second);
            }
        }
    }

    /// Rotates and commits the body left waiting, alone.
    #[inline(always)]
    pub(super) fn finish(self, bodies: &mut impl BodyBatch) {
        if let Some((j, mut last)) = self.waiting {
            rotate_exactly(&mut last, bodies.mass(j), self.h);
            commit(bodies, j, &last);
        }
    }
}

/// The `exact` batch: each body's drift–kick–drift translation, then its free rotation, two
/// bodies at a time ([`ExactPairs`]), or stepped whole by `alone` when it is spherical or its
/// translation cannot run first (a whole step under a torque).
#[inline(always)]
pub(super) fn exact_flow_batch(
    phase: StepPhase,
    bodies: &mut impl BodyBatch,
    dt: Real,
    mut alone: impl FnMut(&mut BodyState, &MassProperties, &Wrench, Real),
) {
    let mut pairs = ExactPairs::new(free_rotation_span(phase, dt));
    let mut next = BodyState::ZEROED;
    for i in 0..bodies.len() {
        bodies.prefetch(i + PREFETCH_AHEAD);
        let Some(wrench) = bodies.take(i, &mut next) else {
            continue;
        };
        let mass = bodies.mass(i);
        if mass.is_spherical() || !drift_kick_drift_translation(phase, &mut next, mass, &wrench, dt)
        {
            let mut single = next;
            alone(&mut single, mass, &wrench, bodies.spring_turn_rate(i));
            commit(bodies, i, &single);
            continue;
        }
        pairs.rotate(i, next, bodies);
    }
    pairs.finish(bodies);
}

#[cfg(test)]
mod tests;
