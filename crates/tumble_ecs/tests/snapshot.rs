//! Save a world, load it elsewhere, resume: bit-identical to running straight through.

use bevy_ecs::prelude::*;
use tumble_core::math::{Quat, Real, Vec3, Widen};

use tumble_core::{Integrator, Mass, MassProperties};
use tumble_ecs::components::HeldLoad;
use tumble_ecs::prelude::*;
use tumble_ecs::state::{BodyRecord, RollbackSnapshot, Snapshot, SnapshotError};

/// A world with every kind of thing a snapshot must carry.
fn scene(integrator: Integrator) -> World {
    let mut world = World::new();
    world.insert_resource(PhysicsSettings::new(1.0 / 120.0, integrator).unwrap());
    world.insert_resource(Gravity(Vec3::new(0.0, -9.81, 0.0)));
    let anchor = world.spawn((RigidBody, Static)).id();
    let mut bodies = Vec::new();
    for i in 0..12 {
        let f = i as Real;
        let mass = MassProperties::new(
            Mass::new(1.0 + 0.3 * f).unwrap(),
            Vec3::new(0.5, 1.0 + 0.05 * f, 1.4),
        )
        .unwrap()
        .with_center_of_mass(Vec3::new(0.05, 0.0, -0.02))
        .unwrap();
        let pose = Pose::new(Vec3::new(f, 1.0, 0.0), Quat::from_rotation_z(0.2 * f));
        let velocity = Velocity::new(
            Vec3::new(0.0, 0.5, 0.1 * f),
            Vec3::new(1.0, 3.0 - 0.2 * f, 0.3),
        );
        let mut e = world.spawn((RigidBody, MassProps(mass), pose, velocity));
        if i % 3 == 0 {
            e.insert(GravityScale(0.5));
        }
        if i % 4 == 0 {
            e.insert(Damping {
                linear: 0.1,
                angular: 0.05,
            });
        }
        bodies.push(e.id());
    }
    world.spawn((RigidBody, Kinematic, Velocity::linear(Vec3::X)));
    for pair in bodies.windows(2) {
        let next = SpringEnd::on_body(pair[1], Vec3::ZERO);
        let spring = Spring::new(pair[0], Vec3::new(0.1, 0.0, 0.0), next, 40.0, 1.0);
        world.spawn(spring.with_damping(0.3));
    }
    let held = SpringEnd::on_body(anchor, Vec3::ZERO);
    world.spawn(Spring::new(bodies[0], Vec3::ZERO, held, 80.0, 0.5));
    world.spawn(ConstantForce {
        body: bodies[5],
        force: Vec3::new(0.0, 0.0, 2.0),
        local_point: Some(Vec3::Y),
    });
    world.spawn(ConstantTorque {
        body: bodies[7],
        torque: Vec3::new(0.1, 0.0, 0.0),
    });
    world
}

fn run(world: &mut World, physics: &mut PhysicsRunner, steps: usize) {
    for _ in 0..steps {
        physics.step(world);
        world.clear_trackers();
    }
}

/// Every body's state as bits, sorted (entity ids and archetype order differ between a world
/// and its restored copy; the set of body states must not).
fn bits(world: &mut World) -> Vec<Vec<u64>> {
    let mut q = world.query_filtered::<(&Pose, &Velocity), With<RigidBody>>();
    let mut bodies: Vec<Vec<u64>> = q
        .iter(world)
        .map(|(t, v)| {
            t.translation
                .to_array()
                .into_iter()
                .chain(t.rotation.to_array())
                .chain(v.linear.to_array())
                .chain(v.angular.to_array())
                .map(|x| x.widen().to_bits())
                .collect()
        })
        .collect();
    bodies.sort();
    bodies
}

#[test]
fn resuming_a_saved_world_is_bit_identical_over_ten_thousand_steps() {
    for integrator in [Integrator::Splitting, Integrator::SymplecticEuler] {
        let mut straight = scene(integrator);
        let mut physics = PhysicsRunner::new(&mut straight);
        run(&mut straight, &mut physics, 10_000);

        let mut first = scene(integrator);
        let mut physics = PhysicsRunner::new(&mut first);
        run(&mut first, &mut physics, 5_000);
        let text = serde_json::to_string(&Snapshot::capture(&mut first)).unwrap();
        drop(first);

        let snapshot: Snapshot = serde_json::from_str(&text).unwrap();
        let mut resumed = World::new();
        snapshot.restore(&mut resumed).unwrap();
        let mut physics = PhysicsRunner::new(&mut resumed);
        run(&mut resumed, &mut physics, 5_000);

        let (a, b) = (bits(&mut straight), bits(&mut resumed));
        assert_eq!(a.len(), b.len());
        assert!(a == b, "{integrator}: resumed run differs");
        assert!(a.iter().flatten().all(|x| f64::from_bits(*x).is_finite()));
        // And the saved world was really in motion.
        assert_ne!(a, bits(&mut scene(integrator)));
    }
}

#[test]
fn snapshots_round_trip_and_bad_ones_are_refused() {
    let mut world = scene(Integrator::Splitting);
    let snapshot = Snapshot::capture(&mut world);
    let text = serde_json::to_string(&snapshot).unwrap();
    assert_eq!(serde_json::from_str::<Snapshot>(&text).unwrap(), snapshot);
    assert_eq!(snapshot.bodies.len(), 14);
    assert_eq!(snapshot.springs.len(), 12);

    // A non-positive time step or a tampered mass is refused by the checked types.
    let dt_at = text.find("\"dt\":").unwrap();
    let dt_end = dt_at + text[dt_at..].find(',').unwrap();
    let bad_dt = format!("{}\"dt\":-1.0{}", &text[..dt_at], &text[dt_end..]);
    assert_ne!(bad_dt, text);
    let err = serde_json::from_str::<Snapshot>(&bad_dt).unwrap_err();
    assert!(err.to_string().contains("time step"), "{err}");
    // Substeps too short for the precision are refused like the step itself.
    let shortest = 8.0 * tumble_core::error::TIME_STEP_RANGE.0;
    let eight = PhysicsSettings::new(shortest, Integrator::Splitting)
        .unwrap()
        .with_substeps(std::num::NonZeroU32::new(8).unwrap())
        .unwrap();
    let text_eight = serde_json::to_string(&eight).unwrap();
    assert_eq!(
        serde_json::from_str::<PhysicsSettings>(&text_eight).unwrap(),
        eight
    );
    let nine = text_eight.replacen("\"substeps\":8", "\"substeps\":9", 1);
    assert_ne!(nine, text_eight);
    let err = serde_json::from_str::<PhysicsSettings>(&nine).unwrap_err();
    assert!(err.to_string().contains("9 substeps"), "{err}");
    let bad_mass = text.replacen("\"inv_mass\":1.0", "\"inv_mass\":-1.0", 1);
    assert_ne!(bad_mass, text);
    assert!(serde_json::from_str::<Snapshot>(&bad_mass).is_err());

    // A generator naming a body that is not in the snapshot.
    let mut orphan = snapshot.clone();
    orphan.bodies.remove(1);
    let err = orphan.restore(&mut World::new()).unwrap_err();
    assert!(matches!(err, SnapshotError::UnknownBody(_)), "{err}");
}

/// A world of one body with every part a body record holds, none at its default.
fn full_body() -> (World, Entity) {
    let mut world = World::new();
    world.insert_resource(PhysicsSettings::new(1.0 / 60.0, Integrator::Splitting).unwrap());
    let mass = MassProperties::new(Mass::new(2.5).unwrap(), Vec3::new(0.2, 0.3, 0.4))
        .unwrap()
        .with_center_of_mass(Vec3::new(0.01, 0.0, -0.02))
        .unwrap()
        .with_principal_frame(Quat::from_rotation_x(0.3))
        .unwrap();
    let body = world
        .spawn((
            RigidBody,
            MassProps(mass),
            Pose::from_translation(Vec3::new(1.0, 2.0, 3.0)),
            Velocity::new(Vec3::new(0.1, 0.2, 0.3), Vec3::new(-1.0, 0.5, 0.25)),
            ForceAccumulator {
                force: Vec3::new(1.0, 0.0, -1.0),
                torque: Vec3::new(0.0, 0.5, 0.0),
            },
            GravityScale(0.5),
            Damping {
                linear: 0.1,
                angular: 0.2,
            },
        ))
        .id();
    *world.get_mut::<HeldLoad>(body).unwrap() = HeldLoad {
        force: Vec3::new(0.0, 3.0, 0.0),
        torque: Vec3::new(0.0, 0.0, 0.7),
    };
    (world, body)
}

/// Rollback, the checksum and serde snapshots share one body record: a change to any part of
/// a body changes the checksum, a rollback puts it back, and a snapshot carries it.
#[test]
fn every_part_of_a_body_is_checksummed_rolled_back_and_saved() {
    type Change = fn(&mut World, Entity);
    let changes: [(&str, Change); 16] = [
        ("position", |w, b| {
            w.get_mut::<Pose>(b).unwrap().translation.x += 1.0
        }),
        ("rotation", |w, b| {
            w.get_mut::<Pose>(b).unwrap().rotation = Quat::from_rotation_y(0.5)
        }),
        ("linear velocity", |w, b| {
            w.get_mut::<Velocity>(b).unwrap().linear.y += 1.0
        }),
        ("angular velocity", |w, b| {
            w.get_mut::<Velocity>(b).unwrap().angular.z += 1.0
        }),
        ("mass", |w, b| {
            let mass = MassProperties::new(Mass::new(3.0).unwrap(), Vec3::ONE).unwrap();
            w.entity_mut(b).insert(MassProps(mass));
        }),
        ("force", |w, b| {
            w.get_mut::<ForceAccumulator>(b).unwrap().force.x += 1.0
        }),
        ("torque", |w, b| {
            w.get_mut::<ForceAccumulator>(b).unwrap().torque.x += 1.0
        }),
        ("held force", |w, b| {
            w.get_mut::<HeldLoad>(b).unwrap().force.z += 1.0
        }),
        ("held torque", |w, b| {
            w.get_mut::<HeldLoad>(b).unwrap().torque.y += 1.0
        }),
        ("gravity scale", |w, b| {
            w.get_mut::<GravityScale>(b).unwrap().0 = 2.0
        }),
        ("no gravity scale", |w, b| {
            w.entity_mut(b).remove::<GravityScale>();
        }),
        ("linear damping", |w, b| {
            w.get_mut::<Damping>(b).unwrap().linear = 0.3
        }),
        ("angular damping", |w, b| {
            w.get_mut::<Damping>(b).unwrap().angular = 0.3
        }),
        ("static", |w, b| {
            w.entity_mut(b).insert(Static);
        }),
        ("kinematic", |w, b| {
            w.entity_mut(b).insert(Kinematic);
        }),
        ("quarantined", |w, b| {
            let error = BodyError {
                entity: b,
                kind: BodyErrorKind::Restored("test".to_owned()),
            };
            w.entity_mut(b).insert(Rejected(error));
        }),
    ];
    for (part, change) in changes {
        let (mut world, body) = full_body();
        let before = world_checksum(&world);
        let saved = RollbackSnapshot::capture(&mut world);
        change(&mut world, body);
        let changed = world_checksum(&world);
        assert_ne!(changed, before, "{part}: the checksum must see it");
        let record = RollbackSnapshot::capture(&mut world).bodies()[0];
        assert_ne!(record, saved.bodies()[0], "{part}: the record must hold it");

        // A serde snapshot carries the changed record whole (the entity is the new world's).
        let text = serde_json::to_string(&Snapshot::capture(&mut world)).unwrap();
        let mut elsewhere = World::new();
        let map = serde_json::from_str::<Snapshot>(&text)
            .unwrap()
            .restore(&mut elsewhere)
            .unwrap();
        let loaded = RollbackSnapshot::capture(&mut elsewhere).bodies()[0];
        assert_eq!(loaded.entity, map[&body]);
        assert_eq!(
            BodyRecord {
                entity: body,
                ..loaded
            },
            record,
            "{part}: the snapshot must carry it"
        );

        saved.restore(&mut world).unwrap();
        assert_eq!(
            world_checksum(&world),
            before,
            "{part}: the rollback must undo it"
        );
    }
}
