//! Markers the planner and the systems put on bodies and springs, and the query shapes the
//! integrate systems share.

use bevy_ecs::prelude::*;
use glam::{DMat3, DVec3};
use tumble_core::math::{Narrow, Real, Vec3, Widen};

use super::body::{Damping, Kinematic, MassProps, Pose, RigidBody, Static, Velocity};
use super::errors::Rejected;

/// Marks a spring stepped by the implicit step.
#[derive(Component, Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct ImplicitSpring;

/// Marks a body of a spring group stepped by the implicit step.
#[derive(Component, Debug, Clone, Copy, PartialEq)]
pub struct ImplicitBody {
    /// The moment `P = Σ aᵢ Fᵢᵀ` of the [`ConstantForce`](crate::components::ConstantForce)s at body
    /// points this stage (`aᵢ` the arm from the centre of mass in the body frame, `Fᵢ` the world
    /// force): their forces are in the accumulator, their torque is taken at mid-step inside the
    /// implicit solve (see [`GroupBody::load_moment`]), which consumes it.
    load_moment: DMat3,
    /// `ω_turn` (rad/s), how fast the body's springs can turn it (see [`crate::springs`]): the
    /// implicit solve turns it by the world's integrator where that is slow for the step, by the
    /// implicit midpoint otherwise.
    turn_rate: Real,
}

impl Default for ImplicitBody {
    /// No point forces recorded. (Not derived: `DMat3::default()` is the identity.)
    fn default() -> Self {
        Self {
            load_moment: DMat3::ZERO,
            turn_rate: 0.0,
        }
    }
}

impl ImplicitBody {
    /// Records a force `force` (world) at the arm `arm` (body frame, from the centre of mass).
    pub(crate) fn add_point_force(&mut self, arm: Vec3, force: Vec3) {
        self.load_moment += outer(arm.widen(), force.widen());
    }

    /// A body whose springs turn it at up to `turn_rate` (rad/s; see the field).
    pub(crate) fn turned_at(turn_rate: Real) -> Self {
        Self {
            turn_rate,
            ..Self::default()
        }
    }

    /// Sets the turning rate (see the field), keeping the recorded point forces.
    pub(crate) fn set_turn_rate(&mut self, turn_rate: Real) {
        self.turn_rate = turn_rate;
    }

    /// `ω_turn` (rad/s): how fast the body's springs can turn it, `√(Σ k c)` over its spring
    /// ends with `c` the end's [`turning_compliance`](tumble_core::springs::turning_compliance).
    pub fn turn_rate(&self) -> Real {
        self.turn_rate
    }

    /// True when the implicit solve turns the body by the implicit midpoint rather than by the
    /// world's integrator (see [`crate::springs`]): its springs turn it at `ω_turn ≥`
    /// [`METHOD_TURN_RATE`](tumble_core::springs::METHOD_TURN_RATE), or at `ω_turn Δt ≥`
    /// [`IMPLICIT_OMEGA_DT`](tumble_core::springs::IMPLICIT_OMEGA_DT) (`Δt` the span the spring
    /// classification judges, [`Stages::accuracy_span`](tumble_core::integrate::Stages::accuracy_span)).
    pub fn turns_by_midpoint(&self, span: Real) -> bool {
        use tumble_core::springs::{IMPLICIT_OMEGA_DT, METHOD_TURN_RATE};
        !(self.turn_rate < METHOD_TURN_RATE && self.turn_rate * span < IMPLICIT_OMEGA_DT)
    }

    /// The recorded moment `P`, leaving none recorded (the implicit solve consumes it).
    pub(crate) fn take_load_moment(&mut self) -> DMat3 {
        std::mem::replace(&mut self.load_moment, DMat3::ZERO)
    }

    /// The torque `Σ (R aᵢ) × Fᵢ` of the recorded point forces with the body at `rotation`.
    pub(crate) fn point_torque(&self, rotation: tumble_core::math::Quat) -> Vec3 {
        tumble_core::math::axial_vector(DMat3::from_quat(rotation.widen()) * self.load_moment)
            .narrow()
    }
}

/// `a bᵀ`.
fn outer(a: DVec3, b: DVec3) -> DMat3 {
    DMat3::from_cols(a * b.x, a * b.y, a * b.z)
}

/// The bodies the integrate systems step: valid rigid bodies that are neither [`Static`] nor
/// [`Kinematic`].
pub type Dynamic = (
    With<RigidBody>,
    Without<Rejected>,
    Without<Static>,
    Without<Kinematic>,
);

/// What an integrate system reads and writes of a body: its pose, velocity, mass, its load
/// component `L` and its damping.
pub(crate) type Stepped<L> = (
    Entity,
    &'static mut Pose,
    &'static mut Velocity,
    &'static MassProps,
    L,
    Option<&'static Damping>,
);

/// The physics queries hold only table components and archetype filters, so they are always
/// dense (contiguously iterable).
pub(crate) fn dense<I>(iter: Result<I, bevy_ecs::query::QueryNotDenseError>) -> I {
    iter.expect("physics queries use table storage and archetype filters only")
}
