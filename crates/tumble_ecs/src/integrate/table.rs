//! One table's run of bodies, stepped through the core's batched step: the [`BodyBatch`] the
//! integrate systems hand to [`Integrator::stage_batch`], reading and writing the components in
//! place, split over the compute pool's threads for big tables.
//!
//! Game code may have written bad data through a `&mut` borrow, and the method may have left its
//! stable region: a body's rotation (and its accumulator) is checked before it is stepped, its
//! stepped state after, and a failing body keeps its components as they were and is reported
//! with what failed (the field game code broke, or the divergence); the others step on
//! unharmed. A non-finite translation or velocity needs no test of its own before the step: it
//! reaches the stepped state (every method moves the position by the velocity and the rotation
//! by the angular velocity, and IEEE arithmetic keeps NaN and infinities), whose check then
//! fails; the untouched components name the field. (On the cheapest methods a second full test
//! per body was the largest part of the layer's own work.)

use std::sync::Mutex;

use bevy_ecs::prelude::*;
use tumble_core::damping::decrement;
use tumble_core::integrate::ExactSwitch;
use tumble_core::math::{Real, Vec3};
use tumble_core::prefetch::prefetch;
use tumble_core::{BodyBatch, BodyState, Integrator, MassProperties, StepPhase, Wrench};

use crate::components::{BodyError, BodyErrorKind, check_accumulator, check_body, check_rotation};
use crate::components::{
    Damping, ForceAccumulator, GravityScale, MassProps, PhysicsSettings, Pose, SpringTurn,
    Velocity, body_state, write_body_state,
};
use crate::integrate::StageCursor;
use crate::parallel::Parallelism;

/// Where each body's load comes from.
pub(crate) enum Loads<'a> {
    /// A uniform field (or nothing): `F = m s g`, no torque.
    Field {
        gravity: Option<Vec3>,
        scales: Option<&'a [GravityScale]>,
    },
    /// Accumulators that are only checked (the first half-drift samples no load), with the
    /// bodies' gravity scales while a gravity field applies (`None` otherwise: unused, a scale
    /// harms nothing).
    Checked {
        accs: &'a [ForceAccumulator],
        scales: Option<&'a [GravityScale]>,
    },
    /// Accumulators that are checked and consumed (scales as for `Checked`).
    Consumed {
        accs: &'a mut [ForceAccumulator],
        scales: Option<&'a [GravityScale]>,
    },
}

/// Body `i`'s gravity scale (1 where the table has none or no gravity applies), checked before
/// its load: a bad scale is named as such, not as the non-finite accumulator or state it would
/// make, and before the first half drift of a stage, so the body keeps the state it had.
#[inline(always)]
fn check_scale(scales: Option<&[GravityScale]>, i: usize) -> Result<Real, BodyErrorKind> {
    match scales {
        Some(s) => s[i].check().map(|()| s[i].0),
        None => Ok(1.0),
    }
}

/// Splits optional per-body slices at `mid`.
fn split_column<T>(column: Option<&[T]>, mid: usize) -> (Option<&[T]>, Option<&[T]>) {
    column.map_or((None, None), |c| {
        let (a, b) = c.split_at(mid);
        (Some(a), Some(b))
    })
}

impl Loads<'_> {
    /// Splits at `mid` like `split_at_mut`.
    fn split_at(self, mid: usize) -> (Self, Self) {
        match self {
            Loads::Field { gravity, scales } => {
                let (a, b) = split_column(scales, mid);
                (
                    Loads::Field { gravity, scales: a },
                    Loads::Field { gravity, scales: b },
                )
            }
            Loads::Checked { accs, scales } => {
                let (a, b) = accs.split_at(mid);
                let (sa, sb) = split_column(scales, mid);
                (
                    Loads::Checked {
                        accs: a,
                        scales: sa,
                    },
                    Loads::Checked {
                        accs: b,
                        scales: sb,
                    },
                )
            }
            Loads::Consumed { accs, scales } => {
                let (a, b) = accs.split_at_mut(mid);
                let (sa, sb) = split_column(scales, mid);
                (
                    Loads::Consumed {
                        accs: a,
                        scales: sa,
                    },
                    Loads::Consumed {
                        accs: b,
                        scales: sb,
                    },
                )
            }
        }
    }

    /// Checks body `i`'s load and returns it (consuming an accumulator).
    #[inline(always)]
    fn take(&mut self, i: usize, mass: &MassProps) -> Result<Wrench, BodyErrorKind> {
        match self {
            Loads::Field { gravity, scales } => Ok(match gravity {
                Some(g) => Wrench {
                    force: (mass.mass() * check_scale(*scales, i)?) * *g,
                    torque: Vec3::ZERO,
                },
                None => Wrench::ZERO,
            }),
            Loads::Checked { accs, scales } => {
                check_scale(*scales, i)?;
                check_accumulator(&accs[i]).map(|()| Wrench::ZERO)
            }
            Loads::Consumed { accs, scales } => {
                check_scale(*scales, i)?;
                check_accumulator(&accs[i]).map(|()| accs[i].take())
            }
        }
    }
}

/// What a phase does with the state its bodies had before the first half drift of a
/// drift–kick–drift stage.
pub(crate) enum TableStarts<'a> {
    /// Nothing: a whole stage (nothing is left half done).
    Unused,
    /// Saves each body's state as it is read, before the first half drift changes it.
    Save(&'a mut [(Pose, Velocity)]),
    /// Puts a body refused in the second half back to its saved state, so that it keeps the
    /// state the stage found, not one drifted half a stage: the bodies' entities when saved,
    /// and their states. A row whose entity changed in between (game code with the whole
    /// world despawned and spawned bodies of the table) is left as it is.
    Restore(&'a [Entity], &'a [(Pose, Velocity)]),
}

impl TableStarts<'_> {
    /// Splits at `mid` like `split_at_mut`.
    fn split_at(self, mid: usize) -> (Self, Self) {
        match self {
            TableStarts::Unused => (TableStarts::Unused, TableStarts::Unused),
            TableStarts::Save(s) => {
                let (a, b) = s.split_at_mut(mid);
                (TableStarts::Save(a), TableStarts::Save(b))
            }
            TableStarts::Restore(e, s) => {
                let ((e0, e1), (s0, s1)) = (e.split_at(mid), s.split_at(mid));
                (TableStarts::Restore(e0, s0), TableStarts::Restore(e1, s1))
            }
        }
    }
}

/// A run of bodies from one table, as plain slices.
pub(crate) struct Bodies<'a> {
    pub(crate) entities: &'a [Entity],
    pub(crate) transforms: &'a mut [Pose],
    pub(crate) velocities: &'a mut [Velocity],
    pub(crate) masses: &'a [MassProps],
    pub(crate) dampings: Option<&'a [Damping]>,
    /// How fast each body's springs can turn it (see [`SpringTurn`]), where the table has them.
    pub(crate) turns: Option<&'a [SpringTurn]>,
    pub(crate) loads: Loads<'a>,
    pub(crate) starts: TableStarts<'a>,
}

impl<'a> Bodies<'a> {
    fn len(&self) -> usize {
        self.entities.len()
    }

    /// Splits into bodies `[0, mid)` and `[mid, len)`.
    fn split_at(self, mid: usize) -> (Self, Self) {
        let (e0, e1) = self.entities.split_at(mid);
        let (t0, t1) = self.transforms.split_at_mut(mid);
        let (v0, v1) = self.velocities.split_at_mut(mid);
        let (m0, m1) = self.masses.split_at(mid);
        let (d0, d1) = split_column(self.dampings, mid);
        let (s0, s1) = split_column(self.turns, mid);
        let (l0, l1) = self.loads.split_at(mid);
        let (b0, b1) = self.starts.split_at(mid);
        (
            Bodies {
                entities: e0,
                transforms: t0,
                velocities: v0,
                masses: m0,
                dampings: d0,
                turns: s0,
                loads: l0,
                starts: b0,
            },
            Bodies {
                entities: e1,
                transforms: t1,
                velocities: v1,
                masses: m1,
                dampings: d1,
                turns: s1,
                loads: l1,
                starts: b1,
            },
        )
    }
}

/// One table run of bodies as a [`BodyBatch`] for the core's batched step: bodies are read
/// from and written to their components directly. A body whose data is bad is skipped and one
/// whose step diverges keeps its state; both are reported in `errors`.
struct TableBatch<'a, 'e> {
    bodies: Bodies<'a>,
    /// [`Damping`]'s first half-substep flow applies to the velocity read by a phase that
    /// begins a substep, its second to the velocity written by a phase that ends one.
    damp_read: bool,
    damp_write: bool,
    /// Half the substep, `Δt/(2N)`: the span of each damping flow.
    half_dt: Real,
    integrator: Integrator,
    errors: &'e mut Vec<BodyError>,
}

/// What one integrate system does to its bodies: which phase of which stage, and where the
/// [`Damping`] flow runs.
pub(crate) struct StageTiming {
    integrator: Integrator,
    phase: StepPhase,
    /// The stage's span `h`.
    h: Real,
    /// Half the substep: the span of each half of the damping flow.
    half_substep: Real,
    damp_read: bool,
    damp_write: bool,
    /// The whole substep at once (`h` is the substep): [`Integrator::step_batch`].
    whole_substep: bool,
    /// The switch of a split method to the exact free flow for fast spins
    /// ([`PhysicsSettings::free_flow`]).
    switch: Option<ExactSwitch>,
}

impl StageTiming {
    /// A whole substep, for bodies whose only load is constant (no accumulator): in a plan whose
    /// integrator is a composition, the substep's stages run at once in the stage that opens
    /// it (`None` in its other stages), so that a torque-free composed step rounds its rotation
    /// once (see [`Integrator::step`]); otherwise the stage's [`Whole`](StepPhase::Whole) phase.
    pub(crate) fn free_motion(settings: &PhysicsSettings, cursor: StageCursor) -> Option<Self> {
        if settings.integrator.composition().len() == 1 {
            return Some(Self::new(settings, cursor, StepPhase::Whole));
        }
        let span = cursor.span(settings);
        span.opens_substep.then_some(Self {
            integrator: settings.integrator,
            phase: StepPhase::Whole,
            h: span.substep,
            half_substep: 0.5 * span.substep,
            damp_read: true,
            damp_write: true,
            whole_substep: true,
            switch: ExactSwitch::new(settings.integrator, settings.free_flow, span.substep),
        })
    }

    /// `phase` of the stage `cursor` points at, under `settings`: the damping flow's first half
    /// before a phase that begins the stage (`Begin`, `Whole`) when the stage opens its
    /// substep, its second half after a phase that ends the stage (`Finish`, `Whole`) when the
    /// stage closes it.
    pub(crate) fn new(settings: &PhysicsSettings, cursor: StageCursor, phase: StepPhase) -> Self {
        let span = cursor.span(settings);
        Self {
            integrator: settings.integrator,
            phase,
            h: span.h,
            half_substep: 0.5 * span.substep,
            damp_read: phase != StepPhase::Finish && span.opens_substep,
            damp_write: phase != StepPhase::Begin && span.closes_substep,
            whole_substep: false,
            switch: ExactSwitch::new(settings.integrator, settings.free_flow, span.substep),
        }
    }
}

impl BodyBatch for TableBatch<'_, '_> {
    fn len(&self) -> usize {
        self.bodies.len()
    }

    #[inline(always)]
    fn take(&mut self, i: usize, state: &mut BodyState) -> Option<Wrench> {
        let bodies = &mut self.bodies;
        let (transform, velocity) = (&bodies.transforms[i], &bodies.velocities[i]);
        if let TableStarts::Save(starts) = &mut bodies.starts {
            starts[i] = (*transform, *velocity);
        }
        let mass = &bodies.masses[i];
        // Only the rotation is checked here, and the damping (its flow would ignore a bad rate
        // silently); a non-finite translation or velocity is found in the stepped state and
        // named by `diverged` (see `check_rotation`).
        let checked = check_rotation(transform)
            .and_then(|()| bodies.dampings.map_or(Ok(()), |d| d[i].check()));
        match checked.and_then(|()| bodies.loads.take(i, mass)) {
            Ok(wrench) => {
                state.copy_fields_from(&body_state(transform, velocity, mass));
                if self.damp_read
                    && let Some(d) = bodies.dampings.map(|d| &d[i])
                {
                    damp(
                        d,
                        self.half_dt,
                        &mut state.linear_velocity,
                        &mut state.angular_velocity,
                    );
                }
                Some(wrench)
            }
            Err(kind) => {
                self.errors.push(BodyError {
                    entity: bodies.entities[i],
                    kind,
                });
                self.put_back(i);
                None
            }
        }
    }

    #[inline(always)]
    fn mass(&self, i: usize) -> &MassProperties {
        &self.bodies.masses[i].0
    }

    #[inline(always)]
    fn prefetch(&self, i: usize) {
        let bodies = &self.bodies;
        if i < bodies.len() {
            prefetch(&bodies.transforms[i]);
            prefetch(&bodies.velocities[i]);
            prefetch(&bodies.masses[i]);
        }
    }

    #[inline(always)]
    fn write(&mut self, i: usize, state: &BodyState) {
        let bodies = &mut self.bodies;
        let (transform, velocity) = (&mut bodies.transforms[i], &mut bodies.velocities[i]);
        write_body_state(state, &bodies.masses[i], transform, velocity);
        if self.damp_write
            && let Some(d) = bodies.dampings.map(|d| &d[i])
        {
            damp(d, self.half_dt, &mut velocity.linear, &mut velocity.angular);
        }
    }

    /// The stepped state is bad: bad input the step carried (the components are untouched, so
    /// [`check_body`] names the field), or a step outside the method's stable region.
    fn diverged(&mut self, i: usize) {
        let bodies = &self.bodies;
        let integrator = self.integrator;
        let kind = match check_body(&bodies.transforms[i], &bodies.velocities[i], None) {
            Err(bad_input) => bad_input,
            Ok(()) => BodyErrorKind::Diverged(tumble_core::StepError::Diverged { integrator }),
        };
        self.errors.push(BodyError {
            entity: bodies.entities[i],
            kind,
        });
        self.put_back(i);
    }
}

impl TableBatch<'_, '_> {
    /// Puts refused body `i` back to the state the stage found it in, where the first half
    /// drift changed it (see [`TableStarts::Restore`]).
    #[cold]
    fn put_back(&mut self, i: usize) {
        let bodies = &mut self.bodies;
        if let TableStarts::Restore(entities, starts) = &bodies.starts
            && entities[i] == bodies.entities[i]
        {
            (bodies.transforms[i], bodies.velocities[i]) = starts[i];
        }
    }
}

/// A table whose bodies carry [`SpringTurn`]: the [`TableBatch`] with their rates. A table
/// without them steps through the plain `TableBatch`, whose rate is the constant 0, so the hot
/// loop of free bodies is compiled without it (reading an optional column per body cost free
/// bodies a fifth of their step).
struct TurnedBatch<'b, 'a, 'e> {
    batch: &'b mut TableBatch<'a, 'e>,
    turns: &'a [SpringTurn],
}

impl BodyBatch for TurnedBatch<'_, '_, '_> {
    fn len(&self) -> usize {
        self.batch.len()
    }

    #[inline(always)]
    fn take(&mut self, i: usize, state: &mut BodyState) -> Option<Wrench> {
        self.batch.take(i, state)
    }

    #[inline(always)]
    fn mass(&self, i: usize) -> &MassProperties {
        self.batch.mass(i)
    }

    #[inline(always)]
    fn spring_turn_rate(&self, i: usize) -> Real {
        self.turns[i].rate()
    }

    #[inline(always)]
    fn prefetch(&self, i: usize) {
        self.batch.prefetch(i);
    }

    #[inline(always)]
    fn write(&mut self, i: usize, state: &BodyState) {
        self.batch.write(i, state);
    }

    fn diverged(&mut self, i: usize) {
        self.batch.diverged(i);
    }
}

/// [`Damping`]'s flow over `τ`: `v ← decay(c_lin τ) v`, `ω ← decay(c_ang τ) ω`, written as
/// `v − decrement(c τ) v` (see [`tumble_core::damping`]). Outside the core's step, in the
/// adapter's `take` and `write`, so every kernel path of the batch sees the same bits.
#[inline(always)]
pub(crate) fn damp(damping: &Damping, tau: Real, linear: &mut Vec3, angular: &mut Vec3) {
    *linear -= decrement(damping.linear * tau) * *linear;
    *angular -= decrement(damping.angular * tau) * *angular;
}

/// Steps one table's bodies through the stage's phase with the core's batched step
/// (bit-identical to stepping each body alone), split over the compute pool's threads when
/// [`Parallelism`] says the table is big enough. Each body is stepped by the same code in any
/// split, so the result does not depend on the number of threads. Errors are appended sorted
/// by entity.
pub(crate) fn step_table(
    stage: &StageTiming,
    parallelism: &Parallelism,
    mut bodies: Bodies<'_>,
    errors: &mut Vec<BodyError>,
) {
    let threads = parallelism.threads_for(bodies.len());
    if threads > 1 {
        return step_in_parts(stage, split_evenly(bodies, threads), errors);
    }
    let found = errors.len();
    let turns = bodies.turns.take();
    let mut batch = TableBatch {
        bodies,
        damp_read: stage.damp_read,
        damp_write: stage.damp_write,
        half_dt: stage.half_substep,
        integrator: stage.integrator,
        errors,
    };
    let (integrator, phase, h, switch) = (stage.integrator, stage.phase, stage.h, stage.switch);
    match turns {
        None if stage.whole_substep => integrator.step_batch_switched(&mut batch, h, switch),
        None => integrator.stage_batch_switched(phase, &mut batch, h, switch),
        Some(turns) => {
            let mut turned = TurnedBatch {
                batch: &mut batch,
                turns,
            };
            if stage.whole_substep {
                integrator.step_batch_switched(&mut turned, h, switch);
            } else {
                integrator.stage_batch_switched(phase, &mut turned, h, switch);
            }
        }
    }
    batch.errors[found..].sort_by_key(|e| e.entity);
}

/// Steps each part on a thread of the compute pool ([`step_table`] on one thread each) and
/// appends their errors sorted by entity.
fn step_in_parts(stage: &StageTiming, parts: Vec<Bodies<'_>>, errors: &mut Vec<BodyError>) {
    let found = Mutex::new(Vec::new());
    crate::parallel::scope(|spawn| {
        for part in parts {
            let found = &found;
            spawn(Box::new(move || {
                let mut local = Vec::new();
                step_table(stage, &Parallelism::SINGLE_THREAD, part, &mut local);
                if !local.is_empty() {
                    found
                        .lock()
                        .unwrap_or_else(|poisoned| poisoned.into_inner())
                        .extend(local);
                }
            }));
        }
    });
    let mut found = found
        .into_inner()
        .unwrap_or_else(|poisoned| poisoned.into_inner());
    found.sort_by_key(|e| e.entity);
    errors.extend(found);
}

/// Splits `bodies` into `parts` runs of nearly equal length.
fn split_evenly(bodies: Bodies<'_>, parts: usize) -> Vec<Bodies<'_>> {
    let mut out = Vec::with_capacity(parts);
    let mut rest = bodies;
    for k in (1..=parts).rev() {
        let take = rest.len() / k;
        let (head, tail) = rest.split_at(take);
        out.push(head);
        rest = tail;
    }
    out
}
