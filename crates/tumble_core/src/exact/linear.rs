//! Closed forms for linear motion: the projectile and the undamped harmonic spring.

use glam::DVec3;

use super::ExactError;

/// Projectile under the uniform acceleration `g`: returns `(x, v)` with
/// `x(t) = x₀ + v₀t + ½gt²` and `v(t) = v₀ + gt` (exact for any `t`, also negative).
pub fn projectile(x0: DVec3, v0: DVec3, g: DVec3, t: f64) -> (DVec3, DVec3) {
    (x0 + (v0 + 0.5 * g * t) * t, v0 + g * t)
}

/// Undamped spring `m ẍ = −k x`: returns `(x, v)` with `ω = √(k/m)`,
/// `x(t) = x₀ cos ωt + (v₀/ω) sin ωt` and `v(t) = −x₀ω sin ωt + v₀ cos ωt`.
///
/// Unchecked: a non-positive or non-finite `stiffness` or `mass` gives NaN. Use
/// [`HarmonicSpring::new`] for a typed error instead.
pub fn harmonic_spring(x0: f64, v0: f64, stiffness: f64, mass: f64, t: f64) -> (f64, f64) {
    let w = (stiffness / mass).sqrt();
    if !(w.is_finite() && w > 0.0) {
        return (f64::NAN, f64::NAN);
    }
    let (s, c) = (w * t).sin_cos();
    (x0 * c + v0 / w * s, -x0 * w * s + v0 * c)
}

/// The undamped spring `m ẍ = −k x` from `(x₀, v₀)` at `t = 0`, validated once.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HarmonicSpring {
    x0: f64,
    v0: f64,
    stiffness: f64,
    mass: f64,
    omega: f64,
}

impl HarmonicSpring {
    /// A spring of `stiffness` k (N/m) carrying `mass` m (kg), released at `x0` with velocity
    /// `v0`. Fails unless `k` and `m` are finite and `> 0` and `x0`, `v0` are finite.
    pub fn new(x0: f64, v0: f64, stiffness: f64, mass: f64) -> Result<Self, ExactError> {
        let omega = (stiffness / mass).sqrt();
        let valid = stiffness.is_finite() && mass.is_finite() && stiffness > 0.0 && mass > 0.0;
        if !(valid && omega.is_finite() && omega > 0.0) {
            return Err(ExactError::BadSpring { stiffness, mass });
        }
        if !(x0.is_finite() && v0.is_finite()) {
            return Err(ExactError::NonFinite("spring initial state"));
        }
        Ok(Self {
            x0,
            v0,
            stiffness,
            mass,
            omega,
        })
    }

    /// Angular frequency `ω = √(k/m)` (rad/s).
    pub fn angular_frequency(&self) -> f64 {
        self.omega
    }

    /// Period `2π/ω` (s).
    pub fn period(&self) -> f64 {
        std::f64::consts::TAU / self.omega
    }

    /// `(x(t), v(t))`, see [`harmonic_spring`].
    pub fn state(&self, t: f64) -> (f64, f64) {
        harmonic_spring(self.x0, self.v0, self.stiffness, self.mass, t)
    }

    /// Total energy `½kx₀² + ½mv₀²` (J), constant.
    pub fn energy(&self) -> f64 {
        0.5 * self.stiffness * self.x0 * self.x0 + 0.5 * self.mass * self.v0 * self.v0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn projectile_satisfies_its_equations() {
        let (x0, v0, g) = (
            DVec3::new(0.5, 1.0, -2.0),
            DVec3::new(1.0, 2.0, 0.0),
            DVec3::new(0.0, -10.0, 0.0),
        );
        let (x, v) = projectile(DVec3::ZERO, v0, g, 2.0);
        assert_eq!(x, DVec3::new(2.0, -16.0, 0.0));
        assert_eq!(v, DVec3::new(1.0, -18.0, 0.0));
        assert_eq!(projectile(x0, v0, g, 0.0), (x0, v0));
        // Central second difference of x is g (exact for a quadratic up to round-off), and
        // mechanical energy ½v² − g·x is constant.
        let h = 1e-3;
        for t in [-1.0, 0.3, 4.0] {
            let acc = (projectile(x0, v0, g, t + h).0 - 2.0 * projectile(x0, v0, g, t).0
                + projectile(x0, v0, g, t - h).0)
                / (h * h);
            assert!((acc - g).length() < 1e-6, "{acc}");
            let (x, v) = projectile(x0, v0, g, t);
            let e = 0.5 * v.length_squared() - g.dot(x);
            assert!((e - (0.5 * v0.length_squared() - g.dot(x0))).abs() < 1e-12);
        }
    }

    #[test]
    fn spring_satisfies_its_equations() {
        let (k, m) = (4.0, 0.25);
        let spring = HarmonicSpring::new(0.3, 0.5, k, m).unwrap();
        assert_eq!(spring.angular_frequency(), 4.0);
        assert_eq!(spring.state(0.0), (0.3, 0.5));
        for t in [0.1, 1.0, 7.3, -2.0] {
            let (x, v) = spring.state(t);
            // Energy conserved to round-off.
            let e = 0.5 * k * x * x + 0.5 * m * v * v;
            assert!((e / spring.energy() - 1.0).abs() < 1e-14);
            // v is dx/dt (central difference, error ~h²ω³|x| ~ 1e-8).
            let h = 1e-5;
            let dx = (spring.state(t + h).0 - spring.state(t - h).0) / (2.0 * h);
            assert!((dx - v).abs() < 1e-8, "{dx} vs {v}");
        }
        let (x, v) = spring.state(spring.period());
        assert!((x - 0.3).abs() < 1e-14 && (v - 0.5).abs() < 1e-14);
        let (x, _) = harmonic_spring(1.0, 0.0, k, m, 0.25 * spring.period());
        assert!(x.abs() < 1e-15);
        assert!(matches!(
            HarmonicSpring::new(1.0, 0.0, -1.0, 1.0),
            Err(ExactError::BadSpring { .. })
        ));
        assert!(HarmonicSpring::new(1.0, 0.0, 1.0, 0.0).is_err());
        assert!(HarmonicSpring::new(f64::NAN, 0.0, 1.0, 1.0).is_err());
        assert!(harmonic_spring(1.0, 0.0, 1.0, -1.0, 1.0).0.is_nan());
    }
}
