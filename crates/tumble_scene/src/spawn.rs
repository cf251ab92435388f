//! Spawning a checked scene into a world without moving a row.
//!
//! A bevy table never shrinks: a row that moves to another table (a component added after the
//! spawn) leaves its old table at its size, so a world whose bodies all moved would hold them
//! twice; and a table grown one spawn at a time doubles, up to twice what it holds. So each
//! body is spawned with every component it will carry (a [`ForceAccumulator`] when a force
//! generator names it, its [`GravityScale`], [`Damping`], and the [`SpringTurn`] and
//! [`ImplicitBody`] the spring classification gives it; a spring its `ImplicitSpring`), and each
//! run of bodies (or of force generators) of one kind by one `spawn_batch`, which reserves the
//! table once for the whole run. Entities are spawned in file order, as one `spawn` each would.

use bevy_ecs::bundle::NoBundleEffect;
use bevy_ecs::prelude::*;
use tumble_core::math::Real;
use tumble_ecs::components::{ImplicitBody, SpringTurn};
use tumble_ecs::prelude::*;
use tumble_ecs::springs::Classification;

use crate::model::ValidBody;

/// A body to spawn and what it carries besides its state.
pub(crate) struct BodySpawn {
    pub(crate) body: ValidBody,
    /// A force generator names it: spawned with its [`ForceAccumulator`] (which the
    /// generator's hook would otherwise add).
    pub(crate) loaded: bool,
    pub(crate) turn: Option<SpringTurn>,
    /// In a stiff spring group: spawned with its [`ImplicitBody`].
    pub(crate) implicit: bool,
}

/// Which optional components a body carries: bodies of one kind share a table.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct BodyKind {
    loaded: bool,
    gravity: bool,
    damping: bool,
    turn: bool,
    implicit: bool,
}

impl BodyKind {
    /// The kind of a body with these components (`loaded`: with an accumulator).
    pub(crate) fn new(
        loaded: bool,
        (gravity_scale, damping): (Real, Damping),
        turn: Option<SpringTurn>,
        implicit: bool,
    ) -> Self {
        Self {
            loaded,
            gravity: gravity_scale != 1.0,
            damping: damping != Damping::default(),
            turn: turn.is_some(),
            implicit,
        }
    }

    /// The kind of `b`.
    fn of(b: &BodySpawn) -> Self {
        Self::new(
            b.loaded,
            (b.body.gravity_scale, b.body.damping),
            b.turn,
            b.implicit,
        )
    }
}

/// Spawns `run`, bodies all of kind `kind` (checked in debug builds), in order, by one
/// `spawn_batch`, handing each entity to `out`. Each optional component picks one of two
/// bundle types in its own stage, so every body of the run has the same bundle type.
pub(crate) fn spawn_bodies(
    world: &mut World,
    kind: BodyKind,
    run: impl ExactSizeIterator<Item = BodySpawn>,
    out: impl FnMut(Entity),
) {
    let state = |b: &BodySpawn| {
        (
            RigidBody,
            MassProps(b.body.mass),
            b.body.transform,
            b.body.velocity,
        )
    };
    let run = run.inspect(move |b| {
        debug_assert_eq!(BodyKind::of(b), kind);
    });
    if kind.loaded {
        with_gravity(
            world,
            kind,
            run,
            move |b| (state(b), ForceAccumulator::default()),
            out,
        );
    } else {
        with_gravity(world, kind, run, state, out);
    }
}

fn with_gravity<B: Bundle<Effect: NoBundleEffect>>(
    world: &mut World,
    kind: BodyKind,
    run: impl ExactSizeIterator<Item = BodySpawn>,
    bundle: impl Fn(&BodySpawn) -> B,
    out: impl FnMut(Entity),
) {
    if kind.gravity {
        let scale = |b: &BodySpawn| GravityScale(b.body.gravity_scale);
        with_damping(world, kind, run, move |b| (bundle(b), scale(b)), out);
    } else {
        with_damping(world, kind, run, bundle, out);
    }
}

fn with_damping<B: Bundle<Effect: NoBundleEffect>>(
    world: &mut World,
    kind: BodyKind,
    run: impl ExactSizeIterator<Item = BodySpawn>,
    bundle: impl Fn(&BodySpawn) -> B,
    out: impl FnMut(Entity),
) {
    if kind.damping {
        with_turn(world, kind, run, move |b| (bundle(b), b.body.damping), out);
    } else {
        with_turn(world, kind, run, bundle, out);
    }
}

fn with_turn<B: Bundle<Effect: NoBundleEffect>>(
    world: &mut World,
    kind: BodyKind,
    run: impl ExactSizeIterator<Item = BodySpawn>,
    bundle: impl Fn(&BodySpawn) -> B,
    out: impl FnMut(Entity),
) {
    if kind.turn {
        let turn = |b: &BodySpawn| b.turn.unwrap_or_default();
        with_implicit(world, kind, run, move |b| (bundle(b), turn(b)), out);
    } else {
        with_implicit(world, kind, run, bundle, out);
    }
}

fn with_implicit<B: Bundle<Effect: NoBundleEffect>>(
    world: &mut World,
    kind: BodyKind,
    run: impl ExactSizeIterator<Item = BodySpawn>,
    bundle: impl Fn(&BodySpawn) -> B,
    out: impl FnMut(Entity),
) {
    if kind.implicit {
        batch(
            world,
            run.map(move |b| (bundle(&b), ImplicitBody::default())),
            out,
        );
    } else {
        batch(world, run.map(move |b| bundle(&b)), out);
    }
}

/// Spawns `bundles` in order by one `spawn_batch` (which reserves the table for all of them
/// at once), handing each entity to `out`.
pub(crate) fn batch<B: Bundle<Effect: NoBundleEffect>>(
    world: &mut World,
    bundles: impl ExactSizeIterator<Item = B>,
    out: impl FnMut(Entity),
) {
    world.spawn_batch(bundles).for_each(out);
}

/// Body `i` (`body`) as it is spawned: with its accumulator when a generator names it
/// (`loaded`) and the markers the spring classification gives it.
fn body_spawn(
    body: ValidBody,
    i: usize,
    loaded: &[bool],
    classified: &Classification,
) -> BodySpawn {
    BodySpawn {
        body,
        loaded: loaded[i],
        turn: classified.turns.get(i).copied().flatten(),
        implicit: classified.implicit_bodies.get(i).copied().unwrap_or(false),
    }
}

/// The runs of equal consecutive values of `kinds`, as `(start, length)`.
pub(crate) fn runs<K: PartialEq>(kinds: &[K]) -> impl Iterator<Item = (usize, usize)> + '_ {
    let mut start = 0;
    std::iter::from_fn(move || {
        let first = kinds.get(start)?;
        let len = kinds[start..].iter().take_while(|k| *k == first).count();
        start += len;
        Some((start - len, len))
    })
}

/// Spawns the bodies in file order, each run of one kind (`kinds`, per body) by one batch;
/// `next(i)` gives body `i`'s name and checked body, once per body, in order.
pub(crate) fn spawn_in_runs(
    world: &mut World,
    kinds: &[BodyKind],
    loaded: &[bool],
    classified: &Classification,
    mut next: impl FnMut(usize) -> (String, ValidBody),
) -> Vec<(String, Entity)> {
    let mut bodies: Vec<(String, Entity)> = Vec::with_capacity(kinds.len());
    for (start, len) in runs(kinds) {
        let run = (start..start + len).map(|i| {
            let (name, body) = next(i);
            bodies.push((name, Entity::PLACEHOLDER));
            body_spawn(body, i, loaded, classified)
        });
        let mut spawned = Vec::with_capacity(len);
        spawn_bodies(world, kinds[start], run, |e| spawned.push(e));
        for (slot, entity) in bodies[start..].iter_mut().zip(spawned) {
            slot.1 = entity;
        }
    }
    bodies
}
