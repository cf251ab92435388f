use bevy_ecs::prelude::*;
use bevy_ecs::world::WorldId;

use crate::components::{
    ConstantForce, ConstantLocalForce, ConstantTorque, ForceAccumulator, Generator, GeneratorError,
    GeneratorErrorKind, RemovedBodies, Spring, check_inserted, reject_generator,
};

/// A query of the generators of type `G` changed since the world's last change-tracker clear,
/// with the world it was built for.
type ChangedQuery<G> = (WorldId, QueryState<(Entity, &'static G), Changed<G>>);

/// The runner's checks of the generators before each step (see the module docs). Keeps its
/// queries between steps, so checking allocates nothing in a world whose generators are valid.
#[derive(Default)]
pub(crate) struct GeneratorWatch {
    forces: Option<ChangedQuery<ConstantForce>>,
    local_forces: Option<ChangedQuery<ConstantLocalForce>>,
    torques: Option<ChangedQuery<ConstantTorque>>,
    springs: Option<ChangedQuery<Spring>>,
}

impl GeneratorWatch {
    /// Leaves out every generator whose values turned bad since the last check, or whose body
    /// went away.
    pub(crate) fn check(&mut self, world: &mut World) {
        let removed = world
            .get_resource_mut::<RemovedBodies>()
            .map(|mut r| std::mem::take(&mut r.0))
            .unwrap_or_default();
        let orphans = if removed.is_empty() {
            None
        } else {
            let removed: bevy_ecs::entity::EntityHashSet = removed
                .into_iter()
                .filter(|&e| {
                    !world
                        .get_entity(e)
                        .is_ok_and(|e| e.contains::<crate::components::RigidBody>())
                })
                .collect();
            Some(removed)
        };
        let mut errors = Vec::new();
        let mut lacking = Vec::new();
        let found = &mut (&mut errors, &mut lacking);
        check_changed(&mut self.forces, world, orphans.as_ref(), found);
        check_changed(&mut self.local_forces, world, orphans.as_ref(), found);
        check_changed(&mut self.torques, world, orphans.as_ref(), found);
        check_changed(&mut self.springs, world, orphans.as_ref(), found);
        for (reject, error) in errors {
            reject(world, error);
        }
        // A generator changed in place (a spring's end moved to another body) gives its new
        // bodies accumulators, as its insertion would have: without one a body is no target,
        // and the force on it was dropped while its partner took the other half.
        for body in lacking {
            if let Ok(mut e) = world.get_entity_mut(body) {
                e.insert_if_new(ForceAccumulator::default());
            }
        }
    }
}

/// A generator to leave out, with the function that does it for its type.
type Rejection = (fn(&mut World, GeneratorError), GeneratorError);

/// Checks the generators of type `G`: the changed ones' values and bodies (as their insertion
/// would: the bodies exist; those without an accumulator are listed in `found.1`), and, when
/// bodies went away (`orphans`), every one's bodies. Rejections go to `found.0`.
fn check_changed<G: Generator>(
    query: &mut Option<ChangedQuery<G>>,
    world: &World,
    orphans: Option<&bevy_ecs::entity::EntityHashSet>,
    found: &mut (&mut Vec<Rejection>, &mut Vec<Entity>),
) {
    let (errors, lacking) = found;
    if query.as_ref().is_none_or(|(id, _)| *id != world.id()) {
        *query = world
            .try_query_filtered::<(Entity, &G), Changed<G>>()
            .map(|q| (world.id(), q));
    }
    let Some((_, query)) = query.as_mut() else {
        return;
    };
    let mut push = |entity, kind| {
        let error = GeneratorError {
            entity,
            generator: G::NAME,
            kind,
        };
        errors.push((
            reject_generator::<G> as fn(&mut World, GeneratorError),
            error,
        ));
    };
    for (entity, g) in query.iter(world) {
        match check_inserted(g, |body| world.get_entity(body).is_ok()) {
            Err(kind) => push(entity, kind),
            Ok(()) => lacking.extend(g.bodies().map(|(_, body)| body).filter(|&body| {
                world
                    .get_entity(body)
                    .is_ok_and(|e| !e.contains::<ForceAccumulator>())
            })),
        }
    }
    let Some(orphans) = orphans else {
        return;
    };
    let mut all = world.try_query::<(Entity, &G)>().expect("registered above");
    for (entity, g) in all.iter(world) {
        if let Some((field, body)) = g.bodies().find(|(_, b)| orphans.contains(b)) {
            push(entity, GeneratorErrorKind::MissingBody { field, body });
        }
    }
}
