//! Rollback: a `RollbackSnapshot` puts back exactly what the next step depends on (the world
//! checksum of the capture, and the same steps after it), in place, without re-planning; a
//! restore into a world with other entities fails and changes nothing; and GGRS's
//! `SyncTestSession` finds every resimulated frame equal to the first simulation of it.

use tumble::bevy_ecs::prelude::*;
use tumble::ecs::state::{Parts, RollbackError};
use tumble::math::{Real, Vec3};
use tumble::prelude::*;

use super::checksum::reference_world;
use super::util::{mass_props, spawn_body};

#[path = "../../examples/rollback/game.rs"]
mod game;

/// The checksum scene with a stiff pair (stepped by the implicit solve) added.
fn world(integrator: Integrator, substeps: u32) -> World {
    let mut world = reference_world(integrator);
    let settings = *world.resource::<PhysicsSettings>();
    let substeps = std::num::NonZeroU32::new(substeps).expect("substeps ≥ 1");
    world.insert_resource(
        settings
            .with_substeps(substeps)
            .expect("a substep in range"),
    );
    let rising = Velocity::linear(Vec3::new(0.0, 1.0, 0.0));
    let a = spawn_body(&mut world, 0.5, [0.02, 0.03, 0.04], rising);
    let beside = Pose::from_translation(Vec3::new(0.6, 0.0, 0.0));
    let b = spawn_body(&mut world, 0.7, [0.05, 0.02, 0.04], beside);
    let end = SpringEnd::on_body(b, Vec3::new(-0.1, 0.0, 0.05));
    world.spawn(Spring::new(a, Vec3::new(0.1, 0.05, 0.0), end, 2.0e5, 0.35));
    world
}

/// The splitting world after one step, its runner, and a capture of it then.
fn captured_after_a_step() -> (World, PhysicsRunner, RollbackSnapshot) {
    let mut w = world(Integrator::Splitting, 1);
    let mut runner = PhysicsRunner::new(&mut w);
    runner.step(&mut w);
    let saved = RollbackSnapshot::capture(&mut w);
    (w, runner, saved)
}

fn bodies(world: &mut World) -> Vec<Entity> {
    let mut q = world.query_filtered::<Entity, With<RigidBody>>();
    let mut all: Vec<Entity> = q.iter(world).collect();
    all.sort();
    all
}

/// What game code does in frames that a rollback takes back: loads, a changed generator, a
/// changed gravity, damping added to a body, an accumulator removed, a body pushed to NaN (the
/// step quarantines it), and a changed mass.
fn mispredict(world: &mut World, frame: usize) {
    let ids = bodies(world);
    let k = frame % ids.len();
    if let Some(mut acc) = world.get_mut::<ForceAccumulator>(ids[k]) {
        acc.add_force(Vec3::new(3.0, -1.0, 0.5));
        acc.add_torque(Vec3::new(0.0, 0.2, 0.0));
    }
    match frame {
        0 => world.resource_mut::<Gravity>().0.y = -3.0,
        1 => {
            world.entity_mut(ids[0]).insert(Damping {
                linear: 2.0,
                angular: 1.0,
            });
        }
        2 => {
            world.get_mut::<Velocity>(ids[4]).unwrap().linear.x = Real::NAN;
        }
        3 => {
            let mut q = world.query::<&mut Spring>();
            for mut s in q.iter_mut(world) {
                s.stiffness *= 1.5;
            }
        }
        4 => {
            world.entity_mut(ids[6]).remove::<ForceAccumulator>();
        }
        5 => {
            world
                .entity_mut(ids[2])
                .insert(mass_props(3.0, [0.1, 0.2, 0.3]));
        }
        _ => {}
    }
}

/// Capture at frame 5, mispredict 8 frames, restore, then step on with the true inputs: the
/// checksum of every frame equals that of a world that never rolled back.
fn rollback_matches_straight_run(integrator: Integrator, substeps: u32) {
    let mut straight = world(integrator, substeps);
    let mut rolled = world(integrator, substeps);
    let mut runner_straight = PhysicsRunner::new(&mut straight);
    let mut runner = PhysicsRunner::new(&mut rolled);
    for _ in 0..5 {
        runner_straight.step(&mut straight);
        runner.step(&mut rolled);
    }
    let saved = RollbackSnapshot::capture(&mut rolled);
    let at_capture = world_checksum(&rolled);
    for frame in 0..8 {
        mispredict(&mut rolled, frame);
        runner.step(&mut rolled);
        rolled.clear_trackers();
    }
    assert_ne!(world_checksum(&rolled), at_capture);
    let quarantined = rolled
        .query_filtered::<(), With<Rejected>>()
        .iter(&rolled)
        .count();
    assert!(quarantined > 0, "the NaN body was quarantined");
    let replans = runner.replans();
    saved.restore(&mut rolled).expect("same entities");
    assert_eq!(world_checksum(&rolled), at_capture, "{integrator}");
    for frame in 0..40 {
        runner_straight.step(&mut straight);
        runner.step(&mut rolled);
        straight.clear_trackers();
        rolled.clear_trackers();
        assert_eq!(
            world_checksum(&rolled),
            world_checksum(&straight),
            "{integrator} × {substeps}: frame {frame} after the restore"
        );
    }
    // The mispredicted frames changed plan inputs (an accumulator removed, damping added), so
    // the runner re-planned then; the restore brings back the captured plan once, no more.
    assert!(runner.replans() <= replans + 1);
}

#[test]
fn a_restore_gives_back_the_captured_world_and_its_future() {
    rollback_matches_straight_run(Integrator::Splitting, 1);
    rollback_matches_straight_run(Integrator::Yoshida4, 1);
    rollback_matches_straight_run(Integrator::Exact, 2);
    rollback_matches_straight_run(Integrator::SymplecticEuler, 1);
}

#[test]
fn a_restore_that_changes_nothing_keeps_the_schedule() {
    let (mut w, mut runner, saved) = captured_after_a_step();
    for _ in 0..3 {
        let ids = bodies(&mut w);
        w.get_mut::<ForceAccumulator>(ids[1])
            .unwrap()
            .add_force(Vec3::X);
        runner.step(&mut w);
        saved.restore(&mut w).unwrap();
        w.clear_trackers();
    }
    assert_eq!(runner.replans(), 0);
}

#[test]
fn a_quarantine_at_the_capture_comes_back() {
    let mut w = world(Integrator::Splitting, 1);
    let mut runner = PhysicsRunner::new(&mut w);
    let ids = bodies(&mut w);
    w.get_mut::<Velocity>(ids[3]).unwrap().angular.y = Real::INFINITY;
    runner.step(&mut w);
    assert!(w.get::<Rejected>(ids[3]).is_some());
    let saved = RollbackSnapshot::capture(&mut w);
    let record = saved.bodies().iter().find(|r| r.entity == ids[3]).unwrap();
    assert!(record.parts.contains(Parts::REJECTED));
    let at_capture = world_checksum(&w);
    // Game code rescues the body (a valid velocity releases it), then the frame is rolled back.
    w.entity_mut(ids[3]).insert(Velocity::default());
    w.flush();
    assert!(w.get::<Rejected>(ids[3]).is_none());
    runner.step(&mut w);
    saved.restore(&mut w).unwrap();
    assert!(w.get::<Rejected>(ids[3]).is_some());
    assert_eq!(world_checksum(&w), at_capture);
}

#[test]
fn a_restore_into_other_entities_fails_and_changes_nothing() {
    let (mut w, mut runner, saved) = captured_after_a_step();
    runner.step(&mut w);
    let ids = bodies(&mut w);

    let extra = w.spawn(RigidBody).id();
    let before = world_checksum(&w);
    assert_eq!(
        saved.restore(&mut w),
        Err(RollbackError::BodyCountChanged {
            saved: ids.len(),
            found: ids.len() + 1
        })
    );
    assert_eq!(world_checksum(&w), before);

    w.despawn(ids[2]);
    let before = world_checksum(&w);
    assert_eq!(
        saved.restore(&mut w),
        Err(RollbackError::MissingBody(ids[2]))
    );
    assert_eq!(world_checksum(&w), before);
    w.despawn(extra);

    let w2_error = {
        let mut w2 = world(Integrator::Splitting, 1);
        let s2 = RollbackSnapshot::capture(&mut w2);
        let mut q = w2.query_filtered::<Entity, With<Spring>>();
        let first = q.iter(&w2).next().unwrap();
        w2.despawn(first);
        s2.restore(&mut w2)
    };
    assert!(matches!(
        w2_error,
        Err(RollbackError::GeneratorCountChanged { kind: "Spring", .. })
    ));
}

#[test]
fn a_body_costs_a_few_hundred_bytes() {
    let mut w = world(Integrator::Splitting, 1);
    let saved = RollbackSnapshot::capture(&mut w);
    let per_body = std::mem::size_of::<tumble::ecs::state::BodyRecord>();
    // Pose, velocity, mass properties, two loads, gravity scale, damping, an entity and flags:
    // 43 reals and 9 bytes, padded.
    let reals = 43 * std::mem::size_of::<Real>();
    assert!(
        per_body >= reals && per_body <= reals + 32,
        "{per_body} bytes"
    );
    assert!(saved.bytes() >= std::mem::size_of_val(saved.bodies()));
}

#[test]
fn ggrs_sync_test_resimulates_every_frame_to_the_same_checksum() {
    for integrator in [Integrator::Splitting, Integrator::Yoshida4] {
        let frames = 1000;
        let synced = game::sync_test(integrator, frames, 7)
            .unwrap_or_else(|e| panic!("{integrator}: GGRS found a desync: {e}"));
        assert!(
            synced.loaded >= (frames as u64 - 8),
            "{} rollbacks",
            synced.loaded
        );
        assert!(synced.advanced >= 7 * synced.loaded);
        assert_eq!(synced.replans(), 0, "a rollback rebuilt the schedule");
        let straight = game::straight(integrator, frames);
        assert_eq!(
            world_checksum(&synced.world),
            world_checksum(&straight.world),
            "{integrator}: the rolled-back run ended elsewhere"
        );
        // The implicit solve is in the loop: one spring group is stiff.
        let implicit = synced
            .world
            .iter_entities()
            .filter(|e| e.contains::<tumble::ecs::components::ImplicitSpring>())
            .count();
        assert!(implicit > 0);
    }
}
