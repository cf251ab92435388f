//! Generators in entity order.
//!
//! A sweep or a sum over generators that share bodies (springs, constant forces, torques)
//! depends on the order it visits them in, so that order must be a fact of the world, not of
//! its storage: a system's query visits the tables that existed when it was created in the
//! order of a hash of their archetype ids, which anything that made an archetype earlier (a
//! resource, another kind of entity) changes. Entity order, by entity index — unique among a
//! world's live entities: the order the generators were spawned in, unless an index was freed
//! and reused — is the same however the world's tables came about. (Not `Entity`'s own `Ord`,
//! which does not follow the index.) One table of generators spawned in order (the common case)
//! is visited as the query visits it, with no sort and no lookups.

use bevy_ecs::prelude::*;
use bevy_ecs::query::ArchetypeFilter;

use super::dense;

/// The components `T` a system visits, with their entities.
pub(crate) type IndexedQuery<'w, 's, T, F> = Query<'w, 's, (Entity, &'static T), F>;

/// The entities of a query in entity index order when the query does not visit them in that
/// order, else empty; the buffer is kept between steps (no allocation once warm).
#[derive(Debug, Default)]
pub struct IndexOrder(Vec<Entity>);

impl IndexOrder {
    /// Takes the order of `query` as it stands now.
    pub(crate) fn refresh<T: Component, F: ArchetypeFilter>(
        &mut self,
        query: &IndexedQuery<'_, '_, T, F>,
    ) {
        self.refresh_entities(query.iter().map(|(e, _)| e));
    }

    /// Takes the order of `entities`, a query's entities in the order it visits them (for a
    /// query of more than one component; see [`entities`](Self::entities)).
    pub(crate) fn refresh_entities(&mut self, entities: impl Iterator<Item = Entity> + Clone) {
        self.0.clear();
        if !entities.clone().map(|e| e.index_u32()).is_sorted() {
            self.0.extend(entities);
            self.0.sort_unstable_by_key(|e| e.index_u32());
        }
    }

    /// The entities in index order, as of the last refresh; empty when the query visits them
    /// in that order itself ([`is_query_order`](Self::is_query_order)).
    pub(crate) fn entities(&self) -> &[Entity] {
        &self.0
    }

    /// True when the query visits its entities in index order itself (as of the last
    /// [`refresh`](Self::refresh)).
    pub(crate) fn is_query_order(&self) -> bool {
        self.0.is_empty()
    }

    /// Calls `f` on every item of `query` in entity index order (the order of the last
    /// [`refresh`](Self::refresh) on the same query).
    pub(crate) fn for_each<T: Component, F: ArchetypeFilter>(
        &self,
        query: &IndexedQuery<'_, '_, T, F>,
        mut f: impl FnMut(&T),
    ) {
        if self.0.is_empty() {
            for (_, item) in query {
                f(item);
            }
        } else {
            for &entity in &self.0 {
                if let Ok((_, item)) = query.get(entity) {
                    f(item);
                }
            }
        }
    }

    /// Calls `f` on every item of `query` in reverse entity index order.
    pub(crate) fn for_each_rev<T: Component, F: ArchetypeFilter>(
        &self,
        query: &IndexedQuery<'_, '_, T, F>,
        mut f: impl FnMut(&T),
    ) {
        if self.0.is_empty() {
            // In order already: the query's tables from the last, each from its last row. They
            // are few; finding each from the front keeps this free of allocations.
            let tables = dense(query.contiguous_iter()).count();
            for t in (0..tables).rev() {
                let Some((_, table)) = dense(query.contiguous_iter()).nth(t) else {
                    continue;
                };
                for item in table.iter().rev() {
                    f(item);
                }
            }
        } else {
            for &entity in self.0.iter().rev() {
                if let Ok((_, item)) = query.get(entity) {
                    f(item);
                }
            }
        }
    }
}
