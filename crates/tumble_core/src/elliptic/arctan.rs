//! `atan` and `atan2` in IEEE arithmetic only (`+ − × ÷`), so that a step that needs an angle
//! gives the same bits on every platform (the platform `atan` differs between libms).
//!
//! Reduction: `atan x = π/2 − atan(1/x)` above 1, then `atan x = π/6 + atan((x√3 − 1)/(x + √3))`
//! above `tan(π/12) = 2 − √3`, leaving `|t| ≤ 0.268`, where the alternating series
//! `Σ (−1)ᵏ t^{2k+1}/(2k + 1)` through `t³¹` is below `0.268³³/33 < 3e-21` in its first omitted
//! term. Error ≲ 2 ulp.

use std::f64::consts::{FRAC_PI_2, FRAC_PI_6, PI};

/// `2 − √3 = tan(π/12)`.
const TAN_PI_12: f64 = 0.267_949_192_431_122_7;

/// `√3`.
const SQRT_3: f64 = 1.732_050_807_568_877_2;

/// `atan t` for `|t| ≤ tan(π/12)` by its series through `t³¹` (Horner in `t²`).
fn atan_reduced(t: f64) -> f64 {
    let t2 = t * t;
    let mut sum = 0.0;
    for k in (0..16).rev() {
        let term = 1.0 / f64::from(2 * k + 1);
        sum = if k % 2 == 0 { term } else { -term } + t2 * sum;
    }
    t * sum
}

/// `atan x` for every finite `x` (NaN gives NaN, `±∞` gives `±π/2`).
pub(crate) fn atan(x: f64) -> f64 {
    let (sign, a) = if x < 0.0 { (-1.0, -x) } else { (1.0, x) };
    let (base, a) = if a > 1.0 {
        (FRAC_PI_2, -1.0 / a)
    } else {
        (0.0, a)
    };
    // `a` is now in [−1, 1]; with `base = π/2` it enters negated (π/2 − atan(1/x)).
    let (offset, t) = if a.abs() > TAN_PI_12 {
        let s = a.signum();
        let b = a.abs();
        (s * FRAC_PI_6, s * ((b * SQRT_3 - 1.0) / (b + SQRT_3)))
    } else {
        (0.0, a)
    };
    sign * (base + offset + atan_reduced(t))
}

/// `atan2(y, x)` in `(−π, π]`, from [`atan`].
pub(crate) fn atan2(y: f64, x: f64) -> f64 {
    if x > 0.0 {
        atan(y / x)
    } else if x < 0.0 {
        let a = atan(y / x);
        if y < 0.0 { a - PI } else { a + PI }
    } else if y > 0.0 {
        FRAC_PI_2
    } else if y < 0.0 {
        -FRAC_PI_2
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_the_platform_to_a_few_ulp() {
        let mut worst = 0.0f64;
        for k in -4000..=4000 {
            let x = f64::from(k) * 0.0137;
            for v in [x, x * x * x, 1.0 / (x + 1e-3)] {
                let (mine, platform) = (atan(v), v.atan());
                worst = worst.max((mine - platform).abs() / platform.abs().max(1e-300));
            }
        }
        assert!(worst < 4.0 * f64::EPSILON, "worst relative error {worst:e}");
        assert_eq!(atan(0.0), 0.0);
        assert_eq!(atan(f64::INFINITY), FRAC_PI_2);
        assert!(atan(f64::NAN).is_nan());
    }

    #[test]
    fn atan2_covers_every_quadrant() {
        for (y, x) in [
            (1.0, 2.0),
            (1.0, -2.0),
            (-1.0, -2.0),
            (-1.0, 2.0),
            (3.0, 0.0),
            (-3.0, 0.0),
            (0.0, -1.0),
            (0.0, 0.0),
            (1e-300, 1.0),
        ] {
            let (mine, platform) = (atan2(y, x), f64::atan2(y, x));
            assert!(
                (mine - platform).abs() <= 4.0 * f64::EPSILON * platform.abs().max(1e-300),
                "atan2({y}, {x}) = {mine} vs {platform}"
            );
        }
    }
}
