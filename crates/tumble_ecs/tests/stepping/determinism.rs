//! The same inputs give bit-identical results, run after run.

use tumble_core::integrate::{ExactSwitch, FreeFlow};
use tumble_core::math::{DOUBLE_PRECISION, Quat, Real, Vec3, Widen};
use tumble_ecs::prelude::*;

use super::util::{mass_props, run, world_with};

fn scene_bits() -> Vec<u64> {
    let mut world = world_with(1.0 / 90.0, Integrator::SymplecticEuler);
    world.insert_resource(Gravity(Vec3::new(0.0, -9.81, 0.0)));
    let mut bodies = Vec::new();
    for i in 0..64u32 {
        let f = i as Real;
        let e = world
            .spawn((
                RigidBody,
                mass_props(1.0 + f * 0.1, [1.0, 1.0 + f * 0.01, 1.9 + f * 0.01]),
                Pose {
                    translation: Vec3::new(f, (f * 0.7).sin(), 0.0),
                    rotation: Quat::from_rotation_y(f * 0.1),
                },
                Velocity {
                    linear: Vec3::new(0.0, 1.0, f * 0.01),
                    angular: Vec3::new(0.5, 2.0, f * 0.03),
                },
                ForceAccumulator::default(),
            ))
            .id();
        bodies.push(e);
    }
    for pair in bodies.windows(2) {
        let next = SpringEnd::on_body(pair[1], Vec3::new(-0.1, 0.0, 0.0));
        let spring = Spring::new(pair[0], Vec3::new(0.1, 0.0, 0.0), next, 30.0, 1.0);
        world.spawn(spring.with_damping(0.2));
        world.spawn(ConstantForce {
            body: pair[0],
            force: Vec3::Z,
            local_point: Some(Vec3::Y),
        });
    }
    run(&mut world, 500);
    let mut bits = Vec::new();
    for e in bodies {
        let t = world.get::<Pose>(e).unwrap();
        let v = world.get::<Velocity>(e).unwrap();
        for x in t
            .translation
            .to_array()
            .into_iter()
            .chain(t.rotation.to_array())
            .chain(v.linear.to_array())
            .chain(v.angular.to_array())
        {
            bits.push(x.widen().to_bits());
        }
    }
    bits
}

#[test]
fn two_runs_are_bit_identical() {
    let a = scene_bits();
    let b = scene_bits();
    assert_eq!(a, b);
    assert!(a.iter().all(|&x| f64::from_bits(x).is_finite()));
}

#[test]
fn ecs_matches_the_raw_loop_bit_for_bit() {
    use tumble_core::{BodyState, Wrench};
    // A torque driven tumbling body and a free one, through the ECS and through the core API.
    for integrator in Integrator::ALL.iter().copied() {
        let dt = 1.0 / 120.0;
        let mass = mass_props(1.3, [0.4, 1.0, 1.3]);
        let torque = Vec3::new(0.2, -0.1, 0.05);
        let start = BodyState {
            position: Vec3::new(1.0, 2.0, 3.0),
            rotation: Quat::from_rotation_z(0.4),
            linear_velocity: Vec3::new(0.1, 0.0, -0.2),
            angular_velocity: Vec3::new(0.7, 1.9, -0.4),
        };
        let mut world = world_with(dt, integrator);
        let body = world
            .spawn((
                RigidBody,
                mass,
                Pose {
                    translation: start.position,
                    rotation: start.rotation,
                },
                Velocity {
                    linear: start.linear_velocity,
                    angular: start.angular_velocity,
                },
            ))
            .id();
        world.spawn(ConstantTorque { body, torque });
        run(&mut world, 300);
        let mut raw = start;
        let wrench = Wrench {
            force: Vec3::ZERO,
            torque,
        };
        // The free-flow switch the world makes by default, made here by hand: each step the
        // exact counterpart where the split would cost more than the tolerance.
        let switch = ExactSwitch::new(integrator, FreeFlow::Auto, dt);
        let mut switched = 0;
        for _ in 0..300 {
            match switch {
                Some(switch) if switch.applies(&raw, &mass) => {
                    switched += 1;
                    switch.exact().step(&mut raw, &mass, &wrench, dt);
                }
                _ => integrator.step(&mut raw, &mass, &wrench, dt),
            }
        }
        // The body spins up under its torque: a split method of one stage switches in some
        // step in `f64`, whose tolerance is tight, and never in `f32`.
        if integrator.exact_counterpart().is_some() && integrator.composition().len() == 1 {
            assert_eq!(
                switched > 0,
                DOUBLE_PRECISION,
                "{integrator}: {switched} switched"
            );
        }
        let t = world.get::<Pose>(body).unwrap();
        let v = world.get::<Velocity>(body).unwrap();
        assert_eq!(t.translation, raw.position, "{integrator}");
        assert_eq!(t.rotation, raw.rotation, "{integrator}");
        assert_eq!(v.angular, raw.angular_velocity, "{integrator}");
    }
}

/// A large mixed world (free bodies under gravity, bodies with accumulators, constant forces,
/// springs, spheres, asymmetric and locked-axis bodies) stepped with the given threading policy.
fn big_world_bits(parallelism: Parallelism, integrator: Integrator) -> Vec<u64> {
    let mut world = world_with(1.0 / 60.0, integrator);
    world.insert_resource(Gravity(Vec3::new(0.0, -9.81, 0.0)));
    world.insert_resource(parallelism);
    let mut bodies = Vec::new();
    for i in 0..6000u32 {
        let f = i as Real / 6000.0;
        let inertia = match i % 4 {
            0 => [1.0, 2.0 + f, 3.0],
            1 => [0.5, 0.5, 0.5],
            2 => [0.0, 1.0, 1.2],
            _ => [2.0, 1.0, 2.1],
        };
        let mut e = world.spawn((
            RigidBody,
            mass_props(1.0 + f, inertia),
            Pose {
                translation: Vec3::new(f * 100.0, 0.0, (i % 7) as Real),
                rotation: Quat::from_rotation_y(f * 9.0),
            },
            Velocity {
                linear: Vec3::new(1.0, 2.0, f),
                angular: Vec3::new(0.3 + f, 1.0 - f, 0.2 + 3.0 * f),
            },
        ));
        if i % 3 == 0 {
            e.insert(ForceAccumulator::default());
        }
        bodies.push(e.id());
    }
    // Constant forces, world and body frame, at points and through the centre of mass, two on
    // some bodies: enough of them that the threaded policy computes them on the pool.
    for (i, &body) in bodies.iter().enumerate().filter(|(i, _)| i % 2 == 0) {
        let f = i as Real / 6000.0;
        world.spawn(ConstantForce {
            body,
            force: Vec3::new(0.5, -1.0 + f, 0.25),
            local_point: (i % 4 == 0).then(|| Vec3::new(0.1, 0.05 * f, -0.02)),
        });
        world.spawn(ConstantLocalForce {
            body,
            force: Vec3::new(-0.3, 0.2, 1.0 - f),
            local_point: (i % 6 != 0).then(|| Vec3::new(0.0, 0.1, 0.03)),
        });
        if i % 10 == 0 {
            world.spawn(ConstantForce {
                body,
                force: Vec3::new(0.0, 0.0, 2.0),
                local_point: Some(Vec3::new(-0.05, 0.0, 0.1)),
            });
        }
    }
    // Springs within each group of six (bodies 0, 3 and 5 each held by two), one to a body
    // half the world away (its ends in different threads' shares of the rows), one to a world
    // point: every body's spring forces are added in spring order on any thread count.
    let groups: Vec<&[bevy_ecs::entity::Entity]> = bodies.chunks(6).collect();
    for (g, pair) in groups.iter().enumerate() {
        let far = groups[(g + groups.len() / 2) % groups.len()][4];
        let springs = [
            (
                pair[0],
                Vec3::new(0.1, 0.0, 0.0),
                SpringEnd::on_body(pair[3], Vec3::ZERO),
            ),
            (
                pair[3],
                Vec3::new(0.0, 0.05, 0.0),
                SpringEnd::on_body(pair[5], Vec3::X * 0.1),
            ),
            (
                pair[5],
                Vec3::new(0.0, 0.0, 0.1),
                SpringEnd::on_body(pair[0], Vec3::Y * 0.1),
            ),
            (
                pair[1],
                Vec3::new(0.05, 0.0, 0.0),
                SpringEnd::on_body(far, Vec3::ZERO),
            ),
            (
                pair[2],
                Vec3::ZERO,
                SpringEnd::World(Vec3::new(0.0, 1.0, 0.0)),
            ),
        ];
        for (a, anchor, end) in springs {
            let spring = Spring::new(a, anchor, end, 10.0, 0.5);
            world.spawn(spring.with_damping(0.1));
        }
    }
    run(&mut world, 40);
    let mut bits = Vec::new();
    for e in bodies {
        let t = world.get::<Pose>(e).unwrap();
        let v = world.get::<Velocity>(e).unwrap();
        let values = t
            .translation
            .to_array()
            .into_iter()
            .chain(t.rotation.to_array())
            .chain(v.linear.to_array())
            .chain(v.angular.to_array());
        bits.extend(values.map(|x| x.widen().to_bits()));
    }
    bits
}

#[test]
fn one_and_several_threads_give_identical_bits() {
    // Small batches force the work over every thread of the pool, in different splits.
    let threaded = Parallelism {
        enabled: true,
        min_bodies: 0,
        min_batch: 64,
    };
    if std::thread::available_parallelism().map_or(1, |n| n.get()) >= 2 {
        assert!(tumble_ecs::parallel::pool_threads() >= 2 || !cfg!(feature = "parallel"));
    }
    for integrator in [Integrator::Splitting, Integrator::SymplecticEuler] {
        let single = big_world_bits(Parallelism::SINGLE_THREAD, integrator);
        let parallel = big_world_bits(threaded, integrator);
        assert_eq!(single.len(), parallel.len());
        assert!(
            single == parallel,
            "{integrator}: thread count changed the result"
        );
        assert!(single.iter().all(|&x| f64::from_bits(x).is_finite()));
    }
}
