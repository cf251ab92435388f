//! `TumblePlugin` in any schedule, with its runner kept in the world: a rollback of the world
//! alone (a `RollbackSnapshot`) steps on exactly as a run that never rolled back.

use bevy_app::{App, Update};
use bevy_ecs::prelude::*;
use bevy_ecs::schedule::ScheduleLabel;
use tumble_core::math::Vec3;
use tumble_ecs::checksum::world_checksum;
use tumble_ecs::plugin::{TumblePlugin, TumbleStep};
use tumble_ecs::prelude::*;

/// A schedule of the game's own.
#[derive(ScheduleLabel, Debug, Clone, PartialEq, Eq, Hash)]
struct Tick;

/// Pushes every body along +x with 1 N.
fn push(mut bodies: Query<&mut ForceAccumulator>) {
    for mut acc in &mut bodies {
        acc.add_force(Vec3::X);
    }
}

fn app_in<L: ScheduleLabel + Clone>(label: L) -> (App, Entity) {
    let mut app = App::new();
    app.add_plugins(TumblePlugin::new(label.clone()))
        .add_systems(label, push.before(TumbleStep));
    app.world_mut()
        .insert_resource(Gravity(Vec3::new(0.0, -1.0, 0.0)));
    let body = app
        .world_mut()
        .spawn((
            RigidBody,
            Velocity {
                linear: Vec3::ZERO,
                angular: Vec3::new(0.3, 2.0, 0.1),
            },
            ForceAccumulator::default(),
        ))
        .id();
    (app, body)
}

#[test]
fn one_step_per_run_of_the_chosen_schedule() {
    for (mut app, body, run) in [
        {
            let (app, body) = app_in(Tick);
            (app, body, Tick.intern())
        },
        {
            let (app, body) = app_in(Update);
            (app, body, Update.intern())
        },
    ] {
        for _ in 0..64 {
            app.world_mut().run_schedule(run);
        }
        // One second at 64 Hz under (1, −1, 0) m/s² from rest: x = ½ t², y = −½ t².
        let x = app.world().get::<Transform>(body).unwrap().translation;
        assert!((x.x - 0.5).abs() < 1e-5 && (x.y + 0.5).abs() < 1e-5, "{x}");
        assert!(app.world().contains_resource::<PhysicsRunner>());
    }
}

#[test]
fn the_plugin_keeps_no_state_outside_the_world() {
    let (mut rolled, body) = app_in(Tick);
    let (mut straight, _) = app_in(Tick);
    for _ in 0..10 {
        rolled.world_mut().run_schedule(Tick);
        straight.world_mut().run_schedule(Tick);
    }
    let saved = RollbackSnapshot::capture(rolled.world_mut());
    for _ in 0..7 {
        // A mispredicted frame: an extra push and another integrator for a while.
        rolled
            .world_mut()
            .get_mut::<ForceAccumulator>(body)
            .unwrap()
            .add_torque(Vec3::Y);
        rolled
            .world_mut()
            .resource_mut::<PhysicsSettings>()
            .integrator = Integrator::Rk4;
        rolled.world_mut().run_schedule(Tick);
    }
    saved.restore(rolled.world_mut()).unwrap();
    for frame in 0..20 {
        rolled.world_mut().run_schedule(Tick);
        straight.world_mut().run_schedule(Tick);
        assert_eq!(
            world_checksum(rolled.world()),
            world_checksum(straight.world()),
            "frame {frame}"
        );
    }
}
