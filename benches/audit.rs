//! What the energy audit costs a spring world: the same chain of bodies (springs between
//! off-centre anchors, gravity, a force at a point), stepped through the ECS schedule with the
//! audit (`EnergyAudit::Auto`, the default for a world with springs) and without it
//! (`EnergyAudit::Never`). Report the ratio, not the absolute time. The springs are stepped
//! explicitly (`SpringSolver::Explicit`; the chain stays clean, nothing is quarantined): the
//! default classification finds this chain stiff, and its implicit solve, five times the
//! explicit step, would otherwise be most of what is timed.

mod common;

use criterion::{BenchmarkId, Criterion, Throughput};
use tumble::bevy_ecs::prelude::*;
use tumble::math::{Quat, Real, Vec3};
use tumble::prelude::*;

fn chain(n: usize, audit: EnergyAudit) -> World {
    let mut world = World::new();
    let mut settings = PhysicsSettings::new(1.0 / 60.0, Integrator::Splitting).unwrap();
    settings.springs = SpringSolver::Explicit;
    world.insert_resource(settings);
    world.insert_resource(Parallelism::SINGLE_THREAD);
    world.insert_resource(Gravity(Vec3::new(0.0, -9.81, 0.0)));
    world.insert_resource(audit);
    let mut previous = None;
    for i in 0..n {
        let f = i as Real / n as Real;
        let mass = MassProperties::new(Mass::new(1.0 + f).unwrap(), Vec3::new(0.02, 0.03, 0.04));
        let body = world
            .spawn((
                RigidBody,
                MassProps(mass.unwrap()),
                Pose {
                    translation: Vec3::new(i as Real, 0.0, 0.0),
                    rotation: Quat::from_rotation_z(f),
                },
                Velocity::angular(Vec3::new(0.1, 0.2, 0.3)),
            ))
            .id();
        let end = match previous {
            Some(other) => SpringEnd::Body {
                body: other,
                anchor: Vec3::new(0.1, 0.0, 0.05),
            },
            None => SpringEnd::World(Vec3::new(-1.0, 0.0, 0.0)),
        };
        world.spawn(Spring {
            a: body,
            anchor_a: Vec3::new(-0.1, 0.05, 0.0),
            b: end,
            stiffness: 50.0,
            damping: 0.1,
            rest_length: 0.8,
        });
        if i % 10 == 0 {
            world.spawn(ConstantForce {
                body,
                force: Vec3::Z,
                local_point: Some(Vec3::Y * 0.1),
            });
        }
        previous = Some(body);
    }
    world
}

fn audit_cost(c: &mut Criterion) {
    let n = 10_000;
    let mut group = c.benchmark_group("spring_chain_step");
    group.throughput(Throughput::Elements(n as u64));
    for (name, audit) in [
        ("audited", EnergyAudit::Auto),
        ("unaudited", EnergyAudit::Never),
    ] {
        group.bench_with_input(BenchmarkId::from_parameter(name), &audit, |b, &audit| {
            let mut world = chain(n, audit);
            let mut physics = PhysicsRunner::new(&mut world);
            b.iter(|| {
                physics.step(&mut world);
                world.clear_trackers();
            });
        });
    }
    group.finish();
}

fn main() {
    common::run(audit_cost, 3);
}
