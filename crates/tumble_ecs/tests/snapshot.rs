//! Save a world, load it elsewhere, resume: bit-identical to running straight through.

use bevy_ecs::prelude::*;
use tumble_core::math::{Quat, Real, Vec3, Widen};

use tumble_core::{Integrator, Mass, MassProperties};
use tumble_ecs::prelude::*;
use tumble_ecs::state::{Snapshot, SnapshotError};

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
    let bad_mass = text.replacen("\"inv_mass\":1.0", "\"inv_mass\":-1.0", 1);
    assert_ne!(bad_mass, text);
    assert!(serde_json::from_str::<Snapshot>(&bad_mass).is_err());

    // A generator naming a body that is not in the snapshot.
    let mut orphan = snapshot.clone();
    orphan.bodies.remove(1);
    let err = orphan.restore(&mut World::new()).unwrap_err();
    assert!(matches!(err, SnapshotError::UnknownBody(_)), "{err}");
}
