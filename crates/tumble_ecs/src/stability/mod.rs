//! Predicting, when a schedule is planned, the settings that leave the selected integrator's
//! stable region, so a game hears about it before the body blows up (the integrate systems still
//! catch an actual divergence and quarantine the body).
//!
//! Every limit is stated for one plain step; `Δt` below is the span of the plain step with the
//! same stability limit as one substep of the world's step (see [`crate::integrate`]): `Δt/N` with
//! `N` substeps, `1.27 Δt/N` for `yoshida4`'s composition (a triple jump keeps a linear spring
//! bounded up to `ωh = 1.5734` per substep, against 2 for one plain step).
//!
//! Two mechanisms matter for free bodies and springs:
//!
//! - **Springs** stepped explicitly (see [`crate::springs`]: by default only soft spring groups
//!   are; the implicit spring step is stable at any stiffness and never warned about). Every
//!   method here advances positions with a symplectic kick–drift or
//!   drift–kick–drift update, whose harmonic oscillator is stable iff `ω Δt < 2`, `ω = √(k/μ)`
//!   with `μ` the reduced mass of the two ends (the body's mass for a world anchor). Damping is
//!   ignored: it is a separate flow that only shrinks velocities, at any `cΔt`
//!   ([`crate::springs`]).
//! - **Explicit gyroscopic term** (`symplectic-euler`, `symplectic-euler-linear`). About a
//!   principal axis `i` the torque-free motion nutates at `Ω² = ω² (I_j − I_i)(I_k − I_i)/(I_j I_k)`;
//!   forward Euler multiplies each such oscillation by `√(1 + Ω²Δt²)` per step, a growth rate of
//!   `Ω²Δt/2` per second. Round-off (1e-7) reaches order one after `t* = 2 ln(10⁷)/(Ω²Δt)`
//!   (≈ 32/(Ω²Δt)): I = (1, 2, 3) at 20 rad/s and 60 Hz gives 4.8 s (measured: 3.5 s). A warning
//!   is raised when `t*` is shorter than [`EXPLICIT_GYROSCOPIC_HORIZON`].
//!
//! Bodies in stiff spring groups are stepped by the implicit spring solve ([`crate::springs`]):
//! translation and springs implicit, rotation by the selected method or by the implicit
//! midpoint. None of the method's stability checks below applies to them (the predictor never
//! refuses a method for a body it would not step); one [`StabilityWarning::ImplicitGroups`]
//! says how many there are and how many turn by the midpoint now, and a first-order method,
//! which cannot be combined with the implicit solve, gets one
//! [`StabilityWarning::CannotCombine`] instead: a refusal.
//!
//! One limit of the default method's accuracy (not its stability), which the step itself
//! takes care of by default:
//!
//! - **Split free rotation.** `splitting`, `splitting-xyz` and `yoshida4` split the torque-free
//!   rotation into an exact symmetric top and a residual rotation, which errs per step by a
//!   relative `e = Δt² |ω_b ω_c| |I_b − I_c| / I_a` in the odd axis's rate (see
//!   [`tumble_core::integrate::FreeFlow`] for the derivation and measurements). Under
//!   [`FreeFlow::Auto`] (the default) a body above [`SPLIT_ERROR_LIMIT`]
//!   ([`COMPOSED_SPLIT_ERROR_LIMIT`] on `yoshida4`'s largest stage) takes the exact free flow
//!   in that stage, and one [`StabilityWarning::ExactFreeFlow`] names the bodies that do at
//!   planning time; under [`FreeFlow::Method`] each such body is warned of
//!   ([`StabilityWarning::InexactFreeRotation`]): the run goes on (the motion stays bounded,
//!   `|L|` exact), with an accuracy limit like the ones below.
//!
//! - **First-order gyroscopic term** (`lclamp`, `implicit-gyroscopic`). Stable, but each step
//!   errs in the rate by `∝ (Ω h)²` (`Ω` the nutation frequency above), and the error accumulates:
//!   over `T` the orientation drifts by `≈ c |ω| Ω² h T²` ([`first_order_drift`]; box
//!   I = (1, 2, 3) at 1 rad/s and 60 Hz: 0.03–0.07 rad in 10 s, where `splitting` is 2e-5). A
//!   warning naming `splitting` and `exact` is raised when the drift over [`ACCURACY_HORIZON`]
//!   exceeds [`FIRST_ORDER_DRIFT_LIMIT`].
//!
//! - **`rk4` at constant `L`** integrates `q̇ = ½ ω(q) q` with `ω(q) = R I⁻¹ Rᵀ L`. A trial
//!   orientation off the true path by `δ` tilts `L` into the body's thinnest axis and spins it
//!   at `|L| δ / I_min`: the equation is stiff with rate `|L|/I_min`, the spin the body would
//!   have with all of `L` on that axis, however slowly it really turns. Explicit RK4 is accurate
//!   only while `|L| Δt / I_min` is well inside its stable interval: measured over 10 s at 60 Hz,
//!   0.2 → 5e-5 rad, 0.6 → 0.15 rad, 1.0 → 3 rad (box I = (1, 2, 3)); a rod I = (1e-4, 1, 1) has
//!   `|L|Δt/I_min` = 110 already at 2 rad/s and is 0.3 rad off, and 2–3 rad at 18 rad/s
//!   (`splitting`: 1e-5 to 2e-4 rad). A warning naming `splitting` and `exact` is raised above
//!   [`RK4_STIFFNESS_LIMIT`].
//!
//! And two limits of the precision, not of the method:
//!
//! - **Positions far from the origin.** A stored coordinate `r` is rounded to the spacing of
//!   the precision there, at most `r ε` (`ε` = 1.2e-7 in `f32`). A body whose origin moves
//!   `s Δt` per step (`s = |v| + |ω| |R c| + |g s_g| Δt`: translation, the origin's swing about an
//!   off-centre centre of mass, one step of gravity) loses up to `½ r ε` of it every step, a
//!   relative error `r ε / (2 s Δt)` that does not shrink with time and *grows* as `Δt`
//!   shrinks. A warning is raised when it exceeds [`POSITION_RESOLUTION_LIMIT`] (in `f32`:
//!   1 m/s at 60 Hz from about 280 m out); the cure is the `f64` feature.
//! - **Fast spins about an axis of small moment.** The angular velocity is stored in world
//!   coordinates, each component rounded to at most `½ ε |ω|`, so the angular momentum it
//!   stands for, `L = I ω`, is off by up to `I_max ε |ω|` after every step that writes it: a
//!   relative error `I_max ε |ω| / |L|` that is at most `ε I_max / I_min`, so only a lopsided
//!   body spinning about its small axis reaches [`ANGULAR_RESOLUTION_LIMIT`] (in `f32`, a rod
//!   with `I = (1, 1, 10⁻⁶)` spinning at 10⁵ rad/s about its axis: 0.8 %). `|L|` and the energy
//!   then wander by that much every step, whatever the method; the cure is the `f64` feature.

use bevy_ecs::prelude::*;
use tumble_core::Integrator;
use tumble_core::integrate::{ExactSwitch, FreeFlow};
use tumble_core::math::{Narrow, Real, Vec3, Widen};

use crate::components::{
    Gravity, GravityScale, Kinematic, MassProps, PhysicsSettings, Pose, RigidBody, Static,
    Velocity, body_state,
};
use crate::components::{ImplicitBody, SpringTurn};
use crate::components::{Spring, SpringEnd};

/// `ω Δt` above which the symplectic position update of a spring diverges.
pub const SPRING_LIMIT: Real = 2.0;

/// Bodies whose explicit gyroscopic step would amplify round-off to order one within this many
/// seconds are reported (s).
pub const EXPLICIT_GYROSCOPIC_HORIZON: Real = 600.0;

/// Largest relative error `r ε / (2 s Δt)` of one step's motion, from position rounding, that
/// passes without a warning.
pub const POSITION_RESOLUTION_LIMIT: Real = 1e-3;

/// Largest relative error `I_max ε |ω| / |L|` of a body's angular momentum, from the rounding
/// of its stored angular velocity in one step, that passes without a warning.
pub const ANGULAR_RESOLUTION_LIMIT: Real = 1e-3;

pub use tumble_core::integrate::{
    ACCURACY_HORIZON, COMPOSED_SPLIT_ERROR_LIMIT, SPLIT_DRIFT_TOLERANCE, SPLIT_ERROR_LIMIT,
};

/// `|L| Δt / I_min` above which `rk4`'s constant-`L` rotation goes wrong (module docs).
pub const RK4_STIFFNESS_LIMIT: Real = 0.5;

/// Orientation error over [`ACCURACY_HORIZON`] (rad) above which a first-order gyroscopic method
/// (`lclamp`, `implicit-gyroscopic`) is warned of (module docs).
pub const FIRST_ORDER_DRIFT_LIMIT: Real = 0.02;

/// Smallest rate about a locked axis, relative to `|ω|`, that [`check_stability`] reports: below
/// it the rate is the rounding of a rotation written with a few digits, not a spin.
pub const LOCKED_RATE_LIMIT: Real = 1e-5;

mod warning;

pub use warning::StabilityWarning;

/// Squared nutation frequency per unit `|ω|²`, largest over the principal axes:
/// `max_i |(I_j − I_i)(I_k − I_i)| / (I_j I_k)`.
fn nutation_factor(inertia: Vec3) -> Real {
    let i = inertia.to_array();
    (0..3)
        .map(|a| {
            let (b, c) = ((a + 1) % 3, (a + 2) % 3);
            if i[b] > 0.0 && i[c] > 0.0 {
                ((i[b] - i[a]) * (i[c] - i[a])).abs() / (i[b] * i[c])
            } else {
                0.0
            }
        })
        .fold(0.0, Real::max)
}

pub use tumble_core::integrate::split_rotation_error;

/// The orientation drift over [`ACCURACY_HORIZON`] `T` (rad) of a first-order gyroscopic method
/// on a body with principal moments `inertia` spinning at `omega`, with steps of `h`:
/// `c |ω| Ω² h T²`, `Ω² = |ω|² ·` the nutation factor (module docs), from a relative error of
/// `c' (Ω h)²` in the rate per step that accumulates over `T/h` steps and then in the angle.
/// `c` as measured over 10 s on boxes, plates, rods and near-symmetric bodies at 0.5–32 rad/s,
/// 60 and 240 Hz (f32): 0.03 for `lclamp`, 0.06 for `implicit-gyroscopic`, the upper ends of
/// their scatter. `None` for a method without a first-order gyroscopic term.
pub fn first_order_drift(
    integrator: Integrator,
    inertia: Vec3,
    omega: Vec3,
    h: Real,
) -> Option<Real> {
    let c = match integrator {
        Integrator::Lclamp => 0.03,
        Integrator::ImplicitGyroscopic => 0.06,
        _ => return None,
    };
    let nutation2 = omega.length_squared() * nutation_factor(inertia);
    Some(c * omega.length() * nutation2 * h * ACCURACY_HORIZON * ACCURACY_HORIZON)
}

/// Checks the world's springs and spins against the selected integrator's stable region.
/// Springs stepped implicitly (see [`crate::springs`]; classified here if needed) are never
/// reported: the implicit step is stable at any stiffness.
pub fn check_stability(world: &mut World) -> Vec<StabilityWarning> {
    crate::components::assume_missing_masses(world);
    let Some(settings) = world.get_resource::<PhysicsSettings>().copied() else {
        return Vec::new();
    };
    // Every limit below is for one plain step of the stability span (`Δt` without substeps).
    let dt = settings.stages().stability_span(settings.dt());
    // Springs the implicit step takes are stable at any ωΔt: classify first.
    if crate::springs::classification_is_stale(world) {
        crate::springs::classify_springs(world);
    }
    // The spin checks judge one substep, `Δt/N`, which every stage of it shares.
    let substep = settings.stages().span(settings.dt(), 0).substep;
    let mut warnings = Vec::new();
    check_springs(world, dt, &mut warnings);
    check_positions(world, dt, &mut warnings);
    check_free_rotation(world, &settings, substep, &mut warnings);
    check_first_order(world, &settings, substep, &mut warnings);
    check_rk4(world, &settings, substep, &mut warnings);
    check_explicit_gyroscopic(world, &settings, dt, &mut warnings);
    note_implicit_groups(world, &settings, &mut warnings);
    warnings
}

/// Springs stepped explicitly whose `√(k/μ) Δt` reaches [`SPRING_LIMIT`].
fn check_springs(world: &mut World, dt: Real, warnings: &mut Vec<StabilityWarning>) {
    let springs: Vec<(Entity, Spring)> = world
        .query_filtered::<(Entity, &Spring), Without<crate::components::ImplicitSpring>>()
        .iter(world)
        .map(|(e, s)| (e, *s))
        .collect();
    let mut bodies = world.query_filtered::<&MassProps, With<RigidBody>>();
    for (entity, spring) in springs {
        let mut mass_of = |e: Entity| bodies.get(world, e).ok().map(|m| m.mass());
        // The ends' masses: one for a spring to a world point.
        let (ma, mb) = match (mass_of(spring.a), spring.b) {
            (Some(ma), SpringEnd::World(_)) => (ma, None),
            (Some(ma), SpringEnd::Body { body, .. }) => match mass_of(body) {
                Some(mb) => (ma, Some(mb)),
                None => continue,
            },
            (None, _) => continue,
        };
        let reduced = mb.map_or(ma, |mb| ma * mb / (ma + mb));
        let omega_dt = (spring.stiffness / reduced).sqrt() * dt;
        // As the step's precision computes it (at the limit itself, the bits decide); where
        // that is not a number (`k/μ` past the precision's largest number, or `μ` rounded to
        // 0), from `f64`, capped at that number.
        let omega_dt = if omega_dt.is_finite() {
            omega_dt
        } else {
            let (ma, mb) = (ma.widen(), mb.map(Widen::widen));
            let reduced = mb.map_or(ma, |mb| ma * mb / (ma + mb));
            let wide = (spring.stiffness.widen() / reduced).sqrt() * dt.widen();
            wide.min(Real::MAX.widen()).narrow()
        };
        if omega_dt >= SPRING_LIMIT {
            warnings.push(StabilityWarning::StiffSpring {
                spring: entity,
                omega_dt,
            });
        }
    }
}

/// Moving bodies that turn about a locked axis, spin so fast about an axis of small moment
/// that their angular velocity's rounding moves a visible part of their angular momentum, or
/// sit so far out that their position rounds away a visible part of each step.
fn check_positions(world: &mut World, dt: Real, warnings: &mut Vec<StabilityWarning>) {
    let gravity = world
        .get_resource::<Gravity>()
        .and_then(Gravity::field)
        .unwrap_or(Vec3::ZERO);
    let mut moving = world.query_filtered::<(
        Entity,
        &Pose,
        &Velocity,
        &MassProps,
        Option<&GravityScale>,
    ), (With<RigidBody>, Without<Static>, Without<Kinematic>)>();
    for (body, t, v, m, scale) in moving.iter(world) {
        if m.has_locked_axis() {
            let rate = m.locked_axis_rates(t.rotation, v.angular).length();
            if rate > LOCKED_RATE_LIMIT * v.angular.length() {
                warnings.push(StabilityWarning::LockedAxisRate { body, rate });
            }
        }
        let spin = length_f64(v.angular);
        let momentum = length_f64(m.world_inertia_mul(t.rotation, v.angular));
        if spin > 0.0 && momentum > 0.0 && momentum.is_finite() {
            let largest_moment = m.principal_inertia().max_element().widen();
            let relative_error = largest_moment * Real::EPSILON.widen() * spin / momentum;
            if relative_error > ANGULAR_RESOLUTION_LIMIT.widen() {
                warnings.push(StabilityWarning::CoarseAngularVelocity {
                    body,
                    spin,
                    momentum,
                    relative_error,
                });
            }
        }
        let distance = length_f64(t.translation);
        let swing = spin * length_f64(t.rotation * m.local_center_of_mass());
        let fall = length_f64(gravity) * scale.map_or(1.0, |s| s.0).widen().abs() * dt.widen();
        let step_motion = (length_f64(v.linear) + swing + fall) * dt.widen();
        if step_motion > 0.0 {
            let relative_error = distance * Real::EPSILON.widen() / (2.0 * step_motion);
            if relative_error > POSITION_RESOLUTION_LIMIT.widen() {
                warnings.push(StabilityWarning::CoarsePosition {
                    body,
                    distance,
                    step_motion,
                    relative_error,
                });
            }
        }
    }
}

/// `|v|` in `f64`, scaled by its largest component: a finite position may lie farther from the
/// origin than its squared length can count (beyond 1.8e19 m in `f32`), and a warning must give
/// the distance, not `inf`.
fn length_f64(v: Vec3) -> f64 {
    let v = v.widen();
    let scale = v.abs().max_element();
    if scale > 0.0 && scale.is_finite() {
        scale * (v / scale).length()
    } else {
        scale
    }
}

/// The split methods' free rotation, under the world's [`FreeFlow`] setting.
fn check_free_rotation(
    world: &mut World,
    settings: &PhysicsSettings,
    substep: Real,
    warnings: &mut Vec<StabilityWarning>,
) {
    // The split methods' free rotation. Under `auto` the step judges each body itself
    // (`ExactSwitch`) and gives the exact flow to those it would integrate badly: one notice
    // names the bodies that take it now. Under `method` each body whose split errs by more
    // than the limit a stage is warned of.
    let mut spins = world
        .query_filtered::<(Entity, &MassProps, &Pose, &Velocity, Option<&SpringTurn>), (
            With<RigidBody>,
            Without<ImplicitBody>,
            Without<Static>,
            Without<Kinematic>,
        )>();
    match settings.free_flow {
        FreeFlow::Auto => {
            if let Some(switch) = ExactSwitch::new(settings.integrator, FreeFlow::Auto, substep) {
                let mut first: Option<(Entity, Real)> = None;
                let mut count = 0;
                for (body, mass, transform, velocity, turn) in spins.iter(world) {
                    let state = body_state(transform, velocity, mass);
                    let rate = turn.map_or(0.0, SpringTurn::rate);
                    if switch.applies_turned(&state, mass, rate) {
                        count += 1;
                        first.get_or_insert((body, switch.measure(&state, mass) as Real));
                    }
                }
                if let Some((body, measure)) = first {
                    warnings.push(StabilityWarning::ExactFreeFlow {
                        body,
                        bodies: count,
                        integrator: settings.integrator,
                        measure,
                    });
                }
            }
        }
        FreeFlow::Method => {
            let limit = match settings.integrator {
                Integrator::Splitting | Integrator::SplittingXyz => Some(SPLIT_ERROR_LIMIT),
                Integrator::Yoshida4 => Some(COMPOSED_SPLIT_ERROR_LIMIT),
                _ => None,
            };
            if let Some(limit) = limit {
                // The largest stage's span: the split is applied once per stage.
                let largest = settings
                    .integrator
                    .composition()
                    .iter()
                    .fold(0.0, |m: Real, w| m.max(w.abs()));
                let h = largest * substep;
                for (body, mass, transform, velocity, _) in spins.iter(world) {
                    let principal = transform.rotation * mass.principal_frame();
                    let omega = tumble_core::integrate::rotate_inv(principal, velocity.angular);
                    let error_per_step = split_rotation_error(
                        mass.principal_inertia().widen(),
                        omega.widen(),
                        h.widen(),
                    ) as Real;
                    if error_per_step > limit {
                        warnings.push(StabilityWarning::InexactFreeRotation {
                            body,
                            integrator: settings.integrator,
                            error_per_step,
                        });
                    }
                }
            }
        }
    }
}

/// Spins a first-order gyroscopic method (`lclamp`, `implicit-gyroscopic`) drifts on.
fn check_first_order(
    world: &mut World,
    settings: &PhysicsSettings,
    h: Real,
    warnings: &mut Vec<StabilityWarning>,
) {
    if matches!(
        settings.integrator,
        Integrator::Lclamp | Integrator::ImplicitGyroscopic
    ) {
        let mut spins = world.query_filtered::<
            (Entity, &MassProps, &Velocity),
            (With<RigidBody>, Without<ImplicitBody>),
        >();
        for (body, mass, velocity) in spins.iter(world) {
            let drift = first_order_drift(
                settings.integrator,
                mass.principal_inertia(),
                velocity.angular,
                h,
            );
            if let Some(drift) = drift.filter(|&d| d > FIRST_ORDER_DRIFT_LIMIT) {
                warnings.push(StabilityWarning::FirstOrderGyroscopic {
                    body,
                    integrator: settings.integrator,
                    drift,
                });
            }
        }
    }
}

/// Bodies whose `rk4` rotation is stiff.
fn check_rk4(
    world: &mut World,
    settings: &PhysicsSettings,
    h: Real,
    warnings: &mut Vec<StabilityWarning>,
) {
    if settings.integrator == Integrator::Rk4 {
        let mut spins = world.query_filtered::<
            (Entity, &MassProps, &Pose, &Velocity),
            (With<RigidBody>, Without<ImplicitBody>),
        >();
        for (body, mass, transform, velocity) in spins.iter(world) {
            let momentum = mass
                .world_inertia_mul(transform.rotation, velocity.angular)
                .length();
            let thinnest = mass.principal_inertia().min_element();
            if thinnest > 0.0 {
                let stiffness = momentum * h / thinnest;
                if stiffness > RK4_STIFFNESS_LIMIT {
                    warnings.push(StabilityWarning::StiffRk4Rotation { body, stiffness });
                }
            }
        }
    }
}

/// Spins whose explicit gyroscopic term (`symplectic-euler`, `symplectic-euler-linear`) blows
/// up within [`EXPLICIT_GYROSCOPIC_HORIZON`].
fn check_explicit_gyroscopic(
    world: &mut World,
    settings: &PhysicsSettings,
    dt: Real,
    warnings: &mut Vec<StabilityWarning>,
) {
    if matches!(
        settings.integrator,
        Integrator::SymplecticEuler | Integrator::SymplecticEulerLinear
    ) {
        let mut spins = world.query_filtered::<
            (Entity, &MassProps, &Velocity),
            (With<RigidBody>, Without<ImplicitBody>),
        >();
        for (body, mass, velocity) in spins.iter(world) {
            let omega2 =
                velocity.angular.length_squared() * nutation_factor(mass.principal_inertia());
            if omega2 > 0.0 {
                let seconds = 2.0 * (1e7 as Real).ln() / (omega2 * dt);
                if seconds < EXPLICIT_GYROSCOPIC_HORIZON {
                    warnings.push(StabilityWarning::ExplicitGyroscopic {
                        body,
                        integrator: settings.integrator,
                        seconds,
                    });
                }
            }
        }
    }
}

/// The bodies of stiff spring groups, which the implicit spring solve steps (see
/// [`crate::springs`]): named once, with how many of them it turns by the implicit midpoint
/// rather than by the selected method; or, for a method that cannot be combined with the
/// implicit solve (the first-order ones), refused.
fn note_implicit_groups(
    world: &mut World,
    settings: &PhysicsSettings,
    warnings: &mut Vec<StabilityWarning>,
) {
    let span = crate::springs::classification_span(settings);
    let mut implicit = world.query_filtered::<(Entity, Option<&SpringTurn>), With<ImplicitBody>>();
    let mut first = None;
    let (mut bodies, mut midpoint) = (0, 0);
    for (body, turn) in implicit.iter(world) {
        first.get_or_insert(body);
        bodies += 1;
        if turn.copied().unwrap_or_default().turns_by_midpoint(span) {
            midpoint += 1;
        }
    }
    let Some(body) = first else {
        return;
    };
    let integrator = settings.integrator;
    warnings.push(if integrator.turns_at_constant_momentum() {
        StabilityWarning::ImplicitGroups {
            body,
            bodies,
            integrator,
            midpoint,
        }
    } else {
        StabilityWarning::CannotCombine {
            body,
            bodies,
            integrator,
        }
    });
}
