//! The energy audit: a step that creates energy out of nothing is a divergence, even while every
//! number is still finite.
//!
//! An integrator outside its stable region (a spring with `√(k/μ)Δt ≥ 2`, an explicit
//! gyroscopic term on a fast asymmetric spin) grows the energy geometrically; the state stays
//! finite for many steps, long enough to write positions of 10²⁰ m as if they were state. The
//! audit catches that at the step where it happens, quarantines the bodies involved and puts
//! them back to the state they had before that step.
//!
//! ## The balance
//!
//! Bodies joined by springs share their energy, so the audit works on *groups*: the connected
//! components of the spring graph (a lone body is its own group). For a group, with `T` the
//! kinetic energy `Σ ½m|v|² + ½ωᵀIω` and `V` the elastic energy `Σ ½k(|d| − L₀)²` of its
//! springs, each step must satisfy
//!
//! ```text
//! (T + V)_end − (T + V)_start = W_ext + e_step
//! W_ext = Δt Σ_bodies ( F·(v_start + v_end)/2 + τ·(ω_start + ω_end)/2 )
//! ```
//!
//! where `F`, `τ` are every load on the body except the springs (gravity, constant forces and
//! torques, forces game code or its own systems added) and `e_step` is the integrator's energy
//! error. The `(v_start + v_end)/2` form is the drift–kick–drift displacement exactly, so a
//! constant force credits exactly the work the step did. In a step of several stages (substeps,
//! `yoshida4`; see [`crate::stages`]) the balance is still closed once per step, with `F`, `τ`
//! the loads of the stages weighted by their spans, `Σ (h/Δt) F_stage`, and `ω_max Δt` below
//! measured on the step's stability span (`Stages::stability_span`). Spring dampers and
//! [`Damping`](crate::components::Damping) are velocity flows at the start and end of the step
//! ([`crate::damping`]); they only remove energy, are not credited, and lower `D`. The audit keeps the running sum `D = Σ e_step` per group
//! (the energy the integrator made up; changes game code makes between steps are not part of
//! it) and rejects the group when
//!
//! ```text
//! D > (A − 1) · E + ε,      E = (T + V)_start − D    (the energy the group should have)
//! ```
//!
//! `A` is twice the largest ratio of energies on one orbit of a *stable* linear spring under the
//! method's position update, with `x = min(ω_max Δt, 1.99)/2`:
//!
//! - drift–kick–drift (Störmer–Verlet, the midpoint methods): the step conserves
//!   `½(1 − x²)|v|² + ½ω²|d|²` exactly, so the energy swings within `[1, 1/(1 − x²)]` times it;
//!   `A = 2/(1 − x²)`;
//! - kick–drift (symplectic Euler and the other start-of-step methods): it conserves
//!   `½(|v|² + ω²|d|² − ωΔt ω d·v)`, a swing of `(1 + x)/(1 − x)`; `A = 2(1 + x)/(1 − x)`.
//!
//! A stable spring's energy swings up to that factor and comes back, and must never be flagged.
//! `ω_max` is the stiffest spring of the group (`√(k/μ)`, `μ` the reduced mass of its ends); the
//! factor 2 covers the extra compliance of off-centre anchors and the O(Δt²) error of the
//! rotation. A group without springs has `A = 2`: a free body may not double its energy on its
//! own. `ε` is round-off: `64 ε_Real` times the energy and work magnitudes of the step.
//!
//! Unstable integration grows `D` geometrically, so it crosses the bound within a few periods;
//! the group is then rejected *before* its state is garbage, and keeps the last state that
//! passed.
//!
//! ## What is audited, and what it costs
//!
//! [`EnergyAudit::Auto`] (the default) audits a world with springs: whether a spring network is
//! inside the stable region depends on the state (off-centre anchors change the effective mass
//! as the bodies turn), so only a check of what happened is safe. Other worlds pay nothing: the
//! audit's systems are not in their plan. The other divergence the planner knows, an explicit
//! gyroscopic term on a fast asymmetric spin (`symplectic-euler`, `symplectic-euler-linear`), is
//! predicted from the spins at planning time ([`check_stability`](crate::stability)); insert
//! [`EnergyAudit::Always`] to have such a run audited as well (the `tumble` CLI does when it runs
//! a world despite a warning). [`EnergyAudit::Never`] turns the audit off.
//!
//! The audit costs one pass over the bodies and the springs at the start of the step, one over
//! the bodies' accumulators before the springs add to them (the plan runs the springs right
//! after it, so the other loads are read as they are, not recomputed as the sum less every
//! spring's force), and one at the end. The end pass measures one kinetic and one elastic
//! energy per body and spring; the start pass reuses them where the body or spring is, bit for
//! bit, as that pass left it (`memo`), and measures afresh only what game code changed. When
//! the spring graph is as the last step left it (the same bodies, masses and springs), the
//! start also keeps the last step's groups (`EnergyLedger::restart`); when nothing changed at
//! all, it takes each group's `T + V` from the sum its end pass closed with: the same number,
//! added in the same order. All serial, so in a
//! loaded spring world it is the largest single part of the step
//! (`cargo bench --bench audit` measures the ratio on a 10⁴-body chain). Bodies are found by
//! entity index in a table the ledger keeps, not by hashing; it allocates only when the world
//! grows.
//!
//! Not audited: a group holding a [`Kinematic`] body (game code moves it and does work the
//! audit cannot see). [`Static`] bodies are fixed anchors.

mod memo;

use bevy_ecs::entity::EntityHashMap;
use bevy_ecs::prelude::*;
use tumble_core::math::{Real, Vec3, Widen};

use crate::components::{
    ForceAccumulator, Gravity, GravityScale, Kinematic, MassProps, PhysicsSettings, Pose,
    RigidBody, Static, Velocity, kinetic_energy_f64,
};
use crate::forces::{Spring, SpringEnd};
use crate::stages::StageCursor;
use crate::systems::Dynamic;
use crate::validate::{BodyError, BodyErrorKind, Rejected, reject};
use memo::BodyMemo;

/// Whether a world's steps are audited for energy created by the integrator (see the module
/// docs). Insert it as a resource to override the default, [`EnergyAudit::Auto`].
#[derive(Resource, Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum EnergyAudit {
    /// Audit worlds with springs.
    #[default]
    Auto,
    /// Audit every world with dynamic bodies.
    Always,
    /// Never audit.
    Never,
}

impl EnergyAudit {
    /// Whether a world with (or without) springs is audited.
    pub fn applies(self, has_springs: bool) -> bool {
        match self {
            EnergyAudit::Always => true,
            EnergyAudit::Never => false,
            EnergyAudit::Auto => has_springs,
        }
    }
}

/// The audit's largest `ωΔt` in the stable-spring factor: at 2 the factor is infinite, and
/// beyond it the spring is unstable and grows geometrically past any finite bound anyway.
const OMEGA_DT_CAP: f64 = 1.99;

/// Round-off allowance, in units of the precision's epsilon, on the step's energy magnitudes.
const ROUND_OFF_ULPS: f64 = 64.0;

/// What the audit remembers of one body during a step.
#[derive(Debug, Clone, Copy)]
struct Audited {
    entity: Entity,
    start: (Pose, Velocity),
    /// Pose at the end of the step (for the springs' energy).
    end: Pose,
    /// Every load except the springs: force and torque (world frame).
    load: (Vec3, Vec3),
    /// Mass (kg), for the springs' reduced mass.
    mass: f64,
    /// Union–find parent.
    parent: usize,
    /// Its group's index in [`EnergyLedger::groups`], once the start pass has joined every
    /// spring's ends.
    group: usize,
    /// Unchanged since the end of the last step (bit for bit, [`memo`]).
    still: bool,
    /// Kinetic energy at the start of the step.
    start_energy: f64,
}

/// One end of a spring as the audit sees it.
#[derive(Debug, Clone, Copy)]
enum End {
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
struct Link {
    stiffness: Real,
    rest_length: Real,
    a: End,
    b: End,
    /// The end pass that measured `elastic` with these inputs (0: none did).
    measured: u64,
    /// The elastic energy that pass measured.
    elastic: f64,
}

impl Link {
    /// The spring `spring` with its ends resolved to `a` and `b`, not measured yet.
    fn new(spring: &Spring, a: End, b: End) -> Self {
        Self {
            stiffness: spring.stiffness,
            rest_length: spring.rest_length,
            a,
            b,
            measured: 0,
            elastic: 0.0,
        }
    }

    /// The audited bodies at its ends.
    fn audited_bodies(&self) -> impl Iterator<Item = usize> {
        [self.a, self.b].into_iter().filter_map(|end| match end {
            End::Audited(i, _) => Some(i as usize),
            _ => None,
        })
    }

    /// True when `other` has the same inputs, bit for bit, apart from its audited bodies'
    /// poses (see [`BodyMemo::still`] for those).
    fn same_inputs(&self, other: &Link) -> bool {
        let bits = |l: &Link| [l.stiffness, l.rest_length].map(Real::to_bits);
        bits(self) == bits(other) && same_end(self.a, other.a) && same_end(self.b, other.b)
    }

    /// `½ k (|d| − L₀)²` with the anchors at the world points `pa` and `pb` (J, `f64`).
    fn elastic_energy(&self, pa: Vec3, pb: Vec3) -> f64 {
        let stretch = (pa - pb).widen().length() - self.rest_length.widen();
        0.5 * self.stiffness.widen() * stretch * stretch
    }
}

/// One group's running account, keyed by its smallest entity.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Account {
    /// Members and springs when the account was opened: a group that changes starts afresh.
    signature: (usize, usize),
    /// `D`: energy the integrator created so far (J).
    created: f64,
    /// Seen in the current step (stale accounts are dropped).
    seen: bool,
}

/// Per-group sums of one step.
#[derive(Debug, Clone, Copy, Default)]
struct GroupStep {
    members: usize,
    springs: usize,
    key: Option<Entity>,
    kinematic: bool,
    /// `(T + V)` at the start.
    start: f64,
    /// `(T + V)` at the end.
    end: f64,
    /// `W_ext`.
    work: f64,
    /// Magnitudes for the round-off allowance.
    magnitude: f64,
    /// Stiffest spring's `ωΔt`.
    omega_dt: f64,
}

/// The audit's bookkeeping (reused every step so that steps do not allocate).
#[derive(Resource, Debug, Default)]
pub struct EnergyLedger {
    bodies: Vec<Audited>,
    /// The index in `bodies` of an entity, at its `index_u32`: a dense table, not a hash map
    /// (four lookups per body and step). Entries of entities no longer audited are left in
    /// place: a lookup checks the entity it finds.
    slots: Vec<u32>,
    links: Vec<Link>,
    groups: Vec<GroupStep>,
    accounts: EntityHashMap<Account>,
    dt: f64,
    /// The plain step with the stability of one substep (`Δt` unless there are substeps or a
    /// composition, see `Stages::stability_span`): the span a spring's `ωh` is measured on.
    stability_span: f64,
    /// Whether the integrator drifts–kicks–drifts (else it kicks, then drifts).
    midpoint: bool,
    /// Accounts were restored under some member of their group, not necessarily its smallest
    /// entity (entity ids change when a world is restored): re-key them at the next audit.
    restored: bool,
    /// End passes so far: what the last one measured carries its number.
    end_passes: u64,
    /// The last end pass's kinetic energies, by body index, with their inputs ([`memo`]).
    measured_bodies: Vec<Option<BodyMemo>>,
    /// The groups were closed by an end pass since the last start: their end sums are the
    /// energies the bodies stand at now, if nothing changed ([`EnergyLedger::restart`]).
    closed: bool,
    /// Starts that took the unchanged world's shortcut (for tests).
    #[cfg(test)]
    restarts: usize,
    /// Starts that kept the last step's groups and measured what changed (for tests).
    #[cfg(test)]
    partial_restarts: usize,
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

/// The audit's running accounts as a [`RollbackSnapshot`](crate::rollback::RollbackSnapshot)
/// keeps them: the energy each spring group's integration has made up so far, which decides
/// whether a later step quarantines the group. Opaque; in entity order.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct LedgerState {
    accounts: Vec<(Entity, Account)>,
    restored: bool,
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
    fn slot(&self, entity: Entity) -> Option<usize> {
        let i = *self.slots.get(entity.index_u32() as usize)? as usize;
        (self.bodies.get(i)?.entity == entity).then_some(i)
    }

    /// Records that `entity` is audited at index `i`.
    fn set_slot(&mut self, entity: Entity, i: usize) {
        let at = entity.index_u32() as usize;
        if at >= self.slots.len() {
            self.slots.resize(at + 1, u32::MAX);
        }
        self.slots[at] = i as u32;
    }

    fn find(&mut self, mut i: usize) -> usize {
        while self.bodies[i].parent != i {
            let grand = self.bodies[self.bodies[i].parent].parent;
            self.bodies[i].parent = grand;
            i = grand;
        }
        i
    }

    fn union(&mut self, a: usize, b: usize) {
        let (ra, rb) = (self.find(a), self.find(b));
        if ra != rb {
            // Attach to the smaller index so that the root does not depend on spring order.
            let (lo, hi) = if ra < rb { (ra, rb) } else { (rb, ra) };
            self.bodies[hi].parent = lo;
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

    /// The group (root index) a link belongs to, if it touches an audited body.
    fn group_of(&self, link: &Link) -> Option<usize> {
        match (link.a, link.b) {
            (End::Audited(i, _), _) | (_, End::Audited(i, _)) => {
                Some(self.bodies[i as usize].group)
            }
            _ => None,
        }
    }

    /// World anchor of an end, from the pose `pose` gives an audited body.
    fn anchor(&self, end: End, pose: impl Fn(&Audited) -> Pose) -> Option<Vec3> {
        match end {
            End::Audited(i, local) => Some(pose(&self.bodies[i as usize]).transform_point(local)),
            End::Fixed(p) => Some(p),
            End::Kinematic | End::Inactive => None,
        }
    }

    /// Elastic energy of a link with the bodies at the poses `pose` gives.
    fn elastic(&self, link: &Link, pose: impl Fn(&Audited) -> Pose + Copy) -> Option<f64> {
        let pa = self.anchor(link.a, pose)?;
        let pb = self.anchor(link.b, pose)?;
        Some(link.elastic_energy(pa, pb))
    }

    /// Link `k`'s elastic energy at the start of the step: the one the last step ended with
    /// when its inputs are the same bit for bit, else measured afresh.
    fn start_elastic(&self, link: &Link) -> Option<f64> {
        // Its bodies are still, so their memos are from the same pass as the spring's.
        if link.measured == self.end_passes && link.audited_bodies().all(|i| self.bodies[i].still) {
            return Some(link.elastic);
        }
        self.elastic(link, |b| b.start.0)
    }

    /// The start of a step when the world's spring graph is as the last step left it: the
    /// same audited bodies in the same order with the same masses, the same springs (bit for
    /// bit) with the same ends. Then the groups, links and union–find of the last step hold,
    /// and only the energies need measuring, each reused from its [`memo`] where its inputs
    /// are unchanged; when nothing changed at all, each group's `T + V` is the sum its end pass
    /// closed with (the start pass would add the same energies in the same order). Either way
    /// the sums are the full start pass's, bit for bit. Returns false as soon as the graph
    /// differs, having changed only what the full start pass rebuilds.
    fn restart(&mut self, bodies: &AuditedBodies, ends: &Ends, springs: &Query<&Spring>) -> bool {
        let mut n = 0;
        let mut all_still = true;
        for (entity, t, v, m) in bodies {
            let Some(body) = self.bodies.get(n) else {
                return false;
            };
            if body.entity != entity {
                return false;
            }
            let (energy, still) = self.start_kinetic(n, (entity, t, v, m));
            // A new mass changes the springs' reduced masses, so their stiffness bound: regroup.
            if !still && m.mass().widen().to_bits() != body.mass.to_bits() {
                return false;
            }
            let body = &mut self.bodies[n];
            body.start = (*t, *v);
            body.end = *t;
            body.load = (Vec3::ZERO, Vec3::ZERO);
            (body.start_energy, body.still) = (energy, still);
            all_still &= still;
            n += 1;
        }
        if n != self.bodies.len() {
            return false;
        }
        let mut k = 0;
        for spring in springs {
            let Some(link) = self.links.get(k) else {
                return false;
            };
            // Resolved again: an end that is not an audited body may have moved (a static
            // body) or changed kind since.
            let (a, b) = resolve_ends(self, ends, spring);
            if !link.same_inputs(&Link::new(spring, a, b)) {
                return false;
            }
            k += 1;
        }
        if k != self.links.len() {
            return false;
        }
        if all_still {
            for g in &mut self.groups {
                (g.start, g.magnitude) = (g.end, g.end);
                (g.end, g.work) = (0.0, 0.0);
            }
            #[cfg(test)]
            {
                self.restarts += 1;
            }
            return true;
        }
        self.sum_start_energies();
        #[cfg(test)]
        {
            self.partial_restarts += 1;
        }
        true
    }

    /// The kinetic energy at the start of the step of the body read at index `i`, and whether
    /// it is still as the last end pass measured it there (bit for bit, [`memo`]): then the
    /// energy is that measurement, else it is measured now.
    fn start_kinetic(
        &self,
        i: usize,
        (entity, t, v, m): (Entity, &Pose, &Velocity, &MassProps),
    ) -> (f64, bool) {
        match self.measured_bodies.get(i) {
            Some(Some(memo)) if memo.pass == self.end_passes && memo.still(entity, t, v, m) => {
                (memo.kinetic(), true)
            }
            _ => (kinetic_energy_f64(t, v, m), false),
        }
    }

    /// Each group's `T + V` at the start of the step (and its magnitude for the round-off
    /// allowance), from the bodies' `start_energy` and the springs' elastic energy
    /// ([`start_elastic`](Self::start_elastic)): the bodies by index into their roots, then the
    /// springs in order, so the sums do not depend on which start pass formed the groups.
    fn sum_start_energies(&mut self) {
        for g in &mut self.groups {
            (g.start, g.magnitude, g.end, g.work) = (0.0, 0.0, 0.0, 0.0);
        }
        for i in 0..self.bodies.len() {
            let Audited {
                group,
                start_energy,
                ..
            } = self.bodies[i];
            let g = &mut self.groups[group];
            g.start += start_energy;
            g.magnitude += start_energy;
        }
        for k in 0..self.links.len() {
            let link = self.links[k];
            let Some(group) = self.group_of(&link) else {
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
        self.measured_bodies.clear();
        for link in &mut self.links {
            link.measured = 0;
        }
        self.closed = false;
    }
}

/// Rigid bodies that are not quarantined, whatever their kind (spring ends may be static or
/// kinematic).
type Ends<'w, 's> = Query<
    'w,
    's,
    (&'static Pose, Has<Static>, Has<Kinematic>),
    (With<RigidBody>, Without<Rejected>),
>;

/// Both ends of `spring`, resolved.
fn resolve_ends(ledger: &EnergyLedger, ends: &Ends, spring: &Spring) -> (End, End) {
    let a = end_of(ledger, ends, spring.a, spring.anchor_a);
    let b = match spring.b {
        SpringEnd::World(p) => End::Fixed(p),
        SpringEnd::Body { body, anchor } => end_of(ledger, ends, body, anchor),
    };
    (a, b)
}

fn end_of(ledger: &EnergyLedger, ends: &Ends, body: Entity, anchor: Vec3) -> End {
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
fn same_end(a: End, b: End) -> bool {
    let bits = |p: Vec3| p.to_array().map(Real::to_bits);
    match (a, b) {
        (End::Audited(i, p), End::Audited(j, q)) => i == j && bits(p) == bits(q),
        (End::Fixed(p), End::Fixed(q)) => bits(p) == bits(q),
        (End::Kinematic, End::Kinematic) | (End::Inactive, End::Inactive) => true,
        _ => false,
    }
}

/// The bodies the audit watches, as its start pass reads them.
type AuditedBodies<'w, 's> =
    Query<'w, 's, (Entity, &'static Pose, &'static Velocity, &'static MassProps), Dynamic>;

/// Start of an audited step (first in the plan): remembers each dynamic body's state, resolves
/// the springs' ends, forms the spring groups and measures each group's `T + V`.
pub fn audit_energy_start(
    settings: Res<PhysicsSettings>,
    cursor: Res<StageCursor>,
    mut ledger: ResMut<EnergyLedger>,
    bodies: AuditedBodies,
    ends: Ends,
    springs: Query<&Spring>,
) {
    let ledger = &mut *ledger;
    if !cursor.span(&settings).opens_step {
        return;
    }
    ledger.dt = settings.dt().widen();
    let stability_span = settings.stages().stability_span(settings.dt()).widen();
    let same_span = stability_span.to_bits() == ledger.stability_span.to_bits();
    ledger.stability_span = stability_span;
    ledger.midpoint = settings.integrator.samples_forces_at_midpoint();
    if std::mem::take(&mut ledger.closed) && same_span && ledger.restart(&bodies, &ends, &springs) {
        return;
    }
    ledger.bodies.clear();
    ledger.groups.clear();
    // Exact sizes: grown by doubling, a vector of a million entries would briefly be held
    // twice, and this pass is the audit's peak.
    ledger.bodies.reserve_exact(bodies.iter().len());
    ledger
        .links
        .reserve_exact(springs.iter().len().saturating_sub(ledger.links.len()));
    for (entity, t, v, m) in &bodies {
        let i = ledger.bodies.len();
        let (energy, still) = ledger.start_kinetic(i, (entity, t, v, m));
        ledger.set_slot(entity, i);
        ledger.bodies.push(Audited {
            entity,
            start: (*t, *v),
            end: *t,
            load: (Vec3::ZERO, Vec3::ZERO),
            mass: m.mass().widen(),
            parent: i,
            group: 0,
            still,
            start_energy: energy,
        });
    }
    // Each link is written over the last step's link at its index, keeping that one's
    // measurement when the inputs are the same ([`memo`]).
    let old = ledger.links.len();
    let mut k = 0;
    for spring in &springs {
        let (a, b) = resolve_ends(ledger, &ends, spring);
        if let (End::Audited(i, _), End::Audited(j, _)) = (a, b) {
            ledger.union(i as usize, j as usize);
        }
        let mut link = Link::new(spring, a, b);
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
    }
    ledger.links.truncate(k);
    // Each body's group (roots are final now), numbered in the order of their roots. A root
    // is its group's smallest index (`union` attaches to the smaller), so it is met first and
    // its group numbered before any other member asks for it.
    for i in 0..ledger.bodies.len() {
        let root = ledger.find(i);
        let group = if root == i {
            ledger.groups.push(GroupStep::default());
            ledger.groups.len() - 1
        } else {
            ledger.bodies[root].group
        };
        ledger.bodies[i].group = group;
        let entity = ledger.bodies[i].entity;
        let g = &mut ledger.groups[group];
        g.members += 1;
        g.key = Some(g.key.map_or(entity, |k| k.min(entity)));
    }
    for k in 0..ledger.links.len() {
        let link = ledger.links[k];
        let Some(group) = ledger.group_of(&link) else {
            continue;
        };
        let kinematic = matches!(link.a, End::Kinematic) || matches!(link.b, End::Kinematic);
        let mass = |end: End| match end {
            End::Audited(i, _) => ledger.bodies[i as usize].mass,
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
        let omega_dt = (link.stiffness.widen() / reduced).sqrt() * ledger.stability_span;
        let g = &mut ledger.groups[group];
        g.springs += 1;
        g.kinematic |= kinematic;
        g.omega_dt = g.omega_dt.max(omega_dt);
    }
    ledger.sum_start_energies();
}

/// Before the integration, after every force system but the springs (the plan runs
/// [`apply_springs`](crate::forces::apply_springs) right after this system in audited worlds):
/// records each audited body's load without the springs, `F`, `τ`, as the accumulators hold it
/// now. (Spring dampers are not forces in the accumulators: they are the velocity flow of
/// [`crate::damping`], an energy loss the balance sees and never flags. Implicit springs never
/// write to the accumulators.)
pub fn audit_external_loads(
    settings: Res<PhysicsSettings>,
    cursor: Res<StageCursor>,
    mut ledger: ResMut<EnergyLedger>,
    bodies: Query<
        (
            Entity,
            &Pose,
            &ForceAccumulator,
            Option<&crate::stiff::ImplicitBody>,
        ),
        Dynamic,
    >,
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
    for (entity, t, acc, implicit) in &bodies {
        let Some(i) = ledger.slot(entity) else {
            continue;
        };
        // The torque of the forces at points an implicit body's solve takes at mid-step,
        // credited here at the pose the forces were sampled at.
        let torque = acc.torque + implicit.map_or(Vec3::ZERO, |b| b.point_torque(t.rotation));
        let load = &mut ledger.bodies[i].load;
        match share {
            None => *load = (acc.force, torque),
            Some(w) => {
                if span.opens_step {
                    *load = (Vec3::ZERO, Vec3::ZERO);
                }
                load.0 += w * acc.force;
                load.1 += w * torque;
            }
        }
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
    bodies: Query<
        (
            Entity,
            &Pose,
            &Velocity,
            &MassProps,
            Option<&GravityScale>,
            Has<ForceAccumulator>,
        ),
        Dynamic,
    >,
    mut commands: Commands,
) {
    let ledger = &mut *ledger;
    if !cursor.span(&settings).closes_step {
        return;
    }
    let dt = ledger.dt;
    let gravity = gravity.map(|g| g.0);
    // Only what this pass measures may be reused (a body it does not see keeps an older memo,
    // which its number rules out): a spring's memo is reused only with its bodies' poses
    // measured in the same pass.
    ledger.end_passes += 1;
    let pass = ledger.end_passes;
    ledger.measured_bodies.resize(ledger.bodies.len(), None);
    for (entity, t, v, m, scale, has_accumulator) in &bodies {
        let Some(i) = ledger.slot(entity) else {
            continue;
        };
        let body = &mut ledger.bodies[i];
        let group = body.group;
        body.end = *t;
        let (force, torque) = match gravity {
            // Bodies without an accumulator take gravity inside the integration.
            Some(g) if !has_accumulator => (m.mass() * scale.map_or(1.0, |s| s.0) * g, Vec3::ZERO),
            _ => body.load,
        };
        let v0 = body.start.1;
        let v_mean = 0.5 * (v0.linear.widen() + v.linear.widen());
        let w_mean = 0.5 * (v0.angular.widen() + v.angular.widen());
        let work = dt * (force.widen().dot(v_mean) + torque.widen().dot(w_mean));
        let measured = BodyMemo::measure(pass, entity, t, v, m);
        let energy = measured.kinetic();
        ledger.measured_bodies[i] = Some(measured);
        let g = &mut ledger.groups[group];
        g.end += energy;
        g.work += work;
        g.magnitude += energy + work.abs();
    }
    for k in 0..ledger.links.len() {
        let link = ledger.links[k];
        let Some(group) = ledger.group_of(&link) else {
            continue;
        };
        let elastic = ledger.elastic(&link, |b| b.end);
        let memo = &mut ledger.links[k];
        (memo.measured, memo.elastic) = match elastic {
            Some(v) => (pass, v),
            None => (0, 0.0),
        };
        if let Some(v) = elastic {
            ledger.groups[group].end += v;
            ledger.groups[group].magnitude += v;
        }
    }
    if std::mem::take(&mut ledger.restored) {
        // Move each restored account to its group's key (the smallest entity of the group).
        for i in 0..ledger.bodies.len() {
            let Audited { entity, group, .. } = ledger.bodies[i];
            if let Some(key) = ledger.groups[group].key
                && key != entity
                && let Some(account) = ledger.accounts.remove(&entity)
            {
                ledger.accounts.insert(key, account);
            }
        }
    }
    for account in ledger.accounts.values_mut() {
        account.seen = false;
    }
    let eps = ROUND_OFF_ULPS * Real::EPSILON.widen();
    for group in 0..ledger.groups.len() {
        // Every group has a member, so a key; a group without one would have nothing to audit.
        let Some(key) = ledger.groups[group].key else {
            continue;
        };
        let g = ledger.groups[group];
        if g.kinematic {
            continue;
        }
        let signature = (g.members, g.springs);
        let account = ledger.accounts.entry(key).or_insert(Account {
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
        let should = (g.start - before).max(0.0);
        account.created += g.end - g.start - g.work;
        let x = OMEGA_DT_CAP.min(g.omega_dt) / 2.0;
        let factor = if ledger.midpoint {
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
        for i in 0..ledger.bodies.len() {
            if ledger.bodies[i].group != group {
                continue;
            }
            let body = ledger.bodies[i];
            commands.entity(body.entity).insert(body.start);
            reject(
                &mut commands,
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
    ledger.accounts.retain(|_, a| a.seen);
    ledger.closed = true;
}

#[cfg(test)]
mod tests;
