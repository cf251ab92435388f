//! Force pushes computed on the compute pool and added to the accumulators in generator order,
//! on as many threads as the generators' bodies allow, with the same bits on any number.
//!
//! A force system (the springs, the constant forces) first computes each generator's *push*
//! (what it adds to which body) from the bodies' poses alone, many at once. The additions must
//! then follow generator order: a body's sum `((a + f₁) + f₂) + …` depends on it. Two runs of
//! consecutive generators can be added on two threads without changing a bit wherever no body
//! takes pushes from both: each body then takes all of its pushes, in order, on one thread.
//! Each push's bodies are ordered by where they sit ([`TargetKey`]: table, row), and a cut
//! between pushes `s − 1` and `s` is clean when every body of the pushes before it sits before
//! every body of the pushes after it; each thread then owns a range of rows
//! ([`Targets::shares`]). Spring chains and constant forces spawned body by body have clean
//! cuts every few generators; a world whose generators jump around its tables has none, and
//! adds on one thread, as before.

use bevy_ecs::prelude::*;

use super::targets::{PushTarget, TargetKey, Targets};
use crate::parallel::{MAX_RUNS, Runs, scope};

/// Generators whose pushes one round computes on the pool at once, then adds: the buffer stays
/// a few megabytes however many there are, and a round is long enough that handing it out costs
/// little beside its work.
pub(super) const PUSH_BLOCK: usize = 1 << 15;

/// A push of a generator `T`: computed from the bodies, added to them later.
pub(super) trait Push<T>: Copy + Default + Send + Sync {
    /// The bodies the push adds to.
    fn bodies(&self, item: &T) -> [Option<Entity>; 2];
    /// Adds the push to its bodies' accumulators.
    fn apply(self, item: &T, targets: &mut impl PushTarget);
}

/// The pushes of one round, kept between steps so that a step does not allocate.
#[derive(Debug, Default)]
pub(super) struct PushBuffer<P> {
    pushes: Vec<P>,
    /// Per push, the smallest and the largest key of its bodies (`(MAX, 0)` for none).
    keys: Vec<(TargetKey, TargetKey)>,
}

/// Computes `of(item, targets)` for every item of `table` on `threads` threads of the compute
/// pool, [`PUSH_BLOCK`] items at a time, then adds each item's push to its bodies in table order:
/// on `threads` threads where the items can be cut into runs that share no body, else on this
/// thread. Either way each body takes its pushes in item order: the same bits on any number of
/// threads. Returns the fewest runs any round was added in (1: some round on this thread).
pub(super) fn push_in_blocks<T: Sync, P: Push<T>>(
    table: &[T],
    threads: usize,
    buffer: &mut PushBuffer<P>,
    targets: &mut Targets,
    of: impl Fn(&T, &Targets) -> P + Sync,
) -> usize {
    let threads = threads.clamp(1, MAX_RUNS);
    let mut fewest = threads;
    for block in table.chunks(PUSH_BLOCK) {
        let PushBuffer { pushes, keys } = buffer;
        pushes.clear();
        pushes.resize(block.len(), P::default());
        keys.clear();
        keys.resize(block.len(), (0, 0));
        let per = block.len().div_ceil(threads).max(1);
        let (shared, of) = (&*targets, &of);
        scope(|spawn| {
            for ((items, out), spans) in block
                .chunks(per)
                .zip(pushes.chunks_mut(per))
                .zip(keys.chunks_mut(per))
            {
                spawn(Box::new(move || {
                    for ((item, push), span) in items.iter().zip(out.iter_mut()).zip(spans) {
                        *push = of(item, shared);
                        *span = key_span(push.bodies(item), shared);
                    }
                }));
            }
        });
        let keys = &*keys;
        let runs = Runs::of_keys(block.len(), threads, |i| Some(keys[i]));
        fewest = fewest.min(runs.count());
        let Some(parts) = (runs.count() > 1)
            .then(|| targets.shares(runs.bounds()))
            .flatten()
        else {
            for (item, push) in block.iter().zip(pushes.iter()) {
                push.apply(item, targets);
            }
            continue;
        };
        let pushes = &*pushes;
        scope(|spawn| {
            for (k, share) in parts.into_iter().flatten().enumerate() {
                let range = runs.items(k);
                let (items, pushes) = (&block[range.clone()], &pushes[range]);
                let mut share = share;
                spawn(Box::new(move || {
                    for (item, push) in items.iter().zip(pushes) {
                        push.apply(item, &mut share);
                    }
                }));
            }
        });
    }
    fewest
}

/// The smallest and largest key of a push's bodies (`(MAX, 0)` for none: it adds nothing).
#[inline]
fn key_span(bodies: [Option<Entity>; 2], targets: &Targets) -> (TargetKey, TargetKey) {
    bodies
        .into_iter()
        .flatten()
        .filter_map(|body| targets.key(body))
        .fold((TargetKey::MAX, 0), |(lo, hi), key| {
            (lo.min(key), hi.max(key))
        })
}

#[cfg(test)]
mod tests {
    use bevy_ecs::system::SystemState;
    use tumble_core::math::{Real, Vec3, Widen};

    use super::super::targets::{ForceTargets, TargetRows};
    use super::*;
    use crate::components::ForceAccumulator;
    use crate::prelude::*;

    /// A pair of bodies pulled together by a force: `f` on `a`, `−f` on `b`.
    struct Pull {
        a: Entity,
        b: Entity,
        f: Vec3,
    }

    impl Push<Pull> for Option<Vec3> {
        fn bodies(&self, pull: &Pull) -> [Option<Entity>; 2] {
            [Some(pull.a), Some(pull.b)]
        }
        fn apply(self, pull: &Pull, targets: &mut impl PushTarget) {
            if let Some(f) = self {
                targets.push(pull.a, |acc| acc.add_force(f));
                targets.push(pull.b, |acc| acc.add_force(-f));
            }
        }
    }

    /// Bodies in chains of `chain` (pulls between neighbours), plus `far` pulls between bodies
    /// half the world apart, added on `threads` threads: each body's force and the fewest runs
    /// a round was added in.
    fn pulled(threads: usize, chain: usize, far: usize) -> (Vec<[u64; 3]>, usize) {
        let mut world = World::new();
        let bodies: Vec<Entity> = (0..3000)
            .map(|i| {
                let mass = MassProperties::new(Mass::new(1.0).unwrap(), Vec3::ONE).unwrap();
                world
                    .spawn((
                        RigidBody,
                        MassProps(mass),
                        Pose::default(),
                        Velocity::default(),
                        ForceAccumulator {
                            force: Vec3::splat(0.1 * i as Real),
                            torque: Vec3::ZERO,
                        },
                    ))
                    .id()
            })
            .collect();
        let mut pulls: Vec<Pull> = bodies
            .chunks(chain)
            .flat_map(|c| c.windows(2))
            .enumerate()
            .map(|(k, pair)| Pull {
                a: pair[0],
                b: pair[1],
                f: Vec3::new(1.0 / (1.0 + k as Real), 0.3, -0.7 / (3.0 + k as Real)),
            })
            .collect();
        // Spread evenly, each from a body near its place in the order to one half the world
        // away: every cut has a body on both sides.
        let (n, len) = (bodies.len(), pulls.len());
        for k in (0..far).rev() {
            let at = k * len / far;
            let a = at * n / len;
            let (a, b) = (bodies[a], bodies[(a + n / 2) % n]);
            let f = Vec3::new(0.11, 1.0 / (5.0 + k as Real), 0.0);
            pulls.insert(at, Pull { a, b, f });
        }
        let mut state = SystemState::<ForceTargets>::new(&mut world);
        let mut query = state
            .get_mut(&mut world)
            .expect("the query's resources exist");
        let mut rows = TargetRows::default();
        let mut targets = Targets::of(&mut query, &mut rows);
        let mut buffer = PushBuffer::default();
        let fewest = push_in_blocks(&pulls, threads, &mut buffer, &mut targets, |pull, _| {
            Some(pull.f)
        });
        let forces = bodies
            .iter()
            .map(|&b| {
                let f = world.get::<ForceAccumulator>(b).unwrap().force;
                f.to_array().map(|x| x.widen().to_bits())
            })
            .collect();
        (forces, fewest)
    }

    #[test]
    fn chains_are_added_on_several_threads_with_the_same_bits() {
        let (one, runs) = pulled(1, 10, 0);
        assert_eq!(runs, 1);
        for threads in [2, 3, 8] {
            let (several, runs) = pulled(threads, 10, 0);
            assert_eq!(runs, threads, "chains of ten cut cleanly");
            assert!(one == several, "{threads} threads changed a sum");
        }
    }

    #[test]
    fn bodies_pulled_across_the_world_are_added_on_one_thread() {
        let (one, _) = pulled(1, 10, 40);
        let (several, runs) = pulled(4, 10, 40);
        assert_eq!(runs, 1, "no clean cut");
        assert!(one == several);
    }
}
