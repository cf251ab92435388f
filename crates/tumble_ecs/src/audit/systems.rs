//! The audit's systems: open the balance, credit the external loads, close it and quarantine.

use bevy_ecs::prelude::*;
use bevy_ecs::system::SystemChangeTick;
use tumble_core::math::{Real, Vec3, Widen};

use super::ledger::{
    Account, Audited, AuditedBodies, AuditedSprings, End, Ends, EnergyLedger, GroupStep, Link,
    OMEGA_DT_CAP, ROUND_OFF_ULPS, elastic_among, for_each_audited, for_each_spring, index_u32,
    resolve_ends, zip_table,
};
use super::memo::{BodyMemo, Marks};
use crate::components::{
    BodyError, BodyErrorKind, Dynamic, ForceAccumulator, Gravity, GravityScale, ImplicitBody,
    MassProps, PhysicsSettings, Pose, StepRefusals, Velocity, dense, kinetic_energy_f64, reject,
};
use crate::integrate::StageCursor;
use crate::parallel::{Parallelism, in_runs, in_runs_of_sums};

/// Start of an audited step (first in the plan): remembers each dynamic body's state, resolves
/// the springs' ends, forms the spring groups and measures each group's `T + V`.
pub fn audit_energy_start(
    settings: Res<PhysicsSettings>,
    cursor: Res<StageCursor>,
    mut ledger: ResMut<EnergyLedger>,
    parallelism: Option<Res<Parallelism>>,
    bodies: AuditedBodies,
    ends: Ends,
    (springs, refusals, ticks): (
        AuditedSprings,
        Option<ResMut<StepRefusals>>,
        SystemChangeTick,
    ),
) {
    let ledger = &mut *ledger;
    if !cursor.span(&settings).opens_step {
        return;
    }
    let marks = Marks::new(ledger.end_tick, ledger.start_tick, &ticks);
    ledger.start_tick = Some(ticks.this_run());
    // Refusals from before this step (one cut short) are not this step's.
    if let Some(mut refusals) = refusals {
        refusals.drain();
    }
    // Bodies and springs in entity index order, so that every sum over a group follows it.
    ledger
        .spring_order
        .refresh_entities(springs.iter().map(|(e, _)| e));
    ledger.dt = settings.dt().widen();
    let stability_span = settings.stages().stability_span(settings.dt()).widen();
    let same_span = stability_span.to_bits() == ledger.stability_span.to_bits();
    ledger.stability_span = stability_span;
    ledger.midpoint = settings.integrator.samples_forces_at_midpoint();
    let parallelism = parallelism.map_or_else(Parallelism::default, |p| *p);
    if std::mem::take(&mut ledger.closed)
        && same_span
        && ledger.restart(&bodies, &ends, &springs, (&marks, &parallelism))
    {
        return;
    }
    ledger.groups.clear();
    // Exact sizes: grown by doubling, a vector of a million entries would briefly be held
    // twice, and this pass is the audit's peak.
    let old = ledger.bodies.len();
    ledger
        .bodies
        .reserve_exact(bodies.iter().len().saturating_sub(old));
    ledger
        .links
        .reserve_exact(springs.iter().len().saturating_sub(ledger.links.len()));
    // Each entry is written over the last step's at its index, after its memo is read.
    let mut i = 0;
    let mut order = std::mem::take(&mut ledger.body_order);
    for_each_audited(&mut order, &bodies, |item| {
        let (energy, still) = ledger.start_kinetic(i, item, &marks.end);
        let (entity, t, v, m, _) = item;
        ledger.set_slot(entity, i);
        let body = Audited {
            entity,
            start: (*t, *v),
            end: *t,
            memo: BodyMemo::NONE,
            load: (Vec3::ZERO, Vec3::ZERO),
            work: 0.0,
            mass: m.mass().widen(),
            parent: index_u32(i),
            group: 0,
            still,
            start_energy: energy,
        };
        if i < old {
            ledger.bodies[i] = body;
        } else {
            ledger.bodies.push(body);
        }
        i += 1;
    });
    ledger.body_order = order;
    ledger.bodies.truncate(i);
    // Each link is written over the last step's link at its index, keeping that one's
    // measurement when the inputs are the same ([`memo`]).
    let old = ledger.links.len();
    let mut k = 0;
    let spring_order = std::mem::take(&mut ledger.spring_order);
    for_each_spring(&spring_order, &springs, |entity, spring, _| {
        let (a, b) = resolve_ends(ledger, &ends, spring);
        if let (End::Audited(i, _), End::Audited(j, _)) = (a, b) {
            ledger.union(i as usize, j as usize);
        }
        let mut link = Link::new(entity, spring, a, b);
        if k < old {
            let last = ledger.links[k];
            if last.same_inputs(&link) {
                (link.measured, link.elastic) = (last.measured, last.elastic);
            }
            ledger.links[k] = link;
        } else {
            ledger.links.push(link);
        }
        k += 1;
    });
    ledger.spring_order = spring_order;
    ledger.links.truncate(k);
    ledger.number_groups();
    ledger.count_group_springs();
    ledger.sum_start_energies();
}

/// Before the integration, after every force system but the springs (the plan runs
/// [`apply_springs`](crate::forces::apply_springs) right after this system in audited worlds):
/// records each audited body's load without the springs, `F`, `τ`, as the accumulators hold it
/// now. (Spring dampers are not forces in the accumulators: they are the velocity flow of
/// [`crate::springs`], an energy loss the balance sees and never flags. Implicit springs never
/// write to the accumulators.)
pub fn audit_external_loads(
    settings: Res<PhysicsSettings>,
    cursor: Res<StageCursor>,
    mut ledger: ResMut<EnergyLedger>,
    parallelism: Option<Res<Parallelism>>,
    bodies: LoadedBodies,
) {
    let ledger = &mut *ledger;
    let span = cursor.span(&settings);
    // Each stage's load counts with the stage's share `h/Δt` of the step (1 for a step of one
    // stage, so its load is used as it is).
    let share = if span.opens_step && span.closes_step {
        None
    } else {
        Some(span.h / settings.dt())
    };
    let record = LoadRecord {
        share,
        opens_step: span.opens_step,
    };
    let parallelism = parallelism.map_or_else(Parallelism::default, |p| *p);
    if !record.in_table_order(ledger, &bodies, &parallelism) {
        for (entity, t, acc, implicit) in &bodies {
            if let Some(i) = ledger.slot(entity) {
                record.record(&mut ledger.bodies[i], t, acc, implicit);
            }
        }
    }
}

/// The bodies whose loads [`audit_external_loads`] records.
type LoadedBodies<'w, 's> = Query<
    'w,
    's,
    (
        Entity,
        &'static Pose,
        &'static ForceAccumulator,
        Option<&'static ImplicitBody>,
    ),
    Dynamic,
>;

/// How [`audit_external_loads`] records a stage's loads.
struct LoadRecord {
    /// The stage's share `h/Δt` of the step (`None`: the step's only stage).
    share: Option<Real>,
    /// The stage opens the step.
    opens_step: bool,
}

impl LoadRecord {
    /// Records one body's load.
    #[inline]
    fn record(
        &self,
        body: &mut Audited,
        t: &Pose,
        acc: &ForceAccumulator,
        implicit: Option<&ImplicitBody>,
    ) {
        // The torque of the forces at points an implicit body's solve takes at mid-step,
        // credited here at the pose the forces were sampled at.
        let torque = acc.torque + implicit.map_or(Vec3::ZERO, |b| b.point_torque(t.rotation));
        let load = &mut body.load;
        match self.share {
            None => *load = (acc.force, torque),
            Some(w) => {
                if self.opens_step {
                    *load = (Vec3::ZERO, Vec3::ZERO);
                }
                load.0 += w * acc.force;
                load.1 += w * torque;
            }
        }
    }

    /// Records every body's load table by table, zipped with the ledger's entries and split over
    /// the compute pool's threads (as [`EndPass::measure_in_table_order`]). Returns false where
    /// a table's bodies are not the ledger's next entries, and the caller's lookup by entity
    /// records the loads: a step of one stage sets each load (recording one again is
    /// harmless), a stage's share adds to it, so then the tables are matched with the entries
    /// before any load is recorded.
    fn in_table_order(
        &self,
        ledger: &mut EnergyLedger,
        bodies: &LoadedBodies,
        parallelism: &Parallelism,
    ) -> bool {
        let matches = |ledger: &EnergyLedger, first: usize, entities: &[Entity]| {
            ledger
                .bodies
                .get(first..first + entities.len())
                .is_some_and(|entries| entries.iter().zip(entities).all(|(b, e)| b.entity == *e))
        };
        if self.share.is_some() {
            let mut first = 0;
            for (entities, ..) in dense(bodies.contiguous_iter()) {
                if !matches(ledger, first, entities) {
                    return false;
                }
                first += entities.len();
            }
        }
        let mut first = 0;
        for (entities, poses, accumulators, implicit) in dense(bodies.contiguous_iter()) {
            let recorded = zip_table(
                &mut ledger.bodies,
                first,
                entities,
                parallelism,
                |body, j| {
                    let implicit = implicit.map(|b| &b[j]);
                    self.record(body, &poses[j], &accumulators[j], implicit);
                    true
                },
            );
            if !recorded {
                return false;
            }
            first += entities.len();
        }
        true
    }
}

/// End of an audited step (last in the plan): closes each group's balance and quarantines the
/// groups whose integrator created more energy than the bound allows, putting them back to
/// their state at the start of the step.
pub fn audit_energy(
    settings: Res<PhysicsSettings>,
    cursor: Res<StageCursor>,
    mut ledger: ResMut<EnergyLedger>,
    gravity: Option<Res<Gravity>>,
    parallelism: Option<Res<Parallelism>>,
    (bodies, refusals, ticks): (EndBodies, Option<ResMut<StepRefusals>>, SystemChangeTick),
    mut commands: Commands,
) {
    let ledger = &mut *ledger;
    if !cursor.span(&settings).closes_step {
        return;
    }
    // What this pass measures is as it left it until something writes it after this tick.
    ledger.end_tick = Some(ticks.this_run());
    let dt = ledger.dt;
    let gravity = gravity.and_then(|g| g.field());
    // Only what this pass measures may be reused (a body it does not see keeps an older memo,
    // which its number rules out): a spring's memo is reused only with its bodies' poses
    // measured in the same pass.
    ledger.end_passes += 1;
    let end = EndPass {
        pass: ledger.end_passes,
        dt,
        gravity,
    };
    let parallelism = parallelism.map_or_else(Parallelism::default, |p| *p);
    if !end.measure_in_table_order(ledger, &bodies, &parallelism) {
        for (entity, t, v, m, scale, has_accumulator) in &bodies {
            if let Some(i) = ledger.slot(entity) {
                end.measure(&mut ledger.bodies[i], t, v, m, scale, has_accumulator);
            }
        }
    }
    let pass = end.pass;
    // Summed in the ledger's order (entity index order), not the query's: each group on one
    // thread.
    let runs = ledger.group_runs(parallelism.threads_for(ledger.bodies.len()));
    let bodies = &ledger.bodies;
    in_runs_of_sums(&runs.bodies, &mut ledger.groups, |items, groups, first| {
        for body in &bodies[items] {
            let g = &mut groups[body.group() - first];
            if !body.memo.measured_by(pass) {
                g.left = true;
                continue;
            }
            let (energy, work) = (body.memo.kinetic(), body.work);
            g.end += energy;
            g.work += work;
            g.magnitude += energy + work.abs();
        }
    });
    // A body refused in this step's last stage is still measured (its quarantine is a deferred
    // command), with the state it kept: its group has no verdict this step, as one refused in
    // an earlier stage.
    if let Some(mut refusals) = refusals {
        for entity in refusals.drain() {
            if let Some(i) = ledger.slot(entity) {
                let group = ledger.bodies[i].group();
                ledger.groups[group].left = true;
            }
        }
    }
    ledger.measure_springs_at_end(pass, &parallelism);
    ledger.rekey_restored_accounts();
    ledger.close_balances(&mut commands);
    ledger.accounts.retain(|_, a| a.seen);
    ledger.closed = true;
}

/// The bodies the end pass measures.
type EndBodies<'w, 's> = Query<
    'w,
    's,
    (
        Entity,
        &'static Pose,
        &'static Velocity,
        &'static MassProps,
        Option<&'static GravityScale>,
        Has<ForceAccumulator>,
    ),
    Dynamic,
>;

/// What the end pass measures each audited body with.
struct EndPass {
    /// The pass's number.
    pass: u64,
    dt: f64,
    gravity: Option<Vec3>,
}

impl EndPass {
    /// Measures one body at the end of the step: its end pose, the work its load did over the
    /// step (`W = Δt (F·v̄ + τ·ω̄)` with the mean velocities), and its kinetic energy, kept with
    /// its inputs for the next start ([`BodyMemo`]).
    #[inline]
    fn measure(
        &self,
        body: &mut Audited,
        t: &Pose,
        v: &Velocity,
        m: &MassProps,
        scale: Option<&GravityScale>,
        has_accumulator: bool,
    ) {
        body.end = *t;
        let (force, torque) = match self.gravity {
            // Bodies without an accumulator take gravity inside the integration.
            Some(g) if !has_accumulator => (m.mass() * scale.map_or(1.0, |s| s.0) * g, Vec3::ZERO),
            _ => body.load,
        };
        let v0 = body.start.1;
        let v_mean = 0.5 * (v0.linear.widen() + v.linear.widen());
        let w_mean = 0.5 * (v0.angular.widen() + v.angular.widen());
        body.work = self.dt * (force.widen().dot(v_mean) + torque.widen().dot(w_mean));
        body.memo = BodyMemo::new(self.pass, kinetic_energy_f64(t, v, m));
    }

    /// Measures every body table by table, each table zipped with the ledger's entries in the
    /// same order and split over the compute pool's threads as [`Parallelism`] allows (each
    /// body is measured by the same code on any thread). Returns false, leaving the rest to the
    /// caller's lookup by entity, where a table's bodies are not the ledger's next entries (the
    /// tables visit the bodies out of entity index order, or a body came or went since the
    /// start); what was measured by then is measured again from the same inputs.
    fn measure_in_table_order(
        &self,
        ledger: &mut EnergyLedger,
        bodies: &EndBodies,
        parallelism: &Parallelism,
    ) -> bool {
        let mut first = 0;
        for (entities, poses, velocities, masses, scales, has_accumulator) in
            dense(bodies.contiguous_iter())
        {
            let measured = zip_table(
                &mut ledger.bodies,
                first,
                entities,
                parallelism,
                |body, j| {
                    let scale = scales.map(|s| &s[j]);
                    let (t, v, m) = (&poses[j], &velocities[j], &masses[j]);
                    self.measure(body, t, v, m, scale, has_accumulator);
                    true
                },
            );
            if !measured {
                return false;
            }
            first += entities.len();
        }
        true
    }
}

impl EnergyLedger {
    /// Gives each body its group (the union–find roots are final now), numbered in the order
    /// of their roots. A root is its group's smallest index (`union` attaches to the smaller),
    /// so it is met first and its group numbered before any other member asks for it.
    fn number_groups(&mut self) {
        self.group_runs = None;
        for i in 0..self.bodies.len() {
            let root = self.find(i);
            let group = if root == i {
                self.groups.push(GroupStep::default());
                self.groups.len() - 1
            } else {
                self.bodies[root].group()
            };
            self.bodies[i].group = index_u32(group);
            let entity = self.bodies[i].entity;
            let g = &mut self.groups[group];
            g.members += 1;
            g.key = Some(g.key.map_or(entity, |k| k.min(entity)));
        }
    }

    /// Gives each link its group, and counts each group's springs, whether a kinematic body
    /// holds one, and its stiffest spring's `ω Δt` on the stability span.
    fn count_group_springs(&mut self) {
        for k in 0..self.links.len() {
            let link = self.links[k];
            let Some(group) = self.group_of_ends(&link) else {
                continue;
            };
            self.links[k].group = u32::try_from(group).expect("fewer than 2³² groups");
            let kinematic = matches!(link.a, End::Kinematic) || matches!(link.b, End::Kinematic);
            let mass = |end: End| match end {
                End::Audited(i, _) => self.bodies[i as usize].mass,
                _ => f64::INFINITY,
            };
            let (ma, mb) = (mass(link.a), mass(link.b));
            let reduced = if mb.is_infinite() {
                ma
            } else if ma.is_infinite() {
                mb
            } else {
                ma * mb / (ma + mb)
            };
            let omega_dt = (link.stiffness.widen() / reduced).sqrt() * self.stability_span;
            let g = &mut self.groups[group];
            g.springs += 1;
            g.kinematic |= kinematic;
            g.omega_dt = g.omega_dt.max(omega_dt);
        }
    }

    /// Adds each spring's elastic energy at the end of the step to its group, remembering it
    /// for the next step's start (measured in pass `pass`). The energies are measured on the
    /// compute pool's threads as [`Parallelism`] allows, then added in spring order.
    fn measure_springs_at_end(&mut self, pass: u64, parallelism: &Parallelism) {
        let bodies = &self.bodies;
        let threads = parallelism.threads_for(self.links.len());
        in_runs(threads, &mut self.links, |_, links| {
            for link in links.iter_mut().filter(|link| link.is_audited()) {
                (link.measured, link.elastic) = match elastic_among(bodies, link, |b| b.end) {
                    Some(v) => (pass, v),
                    None => (0, 0.0),
                };
            }
            true
        });
        // Added in spring order, each group on one thread.
        let runs = self.group_runs(parallelism.threads_for(self.bodies.len()));
        let links = &self.links;
        in_runs_of_sums(&runs.links, &mut self.groups, |items, groups, first| {
            for link in &links[items] {
                if let Some(group) = link.group().filter(|_| link.measured == pass) {
                    let g = &mut groups[group - first];
                    g.end += link.elastic;
                    g.magnitude += link.elastic;
                }
            }
        });
    }

    /// After a rollback restore, moves each account to its group's key (the smallest entity of
    /// the group).
    fn rekey_restored_accounts(&mut self) {
        if std::mem::take(&mut self.restored) {
            for i in 0..self.bodies.len() {
                let Audited { entity, group, .. } = self.bodies[i];
                if let Some(key) = self.groups[group as usize].key
                    && key != entity
                    && let Some(account) = self.accounts.remove(&entity)
                {
                    self.accounts.insert(key, account);
                }
            }
        }
    }

    /// Closes every group's balance: adds the energy the step created to its account and, where
    /// the account exceeds what a stable step allows, puts the group back to its start and
    /// quarantines its bodies.
    fn close_balances(&mut self, commands: &mut Commands) {
        for account in self.accounts.values_mut() {
            account.seen = false;
        }
        let eps = ROUND_OFF_ULPS * Real::EPSILON.widen();
        for group in 0..self.groups.len() {
            // Every group has a member, so a key; a group without one would have nothing to audit.
            let Some(key) = self.groups[group].key else {
                continue;
            };
            let g = self.groups[group];
            if g.kinematic {
                continue;
            }
            if g.left {
                // Start the account afresh from the next step, as for non-finite data below.
                if let Some(account) = self.accounts.get_mut(&key) {
                    account.created = 0.0;
                    account.seen = true;
                }
                continue;
            }
            let signature = (g.members, g.springs);
            let account = self.accounts.entry(key).or_insert(Account {
                signature,
                created: 0.0,
                seen: true,
            });
            if account.signature != signature {
                *account = Account {
                    signature,
                    created: 0.0,
                    seen: true,
                };
            }
            account.seen = true;
            let before = account.created;
            // The energy the group should hold, at the most over the step: from its start to
            // its start plus the loads' work. A group at rest and relaxed holds nothing at the
            // start, yet a load's first step gives it energy, and the step's own error in that
            // energy (`≤ W` for a stable spring) must fit the bound.
            let should = (g.start - before).max(g.start - before + g.work).max(0.0);
            account.created += g.end - g.start - g.work;
            let x = OMEGA_DT_CAP.min(g.omega_dt) / 2.0;
            let factor = if self.midpoint {
                2.0 / (1.0 - x * x)
            } else {
                2.0 * (1.0 + x) / (1.0 - x)
            };
            let bound = (factor - 1.0) * should + eps * g.magnitude + f64::MIN_POSITIVE;
            let created = account.created;
            if !(g.end.is_finite() && g.work.is_finite() && created.is_finite()) {
                // A member with non-finite data was rejected by the integrate systems' own checks
                // this step; the group's balance is meaningless until then, so start it afresh.
                account.created = 0.0;
                continue;
            }
            if created <= bound {
                continue;
            }
            account.created = before;
            for i in 0..self.bodies.len() {
                if self.bodies[i].group() != group {
                    continue;
                }
                let body = self.bodies[i];
                commands.entity(body.entity).insert(body.start);
                reject(
                    commands,
                    BodyError {
                        entity: body.entity,
                        kind: BodyErrorKind::EnergyGrew {
                            should,
                            created,
                            bound,
                            group: g.members,
                        },
                    },
                );
            }
        }
    }
}
