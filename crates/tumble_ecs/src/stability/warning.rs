//! What the stability prediction reports, and how it says it.

use bevy_ecs::prelude::*;
use tumble_core::Integrator;
use tumble_core::math::{DOUBLE_PRECISION, REAL_NAME, Real, Widen};

use super::{
    ACCURACY_HORIZON, COMPOSED_SPLIT_ERROR_LIMIT, RK4_STIFFNESS_LIMIT, SPLIT_DRIFT_TOLERANCE,
    SPRING_LIMIT,
};

/// A setting outside the selected integrator's stable region, or beyond what the precision can
/// resolve.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum StabilityWarning {
    /// A spring too stiff for the time step, stepped explicitly ([`SpringSolver::Explicit`](crate::components::SpringSolver::Explicit)).
    StiffSpring {
        /// The spring entity.
        spring: Entity,
        /// `√(k/μ) Δt` (stable below [`SPRING_LIMIT`]).
        omega_dt: Real,
    },
    /// A spin the explicit gyroscopic step will blow up.
    ExplicitGyroscopic {
        /// The body.
        body: Entity,
        /// The integrator.
        integrator: Integrator,
        /// Predicted time for round-off to grow to order one (s).
        seconds: Real,
    },
    /// A spin the split free rotation of `splitting` / `splitting-xyz` integrates with a large
    /// error per step (not an instability: the motion stays bounded and `|L|` exact, but wrong);
    /// `exact` integrates it exactly.
    InexactFreeRotation {
        /// The body.
        body: Entity,
        /// The integrator.
        integrator: Integrator,
        /// `Δt² |ω_b ω_c| |I_b − I_c| / I_a`, compared with [`SPLIT_ERROR_LIMIT`](super::SPLIT_ERROR_LIMIT).
        error_per_step: Real,
    },
    /// A body whose `rk4` rotation is stiff, `|L| Δt / I_min` above [`RK4_STIFFNESS_LIMIT`]
    /// (module docs): the state stays finite, the orientation goes wrong.
    StiffRk4Rotation {
        /// The body.
        body: Entity,
        /// `|L| Δt / I_min`.
        stiffness: Real,
    },
    /// Bodies a split method gives the exact free flow under
    /// [`FreeFlow::Auto`](tumble_core::integrate::FreeFlow::Auto): their split free rotation
    /// would err by more than the limit in a stage (see [`tumble_core::integrate::FreeFlow`]).
    /// Not a fault: what the planner chose, said so that the choice is never silent. One for
    /// the world, naming the first such body; the choice is made again every stage, from each
    /// body's state then.
    ExactFreeFlow {
        /// The first such body.
        body: Entity,
        /// How many bodies take the exact flow now.
        bodies: usize,
        /// The selected (split) integrator.
        integrator: Integrator,
        /// What the split would cost the first body, as [`ExactSwitch::measure`](tumble_core::integrate::ExactSwitch::measure) judges it: the
        /// predicted drift over [`ACCURACY_HORIZON`] (rad), or for a composition (`yoshida4`)
        /// the relative error `e` of its largest stage.
        measure: Real,
    },
    /// Bodies in stiff spring groups (see [`crate::springs`]), which the implicit spring solve
    /// steps: translation with the springs, rotation by the selected integrator's free flow or,
    /// for a body its springs turn stiffly, by the implicit midpoint (not an instability: what
    /// the planner chose, said so that it is never silent). One warning for the world, naming
    /// the first such body.
    ImplicitGroups {
        /// The first body of an implicit group.
        body: Entity,
        /// Bodies in implicit groups.
        bodies: usize,
        /// The selected integrator.
        integrator: Integrator,
        /// How many of them turn by the implicit midpoint (see
        /// [`SpringTurn::turns_by_midpoint`](crate::components::SpringTurn::turns_by_midpoint)).
        midpoint: usize,
    },
    /// Bodies in stiff spring groups under a first-order integrator, which has no free rotation
    /// at constant momentum to run inside the implicit spring solve: the step refuses the groups
    /// ([`ImplicitSpringError::CannotCombine`](tumble_core::springs::ImplicitSpringError::CannotCombine)),
    /// so the world cannot run as set. One warning for the world, naming the first such body.
    CannotCombine {
        /// The first body of an implicit group.
        body: Entity,
        /// Bodies in implicit groups.
        bodies: usize,
        /// The integrator.
        integrator: Integrator,
    },
    /// A spin whose gyroscopic term a first-order method (`lclamp`, `implicit-gyroscopic`)
    /// integrates with an orientation drift over [`ACCURACY_HORIZON`] above
    /// [`FIRST_ORDER_DRIFT_LIMIT`](super::FIRST_ORDER_DRIFT_LIMIT) (not an instability: the motion stays bounded, but wrong).
    FirstOrderGyroscopic {
        /// The body.
        body: Entity,
        /// The integrator.
        integrator: Integrator,
        /// The predicted orientation drift over [`ACCURACY_HORIZON`] (rad), see
        /// [`first_order_drift`](super::first_order_drift).
        drift: Real,
    },
    /// A body so far from the origin that rounding of its stored position eats a visible part
    /// of each step's motion (not an instability: the motion stays bounded, but wrong).
    CoarsePosition {
        /// The body.
        body: Entity,
        /// Its distance from the origin (m), in `f64` (a finite `f32` position may lie farther
        /// than `f32` can count).
        distance: f64,
        /// Its motion in one step, `s Δt` (m).
        step_motion: f64,
        /// `r ε / (2 s Δt)`, compared with [`POSITION_RESOLUTION_LIMIT`](super::POSITION_RESOLUTION_LIMIT).
        relative_error: f64,
    },
    /// A body spinning so fast about an axis of small moment that rounding of its stored
    /// (world-frame) angular velocity moves its angular momentum by a visible part of it every
    /// step (not an instability: the spin stays bounded, but `|L|` and the energy wander).
    CoarseAngularVelocity {
        /// The body.
        body: Entity,
        /// `|ω|` (rad/s), in `f64`.
        spin: f64,
        /// Its angular momentum `|L|` (kg·m²/s), in `f64`.
        momentum: f64,
        /// `I_max ε |ω| / |L|`, compared with
        /// [`ANGULAR_RESOLUTION_LIMIT`](super::ANGULAR_RESOLUTION_LIMIT).
        relative_error: f64,
    },
    /// A body that turns about a locked principal axis (a zero moment of inertia): every
    /// integrator holds that rate at 0, so the first step drops it (not an instability, but the
    /// motion is not the one given).
    LockedAxisRate {
        /// The body.
        body: Entity,
        /// `|b|`, the rates about its locked axes (rad/s), see
        /// [`MassProperties::locked_axis_rates`](tumble_core::MassProperties::locked_axis_rates).
        rate: Real,
    },
}

impl StabilityWarning {
    /// The spring or body warned of.
    pub fn subject(&self) -> Entity {
        match *self {
            StabilityWarning::StiffSpring { spring, .. } => spring,
            StabilityWarning::ExplicitGyroscopic { body, .. }
            | StabilityWarning::FirstOrderGyroscopic { body, .. }
            | StabilityWarning::ImplicitGroups { body, .. }
            | StabilityWarning::CannotCombine { body, .. }
            | StabilityWarning::ExactFreeFlow { body, .. }
            | StabilityWarning::InexactFreeRotation { body, .. }
            | StabilityWarning::StiffRk4Rotation { body, .. }
            | StabilityWarning::CoarsePosition { body, .. }
            | StabilityWarning::CoarseAngularVelocity { body, .. }
            | StabilityWarning::LockedAxisRate { body, .. } => body,
        }
    }

    /// True for settings that make the integration diverge (stiff springs, explicit gyroscopic
    /// blow-ups) or that the step refuses (a method that cannot step a stiff spring group);
    /// false for a limit of accuracy or precision.
    pub fn is_instability(&self) -> bool {
        !matches!(
            self,
            StabilityWarning::CoarsePosition { .. }
                | StabilityWarning::CoarseAngularVelocity { .. }
                | StabilityWarning::LockedAxisRate { .. }
                | StabilityWarning::FirstOrderGyroscopic { .. }
                | StabilityWarning::ImplicitGroups { .. }
                | StabilityWarning::ExactFreeFlow { .. }
                | StabilityWarning::InexactFreeRotation { .. }
                | StabilityWarning::StiffRk4Rotation { .. }
        )
    }
}

impl std::fmt::Display for StabilityWarning {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            StabilityWarning::StiffSpring { spring, omega_dt } => write!(
                f,
                "spring {spring}: √(k/μ)Δt = {} ≥ {SPRING_LIMIT}, outside the stable \
                 region of the explicit spring step; use the implicit one (springs = `auto` or \
                 `implicit`), or lower the stiffness or the time step",
                if omega_dt >= Real::MAX {
                    format!("{} or more", tumble_core::error::compact(Real::MAX))
                } else if omega_dt < 1e6 {
                    format!("{omega_dt:.3}")
                } else {
                    format!("{omega_dt:.3e}")
                }
            ),
            StabilityWarning::ExplicitGyroscopic {
                body,
                integrator,
                seconds,
            } => write!(
                f,
                "rigid body {body}: integrator `{integrator}` amplifies its spin's round-off to \
                 order one in about {seconds:.1} s (explicit gyroscopic term); use `splitting`"
            ),
            StabilityWarning::InexactFreeRotation {
                body,
                integrator,
                error_per_step,
            } => inexact_free_rotation(f, body, integrator, error_per_step),
            StabilityWarning::ExactFreeFlow {
                body,
                bodies,
                integrator,
                measure,
            } => exact_free_flow(f, body, bodies, integrator, measure),
            StabilityWarning::ImplicitGroups {
                body,
                bodies,
                integrator,
                midpoint,
            } => write!(
                f,
                "rigid body {body}: {} in stiff spring groups, stepped by the implicit spring \
                 solve: translation with the springs; rotation by `{integrator}` for {}, by the \
                 implicit midpoint for {midpoint} (their springs turn them stiffly: energy kept \
                 exactly)",
                alone_or_with(bodies),
                bodies - midpoint
            ),
            StabilityWarning::CannotCombine {
                body,
                bodies,
                integrator,
            } => write!(
                f,
                "rigid body {body}: {} in stiff spring groups, which `{integrator}` cannot step: \
                 a first-order method has no free rotation at constant momentum to run inside \
                 the implicit spring solve; choose `splitting`, `splitting-xyz`, `yoshida4`, \
                 `rk4`, `exact` or `exact4`, or springs = `explicit` with a time step small \
                 enough for their stiffness",
                alone_or_with(bodies)
            ),
            StabilityWarning::FirstOrderGyroscopic {
                body,
                integrator,
                drift,
            } => write!(
                f,
                "rigid body {body}: integrator `{integrator}` integrates its gyroscopic term to \
                 first order, and at this spin its orientation drifts by about {drift:.2} rad in \
                 {ACCURACY_HORIZON} s; use `splitting`, or `exact` for a thin or fast body"
            ),
            StabilityWarning::StiffRk4Rotation { body, stiffness } => write!(
                f,
                "rigid body {body}: integrator `rk4` is stiff for this body, |L|Δt/I_min = \
                 {stiffness:.2} > {RK4_STIFFNESS_LIMIT} (its rotation at constant L reads any \
                 tilt as a spin about the thinnest axis), so its orientation goes wrong; use \
                 `splitting` or `exact`"
            ),
            StabilityWarning::CoarsePosition {
                body,
                distance,
                step_motion,
                relative_error,
            } => write!(
                f,
                "rigid body {body}: {distance:.3e} m from the origin, {REAL_NAME} positions are \
                 spaced up to {:.1e} m there, and it moves {step_motion:.1e} m per step: {}{}",
                distance * Real::EPSILON.widen(),
                if relative_error < 1.0 {
                    format!(
                        "up to {:.2} % of every step is lost to rounding",
                        100.0 * relative_error
                    )
                } else {
                    // Beyond 100 % a percentage is only a long number: the step may be lost.
                    "a whole step can be lost to rounding".to_owned()
                },
                if DOUBLE_PRECISION {
                    "; move the origin closer"
                } else {
                    "; build with the `f64` feature (or move the origin closer)"
                }
            ),
            StabilityWarning::CoarseAngularVelocity {
                body,
                spin,
                momentum,
                relative_error,
            } => write!(
                f,
                "rigid body {body}: spins at {spin:.3e} rad/s with |L| = {momentum:.3e} kg·m²/s: \
                 {REAL_NAME} rounds its world-frame angular velocity by up to {:.1e} kg·m²/s of \
                 angular momentum, {}, so |L| and the energy wander by about that every step \
                 (a fast spin about an axis of small moment){}",
                relative_error * momentum,
                if relative_error < 1.0 {
                    format!("{:.2} % of |L|", 100.0 * relative_error)
                } else {
                    format!("{relative_error:.1e} times |L|")
                },
                if DOUBLE_PRECISION {
                    ""
                } else {
                    "; build with the `f64` feature"
                }
            ),
            StabilityWarning::LockedAxisRate { body, rate } => write!(
                f,
                "rigid body {body}: turns at {rate:.3e} rad/s about a locked principal axis (a \
                 zero moment of inertia), a rate every integrator holds at 0: the first step \
                 drops it; give it no rate about that axis, or a nonzero moment"
            ),
        }
    }
}

/// "alone" for a group of one body, "and N more bodies" for a bigger one.
fn alone_or_with(bodies: usize) -> String {
    if bodies == 1 {
        "alone".to_owned()
    } else {
        format!("and {} more bodies", bodies - 1)
    }
}

/// The notice of [`StabilityWarning::InexactFreeRotation`].
fn inexact_free_rotation(
    f: &mut std::fmt::Formatter<'_>,
    body: Entity,
    integrator: Integrator,
    error_per_step: Real,
) -> std::fmt::Result {
    let span = if integrator.composition().len() > 1 {
        "stage"
    } else {
        "step"
    };
    write!(
        f,
        "rigid body {body}: integrator `{integrator}` splits its free rotation with a relative \
         error of {:.1} % per {span} in its spin (Δt²|ω_b ω_c||I_b − I_c|/I_a); use free_flow = \
         `auto` (the exact flow where the split errs), `exact`, or a smaller time step",
        100.0 * error_per_step,
    )
}

/// The notice of [`StabilityWarning::ExactFreeFlow`].
fn exact_free_flow(
    f: &mut std::fmt::Formatter<'_>,
    body: Entity,
    bodies: usize,
    integrator: Integrator,
    measure: Real,
) -> std::fmt::Result {
    write!(
        f,
        "rigid body {body}{}: `{integrator}`'s split free rotation would {}; stepped \
                 with the exact free flow (as `{}`) while that holds; free_flow = `method` \
                 keeps the split",
        if bodies == 1 {
            String::new()
        } else {
            format!(" and {} more bodies", bodies - 1)
        },
        // An estimate past the precision's range (a step of 1e38 s) says so, not `inf`.
        if integrator.composition().len() > 1 {
            format!(
                "err by {} a stage (Δt²|ω_b ω_c||I_b − I_c|/I_a > {:.0} %)",
                if measure.is_finite() {
                    format!("{:.1} %", 100.0 * measure)
                } else {
                    format!("more than {REAL_NAME} can count")
                },
                100.0 * COMPOSED_SPLIT_ERROR_LIMIT
            )
        } else {
            format!(
                "drift by {} in {ACCURACY_HORIZON} s (> {SPLIT_DRIFT_TOLERANCE:.0e} rad, the \
                 {REAL_NAME} state's own rounding)",
                if measure.is_finite() {
                    format!("about {measure:.1e} rad")
                } else {
                    format!("more radians than {REAL_NAME} can count")
                }
            )
        },
        integrator
            .exact_counterpart()
            .map_or("exact", |exact| exact.name()),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A split's error estimate past the precision's range (a step of 1e38 s) is said in words,
    /// never printed as `inf`; a finite one keeps its number.
    #[test]
    fn an_estimate_past_the_range_is_not_printed_as_inf() {
        let body = Entity::from_raw_u32(7).expect("a valid index");
        for integrator in [Integrator::Splitting, Integrator::Yoshida4] {
            let text = |measure: Real| {
                StabilityWarning::ExactFreeFlow {
                    body,
                    bodies: 1,
                    integrator,
                    measure,
                }
                .to_string()
            };
            let past = text(Real::INFINITY);
            assert!(!past.contains("inf") && !past.contains("NaN"), "{past}");
            assert!(past.contains("can count"), "{past}");
            let finite = text(0.25);
            assert!(
                finite.contains("2.5e-1 rad") || finite.contains("25.0 %"),
                "{finite}"
            );
        }
    }
}
