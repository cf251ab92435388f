//! A physics step allocates nothing once the world is set up: the systems work on component
//! slices and stack buffers, and re-planning keeps its stages inline. Counted with an allocator
//! that tallies the allocations of the current thread (this file is its own test binary, so the
//! counting allocator serves only these tests; with one thread, every system runs on the
//! thread that runs the schedule). With the thread pool, bevy_tasks' scope allocates while it
//! spawns and waits for the tasks (a few dozen times per step, measured; none per body).

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

use tumble::bevy_ecs::prelude::*;
use tumble::math::{Quat, Real, Vec3};
use tumble::prelude::*;

#[path = "../crates/tumble_ecs/tests/common/stages.rs"]
mod stages;

/// The system allocator, counting allocations per thread.
struct Counting;

thread_local! {
    static ALLOCATIONS: Cell<u64> = const { Cell::new(0) };
}

// SAFETY: forwards every call to the system allocator unchanged; the counter is a const-initialized
// thread-local `Cell` (no allocation, no destructor), so counting cannot recurse.
#[allow(unsafe_code)]
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.with(|n| n.set(n.get() + 1));
        // SAFETY: same contract as the caller's.
        unsafe { System.alloc(layout) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: same contract as the caller's.
        unsafe { System.dealloc(ptr, layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        ALLOCATIONS.with(|n| n.set(n.get() + 1));
        // SAFETY: same contract as the caller's.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

fn allocations() -> u64 {
    ALLOCATIONS.with(Cell::get)
}

/// `bodies` asymmetric bodies tumbling under gravity; every third has an accumulator pulled by a
/// spring to its neighbour and pushed by a force at a point, every fifth is damped.
fn world(integrator: Integrator, bodies: usize) -> World {
    let mut world = World::new();
    world.insert_resource(PhysicsSettings::new(1.0 / 60.0, integrator).unwrap());
    world.insert_resource(Parallelism::SINGLE_THREAD);
    world.insert_resource(Gravity(Vec3::new(0.0, -9.81, 0.0)));
    let mut previous = None;
    for i in 0..bodies {
        let f = i as Real / bodies as Real;
        let mass = MassProperties::new(Mass::new(1.0 + f).unwrap(), Vec3::new(1.0, 2.0 + f, 3.0));
        let mut body = world.spawn((
            RigidBody,
            MassProps(mass.unwrap()),
            Pose {
                translation: Vec3::new(2.0 * i as Real, 0.0, 0.0),
                rotation: Quat::from_rotation_y(f),
            },
            Velocity {
                linear: Vec3::new(0.0, 1.0, f),
                angular: Vec3::new(0.3, 1.0 - f, 0.2),
            },
        ));
        if i % 5 == 0 {
            body.insert(Damping {
                linear: 0.1,
                angular: 0.05,
            });
        }
        let id = body.id();
        if i % 3 == 0 {
            world.entity_mut(id).insert(ForceAccumulator::default());
            if let Some(other) = previous {
                world.spawn(Spring {
                    a: id,
                    anchor_a: Vec3::X * 0.1,
                    b: SpringEnd::Body {
                        body: other,
                        anchor: Vec3::ZERO,
                    },
                    stiffness: 20.0,
                    damping: 0.1,
                    rest_length: 2.0,
                });
            }
            world.spawn(ConstantForce {
                body: id,
                force: Vec3::Z,
                local_point: Some(Vec3::Y * 0.2),
            });
            previous = Some(id);
        }
    }
    world
}

#[test]
fn physics_steps_do_not_allocate() {
    // The plain step, a kick–drift method, and steps of several stages (the composition, and
    // substeps of it: the stage systems and the held loads).
    let one_stage = [(Integrator::Splitting, 1), (Integrator::SymplecticEuler, 1)];
    for (integrator, substeps) in one_stage.into_iter().chain(stages::SEVERAL_STAGES) {
        let mut world = world(integrator, 1000);
        world
            .resource_mut::<PhysicsSettings>()
            .set_substeps(std::num::NonZeroU32::new(substeps).unwrap())
            .unwrap();
        let mut physics = PhysicsRunner::new(&mut world);
        // Warm-up: the first steps may size buffers (command queues, trackers) once.
        for _ in 0..3 {
            physics.step(&mut world);
            world.clear_trackers();
        }
        let before = allocations();
        for _ in 0..100 {
            physics.step(&mut world);
            world.clear_trackers();
        }
        let during = allocations() - before;
        assert_eq!(
            during, 0,
            "{integrator} × {substeps}: {during} allocations in 100 steps"
        );
    }
}

/// The counter sees allocations at all (so a zero above means something).
#[test]
fn the_counter_counts() {
    let before = allocations();
    let v = std::hint::black_box(vec![1u8; 64]);
    assert!(allocations() > before);
    drop(v);
}
