//! Springs in entity order.
//!
//! A sweep or a sum over springs that share bodies depends on the order it visits them in, so
//! that order must be a fact of the world, not of its storage: a system's query visits the
//! tables that existed when it was created in the order of a hash of their archetype ids,
//! which anything that made an archetype earlier (a resource, another kind of entity) changes.
//! Entity order — by entity index, unique among the live entities of a world: the order the
//! springs were spawned in, unless an index was freed and reused — is the same however the
//! world's tables came about. (Not `Entity`'s own `Ord`, which does not follow the index.) One table of springs spawned in order (the common case) is visited as the query
//! visits it, with no sort and no lookups.

use bevy_ecs::prelude::*;
use bevy_ecs::query::ArchetypeFilter;

use crate::components::Spring;

/// The springs a system visits, with their entities.
pub(crate) type SpringQuery<'w, 's, F> = Query<'w, 's, (Entity, &'static Spring), F>;

/// The springs' entities in entity order when their query does not visit them in that order,
/// else empty; the buffer is kept between steps (no allocation once warm).
#[derive(Debug, Default)]
pub struct SpringOrder(Vec<Entity>);

impl SpringOrder {
    /// Takes the order of `springs` as they stand now.
    pub(crate) fn refresh<F: ArchetypeFilter>(&mut self, springs: &SpringQuery<'_, '_, F>) {
        self.0.clear();
        if !springs.iter().map(|(e, _)| e.index_u32()).is_sorted() {
            self.0.extend(springs.iter().map(|(e, _)| e));
            self.0.sort_unstable_by_key(|e| e.index_u32());
        }
    }

    /// Calls `f` on every spring of `springs` in entity order (the order of the last
    /// [`refresh`](Self::refresh) on the same query).
    pub(crate) fn for_each<F: ArchetypeFilter>(
        &self,
        springs: &SpringQuery<'_, '_, F>,
        mut f: impl FnMut(&Spring),
    ) {
        if self.0.is_empty() {
            for (_, spring) in springs {
                f(spring);
            }
        } else {
            for &entity in &self.0 {
                if let Ok((_, spring)) = springs.get(entity) {
                    f(spring);
                }
            }
        }
    }

    /// Calls `f` on every spring of `springs` in reverse entity order.
    pub(crate) fn for_each_rev<F: ArchetypeFilter>(
        &self,
        springs: &SpringQuery<'_, '_, F>,
        mut f: impl FnMut(&Spring),
    ) {
        if self.0.is_empty() {
            // In order already: the query's tables from the last, each from its last row. They
            // are few; finding each from the front keeps this free of allocations.
            let tables = crate::components::dense(springs.contiguous_iter()).count();
            for t in (0..tables).rev() {
                let Some((_, table)) = crate::components::dense(springs.contiguous_iter()).nth(t)
                else {
                    continue;
                };
                for spring in table.iter().rev() {
                    f(spring);
                }
            }
        } else {
            for &entity in self.0.iter().rev() {
                if let Ok((_, spring)) = springs.get(entity) {
                    f(spring);
                }
            }
        }
    }
}
