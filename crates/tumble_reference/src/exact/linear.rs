//! Closed forms for linear motion: the projectile, the undamped harmonic spring and the damped
//! harmonic oscillator.

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

/// How a [`DampedSpring`] returns to rest, from `γ = c/(2m)` against `ω₀ = √(k/m)`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DampingRegime {
    /// `γ < ω₀`: oscillates at `ω_d = √(ω₀² − γ²)` inside the envelope `e^{−γt}`.
    Underdamped,
    /// `γ = ω₀`: the fastest return without oscillation.
    Critical,
    /// `γ > ω₀`: creeps back, with the rates `γ ∓ √(γ² − ω₀²)`.
    Overdamped,
}

/// Damped harmonic oscillator `m ẍ + c ẋ + k x = 0` from `x(0) = x₀`, `ẋ(0) = v₀`: returns
/// `(x(t), v(t))`.
///
/// With `γ = c/(2m)`, `ω₀² = k/m`, `B = v₀ + γ x₀` and
///
/// ```text
/// (C(t), S(t)) = (cos ω_d t, sin(ω_d t)/ω_d)      ω_d = √(ω₀² − γ²)   underdamped (γ < ω₀)
///              = (1, t)                                                 critical    (γ = ω₀)
///              = (cosh ω_d t, sinh(ω_d t)/ω_d)   ω_d = √(γ² − ω₀²)   overdamped  (γ > ω₀)
///
/// x(t) = e^{−γt} (x₀ C(t) + B S(t))
/// v(t) = e^{−γt} (v₀ C(t) − (ω₀² x₀ + γ v₀) S(t))
/// ```
///
/// (`v` is `ẋ`: differentiate `x` and use `Ċ = ∓ω_d² S`, `Ṡ = C`.) The three cases are one
/// formula in `ω_d² = ω₀² − γ²`, continuous through the critical case; `c = 0` is
/// [`harmonic_spring`]. Overdamped, `e^{−γt} cosh ω_d t` is evaluated as
/// `½(e^{−(γ−ω_d)t} + e^{−(γ+ω_d)t})` once `ω_d t > 1`, so a long horizon neither overflows nor
/// loses the slow mode.
///
/// Unchecked: a non-positive or non-finite `stiffness` or `mass`, or a negative or non-finite
/// `damping`, gives NaN. Use [`DampedSpring::new`] for a typed error instead.
pub fn damped_spring(
    x0: f64,
    v0: f64,
    stiffness: f64,
    damping: f64,
    mass: f64,
    t: f64,
) -> (f64, f64) {
    let w0_sq = stiffness / mass;
    let gamma = damping / (2.0 * mass);
    if !(w0_sq.is_finite() && w0_sq > 0.0 && gamma.is_finite() && gamma >= 0.0 && mass > 0.0) {
        return (f64::NAN, f64::NAN);
    }
    let b = v0 + gamma * x0;
    let slope = w0_sq * x0 + gamma * v0;
    let wd_sq = w0_sq - gamma * gamma;
    // `e^{−γt} C(t)` and `e^{−γt} S(t)`.
    let (ec, es) = if wd_sq > 0.0 {
        let wd = wd_sq.sqrt();
        let (s, c) = (wd * t).sin_cos();
        let e = (-gamma * t).exp();
        (e * c, e * s / wd)
    } else if wd_sq < 0.0 {
        let wd = (-wd_sq).sqrt();
        if (wd * t).abs() > 1.0 {
            let slow = (-(gamma - wd) * t).exp();
            let fast = (-(gamma + wd) * t).exp();
            (0.5 * (slow + fast), 0.5 * (slow - fast) / wd)
        } else {
            let e = (-gamma * t).exp();
            (e * (wd * t).cosh(), e * (wd * t).sinh() / wd)
        }
    } else {
        let e = (-gamma * t).exp();
        (e, e * t)
    };
    (x0 * ec + b * es, v0 * ec - slope * es)
}

/// The damped oscillator `m ẍ + c ẋ + k x = 0` from `(x₀, v₀)` at `t = 0`, validated once (see
/// [`damped_spring`] for the closed form).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DampedSpring {
    x0: f64,
    v0: f64,
    stiffness: f64,
    damping: f64,
    mass: f64,
}

impl DampedSpring {
    /// A spring of `stiffness` k (N/m) and `damping` c (N·s/m) carrying `mass` m (kg), released
    /// at `x0` with velocity `v0`. Fails unless `k` and `m` are finite and `> 0`, `c` is finite
    /// and `>= 0`, and `x0`, `v0` are finite.
    pub fn new(
        x0: f64,
        v0: f64,
        stiffness: f64,
        damping: f64,
        mass: f64,
    ) -> Result<Self, ExactError> {
        HarmonicSpring::new(x0, v0, stiffness, mass)?;
        if !(damping.is_finite() && damping >= 0.0) {
            return Err(ExactError::BadDamping(damping));
        }
        Ok(Self {
            x0,
            v0,
            stiffness,
            damping,
            mass,
        })
    }

    /// Undamped angular frequency `ω₀ = √(k/m)` (rad/s).
    pub fn natural_frequency(&self) -> f64 {
        (self.stiffness / self.mass).sqrt()
    }

    /// Damping ratio `ζ = γ/ω₀ = c / (2√(km))`: below 1 underdamped, 1 critical, above 1
    /// overdamped.
    pub fn damping_ratio(&self) -> f64 {
        self.damping / (2.0 * (self.stiffness * self.mass).sqrt())
    }

    /// Which of the three cases of [`damped_spring`] this is (exactly, as the formula decides
    /// it: by the sign of `ω₀² − γ²`).
    pub fn regime(&self) -> DampingRegime {
        let gamma = self.damping / (2.0 * self.mass);
        let wd_sq = self.stiffness / self.mass - gamma * gamma;
        if wd_sq > 0.0 {
            DampingRegime::Underdamped
        } else if wd_sq < 0.0 {
            DampingRegime::Overdamped
        } else {
            DampingRegime::Critical
        }
    }

    /// `(x(t), v(t))`, see [`damped_spring`].
    pub fn state(&self, t: f64) -> (f64, f64) {
        damped_spring(self.x0, self.v0, self.stiffness, self.damping, self.mass, t)
    }

    /// Mechanical energy `E(t) = ½ k x(t)² + ½ m v(t)²` (J); it decays as `Ė = −c v² ≤ 0`.
    pub fn energy(&self, t: f64) -> f64 {
        let (x, v) = self.state(t);
        0.5 * self.stiffness * x * x + 0.5 * self.mass * v * v
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

    #[test]
    fn damped_spring_satisfies_its_equation_in_every_regime() {
        let (k, m) = (4.0, 0.25); // ω₀ = 4 rad/s; critical at c = 2√(km) = 2
        for (c, regime) in [
            (0.3, DampingRegime::Underdamped),
            (1.999, DampingRegime::Underdamped),
            (2.0, DampingRegime::Critical),
            (2.001, DampingRegime::Overdamped),
            (9.0, DampingRegime::Overdamped),
        ] {
            let spring = DampedSpring::new(0.3, -0.5, k, c, m).unwrap();
            assert_eq!(spring.regime(), regime, "c = {c}");
            assert_eq!(spring.state(0.0), (0.3, -0.5));
            let mut previous = spring.energy(0.0);
            for i in 1..200 {
                let t = 0.02 * f64::from(i);
                let (x, v) = spring.state(t);
                // Central differences: truncation ≈ h² λ³|x|/6 for ẋ and h² λ⁴|x| m/6 for m ẍ,
                // λ = γ + |ω_d| ≤ 36 /s the fastest rate here: ≤ 2.5e-7 and 2e-6 at h = 1e-5;
                // round-off ≈ ε|x|/h ≈ 1e-11.
                let h = 1e-5;
                let (xp, vp) = spring.state(t + h);
                let (xm, vm) = spring.state(t - h);
                let dx = (xp - xm) / (2.0 * h);
                let acc = (vp - vm) / (2.0 * h);
                assert!((dx - v).abs() < 5e-7, "c={c} t={t}: ẋ {dx} vs v {v}");
                let residual = m * acc + c * v + k * x;
                assert!(residual.abs() < 4e-6, "c={c} t={t}: residual {residual:e}");
                // Ė = −c v² ≤ 0.
                let e = spring.energy(t);
                assert!(e <= previous * (1.0 + 1e-14), "c={c} t={t}: energy grew");
                previous = e;
            }
        }
    }

    #[test]
    fn damped_spring_limits() {
        let (x0, v0, k, m) = (0.3, 0.5, 4.0, 0.25);
        // c = 0 is the harmonic spring.
        for t in [0.1, 1.0, 7.3, -2.0] {
            let (x, v) = damped_spring(x0, v0, k, 0.0, m, t);
            let (xe, ve) = harmonic_spring(x0, v0, k, m, t);
            assert!((x - xe).abs() < 1e-14 && (v - ve).abs() < 1e-14, "t={t}");
        }
        // Continuous through the critical case, from both sides.
        for t in [0.05, 0.7, 3.0] {
            let critical = damped_spring(x0, v0, k, 2.0, m, t);
            for c in [2.0 - 1e-9, 2.0 + 1e-9] {
                let (x, v) = damped_spring(x0, v0, k, c, m, t);
                assert!((x - critical.0).abs() < 1e-8 && (v - critical.1).abs() < 1e-8);
            }
        }
        // Underdamped: the envelope e^{−γt} at whole damped periods (x returns to x₀ e^{−γT}
        // when v₀ = −γ x₀, i.e. B = 0).
        let (c, gamma) = (0.4, 0.8);
        let wd = (16.0_f64 - gamma * gamma).sqrt();
        let period = std::f64::consts::TAU / wd;
        let (x, _) = damped_spring(1.0, -gamma, k, c, m, 3.0 * period);
        assert!((x - (-gamma * 3.0 * period).exp()).abs() < 1e-13);
        // Strongly overdamped: the slow rate ω₀²/(2γ) dominates and nothing overflows at a far
        // horizon.
        let (x, v) = damped_spring(1.0, 0.0, k, 400.0, m, 2000.0);
        assert!(x.is_finite() && v.is_finite() && x > 0.0 && v < 0.0);
        let slow = 800.0 - (800.0_f64 * 800.0 - 16.0).sqrt();
        let (x1, _) = damped_spring(1.0, 0.0, k, 400.0, m, 1.0);
        let (x2, _) = damped_spring(1.0, 0.0, k, 400.0, m, 2.0);
        assert!(((x1 / x2).ln() - slow).abs() < 1e-9);
        // Validation.
        assert!(matches!(
            DampedSpring::new(1.0, 0.0, 1.0, -0.1, 1.0),
            Err(ExactError::BadDamping(_))
        ));
        assert!(DampedSpring::new(1.0, 0.0, 0.0, 0.1, 1.0).is_err());
        assert!(DampedSpring::new(1.0, 0.0, 1.0, f64::NAN, 1.0).is_err());
        assert!(damped_spring(1.0, 0.0, 1.0, -1.0, 1.0, 1.0).0.is_nan());
        let s = DampedSpring::new(1.0, 0.0, k, 0.5, m).unwrap();
        assert_eq!(s.natural_frequency(), 4.0);
        assert!((s.damping_ratio() - 0.25).abs() < 1e-15);
    }
}
