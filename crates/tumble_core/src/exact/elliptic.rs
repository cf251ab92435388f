//! Jacobi elliptic functions and elliptic integrals of the first kind, in f64, with parameter
//! `m = k²`.
//!
//! - `sn, cn, dn` by the descending Landen transformation (the AGM scale, Abramowitz & Stegun
//!   16.4): `aₙ₊₁ = (aₙ + bₙ)/2`, `bₙ₊₁ = √(aₙbₙ)`, `cₙ₊₁ = (aₙ − bₙ)/2`, then
//!   `φ_N = 2^N a_N u` and `φₙ₋₁ = (φₙ + asin(cₙ/aₙ · sin φₙ))/2`; `sn = sin φ₀`, `cn = cos φ₀`,
//!   `dn = √(1 − m sn²)`.
//! - `K(m) = π / (2 AGM(1, √(1 − m)))`.
//! - `F(φ | m) = sin φ · R_F(cos²φ, 1 − m sin²φ, 1)` on `|φ| ≤ π/2` (Carlson's symmetric form,
//!   duplication algorithm), extended by `F(φ + nπ) = F(φ) + 2nK`.

use std::f64::consts::{FRAC_PI_2, PI};

/// Clamps a parameter that round-off pushed slightly outside `[0, 1]`.
fn clamp_parameter(m: f64) -> f64 {
    m.clamp(0.0, 1.0)
}

/// `(sn u, cn u, dn u)` for parameter `m = k² ∈ [0, 1]`.
pub fn jacobi_sn_cn_dn(u: f64, m: f64) -> (f64, f64, f64) {
    let m = clamp_parameter(m);
    if m == 0.0 {
        return (u.sin(), u.cos(), 1.0);
    }
    if m == 1.0 {
        let sech = 1.0 / u.cosh();
        return (u.tanh(), sech, sech);
    }
    const LEVELS: usize = 16;
    let mut a = [0.0; LEVELS];
    let mut c = [0.0; LEVELS];
    a[0] = 1.0;
    let mut b = (1.0 - m).sqrt();
    c[0] = m.sqrt();
    let mut n = 0;
    while n + 1 < LEVELS && (c[n] / a[n]).abs() > f64::EPSILON {
        a[n + 1] = 0.5 * (a[n] + b);
        c[n + 1] = 0.5 * (a[n] - b);
        b = (a[n] * b).sqrt();
        n += 1;
    }
    let mut phi = f64::from(1u32 << n) * a[n] * u;
    for level in (1..=n).rev() {
        phi = 0.5 * (phi + (c[level] / a[level] * phi.sin()).asin());
    }
    let (sn, cn) = phi.sin_cos();
    // dn > 0 for m < 1; from sn it is exact and free of the 0/0 of cn / cos(φ₁ − φ₀) near cn = 0.
    (sn, cn, (1.0 - m * sn * sn).sqrt())
}

/// Arithmetic–geometric mean of two positive numbers.
fn agm(mut a: f64, mut b: f64) -> f64 {
    for _ in 0..64 {
        if (a - b).abs() <= f64::EPSILON * a {
            break;
        }
        (a, b) = (0.5 * (a + b), (a * b).sqrt());
    }
    0.5 * (a + b)
}

/// Complete elliptic integral of the first kind `K(m) = π / (2 AGM(1, √(1 − m)))`
/// (infinite at `m = 1`).
pub fn complete_k(m: f64) -> f64 {
    let m = clamp_parameter(m);
    if m == 1.0 {
        return f64::INFINITY;
    }
    PI / (2.0 * agm(1.0, (1.0 - m).sqrt()))
}

/// Carlson's symmetric integral `R_F(x, y, z)` by the duplication theorem.
fn carlson_rf(mut x: f64, mut y: f64, mut z: f64) -> f64 {
    for _ in 0..64 {
        let mean = (x + y + z) / 3.0;
        let (dx, dy, dz) = (1.0 - x / mean, 1.0 - y / mean, 1.0 - z / mean);
        if dx.abs().max(dy.abs()).max(dz.abs()) < 1e-4 {
            // Fifth-order series in the deviations (Carlson 1995): error ~ δ⁶ < 1e-24.
            let e2 = dx * dy - dz * dz;
            let e3 = dx * dy * dz;
            return (1.0 - e2 / 10.0 + e3 / 14.0 + e2 * e2 / 24.0 - 3.0 * e2 * e3 / 44.0)
                / mean.sqrt();
        }
        let (sx, sy, sz) = (x.sqrt(), y.sqrt(), z.sqrt());
        let lambda = sx * (sy + sz) + sy * sz;
        x = 0.25 * (x + lambda);
        y = 0.25 * (y + lambda);
        z = 0.25 * (z + lambda);
    }
    1.0 / ((x + y + z) / 3.0).sqrt()
}

/// Incomplete elliptic integral of the first kind `F(φ | m)` for any real `φ`.
pub fn incomplete_f(phi: f64, m: f64) -> f64 {
    let m = clamp_parameter(m);
    // φ = nπ + r with |r| ≤ π/2.
    let n = (phi / PI).round();
    let r = phi - n * PI;
    let (s, c) = r.sin_cos();
    let base = if r.abs() == FRAC_PI_2 && m == 1.0 {
        f64::INFINITY.copysign(r)
    } else {
        s * carlson_rf(c * c, 1.0 - m * s * s, 1.0)
    };
    if n == 0.0 {
        base
    } else {
        base + 2.0 * n * complete_k(m)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const MS: [f64; 6] = [0.0, 0.1, 0.5, 0.9, 0.999, 0.999_999_9];

    #[test]
    fn identities_hold() {
        for m in MS {
            for i in -200..200 {
                let u = f64::from(i) * 0.037;
                let (sn, cn, dn) = jacobi_sn_cn_dn(u, m);
                assert!((sn * sn + cn * cn - 1.0).abs() < 1e-14, "m={m} u={u}");
                assert!((dn * dn + m * sn * sn - 1.0).abs() < 1e-14, "m={m} u={u}");
            }
        }
    }

    #[test]
    fn special_values_and_periods() {
        for m in [0.1, 0.5, 0.9, 0.99] {
            let k = complete_k(m);
            let (sn, cn, dn) = jacobi_sn_cn_dn(k, m);
            assert!(
                (sn - 1.0).abs() < 1e-13
                    && cn.abs() < 1e-7
                    && (dn - (1.0 - m).sqrt()).abs() < 1e-12,
                "m={m}"
            );
            for u in [0.3, 1.1, -2.4] {
                let (s0, c0, d0) = jacobi_sn_cn_dn(u, m);
                let (s4, c4, _) = jacobi_sn_cn_dn(u + 4.0 * k, m);
                let (_, _, d2) = jacobi_sn_cn_dn(u + 2.0 * k, m);
                assert!(
                    (s0 - s4).abs() < 1e-12 && (c0 - c4).abs() < 1e-12 && (d0 - d2).abs() < 1e-12
                );
                let (s2, c2, _) = jacobi_sn_cn_dn(u + 2.0 * k, m);
                assert!(
                    (s0 + s2).abs() < 1e-12 && (c0 + c2).abs() < 1e-12,
                    "half period m={m}"
                );
            }
        }
        // Limits.
        let (sn, cn, dn) = jacobi_sn_cn_dn(0.7, 1.0);
        assert!(
            (sn - 0.7f64.tanh()).abs() < 1e-15
                && (cn - 1.0 / 0.7f64.cosh()).abs() < 1e-15
                && cn == dn
        );
        let (sn, cn, dn) = jacobi_sn_cn_dn(0.7, 0.0);
        assert!(
            (sn - 0.7f64.sin()).abs() < 1e-15 && (cn - 0.7f64.cos()).abs() < 1e-15 && dn == 1.0
        );
    }

    #[test]
    fn complete_integral_matches_tables() {
        assert!((complete_k(0.0) - FRAC_PI_2).abs() < 1e-15);
        assert!((complete_k(0.5) - 1.854_074_677_301_372).abs() < 1e-14);
        assert!((complete_k(0.9) - 2.578_092_113_348_173).abs() < 1e-14);
        assert!((incomplete_f(FRAC_PI_2, 0.9) - complete_k(0.9)).abs() < 1e-13);
    }

    #[test]
    fn incomplete_integral_inverts_the_amplitude() {
        for m in [0.0, 0.3, 0.8, 0.9999] {
            for i in -50..50 {
                let u = f64::from(i) * 0.113;
                let (sn, cn, _) = jacobi_sn_cn_dn(u, m);
                // Within the principal branch |u| < K the amplitude is atan2(sn, cn).
                if u.abs() < complete_k(m) {
                    let back = incomplete_f(sn.atan2(cn), m);
                    assert!((back - u).abs() < 1e-12, "m={m} u={u}: {back}");
                }
            }
            let k = complete_k(m);
            assert!((incomplete_f(3.0 * PI, m) - 6.0 * k).abs() < 1e-11);
        }
    }
}
