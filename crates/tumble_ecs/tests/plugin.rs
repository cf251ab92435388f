//! `TumblePlugin` in any schedule, with its runner kept in the world: a rollback of the world
//! alone (a `RollbackSnapshot`) steps on exactly as a run that never rolled back.

use std::time::Duration;

use bevy_app::{App, FixedUpdate, Update};
use bevy_ecs::prelude::*;
use bevy_ecs::schedule::ScheduleLabel;
use bevy_time::{Fixed, Time, TimePlugin, TimeUpdateStrategy, Virtual};
use tumble_core::math::{Real, Vec3, to_f64};
use tumble_ecs::prelude::*;
use tumble_ecs::schedule::{TumblePlugin, TumbleStep};
use tumble_ecs::state::world_checksum;

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
        let x = app.world().get::<Pose>(body).unwrap().translation;
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

/// An app on Bevy's clock: `FixedUpdate` at `hz`, frames of `frame` of game time each.
fn app_on_clock(hz: f64, frame: Duration, plugin: TumblePlugin) -> App {
    let mut app = App::new();
    app.add_plugins((TimePlugin, plugin))
        .insert_resource(Time::<Fixed>::from_hz(hz))
        .insert_resource(TimeUpdateStrategy::ManualDuration(frame));
    app
}

/// Runs frames until `seconds` of game (virtual) time have passed; returns the fixed clock's
/// elapsed time, the game time the physics steps cover.
fn run_for(app: &mut App, seconds: f64) -> f64 {
    while app.world().resource::<Time<Virtual>>().elapsed_secs_f64() < seconds {
        app.update();
    }
    app.world().resource::<Time<Fixed>>().elapsed_secs_f64()
}

/// `FixedUpdate` at 60 Hz: one second of game time moves a body at 1 m/s by 1 m and a body
/// under 1 m/s² by ½ m (the default integrator is exact for a constant force), to f32
/// rounding over 60 steps, whatever the plugin's own default step (1/64 s) says.
#[test]
fn the_plugin_steps_by_bevys_fixed_clock() {
    let mut app = app_on_clock(60.0, Duration::from_millis(10), TumblePlugin::default());
    let moving = app
        .world_mut()
        .spawn((RigidBody, Velocity::linear(Vec3::X)))
        .id();
    let pushed = app.world_mut().spawn(RigidBody).id();
    app.world_mut().spawn(ConstantForce {
        body: pushed,
        force: Vec3::X,
        local_point: None,
    });
    let t = run_for(&mut app, 1.0);
    // The fixed clock lags game time by less than one of its steps (1/60 s rounded up to the
    // nanosecond: 59 steps fit in the first second).
    assert!(t <= 1.0 && 1.0 - t < 1.0 / 60.0, "fixed clock at {t} s");
    let x = |e| to_f64(app.world().get::<Pose>(e).unwrap().translation.x);
    let tol = 60.0 * 4.0 * f64::from(f32::EPSILON);
    assert!(
        (x(moving) - t).abs() < tol,
        "moved {} m in {t} s",
        x(moving)
    );
    assert!(
        (x(pushed) - 0.5 * t * t).abs() < tol,
        "pushed {} m in {t} s",
        x(pushed)
    );
    let dt = app.world().resource::<PhysicsSettings>().dt();
    let timestep = app.world().resource::<Time<Fixed>>().timestep();
    assert_eq!(dt, timestep.as_secs_f64() as Real);
}

/// A time step set by game code that differs from the clock is overridden by the clock (with a
/// warning), and a change of the clock's rate is followed from the next step on.
#[test]
fn the_clock_wins_over_a_settings_time_step() {
    let settings = PhysicsSettings::new(0.1, Integrator::Splitting).unwrap();
    let plugin = TumblePlugin::default().with_settings(settings);
    let mut app = app_on_clock(50.0, Duration::from_millis(5), plugin);
    let moving = app
        .world_mut()
        .spawn((RigidBody, Velocity::linear(Vec3::X)))
        .id();
    let t = run_for(&mut app, 0.5);
    assert_eq!(app.world().resource::<PhysicsSettings>().dt(), 0.02);
    app.world_mut()
        .resource_mut::<Time<Fixed>>()
        .set_timestep_hz(100.0);
    let t = run_for(&mut app, 1.0) - t;
    assert_eq!(app.world().resource::<PhysicsSettings>().dt(), 0.01);
    let fixed = app.world().resource::<Time<Fixed>>().elapsed_secs_f64();
    let x = to_f64(app.world().get::<Pose>(moving).unwrap().translation.x);
    assert!(
        (x - fixed).abs() < 1e-5,
        "moved {x} m in {fixed} s ({t} s at 100 Hz)"
    );
}

/// A force system placed in `PhysicsSet::Forces` of the plugin's schedule (the avian habit) runs
/// before the step, once per step.
#[test]
fn a_force_system_in_the_forces_set_is_applied() {
    let mut app = App::new();
    app.add_plugins(TumblePlugin::new(Tick))
        .add_systems(Tick, push.in_set(PhysicsSet::Forces));
    let body = app
        .world_mut()
        .spawn((RigidBody, ForceAccumulator::default()))
        .id();
    app.world_mut().run_schedule(Tick);
    let v = app.world().get::<Velocity>(body).unwrap().linear;
    assert_eq!(v, Vec3::X / 64.0, "one kick of F Δt / m");
}

/// Without a fixed clock (a schedule of the game's own) the step is the settings' time step.
#[test]
fn a_schedule_of_the_game_steps_by_the_settings() {
    let settings = PhysicsSettings::new(0.1, Integrator::Splitting).unwrap();
    let mut app = App::new();
    app.add_plugins((TimePlugin, TumblePlugin::new(Tick).with_settings(settings)));
    let body = app
        .world_mut()
        .spawn((RigidBody, Velocity::linear(Vec3::X)))
        .id();
    app.world_mut().run_schedule(Tick);
    let x = app.world().get::<Pose>(body).unwrap().translation.x;
    assert!((x - 0.1).abs() < 1e-6, "{x}");
    assert!(!TumblePlugin::new(Tick).on_fixed_clock());
    assert!(TumblePlugin::new(FixedUpdate).on_fixed_clock());
}
