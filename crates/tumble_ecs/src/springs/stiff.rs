//! Classification of spring groups into implicit and explicit, and the implicit solve system.

use bevy_ecs::entity::EntityHashMap;
use bevy_ecs::prelude::*;

use tumble_core::integrate::ExactSwitch;
use tumble_core::math::{Real, Vec3};
use tumble_core::springs::{
    AUTO_REFERENCE_DT, GroupBody, GroupRotation, GroupSpring, IMPLICIT_OMEGA_DT,
    ImplicitSpringSolver, LinkEnd, inverse_effective_mass_bound, omega_dt_bound,
    turning_compliance,
};

use crate::components::{
    BodyError, BodyErrorKind, Dynamic, ForceAccumulator, ImplicitBody, ImplicitSpring, MassProps,
    PhysicsSettings, Pose, RigidBody, Spring, SpringEnd, SpringSolver, SpringTurn, Stepped,
    body_state, check_body, reject, write_body_state,
};
use crate::integrate::damp;

use crate::components::{IndexOrder, IndexedQuery};

/// What the classification was made for; a change re-classifies.
#[derive(Resource, Debug, Clone, Copy, PartialEq)]
pub struct SpringClassification {
    dt: Real,
    solver: SpringSolver,
    springs: usize,
}

/// The span the explicit spring step's accuracy is judged on, as if it were one plain step
/// (`Δt` without substeps, `Δt/N` with `N`, `0.44 Δt/N` for `yoshida4`'s composition: see
/// [`Stages::accuracy_span`](tumble_core::integrate::Stages::accuracy_span)), with `Δt` no finer
/// than [`AUTO_REFERENCE_DT`] (see there: refining the step does not change the
/// classification).
pub(crate) fn classification_span(settings: &PhysicsSettings) -> Real {
    settings
        .stages()
        .accuracy_span(settings.dt().max(AUTO_REFERENCE_DT))
}

/// Number of spring entities, from the archetypes (no query state needed).
fn spring_count(world: &World) -> usize {
    let Some(id) = world.component_id::<Spring>() else {
        return 0;
    };
    world
        .archetypes()
        .iter()
        .filter(|a| a.contains(id))
        .map(|a| a.len() as usize)
        .sum()
}

/// True when [`classify_springs`] must run again: the time step, the setting or the number of
/// springs changed since it last ran.
pub fn classification_is_stale(world: &World) -> bool {
    let settings = world
        .get_resource::<PhysicsSettings>()
        .copied()
        .unwrap_or_default();
    let springs = spring_count(world);
    match world.get_resource::<SpringClassification>() {
        None => springs > 0,
        Some(c) => {
            c.dt != classification_span(&settings)
                || c.solver != settings.springs
                || c.springs != springs
        }
    }
}

/// The indices (in `index`) of a spring's two ends, `None` for an end outside it (a world anchor
/// or a body that is not indexed).
fn ends_in(index: &EntityHashMap<usize>, spring: &Spring) -> (Option<usize>, Option<usize>) {
    let a = index.get(&spring.a).copied();
    let b = match spring.b {
        SpringEnd::Body { body, .. } => index.get(&body).copied(),
        SpringEnd::World(_) => None,
    };
    (a, b)
}

fn find(parent: &mut [usize], mut i: usize) -> usize {
    while parent[i] != i {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    i
}

/// A spring as the classification sees it: its ends as indices into the dynamic bodies' masses
/// (`None`: a world anchor, or a body that is not dynamic), its body-local anchors and its
/// stiffness.
#[derive(Debug, Clone, Copy)]
pub struct ClassifiedSpring {
    /// The index of end `a`'s body.
    pub a: Option<usize>,
    /// End `a`'s anchor, body-local.
    pub anchor_a: Vec3,
    /// The index of end `b`'s body.
    pub b: Option<usize>,
    /// End `b`'s anchor, body-local (unused for a world anchor).
    pub anchor_b: Vec3,
    /// `k` (N/m).
    pub stiffness: Real,
}

/// What [`classify`] decides: per spring, whether the implicit step solves it; per body,
/// whether it is in an implicit group and the [`SpringTurn`] it carries.
#[derive(Debug, Clone, Default)]
pub struct Classification {
    /// Per spring, stepped implicitly.
    pub implicit_springs: Vec<bool>,
    /// Per body, in an implicit group.
    pub implicit_bodies: Vec<bool>,
    /// Per body, how fast its springs turn it (`None`: they cannot).
    pub turns: Vec<Option<SpringTurn>>,
}

/// The spring classification of dynamic bodies of mass `masses` joined by `springs` (given in
/// entity index order: a body's sums over its springs follow it) under `settings` (see the
/// module docs). [`classify_springs`] applies it to a world; code that spawns a world whose
/// springs it knows (a scene file) can spawn each body and spring with the markers it will
/// carry, so that none moves to another table when the world is planned (a move leaves the
/// table it left at its size).
pub fn classify<I>(settings: &PhysicsSettings, masses: &[MassProps], springs: I) -> Classification
where
    I: IntoIterator<Item = ClassifiedSpring>,
    I::IntoIter: Clone,
{
    // Walked three times rather than collected: a million springs would be held twice.
    let springs = springs.into_iter();
    let dt = classification_span(settings);
    let mut parent: Vec<usize> = (0..masses.len()).collect();
    let mut stiff_group = vec![false; masses.len()];
    let mut spring_root: Vec<Option<u32>> = Vec::new();
    // Per spring, its inverse effective mass bounds `ι`; per body, `Σ k (ι_a + ι_b)` over its
    // springs (see the module docs).
    let bound = |end: Option<usize>, anchor| {
        end.map_or(0.0, |i| inverse_effective_mass_bound(&masses[i], anchor))
    };
    let iotas: Vec<[Real; 2]> = springs
        .clone()
        .map(|s| [bound(s.a, s.anchor_a), bound(s.b, s.anchor_b)])
        .collect();
    spring_root.reserve_exact(iotas.len());
    let mut pull: Vec<Real> = vec![0.0; masses.len()];
    for (spring, iota) in springs.clone().zip(&iotas) {
        for i in [spring.a, spring.b].into_iter().flatten() {
            pull[i] += spring.stiffness * (iota[0] + iota[1]);
        }
    }
    let rates = turn_rates(
        masses,
        springs.clone().flat_map(|s| {
            [(s.a, s.anchor_a), (s.b, s.anchor_b)]
                .into_iter()
                .filter_map(move |(end, anchor)| Some((end?, anchor, s.stiffness)))
        }),
    );
    for (spring, &iota) in springs.zip(&iotas) {
        // A body's pull includes this spring's own `k (ι_a + ι_b)`; a spring without a dynamic
        // end joins no group, and its own bound is all there is.
        let own = omega_dt_bound(spring.stiffness, iota, dt);
        let omega_dt = [spring.a, spring.b]
            .into_iter()
            .flatten()
            .map(|i| pull[i].sqrt() * dt)
            .fold(own, Real::max);
        let stiff = match settings.springs {
            SpringSolver::Auto => omega_dt >= IMPLICIT_OMEGA_DT,
            SpringSolver::Implicit => true,
            SpringSolver::Explicit => false,
        };
        let root = match (spring.a, spring.b) {
            (Some(i), Some(j)) => {
                let (ri, rj) = (find(&mut parent, i), find(&mut parent, j));
                let merged = stiff_group[ri] || stiff_group[rj];
                parent[ri] = rj;
                stiff_group[rj] = merged;
                Some(rj)
            }
            (Some(i), None) | (None, Some(i)) => Some(find(&mut parent, i)),
            (None, None) => None,
        };
        if let Some(r) = root {
            stiff_group[r] |= stiff;
        }
        spring_root.push(root.map(|r| r as u32));
    }
    let implicit_springs = spring_root
        .into_iter()
        .map(|root| root.is_some_and(|r| stiff_group[find(&mut parent, r as usize)]))
        .collect();
    let implicit_bodies = (0..masses.len())
        .map(|i| stiff_group[find(&mut parent, i)])
        .collect();
    Classification {
        implicit_springs,
        implicit_bodies,
        turns: rates
            .into_iter()
            .map(|rate| (rate > 0.0).then(|| SpringTurn::new(rate)))
            .collect(),
    }
}

/// Decides which spring groups are stepped implicitly and marks them (see the module docs and
/// [`classify`]).
pub fn classify_springs(world: &mut World) {
    let settings = world
        .get_resource::<PhysicsSettings>()
        .copied()
        .unwrap_or_default();
    let dt = classification_span(&settings);
    // In entity order: a body's sums over its springs must not follow the order a query
    // visits the spring tables in (see `ImplicitScratch::sort_by_entity`).
    let mut springs: Vec<(Entity, Spring)> = world
        .query::<(Entity, &Spring)>()
        .iter(world)
        .map(|(e, s)| (e, *s))
        .collect();
    springs.sort_unstable_by_key(|(e, _)| e.index_u32());
    let mut dynamic = world.query_filtered::<(Entity, &MassProps), Dynamic>();
    let mut index = EntityHashMap::default();
    let mut masses = Vec::new();
    for (entity, mass) in dynamic.iter(world) {
        index.insert(entity, masses.len());
        masses.push(*mass);
    }
    let classified = springs.iter().map(|(_, spring)| {
        let (a, b) = ends_in(&index, spring);
        ClassifiedSpring {
            a,
            anchor_a: spring.anchor_a,
            b,
            anchor_b: match spring.b {
                SpringEnd::Body { anchor, .. } => anchor,
                SpringEnd::World(_) => Vec3::ZERO,
            },
            stiffness: spring.stiffness,
        }
    });
    let Classification {
        implicit_springs: implicit_spring,
        implicit_bodies: implicit_body,
        turns,
    } = classify(&settings, &masses, classified);
    mark_stiff(world, &springs, implicit_spring, &index, &implicit_body);
    // After the implicit markers, in a pass of its own: the order components are added in
    // decides which bodies share a table.
    mark_turn_rates(world, &index, &turns);
    let springs = spring_count(world);
    world.insert_resource(SpringClassification {
        dt,
        solver: settings.springs,
        springs,
    });
}

/// Per body (an index into `masses`), how fast its springs can turn it: `ω_turn = √(Σ k c)`
/// over its spring ends `(body, body-local anchor, stiffness k)`, summed in the order given, `c`
/// the end's [`turning_compliance`] (see [`SpringTurn`]).
fn turn_rates(
    masses: &[MassProps],
    ends: impl IntoIterator<Item = (usize, Vec3, Real)>,
) -> Vec<Real> {
    let mut turn: Vec<Real> = vec![0.0; masses.len()];
    for (i, anchor, stiffness) in ends {
        turn[i] += stiffness * turning_compliance(&masses[i], anchor);
    }
    for t in &mut turn {
        *t = t.sqrt();
    }
    turn
}

/// Puts [`ImplicitSpring`] on the springs and [`ImplicitBody`] on the bodies the classification
/// found stiff (`implicit_spring` per spring, `implicit_body` per dynamic body of `index`), and
/// takes them off the others.
fn mark_stiff(
    world: &mut World,
    springs: &[(Entity, Spring)],
    implicit_spring: Vec<bool>,
    index: &EntityHashMap<usize>,
    implicit_body: &[bool],
) {
    for ((entity, _), stiff) in springs.iter().zip(implicit_spring) {
        let has = world.get::<ImplicitSpring>(*entity).is_some();
        if stiff && !has {
            world.entity_mut(*entity).insert(ImplicitSpring);
        } else if !stiff && has {
            world.entity_mut(*entity).remove::<ImplicitSpring>();
        }
    }
    for entity in rigid_bodies(world) {
        let stiff = index.get(&entity).is_some_and(|&i| implicit_body[i]);
        let has = world.get::<ImplicitBody>(entity).is_some();
        if stiff && !has {
            world.entity_mut(entity).insert(ImplicitBody::default());
        } else if !stiff && has {
            world.entity_mut(entity).remove::<ImplicitBody>();
        }
    }
}

/// Puts its [`SpringTurn`] on every dynamic body of `index` whose springs can turn it (`turns`
/// per body), and takes it off the others.
fn mark_turn_rates(world: &mut World, index: &EntityHashMap<usize>, turns: &[Option<SpringTurn>]) {
    for entity in rigid_bodies(world) {
        let turn = index.get(&entity).and_then(|&i| turns[i]);
        match (turn, world.get::<SpringTurn>(entity).copied()) {
            (Some(turn), Some(has)) if has == turn => {}
            (Some(turn), _) => {
                world.entity_mut(entity).insert(turn);
            }
            (None, Some(_)) => {
                world.entity_mut(entity).remove::<SpringTurn>();
            }
            (None, None) => {}
        }
    }
}

/// Every rigid body, in query order (as the world's tables stand now).
fn rigid_bodies(world: &mut World) -> Vec<Entity> {
    world
        .query_filtered::<Entity, With<RigidBody>>()
        .iter(world)
        .collect()
}

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
    mut scratch: Local<ImplicitScratch>,
    mut commands: Commands,
    springs: ImplicitSprings,
    mut bodies: Query<
        (Stepped<&mut ForceAccumulator>, &mut ImplicitBody),
        (Dynamic, With<ImplicitBody>),
    >,
    others: Query<&Pose, (With<RigidBody>, Without<ImplicitBody>)>,
) {
    let s = &mut *scratch;
    s.index.clear();
    s.entities.clear();
    s.parent.clear();
    s.all.clear();
    let span = cursor.span(&settings);
    let dt = span.h;
    let half_substep = 0.5 * span.substep;
    let switch = ExactSwitch::new(settings.integrator, settings.free_flow, span.substep);
    let judged = classification_span(&settings);
    // Exact sizes (see `ImplicitSpringSolver`'s buffers): a group may hold every body.
    let count = bodies.iter().len();
    s.entities.reserve_exact(count);
    s.parent.reserve_exact(count);
    s.all.reserve_exact(count);
    s.index.reserve(count);
    for ((entity, t, mut v, m, mut acc, damping, turn), mut implicit) in &mut bodies {
        // Bad data game code wrote into one body is refused for that body alone, naming the
        // field, as on the explicit path: left out here, it is not in its group this stage
        // (its springs exert nothing, as a quarantined body's), and its components and
        // accumulator stay as they are. The point forces' moment is this stage's only (no
        // snapshot holds it): it goes with the stage.
        let checked =
            check_body(&t, &v, Some(&acc)).and_then(|()| damping.map_or(Ok(()), |d| d.check()));
        if let Err(kind) = checked {
            implicit.take_load_moment();
            reject(&mut commands, BodyError { entity, kind });
            continue;
        }
        // `Damping` is a flow of its own, half a substep before the substep and half after (see
        // `tumble_core::damping`), as on the explicit path.
        if let Some(d) = damping
            && span.opens_substep
        {
            let v = &mut *v;
            damp(d, half_substep, &mut v.linear, &mut v.angular);
        }
        s.parent.push(s.entities.len());
        s.entities.push(entity);
        let state = body_state(&t, &v, m);
        let turn = turn.copied().unwrap_or_default();
        let rotation = group_rotation(&settings, switch.as_ref(), judged, turn, &state, &m.0);
        s.all.push(GroupBody {
            state,
            mass: m.0,
            load: acc.take(),
            load_moment: implicit.take_load_moment(),
            rotation,
        });
    }
    s.sort_by_entity();
    let mut spring_order = std::mem::take(&mut s.spring_order);
    spring_order.refresh(&springs);
    let groups = s.group_bodies(&springs, &spring_order);
    s.group_springs(&springs, &spring_order, &others, groups);
    s.spring_order = spring_order;
    for g in 0..groups {
        let members = s.member_start[g]..s.member_start[g + 1];
        s.bodies.clear();
        s.bodies
            .extend(s.members[members.clone()].iter().map(|&i| s.all[i]));
        let springs = &s.springs[s.spring_start[g]..s.spring_start[g + 1]];
        match s.solver.step(&mut s.bodies, springs, dt) {
            Ok(stats) => {
                tracing::trace!(
                    bodies = s.bodies.len(),
                    springs = springs.len(),
                    newton = stats.newton_iterations,
                    linear = stats.linear_iterations,
                    splits = stats.splits,
                    evaluations = stats.residual_evaluations,
                    factorizations = stats.factorizations,
                    "implicit spring group stepped"
                );
                for (k, &i) in s.members[members].iter().enumerate() {
                    if let Ok(((_, mut t, mut v, m, _, damping, _), _)) =
                        bodies.get_mut(s.entities[i])
                    {
                        write_body_state(&s.bodies[k].state, m, &mut t, &mut v);
                        if let Some(d) = damping
                            && span.closes_substep
                        {
                            let v = &mut *v;
                            damp(d, half_substep, &mut v.linear, &mut v.angular);
                        }
                    }
                }
            }
            Err(error) => {
                for &i in &s.members[members] {
                    reject(
                        &mut commands,
                        BodyError {
                            entity: s.entities[i],
                            kind: BodyErrorKind::ImplicitSprings(error),
                        },
                    );
                }
            }
        }
    }
}

/// How the implicit solve turns a body of a stiff group (see the module docs): by the world's
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
