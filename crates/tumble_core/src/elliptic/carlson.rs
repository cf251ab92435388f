//! Carlson's symmetric elliptic integrals `R_F`, `R_C` and `R_J` by the duplication theorem
//! (B. C. Carlson, *Numerical computation of real or complex elliptic integrals*, Numer.
//! Algorithms 10 (1995) 13–26; DLMF §19.36(i)), and the one integral of the third kind the exact
//! free rigid body needs ([`integral_sn2_over`]).
//!
//! Each duplication step replaces the arguments `w` by `(w + λ)/4`, `λ = √x√y + √y√z + √z√x`,
//! which leaves the integral unchanged (up to an elementary term for `R_J`) and shrinks the
//! spread of the arguments about their mean by 4. Once the relative spread is below `10⁻³` a
//! fifth-order Taylor series about the mean is exact to `≈ 10⁻¹⁸` relative: about six steps for
//! arguments of similar size, more when one of them is zero or they differ by many decades.

/// Relative spread of the arguments below which the fifth-order series is used: its truncation
/// error is `O(δ⁶) ≈ 10⁻¹⁸` (Carlson 1995, eqs. 2.2 and 2.13).
const SERIES_SPREAD: f64 = 1e-3;

/// Safety bound on the number of duplication steps (each divides the spread by 4; 200 is far
/// beyond what any finite f64 arguments need).
const MAX_DUPLICATIONS: usize = 200;

/// `R_F(x, y, z) = ½ ∫₀^∞ dt / √((t+x)(t+y)(t+z))` for `x, y, z ≥ 0` with at most one of them
/// zero.
pub fn carlson_rf(mut x: f64, mut y: f64, mut z: f64) -> f64 {
    // Each duplication shifts the three arguments by the same λ and divides them by 4, so their
    // deviations from the mean shrink exactly as 4⁻ᵏ: the stopping test needs no division.
    let mean0 = (x + y + z) * (1.0 / 3.0);
    let spread = (mean0 - x)
        .abs()
        .max((mean0 - y).abs())
        .max((mean0 - z).abs());
    let (mut mean, mut shrink) = (mean0, 1.0);
    for _ in 0..MAX_DUPLICATIONS {
        if shrink * spread < SERIES_SPREAD * mean {
            break;
        }
        let (sx, sy, sz) = (x.sqrt(), y.sqrt(), z.sqrt());
        let lambda = sx * (sy + sz) + sy * sz;
        x = 0.25 * (x + lambda);
        y = 0.25 * (y + lambda);
        z = 0.25 * (z + lambda);
        mean = 0.25 * (mean + lambda);
        shrink *= 0.25;
    }
    let inv = 1.0 / mean;
    // Deviations from the mean; they sum to zero.
    let (dx, dy) = (1.0 - x * inv, 1.0 - y * inv);
    let dz = -(dx + dy);
    let e2 = dx * dy - dz * dz;
    let e3 = dx * dy * dz;
    (1.0 - e2 / 10.0 + e3 / 14.0 + e2 * e2 / 24.0 - 3.0 * e2 * e3 / 44.0) * inv.sqrt()
}

/// `R_C(1, 1 + e) = ½ ∫₀^∞ dt / ((t + 1 + e) √(t + 1))` for `e > −1`: `atan(√e)/√e` for `e > 0`
/// (tumble's own `atan`, see `arctan`),
/// `atanh(√−e)/√−e` for `e < 0`, and the alternating series `Σ (−e)ᵏ/(2k + 1)` for `|e|` below
/// `10⁻³`, where the closed forms would divide a small difference by a small number.
pub fn carlson_rc1(e: f64) -> f64 {
    if e.abs() < SERIES_SPREAD {
        // Σₖ₌₀⁵ (−e)ᵏ/(2k+1); the first term left out is e⁶/13 < 1e-19.
        1.0 - e * (1.0 / 3.0 - e * (1.0 / 5.0 - e * (1.0 / 7.0 - e * (1.0 / 9.0 - e / 11.0))))
    } else if e > 0.0 {
        let s = e.sqrt();
        super::arctan::atan(s) / s
    } else {
        // Only for `p` below an argument, never on the exact flow's path (its `p ≥ 1 ≥ x, y, z`).
        let s = (-e).sqrt();
        s.atanh() / s
    }
}

/// `R_J(x, y, z, p) = (3/2) ∫₀^∞ dt / ((t + p) √((t+x)(t+y)(t+z)))` for `x, y, z ≥ 0` with at
/// most one of them zero, and `p > 0`.
///
/// Duplication (DLMF 19.36.9–12): with `δ = (p − x)(p − y)(p − z)`, `d = (√p+√x)(√p+√y)(√p+√z)`
/// and `e = δ / (4^{3k} d²)` at step `k`, `R_J = 4^{−N} R_J(x_N, …) + 6 Σₖ 4^{−k} R_C(1, 1 + eₖ)/dₖ`,
/// and the final `R_J` is the fifth-order series in `X, Y, Z` (the relative deviations of
/// `x, y, z` from the mean `A = (x + y + z + 2p)/5`) and `P = −(X + Y + Z)/2`:
/// `A^{−3/2}(1 − 3E₂/14 + E₃/6 + 9E₂²/88 − 3E₄/22 − 9E₂E₃/52 + 3E₅/26)`.
pub fn carlson_rj(mut x: f64, mut y: f64, mut z: f64, mut p: f64) -> f64 {
    let delta = (p - x) * (p - y) * (p - z);
    let mean0 = (x + y + z + 2.0 * p) * 0.2;
    let spread = (mean0 - x)
        .abs()
        .max((mean0 - y).abs())
        .max((mean0 - z).abs())
        .max((mean0 - p).abs());
    let mut sum = 0.0;
    // 4^{−k} (the deviations from the mean shrink exactly so, see `carlson_rf`) and 4^{−3k}.
    let (mut mean, mut shrink, mut shrink3) = (mean0, 1.0, 1.0);
    for _ in 0..MAX_DUPLICATIONS {
        if shrink * spread < SERIES_SPREAD * mean {
            break;
        }
        let (sx, sy, sz, sp) = (x.sqrt(), y.sqrt(), z.sqrt(), p.sqrt());
        let lambda = sx * (sy + sz) + sy * sz;
        let inv_d = 1.0 / ((sp + sx) * (sp + sy) * (sp + sz));
        sum += shrink * carlson_rc1(shrink3 * delta * inv_d * inv_d) * inv_d;
        x = 0.25 * (x + lambda);
        y = 0.25 * (y + lambda);
        z = 0.25 * (z + lambda);
        p = 0.25 * (p + lambda);
        mean = 0.25 * (mean + lambda);
        shrink *= 0.25;
        shrink3 *= 1.0 / 64.0;
    }
    let inv = 1.0 / mean;
    let (dx, dy, dz) = (1.0 - x * inv, 1.0 - y * inv, 1.0 - z * inv);
    let pp = -0.5 * (dx + dy + dz);
    let e2 = dx * dy + dx * dz + dy * dz - 3.0 * pp * pp;
    let e3 = dx * dy * dz + 2.0 * e2 * pp + 4.0 * pp * pp * pp;
    let e4 = (2.0 * dx * dy * dz + e2 * pp + 3.0 * pp * pp * pp) * pp;
    let e5 = dx * dy * dz * pp * pp;
    let series = 1.0 - 3.0 * e2 / 14.0 + e3 / 6.0 + 9.0 * e2 * e2 / 88.0
        - 3.0 * e4 / 22.0
        - 9.0 * e2 * e3 / 52.0
        + 3.0 * e5 / 26.0;
    shrink * series * inv * inv.sqrt() + 6.0 * sum
}

/// `∫₀^φ sin²θ / ((1 + ν sin²θ) √(1 − m sin²θ)) dθ` on `|φ| ≤ π/2`, from `sin φ`, `cos φ ≥ 0`,
/// the complementary parameter `m₁ = 1 − m` and `ν ≥ 0`:
/// `(sin³φ / 3) R_J(cos²φ, cos²φ + m₁ sin²φ, 1, 1 + ν sin²φ)`.
///
/// It is `(Π(−ν; φ | m) − F(φ | m))/(−ν)` written without the difference, so it keeps its relative
/// accuracy for every `ν` (Legendre's `Π` with a negative characteristic loses digits to that
/// difference when `ν` is large). In terms of `τ = F(φ | m)` it is `∫₀^τ sn²/(1 + ν sn²) dτ`.
/// At `m₁ = 0` and `φ = ±π/2` it diverges (`+∞` with the sign of `sin φ`).
pub fn integral_sn2_over(sin_phi: f64, cos_phi: f64, m1: f64, nu: f64) -> f64 {
    let (s, c) = (sin_phi, cos_phi.max(0.0));
    if s == 0.0 {
        return 0.0;
    }
    let c2 = c * c;
    let delta2 = c2 + m1 * s * s;
    if c2 == 0.0 && delta2 == 0.0 {
        return f64::INFINITY.copysign(s);
    }
    s * s * s / 3.0 * carlson_rj(c2, delta2, 1.0, 1.0 + nu * s * s)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Composite 10-point Gauss–Legendre over `[a, b]` in `panels` panels: an independent
    /// check of the closed forms (the integrands are analytic on the intervals used).
    fn quadrature(f: impl Fn(f64) -> f64, a: f64, b: f64, panels: usize) -> f64 {
        const NODES: [f64; 5] = [
            0.148_874_338_981_631_2,
            0.433_395_394_129_247_2,
            0.679_409_568_299_024_4,
            0.865_063_366_688_984_5,
            0.973_906_528_517_171_7,
        ];
        const WEIGHTS: [f64; 5] = [
            0.295_524_224_714_752_9,
            0.269_266_719_309_996_3,
            0.219_086_362_515_982,
            0.149_451_349_150_580_6,
            0.066_671_344_308_688_1,
        ];
        let width = (b - a) / panels as f64;
        (0..panels)
            .map(|k| {
                let mid = a + (k as f64 + 0.5) * width;
                let half = 0.5 * width;
                NODES
                    .iter()
                    .zip(WEIGHTS)
                    .map(|(&x, w)| w * (f(mid - half * x) + f(mid + half * x)))
                    .sum::<f64>()
                    * half
            })
            .sum()
    }

    fn rel(a: f64, b: f64) -> f64 {
        ((a - b) / b).abs()
    }

    #[test]
    fn carlson_test_values() {
        // Carlson (1995), table of test values (also DLMF §19.36 and Numerical Recipes).
        assert!(rel(carlson_rf(1.0, 2.0, 0.0), 1.311_028_777_146_1) < 1e-13);
        assert!(rel(carlson_rj(0.0, 1.0, 2.0, 3.0), 0.776_886_237_785_82) < 1e-13);
        assert!(rel(carlson_rj(2.0, 3.0, 4.0, 5.0), 0.142_975_796_671_57) < 1e-13);
        // R_J(x, y, z, z) is R_D; R_D(0, 2, 1) = 1.797 210 352 103 4.
        assert!(rel(carlson_rj(0.0, 2.0, 1.0, 1.0), 1.797_210_352_103_4) < 1e-13);
        // Homogeneity of degree −3/2 and the value at coincident arguments.
        assert!(rel(carlson_rj(4.0, 4.0, 4.0, 4.0), 0.125) < 1e-15);
        let (a, b) = (
            carlson_rj(0.3, 1.7, 2.2, 0.9),
            carlson_rj(1.2, 6.8, 8.8, 3.6),
        );
        assert!(rel(b, a / 8.0) < 1e-14);
    }

    #[test]
    fn rc_series_and_closed_forms_agree_at_the_switch() {
        for e in [0.999e-3, -0.999e-3] {
            let series = carlson_rc1(e);
            let closed = if e > 0.0 {
                e.sqrt().atan() / e.sqrt()
            } else {
                (-e).sqrt().atanh() / (-e).sqrt()
            };
            assert!(rel(series, closed) < 1e-15, "{e}: {series} vs {closed}");
        }
        assert_eq!(carlson_rc1(0.0), 1.0);
    }

    #[test]
    fn third_kind_matches_quadrature() {
        // (φ, m, ν): ordinary, large characteristic (thin bodies: ν up to 1e8), near m = 1.
        for (phi, m, nu) in [
            (0.7, 0.3, 0.5),
            (1.5, 0.9, 1e3),
            (-1.2, 0.5, 2e8),
            (1.55, 1.0 - 1e-9, 3.0),
            (0.4, 0.0, 0.0),
            (1.57, 0.999, 0.0),
        ] {
            let (s, c) = f64::sin_cos(phi);
            let closed = integral_sn2_over(s, c, 1.0 - m, nu);
            let f = |t: f64| {
                let s2 = t.sin().powi(2);
                s2 / ((1.0 + nu * s2) * (1.0 - m * s2).sqrt())
            };
            let numeric = quadrature(f, 0.0, phi, 40_000);
            assert!(
                rel(closed, numeric) < 1e-12,
                "φ = {phi}, m = {m}, ν = {nu}: {closed} vs {numeric}"
            );
        }
    }
}
