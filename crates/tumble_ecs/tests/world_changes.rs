//! Every public way to step a world follows the world's changes: an integrator switched
//! mid-run, a body spawned later without an accumulator, a spring spawned later. Each is
//! checked against its closed form through the runner and through the plugin.

use bevy_app::App;
use bevy_ecs::prelude::*;
use bevy_ecs::schedule::ScheduleLabel;
use tumble_core::math::{Real, Vec3, to_f64};
use tumble_ecs::components::{ImplicitBody, ImplicitSpring};
use tumble_ecs::prelude::*;
use tumble_ecs::schedule::TumblePlugin;

/// A schedule of the game's own, run once per step by hand.
#[derive(ScheduleLabel, Debug, Clone, PartialEq, Eq, Hash)]
struct Tick;

const DT: Real = 0.01;
const G: Real = -9.81;

/// A public way to step a world.
enum Entry {
    /// `PhysicsRunner::step` on a bare world.
    Runner(Box<World>, Option<Box<PhysicsRunner>>),
    /// `TumblePlugin` in an app, one step per run of its schedule.
    Plugin(Box<App>),
}

impl Entry {
    fn all() -> [Entry; 2] {
        let settings = PhysicsSettings::new(DT, Integrator::SymplecticEuler).unwrap();
        let mut world = World::new();
        world.insert_resource(settings);
        let mut app = App::new();
        app.add_plugins(TumblePlugin::new(Tick).with_settings(settings));
        [
            Entry::Runner(Box::new(world), None),
            Entry::Plugin(Box::new(app)),
        ]
    }

    fn name(&self) -> &'static str {
        match self {
            Entry::Runner(..) => "runner",
            Entry::Plugin(_) => "plugin",
        }
    }

    fn world(&mut self) -> &mut World {
        match self {
            Entry::Runner(world, _) => world,
            Entry::Plugin(app) => app.world_mut(),
        }
    }

    fn step(&mut self, steps: usize) {
        for _ in 0..steps {
            match self {
                Entry::Runner(world, runner) => {
                    runner
                        .get_or_insert_with(|| Box::new(PhysicsRunner::new(world)))
                        .step(world);
                    world.clear_trackers();
                }
                Entry::Plugin(app) => app.world_mut().run_schedule(Tick),
            }
        }
    }
}

/// Relative error of `x` against `exact`, in f64.
fn rel(x: Real, exact: f64) -> f64 {
    (to_f64(x) - exact).abs() / exact.abs()
}

/// A free fall under symplectic Euler, then `yoshida4` (exact for a constant force) from the
/// state the first part left: `x₁ = ½ g Δt² n(n+1)`, `v₁ = g n Δt`, then `x₁ + v₁ t + ½ g t²`.
#[test]
fn an_integrator_switched_mid_run_runs_as_chosen() {
    for mut entry in Entry::all() {
        entry
            .world()
            .insert_resource(Gravity(Vec3::new(0.0, G, 0.0)));
        let body = entry
            .world()
            .spawn((RigidBody, ForceAccumulator::default()))
            .id();
        let n = 30;
        entry.step(n);
        entry.world().resource_mut::<PhysicsSettings>().integrator = Integrator::Yoshida4;
        entry.step(n);
        let (g, dt, n) = (to_f64(G), to_f64(DT), n as f64);
        let x1 = 0.5 * g * dt * dt * n * (n + 1.0);
        let v1 = g * n * dt;
        let t = n * dt;
        let exact = x1 + v1 * t + 0.5 * g * t * t;
        let y = entry.world().get::<Pose>(body).unwrap().translation.y;
        // f32 rounding over 60 steps: far below 1e-5 of a fall of 0.18 m.
        assert!(
            rel(y, exact) < 1e-5,
            "{}: y = {y}, exact {exact}",
            entry.name()
        );
    }
}

/// A body spawned after the first steps, without an accumulator, falls as symplectic Euler's
/// closed form says from its first step on.
#[test]
fn a_body_spawned_later_without_accumulator_moves() {
    for mut entry in Entry::all() {
        entry
            .world()
            .insert_resource(Gravity(Vec3::new(0.0, G, 0.0)));
        entry
            .world()
            .spawn((RigidBody, ForceAccumulator::default()));
        entry.step(5);
        let late = entry.world().spawn(RigidBody).id();
        let n = 40;
        entry.step(n);
        let (g, dt, n) = (to_f64(G), to_f64(DT), n as f64);
        let exact = 0.5 * g * dt * dt * n * (n + 1.0);
        let y = entry.world().get::<Pose>(late).unwrap().translation.y;
        assert!(
            rel(y, exact) < 1e-5,
            "{}: y = {y}, exact {exact}",
            entry.name()
        );
    }
}

/// A spring to a world anchor spawned after the first steps pulls its body from then on: the
/// unit oscillator `x = cos t`, to the order of `splitting` (second: phase error
/// `t Δt²/24 ≈ 4e-6` at t = 1) and f32 rounding.
#[test]
fn a_spring_spawned_later_pulls() {
    for mut entry in Entry::all() {
        entry.world().resource_mut::<PhysicsSettings>().integrator = Integrator::Splitting;
        let body = entry
            .world()
            .spawn((RigidBody, Pose::from_translation(Vec3::X)))
            .id();
        entry.step(3);
        let name = entry.name();
        let x = entry.world().get::<Pose>(body).unwrap().translation;
        assert_eq!(x, Vec3::X, "{name}: nothing moves it yet");
        entry.world().spawn(Spring {
            a: body,
            anchor_a: Vec3::ZERO,
            b: SpringEnd::World(Vec3::ZERO),
            stiffness: 1.0,
            damping: 0.0,
            rest_length: 0.0,
        });
        let n = 100;
        entry.step(n);
        let exact = (n as f64 * to_f64(DT)).cos();
        let x = entry.world().get::<Pose>(body).unwrap().translation.x;
        assert!(
            (to_f64(x) - exact).abs() < 1e-4,
            "{}: x = {x}, exact {exact}",
            entry.name()
        );
    }
}

/// `PhysicsErrors` exists from the first step on, errors or not.
#[test]
fn physics_errors_exist_from_the_first_step() {
    for mut entry in Entry::all() {
        entry.world().spawn(RigidBody);
        entry.step(1);
        let errors = entry.world().resource::<PhysicsErrors>();
        assert!(errors.is_empty(), "{}", entry.name());
    }
}

/// A dynamic body spawned without `MassProps` is stepped on the default mass only after it was
/// marked and named; a body given its mass, or a static one, is not marked.
#[test]
fn a_body_without_mass_is_marked_once() {
    for mut entry in Entry::all() {
        let name = entry.name();
        let bare = entry.world().spawn(RigidBody).id();
        let given = entry.world().spawn((RigidBody, MassProps::default())).id();
        let wall = entry.world().spawn((RigidBody, Static)).id();
        assert!(entry.world().get::<MassProps>(bare).is_none(), "{name}");
        entry.step(3);
        let world = entry.world();
        assert!(world.get::<AssumedMass>(bare).is_some(), "{name}");
        assert_eq!(world.get::<MassProps>(bare), Some(&MassProps::default()));
        assert!(world.get::<AssumedMass>(given).is_none(), "{name}");
        assert!(world.get::<AssumedMass>(wall).is_none(), "{name}");
        assert!(
            !tumble_ecs::components::bodies_without_mass(world),
            "{name}"
        );
    }
}

/// A 1 kg body with moments 0.1 at `at`, at rest, with its accumulator.
fn unit_body(world: &mut World, at: Vec3) -> Entity {
    let mass = MassProperties::new(Mass::new(1.0).unwrap(), Vec3::splat(0.1)).unwrap();
    let pose = Pose::from_translation(at);
    (world.spawn((
        RigidBody,
        MassProps(mass),
        pose,
        ForceAccumulator::default(),
    )))
    .id()
}

/// The total linear momentum of `bodies` (kg·m/s, `f64`).
fn momentum(world: &World, bodies: &[Entity]) -> [f64; 3] {
    let mut p = [0.0; 3];
    for &e in bodies {
        let m = to_f64(world.get::<MassProps>(e).unwrap().mass());
        let v = world.get::<Velocity>(e).unwrap().linear;
        for (p, v) in p.iter_mut().zip(v.to_array()) {
            *p += m * to_f64(v);
        }
    }
    p
}

/// A spring changed in place — its end moved to another body, its stiffness raised past the
/// explicit step's reach — or a body's mass lowered is classified again before the next step,
/// though the number of springs and every body's components stay the same: a stiff spring
/// rewired onto a free body pulls both its new ends (it pulled one, creating momentum), and a
/// spring made stiff either way is stepped implicitly (it stayed explicit and blew up). Each
/// change alone, the world's tables unchanged by it.
#[test]
fn springs_and_masses_changed_in_place_are_classified_again() {
    let body = |world: &mut World, y: Real| unit_body(world, Vec3::new(0.0, y, 0.0));
    let pair = |world: &mut World, y: Real, k: Real, rest: Real| {
        let (a, b) = (body(world, y), body(world, y + 1.0));
        let spring = Spring::new(a, Vec3::ZERO, SpringEnd::on_body(b, Vec3::ZERO), k, rest);
        (a, b, world.spawn(spring).id())
    };
    for mut entry in Entry::all() {
        let name = entry.name();
        entry.world().resource_mut::<PhysicsSettings>().integrator = Integrator::Splitting;
        let world = entry.world();
        let (a, b, stiff) = pair(world, 0.0, 1.0e6, 1.0);
        let c = body(world, 1.1);
        let (_, _, soft) = pair(world, 5.0, 1.0, 0.9);
        let (f, g, light) = pair(world, 10.0, 1.0, 0.9);
        entry.step(5);
        let implicit =
            |entry: &mut Entry, spring| entry.world().get::<ImplicitSpring>(spring).is_some();
        assert!(implicit(&mut entry, stiff), "{name}");
        assert!(
            !implicit(&mut entry, soft) && !implicit(&mut entry, light),
            "{name}"
        );
        // The stiff spring moved from `b` to `c`, 0.1 m past its rest length.
        entry.world().get_mut::<Spring>(stiff).unwrap().b = SpringEnd::on_body(c, Vec3::ZERO);
        entry.step(30);
        let world = entry.world();
        assert!(world.get::<ImplicitBody>(c).is_some(), "{name}");
        let vc = world.get::<Velocity>(c).unwrap().linear;
        assert!(vc.length() > 1.0, "{name}: `c` not pulled ({vc})");
        // The pair a–c keeps its momentum (zero) to the solve's tolerance: it is pulled at
        // both ends.
        let p = momentum(world, &[a, b, c]);
        let scale = to_f64(vc.length());
        assert!(
            p.iter().all(|p| p.abs() <= 1e-4 * scale),
            "{name}: momentum {p:?} of a pair moving at {scale} m/s"
        );
        // The soft spring a million times stiffer: √(k/μ)Δt = 14.
        entry.world().get_mut::<Spring>(soft).unwrap().stiffness = 1.0e6;
        entry.step(1);
        assert!(
            implicit(&mut entry, soft),
            "{name}: the stiffened spring left explicit"
        );
        // The light pair's masses a million times smaller (the same inertia shape).
        for body in [f, g] {
            let mass = MassProperties::new(Mass::new(1.0e-6).unwrap(), Vec3::splat(1.0e-7));
            entry
                .world()
                .entity_mut(body)
                .insert(MassProps(mass.unwrap()));
        }
        entry.step(1);
        assert!(
            implicit(&mut entry, light),
            "{name}: the lightened pair left explicit"
        );
        let errors = entry.world().resource::<PhysicsErrors>();
        assert!(errors.bodies.is_empty(), "{name}: {:?}", errors.bodies);
    }
}

/// A world without `PhysicsSettings` steps with the default ones and says so in
/// `PhysicsErrors`; settings removed mid-run are put back as they were planned (not the
/// default, which would change the step silently), recorded too.
#[test]
fn missing_settings_are_recorded_and_the_planned_ones_kept() {
    let falling = |world: &mut World| {
        world.insert_resource(Gravity(Vec3::new(0.0, G, 0.0)));
        world.spawn((RigidBody, Pose::IDENTITY)).id()
    };
    let mut bare = World::new();
    falling(&mut bare);
    let mut runner = PhysicsRunner::new(&mut bare);
    runner.step(&mut bare);
    let recorded = &bare.resource::<PhysicsErrors>().world;
    assert_eq!(recorded.len(), 1, "{recorded:?}");
    let message = recorded[0].to_string();
    assert!(
        message.starts_with("PhysicsSettings: missing") && message.contains("default"),
        "{message}"
    );

    let dt: Real = 1.0 / 120.0;
    let mut world = World::new();
    world.insert_resource(PhysicsSettings::new(dt, Integrator::Rk4).unwrap());
    let body = falling(&mut world);
    let mut runner = PhysicsRunner::new(&mut world);
    for _ in 0..10 {
        runner.step(&mut world);
    }
    world.remove_resource::<PhysicsSettings>();
    for _ in 0..10 {
        runner.step(&mut world);
    }
    let settings = world.resource::<PhysicsSettings>();
    assert_eq!((settings.dt(), settings.integrator), (dt, Integrator::Rk4));
    // Twenty steps of 1/120 s under gravity: v = g t, exact for every method.
    let v = world.get::<Velocity>(body).unwrap().linear.y;
    let exact = to_f64(G) * 20.0 * to_f64(dt);
    assert!(rel(v, exact) < 1e-5, "v = {v}, exact {exact}");
    let recorded = &world.resource::<PhysicsErrors>().world;
    assert_eq!(recorded.len(), 1, "{recorded:?}");
    assert!(
        recorded[0]
            .to_string()
            .contains("the settings it was planned with"),
        "{}",
        recorded[0]
    );
}

/// A spring changed right after the runner is made, before any step (a game tuning its world
/// from a config), is seen too: the classification's tick is past, not at, the world's.
#[test]
fn a_spring_changed_before_the_first_step_is_classified_again() {
    let mut world = World::new();
    world.insert_resource(PhysicsSettings::new(DT, Integrator::Splitting).unwrap());
    let body = |world: &mut World, x: Real| unit_body(world, Vec3::new(x, 0.0, 0.0));
    let (a, b) = (body(&mut world, 0.0), body(&mut world, 1.0));
    let spring = Spring::new(a, Vec3::ZERO, SpringEnd::on_body(b, Vec3::ZERO), 1.0, 0.9);
    let spring = world.spawn(spring).id();
    let mut runner = PhysicsRunner::new(&mut world);
    assert!(world.get::<ImplicitSpring>(spring).is_none());
    world.get_mut::<Spring>(spring).unwrap().stiffness = 1.0e6;
    runner.step(&mut world);
    assert!(world.get::<ImplicitSpring>(spring).is_some());
}
