//! Classification of spring groups into implicit and explicit: which groups the implicit
//! step solves, and how fast each body's springs can turn it.

use bevy_ecs::change_detection::Tick;
use bevy_ecs::entity::EntityHashMap;
use bevy_ecs::prelude::*;
use bevy_ecs::world::WorldId;

use tumble_core::math::{Real, Vec3};
use tumble_core::springs::{
    AUTO_REFERENCE_DT, IMPLICIT_OMEGA_DT, inverse_effective_mass_bound, omega_dt_bound,
    turning_compliance,
};

use crate::components::{
    Dynamic, ImplicitBody, ImplicitSpring, MassProps, PhysicsSettings, RigidBody, Spring,
    SpringEnd, SpringSolver, SpringTurn,
};

/// What the classification was made for; a change re-classifies.
#[derive(Resource, Debug, Clone, Copy, PartialEq)]
pub struct SpringClassification {
    dt: Real,
    solver: SpringSolver,
    springs: usize,
    /// The world's change tick when it was made: a spring or a body's mass changed (or added)
    /// since then was not seen by it.
    at: Tick,
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
/// springs changed since it last ran, or a spring (its ends, anchors, stiffness: the same count
/// of springs rewired, or one despawned and another spawned) or a body's mass properties were
/// changed or added since. Builds its queries (the runner keeps its own, as it checks every
/// step).
pub fn classification_is_stale(world: &World) -> bool {
    classification_is_stale_with(world, &mut ClassifiedInputs::default())
}

/// [`classification_is_stale`] with the queries `inputs` keeps.
pub(crate) fn classification_is_stale_with(world: &World, inputs: &mut ClassifiedInputs) -> bool {
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
                || (springs > 0 && inputs.changed_since(world, c.at))
        }
    }
}

/// The queries of what a classification reads that can change in place (springs, bodies'
/// mass properties), kept between steps by a caller that checks every step.
#[derive(Default)]
pub(crate) struct ClassifiedInputs {
    springs: Option<(WorldId, QueryState<Ref<'static, Spring>>)>,
    masses: Option<(
        WorldId,
        QueryState<Ref<'static, MassProps>, With<RigidBody>>,
    )>,
}

impl ClassifiedInputs {
    /// True when a spring or a rigid body's mass properties changed (or were added) after the
    /// change tick `at`: one comparison of change ticks a component, nothing the engine's own
    /// step writes.
    fn changed_since(&mut self, world: &World, at: Tick) -> bool {
        let now = world.read_change_tick();
        let id = world.id();
        if self.springs.as_ref().is_none_or(|(w, _)| *w != id) {
            self.springs = world.try_query::<Ref<Spring>>().map(|q| (id, q));
        }
        if self.masses.as_ref().is_none_or(|(w, _)| *w != id) {
            self.masses = world
                .try_query_filtered::<Ref<MassProps>, With<RigidBody>>()
                .map(|q| (id, q));
        }
        let newer = |tick: Tick| tick.is_newer_than(at, now);
        self.springs
            .as_mut()
            .is_some_and(|(_, q)| q.iter(world).any(|s| newer(s.last_changed())))
            || self
                .masses
                .as_mut()
                .is_some_and(|(_, q)| q.iter(world).any(|m| newer(m.last_changed())))
    }
}

/// The indices (in `index`) of a spring's two ends, `None` for an end outside it (a world anchor
/// or a body that is not indexed).
pub(super) fn ends_in(
    index: &EntityHashMap<usize>,
    spring: &Spring,
) -> (Option<usize>, Option<usize>) {
    let a = index.get(&spring.a).copied();
    let b = match spring.b {
        SpringEnd::Body { body, .. } => index.get(&body).copied(),
        SpringEnd::World(_) => None,
    };
    (a, b)
}

pub(super) fn find(parent: &mut [usize], mut i: usize) -> usize {
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
/// [`springs`](crate::springs) docs). [`classify_springs`] applies it to a world; code that spawns a world whose
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
    // springs (see the `springs` module docs).
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

/// Decides which spring groups are stepped implicitly and marks them (see the [`springs`](crate::springs) docs and
/// [`classify`]).
pub fn classify_springs(world: &mut World) {
    let settings = world
        .get_resource::<PhysicsSettings>()
        .copied()
        .unwrap_or_default();
    let dt = classification_span(&settings);
    // In entity order: a body's sums over its springs must not follow the order a query
    // visits the spring tables in (see `ImplicitScratch::sort_by_entity`). The entities only,
    // each spring read where it is when the walks need it: a copy of a million springs would
    // be the largest table of the plan.
    let mut springs: Vec<Entity> = world
        .query_filtered::<Entity, With<Spring>>()
        .iter(world)
        .collect();
    springs.sort_unstable_by_key(|e| e.index_u32());
    let mut dynamic = world.query_filtered::<(Entity, &MassProps), Dynamic>();
    let mut index = EntityHashMap::default();
    let mut masses = Vec::new();
    for (entity, mass) in dynamic.iter(world) {
        index.insert(entity, masses.len());
        masses.push(*mass);
    }
    let spring = |entity: &Entity| *world.get::<Spring>(*entity).expect("queried with a Spring");
    let classified = springs.iter().map(|entity| {
        let spring = &spring(entity);
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
    // Past this tick: a change game code makes before any system runs again (right after a
    // runner is made, say) gets a newer tick than the classification's, and is seen.
    let at = world.increment_change_tick();
    world.insert_resource(SpringClassification {
        dt,
        solver: settings.springs,
        springs,
        at,
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
    springs: &[Entity],
    implicit_spring: Vec<bool>,
    index: &EntityHashMap<usize>,
    implicit_body: &[bool],
) {
    for (entity, stiff) in springs.iter().zip(implicit_spring) {
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
