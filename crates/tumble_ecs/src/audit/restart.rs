//! The start of a step when the world's spring graph is as the last step left it: the groups,
//! links and union–find of the last step hold, and only the energies need measuring.

use std::sync::atomic::{AtomicBool, Ordering};

use tumble_core::math::{Vec3, Widen};

use super::ledger::{
    Audited, AuditedBodies, AuditedSprings, BodyItem, Ends, EnergyLedger, Link, for_each_audited,
    for_each_spring, resolve_ends, start_kinetic_of, zip_table,
};
use super::memo::{EndTick, Marks};
use crate::components::{Spring, dense};
use crate::parallel::{Parallelism, all_runs};
use bevy_ecs::change_detection::Tick;
use bevy_ecs::entity::Entity;

impl EnergyLedger {
    /// The start of a step when the world's spring graph is as the last step left it: the
    /// same audited bodies in the same order with the same masses, the same springs (bit for
    /// bit) with the same ends. Then the groups, links and union–find of the last step hold,
    /// and only the energies need measuring, each reused from its [`memo`] where its inputs
    /// are unchanged; when nothing changed at all, each group's `T + V` is the sum its end pass
    /// closed with (the start pass would add the same energies in the same order). Either way
    /// the sums are the full start pass's, bit for bit. Returns false as soon as the graph
    /// differs, having changed only what the full start pass rebuilds.
    pub(super) fn restart(
        &mut self,
        bodies: &AuditedBodies,
        ends: &Ends,
        springs: &AuditedSprings,
        (marks, parallelism): (&Marks, &Parallelism),
    ) -> bool {
        let Some(all_still) = self.restart_bodies(bodies, marks, parallelism) else {
            return false;
        };
        if !self.same_springs(ends, springs, &marks.start, parallelism) {
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

    /// The springs' part of [`restart`](Self::restart): each spring, in entity index order, is
    /// the ledger's link at its index with the same inputs, bit for bit, its ends resolved
    /// again (an end that is not an audited body may have moved, a static body, or changed
    /// kind since). Where the query visits the springs in that order, table by table, each
    /// table is zipped with the ledger's next links and split over the compute pool's threads
    /// as [`Parallelism`] allows.
    fn same_springs(
        &self,
        ends: &Ends,
        springs: &AuditedSprings,
        since: &EndTick,
        parallelism: &Parallelism,
    ) -> bool {
        let same_link = |link: &Link, (entity, spring, changed): (Entity, &Spring, Tick)| {
            // The same spring, not written since the last start resolved it, between the last
            // step's audited bodies (checked first, by `restart_bodies`): resolved as it was.
            if link.stable && link.spring == entity && !since.written(changed) {
                return true;
            }
            let (a, b) = resolve_ends(self, ends, spring);
            link.same_inputs(&Link::new(entity, spring, a, b))
        };
        let mut k = 0;
        if self.spring_order.is_query_order() {
            for (entities, table) in dense(springs.contiguous_iter()) {
                let Some(links) = self.links.get(k..k + table.len()) else {
                    return false;
                };
                let changed = table.changed_ticks_slice();
                let threads = parallelism.threads_for(links.len());
                let same = all_runs(threads, links, |at, run| {
                    run.iter().enumerate().all(|(k, link)| {
                        let j = at + k;
                        same_link(link, (entities[j], &table[j], changed[j]))
                    })
                });
                if !same {
                    return false;
                }
                k += table.len();
            }
        } else {
            let mut same = true;
            for_each_spring(&self.spring_order, springs, |entity, spring, changed| {
                match self.links.get(k).filter(|_| same) {
                    Some(link) => same = same_link(link, (entity, spring, changed)),
                    None => same = false,
                }
                k += 1;
            });
            if !same {
                return false;
            }
        }
        k == self.links.len()
    }

    /// The bodies' part of [`restart`](Self::restart): each audited body, in entity index
    /// order, must be the ledger's entry at its index with its mass unchanged; each entry then
    /// takes its body's start. Returns whether every body is still (`None` where the bodies
    /// differ from the ledger's, having restarted some entries: the full start pass rebuilds
    /// them). Where the query visits the bodies in that order, table by table, each table is
    /// zipped with the ledger's next entries and split over the compute pool's threads as
    /// [`Parallelism`] allows (each entry is restarted by the same code on any thread).
    fn restart_bodies(
        &mut self,
        bodies: &AuditedBodies,
        marks: &Marks,
        parallelism: &Parallelism,
    ) -> Option<bool> {
        let passes = self.end_passes;
        let mut order = std::mem::take(&mut self.body_order);
        order.refresh_entities(bodies.iter().map(|(e, ..)| e));
        let in_order = order.is_query_order();
        self.body_order = order;
        let mut n = 0;
        let mut all_still = true;
        if in_order {
            let moved = AtomicBool::new(false);
            for (entities, poses, velocities, masses) in dense(bodies.contiguous_iter()) {
                let (pose_ticks, velocity_ticks, mass_ticks) = (
                    poses.changed_ticks_slice(),
                    velocities.changed_ticks_slice(),
                    masses.changed_ticks_slice(),
                );
                let same = zip_table(&mut self.bodies, n, entities, parallelism, |body, j| {
                    let ticks = [pose_ticks[j], velocity_ticks[j], mass_ticks[j]];
                    let item = (entities[j], &poses[j], &velocities[j], &masses[j], ticks);
                    let still = restart_entry(body, passes, item, marks);
                    if still == Some(false) {
                        moved.store(true, Ordering::Relaxed);
                    }
                    still.is_some()
                });
                if !same {
                    return None;
                }
                n += entities.len();
            }
            all_still = !moved.into_inner();
        } else {
            let mut same = true;
            let mut order = std::mem::take(&mut self.body_order);
            for_each_audited(&mut order, bodies, |item| {
                let Some(body) = self.bodies.get_mut(n).filter(|_| same) else {
                    same = false;
                    return;
                };
                match restart_entry(body, passes, item, marks) {
                    None => same = false,
                    Some(still) => all_still &= still,
                }
                n += 1;
            });
            self.body_order = order;
            if !same {
                return None;
            }
        }
        (n == self.bodies.len()).then_some(all_still)
    }
}

/// Restarts the ledger's entry `body` with the audited body `item` read at its index: `None`
/// (the entry untouched) where it is another entity or its mass changed (a new mass changes its
/// springs' reduced masses, so their stiffness bound: the groups must be formed again); else
/// the entry takes the body's start, its kinetic energy reused from the memo where the body is
/// still as end pass `passes` measured it (nothing written since, `marks`), and says whether
/// it is. A mass written since the last start pass (by game code between steps, or a force
/// system during the last one) is compared with the entry's.
#[inline]
fn restart_entry(body: &mut Audited, passes: u64, item: BodyItem, marks: &Marks) -> Option<bool> {
    let (entity, t, v, m, [_, _, mass_changed]) = item;
    if body.entity != entity {
        return None;
    }
    let (energy, still) = start_kinetic_of(body, passes, item, &marks.end);
    let mass_written = marks.start.written(mass_changed);
    if (mass_written || !still) && m.mass().widen().to_bits() != body.mass.to_bits() {
        return None;
    }
    // The end pose and the memo stay the last end pass's: this step's end pass writes both,
    // and a body it does not measure (one that left the step) is told apart by the memo's
    // pass number, as are the springs it holds.
    body.start = (*t, *v);
    body.load = (Vec3::ZERO, Vec3::ZERO);
    (body.start_energy, body.still) = (energy, still);
    Some(still)
}
