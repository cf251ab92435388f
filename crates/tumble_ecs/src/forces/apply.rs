//! The systems of the force stage: gravity, constant forces and torques, explicit springs.

use crate::components::{IndexOrder, IndexedQuery};
use bevy_ecs::prelude::*;
use tumble_core::math::{Real, Vec3, quat_rotate};

use super::push_blocks::{Push, PushBuffer, push_in_blocks};
use super::targets::{ForceTargets, PushTarget, TargetRows, Targets};
use crate::components::{
    ConstantForce, ConstantLocalForce, ConstantTorque, ForceAccumulator, Gravity, GravityScale,
    ImplicitBody, MassProps, Pose, Spring, SpringEnd, Velocity, dense,
};
use crate::parallel::Parallelism;

/// Kinetic energy of every body with a velocity plus the elastic energy of every spring (J), in
/// `f64`. Panics if a spring names a body without a [`Pose`].
pub fn kinetic_and_elastic_energy(world: &mut World) -> f64 {
    crate::components::assume_missing_masses(world);
    let kinetic: f64 = world
        .query::<(&Pose, &Velocity, &MassProps)>()
        .iter(world)
        .map(|(t, v, m)| crate::components::kinetic_energy_f64(t, v, m))
        .sum();
    let springs: Vec<Spring> = world.query::<&Spring>().iter(world).copied().collect();
    let mut poses = world.query::<&Pose>();
    let elastic: f64 = springs
        .iter()
        .map(|s| {
            let pa = poses.get(world, s.a).unwrap().transform_point(s.anchor_a);
            let pb = match s.b {
                SpringEnd::World(p) => p,
                SpringEnd::Body { body, anchor } => {
                    poses.get(world, body).unwrap().transform_point(anchor)
                }
            };
            s.elastic_energy(pa, pb)
        })
        .sum();
    kinetic + elastic
}

/// Adds `m g s` to every dynamic body with an accumulator (`s` = [`GravityScale`], default 1).
/// Only in the schedule when a [`Gravity`] resource exists; nothing while it is not finite
/// ([`Gravity::field`]). Table by table, each split over the compute pool's threads as
/// [`Parallelism`] allows: every body's sum is its own, the same bits on any thread.
pub fn apply_gravity(
    gravity: Res<Gravity>,
    mut bodies: Query<
        (&MassProps, Option<&GravityScale>, &mut ForceAccumulator),
        crate::components::Dynamic,
    >,
    parallelism: Option<Res<Parallelism>>,
) {
    let Some(g) = gravity.field() else {
        return;
    };
    let parallelism = parallelism.map_or_else(Parallelism::default, |p| *p);
    for (masses, scales, accumulators) in dense(bodies.contiguous_iter_mut()) {
        // Marks the whole column changed, once.
        let accumulators = bevy_ecs::change_detection::ContiguousMut::split(accumulators).0;
        let threads = parallelism.threads_for(accumulators.len());
        crate::parallel::in_runs(threads, accumulators, |at, run| {
            for (k, acc) in run.iter_mut().enumerate() {
                let s = scales.map_or(1.0, |s| s[at + k].0);
                acc.force += (masses[at + k].mass() * s) * g;
            }
            true
        });
    }
}

/// What one constant force adds to its body's accumulator: the force, and the torque of a
/// force at a body point about the centre of mass. Computed from the body's pose alone, so many
/// forces can be computed at once; added in generator order, so the sums are the same whatever
/// computed them.
#[derive(Debug, Clone, Copy, Default)]
enum ForcePush {
    /// The body is missing: nothing.
    #[default]
    Nothing,
    /// A force through the centre of mass.
    Force(Vec3),
    /// A force at a point, and its torque `(p − x) × F`.
    AtPoint { force: Vec3, torque: Vec3 },
}

impl ForcePush {
    /// The push of a force on `body` (given in the body's frame when `in_body_frame`, turned
    /// into the world by the body's rotation), at the body-local `local_point` or the centre of
    /// mass, with the body as `targets` holds it.
    #[inline]
    fn of(
        body: Entity,
        force: Vec3,
        in_body_frame: bool,
        local_point: Option<Vec3>,
        targets: &Targets,
    ) -> Self {
        let Some((transform, mass)) = targets.body(body) else {
            return Self::Nothing;
        };
        let force = if in_body_frame {
            quat_rotate(transform.rotation, force)
        } else {
            force
        };
        match local_point {
            None => Self::Force(force),
            Some(local) => {
                let (point, center) = anchor_point(transform, mass, local);
                Self::AtPoint {
                    force,
                    torque: (point - center).cross(force),
                }
            }
        }
    }

    /// Adds the push to `body`'s accumulator (the bits of
    /// [`ForceAccumulator::add_force_at_point`] for a force at a point).
    #[inline]
    fn apply(self, body: Entity, targets: &mut impl PushTarget) {
        match self {
            Self::Nothing => {}
            Self::Force(force) => targets.push(body, |acc| acc.add_force(force)),
            Self::AtPoint { force, torque } => targets.push(body, |acc| {
                acc.add_force(force);
                acc.add_torque(torque);
            }),
        }
    }
}

impl<G: ForceGenerator> Push<G> for ForcePush {
    #[inline]
    fn bodies(&self, generator: &G) -> [Option<Entity>; 2] {
        match self {
            Self::Nothing => [None, None],
            _ => [Some(generator.parts().0), None],
        }
    }

    #[inline]
    fn apply(self, generator: &G, targets: &mut impl PushTarget) {
        ForcePush::apply(self, generator.parts().0, targets);
    }
}

/// The pushes of one run of [`apply_constant_forces`] on the compute pool, kept between steps
/// so that a step does not allocate.
#[derive(Debug, Default)]
pub struct ForcePushes(PushBuffer<ForcePush>);

/// Applies every [`ConstantForce`] and [`ConstantLocalForce`]: its force, and the torque of a
/// force at a body point about the centre of mass (for a body of an implicit spring group, the
/// point goes to the implicit solve instead, which takes that torque at mid-step: see
/// [`ImplicitBody`]).
///
/// World-frame forces first, then body-frame ones, each in entity order ([`IndexOrder`]: a
/// body's sum must not follow the order a query visits tables in). With [`Parallelism`] and
/// enough forces, in a world without implicit groups, the pushes are computed on the compute
/// pool's threads and added on this thread in that order, as [`apply_springs`] does: the same
/// bits for any thread count.
pub fn apply_constant_forces(
    generators: IndexedQuery<ConstantForce, ()>,
    local_generators: IndexedQuery<ConstantLocalForce, ()>,
    mut bodies: ForceTargets,
    mut rows: Local<TargetRows>,
    mut implicit: Query<&mut ImplicitBody>,
    (mut orders, mut pushes): (Local<[IndexOrder; 2]>, Local<ForcePushes>),
    parallelism: Option<Res<Parallelism>>,
) {
    let mut targets = Targets::of(&mut bodies, &mut rows);
    let parallelism = parallelism.map_or_else(Parallelism::default, |p| *p);
    // Looked up only where some body is in an implicit group: a lookup per force otherwise.
    let any_implicit = !implicit.is_empty();
    let [world_frame, body_frame] = &mut *orders;
    world_frame.refresh(&generators);
    body_frame.refresh(&local_generators);
    // Forces on implicit bodies hand their points to the solve, on this thread.
    let threads = |order: &IndexOrder, count: usize, targets: &Targets| {
        if any_implicit {
            1
        } else {
            push_threads(targets, order, count, &parallelism)
        }
    };
    let pushes = &mut pushes.0;
    let world_threads = threads(world_frame, generators.iter().len(), &targets);
    let body_threads = threads(body_frame, local_generators.iter().len(), &targets);
    let mut kind = ForceKind {
        pushes,
        targets: &mut targets,
        any_implicit,
    };
    kind.apply(&generators, world_frame, world_threads, &mut implicit);
    kind.apply(&local_generators, body_frame, body_threads, &mut implicit);
}

/// A constant force generator's parts: its body, its force, the body point it acts at (`None`:
/// the centre of mass), and whether the force is given in the body's frame.
trait ForceGenerator: Component + Sync {
    /// The force turns with the body.
    const IN_BODY_FRAME: bool;
    /// `(body, force, point)`.
    fn parts(&self) -> (Entity, Vec3, Option<Vec3>);
}

impl ForceGenerator for ConstantForce {
    const IN_BODY_FRAME: bool = false;
    fn parts(&self) -> (Entity, Vec3, Option<Vec3>) {
        (self.body, self.force, self.local_point)
    }
}

impl ForceGenerator for ConstantLocalForce {
    const IN_BODY_FRAME: bool = true;
    fn parts(&self) -> (Entity, Vec3, Option<Vec3>) {
        (self.body, self.force, self.local_point)
    }
}

/// What [`apply_constant_forces`] applies each kind of generator with.
struct ForceKind<'p, 'a, 'w, 's> {
    pushes: &'p mut PushBuffer<ForcePush>,
    targets: &'p mut Targets<'a, 'w, 's>,
    any_implicit: bool,
}

impl ForceKind<'_, '_, '_, '_> {
    /// Applies every generator of one kind in entity order (`order`), computing the pushes on
    /// `threads` threads of the pool where that is more than one (the points of forces on
    /// bodies of implicit groups go to their `implicit` solve, on this thread).
    fn apply<G: ForceGenerator>(
        &mut self,
        generators: &IndexedQuery<G, ()>,
        order: &IndexOrder,
        threads: usize,
        implicit: &mut Query<&mut ImplicitBody>,
    ) {
        if threads > 1 {
            for (_, table) in dense(generators.contiguous_iter()) {
                push_in_blocks(
                    table,
                    threads,
                    self.pushes,
                    self.targets,
                    |g: &G, targets| {
                        let (body, force, point) = g.parts();
                        ForcePush::of(body, force, G::IN_BODY_FRAME, point, targets)
                    },
                );
            }
        } else {
            order.for_each(generators, |g| {
                let (body, force, point) = g.parts();
                apply_force(
                    self.targets,
                    implicit,
                    self.any_implicit,
                    body,
                    force,
                    G::IN_BODY_FRAME,
                    point,
                );
            });
        }
    }
}

/// One constant force on this thread: its push, or for a force at a point of a body in an
/// implicit group, the force to the accumulator and its point to the solve (which takes the
/// torque at mid-step, as the body turns).
#[inline]
fn apply_force(
    targets: &mut Targets,
    implicit: &mut Query<&mut ImplicitBody>,
    any_implicit: bool,
    body: Entity,
    force: Vec3,
    in_body_frame: bool,
    local_point: Option<Vec3>,
) {
    let push = ForcePush::of(body, force, in_body_frame, local_point, targets);
    if any_implicit
        && let (ForcePush::AtPoint { force, .. }, Some(local)) = (push, local_point)
        && let Ok(mut implicit) = implicit.get_mut(body)
        && let Some((_, mass)) = targets.body(body)
    {
        implicit.add_point_force(local - mass.local_center_of_mass(), force);
        targets.push(body, |acc| acc.add_force(force));
        return;
    }
    push.apply(body, targets);
}

/// Applies every [`ConstantTorque`], in entity order.
pub fn apply_constant_torques(
    generators: IndexedQuery<ConstantTorque, ()>,
    mut bodies: ForceTargets,
    mut rows: Local<TargetRows>,
    mut order: Local<IndexOrder>,
) {
    let mut targets = Targets::of(&mut bodies, &mut rows);
    order.refresh(&generators);
    order.for_each(&generators, |g| {
        targets.push(g.body, |acc| acc.add_torque(g.torque));
    });
}

/// World anchor point and the centre of mass, for a body-local anchor.
#[inline]
fn anchor_point(transform: &Pose, mass: &MassProps, local: Vec3) -> (Vec3, Vec3) {
    (
        transform.transform_point(local),
        transform.center_of_mass(mass),
    )
}

/// Elastic spring force on end `a`, `−k (|d| − L₀) n` with `d = p_a − p_b`, `n = d/|d|`; zero
/// when `|d| = 0`. The damper is not a force here: it is the velocity flow of
/// [`crate::springs`].
#[inline]
pub fn spring_force(spring: &Spring, d: Vec3) -> Vec3 {
    let length_squared = d.length_squared();
    if length_squared == Real::INFINITY
        && let Some((length, n)) = long_span(d)
    {
        return -(spring.stiffness * (length - spring.rest_length)) * n;
    }
    let length = length_squared.sqrt();
    if length <= 0.0 {
        return Vec3::ZERO;
    }
    let n = d / length;
    -(spring.stiffness * (length - spring.rest_length)) * n
}

/// The length and direction of a finite `d` whose squared length overflows (`|d|` past
/// `√MAX`, 1.8e19 m in `f32`): scaled by its largest component first. `None` for any other
/// `d` (a non-finite one stays non-finite where it is used, and is refused there).
#[cold]
pub(crate) fn long_span(d: Vec3) -> Option<(Real, Vec3)> {
    let scale = d.abs().max_element();
    if !(d.is_finite() && d.length_squared() == Real::INFINITY) {
        return None;
    }
    let unit = d / scale;
    let length = unit.length();
    Some((scale * length, unit / length))
}

/// What one spring pushes: its force and the anchor points it acts at, with each end's centre
/// of mass (the torque's pivot). Computed from the bodies' poses alone, so many springs can be
/// computed at once; applied in spring order, so the sums are the same whatever computed them.
#[derive(Debug, Clone, Copy, Default)]
enum SpringPush {
    /// An end is missing (or both are one body): nothing.
    #[default]
    Nothing,
    /// `f` on `a` at `pa`; the other end is a world point.
    OnA { f: Vec3, pa: Vec3, com_a: Vec3 },
    /// `f` on `a` at `pa`, `−f` on body `b` at `pb`.
    OnBoth {
        b: Entity,
        f: Vec3,
        pa: Vec3,
        com_a: Vec3,
        pb: Vec3,
        com_b: Vec3,
    },
}

impl SpringPush {
    /// The push of `spring` on the bodies as `targets` holds them. Where the force is not
    /// finite: nothing if an end's anchor or centre is not finite either (bad data game code
    /// wrote into that body between steps — it is refused by the integrate systems, or by
    /// [`check_fixed_bodies`](crate::integrate::check_fixed_bodies) where tumble never steps it
    /// — and the spring must not carry it to the other end first); the force as it is where
    /// both ends are finite and the force overflowed the precision (`k (ℓ − L₀)` past its
    /// largest number): both bodies then carry a force that is not finite and are refused for
    /// it, loudly, rather than stepped as if the spring were not there.
    #[inline]
    fn of(spring: &Spring, targets: &Targets) -> Self {
        let push = Self::unchecked(spring, targets);
        let (force, ends) = push.finite();
        if force || ends { push } else { Self::Nothing }
    }

    /// Whether the force is finite, and whether every anchor and centre it acts at is.
    #[inline(always)]
    fn finite(&self) -> (bool, bool) {
        match *self {
            Self::Nothing => (true, true),
            Self::OnA { f, pa, com_a } => (f.is_finite(), pa.is_finite() && com_a.is_finite()),
            Self::OnBoth {
                f,
                pa,
                com_a,
                pb,
                com_b,
                ..
            } => (
                f.is_finite(),
                pa.is_finite() && com_a.is_finite() && pb.is_finite() && com_b.is_finite(),
            ),
        }
    }

    /// [`of`](Self::of) before the test of the force.
    #[inline(always)]
    fn unchecked(spring: &Spring, targets: &Targets) -> Self {
        let Some((ta, ma)) = targets.body(spring.a) else {
            return Self::Nothing;
        };
        let (pa, com_a) = anchor_point(ta, ma, spring.anchor_a);
        match spring.b {
            SpringEnd::World(anchor_b) => Self::OnA {
                f: spring_force(spring, pa - anchor_b),
                pa,
                com_a,
            },
            // A spring from a body to its own points exerts nothing: its two forces cancel, and
            // so do their torques (the force is along `pa − pb`).
            SpringEnd::Body { body, .. } if body == spring.a => Self::Nothing,
            SpringEnd::Body { body, anchor } => {
                let Some((tb, mb)) = targets.body(body) else {
                    return Self::Nothing;
                };
                let (pb, com_b) = anchor_point(tb, mb, anchor);
                Self::OnBoth {
                    b: body,
                    f: spring_force(spring, pa - pb),
                    pa,
                    com_a,
                    pb,
                    com_b,
                }
            }
        }
    }

    /// Adds the push to the accumulators of `spring`'s bodies.
    #[inline]
    fn apply(self, spring: &Spring, targets: &mut impl PushTarget) {
        match self {
            Self::Nothing => {}
            Self::OnA { f, pa, com_a } => {
                targets.push(spring.a, |acc| acc.add_force_at_point(f, pa, com_a));
            }
            Self::OnBoth {
                b,
                f,
                pa,
                com_a,
                pb,
                com_b,
            } => {
                targets.push(spring.a, |acc| acc.add_force_at_point(f, pa, com_a));
                targets.push(b, |acc| acc.add_force_at_point(-f, pb, com_b));
            }
        }
    }
}

impl Push<Spring> for SpringPush {
    #[inline]
    fn bodies(&self, spring: &Spring) -> [Option<Entity>; 2] {
        match *self {
            Self::Nothing => [None, None],
            Self::OnA { .. } => [Some(spring.a), None],
            Self::OnBoth { b, .. } => [Some(spring.a), Some(b)],
        }
    }

    #[inline]
    fn apply(self, spring: &Spring, targets: &mut impl PushTarget) {
        SpringPush::apply(self, spring, targets);
    }
}

/// The springs' pushes of one run of [`apply_springs`] on the compute pool, kept between steps
/// so that a step does not allocate.
#[derive(Debug, Default)]
pub struct SpringPushes(PushBuffer<SpringPush>);

/// Applies every [`Spring`]'s elastic force, for the springs stepped explicitly (the implicit
/// step of [`crate::springs`] handles the others; every damper is [`crate::springs`]'s).
///
/// With [`Parallelism`] and enough springs, the pushes are computed on the compute pool's
/// threads (each spring reads only its two bodies) into a buffer kept between steps, then added
/// to the accumulators on this thread in spring order, a block of springs at a time: a spring system writes to bodies in any
/// order, and this keeps the threads busy without letting two of them add to one accumulator.
/// The sums are the same bits for any thread count.
pub fn apply_springs(
    springs: IndexedQuery<Spring, Without<crate::components::ImplicitSpring>>,
    mut bodies: ForceTargets,
    mut rows: Local<TargetRows>,
    mut pushes: Local<SpringPushes>,
    mut order: Local<IndexOrder>,
    parallelism: Option<Res<Parallelism>>,
) {
    let mut targets = Targets::of(&mut bodies, &mut rows);
    let parallelism = parallelism.map_or_else(Parallelism::default, |p| *p);
    let count = springs.iter().len();
    order.refresh(&springs);
    let threads = push_threads(&targets, &order, count, &parallelism);
    if threads <= 1 {
        order.for_each(&springs, |spring| {
            SpringPush::of(spring, &targets).apply(spring, &mut targets);
        });
        return;
    }
    for (_, table) in dense(springs.contiguous_iter()) {
        push_in_blocks(table, threads, &mut pushes.0, &mut targets, SpringPush::of);
    }
}

/// Threads that compute a force system's pushes ([`push_in_blocks`]) for `count` items: the
/// pool's share where the items are visited in entity order (`order`) and the targets are
/// tables the threads can share, else one.
fn push_threads(
    targets: &Targets,
    order: &IndexOrder,
    count: usize,
    parallelism: &Parallelism,
) -> usize {
    match targets {
        // Items in several tables, out of entity order: added one by one in that order.
        _ if !order.is_query_order() => 1,
        Targets::Tables { .. } => parallelism.threads_for(count),
        // The query's own lookups are not shared between threads.
        Targets::Query(_) => 1,
    }
}
