//! The spring dampers' velocity flow, half a step on each side of the step.

use bevy_ecs::prelude::*;
use tumble_core::damping::decrement;
use tumble_core::math::{Real, Vec3};

use crate::components::Rejected;
use crate::components::{IndexOrder, IndexedQuery};
use crate::components::{Kinematic, MassProps, PhysicsSettings, Pose, RigidBody, Static, Velocity};
use crate::components::{Spring, SpringEnd};
use crate::forces::long_span;
use crate::integrate::StageCursor;

/// The spring ends a damper reads and pushes: valid rigid bodies of any kind (a [`Static`] or
/// [`Kinematic`] end lends its velocity to `u` but takes no impulse).
type DamperEnds<'w, 's> = Query<
    'w,
    's,
    (
        &'static Pose,
        &'static mut Velocity,
        &'static MassProps,
        Has<Static>,
        Has<Kinematic>,
    ),
    (With<RigidBody>, Without<Rejected>),
>;

/// First half of the spring dampers' flow over a substep `h` (the whole step without substeps),
/// `D(h/2)`, before anything else moves the bodies: every [`Spring`] with `damping > 0`, in
/// entity order, in the first stage of each substep. Only in the plan when such a spring exists.
pub fn damp_springs_start(
    settings: Res<PhysicsSettings>,
    cursor: Res<StageCursor>,
    springs: IndexedQuery<Spring, ()>,
    mut bodies: DamperEnds,
    mut order: Local<IndexOrder>,
) {
    let span = cursor.span(&settings);
    if !span.opens_substep {
        return;
    }
    let tau = 0.5 * span.substep;
    order.refresh(&springs);
    order.for_each(&springs, |spring| damp_spring(spring, tau, &mut bodies));
}

/// Second half of the spring dampers' flow, `D(h/2)`, after the integration, in the last stage
/// of each substep: the springs of [`damp_springs_start`] in the reverse order (the adjoint
/// sweep, so the step is symmetric).
pub fn damp_springs_end(
    settings: Res<PhysicsSettings>,
    cursor: Res<StageCursor>,
    springs: IndexedQuery<Spring, ()>,
    mut bodies: DamperEnds,
    mut order: Local<IndexOrder>,
) {
    let span = cursor.span(&settings);
    if !span.closes_substep {
        return;
    }
    let tau = 0.5 * span.substep;
    order.refresh(&springs);
    order.for_each_rev(&springs, |spring| damp_spring(spring, tau, &mut bodies));
}

/// Whether a spring has a damper (`c > 0`; NaN and negative coefficients have none).
#[inline]
pub(crate) fn is_damped(spring: &Spring) -> bool {
    spring.damping > 0.0
}

/// One end of a damper, in world coordinates.
struct Anchor {
    /// Lever arm `r = p − x` from the centre of mass.
    arm: Vec3,
    /// Anchor velocity `v + ω × r` (zero on a [`Static`] body, see [`Anchor::held`]).
    velocity: Vec3,
}

impl Anchor {
    fn of(transform: &Pose, velocity: &Velocity, mass: &MassProps, local: Vec3) -> (Vec3, Self) {
        let point = transform.transform_point(local);
        let arm = point - transform.center_of_mass(mass);
        let velocity = velocity.linear + velocity.angular.cross(arm);
        (point, Self { arm, velocity })
    }

    /// The anchor as the damper sees it: a [`Static`] body (`is_static`) never moves, so its
    /// anchor's velocity is zero whatever its `Velocity` holds (an impulse game code gave it, or
    /// the velocity it had when it was made static).
    fn held((point, anchor): (Vec3, Self), is_static: bool) -> (Vec3, Self) {
        let velocity = if is_static {
            Vec3::ZERO
        } else {
            anchor.velocity
        };
        (point, Self { velocity, ..anchor })
    }

    /// This end's share of `1/m_eff` along `n`: `1/m + (r × n)·I⁻¹(r × n)`.
    fn inverse_mass(&self, transform: &Pose, mass: &MassProps, n: Vec3) -> Real {
        let rn = self.arm.cross(n);
        mass.inv_mass() + rn.dot(mass.world_inv_inertia_mul(transform.rotation, rn))
    }

    /// Applies the impulse `impulse` (world frame) at the anchor.
    fn push(&self, transform: &Pose, mass: &MassProps, velocity: &mut Velocity, impulse: Vec3) {
        velocity.linear += mass.inv_mass() * impulse;
        velocity.angular += mass.world_inv_inertia_mul(transform.rotation, self.arm.cross(impulse));
    }
}

/// The damper's impulse along `n` on end `a` over `τ`, given `w = 1/m_eff` and the relative
/// anchor velocity `u` along `n`: `P = −(1 − e^{−cτw}) u / w`. Zero when both ends are fixed
/// (`w = 0`) and when `u` or `w` is not finite (bad data game code wrote between steps: the
/// integrate systems quarantine that body, and the damper must not carry the NaN to the other
/// end first).
#[inline]
fn impulse(damping: Real, tau: Real, w: Real, u: Real) -> Real {
    if w.is_finite() && w > 0.0 && u.is_finite() {
        -decrement(damping * tau * w) * u / w
    } else {
        0.0
    }
}

/// The damper flow of one spring over `τ` (nothing for an undamped spring, a degenerate axis
/// `|d| = 0`, a missing or rejected end, or two ends that are both fixed).
fn damp_spring(spring: &Spring, tau: Real, bodies: &mut DamperEnds) {
    if !is_damped(spring) {
        return;
    }
    match spring.b {
        SpringEnd::World(anchor_b) => {
            let Ok((t, mut v, m, is_static, is_kinematic)) = bodies.get_mut(spring.a) else {
                return;
            };
            if is_static || is_kinematic {
                return;
            }
            let (pa, a) = Anchor::of(t, &v, m, spring.anchor_a);
            let Some(n) = (pa - anchor_b)
                .try_normalize()
                .or_else(|| long_span(pa - anchor_b).map(|(_, n)| n))
            else {
                return;
            };
            let p = impulse(
                spring.damping,
                tau,
                a.inverse_mass(t, m, n),
                a.velocity.dot(n),
            );
            a.push(t, m, &mut v, p * n);
        }
        SpringEnd::Body { body, anchor } => {
            let Ok([(ta, mut va, ma, sa, ka), (tb, mut vb, mb, sb, kb)]) =
                bodies.get_many_mut([spring.a, body])
            else {
                return;
            };
            let (dynamic_a, dynamic_b) = (!(sa || ka), !(sb || kb));
            let (pa, a) = Anchor::held(Anchor::of(ta, &va, ma, spring.anchor_a), sa);
            let (pb, b) = Anchor::held(Anchor::of(tb, &vb, mb, anchor), sb);
            let Some(n) = (pa - pb)
                .try_normalize()
                .or_else(|| long_span(pa - pb).map(|(_, n)| n))
            else {
                return;
            };
            let share = |dynamic: bool, end: &Anchor, t, m| {
                if dynamic {
                    end.inverse_mass(t, m, n)
                } else {
                    0.0
                }
            };
            let w = share(dynamic_a, &a, ta, ma) + share(dynamic_b, &b, tb, mb);
            let p = impulse(spring.damping, tau, w, (a.velocity - b.velocity).dot(n));
            if dynamic_a {
                a.push(ta, ma, &mut va, p * n);
            }
            if dynamic_b {
                b.push(tb, mb, &mut vb, -p * n);
            }
        }
    }
}
