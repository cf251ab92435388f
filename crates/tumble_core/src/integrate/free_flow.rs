//! Which free rotation a split method gives a body: its own split flow, or the exact flow where
//! the split errs.
//!
//! `splitting` (and `splitting-xyz`, and `yoshida4`, a composition of it) integrate the
//! torque-free body as an exact symmetric top `S` plus a residual rotation `R` about axis `c`
//! (`b, c` the principal axes with the closest reciprocal moments `r = 1/I`, `a` the odd one).
//! The Strang composition errs where `S` and `R` do not commute: per step the odd axis's rate
//! is off by a relative
//!
//! ```text
//! e = h² |ω_b ω_c| |I_b − I_c| / I_a
//! ```
//!
//! and the orientation error over `T` seconds measures ≈ `0.4–0.7 e T/s` rad on plates and
//! needles (f32, `I = (0.01, 1, 1.01)`, `(1e-4, 1, 1.0001)`, `(0.1, 1, 1.1)`, `(0.3, 1, 1.3)` at
//! 1–10 rad/s, 60 and 240 Hz). The `exact` flow has no such error at any spin.
//!
//! That per-step error is a poor guide to what a run loses: on compact bodies it mostly
//! averages out, on elongated ones it accumulates. Measured in `f64` against `exact` over 10 s
//! (13 inertias from rods `(1e-4, 1, 1.0001)` and plates `(0.01, 1, 1.01)` to boxes and
//! near-spheres, `|ω|Δt` from 0.003 to 3, random axes, 30, 60 and 240 Hz), the orientation
//! error of `splitting` stays below
//!
//! ```text
//! D = 2 (1 − ρ)² e_orbit ω_E T,     ρ = I_min / I_mid,     ω_E = √(2E / I_mid),
//! e_orbit = h² |I_b − I_c| / I_a · min(E / √(I_b I_c), |L|² / (2 I_b I_c))
//! ```
//!
//! in 1817 of 1820 cases of five sweeps (the other three, all far above any tolerance, within
//! a factor of 2.4). `e_orbit` bounds `e` over the whole torque-free orbit (`|ω_b ω_c|` by the
//! kinetic energy `E` and by `|L|²`), and `ω_E` is the rate scale of the energy: both are kept
//! by the free flow, so the choice does not flicker as the body tumbles, and the two halves of
//! a drift–kick–drift stage choose alike. `(1 − ρ)²` is the elongation: a rod or a narrow plate
//! loses 20–40 times what a box does at the same `e`.
//!
//! Under [`FreeFlow::Auto`] (the default of a world) `splitting` and `splitting-xyz` check `D`
//! for every body at every stage, from the state they are about to step, and give a body whose
//! `D` over [`ACCURACY_HORIZON`] exceeds [`SPLIT_DRIFT_TOLERANCE`] — about what storing the
//! state costs `exact` itself in the build's precision — the exact free flow instead
//! ([`Integrator::exact_counterpart`]: `exact`): the same drift–kick–drift step, forces sampled
//! at the same points, only the free rotation exact. `yoshida4` cancels the split's error to
//! fourth order while `e` is small, so it switches to `exact4` where `e_orbit` of its largest
//! stage (`|c₀| h ≈ 1.70 h`) exceeds [`COMPOSED_SPLIT_ERROR_LIMIT`]. A body on springs that turn
//! it at `ω_turn` keeps the split where their own error per step, `(ω_turn h)³/24`, outweighs the
//! split's, `e_orbit |ω| h` ([`ExactSwitch::applies_turned`]). A body that spins slowly never
//! pays for the check beyond `|ω|²` (`e_orbit ≤ 0.75 h² |ω|²` and `ω_E ≤ √2 |ω|`, so
//! `D ≤ 2.2 h² |ω|³ T`: `|I_b − I_c| ≤ I_a`, `I_max ≤ √2 √(I_b I_c)` and `I_max ≤ 2 I_mid`
//! follow from the triangle inequality every [`MassProperties`] satisfies). The choice
//! is a pure function of the state in `f64`, so it is the same on every kernel path, thread
//! count and replay. [`FreeFlow::Method`] keeps every body on the method's own flow (to
//! measure the method itself).

use glam::DVec3;

use super::Integrator;
use super::frame::{principal_orientation, rotate64};
use crate::mass::MassProperties;
use crate::math::{Real, Widen};
use crate::state::BodyState;

/// The span over which a method's accuracy is judged (s): the drift `D` of the module docs, and
/// the planner's accuracy warnings.
pub const ACCURACY_HORIZON: Real = 10.0;

/// Orientation drift over [`ACCURACY_HORIZON`] (rad) the split free rotation may cost a body
/// before [`FreeFlow::Auto`] gives it the exact flow: about what rounding the stored state
/// costs `exact` itself (`f32`: 1e-4 on boxes, 4e-4 on plates, 1e-2 on rods over 10 s; `f64`:
/// 1e-8). In `f32` a box (I = (1, 2, 3)) switches above ≈ 1.2 rad/s at 60 Hz, a narrow plate
/// (0.01, 1, 1.01) above ≈ 0.8 rad/s; in `f64` above ≈ 0.26 and 0.17 rad/s.
pub const SPLIT_DRIFT_TOLERANCE: Real = if crate::math::DOUBLE_PRECISION {
    1e-5
} else {
    1e-3
};

/// Relative error per step of the odd axis's rate under the split free rotation, `e` (module
/// docs), above which the planner warns under [`FreeFlow::Method`]: 1 % a step, an orientation
/// drift of about 5e-3 rad/s on a thin body. An ordinary box (I = (1, 2, 3)) reaches it at
/// ≈ 6 rad/s about two axes at 60 Hz.
pub const SPLIT_ERROR_LIMIT: Real = 1e-2;

/// `e` on `yoshida4`'s largest stage (`|c₀| h ≈ 1.70 h` of the triple jump) above which a body
/// takes the exact free flow (`exact4`) under [`FreeFlow::Auto`], and the planner warns under
/// [`FreeFlow::Method`]. The composition cancels the
/// split's error to fourth order only while it is small: measured over 10 s (f32, I at the
/// triangle limit), 7.7 % per stage gives 1e-3–5e-3 rad, 31 % gives 0.04–0.2 rad.
pub const COMPOSED_SPLIT_ERROR_LIMIT: Real = 0.15;

/// Which free rotation a split method (`splitting`, `splitting-xyz`, `yoshida4`) gives each body
/// (module docs). Methods that are not split (`exact`, `rk4`, the first-order ones) ignore it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(rename_all = "lowercase")
)]
pub enum FreeFlow {
    /// The exact free flow for a body while the split's error per step exceeds its limit, the
    /// method's own split flow otherwise.
    #[default]
    Auto,
    /// The method's own free flow for every body, however fast it spins (the planner warns of
    /// bodies above the limit).
    Method,
}

impl FreeFlow {
    /// Every setting, in declaration order.
    pub const ALL: [FreeFlow; 2] = [FreeFlow::Auto, FreeFlow::Method];

    /// The name used in scene files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            FreeFlow::Auto => "auto",
            FreeFlow::Method => "method",
        }
    }
}

impl std::fmt::Display for FreeFlow {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for FreeFlow {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        FreeFlow::ALL
            .into_iter()
            .find(|m| m.name() == s)
            .ok_or_else(|| "expected one of `auto`, `method`".to_owned())
    }
}

/// The principal axes of the split: `a` the odd one, `(b, c)` the pair with the closest
/// reciprocal moments; `None` for a locked axis (its rates are held: no split error).
fn split_axes(i: [f64; 3]) -> Option<(usize, usize, usize)> {
    if i.iter().any(|&x| x.is_nan() || x <= 0.0) {
        return None;
    }
    let r = i.map(|x| 1.0 / x);
    let a = (0..3)
        .min_by(|&x, &y| {
            let gap = |k: usize| (r[(k + 1) % 3] - r[(k + 2) % 3]).abs();
            gap(x).total_cmp(&gap(y))
        })
        .unwrap_or(0);
    Some((a, (a + 1) % 3, (a + 2) % 3))
}

/// `h² |ω_b ω_c| |I_b − I_c| / I_a` of the split free rotation (module docs) for principal
/// moments `inertia` and principal rates `omega`. Zero for a body with a locked axis.
pub fn split_rotation_error(inertia: DVec3, omega: DVec3, h: f64) -> f64 {
    let (i, w) = (inertia.to_array(), omega.to_array());
    let Some((a, b, c)) = split_axes(i) else {
        return 0.0;
    };
    h * h * (w[b] * w[c]).abs() * (i[b] - i[c]).abs() / i[a]
}

/// `D`, the orientation drift (rad) the split free rotation predicts over `horizon` seconds
/// for a body with principal moments `inertia` turning at principal rates `omega`, steps of
/// `h` (module docs). Zero for a body with a locked axis.
pub fn split_rotation_drift(inertia: DVec3, omega: DVec3, h: f64, horizon: f64) -> f64 {
    drift_of_orbit_error(
        inertia,
        omega,
        split_orbit_error(inertia, omega, h),
        horizon,
    )
}

/// `D` over `horizon` from the body's `e_orbit` ([`split_orbit_error`]), see
/// [`split_rotation_drift`].
fn drift_of_orbit_error(inertia: DVec3, omega: DVec3, e_orbit: f64, horizon: f64) -> f64 {
    match OrbitTerms::of(inertia, omega) {
        Some(terms) => terms.drift(inertia, e_orbit, horizon),
        None => 0.0,
    }
}

/// `e_orbit`, the bound of [`split_rotation_error`] over the body's whole torque-free orbit:
/// `|ω_b ω_c|` bounded by `E/√(I_b I_c)` and by `|L|²/(2 I_b I_c)` (module docs). Zero for a
/// body with a locked axis.
pub fn split_orbit_error(inertia: DVec3, omega: DVec3, h: f64) -> f64 {
    OrbitTerms::of(inertia, omega).map_or(0.0, |terms| terms.orbit_error(inertia, omega, h))
}

/// What `e_orbit` and `D` share for one body: its split axes and its kinetic energy, formed
/// once when the switch judges both.
#[derive(Clone, Copy)]
struct OrbitTerms {
    /// The split axes (`a` the odd one, see [`split_axes`]).
    axes: (usize, usize, usize),
    /// `E = ½ Σ I ω²`.
    energy: f64,
}

impl OrbitTerms {
    /// `None` for a body with a locked axis (no split error).
    #[inline]
    fn of(inertia: DVec3, omega: DVec3) -> Option<Self> {
        Some(Self {
            axes: split_axes(inertia.to_array())?,
            energy: 0.5 * (inertia * omega * omega).element_sum(),
        })
    }

    /// `e_orbit` ([`split_orbit_error`]).
    #[inline]
    fn orbit_error(self, inertia: DVec3, omega: DVec3, h: f64) -> f64 {
        let (i, (a, b, c)) = (inertia.to_array(), self.axes);
        let momentum2 = (inertia * omega).length_squared();
        let bc = i[b] * i[c];
        let orbit = (self.energy / bc.sqrt()).min(momentum2 / (2.0 * bc));
        h * h * (i[b] - i[c]).abs() / i[a] * orbit
    }

    /// `D` over `horizon` from `e_orbit` ([`drift_of_orbit_error`]).
    #[inline]
    fn drift(self, inertia: DVec3, e_orbit: f64, horizon: f64) -> f64 {
        let mut sorted = inertia.to_array();
        sorted.sort_by(f64::total_cmp);
        let elongation = 1.0 - sorted[0] / sorted[1];
        let rate = (2.0 * self.energy / sorted[1]).sqrt();
        DRIFT_FACTOR * elongation * elongation * e_orbit * rate * horizon
    }
}

/// The constant of `D` (module docs).
const DRIFT_FACTOR: f64 = 2.0;

/// How a split method is judged for the switch.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Rule {
    /// `D` over [`ACCURACY_HORIZON`] against [`SPLIT_DRIFT_TOLERANCE`] (`splitting`,
    /// `splitting-xyz`).
    Drift,
    /// `e_orbit` of the largest stage against [`COMPOSED_SPLIT_ERROR_LIMIT`] (`yoshida4`).
    StageError,
}

/// A split method's switch to its exact counterpart for the bodies it would integrate badly
/// ([`FreeFlow::Auto`], module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ExactSwitch {
    exact: Integrator,
    rule: Rule,
    /// The span the split is judged on (s): the (largest) stage of a substep.
    span: f64,
    limit: f64,
    /// `|ω|²` at or below which the body is inside the limit whatever its inertia (module
    /// docs), less a margin for the triangle inequality's slack and the rounding of `|ω|²`.
    quick: Real,
}

/// `|ω|² / ω_turn²` at or below which a body's springs outweigh its split whatever its inertia
/// (see [`ExactSwitch::applies_turned`]): `e_orbit ≤ 0.75 h² |ω|²` (module docs), so
/// `e_orbit |ω| ≤ ω_turn³ h²/24` holds wherever `|ω|³ ≤ ω_turn³/18`, i.e.
/// `|ω|² ≤ ω_turn² / 18^{2/3}` (`18^{2/3} = 6.86828…`, rounded up); less a margin for the
/// rounding of `|ω|²` and `ω_turn²`.
const TURN_BOUND: Real = (1.0 / 6.8683) / (1.0 + 1e-3);

/// `|ω|²` of the body, the one number both cheap tests of the switch read.
#[inline(always)]
fn rate_squared(state: &BodyState) -> Real {
    let w = state.angular_velocity;
    // A fixed order of operations: the same bits on every path.
    w.x * w.x + w.y * w.y + w.z * w.z
}

/// False when the body's springs turn it fast enough that the switch cannot apply to it
/// (`w2 = |ω|²` against `ω_turn²`, [`TURN_BOUND`]): the second cheap test of
/// [`ExactSwitch::applies_turned`], which spares a swinging chain link the full judgement.
#[inline(always)]
fn spins_past_turn_bound(w2: Real, turn_rate: Real) -> bool {
    w2 > TURN_BOUND * (turn_rate * turn_rate)
}

impl ExactSwitch {
    /// The switch of `integrator` with substeps of `substep` (s) under `free_flow`; `None` when
    /// every body keeps the method's flow (a method that is not split, or
    /// [`FreeFlow::Method`]).
    pub fn new(integrator: Integrator, free_flow: FreeFlow, substep: Real) -> Option<Self> {
        if free_flow == FreeFlow::Method {
            return None;
        }
        let exact = integrator.exact_counterpart()?;
        let largest = integrator
            .composition()
            .iter()
            .fold(0.0, |m: Real, c| m.max(c.abs()));
        let span = (largest * substep).widen();
        // Far above the rounding of `|ω|²` in either precision.
        let margin = 1.0 + 1e-3;
        let (rule, limit, quick) = if integrator.composition().len() == 1 {
            // D ≤ 2.2 h² |ω|³ T (module docs).
            let limit = SPLIT_DRIFT_TOLERANCE.widen();
            let cube = limit / (2.2 * span * span * ACCURACY_HORIZON.widen());
            (Rule::Drift, limit, cube.powf(2.0 / 3.0) / margin)
        } else {
            // e_orbit ≤ 0.75 h² |ω|² (module docs): inside the limit for |ω|² ≤ limit / (0.75 h²).
            let limit = COMPOSED_SPLIT_ERROR_LIMIT.widen();
            (
                Rule::StageError,
                limit,
                limit / (0.75 * span * span) / margin,
            )
        };
        Some(Self {
            exact,
            rule,
            span,
            limit,
            quick: quick as Real,
        })
    }

    /// The method a body takes when the switch applies to it.
    pub fn exact(&self) -> Integrator {
        self.exact
    }

    /// The limit the switch judges by: [`SPLIT_DRIFT_TOLERANCE`] (rad over
    /// [`ACCURACY_HORIZON`]) for a method of one stage, [`COMPOSED_SPLIT_ERROR_LIMIT`] (per
    /// stage) for a composition.
    pub fn limit(&self) -> f64 {
        self.limit
    }

    /// True when the split would cost this body more than the limit (module docs), from its
    /// state and mass. Cheap unless it spins fast: one `|ω|²`.
    #[inline(always)]
    pub fn applies(&self, state: &BodyState, mass: &MassProperties) -> bool {
        // A copy: a reference would escape into the cold call and keep the caller's state out
        // of registers on the hot path. A NaN rate fails the quick bound: the method's own step
        // takes it and reports it.
        self.spins_past_quick_bound(rate_squared(state)) && self.exceeds(*state, mass)
    }

    /// [`applies`](Self::applies) for a body its springs can turn at up to `turn_rate` (rad/s;
    /// 0 without springs): the switch is also left off where the springs' own error outweighs
    /// the split's. Drift–kick–drift errs on a spring turning the body at `ω_turn` by about
    /// `(ω_turn h)³/24` rad per step (position Verlet's phase error), the split free rotation by
    /// `e_orbit |ω| h` (its relative rate error on the orbit, times the turn of a step): where
    /// `e_orbit |ω| ≤ ω_turn³ h²/24` on the largest stage `h`, the exact flow would cost a
    /// sevenfold step and change nothing the springs do not swamp (a chain link swinging on
    /// its springs). A pure function of the state, like the rest of the switch.
    #[inline(always)]
    pub fn applies_turned(
        &self,
        state: &BodyState,
        mass: &MassProperties,
        turn_rate: Real,
    ) -> bool {
        if turn_rate == 0.0 {
            return self.applies(state, mass);
        }
        let w2 = rate_squared(state);
        self.spins_past_quick_bound(w2)
            && spins_past_turn_bound(w2, turn_rate)
            && self.exceeds_turned(*state, mass, turn_rate)
    }

    /// The split costs more than the limit and more than the springs' error (see
    /// [`applies_turned`](Self::applies_turned)), from one `e_orbit`, out of line.
    #[cold]
    #[inline(never)]
    fn exceeds_turned(&self, state: BodyState, mass: &MassProperties, turn_rate: Real) -> bool {
        let (measure, e_orbit, omega) = self.judge(&state, mass);
        let turn = turn_rate.widen();
        measure > self.limit
            && e_orbit * omega.length() > turn * turn * turn * self.span * self.span / 24.0
    }

    /// False when the body spins too slowly for the switch to apply to it whatever its inertia
    /// and springs (`w2 = |ω|²`): the first, cheap test of [`applies`](Self::applies) and
    /// [`applies_turned`](Self::applies_turned).
    #[inline(always)]
    fn spins_past_quick_bound(&self, w2: Real) -> bool {
        w2 > self.quick
    }

    /// `measure > limit`, out of line.
    #[cold]
    #[inline(never)]
    fn exceeds(&self, state: BodyState, mass: &MassProperties) -> bool {
        self.measure(&state, mass) > self.limit
    }

    /// What the switch compares with [`limit`](Self::limit): the predicted drift `D` (rad over
    /// [`ACCURACY_HORIZON`]) or the largest stage's `e_orbit` (module docs).
    #[cold]
    pub fn measure(&self, state: &BodyState, mass: &MassProperties) -> f64 {
        self.judge(state, mass).0
    }

    /// [`measure`](Self::measure), with the `e_orbit` it was formed from and the principal
    /// rates `ω`.
    fn judge(&self, state: &BodyState, mass: &MassProperties) -> (f64, f64, DVec3) {
        let principal = principal_orientation(state, mass).widen();
        let omega = rotate64(principal.conjugate(), state.angular_velocity.widen());
        let inertia = mass.principal_inertia().widen();
        let Some(terms) = OrbitTerms::of(inertia, omega) else {
            return (0.0, 0.0, omega);
        };
        let e_orbit = terms.orbit_error(inertia, omega, self.span);
        let measure = match self.rule {
            Rule::Drift => terms.drift(inertia, e_orbit, ACCURACY_HORIZON.widen()),
            Rule::StageError => e_orbit,
        };
        (measure, e_orbit, omega)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mass::Mass;
    use crate::math::{Quat, Vec3};

    /// A deterministic stream of numbers in `[0, 1)`.
    fn uniform(seed: &mut u64) -> f64 {
        *seed = seed
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (*seed >> 11) as f64 / (1u64 << 53) as f64
    }

    /// The two cheap tests never pass over a body the full judgement would switch: below the
    /// quick bound the measure is within the limit, and below the turn bound the springs'
    /// error outweighs the split's. Bodies from rods and plates at the triangle limit to
    /// near-spheres, rates just under each bound (where the bounds are tight), random axes.
    #[test]
    fn the_cheap_bounds_never_skip_a_body_the_judgement_would_switch() {
        let mut seed = 7;
        let shapes = [
            [1e-4, 1.0, 1.0001],
            [0.01, 1.0, 1.01],
            [0.5, 0.5, 1.0],
            [1.0, 2.0, 3.0],
            [1.0, 1.0, 1.9999],
            [0.9, 1.0, 1.1],
            // At the triangle limit with `|I_b − I_c| = I_a`: the tightest case of both bounds.
            [1.0, 1.5, 2.5],
        ];
        for integrator in [Integrator::Splitting, Integrator::Yoshida4] {
            for dt in [1.0 / 240.0, 1.0 / 60.0, 0.05] {
                let switch = ExactSwitch::new(integrator, FreeFlow::Auto, dt).unwrap();
                for _ in 0..4000 {
                    let shape = shapes[(uniform(&mut seed) * shapes.len() as f64) as usize];
                    let inertia = Vec3::new(shape[0], shape[1], shape[2]) as Vec3;
                    let mass = MassProperties::new(Mass::new(1.0).unwrap(), inertia)
                        .unwrap()
                        .with_principal_frame(Quat::from_rotation_x(uniform(&mut seed) as Real))
                        .unwrap();
                    let axis = Vec3::new(
                        uniform(&mut seed) as Real - 0.5,
                        uniform(&mut seed) as Real - 0.5,
                        uniform(&mut seed) as Real - 0.5,
                    )
                    .normalize();
                    let turn = (0.1 + 40.0 * uniform(&mut seed)) as Real;
                    let below = 1.0 - 1e-4 * uniform(&mut seed);
                    let rotation = Quat::from_rotation_y(uniform(&mut seed) as Real);
                    // Just under the quick bound.
                    let quick = (switch.quick.widen() * below).sqrt() as Real;
                    let state = BodyState {
                        rotation,
                        angular_velocity: axis * quick,
                        ..BodyState::default()
                    };
                    if !switch.spins_past_quick_bound(rate_squared(&state)) {
                        let measure = switch.measure(&state, &mass);
                        assert!(measure <= switch.limit(), "{measure} at {state:?}");
                    }
                    // Just under the turn bound.
                    let rate = (TURN_BOUND.widen() * below).sqrt() * turn.widen();
                    let state = BodyState {
                        angular_velocity: axis * rate as Real,
                        ..state
                    };
                    if !spins_past_turn_bound(rate_squared(&state), turn) {
                        let (_, e_orbit, omega) = switch.judge(&state, &mass);
                        let springs = turn.widen().powi(3) * switch.span * switch.span / 24.0;
                        assert!(e_orbit * omega.length() <= springs, "{state:?}");
                    }
                }
            }
        }
    }
}
