//! The energy ledger: what the audit remembers of each spring group between its passes.

use bevy_ecs::change_detection::Tick;
use bevy_ecs::entity::EntityHashMap;
use bevy_ecs::prelude::*;
use tumble_core::math::{Real, Vec3, Widen, same_bits};

use super::memo::{BodyMemo, EndTick};
use crate::components::{
    Dynamic, IndexOrder, Kinematic, MassProps, Pose, Rejected, RigidBody, Spring, SpringEnd,
    Static, Velocity, kinetic_energy_f64,
};
use crate::parallel::{Parallelism, Runs, in_runs};

/// The audit's largest `ωΔt` in the stable-spring factor: at 2 the factor is infinite, and
/// beyond it the spring is unstable and grows geometrically past any finite bound anyway.
pub(super) const OMEGA_DT_CAP: f64 = 1.99;

/// Round-off allowance, in units of the precision's epsilon, on the step's energy magnitudes.
pub(super) const ROUND_OFF_ULPS: f64 = 64.0;

/// What the audit remembers of one body during a step.
///
/// Laid out in three cache lines by the passes that touch them: the first holds what the sums
/// over the groups read, on one thread, at the end of every step (the memo, the work, the
/// group) and what the start checks; the second the state to put back; the third what the
/// loads and the end pass write (the springs' energies read the end pose from it).
#[derive(Debug, Clone, Copy)]
#[repr(C, align(64))]
pub(super) struct Audited {
    pub(super) entity: Entity,
    /// What the last end pass measured of this entry's entity, for the next start ([`memo`]).
    pub(super) memo: BodyMemo,
    /// The work of `load` over the step (J), once the end pass has measured it.
    pub(super) work: f64,
    /// Kinetic energy at the start of the step.
    pub(super) start_energy: f64,
    /// Mass (kg), for the springs' reduced mass.
    pub(super) mass: f64,
    /// Union–find parent.
    pub(super) parent: u32,
    /// Its group's index in [`EnergyLedger::groups`], once the start pass has joined every
    /// spring's ends.
    pub(super) group: u32,
    /// Unchanged since the end of the last step (nothing written since, [`memo`]).
    pub(super) still: bool,
    pub(super) start: (Pose, Velocity),
    /// Pose at the end of the step (for the springs' energy; after the end pass, the pose
    /// `memo` was measured at).
    pub(super) end: Pose,
    /// Every load except the springs: force and torque (world frame).
    pub(super) load: (Vec3, Vec3),
}

// What the end of every step reads of every body, on one thread, fills one cache line.
const _: () = assert!(std::mem::offset_of!(Audited, still) < 64);

impl Audited {
    /// Its group's index in [`EnergyLedger::groups`].
    #[inline(always)]
    pub(super) fn group(&self) -> usize {
        self.group as usize
    }
}

/// One end of a spring as the audit sees it.
#[derive(Debug, Clone, Copy)]
pub(super) enum End {
    /// An audited body: its index and the body-local anchor.
    Audited(u32, Vec3),
    /// A fixed point (world anchor or static body), in world coordinates.
    Fixed(Vec3),
    /// A kinematic body: game code moves it and does work the audit cannot see.
    Kinematic,
    /// Missing or rejected: the spring exerts nothing this step.
    Inactive,
}

/// A spring with its ends resolved once per step: the inputs of its elastic energy besides its
/// audited bodies' poses, and that energy as the last end pass measured it ([`memo`]). Only
/// these: a million springs are a million links.
#[derive(Debug, Clone, Copy)]
pub(super) struct Link {
    pub(super) stiffness: Real,
    pub(super) rest_length: Real,
    pub(super) a: End,
    pub(super) b: End,
    /// The end pass that measured `elastic` with these inputs (0: none did).
    pub(super) measured: u64,
    /// The elastic energy that pass measured.
    pub(super) elastic: f64,
    /// Its group's index in [`EnergyLedger::groups`] ([`NO_GROUP`] without an audited end),
    /// once the start pass has numbered the groups: the sums over a group's springs read it
    /// here rather than from the bodies.
    pub(super) group: u32,
    /// Each end is an audited body or a world point: while the audited bodies are the same
    /// entities at the same indices and the spring (this entity) is not written, its ends
    /// resolve as they did (an end on a static, kinematic or missing body is resolved again at
    /// every start).
    pub(super) stable: bool,
    /// The spring's entity.
    pub(super) spring: Entity,
}

/// `i` as a ledger index (entities are indexed by `u32`, so a world never holds more bodies).
#[inline]
pub(super) fn index_u32(i: usize) -> u32 {
    u32::try_from(i).expect("fewer than 2³² audited bodies")
}

/// [`Link::group`] of a link without an audited end.
pub(super) const NO_GROUP: u32 = u32::MAX;

impl Link {
    /// The group the link belongs to (as the start pass numbered it), if it touches an audited
    /// body.
    #[inline]
    pub(super) fn group(&self) -> Option<usize> {
        (self.group != NO_GROUP).then_some(self.group as usize)
    }

    /// The spring `spring` (of entity `entity`) with its ends resolved to `a` and `b`, not
    /// measured yet.
    pub(super) fn new(entity: Entity, spring: &Spring, a: End, b: End) -> Self {
        let audited = |end: End| matches!(end, End::Audited(..));
        let stable = audited(a)
            && match spring.b {
                SpringEnd::World(_) => true,
                SpringEnd::Body { .. } => audited(b),
            };
        Self {
            stiffness: spring.stiffness,
            rest_length: spring.rest_length,
            a,
            b,
            measured: 0,
            elastic: 0.0,
            group: NO_GROUP,
            stable,
            spring: entity,
        }
    }

    /// True when an end is an audited body (the link belongs to that body's group).
    pub(super) fn is_audited(&self) -> bool {
        matches!(self.a, End::Audited(..)) || matches!(self.b, End::Audited(..))
    }

    /// The audited bodies at its ends.
    pub(super) fn audited_bodies(&self) -> impl Iterator<Item = usize> {
        [self.a, self.b].into_iter().filter_map(|end| match end {
            End::Audited(i, _) => Some(i as usize),
            _ => None,
        })
    }

    /// True when `other` has the same inputs, bit for bit, apart from its audited bodies'
    /// poses (see [`BodyMemo::still`] for those).
    pub(super) fn same_inputs(&self, other: &Link) -> bool {
        let inputs = |l: &Link| [l.stiffness, l.rest_length];
        same_bits(inputs(self), inputs(other))
            && same_end(self.a, other.a)
            && same_end(self.b, other.b)
    }

    /// `½ k (|d| − L₀)²` with the anchors at the world points `pa` and `pb` (J, `f64`).
    pub(super) fn elastic_energy(&self, pa: Vec3, pb: Vec3) -> f64 {
        let stretch = (pa - pb).widen().length() - self.rest_length.widen();
        0.5 * self.stiffness.widen() * stretch * stretch
    }
}

/// One group's running account, keyed by its smallest entity.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Account {
    /// Members and springs when the account was opened: a group that changes starts afresh.
    pub(super) signature: (usize, usize),
    /// `D`: energy the integrator created so far (J).
    pub(super) created: f64,
    /// Seen in the current step (stale accounts are dropped).
    pub(super) seen: bool,
}

/// Per-group sums of one step.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct GroupStep {
    pub(super) members: usize,
    pub(super) springs: usize,
    pub(super) key: Option<Entity>,
    pub(super) kinematic: bool,
    /// A member left the audited bodies during the step (refused by a check in any stage, or
    /// despawned): its springs stopped acting part-way, or it kept a state (bad data included)
    /// the step did not give it, so the balance does not measure the integrator, and the group
    /// gets no verdict this step.
    pub(super) left: bool,
    /// `(T + V)` at the start.
    pub(super) start: f64,
    /// `(T + V)` at the end.
    pub(super) end: f64,
    /// `W_ext`.
    pub(super) work: f64,
    /// Magnitudes for the round-off allowance.
    pub(super) magnitude: f64,
    /// Stiffest spring's `ωΔt`.
    pub(super) omega_dt: f64,
}

/// The bodies and the links of the ledger cut into runs of whole groups, for `threads` threads:
/// each group's sums take their terms in ledger order on one thread (see
/// [`crate::parallel::Runs`]), so the accounts are the same bits on any number of threads.
#[derive(Debug, Clone, Copy)]
pub(super) struct GroupRuns {
    threads: usize,
    pub(super) bodies: Runs,
    pub(super) links: Runs,
}

/// The audit's bookkeeping (reused every step so that steps do not allocate).
#[derive(Resource, Debug, Default)]
pub struct EnergyLedger {
    pub(super) bodies: Vec<Audited>,
    /// The index in `bodies` of an entity, at its `index_u32`: a dense table, not a hash map
    /// (four lookups per body and step). Entries of entities no longer audited are left in
    /// place: a lookup checks the entity it finds.
    pub(super) slots: Vec<u32>,
    pub(super) links: Vec<Link>,
    pub(super) groups: Vec<GroupStep>,
    pub(super) accounts: EntityHashMap<Account>,
    pub(super) dt: f64,
    /// The plain step with the stability of one substep (`Δt` unless there are substeps or a
    /// composition, see `Stages::stability_span`): the span a spring's `ωh` is measured on.
    pub(super) stability_span: f64,
    /// Whether the integrator drifts–kicks–drifts (else it kicks, then drifts).
    pub(super) midpoint: bool,
    /// Accounts were restored under some member of their group, not necessarily its smallest
    /// entity (entity ids change when a world is restored): re-key them at the next audit.
    pub(super) restored: bool,
    /// End passes so far: what the last one measured carries its number.
    pub(super) end_passes: u64,
    /// The change tick the last end pass ran at: a body whose pose, velocity and mass were not
    /// written since is as that pass measured it ([`memo`]).
    pub(super) end_tick: Option<Tick>,
    /// The change tick the last start pass ran at: a spring not written since is as its link
    /// says, a body's mass as its entry says ([`memo`]).
    pub(super) start_tick: Option<Tick>,
    /// The groups were closed by an end pass since the last start: their end sums are the
    /// energies the bodies stand at now, if nothing changed ([`EnergyLedger::restart`]).
    pub(super) closed: bool,
    /// The audited bodies in entity index order, when their query visits them otherwise
    /// (scratch, see [`for_each_audited`]).
    pub(super) body_order: IndexOrder,
    /// The springs in entity index order (scratch).
    pub(super) spring_order: IndexOrder,
    /// The bodies and the links cut into runs of whole groups for the end pass's sums
    /// ([`EnergyLedger::group_runs`]); `None` once the groups are numbered again.
    pub(super) group_runs: Option<GroupRuns>,
    /// Starts that took the unchanged world's shortcut (for tests).
    #[cfg(test)]
    pub(super) restarts: usize,
    /// Starts that kept the last step's groups and measured what changed (for tests).
    #[cfg(test)]
    pub(super) partial_restarts: usize,
}

/// One group's running account as a snapshot saves it: a member of the group (any), the group's
/// size and springs when the account was opened, and the energy the integrator made up so far.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct SavedAccount {
    /// A body of the group.
    pub member: Entity,
    /// Bodies in the group.
    pub members: usize,
    /// Springs of the group.
    pub springs: usize,
    /// `D` (J).
    pub created: f64,
}

/// The audit's running accounts as a [`RollbackSnapshot`](crate::state::RollbackSnapshot)
/// keeps them: the energy each spring group's integration has made up so far, which decides
/// whether a later step quarantines the group. Opaque; in entity order.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct LedgerState {
    pub(super) accounts: Vec<(Entity, Account)>,
    pub(super) restored: bool,
}

impl LedgerState {
    /// Bytes on the heap.
    pub fn heap_bytes(&self) -> usize {
        self.accounts.capacity() * std::mem::size_of::<(Entity, Account)>()
    }
}

impl EnergyLedger {
    /// The index in `bodies` of an audited entity.
    #[inline]
    pub(super) fn slot(&self, entity: Entity) -> Option<usize> {
        let i = *self.slots.get(entity.index_u32() as usize)? as usize;
        (self.bodies.get(i)?.entity == entity).then_some(i)
    }

    /// Records that `entity` is audited at index `i`.
    pub(super) fn set_slot(&mut self, entity: Entity, i: usize) {
        let at = entity.index_u32() as usize;
        if at >= self.slots.len() {
            self.slots.resize(at + 1, u32::MAX);
        }
        self.slots[at] = i as u32;
    }

    pub(super) fn find(&mut self, mut i: usize) -> usize {
        while self.bodies[i].parent as usize != i {
            let grand = self.bodies[self.bodies[i].parent as usize].parent;
            self.bodies[i].parent = grand;
            i = grand as usize;
        }
        i
    }

    pub(super) fn union(&mut self, a: usize, b: usize) {
        let (ra, rb) = (self.find(a), self.find(b));
        if ra != rb {
            // Attach to the smaller index so that the root does not depend on spring order.
            let (lo, hi) = if ra < rb { (ra, rb) } else { (rb, ra) };
            self.bodies[hi].parent = index_u32(lo);
        }
    }

    /// The energy the integrator created so far in the group whose smallest entity is `key`.
    pub fn created_energy(&self, key: Entity) -> Option<f64> {
        self.accounts.get(&key).map(|a| a.created)
    }

    /// The running accounts, for a snapshot (in a stable order: by entity).
    pub fn saved_accounts(&self) -> Vec<SavedAccount> {
        let mut saved: Vec<SavedAccount> = self
            .accounts
            .iter()
            .map(|(&member, a)| SavedAccount {
                member,
                members: a.signature.0,
                springs: a.signature.1,
                created: a.created,
            })
            .collect();
        saved.sort_by_key(|a| a.member);
        saved
    }

    /// Restores saved accounts, their members already mapped to the restored entities.
    pub fn restore_accounts(&mut self, saved: impl IntoIterator<Item = SavedAccount>) {
        self.accounts.clear();
        for a in saved {
            self.accounts.insert(
                a.member,
                Account {
                    signature: (a.members, a.springs),
                    created: a.created,
                    seen: true,
                },
            );
        }
        self.restored = true;
    }

    /// Copies the running accounts (by entity) into `into`, for a rollback snapshot.
    pub(crate) fn save_state(&self, into: &mut LedgerState) {
        into.accounts.clear();
        into.accounts
            .extend(self.accounts.iter().map(|(&k, &a)| (k, a)));
        into.accounts.sort_unstable_by_key(|(k, _)| *k);
        into.restored = self.restored;
    }

    /// Puts back the running accounts of `from` exactly (same keys: a rollback keeps entities).
    pub(crate) fn load_state(&mut self, from: &LedgerState) {
        self.accounts.clear();
        self.accounts.extend(from.accounts.iter().copied());
        self.restored = from.restored;
    }

    /// The bodies and the links cut into runs of whole groups for `threads` threads, kept
    /// until the groups are numbered again. Groups are numbered in the order of their first
    /// member, so bodies and springs spawned group by group cut between groups near every even
    /// cut; a world whose groups interleave sums on one thread.
    pub(super) fn group_runs(&mut self, threads: usize) -> GroupRuns {
        if let Some(runs) = self.group_runs
            && runs.threads == threads
            && runs.bodies.len() == self.bodies.len()
            && runs.links.len() == self.links.len()
        {
            return runs;
        }
        let bodies = Runs::of_keys(self.bodies.len(), threads, |i| {
            let g = u64::from(self.bodies[i].group);
            Some((g, g))
        });
        let links = Runs::of_keys(self.links.len(), threads, |k| {
            let g = self.links[k].group()? as u64;
            Some((g, g))
        });
        let runs = GroupRuns {
            threads,
            bodies,
            links,
        };
        self.group_runs = Some(runs);
        runs
    }

    /// The group of a link's first audited end, from the bodies (for numbering the links).
    pub(super) fn group_of_ends(&self, link: &Link) -> Option<usize> {
        match (link.a, link.b) {
            (End::Audited(i, _), _) | (_, End::Audited(i, _)) => {
                Some(self.bodies[i as usize].group())
            }
            _ => None,
        }
    }

    /// Elastic energy of a link with the bodies at the poses `pose` gives.
    pub(super) fn elastic(
        &self,
        link: &Link,
        pose: impl Fn(&Audited) -> Pose + Copy,
    ) -> Option<f64> {
        elastic_among(&self.bodies, link, pose)
    }

    /// Link `k`'s elastic energy at the start of the step: the one the last step ended with
    /// when its inputs are the same bit for bit, else measured afresh.
    pub(super) fn start_elastic(&self, link: &Link) -> Option<f64> {
        // Its bodies are still, so their memos are from the same pass as the spring's.
        if link.measured == self.end_passes && link.audited_bodies().all(|i| self.bodies[i].still) {
            return Some(link.elastic);
        }
        self.elastic(link, |b| b.start.0)
    }

    /// The kinetic energy at the start of the step of the body read at index `i`, and whether
    /// it is still as the last end pass measured it there (nothing written since, [`memo`]): then the
    /// energy is that measurement, else it is measured now.
    pub(super) fn start_kinetic(&self, i: usize, item: BodyItem, since: &EndTick) -> (f64, bool) {
        match self.bodies.get(i) {
            Some(last) if last.entity == item.0 => {
                start_kinetic_of(last, self.end_passes, item, since)
            }
            _ => {
                let (_, t, v, m, _) = item;
                (kinetic_energy_f64(t, v, m), false)
            }
        }
    }

    /// Each group's `T + V` at the start of the step (and its magnitude for the round-off
    /// allowance), from the bodies' `start_energy` and the springs' elastic energy
    /// ([`start_elastic`](Self::start_elastic)): the bodies by index into their roots, then the
    /// springs in order, so the sums do not depend on which start pass formed the groups.
    pub(super) fn sum_start_energies(&mut self) {
        for g in &mut self.groups {
            (g.start, g.magnitude, g.end, g.work) = (0.0, 0.0, 0.0, 0.0);
        }
        for i in 0..self.bodies.len() {
            let Audited {
                group,
                start_energy,
                ..
            } = self.bodies[i];
            let g = &mut self.groups[group as usize];
            g.start += start_energy;
            g.magnitude += start_energy;
        }
        for k in 0..self.links.len() {
            let link = self.links[k];
            let Some(group) = link.group() else {
                continue;
            };
            if let Some(v) = self.start_elastic(&link) {
                let g = &mut self.groups[group];
                g.start += v;
                g.magnitude += v;
            }
        }
    }

    /// Forgets what the last step measured: the next start measures every energy afresh.
    /// (For tests that compare the reuse with fresh measurements.)
    #[cfg(test)]
    pub(crate) fn forget_measurements(&mut self) {
        for body in &mut self.bodies {
            body.memo = BodyMemo::NONE;
        }
        for link in &mut self.links {
            link.measured = 0;
        }
        self.closed = false;
    }
}

/// The kinetic energy at the start of the step of the body `item` whose ledger entry is `last`
/// (the caller has checked the entity), and whether it is still as end pass `passes` measured
/// it (nothing written since, [`memo`]): then the energy is that measurement, else it is
/// measured now.
#[inline]
pub(super) fn start_kinetic_of(
    last: &Audited,
    passes: u64,
    (_, t, v, m, ticks): BodyItem,
    since: &EndTick,
) -> (f64, bool) {
    if last.memo.still(passes, since.any_written(ticks)) {
        (last.memo.kinetic(), true)
    } else {
        (kinetic_energy_f64(t, v, m), false)
    }
}

/// World anchor of an end among the audited `bodies`, from the pose `pose` gives an audited
/// body.
#[inline(always)]
fn anchor_among(bodies: &[Audited], end: End, pose: impl Fn(&Audited) -> Pose) -> Option<Vec3> {
    match end {
        End::Audited(i, local) => Some(pose(&bodies[i as usize]).transform_point(local)),
        End::Fixed(p) => Some(p),
        End::Kinematic | End::Inactive => None,
    }
}

/// Elastic energy of a link among the audited `bodies`, with the bodies at the poses `pose`
/// gives; `None` when an end is kinematic or inactive.
#[inline]
pub(super) fn elastic_among(
    bodies: &[Audited],
    link: &Link,
    pose: impl Fn(&Audited) -> Pose + Copy,
) -> Option<f64> {
    let pa = anchor_among(bodies, link.a, pose)?;
    let pb = anchor_among(bodies, link.b, pose)?;
    Some(link.elastic_energy(pa, pb))
}

/// Works `each` on the ledger's entries from index `first` zipped with a table's `entities`
/// (`each` gets the entry and its body's row in the table, and returns false to stop), split
/// over the compute pool's threads as [`Parallelism`] allows. False where an entry is not its
/// row's body or `each` stopped (the run's entries before it are worked), or the ledger ends
/// before the table does.
pub(super) fn zip_table(
    entries: &mut [Audited],
    first: usize,
    entities: &[Entity],
    parallelism: &Parallelism,
    each: impl Fn(&mut Audited, usize) -> bool + Sync,
) -> bool {
    let Some(entries) = entries.get_mut(first..first + entities.len()) else {
        return false;
    };
    in_runs(
        parallelism.threads_for(entries.len()),
        entries,
        |at, run| {
            run.iter_mut()
                .enumerate()
                .all(|(k, body)| body.entity == entities[at + k] && each(body, at + k))
        },
    )
}

/// Rigid bodies that are not quarantined, whatever their kind (spring ends may be static or
/// kinematic).
pub(super) type Ends<'w, 's> = Query<
    'w,
    's,
    (&'static Pose, Has<Static>, Has<Kinematic>),
    (With<RigidBody>, Without<Rejected>),
>;

/// Both ends of `spring`, resolved.
pub(super) fn resolve_ends(ledger: &EnergyLedger, ends: &Ends, spring: &Spring) -> (End, End) {
    let a = end_of(ledger, ends, spring.a, spring.anchor_a);
    let b = match spring.b {
        SpringEnd::World(p) => End::Fixed(p),
        SpringEnd::Body { body, anchor } => end_of(ledger, ends, body, anchor),
    };
    (a, b)
}

pub(super) fn end_of(ledger: &EnergyLedger, ends: &Ends, body: Entity, anchor: Vec3) -> End {
    if let Some(i) = ledger.slot(body) {
        return End::Audited(i as u32, anchor);
    }
    match ends.get(body) {
        Ok((_, _, true)) => End::Kinematic,
        Ok((t, true, _)) => End::Fixed(t.transform_point(anchor)),
        _ => End::Inactive,
    }
}

/// The same end, bit for bit.
pub(super) fn same_end(a: End, b: End) -> bool {
    let same = |p: Vec3, q: Vec3| same_bits(p.to_array(), q.to_array());
    match (a, b) {
        (End::Audited(i, p), End::Audited(j, q)) => i == j && same(p, q),
        (End::Fixed(p), End::Fixed(q)) => same(p, q),
        (End::Kinematic, End::Kinematic) | (End::Inactive, End::Inactive) => true,
        _ => false,
    }
}

/// The bodies the audit watches, as its start pass reads them (with the change ticks that say
/// whether anything wrote them since the last end pass, or their mass since the last start
/// pass, [`memo`]).
pub(super) type AuditedBodies<'w, 's> = Query<
    'w,
    's,
    (
        Entity,
        Ref<'static, Pose>,
        Ref<'static, Velocity>,
        Ref<'static, MassProps>,
    ),
    Dynamic,
>;

/// One audited body as the start pass reads it: its state and mass, and when each of its pose,
/// velocity and mass last changed.
pub(super) type BodyItem<'a> = (Entity, &'a Pose, &'a Velocity, &'a MassProps, [Tick; 3]);

/// [`BodyItem`] of a query item.
#[inline(always)]
pub(super) fn body_item<'w>(
    (entity, t, v, m): (Entity, Ref<'w, Pose>, Ref<'w, Velocity>, Ref<'w, MassProps>),
) -> BodyItem<'w> {
    let ticks = [t.last_changed(), v.last_changed(), m.last_changed()];
    (
        entity,
        t.into_inner(),
        v.into_inner(),
        m.into_inner(),
        ticks,
    )
}

/// The springs the audit measures, with their entities (visited in entity index order) and
/// the change ticks that say whether anything wrote them since the last start pass resolved
/// them ([`memo`]).
pub(super) type AuditedSprings<'w, 's> = Query<'w, 's, (Entity, Ref<'static, Spring>)>;

/// Calls `f` on every spring with its entity and last change, in entity index order (`order`,
/// refreshed by the caller from the same query).
pub(super) fn for_each_spring(
    order: &IndexOrder,
    springs: &AuditedSprings,
    mut f: impl FnMut(Entity, &Spring, Tick),
) {
    let mut each = |(entity, spring): (Entity, Ref<Spring>)| {
        f(entity, spring.into_inner(), spring.last_changed())
    };
    if order.is_query_order() {
        springs.iter().for_each(&mut each);
    } else {
        for &entity in order.entities() {
            if let Ok(item) = springs.get(entity) {
                each(item);
            }
        }
    }
}

/// Calls `f` on every audited body in entity index order: the order of the ledger's table of
/// bodies, and with it of every sum over a group's bodies, whatever order the query visits its
/// tables in (see [`IndexOrder`]). `order` is scratch, kept between steps.
pub(super) fn for_each_audited(
    order: &mut IndexOrder,
    bodies: &AuditedBodies,
    mut f: impl FnMut(BodyItem),
) {
    order.refresh_entities(bodies.iter().map(|(e, ..)| e));
    if order.is_query_order() {
        for item in bodies {
            f(body_item(item));
        }
        return;
    }
    for &entity in order.entities() {
        if let Ok(item) = bodies.get(entity) {
            f(body_item(item));
        }
    }
}
