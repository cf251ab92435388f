//! A scene's world is spawned in place: every row in the table it stays in (a row that moves
//! leaves its old table at its size), each table reserved once for a run of one kind, and the
//! spring classification changes nothing the spawn decided.

use bevy_ecs::prelude::*;
use tumble_ecs::components::{ImplicitBody, ImplicitSpring, SpringTurn};
use tumble_ecs::prelude::*;
use tumble_ecs::springs::classify_springs;
use tumble_scene::{BuiltScene, Scene};

/// `n` bodies of every kind the spawn distinguishes, interleaved (free, damped, scaled, held at
/// the centre by a spring, turned by springs off-centre), chained by springs off-centre
/// between the bodies `i ≡ 0 mod 5`, a centred spring on `i ≡ 3`, a world spring on `i ≡ 4`,
/// stiff pairs `(i, i + 5)` for `i ≡ 2 mod 10` (implicit groups), a force on `i ≡ 1` and a
/// torque. `grouped`: the bodies in the file sorted by `i mod 5` (each
/// kind one run), else in order (kinds interleaved).
fn mixed_scene(n: usize, grouped: bool) -> String {
    let mut text = String::from(
        "name = \"mixed\"\n[world]\ndt = 0.01\nsteps = 3\ngravity = [0.0, -9.81, 0.0]\n",
    );
    let mut order: Vec<usize> = (0..n).collect();
    if grouped {
        order.sort_by_key(|i| i % 5);
    }
    for i in order {
        text.push_str(&format!(
            "[[bodies]]\nname = \"b{i}\"\nmass = {}\ninertia = [0.3, 0.5, 0.7]\n\
             position = [{}, 0.0, 0.0]\nangular_velocity = [0.1, 0.2, 0.3]\n",
            1.0 + 0.01 * i as f64,
            0.5 * i as f64
        ));
        match i % 5 {
            1 => text.push_str("linear_damping = 0.1\n"),
            2 => text.push_str("gravity_scale = 0.5\n"),
            _ => {}
        }
    }
    for i in (5..n).step_by(5) {
        text.push_str(&format!(
            "[[forces]]\ntype = \"spring\"\na = \"b{}\"\nb = \"b{i}\"\nanchor_a = [0.1, 0.2, 0.0]\n\
             anchor_b = [-0.1, 0.0, 0.3]\nstiffness = {}\nrest_length = 2.0\n",
            i - 5,
            10.0 + i as f64
        ));
    }
    for i in (3..n).step_by(5) {
        text.push_str(&format!(
            "[[forces]]\ntype = \"spring\"\na = \"b{i}\"\nb = \"b{}\"\nstiffness = 3.0\n\
             rest_length = 0.5\n",
            i + 1
        ));
    }
    for i in (4..n).step_by(5) {
        text.push_str(&format!(
            "[[forces]]\ntype = \"spring\"\na = \"b{i}\"\nanchor_a = [0.0, 0.1, 0.0]\n\
             anchor_b = [0.0, 1.0, 0.0]\nstiffness = 7.0\ndamping = 0.2\n"
        ));
    }
    // Stiff pairs (ωΔt ≈ 10: implicit groups) of the gravity-scaled bodies.
    for i in (2..n.saturating_sub(5)).step_by(10) {
        text.push_str(&format!(
            "[[forces]]\ntype = \"spring\"\na = \"b{i}\"\nb = \"b{}\"\nanchor_a = [0.1, 0.0, 0.0]\n\
             anchor_b = [0.0, 0.1, 0.0]\nstiffness = 1.0e6\nrest_length = 2.4\n",
            i + 5
        ));
    }
    for i in (1..n).step_by(5) {
        text.push_str(&format!(
            "[[forces]]\ntype = \"constant\"\nbody = \"b{i}\"\nforce = [0.0, 1.0, 0.0]\n"
        ));
    }
    text.push_str("[[forces]]\ntype = \"torque\"\nbody = \"b0\"\ntorque = [0.0, 0.0, 0.1]\n");
    text
}

/// No table of components holds memory without rows: nothing moved out of a table after the
/// spawn; and (`exact`) each table of bodies holds memory for exactly its rows (at least the
/// 4 of a vector's smallest allocation): it was reserved once at its final size. (bevy's own
/// table of entities without components is left out.)
fn assert_no_row_moved(world: &World, exact: bool, what: &str) {
    let body = world.component_id::<RigidBody>().unwrap();
    for archetype in world.archetypes().iter() {
        if archetype.components().is_empty() {
            continue;
        }
        let table = &world.storages().tables[archetype.table_id()];
        let (capacity, count) = (table.capacity(), table.entity_count() as usize);
        if exact && archetype.contains(body) {
            assert_eq!(
                capacity,
                count.max(4),
                "{what}: capacity of a table of bodies"
            );
        } else {
            assert!(
                count > 0 || capacity == 0,
                "{what}: a table of capacity {capacity} was left empty"
            );
        }
    }
}

fn built_both_ways(text: &str) -> [BuiltScene; 2] {
    let scene = Scene::parse("mixed.toml", text).unwrap();
    [scene.build(), scene.into_built()]
}

#[test]
fn a_scene_is_spawned_where_its_rows_stay() {
    for grouped in [true, false] {
        let text = mixed_scene(60, grouped);
        for (way, mut built) in built_both_ways(&text).into_iter().enumerate() {
            let what = format!("grouped {grouped}, way {way}");
            assert_no_row_moved(&built.world, grouped, &format!("built, {what}"));
            // The classification gave the bodies the components they were spawned with.
            let turned = built
                .world
                .query::<&SpringTurn>()
                .iter(&built.world)
                .count();
            assert!(turned > 10, "{what}: {turned} bodies with a SpringTurn");
            for _ in 0..3 {
                built.step();
            }
            assert_no_row_moved(&built.world, grouped, &format!("stepped, {what}"));
            assert!(built.world.resource::<PhysicsErrors>().is_empty());
        }
    }
}

/// The entities of `world` with `T`, sorted.
fn with<T: Component>(world: &mut World) -> Vec<Entity> {
    let mut entities: Vec<Entity> = world
        .query_filtered::<Entity, With<T>>()
        .iter(world)
        .collect();
    entities.sort_unstable();
    entities
}

#[test]
fn the_spawned_markers_are_the_classifications() {
    let [mut built, _] = built_both_ways(&mixed_scene(40, false));
    let world = &mut built.world;
    let mut spawned: Vec<(Entity, SpringTurn)> = world
        .query::<(Entity, &SpringTurn)>()
        .iter(world)
        .map(|(e, t)| (e, *t))
        .collect();
    let (implicit_bodies, implicit_springs) =
        (with::<ImplicitBody>(world), with::<ImplicitSpring>(world));
    assert!(implicit_bodies.len() >= 6, "{implicit_bodies:?}");
    assert_eq!(implicit_springs.len(), implicit_bodies.len() / 2);
    for e in with::<RigidBody>(world) {
        world.entity_mut(e).remove::<(SpringTurn, ImplicitBody)>();
    }
    for e in with::<Spring>(world) {
        world.entity_mut(e).remove::<ImplicitSpring>();
    }
    world.remove_resource::<tumble_ecs::springs::SpringClassification>();
    classify_springs(world);
    let mut classified: Vec<(Entity, SpringTurn)> = world
        .query::<(Entity, &SpringTurn)>()
        .iter(world)
        .map(|(e, t)| (e, *t))
        .collect();
    spawned.sort_unstable_by_key(|(e, _)| *e);
    classified.sort_unstable_by_key(|(e, _)| *e);
    assert_eq!(spawned, classified);
    assert_eq!(implicit_bodies, with::<ImplicitBody>(world));
    assert_eq!(implicit_springs, with::<ImplicitSpring>(world));
}

#[test]
fn a_run_of_one_kind_reserves_its_table_once() {
    // A chain of identical bodies: one table, reserved at its final size.
    let mut text = String::from("name = \"chain\"\n[world]\ndt = 0.01\nsteps = 1\n");
    let n = 1000;
    for i in 0..n {
        text.push_str(&format!(
            "[[bodies]]\nname = \"b{i}\"\nmass = 1.0\ninertia = [0.3, 0.5, 0.7]\n\
             position = [{i}.0, 0.0, 0.0]\n"
        ));
    }
    for i in 1..n {
        text.push_str(&format!(
            "[[forces]]\ntype = \"spring\"\na = \"b{}\"\nb = \"b{i}\"\nanchor_a = [0.3, 0.0, 0.0]\n\
             anchor_b = [-0.3, 0.0, 0.0]\nstiffness = 5.0\nrest_length = 0.4\n",
            i - 1
        ));
    }
    for (way, built) in built_both_ways(&text).into_iter().enumerate() {
        let tables: Vec<(usize, u32)> = built
            .world
            .storages()
            .tables
            .iter()
            .filter(|t| t.entity_count() >= n as u32 - 1)
            .map(|t| (t.capacity(), t.entity_count()))
            .collect();
        assert_eq!(
            tables.len(),
            2,
            "({way}) the bodies' and the springs' tables"
        );
        for (capacity, count) in tables {
            assert_eq!(capacity, count as usize, "({way}) reserved exactly");
        }
    }
}
