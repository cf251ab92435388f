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
}

impl Default for ImplicitBody {
    /// No point forces recorded. (Not derived: `DMat3::default()` is the identity.)
    fn default() -> Self {
        Self {
            load_moment: DMat3::ZERO,
        }
    }
}

impl ImplicitBody {
    /// Records a force `force` (world) at the arm `arm` (body frame, from the centre of mass).
    pub(crate) fn add_point_force(&mut self, arm: Vec3, force: Vec3) {
        self.load_moment += outer(arm.widen(), force.widen());
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

/// How fast a body's springs can turn it: `ω_turn = √(Σ k c)` over its spring ends (rad/s), `c`
/// the end's [`turning_compliance`](tumble_core::springs::turning_compliance). Put on every
/// dynamic body with springs whose anchors can turn it when the springs are classified (see
/// [`crate::springs`]); a body without one has `ω_turn = 0`. It decides how the implicit
/// spring step turns a body of a stiff group, and leaves a split method's exact switch off a
/// body whose springs' error outweighs the split's
/// ([`ExactSwitch::applies_turned`](tumble_core::integrate::ExactSwitch::applies_turned)).
#[derive(Component, Debug, Clone, Copy, PartialEq, Default)]
pub struct SpringTurn {
    rate: Real,
}

impl SpringTurn {
    /// A body its springs turn at up to `rate` (rad/s).
    pub(crate) fn new(rate: Real) -> Self {
        Self { rate }
    }

    /// `ω_turn` (rad/s).
    pub fn rate(&self) -> Real {
        self.rate
    }

    /// True when the implicit solve turns the body (of a stiff group) by the implicit midpoint
    /// rather than by the world's integrator (see [`crate::springs`]): its springs turn it at
    /// `ω_turn ≥` [`METHOD_TURN_RATE`](tumble_core::springs::METHOD_TURN_RATE), or at
    /// `ω_turn Δt ≥` [`IMPLICIT_OMEGA_DT`](tumble_core::springs::IMPLICIT_OMEGA_DT) (`Δt` the
    /// span the spring classification judges,
    /// [`Stages::accuracy_span`](tumble_core::integrate::Stages::accuracy_span)).
    pub fn turns_by_midpoint(&self, span: Real) -> bool {
        use tumble_core::springs::{IMPLICIT_OMEGA_DT, METHOD_TURN_RATE};
        !(self.rate < METHOD_TURN_RATE && self.rate * span < IMPLICIT_OMEGA_DT)
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
    Option<&'static SpringTurn>,
);

/// The physics queries hold only table components and archetype filters, so they are always
/// dense (contiguously iterable).
pub(crate) fn dense<I>(iter: Result<I, bevy_ecs::query::QueryNotDenseError>) -> I {
    iter.expect("physics queries use table storage and archetype filters only")
}
