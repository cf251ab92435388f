//! `WorldChecksum`: the same for the same world on every run, thread count and kernel path,
//! different for any change of a step-affecting bit, blind to storage order; and pinned for a
//! reference scene under every integrator, so that a change of tumble's bits cannot go unnoticed.

use tumble::bevy_ecs::prelude::*;
use tumble::math::{DOUBLE_PRECISION, Quat, Real, Vec3};
use tumble::prelude::*;

use super::util::{mass_props, run, world_with};

/// The reference scene: a chain of ten asymmetric bodies (a thin plate and a body with a locked
/// axis among them) joined by springs at off-centre anchors, forces at body points, a torque,
/// gravity with one body scaled, damping on one, at 60 Hz. The plate's small moment makes the
/// chain stiff for the planner's `auto` spring classification under most integrators, so their
/// checksums cover the implicit spring solve too (`yoshida4` and `exact4` step it explicitly).
/// The first-order methods cannot run inside an implicit group (the planner refuses them), so
/// their chain is explicit: their checksums cover their own step.
pub(crate) fn reference_world(integrator: Integrator) -> World {
    let mut world = world_with(1.0 / 60.0, integrator);
    if !integrator.turns_at_constant_momentum() {
        let settings = *world.resource::<PhysicsSettings>();
        world.insert_resource(settings.with_springs(SpringSolver::Explicit));
    }
    world.insert_resource(Gravity(Vec3::new(0.0, -9.81, 0.0)));
    let mut bodies = Vec::new();
    for i in 0..10u32 {
        let f = i as Real;
        let inertia = match i % 4 {
            0 => [0.01, 1.0, 1.01],
            1 => [0.3, 0.5, 0.7],
            2 => [0.0, 0.4, 0.45],
            _ => [0.2, 0.2, 0.35],
        };
        let body = world
            .spawn((
                RigidBody,
                mass_props(1.0 + 0.1 * f, inertia),
                Pose {
                    translation: Vec3::new(f, 0.2 * f, 0.0),
                    rotation: Quat::from_rotation_y(0.3 * f),
                },
                Velocity {
                    linear: Vec3::new(0.0, 0.5, 0.1 * f),
                    angular: Vec3::new(1.0, 2.0 - 0.2 * f, 0.5),
                },
            ))
            .id();
        bodies.push(body);
    }
    world.entity_mut(bodies[3]).insert(GravityScale(0.5));
    world.entity_mut(bodies[5]).insert(Damping {
        linear: 0.3,
        angular: 0.2,
    });
    for pair in bodies.windows(2) {
        world.spawn(Spring {
            a: pair[0],
            anchor_a: Vec3::new(0.2, 0.1, 0.0),
            b: SpringEnd::Body {
                body: pair[1],
                anchor: Vec3::new(-0.2, 0.0, 0.1),
            },
            stiffness: 40.0,
            damping: 0.1,
            rest_length: 0.9,
        });
    }
    world.spawn(ConstantForce {
        body: bodies[7],
        force: Vec3::new(0.0, 0.0, 2.0),
        local_point: Some(Vec3::new(0.3, 0.0, 0.0)),
    });
    world.spawn(ConstantTorque {
        body: bodies[2],
        torque: Vec3::new(0.1, 0.0, -0.2),
    });
    world
}

fn checksum_after(integrator: Integrator, steps: usize) -> WorldChecksum {
    let mut world = reference_world(integrator);
    run(&mut world, steps);
    if let Some(errors) = world.get_resource::<PhysicsErrors>() {
        assert!(errors.is_empty(), "{integrator}: {errors:?}");
    }
    world_checksum(&world)
}

#[test]
fn equal_worlds_have_equal_checksums_and_any_changed_bit_shows() {
    let mut a = reference_world(Integrator::Splitting);
    let mut b = reference_world(Integrator::Splitting);
    assert_eq!(world_checksum(&a), world_checksum(&b));
    assert_eq!(
        checksum_after(Integrator::Splitting, 30),
        checksum_after(Integrator::Splitting, 30)
    );
    assert_ne!(
        checksum_after(Integrator::Splitting, 30),
        checksum_after(Integrator::Splitting, 31)
    );
    let before = world_checksum(&a);
    // One ulp of one body's angular velocity.
    let body = a
        .query_filtered::<Entity, With<RigidBody>>()
        .iter(&a)
        .nth(4)
        .unwrap();
    let mut velocity = a.get_mut::<Velocity>(body).unwrap();
    velocity.angular.x = Real::from_bits(velocity.angular.x.to_bits() + 1);
    assert_ne!(world_checksum(&a), before);
    // A resource: the integrator; gravity.
    let c = reference_world(Integrator::Yoshida4);
    assert_ne!(world_checksum(&c), before);
    b.insert_resource(Gravity(Vec3::new(0.0, -9.8, 0.0)));
    assert_ne!(world_checksum(&b), before);
}

#[test]
fn storage_order_does_not_enter_the_checksum() {
    let plain = reference_world(Integrator::Splitting);
    let mut moved = reference_world(Integrator::Splitting);
    // A marker added and removed moves the body to another table and back, to another row.
    let body = moved
        .query_filtered::<Entity, With<RigidBody>>()
        .iter(&moved)
        .next()
        .unwrap();
    #[derive(Component)]
    struct Marker;
    moved.entity_mut(body).insert(Marker);
    moved.entity_mut(body).remove::<Marker>();
    assert_eq!(world_checksum(&plain), world_checksum(&moved));
}

#[test]
fn the_thread_count_does_not_change_the_checksum() {
    for integrator in [Integrator::Splitting, Integrator::Exact] {
        let checksums: Vec<WorldChecksum> = [Parallelism::SINGLE_THREAD, Parallelism::default()]
            .into_iter()
            .map(|parallelism| {
                let mut world = reference_world(integrator);
                world.insert_resource(parallelism);
                run(&mut world, 60);
                world_checksum(&world)
            })
            .collect();
        assert_eq!(checksums[0], checksums[1], "{integrator}");
    }
}

/// The reference scene after 120 steps (2 s) under every integrator, on every kernel path (CI
/// runs this suite on the widest path and again with `TUMBLE_KERNEL=portable`).
///
/// **A failure here means tumble's results changed bits.** Users' recorded replays and lockstep
/// peers on the old version no longer agree with the new one, so a change must be deliberate:
/// say so in the change log, then re-pin by running
/// `cargo test --test core_layer pinned -- --nocapture` (and with `--features f64`, and with
/// `--features enhanced-determinism`) and copying the printed tables.
#[test]
fn pinned_checksums_of_the_reference_scene() {
    // The same table with and without `enhanced-determinism` (glam's scalar math): tumble's
    // step uses no glam `f32` quaternion arithmetic, whose SIMD and scalar code round differently.
    let pinned: &[(&str, &str)] = if DOUBLE_PRECISION {
        PINNED_F64
    } else {
        PINNED_F32
    };
    let measured: Vec<(String, String)> = Integrator::ALL
        .iter()
        .map(|&i| (i.name().to_owned(), checksum_after(i, 120).to_string()))
        .collect();
    for (name, checksum) in &measured {
        println!("        (\"{name}\", \"{checksum}\"),");
    }
    // A pin of a scene that never moved would pin nothing (a refused or quarantined step).
    for (&integrator, (name, checksum)) in Integrator::ALL.iter().zip(&measured) {
        assert_ne!(
            checksum_after(integrator, 0).to_string(),
            *checksum,
            "`{name}` did not step the reference scene"
        );
    }
    for ((name, checksum), (pinned_name, pinned_checksum)) in measured.iter().zip(pinned) {
        assert_eq!(name, pinned_name);
        assert_eq!(
            checksum, pinned_checksum,
            "`{name}` changed its bits (see this test's docs before re-pinning)"
        );
    }
    assert_eq!(
        measured.len(),
        pinned.len(),
        "an integrator was added: pin it"
    );
}

/// `f32` build (the default), with or without `enhanced-determinism`.
const PINNED_F32: &[(&str, &str)] = &[
    ("symplectic-euler", "1d4626a3e720415a22a2ed71be72ad38"),
    (
        "symplectic-euler-linear",
        "fb4da947675f1a45e77365536a7eaaa4",
    ),
    ("lclamp", "33a8d5341c85fc24c4bfaa47948d3a80"),
    ("implicit-gyroscopic", "42d27c6e4bdeebca8938e054393d0102"),
    ("splitting", "945ef82510b54687d754a6ad607558ed"),
    ("splitting-xyz", "d9642652e811e3f503321f6ca2c80f08"),
    ("yoshida4", "ea227359d32e9094363db7a11b72e5f9"),
    ("rk4", "4b30c702adfbfbac897c4ae59093f036"),
    ("exact", "ffdf17092dcdbb9d063e7a1eaa39d8e4"),
    ("exact4", "2bcecce17b7e2aeb0ea173aacb683fbd"),
];
/// `f64` build (with or without `enhanced-determinism`).
const PINNED_F64: &[(&str, &str)] = &[
    ("symplectic-euler", "84603769893a461ec0eb7c7f66b2d11a"),
    (
        "symplectic-euler-linear",
        "3513e31465daec60158029cb5941b250",
    ),
    ("lclamp", "04e38e84b4683986577a1e84a54b3336"),
    ("implicit-gyroscopic", "575d1d8020fdddeb7d1612b54e845d5d"),
    ("splitting", "9d18ead45780b1aa1ea7f587444160cb"),
    ("splitting-xyz", "794e98fb2e9211f389bed18d0ac1032c"),
    ("yoshida4", "7fe2f6c503ece11d652ab72ea66c6776"),
    ("rk4", "aa4ef81e95196064a80d138e6128fa27"),
    ("exact", "936d4c798af8826c4c03a181e6a6095f"),
    ("exact4", "1babf66e140375a74f7b561db2b2b869"),
];

/// The bits do not depend on what else the world held when the step was planned: a resource
/// and an entity of another kind made before planning give every archetype a different id,
/// which reorders the tables a system's query visits (bevy matches the tables that exist when
/// a query is created in the order of a hash of their archetype ids). The reference scene's
/// implicit group sums over bodies of several tables.
#[test]
fn what_else_the_world_holds_does_not_change_the_bits() {
    #[derive(Resource, Default)]
    struct GameClock;
    #[derive(Component)]
    struct Tree;
    for integrator in [Integrator::Splitting, Integrator::Exact, Integrator::Rk4] {
        let mut plain = reference_world(integrator);
        let mut busy = reference_world(integrator);
        busy.init_resource::<GameClock>();
        busy.spawn(Tree);
        run(&mut plain, 60);
        run(&mut busy, 60);
        assert_eq!(
            world_checksum(&plain),
            world_checksum(&busy),
            "{integrator}"
        );
    }
}

/// Forces from generators in several tables (game code adds its own components to some) are
/// summed into each body in entity order, not in the order the systems' queries visit the
/// tables: what else the world made before its bodies does not change the bits (the states
/// are compared body by body: the entity ids differ).
#[test]
fn forces_from_several_tables_sum_the_same_whatever_else_the_world_holds() {
    #[derive(Resource, Default)]
    struct GameClock;
    #[derive(Component)]
    struct Tree;
    #[derive(Component)]
    struct Tag<const N: usize>;
    fn tagged(world: &mut World, e: Entity, k: usize) {
        let mut e = world.entity_mut(e);
        match k % 4 {
            0 => {}
            1 => {
                e.insert(Tag::<1>);
            }
            2 => {
                e.insert(Tag::<2>);
            }
            _ => {
                e.insert(Tag::<3>);
            }
        }
    }
    fn world(busy: bool) -> (World, Vec<Entity>) {
        let mut world = world_with(1.0 / 60.0, Integrator::Splitting);
        if busy {
            // Made first: every archetype after these gets another id.
            world.init_resource::<GameClock>();
            world.spawn(Tree);
        }
        world.insert_resource(
            PhysicsSettings::new(1.0 / 60.0, Integrator::Splitting)
                .unwrap()
                .with_springs(SpringSolver::Explicit),
        );
        let bodies: Vec<Entity> = (0..6)
            .map(|i| {
                let f = i as Real;
                world
                    .spawn((
                        RigidBody,
                        mass_props(1.0 + 0.1 * f, [0.3, 0.5, 0.7]),
                        Pose {
                            translation: Vec3::new(f, 0.1 * f, 0.0),
                            rotation: Quat::from_rotation_y(0.4 * f),
                        },
                        Velocity {
                            linear: Vec3::new(0.1, 0.2, 0.3 * f),
                            angular: Vec3::new(0.5, 1.0 - 0.1 * f, 0.2),
                        },
                    ))
                    .id()
            })
            .collect();
        let mut k = 0;
        for (i, &a) in bodies.iter().enumerate() {
            for j in 1..=4 {
                let b = bodies[(i + j) % bodies.len()];
                let spring = world
                    .spawn(Spring {
                        a,
                        anchor_a: Vec3::new(0.1 * j as Real, 0.05, 0.0),
                        b: SpringEnd::Body {
                            body: b,
                            anchor: Vec3::new(0.0, -0.1, 0.02 * j as Real),
                        },
                        stiffness: 3.0 + j as Real,
                        damping: 0.0,
                        rest_length: 0.7,
                    })
                    .id();
                tagged(&mut world, spring, k);
                let force = world
                    .spawn(ConstantForce {
                        body: a,
                        force: Vec3::new(0.1 * j as Real, 0.3, -0.2),
                        local_point: Some(Vec3::new(0.0, 0.1, 0.05 * j as Real)),
                    })
                    .id();
                tagged(&mut world, force, k + 1);
                let torque = world
                    .spawn(ConstantTorque {
                        body: a,
                        torque: Vec3::new(0.01, 0.02 * j as Real, 0.03),
                    })
                    .id();
                tagged(&mut world, torque, k + 2);
                k += 1;
            }
        }
        (world, bodies)
    }
    let state = |world: &World, bodies: &[Entity]| -> Vec<String> {
        bodies
            .iter()
            .map(|&e| format!("{:?} {:?}", world.get::<Pose>(e), world.get::<Velocity>(e)))
            .collect()
    };
    let ((mut plain, a), (mut busy, b)) = (world(false), world(true));
    run(&mut plain, 60);
    run(&mut busy, 60);
    assert!(plain.resource::<PhysicsErrors>().is_empty());
    assert_eq!(state(&plain, &a), state(&busy, &b));
}
