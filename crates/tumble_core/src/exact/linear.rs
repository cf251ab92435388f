//! Closed forms for linear motion.

use glam::DVec3;

use super::ExactError;

/// Projectile under uniform acceleration `g`: `x = x₀ + v₀t + ½gt²`, `v = v₀ + gt`.
pub fn projectile(x0: DVec3, v0: DVec3, g: DVec3, t: f64) -> (DVec3, DVec3) {
    (x0 + v0 * t + 0.5 * g * t * t, v0 + g * t)
}

/// Undamped spring `m ẍ = −k x`: `x = x₀ cos ωt + (v₀/ω) sin ωt`, `v = −x₀ω sin ωt + v₀ cos ωt`,
/// `ω = √(k/m)`. Returns `(x, v)`.
pub fn harmonic_spring(
    x0: f64,
    v0: f64,
    stiffness: f64,
    mass: f64,
    t: f64,
) -> Result<(f64, f64), ExactError> {
    if !(stiffness.is_finite() && mass.is_finite() && stiffness > 0.0 && mass > 0.0) {
        return Err(ExactError::BadSpring);
    }
    let w = (stiffness / mass).sqrt();
    let (s, c) = (w * t).sin_cos();
    Ok((x0 * c + v0 / w * s, -x0 * w * s + v0 * c))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn projectile_and_spring_satisfy_their_equations() {
        let (x, v) = projectile(
            DVec3::ZERO,
            DVec3::new(1.0, 2.0, 0.0),
            DVec3::new(0.0, -10.0, 0.0),
            2.0,
        );
        assert_eq!(x, DVec3::new(2.0, -16.0, 0.0));
        assert_eq!(v, DVec3::new(1.0, -18.0, 0.0));
        // Energy of the spring is conserved and the period is 2π/ω.
        let (k, m) = (4.0, 1.0);
        let e = |(x, v): (f64, f64)| 0.5 * k * x * x + 0.5 * m * v * v;
        let e0 = e((0.3, 0.5));
        for t in [0.1, 1.0, 7.3] {
            assert!((e(harmonic_spring(0.3, 0.5, k, m, t).unwrap()) - e0).abs() < 1e-14);
        }
        let (x, v) = harmonic_spring(0.3, 0.5, k, m, std::f64::consts::PI).unwrap();
        assert!((x - 0.3).abs() < 1e-14 && (v - 0.5).abs() < 1e-14);
        assert!(harmonic_spring(1.0, 0.0, -1.0, 1.0, 0.0).is_err());
    }
}
