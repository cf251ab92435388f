//! The torque-free rigid body (Landau & Lifshitz, *Mechanics*, §§36–37).
//!
//! Principal moments are sorted `I₁ < I₂ < I₃` internally (any input order is accepted; the
//! sorted frame is kept right-handed by flipping its third axis when the permutation is odd).
//! Body rates `Ω`, body momentum `Mᵢ = IᵢΩᵢ`, `M² = ΣMᵢ²`, `2E = ΣIᵢΩᵢ²`. The three invariant
//! combinations are formed without cancellation from the rates:
//! `2EI₃ − M² = Σ IᵢΩᵢ²(I₃ − Iᵢ)`, `M² − 2EI₁ = Σ IᵢΩᵢ²(Iᵢ − I₁)`,
//! `M² − 2EI₂ = I₃Ω₃²(I₃ − I₂) − I₁Ω₁²(I₂ − I₁)`.
//!
//! **Rates, `M² > 2EI₂`** (the polhode circles the largest axis):
//!
//! ```text
//! Ω₁ = s₁ A₁ cn τ,   Ω₂ = s₁s₃ A₂ sn τ,   Ω₃ = s₃ A₃ dn τ,   τ = λt + τ₀,
//! A₁ = √((2EI₃ − M²)/(I₁(I₃ − I₁))),  A₂ = √((2EI₃ − M²)/(I₂(I₃ − I₂))),
//! A₃ = √((M² − 2EI₁)/(I₃(I₃ − I₁))),  λ = √((I₃ − I₂)(M² − 2EI₁)/(I₁I₂I₃)),
//! m = k² = (I₂ − I₁)(2EI₃ − M²)/((I₃ − I₂)(M² − 2EI₁)),
//! 1 − m = (I₃ − I₁)(M² − 2EI₂)/((I₃ − I₂)(M² − 2EI₁)),
//! ```
//!
//! with `s₁ = sign Ω₁(0)`, `s₃ = sign Ω₃(0)` (substituting into Euler's equations
//! `I₁Ω̇₁ = (I₂ − I₃)Ω₂Ω₃` etc. forces the sign of the `sn` coefficient to be `s₁s₃` for `λ > 0`,
//! so time runs forward). **`M² < 2EI₂`**: indices 1 and 3 swap roles: `Ω₁ = s₁A₁ dn τ`,
//! `Ω₂ = s₁s₃A₂ sn τ`, `Ω₃ = s₃A₃ cn τ` with `A₂ = √((M² − 2EI₁)/(I₂(I₂ − I₁)))`,
//! `λ = √((I₂ − I₁)(2EI₃ − M²)/(I₁I₂I₃))`, `m = (I₃ − I₂)(M² − 2EI₁)/((I₂ − I₁)(2EI₃ − M²))`.
//! Choosing the sign of the `cn` coefficient as the sign of that rate puts `cn τ₀ ≥ 0`, so the
//! phase is on the principal branch: `τ₀ = F(φ₀ | m)` with `sin φ₀ = sn τ₀ = Ω₂(0)/(s₁s₃A₂)` and
//! `cos φ₀ = cn τ₀ = |Ω_cn(0)|/A_cn`, evaluated from `(sin φ₀, cos φ₀)` directly
//! ([`incomplete_f_sin_cos`]) so that a small `cn τ₀` near the separatrix keeps its digits.
//!
//! **Separatrix** `M² = 2EI₂` (to within the round-off of the two terms of `M² − 2EI₂`, 8ε of
//! their magnitude): the `M² > 2EI₂` formulas at `m = 1`, `sn = tanh`, `cn = dn = sech`; the
//! middle-axis rate changes sign at most once (at `τ = 0`) and the body tends to the unstable
//! middle-axis spin.
//!
//! **Orientation.** With Z–X–Z Euler angles `(φ, θ, ψ)` of the body axes `(a, b, c) = (2, 3, 1)`
//! (right-handed; `c` is the axis of smallest moment) relative to a frame whose z axis is along
//! the constant `L`, so that the body→L-frame rotation is `Rz(φ) Rx(θ) Rz(ψ)`:
//! `θ = atan2(√(M_a² + M_b²), M_c)` (i.e. `cos θ = M_c/M`), `ψ = atan2(M_a, M_b)`
//! (`tan ψ = M_a/M_b`), and `φ̇ = M (M_a²/I_a + M_b²/I_b)/(M_a² + M_b²)`, which stays within
//! `[M/I₃, M/I₂]`. (Taking `c` as the axis the polhode circles also works, but when that is the
//! largest axis of a thin body, `φ̇` peaks at `M/I₁` over a sliver of the period that a fixed
//! quadrature misses: 2.9 rad of error for `I = (1e-4, 1, 1.02)`, `Ω₀ = (6, 0.8, 0.5)`. `M_b² +
//! M_c²` never vanishes off a steady spin, so the smallest axis works in both cases.)
//! `φ̇` has period `2K/λ`; its increment over one period is integrated once (composite 10-point
//! Gauss–Legendre, panels of `Δτ = ¼`, error far below 1e-14 relative since the integrand is
//! analytic in a strip of half-width ≳ 1 in `τ`), then `φ(t) = n Δφ + ∫₀^{t − nT} φ̇`, so every
//! horizon costs at most one period of quadrature. On the separatrix `φ̇ → M/I₂` exponentially
//! as `|τ| → ∞`, so `φ = Mt/I₂ + ∫(φ̇ − M/I₂)` over the window `|τ| ≤ 40` only. The constant
//! rotation L-frame → world is fixed so that `orientation(0) = q₀`.
//!
//! **Symmetric top** (two equal moments `I_⊥`, unique axis `ĉ` with moment `I_c`, or all three
//! equal): `Ω(t) = R(ĉ, νt) Ω₀` with `ν = (I_c − I_⊥) Ω₀·ĉ / I_⊥`, and
//! `q(t) = R(L̂, |L|t/I_⊥) q₀ R(ĉ, −νt)` (regular precession about the world `L`). Moments must be
//! exactly equal for this branch; any nonzero gap takes the elliptic solution, which stays valid
//! (if slow) as the gap shrinks.
//!
//! **Steady spin** (`Ω₀` along a principal axis, or zero): `Ω` constant,
//! `q(t) = R(q₀Ω₀, |Ω₀|t) q₀`.
//!
//! **Accuracy** (the tests below, against classic RK4 at `h = 1e-4` with a compensated update of
//! `L`): rates and orientation agree to ≲ 1e-13 over 10 s away from the separatrix, ≲ 5e-12 next
//! to it (`Ω₀ = (0.01, 10, 0.01)`, `I = (1, 2, 3)`, `1 − m ≈ 2e-6`), ≈ 1e-10 at 120 s there, and on the
//! separatrix itself ≲ 1e-13 over 3 s. `E` and the world `L` evaluated from the returned `Ω(t)`,
//! `q(t)` are constant to 1e-12 relative. Cost: `new` integrates one period by quadrature; a
//! rate is a few elliptic functions; an orientation at any horizon costs at most one period of
//! quadrature.
//! Horizons are limited only by `τ = λt + τ₀` and `φ` being f64: the orientation error grows
//! like `ε·φ(t)` (≈ 1e-11 rad at `t = 1e4 s`, `|Ω| = 10 rad/s`).

use std::f64::consts::{FRAC_PI_3, TAU};

use glam::{DMat3, DQuat, DVec3};

use super::{ExactError, ORIENTATION_TOLERANCE};
use tumble_core::elliptic::{
    complete_k_complement, incomplete_f_sin_cos, jacobi_sn_cn_dn_complement, sign,
};

/// 10-point Gauss–Legendre nodes on [−1, 1] (positive half) and their weights.
const GL_NODES: [f64; 5] = [
    0.148_874_338_981_631_2,
    0.433_395_394_129_247_2,
    0.679_409_568_299_024_4,
    0.865_063_366_688_984_5,
    0.973_906_528_517_171_7,
];
const GL_WEIGHTS: [f64; 5] = [
    0.295_524_224_714_752_9,
    0.269_266_719_309_996_3,
    0.219_086_362_515_982,
    0.149_451_349_150_580_6,
    0.066_671_344_308_688_1,
];

/// Half-width in `τ` of the window outside which `φ̇ − M/I₂` is below `e^{−80}` relative on the
/// separatrix (it decays like `sech² τ`).
const SEPARATRIX_WINDOW: f64 = 40.0;

/// Which closed form describes the motion.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TopMotion {
    /// Rotation about a principal axis at a constant rate (or rest): `Ω` constant.
    Steady,
    /// Two or three exactly equal moments: regular precession.
    Symmetric,
    /// `M² > 2EI₂`: the polhode circles the axis of largest moment.
    AboutLargest,
    /// `M² < 2EI₂`: the polhode circles the axis of smallest moment.
    AboutSmallest,
    /// `M² = 2EI₂` to round-off (and not the middle-axis equilibrium): the hyperbolic limit.
    Separatrix,
}

/// Data of the elliptic solution (asymmetric body, not a steady spin).
#[derive(Debug, Clone)]
struct Elliptic {
    /// Columns: the principal-frame directions of the sorted axes (a rotation matrix).
    sorted: DMat3,
    /// Sorted moments `I₁ < I₂ < I₃`.
    i: [f64; 3],
    /// `M² < 2EI₂`: axis 1 carries `dn`, axis 3 carries `cn`.
    about_smallest: bool,
    /// Signed coefficients of the rates along the sorted axes.
    coeff: [f64; 3],
    lambda: f64,
    m: f64,
    m1: f64,
    /// Quarter period `K(m)` (infinite on the separatrix).
    quarter: f64,
    tau0: f64,
    /// Euler-body `(a, b, c)` coordinates → principal coordinates.
    euler_frame: DQuat,
    /// L-aligned frame → world.
    world_from_l: DQuat,
    /// `|M|`.
    momentum: f64,
    /// Increment of `φ` over one period `2K/λ` of `φ̇`.
    phi_period: f64,
}

#[derive(Debug, Clone)]
enum Kind {
    Steady,
    Symmetric {
        /// Unique axis `ĉ` in the principal frame.
        axis: DVec3,
        /// Body-frame precession rate `ν` of `Ω` about `ĉ`.
        nu: f64,
        /// `I_⊥`.
        i_perp: f64,
    },
    Elliptic(Box<Elliptic>),
}

/// The exact torque-free motion of a rigid body from its principal moments, initial body rates
/// and initial orientation (see the [module docs](self) for every formula).
#[derive(Debug, Clone)]
pub struct TorqueFreeTop {
    inertia: DVec3,
    omega0: DVec3,
    q0: DQuat,
    motion: TopMotion,
    kind: Kind,
}

impl TorqueFreeTop {
    /// The motion from the principal moments `principal_inertia` (kg·m², any order, each finite
    /// and `> 0`), the body rates `body_omega0` (rad/s, principal frame, same order) and the
    /// orientation `q0` (principal frame → world: `world = q0 * body`), which must be a unit
    /// quaternion within [`ORIENTATION_TOLERANCE`]; it is renormalized.
    pub fn new(
        principal_inertia: DVec3,
        body_omega0: DVec3,
        q0: DQuat,
    ) -> Result<Self, ExactError> {
        let arr = principal_inertia.to_array();
        if !arr.iter().all(|x| x.is_finite() && *x > 0.0) {
            return Err(ExactError::BadInertia(arr));
        }
        if !body_omega0.is_finite() {
            return Err(ExactError::NonFinite("initial body angular velocity"));
        }
        if !q0.is_finite() {
            return Err(ExactError::NonFinite("initial orientation"));
        }
        let norm = q0.length();
        if (norm - 1.0).abs() > ORIENTATION_TOLERANCE {
            return Err(ExactError::NonUnitQuaternion(norm));
        }
        let q0 = q0 / norm;
        let mut top = Self {
            inertia: principal_inertia,
            omega0: body_omega0,
            q0,
            motion: TopMotion::Steady,
            kind: Kind::Steady,
        };

        // Symmetric (or spherical) body: exactly equal moments.
        let [ix, iy, iz] = arr;
        let unique = if ix == iy {
            Some(2)
        } else if iy == iz {
            Some(0)
        } else if ix == iz {
            Some(1)
        } else {
            None
        };
        if let Some(c) = unique {
            let axis = DVec3::AXES[c];
            let i_perp = arr[(c + 1) % 3];
            let nu = (arr[c] - i_perp) * body_omega0.dot(axis) / i_perp;
            top.motion = TopMotion::Symmetric;
            top.kind = Kind::Symmetric { axis, nu, i_perp };
            return Ok(top);
        }

        if let Some((elliptic, motion)) = Elliptic::new(arr, body_omega0, q0) {
            top.motion = motion;
            top.kind = Kind::Elliptic(Box::new(elliptic));
        }
        Ok(top)
    }

    /// Which closed form describes this motion.
    pub fn motion(&self) -> TopMotion {
        self.motion
    }

    /// The elliptic parameter `m = k²` (0 for steady and symmetric motion, 1 on the separatrix).
    pub fn parameter(&self) -> f64 {
        match &self.kind {
            Kind::Elliptic(e) => e.m,
            _ => 0.0,
        }
    }

    /// The phase rate `λ` of `τ = λt + τ₀` (rad/s; 0 for steady and symmetric motion).
    pub fn phase_rate(&self) -> f64 {
        match &self.kind {
            Kind::Elliptic(e) => e.lambda,
            _ => 0.0,
        }
    }

    /// Body angular velocity `Ω(t)` (rad/s) in the principal frame, in the order of the moments
    /// given to [`new`](Self::new): the `sn, cn, dn` forms of the module docs (or the symmetric /
    /// steady closed forms). Valid for negative `t` too.
    pub fn body_angular_velocity(&self, t: f64) -> DVec3 {
        match &self.kind {
            Kind::Steady => self.omega0,
            Kind::Symmetric { axis, nu, .. } => DQuat::from_axis_angle(*axis, nu * t) * self.omega0,
            Kind::Elliptic(e) => e.sorted * e.sorted_rates(t),
        }
    }

    /// Orientation `q(t)` (principal frame → world) with `q(0) = q₀`: `R_{L→world} Rz(φ) Rx(θ)
    /// Rz(ψ)` composed with the fixed relabelling of the body axes (module docs), or the
    /// symmetric / steady closed forms. Valid for negative `t` too.
    pub fn orientation(&self, t: f64) -> DQuat {
        match &self.kind {
            Kind::Steady => DQuat::from_scaled_axis(self.q0 * self.omega0 * t) * self.q0,
            Kind::Symmetric { axis, nu, i_perp } => {
                let precession =
                    DQuat::from_scaled_axis(self.angular_momentum_world() * t / i_perp);
                precession * self.q0 * DQuat::from_axis_angle(*axis, -nu * t)
            }
            Kind::Elliptic(e) => e.orientation(t),
        }
        .normalize()
    }

    /// Time between sign changes of the middle-axis rate, `2K(k)/λ` (s); infinite for steady,
    /// symmetric and separatrix motion.
    pub fn flip_interval(&self) -> f64 {
        match &self.kind {
            Kind::Elliptic(e) => 2.0 * e.quarter / e.lambda,
            _ => f64::INFINITY,
        }
    }

    /// Period of the body rates (s): `4K(k)/λ` for the asymmetric body, `2π/|ν|` for the
    /// symmetric top; infinite for steady spins and on the separatrix.
    pub fn period(&self) -> f64 {
        match &self.kind {
            Kind::Elliptic(e) => 4.0 * e.quarter / e.lambda,
            Kind::Symmetric { nu, .. } => TAU / nu.abs(),
            Kind::Steady => f64::INFINITY,
        }
    }

    /// Exact number of sign changes of the middle-axis rate `Ω₂ ∝ sn τ` in `(0, t_end]`: the
    /// zeros `τ = 2jK` between `τ₀` (excluded) and `τ₀ + λ t_end` (included),
    /// `⌊(τ₀ + λt_end)/2K⌋ − ⌊τ₀/2K⌋`. Zero for `t_end ≤ 0` and for steady and symmetric motion
    /// (no distinct middle axis, or no flips); at most one on the separatrix.
    pub fn middle_axis_sign_changes(&self, t_end: f64) -> u64 {
        let Kind::Elliptic(e) = &self.kind else {
            return 0;
        };
        if t_end.is_nan() || t_end <= 0.0 {
            return 0;
        }
        let end = e.tau0 + e.lambda * t_end;
        if !e.quarter.is_finite() {
            return u64::from(e.tau0 < 0.0 && end >= 0.0);
        }
        let half = 2.0 * e.quarter;
        ((end / half).floor() - (e.tau0 / half).floor()).max(0.0) as u64
    }

    /// Kinetic energy `E = ½ Σ IᵢΩᵢ²` (J), constant.
    pub fn energy(&self) -> f64 {
        0.5 * self.omega0.dot(self.inertia * self.omega0)
    }

    /// Angular momentum in the world, `L = q₀ (I Ω₀)` (kg·m²/s), constant.
    pub fn angular_momentum_world(&self) -> DVec3 {
        self.q0 * (self.inertia * self.omega0)
    }
}

impl Elliptic {
    /// The elliptic solution for distinct principal moments `arr` (body frame), initial body
    /// rates `body_omega0` and unit orientation `q0`, with the motion it describes; `None` for a
    /// steady spin about a principal axis (no elliptic motion).
    fn new(arr: [f64; 3], body_omega0: DVec3, q0: DQuat) -> Option<(Self, TopMotion)> {
        let mut order = [0usize, 1, 2];
        order.sort_by(|&a, &b| arr[a].total_cmp(&arr[b]));
        let i = [arr[order[0]], arr[order[1]], arr[order[2]]];
        let axis = |k: usize| DVec3::AXES[order[k]];
        let handed = axis(0).cross(axis(1)).dot(axis(2));
        let sorted = DMat3::from_cols(axis(0), axis(1), axis(2) * handed);
        let w = (sorted.transpose() * body_omega0).to_array();

        // Cancellation-free invariant combinations.
        let t = [i[0] * w[0] * w[0], i[1] * w[1] * w[1], i[2] * w[2] * w[2]];
        let m_plus = t[0] * (i[2] - i[0]) + t[1] * (i[2] - i[1]); // 2EI₃ − M²
        let m_minus = t[1] * (i[1] - i[0]) + t[2] * (i[2] - i[0]); // M² − 2EI₁
        let (d_up, d_down) = (t[2] * (i[2] - i[1]), t[0] * (i[1] - i[0]));
        let d = d_up - d_down; // M² − 2EI₂
        if m_plus == 0.0 || m_minus == 0.0 || (w[0] == 0.0 && w[2] == 0.0) {
            return None;
        }
        let separatrix = d.abs() <= 8.0 * f64::EPSILON * (d_up + d_down);
        let (i1, i2, i3) = (i[0], i[1], i[2]);
        let momentum = (0..3)
            .map(|k| i[k] * w[k])
            .fold(0.0f64, |acc, x| acc.hypot(x));

        // The two cases (momentum about the largest or the smallest axis) are one formula with
        // the roles of `(M² − 2EI₁, I₃ − I₂)` and `(2EI₃ − M², I₂ − I₁)` exchanged.
        let about_smallest = !(d > 0.0 || separatrix);
        let (a, gap_a, b, gap_b, d_signed) = if about_smallest {
            (m_plus, i2 - i1, m_minus, i3 - i2, -d)
        } else {
            (m_minus, i3 - i2, m_plus, i2 - i1, d)
        };
        let (s1, s3) = (sign(w[0]), sign(w[2]));
        let coeff = [
            s1 * (m_plus / (i1 * (i3 - i1))).sqrt(),
            s1 * s3 * (b / (i2 * gap_a)).sqrt(),
            s3 * (m_minus / (i3 * (i3 - i1))).sqrt(),
        ];
        let lambda = (gap_a * a / (i1 * i2 * i3)).sqrt();
        let (m, m1) = if separatrix {
            (1.0, 0.0)
        } else {
            (gap_b * b / (gap_a * a), (i3 - i1) * d_signed / (gap_a * a))
        };
        // Euler axes (a, b, c) = sorted (2, 3, 1) in both cases: the cyclic relabelling
        // x → y → z → x is the rotation by 120° about (1, 1, 1).
        let cyclic = DQuat::from_axis_angle(DVec3::ONE.normalize(), 2.0 * FRAC_PI_3);
        let euler_frame = DQuat::from_mat3(&sorted) * cyclic;
        let cn_axis = if about_smallest { 2 } else { 0 };
        let sn0 = w[1] / coeff[1];
        let cn0 = w[cn_axis] / coeff[cn_axis];
        let tau0 = incomplete_f_sin_cos(sn0, cn0, m, m1);
        let quarter = complete_k_complement(m1);
        let mut elliptic = Elliptic {
            sorted,
            i,
            about_smallest,
            coeff,
            lambda,
            m,
            m1,
            quarter,
            tau0,
            euler_frame,
            world_from_l: DQuat::IDENTITY,
            momentum,
            phi_period: 0.0,
        };
        elliptic.world_from_l = q0 * euler_frame * elliptic.euler_rotation(0.0, 0.0).inverse();
        if quarter.is_finite() {
            let period = 2.0 * quarter / lambda;
            elliptic.phi_period = elliptic.integrate(0.0, period, |t| elliptic.phi_rate(t));
        }
        let motion = if separatrix {
            TopMotion::Separatrix
        } else if about_smallest {
            TopMotion::AboutSmallest
        } else {
            TopMotion::AboutLargest
        };
        Some((elliptic, motion))
    }

    /// `(sn τ, cn τ, dn τ)` at time `t`.
    fn jacobi(&self, t: f64) -> (f64, f64, f64) {
        jacobi_sn_cn_dn_complement(self.lambda * t + self.tau0, self.m, self.m1)
    }

    /// Body rates along the sorted axes at time `t`.
    fn sorted_rates(&self, t: f64) -> DVec3 {
        let (sn, cn, dn) = self.jacobi(t);
        let c = self.coeff;
        if self.about_smallest {
            DVec3::new(c[0] * dn, c[1] * sn, c[2] * cn)
        } else {
            DVec3::new(c[0] * cn, c[1] * sn, c[2] * dn)
        }
    }

    /// Body momentum in Euler coordinates `(M_a, M_b, M_c)` and the moments `(I_a, I_b)`.
    fn euler_momentum(&self, t: f64) -> (DVec3, f64, f64) {
        let w = self.sorted_rates(t);
        let m = DVec3::new(self.i[0] * w.x, self.i[1] * w.y, self.i[2] * w.z);
        (DVec3::new(m.y, m.z, m.x), self.i[1], self.i[2])
    }

    /// `φ̇ = M (M_a²/I_a + M_b²/I_b)/(M_a² + M_b²)`, with `(M_a, M_b)` normalized first so tiny
    /// nutation amplitudes cannot underflow.
    fn phi_rate(&self, t: f64) -> f64 {
        let (m, ia, ib) = self.euler_momentum(t);
        let h = m.x.hypot(m.y);
        let (x, y) = (m.x / h, m.y / h);
        self.momentum * (x * x / ia + y * y / ib)
    }

    /// `∫ f dt` over `[t0, t1]` (either order) by composite 10-point Gauss–Legendre with panels
    /// no longer than `1/(4λ)`, i.e. `Δτ ≤ ¼`.
    fn integrate(&self, t0: f64, t1: f64, f: impl Fn(f64) -> f64) -> f64 {
        let length = t1 - t0;
        if length == 0.0 {
            return 0.0;
        }
        let panels = (length.abs() * self.lambda * 4.0).ceil().clamp(1.0, 1e8) as usize;
        let h = length / panels as f64;
        let mut sum = 0.0;
        for p in 0..panels {
            let mid = t0 + (p as f64 + 0.5) * h;
            let mut panel = 0.0;
            for (x, w) in GL_NODES.iter().zip(GL_WEIGHTS) {
                panel += w * (f(mid - 0.5 * h * x) + f(mid + 0.5 * h * x));
            }
            sum += panel;
        }
        0.5 * h * sum
    }

    /// `φ(t) = ∫₀ᵗ φ̇`, by whole periods plus a remainder, or on the separatrix as the asymptotic
    /// rate plus the decaying part over the window `|τ| ≤ 40`.
    fn phi(&self, t: f64) -> f64 {
        if self.quarter.is_finite() {
            let period = 2.0 * self.quarter / self.lambda;
            let n = (t / period).floor();
            let rest = t - n * period;
            n * self.phi_period + self.integrate(0.0, rest, |s| self.phi_rate(s))
        } else {
            let asymptote = self.momentum / self.i[1];
            let lo = (-SEPARATRIX_WINDOW - self.tau0) / self.lambda;
            let hi = (SEPARATRIX_WINDOW - self.tau0) / self.lambda;
            let (a, b) = (t.min(0.0).max(lo), t.max(0.0).min(hi));
            let excess = if a < b {
                self.integrate(a, b, |s| self.phi_rate(s) - asymptote)
            } else {
                0.0
            };
            // ∫₀ᵗ = −∫ over [t, 0] for negative t.
            asymptote * t + if t < 0.0 { -excess } else { excess }
        }
    }

    /// `Rz(φ) Rx(θ) Rz(ψ)`: Euler-body coordinates → L-aligned frame, with `θ, ψ` from the body
    /// momentum at time `t`.
    fn euler_rotation(&self, t: f64, phi: f64) -> DQuat {
        let (m, _, _) = self.euler_momentum(t);
        let theta = m.x.hypot(m.y).atan2(m.z);
        let psi = m.x.atan2(m.y);
        DQuat::from_rotation_z(phi) * DQuat::from_rotation_x(theta) * DQuat::from_rotation_z(psi)
    }

    fn orientation(&self, t: f64) -> DQuat {
        self.world_from_l * self.euler_rotation(t, self.phi(t)) * self.euler_frame.inverse()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::EulerRot;

    /// Classic RK4 on `q̇ = ½ q ⊗ (0, Ω)`, `L̇_b = L_b × Ω`, `Ω = I⁻¹L_b` (body frame), step
    /// `|h| ≤ 1e-4`, from `(q0, Ω0)` to each of the `times` in turn (any sign). Returns `(q, Ω)`.
    ///
    /// Its error: local `O((|Ω|h)⁵)`, so at `|Ω| ≤ 11 rad/s` and `h = 1e-4` the global error over
    /// 10 s is ~1e-13 (measured by halving h); round-off over 1e5 steps adds ~1e-14.
    fn rk4(inertia: DVec3, omega0: DVec3, q0: DQuat, times: &[f64]) -> Vec<(DQuat, DVec3)> {
        rk4_step(inertia, omega0, q0, times, 1e-4)
    }

    fn rk4_step(
        inertia: DVec3,
        omega0: DVec3,
        q0: DQuat,
        times: &[f64],
        step: f64,
    ) -> Vec<(DQuat, DVec3)> {
        let rate = |q: DQuat, l: DVec3| {
            let w = l / inertia;
            (q * DQuat::from_xyzw(w.x, w.y, w.z, 0.0) * 0.5, l.cross(w))
        };
        let (mut q, mut l, mut t) = (q0, inertia * omega0, 0.0);
        let mut carry = DVec3::ZERO;
        times
            .iter()
            .map(|&target| {
                let steps = ((target - t).abs() / step).ceil() as usize;
                let h = if steps == 0 {
                    0.0
                } else {
                    (target - t) / steps as f64
                };
                for _ in 0..steps {
                    let (next, dl) = crate::rk4::step(q, l, h, rate);
                    q = next;
                    // Compensated (Kahan) update of L_b: near the separatrix the motion depends
                    // on M² − 2EI₂, a small difference of large invariants, so plain round-off
                    // of 1e-16 per step would random-walk it far beyond the truncation error.
                    let delta = dl - carry;
                    let sum = l + delta;
                    carry = (sum - l) - delta;
                    l = sum;
                }
                t = target;
                (q, l / inertia)
            })
            .collect()
    }

    /// Rotation angle between two unit quaternions, `2 atan2(|v|, |w|)` of `a⁻¹b` (accurate for
    /// tiny angles, unlike `2 acos |⟨a, b⟩|`).
    fn angle(a: DQuat, b: DQuat) -> f64 {
        let r = a.conjugate() * b;
        2.0 * DVec3::new(r.x, r.y, r.z).length().atan2(r.w.abs())
    }

    /// Worst relative rate error and worst orientation angle against RK4 at `times`; also checks
    /// the invariants of the returned state (`E` and world `L` to 1e-12 relative: both are
    /// evaluated from the elliptic rates and the orientation, whose errors are ~1e-14).
    fn compare(inertia: DVec3, omega0: DVec3, q0: DQuat, times: &[f64]) -> (f64, f64) {
        let top = TorqueFreeTop::new(inertia, omega0, q0).unwrap();
        let (l0, e0) = (top.angular_momentum_world(), top.energy());
        let mut worst: (f64, f64) = (0.0, 0.0);
        for (&t, &(q_ref, w_ref)) in times.iter().zip(&rk4(inertia, omega0, q0, times)) {
            let w = top.body_angular_velocity(t);
            let q = top.orientation(t);
            let (dw, dq) = ((w - w_ref).length() / w_ref.length(), angle(q, q_ref));
            worst = (worst.0.max(dw), worst.1.max(dq));
            let l = q * (inertia * w);
            assert!(
                (l - l0).length() < 1e-12 * l0.length(),
                "{inertia} {omega0} t={t}: L {l} vs {l0}"
            );
            let e = 0.5 * w.dot(inertia * w);
            assert!((e / e0 - 1.0).abs() < 1e-12, "{inertia} {omega0} t={t}: E");
        }
        worst
    }

    /// Asserts agreement with RK4 to `tolerance` (relative rates, radians) at 0…10 s.
    fn check(inertia: DVec3, omega0: DVec3, q0: DQuat, tolerance: f64) -> (f64, f64) {
        let times = [0.0, 0.37, 1.0, 2.5, 4.0, 5.5, 7.25, 8.8, 10.0];
        check_at(inertia, omega0, q0, tolerance, &times)
    }

    /// [`check`] at the given times.
    fn check_at(
        inertia: DVec3,
        omega0: DVec3,
        q0: DQuat,
        tolerance: f64,
        times: &[f64],
    ) -> (f64, f64) {
        let (dw, dq) = compare(inertia, omega0, q0, times);
        eprintln!("I={inertia} ω0={omega0}: rates {dw:.1e}, orientation {dq:.1e} rad");
        assert!(
            dw < tolerance && dq < tolerance,
            "I={inertia} ω0={omega0}: rates {dw:e}, orientation {dq:e}"
        );
        (dw, dq)
    }

    fn tilted() -> DQuat {
        DQuat::from_euler(EulerRot::XYZ, 0.3, -0.8, 1.9)
    }

    // Tolerance of the RK4 comparisons: 1e-8 (rates relative, orientation in radians). Both
    // solutions are good to ~1e-13 over 10 s away from the separatrix (measured agreement
    // ≲ 1e-11 there); near it the flow stretches errors by up to 1/√(1 − m) ≈ 700 for
    // ω0 = (0.01, 10, 0.01), which still leaves a factor > 10 of margin. A sign or phase
    // mistake gives O(1) errors.
    const TOL: f64 = 1e-8;

    #[test]
    fn matches_rk4_about_the_largest_axis() {
        let i = DVec3::new(1.0, 2.0, 3.0);
        let top = TorqueFreeTop::new(i, DVec3::new(1.0, 5.0, 1.0), DQuat::IDENTITY).unwrap();
        assert_eq!(top.motion(), TopMotion::AboutLargest);
        check(i, DVec3::new(1.0, 5.0, 1.0), DQuat::IDENTITY, TOL);
        check(i, DVec3::new(0.01, 10.0, 0.01), DQuat::IDENTITY, TOL);
        check(i, DVec3::new(0.3, -0.7, 1.2), tilted(), TOL);
        check(i, DVec3::new(-0.3, -0.7, -1.2), tilted(), TOL);
        check(i, DVec3::new(0.2, 0.3, -3.0), tilted(), TOL);
        check(i, DVec3::new(-1.0, 5.0, -1.0), tilted(), TOL);
    }

    #[test]
    fn a_thin_asymmetric_body_circling_its_largest_axis_matches_rk4() {
        // φ̇ about the largest axis would peak at M/I₁ = 1e4 M for a sliver of the period;
        // about the smallest axis it stays within [M/I₃, M/I₂] (module docs).
        let i = DVec3::new(1e-4, 1.0, 1.02);
        let omega0 = DVec3::new(6.0, 0.8, 0.5);
        let top = TorqueFreeTop::new(i, omega0, tilted()).unwrap();
        assert_eq!(top.motion(), TopMotion::AboutLargest);
        check(i, omega0, tilted(), TOL);
    }

    #[test]
    fn matches_rk4_about_the_smallest_axis() {
        let i = DVec3::new(1.0, 2.0, 3.0);
        let top = TorqueFreeTop::new(i, DVec3::new(2.0, 0.4, -0.3), DQuat::IDENTITY).unwrap();
        assert_eq!(top.motion(), TopMotion::AboutSmallest);
        check(i, DVec3::new(2.0, 0.4, -0.3), tilted(), TOL);
        check(i, DVec3::new(-2.0, 0.4, 0.3), DQuat::IDENTITY, TOL);
        check(i, DVec3::new(-2.0, -3.0, -0.3), tilted(), TOL);
        // Just below the separatrix: M² − 2EI₂ = −9e-4 + 3e-4 < 0.
        let near = DVec3::new(0.03, 10.0, 0.01);
        assert_eq!(
            TorqueFreeTop::new(i, near, DQuat::IDENTITY)
                .unwrap()
                .motion(),
            TopMotion::AboutSmallest
        );
        check(i, near, tilted(), TOL);
        check(i, DVec3::new(0.03, -10.0, -0.01), tilted(), TOL);
    }

    #[test]
    fn matches_rk4_for_any_order_of_the_moments() {
        // Odd permutations flip the handedness of the sorted frame.
        check(
            DVec3::new(3.0, 1.0, 2.0),
            DVec3::new(0.5, 1.0, -2.0),
            tilted(),
            TOL,
        );
        check(
            DVec3::new(2.0, 1.0, 3.0),
            DVec3::new(1.0, 0.2, 0.6),
            DQuat::IDENTITY,
            TOL,
        );
        check(
            DVec3::new(3.0, 2.0, 1.0),
            DVec3::new(1.0, 5.0, 1.0),
            tilted(),
            TOL,
        );
        check(
            DVec3::new(0.2, 0.05, 0.11),
            DVec3::new(-3.0, 0.7, 2.0),
            tilted(),
            TOL,
        );
    }

    #[test]
    fn matches_rk4_backwards_in_time() {
        let times = [-0.5, -3.0, -7.5];
        for (i, w) in [
            (DVec3::new(1.0, 2.0, 3.0), DVec3::new(1.0, 5.0, 1.0)),
            (DVec3::new(1.0, 2.0, 3.0), DVec3::new(2.0, 0.4, -0.3)),
            (DVec3::new(1.0, 5.0, 9.0), DVec3::new(3.0, 0.4, 1.0)),
        ] {
            let (dw, dq) = compare(i, w, tilted(), &times);
            eprintln!("backwards I={i} ω0={w}: rates {dw:.1e}, orientation {dq:.1e}");
            assert!(dw < TOL && dq < TOL, "backwards {w}: {dw:e} {dq:e}");
        }
    }

    #[test]
    fn separatrix_matches_rk4() {
        // I = (1, 5, 9), Ω₁ = 3Ω₃: M² − 2EI₂ = I₃Ω₃²(I₃ − I₂) − I₁Ω₁²(I₂ − I₁) = 36 − 36 = 0
        // exactly. λ ≈ 2.9 rad/s; the reference leaves the separatrix through its own
        // round-off, which grows like e^{λt}, so compare over 3 s (e^{8.6} ≈ 5e3: 1e-13 → 5e-10).
        let i = DVec3::new(1.0, 5.0, 9.0);
        let times = [0.0, 0.2, 0.7, 1.5, 2.2, 3.0];
        for w in [
            DVec3::new(3.0, 1.0, 1.0),
            DVec3::new(-3.0, 1.0, 1.0),
            DVec3::new(3.0, -2.0, -1.0),
            DVec3::new(-3.0, 0.1, -1.0),
        ] {
            let top = TorqueFreeTop::new(i, w, tilted()).unwrap();
            assert_eq!(top.motion(), TopMotion::Separatrix);
            assert_eq!(top.parameter(), 1.0);
            assert_eq!(top.flip_interval(), f64::INFINITY);
            let (dw, dq) = compare(i, w, tilted(), &times);
            eprintln!("separatrix ω0={w}: rates {dw:.1e}, orientation {dq:.1e}");
            assert!(dw < TOL && dq < TOL, "separatrix {w}: {dw:e} {dq:e}");
            // Ω₂ ∝ tanh τ: one sign change iff τ₀ < 0, i.e. Ω₂(0) has the sign opposite to
            // s₁s₃ = sign(Ω₁Ω₃); backwards the same sign change is not counted.
            let expected = u64::from(w.y * w.x * w.z < 0.0);
            assert_eq!(top.middle_axis_sign_changes(50.0), expected, "{w}");
            // The body approaches the middle-axis spin: Ω₂ → ±A₂,
            // A₂² = (2EI₃ − M²)/(I₂(I₃ − I₂)) = (8·9 + 4·5Ω₂²)/20 here.
            let late = top.body_angular_velocity(30.0);
            let a2 = ((72.0 + 20.0 * w.y * w.y) / 20.0f64).sqrt();
            assert!((late.y.abs() - a2).abs() < 1e-12, "{late} vs {a2}");
            assert!(late.x.abs() < 1e-30 && late.z.abs() < 1e-30);
            // Long horizon: still consistent with L (θ, ψ exact; φ by the asymptote).
            let q = top.orientation(1e4);
            let l = q * (i * top.body_angular_velocity(1e4));
            assert!((l - top.angular_momentum_world()).length() < 1e-12 * l.length());
        }
    }

    #[test]
    fn near_degenerate_inputs_match_rk4() {
        let i = DVec3::new(1.0, 2.0, 3.0);
        // Almost a steady spin about the largest / smallest axis (m ≈ 1e-17): the
        // cancellation-free invariants keep the 1e-8 wobble.
        check(i, DVec3::new(1e-8, 0.0, 2.0), tilted(), TOL);
        check(i, DVec3::new(3.0, 1e-9, 0.0), tilted(), TOL);
        // Almost the middle-axis equilibrium: 1 − m = 1e-26 is not representable next to m, but
        // the complement is kept to full accuracy. λ ≈ 5.8 rad/s: the 1e-12 wobble grows to a
        // full flip at t ≈ 5.4 s and the body returns to within 1e-10 of the equilibrium at
        // t ≈ 10.8 s. Only up to 8 s: beyond, the reference's own round-off (1e-16 of |L| in
        // components of size 1e-10) dominates — RK4 at h = 1e-4 and 5e-5 then disagree by 3e-8.
        check_at(
            i,
            DVec3::new(1e-12, 10.0, 0.0),
            tilted(),
            TOL,
            &[0.0, 1.0, 2.5, 4.0, 5.0, 5.4, 6.0, 7.0, 8.0],
        );
        // Nearly symmetric body (gap 1e-9 relative): the elliptic solution still applies.
        check(
            DVec3::new(1.0, 1.0 + 1e-9, 2.0),
            DVec3::new(0.4, -0.3, 1.0),
            tilted(),
            TOL,
        );
        check(
            DVec3::new(1.0, 2.0, 2.0 + 1e-9),
            DVec3::new(0.4, -0.3, 1.0),
            tilted(),
            TOL,
        );
    }

    #[test]
    fn symmetric_and_steady_motion_match_rk4() {
        for (i, w) in [
            (DVec3::new(1.0, 1.0, 2.0), DVec3::new(0.4, -0.3, 1.0)),
            (DVec3::new(2.0, 1.0, 1.0), DVec3::new(0.4, -0.3, 1.0)),
            (DVec3::new(1.5, 0.5, 1.5), DVec3::new(0.4, 2.0, -1.0)),
            (DVec3::new(2.0, 2.0, 2.0), DVec3::new(0.4, -0.3, 1.0)),
        ] {
            let top = TorqueFreeTop::new(i, w, tilted()).unwrap();
            assert_eq!(top.motion(), TopMotion::Symmetric);
            assert_eq!(top.middle_axis_sign_changes(100.0), 0);
            check(i, w, tilted(), TOL);
        }
        let i = DVec3::new(1.0, 2.0, 3.0);
        for w in [
            DVec3::new(0.0, 0.0, 4.0),
            DVec3::new(-3.0, 0.0, 0.0),
            DVec3::new(0.0, 2.0, 0.0),
        ] {
            let top = TorqueFreeTop::new(i, w, tilted()).unwrap();
            assert_eq!(top.motion(), TopMotion::Steady);
            assert_eq!(top.body_angular_velocity(3.0), w);
            assert_eq!(top.middle_axis_sign_changes(100.0), 0);
            check(i, w, tilted(), TOL);
        }
        let rest = TorqueFreeTop::new(i, DVec3::ZERO, tilted()).unwrap();
        assert!(angle(rest.orientation(5.0), tilted()) < 1e-15);
        let spin = TorqueFreeTop::new(i, DVec3::new(0.0, 0.0, 4.0), DQuat::IDENTITY).unwrap();
        assert!(angle(spin.orientation(0.5), DQuat::from_rotation_z(2.0)) < 1e-14);
    }

    #[test]
    fn reproduces_the_known_flip_counts() {
        let i = DVec3::new(1.0, 2.0, 3.0);
        let top = TorqueFreeTop::new(i, DVec3::new(1.0, 5.0, 1.0), DQuat::IDENTITY).unwrap();
        eprintln!("ω0 = (1, 5, 1): flip interval {:.6} s", top.flip_interval());
        assert!((top.flip_interval() - 1.792).abs() < 5e-4);
        assert_eq!(top.period(), 2.0 * top.flip_interval());
        assert_eq!(top.middle_axis_sign_changes(120.0), 67);
        let near = TorqueFreeTop::new(i, DVec3::new(0.01, 10.0, 0.01), DQuat::IDENTITY).unwrap();
        assert_eq!(near.middle_axis_sign_changes(120.0), 44);
        // The counts agree with sign changes sampled from the solution itself (1 ms sampling
        // cannot miss a flip: they are ≥ 1.7 s apart), for several initial conditions and in
        // both regimes; and the rates repeat after one period.
        for (w, horizon) in [
            (DVec3::new(1.0, 5.0, 1.0), 120.0),
            (DVec3::new(0.01, 10.0, 0.01), 120.0),
            (DVec3::new(0.3, -0.7, 1.2), 60.0),
            (DVec3::new(2.0, 0.4, -0.3), 60.0),
            (DVec3::new(0.03, -10.0, -0.01), 60.0),
        ] {
            let top = TorqueFreeTop::new(i, w, DQuat::IDENTITY).unwrap();
            let mut sampled = 0;
            let mut previous = w.y;
            for n in 1..=(horizon * 1000.0) as u32 {
                let y = top.body_angular_velocity(f64::from(n) * 1e-3).y;
                if y * previous < 0.0 || (previous == 0.0 && y != 0.0 && n > 1) {
                    sampled += 1;
                }
                if y != 0.0 {
                    previous = y;
                }
            }
            assert_eq!(top.middle_axis_sign_changes(horizon), sampled, "{w}");
            for t in [0.0, 0.9, 3.3] {
                let d = top.body_angular_velocity(t + top.period()) - top.body_angular_velocity(t);
                assert!(d.length() < 1e-12 * w.length(), "{w}: period");
            }
        }
        assert_eq!(top.middle_axis_sign_changes(0.0), 0);
        assert_eq!(top.middle_axis_sign_changes(-5.0), 0);
    }

    #[test]
    fn long_horizons_use_the_period_consistently() {
        // φ from whole periods plus a remainder must equal φ integrated straight through, and the
        // orientation must keep the body momentum on the world L, at 120 s and 1e4 s.
        let i = DVec3::new(1.0, 2.0, 3.0);
        for w in [
            DVec3::new(1.0, 5.0, 1.0),
            DVec3::new(0.01, 10.0, 0.01),
            DVec3::new(2.0, 0.4, -0.3),
        ] {
            let top = TorqueFreeTop::new(i, w, tilted()).unwrap();
            let Kind::Elliptic(e) = &top.kind else {
                panic!("elliptic expected");
            };
            for t in [120.0, -37.5] {
                let straight = e.integrate(0.0, t, |s| e.phi_rate(s));
                let periodic = e.phi(t);
                eprintln!(
                    "ω0={w} t={t}: φ periodic − straight = {:.1e}",
                    periodic - straight
                );
                assert!(
                    (periodic - straight).abs() < 1e-11 * straight.abs(),
                    "{w} t={t}"
                );
            }
            for t in [120.0, 1e4] {
                let q = top.orientation(t);
                let l = q * (i * top.body_angular_velocity(t));
                let l0 = top.angular_momentum_world();
                assert!((l - l0).length() < 1e-12 * l0.length(), "{w} t={t}");
                assert!((q.length() - 1.0).abs() < 1e-15);
            }
            // 120 s against the RK4 reference (1.2e6 steps; its error grows to ~1e-11).
            let (dw, dq) = compare(i, w, tilted(), &[60.0, 120.0]);
            eprintln!("ω0={w} at 120 s: rates {dw:.1e}, orientation {dq:.1e}");
            assert!(dw < 1e-7 && dq < 1e-7, "{w}: {dw:e} {dq:e}");
        }
    }

    #[test]
    fn rejects_bad_input() {
        let i = DVec3::new(1.0, 2.0, 3.0);
        let q = DQuat::IDENTITY;
        assert!(matches!(
            TorqueFreeTop::new(DVec3::new(1.0, -1.0, 2.0), DVec3::ONE, q),
            Err(ExactError::BadInertia(_))
        ));
        assert!(TorqueFreeTop::new(DVec3::new(1.0, 0.0, 2.0), DVec3::ONE, q).is_err());
        assert!(TorqueFreeTop::new(DVec3::new(1.0, f64::INFINITY, 2.0), DVec3::ONE, q).is_err());
        assert!(matches!(
            TorqueFreeTop::new(i, DVec3::NAN, q),
            Err(ExactError::NonFinite(_))
        ));
        assert!(matches!(
            TorqueFreeTop::new(i, DVec3::ONE, DQuat::from_xyzw(0.0, 0.0, 0.0, 1.1)),
            Err(ExactError::NonUnitQuaternion(_))
        ));
        assert!(TorqueFreeTop::new(i, DVec3::ONE, DQuat::NAN).is_err());
        // f32-accurate unit quaternions are accepted and renormalized.
        let q32 = DQuat::from_xyzw(0.0, 0.0, 0.0, 1.0 + 1e-7);
        let top = TorqueFreeTop::new(i, DVec3::ONE, q32).unwrap();
        // Renormalized: the identity to the round-off of the frame changes (a few ε).
        let offset = top.orientation(0.0) - DQuat::IDENTITY;
        assert!(offset.length() < 4.0 * f64::EPSILON, "{offset}");
    }
}
