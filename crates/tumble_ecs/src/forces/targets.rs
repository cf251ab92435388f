//! The bodies force generators push on, found by entity through a table the force system keeps.
//!
//! A generator names its body by entity, so a force system looks a body up once per generator
//! (a spring: twice). Through the query (`get_mut`, `get_many_mut`) every lookup resolves the
//! entity's archetype and table, checks the query's filters and marks the accumulator changed:
//! about a hundred instructions, more than the force itself costs. Instead the system takes
//! each table of targets as column slices once per run, and remembers where each entity sits
//! (`(table, row)` by entity index), so a lookup is an index and a check that the entity found
//! is the one asked for. The accumulator columns are marked changed once, as a whole.
//!
//! A world whose targets span more than [`MAX_TABLES`] tables takes the query's lookups: the
//! same bodies and the same arithmetic in the same order, so the same bits.

use bevy_ecs::change_detection::ContiguousMut;
use bevy_ecs::prelude::*;

use crate::components::Rejected;
use crate::components::dense;
use crate::components::{ForceAccumulator, MassProps, Pose, RigidBody, Velocity};
use crate::parallel::MAX_RUNS;

/// The bodies force generators write to: valid rigid bodies (with a velocity) that have an
/// accumulator.
pub type ForceTargets<'w, 's> = Query<
    'w,
    's,
    (
        Entity,
        &'static Pose,
        &'static MassProps,
        &'static mut ForceAccumulator,
    ),
    (With<RigidBody>, With<Velocity>, Without<Rejected>),
>;

/// Tables of targets a force system holds at once (on the stack: a step does not allocate).
const MAX_TABLES: usize = 16;

/// Where each target entity was found by the last run: `(table, row)` at its entity index.
/// Entries of entities that are no longer targets stay in place: a lookup checks the entity it
/// finds. Grows with the world, never per step.
#[derive(Debug, Default)]
pub struct TargetRows(Vec<(u32, u32)>);

/// Where a target sits, as one ordered number: its table in the high half, its row in the low
/// (see [`Targets::key`]). Pushes whose targets' keys fall in disjoint ranges write disjoint
/// rows, so they can be added on different threads ([`Targets::shares`]).
pub(crate) type TargetKey = u64;

/// One table of targets as column slices.
pub(crate) struct TargetTable<'a> {
    entities: &'a [Entity],
    transforms: &'a [Pose],
    masses: &'a [MassProps],
    accumulators: &'a mut [ForceAccumulator],
}

impl TargetTable<'_> {
    /// True when `entity` sits at `row` (the row table is checked against the table itself:
    /// an entity index can be reused by another entity).
    #[inline]
    fn holds(&self, row: usize, entity: Entity) -> bool {
        self.entities.get(row) == Some(&entity)
    }
}

/// A force system's targets: its tables and where each entity sits in them, or the query
/// itself when they span too many tables.
#[expect(
    clippy::large_enum_variant,
    reason = "one per force system run, on the stack because a step does not allocate"
)]
pub(crate) enum Targets<'a, 'w, 's> {
    /// At most [`MAX_TABLES`] tables, found through `rows`.
    Tables {
        tables: [Option<TargetTable<'a>>; MAX_TABLES],
        rows: &'a [(u32, u32)],
    },
    /// Lookups through the query.
    Query(&'a mut ForceTargets<'w, 's>),
}

impl<'a, 'w, 's> Targets<'a, 'w, 's> {
    /// The targets of `query`, their rows recorded in `rows`.
    pub(crate) fn of(query: &'a mut ForceTargets<'w, 's>, rows: &'a mut TargetRows) -> Self {
        if dense(query.contiguous_iter_mut()).count() > MAX_TABLES {
            return Targets::Query(query);
        }
        let rows = &mut rows.0;
        let mut tables: [Option<TargetTable<'a>>; MAX_TABLES] = std::array::from_fn(|_| None);
        let columns = dense(query.contiguous_iter_mut());
        for (t, (slot, (entities, transforms, masses, accumulators))) in
            tables.iter_mut().zip(columns).enumerate()
        {
            for (row, entity) in entities.iter().enumerate() {
                let at = entity.index_u32() as usize;
                if at >= rows.len() {
                    rows.resize(at + 1, (u32::MAX, u32::MAX));
                }
                rows[at] = (t as u32, row as u32);
            }
            *slot = Some(TargetTable {
                entities,
                transforms,
                masses,
                // Marks the whole column changed, once.
                accumulators: ContiguousMut::split(accumulators).0,
            });
        }
        Targets::Tables { tables, rows }
    }

    /// Where `entity` was when the row table was built: `(table, row)`, to be confirmed with
    /// [`TargetTable::holds`].
    #[inline]
    fn slot(rows: &[(u32, u32)], entity: Entity) -> Option<(usize, usize)> {
        let &(t, row) = rows.get(entity.index_u32() as usize)?;
        Some((t as usize, row as usize))
    }

    /// The pose and mass of target `entity`.
    #[inline]
    pub(crate) fn body(&self, entity: Entity) -> Option<(&Pose, &MassProps)> {
        match self {
            Targets::Tables { tables, rows } => {
                let (t, row) = Self::slot(rows, entity)?;
                let table = tables.get(t)?.as_ref()?;
                table
                    .holds(row, entity)
                    .then(|| (&table.transforms[row], &table.masses[row]))
            }
            Targets::Query(query) => query.get(entity).ok().map(|(_, t, m, _)| (t, m)),
        }
    }

    /// The key of target `entity` (`None` where it is not one, or where the targets are the
    /// query's: those have no rows to share).
    #[inline]
    pub(crate) fn key(&self, entity: Entity) -> Option<TargetKey> {
        let Targets::Tables { tables, rows } = self else {
            return None;
        };
        let (t, row) = Self::slot(rows, entity)?;
        let table = tables.get(t)?.as_ref()?;
        table
            .holds(row, entity)
            .then_some(((t as u64) << 32) | row as u64)
    }

    /// The accumulators cut into consecutive shares at `bounds` (increasing keys, at most
    /// [`MAX_RUNS`]` − 1`): share `k` holds the targets with keys from `bounds[k − 1]` (the
    /// first: from 0) up to `bounds[k]` (the last: every key after), the rows of each table
    /// that hold them, and pushes to nothing else. `None` for the query's targets.
    pub(crate) fn shares(
        &mut self,
        bounds: &[TargetKey],
    ) -> Option<[Option<TargetShare<'_>>; MAX_RUNS]> {
        let Targets::Tables { tables, rows } = self else {
            return None;
        };
        assert!(bounds.len() < MAX_RUNS, "at most MAX_RUNS shares");
        let rows: &[(u32, u32)] = rows;
        let mut shares: [Option<TargetShare<'_>>; MAX_RUNS] = std::array::from_fn(|k| {
            (k <= bounds.len()).then(|| TargetShare {
                rows,
                tables: std::array::from_fn(|_| None),
            })
        });
        for (t, table) in tables.iter_mut().enumerate() {
            let Some(table) = table else { continue };
            let entities = table.entities;
            let mut rest: &mut [ForceAccumulator] = &mut *table.accumulators;
            let mut first_row = 0;
            for (k, share) in shares.iter_mut().flatten().enumerate() {
                // The rows of table `t` below the next share's first key.
                let end = bounds.get(k).map_or(entities.len(), |&bound| {
                    match (bound >> 32).cmp(&(t as u64)) {
                        std::cmp::Ordering::Less => 0,
                        std::cmp::Ordering::Equal => (bound as u32 as usize).min(entities.len()),
                        std::cmp::Ordering::Greater => entities.len(),
                    }
                });
                let (mine, after) =
                    std::mem::take(&mut rest).split_at_mut(end.max(first_row) - first_row);
                share.tables[t] = Some(ShareTable {
                    entities,
                    first_row,
                    accumulators: mine,
                });
                first_row = end.max(first_row);
                rest = after;
            }
        }
        Some(shares)
    }

    /// Applies `add` to the accumulator of target `entity` (nothing if it is not a target).
    #[inline]
    pub(crate) fn push(&mut self, entity: Entity, add: impl FnOnce(&mut ForceAccumulator)) {
        match self {
            Targets::Tables { tables, rows } => {
                if let Some((t, row)) = Self::slot(rows, entity)
                    && let Some(Some(table)) = tables.get_mut(t)
                    && table.holds(row, entity)
                {
                    add(&mut table.accumulators[row]);
                }
            }
            Targets::Query(query) => {
                if let Ok((_, _, _, mut acc)) = query.get_mut(entity) {
                    add(&mut acc);
                }
            }
        }
    }
}

/// What force pushes are added to: every target ([`Targets`]) or one thread's share of them
/// ([`TargetShare`]).
pub(crate) trait PushTarget {
    /// Applies `add` to the accumulator of target `entity` (nothing if it is not a target).
    fn push(&mut self, entity: Entity, add: impl FnOnce(&mut ForceAccumulator));
}

impl PushTarget for Targets<'_, '_, '_> {
    #[inline]
    fn push(&mut self, entity: Entity, add: impl FnOnce(&mut ForceAccumulator)) {
        Targets::push(self, entity, add);
    }
}

/// One thread's share of the targets' accumulators ([`Targets::shares`]).
pub(crate) struct TargetShare<'a> {
    rows: &'a [(u32, u32)],
    tables: [Option<ShareTable<'a>>; MAX_TABLES],
}

/// The rows of one table a [`TargetShare`] holds: `accumulators[k]` is row `first_row + k`.
struct ShareTable<'a> {
    entities: &'a [Entity],
    first_row: usize,
    accumulators: &'a mut [ForceAccumulator],
}

impl PushTarget for TargetShare<'_> {
    #[inline]
    fn push(&mut self, entity: Entity, add: impl FnOnce(&mut ForceAccumulator)) {
        if let Some((t, row)) = Targets::slot(self.rows, entity)
            && let Some(Some(table)) = self.tables.get_mut(t)
            && table.entities.get(row) == Some(&entity)
        {
            let at = row.wrapping_sub(table.first_row);
            debug_assert!(
                at < table.accumulators.len(),
                "a push outside its share: the shares were cut between pushes to one body"
            );
            if let Some(acc) = table.accumulators.get_mut(at) {
                add(acc);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use bevy_ecs::system::SystemState;

    use super::*;
    use crate::prelude::*;
    use tumble_core::math::{Quat, Real, Vec3};

    /// A marker that splits bodies into archetypes (tables) without changing their physics.
    #[derive(Component)]
    struct Tag<const N: usize>;

    const BODIES: usize = 20;

    /// A chain of [`BODIES`] asymmetric bodies joined by springs at off-centre anchors and
    /// tied to the world, each pushed by a force at a point, every third twisted by a torque;
    /// `spread` puts every body in a table of its own.
    fn world(spread: bool) -> World {
        let mut world = World::new();
        world.insert_resource(
            PhysicsSettings::new(1.0 / 60.0, Integrator::Splitting)
                .unwrap()
                .with_springs(SpringSolver::Explicit),
        );
        world.insert_resource(Parallelism::SINGLE_THREAD);
        world.insert_resource(Gravity(Vec3::new(0.0, -9.81, 0.0)));
        let bodies: Vec<Entity> = (0..BODIES)
            .map(|i| {
                let x = i as Real;
                let mass = MassProperties::new(
                    Mass::new(1.0 + 0.1 * x).unwrap(),
                    Vec3::new(0.02, 0.03, 0.04 + 0.0005 * x),
                )
                .unwrap();
                let mut body = world.spawn((
                    RigidBody,
                    MassProps(mass),
                    Pose {
                        translation: Vec3::new(x, 0.0, 0.0),
                        rotation: Quat::from_rotation_z(0.3 * x),
                    },
                    Velocity {
                        linear: Vec3::new(0.0, 0.1 * x, 0.0),
                        angular: Vec3::new(0.1, 0.2, 0.3 * x),
                    },
                ));
                if spread {
                    let bit = |k: usize| (i >> k) & 1 == 1;
                    if bit(0) {
                        body.insert(Tag::<0>);
                    }
                    if bit(1) {
                        body.insert(Tag::<1>);
                    }
                    if bit(2) {
                        body.insert(Tag::<2>);
                    }
                    if bit(3) {
                        body.insert(Tag::<3>);
                    }
                    if bit(4) {
                        body.insert(Tag::<4>);
                    }
                }
                body.id()
            })
            .collect();
        world.spawn(Spring::new(
            bodies[0],
            Vec3::new(-0.1, 0.05, 0.0),
            SpringEnd::World(Vec3::new(-1.0, 0.1, 0.0)),
            200.0,
            0.8,
        ));
        for (i, pair) in bodies.windows(2).enumerate() {
            let end = SpringEnd::on_body(pair[1], Vec3::new(-0.1, 0.0, 0.05));
            let k = 150.0 + 10.0 * i as Real;
            world.spawn(Spring::new(pair[0], Vec3::new(0.1, 0.05, 0.0), end, k, 0.7));
        }
        for (i, &body) in bodies.iter().enumerate() {
            world.spawn(ConstantForce {
                body,
                force: Vec3::new(0.5, 0.2 * i as Real, 0.0),
                local_point: Some(Vec3::new(0.0, 0.05, 0.02)),
            });
            if i % 3 == 0 {
                world.spawn(ConstantTorque {
                    body,
                    torque: Vec3::new(0.0, 0.0, 0.01),
                });
            }
        }
        world
    }

    /// Whether the force systems of `world` look bodies up through their tables.
    fn through_tables(world: &mut World) -> bool {
        let mut state = SystemState::<ForceTargets>::new(world);
        let mut query = state.get_mut(world).expect("the query's resources exist");
        let mut rows = TargetRows::default();
        matches!(Targets::of(&mut query, &mut rows), Targets::Tables { .. })
    }

    /// The tables and the query's own lookups push the same forces in the same order: the same
    /// bits, step after step.
    #[test]
    fn table_lookups_and_query_lookups_give_the_same_bits() {
        let (mut tables, mut spread) = (world(false), world(true));
        assert!(through_tables(&mut tables));
        assert!(
            !through_tables(&mut spread),
            "{BODIES} tables are more than MAX_TABLES"
        );
        let (plan_t, plan_s) = (
            PhysicsPlan::for_world(&mut tables),
            PhysicsPlan::for_world(&mut spread),
        );
        let (mut schedule_t, mut schedule_s) = (plan_t.build_schedule(), plan_s.build_schedule());
        for _ in 0..300 {
            plan_t.run_step(&mut schedule_t, &mut tables);
            plan_s.run_step(&mut schedule_s, &mut spread);
        }
        let states = |world: &mut World| {
            let mut query = world.query::<(Entity, &Pose, &Velocity)>();
            let mut states: Vec<(Entity, [Real; 13])> = query
                .iter(world)
                .map(|(e, t, v)| {
                    let mut bits = [0.0; 13];
                    bits[..3].copy_from_slice(&t.translation.to_array());
                    bits[3..7].copy_from_slice(&t.rotation.to_array());
                    bits[7..10].copy_from_slice(&v.linear.to_array());
                    bits[10..].copy_from_slice(&v.angular.to_array());
                    (e, bits)
                })
                .collect();
            states.sort_by_key(|(e, _)| *e);
            states
        };
        let (a, b) = (states(&mut tables), states(&mut spread));
        assert_eq!(a.len(), BODIES);
        for ((ea, sa), (eb, sb)) in a.iter().zip(&b) {
            assert_eq!(ea, eb);
            assert_eq!(sa.map(Real::to_bits), sb.map(Real::to_bits), "{ea}");
        }
        // The chain did move under its loads.
        assert!(
            a.iter()
                .any(|(_, s)| s[7..10].iter().any(|v| v.abs() > 1.0))
        );
    }
}
