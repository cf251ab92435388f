//! The integrate systems: thin loops over the query's tables that hand each table to the core's
//! batched step (the `table` module: a table run of bodies as a `BodyBatch`).
//!
//! A body whose data is bad or whose step diverges is quarantined with [`Rejected`] and keeps its
//! last valid state — the state the stage found it in, even when the stage's first half drift
//! had moved it ([`StageStarts`]) — and the others step on unharmed.

use bevy_ecs::prelude::*;
use tumble_core::StepPhase;

use super::table::{Bodies, Loads, StageTiming, TableStarts, step_table};
use crate::components::{
    BodyError, Dynamic, ForceAccumulator, Gravity, GravityScale, ImplicitBody, Kinematic,
    PhysicsSettings, Pose, Refusals, Rejected, RigidBody, Static, Stepped, Velocity, check_body,
    dense,
};
use crate::parallel::Parallelism;

/// Steps every table of the query `$bodies` ([`Stepped`] items) through [`step_table`], each
/// table's loads made from its load column by the closure-like last argument, then quarantines
/// the bodies that failed. A macro rather than a function: bevy hands out each load
/// component's contiguous column as a type of its own that borrows the query table by table,
/// which a closure parameter of a function cannot name.
macro_rules! step_each_table {
    ($bodies:ident, $stage:ident, $parallelism:ident, $refusals:ident, |$load:pat_param| $loads:expr) => {
        step_each_table!(
            $bodies,
            $stage,
            $parallelism,
            $refusals,
            |_e| TableStarts::Unused,
            |$load| $loads
        )
    };
    ($bodies:ident, $stage:ident, $parallelism:ident, $refusals:ident, |$e:ident| $starts:expr, |$load:pat_param| $loads:expr) => {{
        let parallelism = $parallelism.map_or_else(Parallelism::default, |p| *p);
        let mut errors = Vec::new();
        for (entities, mut t, mut v, masses, $load, dampings, turns) in
            dense($bodies.contiguous_iter_mut())
        {
            let $e = entities;
            let bodies = Bodies {
                entities,
                transforms: &mut t,
                velocities: &mut v,
                masses,
                dampings,
                turns,
                loads: $loads,
                starts: $starts,
            };
            step_table(&$stage, &parallelism, bodies, &mut errors);
        }
        refuse_all(&mut $refusals, errors);
    }};
}

/// Quarantines the bodies in `errors` (in the order found: table by table, entity order
/// within a table).
fn refuse_all(refusals: &mut Refusals, errors: Vec<BodyError>) {
    for error in errors {
        refusals.refuse(error);
    }
}

/// Zeroes the accumulators of [`Static`] and [`Kinematic`] bodies (springs may push on them;
/// they are never integrated, so the forces are discarded rather than left to pile up). In the
/// schedule only when such a body has an accumulator.
pub fn discard_fixed_body_forces(
    mut bodies: Query<
        &mut ForceAccumulator,
        (With<RigidBody>, Or<(With<Static>, With<Kinematic>)>),
    >,
) {
    for mut acc in &mut bodies {
        if *acc != ForceAccumulator::default() {
            *acc = ForceAccumulator::default();
        }
    }
}

/// Refuses each [`Static`] or [`Kinematic`] body whose data game code made bad (a non-finite
/// translation or velocity, a rotation that is not a unit quaternion), naming the field, as the
/// integrate systems refuse a dynamic body's: tumble never steps such a body, so no step's own
/// check would see it, and springs read its pose and velocity. (The springs exert nothing from
/// a bad end in the step it is found, see `apply_springs`, the dampers and the implicit step.)
/// In the plan of a world with springs and such bodies.
pub fn check_fixed_bodies(
    mut refusals: Refusals,
    bodies: Query<
        (Entity, &Pose, Option<&Velocity>),
        (
            With<RigidBody>,
            Or<(With<Static>, With<Kinematic>)>,
            Without<Rejected>,
        ),
    >,
) {
    for (entity, pose, velocity) in &bodies {
        if let Err(kind) = check_body(pose, velocity.unwrap_or(&Velocity::ZERO), None) {
            refusals.refuse(BodyError { entity, kind });
        }
    }
}

/// Set by [`begin_stage`] when it has drifted the bodies with accumulators half a stage, so
/// that [`integrate_with_forces`] finishes the stage instead of taking a whole one. Reset every
/// stage.
#[derive(Resource, Debug, Default, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct HalfDrifted(pub bool);

/// The state of each body [`begin_stage`] half drifted, from before it did, table by table:
/// a body that [`integrate_with_forces`] then refuses (a load game code or a force made bad,
/// or a step outside the method's stable region) is put back to the state the stage found it
/// in, never left half a stage on. Kept between steps so that a step does not allocate.
#[derive(Resource, Debug, Default)]
pub struct StageStarts {
    /// Per table: its bodies' entities and states, in the table's order.
    tables: Vec<(Vec<Entity>, Vec<(Pose, Velocity)>)>,
    /// The tables saved since the stage began (the rest are left over from earlier stages).
    saved: usize,
}

impl StageStarts {
    /// Where the first half drift saves the bodies of the table `entities` lists.
    fn save(&mut self, entities: &[Entity]) -> TableStarts<'_> {
        if entities.is_empty() {
            return TableStarts::Unused;
        }
        if self.saved == self.tables.len() {
            self.tables.push(Default::default());
        }
        let (saved, states) = &mut self.tables[self.saved];
        self.saved += 1;
        saved.clear();
        saved.extend_from_slice(entities);
        states.resize(entities.len(), (Pose::default(), Velocity::default()));
        TableStarts::Save(states)
    }

    /// The saved states of the table `entities` lists, if this stage saved it: found by its
    /// first entity and length (structural changes wait for the end of the schedule run, so a
    /// table is the same between the two halves of a stage unless game code changed the whole
    /// world in between; each row's entity is checked again before it is put back).
    fn restore(&self, entities: &[Entity]) -> TableStarts<'_> {
        self.tables[..self.saved]
            .iter()
            .find(|(saved, _)| saved.len() == entities.len() && saved.first() == entities.first())
            .map_or(TableStarts::Unused, |(saved, states)| {
                TableStarts::Restore(saved, states)
            })
    }
}

/// First phase of a drift–kick–drift stage for bodies with a [`ForceAccumulator`]: the first
/// half of the [`Damping`](crate::components::Damping) flow (when the stage opens a substep), then half a drift before the
/// force systems run, so forces are sampled at the midpoint of the stage. Does nothing for
/// methods that sample forces at the start. Bodies without an accumulator feel no
/// state-dependent force and take their whole stage in [`integrate_without_forces`].
pub fn begin_stage(
    settings: Res<PhysicsSettings>,
    cursor: Res<crate::integrate::StageCursor>,
    parallelism: Option<Res<Parallelism>>,
    (mut drifted, mut starts): (ResMut<HalfDrifted>, ResMut<StageStarts>),
    gravity: Option<Res<Gravity>>,
    mut refusals: Refusals,
    mut bodies: Query<
        Stepped<(&ForceAccumulator, Option<&GravityScale>)>,
        (Dynamic, Without<ImplicitBody>),
    >,
) {
    starts.saved = 0;
    if !settings.integrator.samples_forces_at_midpoint() {
        return;
    }
    drifted.0 = true;
    let stage = StageTiming::new(&settings, *cursor, StepPhase::Begin);
    let weighed = gravity_applies(gravity);
    step_each_table!(
        bodies,
        stage,
        parallelism,
        refusals,
        |entities| starts.save(entities),
        |(accs, scales)| Loads::Checked {
            accs,
            scales: scales.filter(|_| weighed),
        }
    );
}

/// Integrates bodies that have a [`ForceAccumulator`], consuming (reading and zeroing) it.
///
/// For a drift–kick–drift method this finishes the stage that [`begin_stage`] began; if the
/// schedule was planned without `begin_stage` (the integrator was changed afterwards) it takes
/// the whole stage with the forces sampled at its start, and warns once. The [`Damping`](crate::components::Damping) flow
/// runs for half a substep before a whole stage that opens a substep and after any stage that
/// closes one.
pub fn integrate_with_forces(
    settings: Res<PhysicsSettings>,
    cursor: Res<crate::integrate::StageCursor>,
    parallelism: Option<Res<Parallelism>>,
    (mut drifted, mut starts): (ResMut<HalfDrifted>, ResMut<StageStarts>),
    (mut warned, gravity): (Local<bool>, Option<Res<Gravity>>),
    mut refusals: Refusals,
    mut bodies: Query<
        Stepped<(&mut ForceAccumulator, Option<&GravityScale>)>,
        (Dynamic, Without<ImplicitBody>),
    >,
) {
    let phase = if drifted.0 {
        StepPhase::Finish
    } else {
        StepPhase::Whole
    };
    if settings.integrator.samples_forces_at_midpoint() && phase == StepPhase::Whole && !*warned {
        *warned = true;
        tracing::warn!(
            integrator = %settings.integrator,
            "schedule planned without begin_stage: forces are sampled at the start of the stage; \
             plan again after changing the integrator"
        );
    }
    drifted.0 = false;
    let stage = StageTiming::new(&settings, *cursor, phase);
    let weighed = gravity_applies(gravity);
    step_each_table!(
        bodies,
        stage,
        parallelism,
        refusals,
        |entities| match phase {
            StepPhase::Finish => starts.restore(entities),
            _ => TableStarts::Unused,
        },
        |(mut accs, scales)| Loads::Consumed {
            accs: &mut accs,
            scales: scales.filter(|_| weighed),
        }
    );
    // What the stage saved is spent: a later second half without a first finds nothing.
    starts.saved = 0;
}

/// True while a gravity field applies (a finite [`Gravity`]): only then does a body's
/// [`GravityScale`] enter its load, and only then is a bad one refused.
pub(crate) fn gravity_applies(gravity: Option<Res<Gravity>>) -> bool {
    gravity.is_some_and(|g| g.field().is_some())
}

/// Integrates bodies without a [`ForceAccumulator`]: free motion, plus gravity when a
/// [`Gravity`] resource exists (a uniform field needs no accumulator), one whole stage, with the
/// [`Damping`](crate::components::Damping) flow for half a substep before a stage that opens a substep and after one that
/// closes it. With a composed integrator (`yoshida4`) such a body takes its whole substep in the
/// stage that opens it (nothing samples its state in between), its free rotation rounded once.
pub fn integrate_without_forces(
    settings: Res<PhysicsSettings>,
    cursor: Res<crate::integrate::StageCursor>,
    parallelism: Option<Res<Parallelism>>,
    gravity: Option<Res<Gravity>>,
    mut refusals: Refusals,
    mut bodies: Query<Stepped<Option<&GravityScale>>, (Dynamic, Without<ForceAccumulator>)>,
) {
    let gravity = gravity.and_then(|g| g.field());
    let Some(stage) = StageTiming::free_motion(&settings, *cursor) else {
        return;
    };
    step_each_table!(bodies, stage, parallelism, refusals, |scales| {
        Loads::Field { gravity, scales }
    });
}
