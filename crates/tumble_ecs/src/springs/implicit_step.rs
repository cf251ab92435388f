//! The implicit spring step's system: gathers the stiff groups, solves each with the
//! energy-conserving implicit step and writes the bodies back.

use bevy_ecs::entity::EntityHashMap;
use bevy_ecs::prelude::*;

use tumble_core::integrate::{ExactSwitch, StageSpan};
use tumble_core::math::{Real, Vec3};
use tumble_core::springs::{GroupBody, GroupRotation, GroupSpring, ImplicitSpringSolver, LinkEnd};

use super::classify::{classification_span, ends_in, find};
use crate::components::{
    BodyError, BodyErrorKind, Dynamic, ForceAccumulator, Gravity, GravityScale, ImplicitBody,
    ImplicitSpring, PhysicsSettings, Pose, Refusals, RigidBody, Spring, SpringEnd, SpringTurn,
    Stepped, body_state, check_body, write_body_state,
};
use crate::components::{IndexOrder, IndexedQuery};
use crate::integrate::damp;

/// Scratch memory of [`solve_implicit_springs`], kept between steps.
#[derive(Default)]
pub struct ImplicitScratch {
    solver: ImplicitSpringSolver,
    index: EntityHashMap<usize>,
    entities: Vec<Entity>,
    parent: Vec<usize>,
    group_of: Vec<usize>,
    /// Per root body, its group's number (groups numbered in order of their roots).
    rank: Vec<usize>,
    /// Body indices grouped: group `g`'s are `members[member_start[g]..member_start[g + 1]]`,
    /// in index (entity) order.
    members: Vec<usize>,
    member_start: Vec<usize>,
    /// Springs grouped the same way, in entity order within a group, their ends as indices
    /// local to the group.
    springs: Vec<GroupSpring>,
    spring_start: Vec<usize>,
    /// Each spring's group, in entity order, before the springs are grouped.
    pending: Vec<u32>,
    cursor: Vec<usize>,
    /// Per body, its index within its group.
    local: Vec<usize>,
    /// The current group's bodies, handed to the solver.
    bodies: Vec<GroupBody>,
    /// Every implicit body of the world, in entity order.
    all: Vec<GroupBody>,
    /// Scratch of the sort into entity order.
    order: Vec<u32>,
    /// The implicit springs in entity order.
    spring_order: IndexOrder,
}

/// Steps every implicit spring group with the energy-conserving implicit step (see
/// [`tumble_core::springs::implicit`]), consuming the bodies' accumulators. A group whose solve
/// fails keeps its state and is quarantined.
pub fn solve_implicit_springs(
    settings: Res<PhysicsSettings>,
    cursor: Res<crate::integrate::StageCursor>,
    (mut scratch, gravity): (Local<ImplicitScratch>, Option<Res<Gravity>>),
    mut refusals: Refusals,
    springs: ImplicitSprings,
    mut bodies: ImplicitBodies,
    others: Query<&Pose, (With<RigidBody>, Without<ImplicitBody>)>,
) {
    let s = &mut *scratch;
    let span = cursor.span(&settings);
    let weighed = crate::integrate::gravity_applies(gravity);
    s.gather_bodies(&settings, span, weighed, &mut bodies, &mut refusals);
    s.sort_by_entity();
    let mut spring_order = std::mem::take(&mut s.spring_order);
    spring_order.refresh(&springs);
    let groups = s.group_bodies(&springs, &spring_order);
    s.group_springs(&springs, &spring_order, &others, groups);
    s.spring_order = spring_order;
    for g in 0..groups {
        s.step_group(g, span, &mut bodies, &mut refusals);
    }
}

/// The bodies of the stiff groups, as the implicit step reads and writes them.
type ImplicitBodies<'w, 's> = Query<
    'w,
    's,
    (
        Stepped<&'static mut ForceAccumulator>,
        &'static mut ImplicitBody,
        Option<&'static GravityScale>,
    ),
    (Dynamic, With<ImplicitBody>),
>;

/// How the implicit solve turns a body of a stiff group (see the [`springs`](crate::springs) docs): by the world's
/// integrator (its exact counterpart where `switch` gives the body the exact free flow this
/// stage) where its springs turn it softly, by the implicit midpoint otherwise (`judged` the
/// span the classification judges, [`classification_span`]). A method that cannot be combined
/// is passed on as it is, for the solve to refuse.
fn group_rotation(
    settings: &PhysicsSettings,
    switch: Option<&ExactSwitch>,
    judged: Real,
    turn: SpringTurn,
    state: &tumble_core::BodyState,
    mass: &tumble_core::MassProperties,
) -> GroupRotation {
    let method = settings.integrator;
    if method.turns_at_constant_momentum() && turn.turns_by_midpoint(judged) {
        return GroupRotation::Midpoint;
    }
    match switch {
        Some(switch) if switch.applies_turned(state, mass, turn.rate()) => {
            GroupRotation::Method(switch.exact())
        }
        _ => GroupRotation::Method(method),
    }
}

impl ImplicitScratch {
    /// Reads every body of the stiff groups into `all` (with its index in `index`, its entity
    /// in `entities`), consuming its accumulator and applying the first half of its `Damping`
    /// where the stage opens a substep; a body with bad data is refused, not gathered (its
    /// `GravityScale` counts while a gravity field applies, `weighed`).
    fn gather_bodies(
        &mut self,
        settings: &PhysicsSettings,
        span: StageSpan,
        weighed: bool,
        bodies: &mut ImplicitBodies,
        refusals: &mut Refusals,
    ) {
        self.index.clear();
        self.entities.clear();
        self.parent.clear();
        self.all.clear();
        let half_substep = 0.5 * span.substep;
        let switch = ExactSwitch::new(settings.integrator, settings.free_flow, span.substep);
        let judged = classification_span(settings);
        // Exact sizes (see `ImplicitSpringSolver`'s buffers): a group may hold every body.
        let count = bodies.iter().len();
        self.entities.reserve_exact(count);
        self.parent.reserve_exact(count);
        self.all.reserve_exact(count);
        self.index.reserve(count);
        for ((entity, t, mut v, m, mut acc, damping, turn), mut implicit, scale) in
            bodies.iter_mut()
        {
            // Bad data game code wrote into one body is refused for that body alone, naming
            // the field, as on the explicit path: left out here, it is not in its group this
            // stage (its springs exert nothing, as a quarantined body's), and its components
            // and accumulator stay as they are. The point forces' moment is this stage's only
            // (no snapshot holds it): it goes with the stage.
            let checked = scale
                .filter(|_| weighed)
                .map_or(Ok(()), GravityScale::check)
                .and_then(|()| check_body(&t, &v, Some(&acc)))
                .and_then(|()| damping.map_or(Ok(()), |d| d.check()));
            if let Err(kind) = checked {
                implicit.take_load_moment();
                refusals.refuse(BodyError { entity, kind });
                continue;
            }
            // `Damping` is a flow of its own, half a substep before the substep and half after
            // (see `tumble_core::damping`), as on the explicit path.
            if let Some(d) = damping
                && span.opens_substep
            {
                let v = &mut *v;
                damp(d, half_substep, &mut v.linear, &mut v.angular);
            }
            self.parent.push(self.entities.len());
            self.entities.push(entity);
            let state = body_state(&t, &v, m);
            let turn = turn.copied().unwrap_or_default();
            let rotation = group_rotation(settings, switch.as_ref(), judged, turn, &state, &m.0);
            self.all.push(GroupBody {
                state,
                mass: m.0,
                load: acc.take(),
                load_moment: implicit.take_load_moment(),
                rotation,
            });
        }
    }

    /// Solves group `g` over the stage and writes its bodies back (with the second half of
    /// their `Damping` where the stage closes a substep); a group whose solve fails keeps its
    /// state and every member is refused.
    fn step_group(
        &mut self,
        g: usize,
        span: StageSpan,
        bodies: &mut ImplicitBodies,
        refusals: &mut Refusals,
    ) {
        let members = self.member_start[g]..self.member_start[g + 1];
        let group = &self.members[members.clone()];
        // A group whose bodies lie side by side in `all` (a world of one group, or groups
        // spawned one after the other) is solved where it lies; any other is gathered. The
        // solver sees the same bodies in the same order either way.
        let first = group.first().copied().unwrap_or(0);
        let side_by_side = group.iter().copied().eq(first..first + group.len());
        let bodies_of_group = if side_by_side {
            &mut self.all[first..first + group.len()]
        } else {
            self.bodies.clear();
            self.bodies.extend(group.iter().map(|&i| self.all[i]));
            &mut self.bodies[..]
        };
        let springs = &self.springs[self.spring_start[g]..self.spring_start[g + 1]];
        let stats = match self.solver.step(bodies_of_group, springs, span.h) {
            Ok(stats) => stats,
            Err(error) => {
                for &i in &self.members[members] {
                    let kind = BodyErrorKind::ImplicitSprings(error);
                    refusals.refuse(BodyError {
                        entity: self.entities[i],
                        kind,
                    });
                }
                return;
            }
        };
        tracing::trace!(
            bodies = bodies_of_group.len(),
            springs = springs.len(),
            newton = stats.newton_iterations,
            linear = stats.linear_iterations,
            splits = stats.splits,
            evaluations = stats.residual_evaluations,
            factorizations = stats.factorizations,
            "implicit spring group stepped"
        );
        let half_substep = 0.5 * span.substep;
        for (k, &i) in self.members[members].iter().enumerate() {
            if let Ok(((_, mut t, mut v, m, _, damping, _), _, _)) =
                bodies.get_mut(self.entities[i])
            {
                write_body_state(&bodies_of_group[k].state, m, &mut t, &mut v);
                if let Some(d) = damping
                    && span.closes_substep
                {
                    let v = &mut *v;
                    damp(d, half_substep, &mut v.linear, &mut v.angular);
                }
            }
        }
    }

    /// Puts the bodies read into `entities` and `all` in entity order and indexes them.
    ///
    /// A group's sums run over its bodies and springs in order, so the order must be a fact of
    /// the world, not of its storage (see [`IndexOrder`]): entity index order, the order the
    /// bodies were spawned in (unless an index was reused), the same however the world's
    /// tables came about.
    fn sort_by_entity(&mut self) {
        if !self.entities.is_sorted_by_key(|e| e.index_u32()) {
            let entities = &self.entities;
            self.order.clear();
            self.order.extend(0..narrow(entities.len()));
            self.order
                .sort_unstable_by_key(|&i| entities[i as usize].index_u32());
            self.bodies.clear();
            self.bodies
                .extend(self.order.iter().map(|&i| self.all[i as usize]));
            std::mem::swap(&mut self.all, &mut self.bodies);
            self.entities.sort_unstable_by_key(|e| e.index_u32());
        }
        self.index.clear();
        for (i, &entity) in self.entities.iter().enumerate() {
            self.index.insert(entity, i);
        }
    }

    /// Forms the spring groups of the bodies read into `all` (union–find over `springs`) and
    /// lays them out group by group: `members` in order of their roots, members in index
    /// order (entity order), by counting sort, one pass over the bodies and one over the
    /// springs whatever the number of groups. Returns the number of groups.
    fn group_bodies(&mut self, springs: &ImplicitSprings, order: &IndexOrder) -> usize {
        order.for_each(springs, |spring| {
            if let (Some(i), Some(j)) = ends_in(&self.index, spring) {
                let (ri, rj) = (find(&mut self.parent, i), find(&mut self.parent, j));
                self.parent[ri] = rj;
            }
        });
        let n = self.entities.len();
        self.group_of.clear();
        for i in 0..n {
            let r = find(&mut self.parent, i);
            self.group_of.push(r);
        }
        self.rank.clear();
        self.rank.resize(n, usize::MAX);
        let mut groups = 0;
        for i in 0..n {
            if self.group_of[i] == i {
                self.rank[i] = groups;
                groups += 1;
            }
        }
        let (rank, group_of) = (&self.rank, &self.group_of);
        counting_starts(
            &mut self.member_start,
            groups,
            (0..n).map(|i| rank[group_of[i]]),
        );
        self.members.clear();
        self.members.resize(n, 0);
        self.local.clear();
        self.local.resize(n, 0);
        self.cursor.clear();
        self.cursor.extend_from_slice(&self.member_start[..groups]);
        for i in 0..n {
            let g = self.rank[self.group_of[i]];
            self.local[i] = self.cursor[g] - self.member_start[g];
            self.members[self.cursor[g]] = i;
            self.cursor[g] += 1;
        }
        groups
    }

    /// Lays the springs out group by group in `springs`, each resolved to its group's local
    /// body indices.
    fn group_springs(
        &mut self,
        springs: &ImplicitSprings,
        order: &IndexOrder,
        others: &Query<&Pose, (With<RigidBody>, Without<ImplicitBody>)>,
        groups: usize,
    ) {
        // Two passes over the springs: one counts each group's springs, the other writes each in
        // its group's slot. Resolving a spring twice is cheaper than keeping every resolved spring
        // twice (a group of a million springs).
        self.pending.clear();
        order.for_each(springs, |spring| {
            if let Some((first, _)) = group_spring(&self.index, &self.local, others, spring) {
                self.pending.push(self.rank[self.group_of[first]] as u32);
            }
        });
        counting_starts(
            &mut self.spring_start,
            groups,
            self.pending.iter().map(|&g| g as usize),
        );
        self.springs.clear();
        // Every slot is written below (the counts are the same pass's); the filler never reaches
        // the solver.
        let filler = GroupSpring {
            a: 0,
            anchor_a: Vec3::ZERO,
            b: LinkEnd::Fixed(Vec3::ZERO),
            stiffness: 0.0,
            rest_length: 0.0,
        };
        self.springs.resize(self.pending.len(), filler);
        self.cursor.clear();
        self.cursor.extend_from_slice(&self.spring_start[..groups]);
        let mut k = 0;
        order.for_each(springs, |spring| {
            if let Some((_, link)) = group_spring(&self.index, &self.local, others, spring) {
                let g = self.pending[k] as usize;
                k += 1;
                self.springs[self.cursor[g]] = link;
                self.cursor[g] += 1;
            }
        });
    }
}

/// The springs the implicit step solves.
type ImplicitSprings<'w, 's> = IndexedQuery<'w, 's, Spring, With<ImplicitSpring>>;

/// A body or spring count as the scratch's `u32` indices store it.
fn narrow(n: usize) -> u32 {
    u32::try_from(n).expect("fewer than 2³² implicit bodies")
}

/// A spring of an implicit group as the solver takes it, with the index of its first end (an
/// implicit body), or `None` when the spring does not act this step (an end missing or
/// rejected).
fn group_spring(
    index: &EntityHashMap<usize>,
    local: &[usize],
    others: &Query<&Pose, (With<RigidBody>, Without<ImplicitBody>)>,
    spring: &Spring,
) -> Option<(usize, GroupSpring)> {
    // Orient each spring so that its first end is an implicit body.
    let (first, anchor_first, second) = match (ends_in(index, spring), spring.b) {
        ((Some(i), _), _) => (i, spring.anchor_a, spring.b),
        ((None, Some(j)), SpringEnd::Body { anchor, .. }) => (
            j,
            anchor,
            SpringEnd::Body {
                body: spring.a,
                anchor: spring.anchor_a,
            },
        ),
        _ => return None,
    };
    let end = match second {
        SpringEnd::World(p) => LinkEnd::Fixed(p),
        SpringEnd::Body { body, anchor } => match index.get(&body) {
            Some(&k) => LinkEnd::Body {
                index: local[k],
                anchor,
            },
            // A static, kinematic or quarantined body holds its anchor still; a spring to one
            // whose pose game code made bad exerts nothing (that body is refused, see
            // `check_fixed_bodies`).
            None => {
                let point = others.get(body).ok()?.transform_point(anchor);
                LinkEnd::Fixed(point.is_finite().then_some(point)?)
            }
        },
    };
    Some((
        first,
        GroupSpring {
            a: local[first],
            anchor_a: anchor_first,
            b: end,
            stiffness: spring.stiffness,
            rest_length: spring.rest_length,
        },
    ))
}

/// Fills `starts` (length `groups + 1`) with the prefix sums of how many of `keys` fall in each
/// group: group `g`'s items go to `starts[g]..starts[g + 1]`.
fn counting_starts(starts: &mut Vec<usize>, groups: usize, keys: impl Iterator<Item = usize>) {
    starts.clear();
    starts.resize(groups + 1, 0);
    for g in keys {
        starts[g + 1] += 1;
    }
    for g in 0..groups {
        starts[g + 1] += starts[g];
    }
}
