//! Under the default settings a split method gives the exact free flow to the bodies it would
//! integrate badly, and only to them (`tumble_core::integrate::FreeFlow`): thin and fast bodies
//! are as right as `exact` makes them, ordinary bodies keep the split's bits, and the planner
//! says which bodies took the exact flow.

use bevy_ecs::prelude::*;
use tumble_core::math::{Real, Vec3, Widen};
use tumble_core::rotation::angle_between;
use tumble_core::{BodyState, Integrator, Mass, MassProperties, Wrench};
use tumble_ecs::prelude::*;
use tumble_ecs::stability::{ACCURACY_HORIZON, SPLIT_DRIFT_TOLERANCE};

const DT: Real = 1.0 / 60.0;
const ROD: Vec3 = Vec3::new(1e-4, 1.0, 1.0001);
const PLATE: Vec3 = Vec3::new(0.01, 1.0, 1.01);
const BOX: Vec3 = Vec3::new(1.0, 2.0, 3.0);

fn world(integrator: Integrator, free_flow: FreeFlow, inertia: Vec3, omega: Vec3) -> World {
    let mut world = World::new();
    world.insert_resource(
        PhysicsSettings::new(DT, integrator)
            .unwrap()
            .with_free_flow(free_flow),
    );
    let mass = MassProperties::new(Mass::new(1.0).unwrap(), inertia).unwrap();
    world.spawn((RigidBody, MassProps(mass), Velocity::angular(omega)));
    world
}

/// The body's pose and velocity after `steps` steps.
fn run(mut world: World, steps: usize) -> (Pose, Velocity) {
    let mut physics = PhysicsRunner::new(&mut world);
    for _ in 0..steps {
        physics.step(&mut world);
        world.clear_trackers();
    }
    let (pose, velocity) = world.query::<(&Pose, &Velocity)>().single(&world).unwrap();
    (*pose, *velocity)
}

fn same_bits(a: (Pose, Velocity), b: (Pose, Velocity)) -> bool {
    let bits = |(p, v): (Pose, Velocity)| {
        [p.translation, v.linear, v.angular]
            .into_iter()
            .flat_map(|x| x.to_array())
            .chain(p.rotation.to_array())
            .map(|x| x.widen().to_bits())
            .collect::<Vec<_>>()
    };
    bits(a) == bits(b)
}

/// Directions tilted from every principal axis.
fn directions() -> [Vec3; 3] {
    [
        Vec3::new(0.3, 1.0, 0.5).normalize(),
        Vec3::new(1.0, 0.4, -0.7).normalize(),
        Vec3::new(-0.2, 0.6, 1.0).normalize(),
    ]
}

/// A rod and a plate at the triangle limit, at |ω|Δt from 0.3 to 3: the default (`splitting`,
/// `free_flow = auto`) steps them exactly as `exact` does, bit for bit, over 10 s; the split
/// alone is far off there.
#[test]
fn thin_fast_bodies_take_the_exact_flow_by_default() {
    let steps = (ACCURACY_HORIZON / DT).round() as usize;
    for inertia in [ROD, PLATE] {
        for omega_dt in [0.3, 1.0, 3.0] {
            for direction in directions() {
                let omega = direction * (omega_dt / DT);
                let default = run(
                    world(Integrator::Splitting, FreeFlow::default(), inertia, omega),
                    steps,
                );
                let exact = run(
                    world(Integrator::Exact, FreeFlow::default(), inertia, omega),
                    steps,
                );
                assert!(
                    same_bits(default, exact),
                    "I = {inertia}, |ω|Δt = {omega_dt}, axis {direction}"
                );
                let split = run(
                    world(Integrator::Splitting, FreeFlow::Method, inertia, omega),
                    steps,
                );
                let off = angle_between(split.0.rotation, exact.0.rotation);
                assert!(off > 1e-2, "the split is off by only {off:e} rad here");
            }
        }
    }
}

/// `yoshida4` takes `exact4` where its largest stage's split errs by more than its limit.
#[test]
fn yoshida4_takes_exact4_on_a_fast_thin_body() {
    let omega = directions()[0] * (1.0 / DT);
    let steps = 120;
    let default = run(
        world(Integrator::Yoshida4, FreeFlow::default(), PLATE, omega),
        steps,
    );
    let exact4 = run(
        world(Integrator::Exact4, FreeFlow::default(), PLATE, omega),
        steps,
    );
    assert!(same_bits(default, exact4));
}

/// The spin along `direction` at which the split's predicted drift `D` (∝ |ω|³) is `fraction`
/// of the tolerance, at `DT`.
fn spin_at(inertia: Vec3, direction: Vec3, fraction: f64) -> Vec3 {
    let drift = |omega: Vec3| {
        tumble_core::integrate::split_rotation_drift(
            inertia.widen(),
            omega.widen(),
            DT.widen(),
            ACCURACY_HORIZON.widen(),
        )
    };
    let speed = (fraction * SPLIT_DRIFT_TOLERANCE.widen() / drift(direction)).cbrt();
    direction * speed as Real
}

/// Whether `integrator` steps a body of `inertia` turning at `omega` for `steps` steps to the
/// same bits under `free_flow = auto` as under `method`.
fn auto_is_method(integrator: Integrator, inertia: Vec3, omega: Vec3, steps: usize) -> bool {
    let [auto, method] = [FreeFlow::Auto, FreeFlow::Method]
        .map(|free_flow| run(world(integrator, free_flow, inertia, omega), steps));
    same_bits(auto, method)
}

/// Bodies the split integrates well keep it: a box, a plate and a near-sphere turning at a
/// tenth of the drift tolerance step bit for bit as under `free_flow = method`, at no cost but
/// the check of `|ω|²`, and the plan names none; at three times the tolerance they switch.
/// (The speeds follow the precision: `f64` holds the split to a tighter tolerance.)
#[test]
fn bodies_inside_the_tolerance_keep_the_split() {
    for inertia in [BOX, PLATE, Vec3::new(1.0, 1.2, 1.3)] {
        let direction = directions()[1];
        let slow = spin_at(inertia, direction, 0.1);
        assert!(
            auto_is_method(Integrator::Splitting, inertia, slow, 600),
            "I = {inertia} at {slow}"
        );
        let notices = check_stability(&mut world(
            Integrator::Splitting,
            FreeFlow::Auto,
            inertia,
            slow,
        ));
        assert!(
            !notices
                .iter()
                .any(|w| matches!(w, StabilityWarning::ExactFreeFlow { .. })),
            "{notices:?}"
        );
        let fast = spin_at(inertia, direction, 3.0);
        assert!(
            !auto_is_method(Integrator::Splitting, inertia, fast, 60),
            "I = {inertia} at {fast}"
        );
    }
    // `yoshida4` at a slow spin keeps its split too.
    assert!(auto_is_method(
        Integrator::Yoshida4,
        BOX,
        directions()[1] * 0.5,
        600
    ));
}

/// The choice is made from the state of every stage: a body spun up by a torque takes the
/// exact flow once it spins fast enough, and then steps as under `exact`.
#[test]
fn a_body_spun_up_by_a_torque_switches_when_it_spins_fast() {
    let spin_up = |integrator, free_flow| {
        let mut w = world(integrator, free_flow, PLATE, Vec3::new(0.0, 0.01, 0.0));
        let body = w
            .query_filtered::<Entity, With<RigidBody>>()
            .single(&w)
            .unwrap();
        w.spawn(ConstantTorque {
            body,
            torque: Vec3::new(0.4, 12.0, 6.0),
        });
        w
    };
    let steps = 600;
    let auto = run(spin_up(Integrator::Splitting, FreeFlow::Auto), steps);
    let method = run(spin_up(Integrator::Splitting, FreeFlow::Method), steps);
    let exact = run(spin_up(Integrator::Exact, FreeFlow::Auto), steps);
    // Slow at first (the split's bits), fast at the end (the exact flow's).
    assert!(!same_bits(auto, method));
    let (to_exact, split_to_exact) = (
        angle_between(auto.0.rotation, exact.0.rotation),
        angle_between(method.0.rotation, exact.0.rotation),
    );
    // The split alone ends far off; `auto` only carries what its first, slow steps cost.
    assert!(
        split_to_exact > 0.05 && to_exact < split_to_exact / 10.0,
        "auto {to_exact:e} rad from exact, the split {split_to_exact:e}"
    );
}

/// The plan names the bodies that take the exact flow now; under `free_flow = method` each is
/// warned of instead. Neither is an instability.
#[test]
fn the_plan_says_which_bodies_take_the_exact_flow() {
    let omega = directions()[0] * (1.0 / DT);
    let mut w = world(Integrator::Splitting, FreeFlow::Auto, PLATE, omega);
    let mass = MassProperties::new(Mass::new(1.0).unwrap(), ROD).unwrap();
    w.spawn((RigidBody, MassProps(mass), Velocity::angular(omega)));
    w.spawn((RigidBody, MassProps(mass), Velocity::angular(Vec3::Y * 0.1)));
    let warnings = check_stability(&mut w);
    let notices: Vec<_> = warnings
        .iter()
        .filter(|w| matches!(w, StabilityWarning::ExactFreeFlow { .. }))
        .collect();
    assert_eq!(notices.len(), 1, "{warnings:?}");
    assert!(matches!(
        notices[0],
        StabilityWarning::ExactFreeFlow { bodies: 2, .. }
    ));
    assert!(!notices[0].is_instability());
    let text = notices[0].to_string();
    assert!(
        text.contains("and 1 more bodies") && text.contains("`exact`"),
        "{text}"
    );
    let mut w = world(Integrator::Splitting, FreeFlow::Method, PLATE, omega);
    let warnings = check_stability(&mut w);
    assert!(
        warnings
            .iter()
            .any(|w| matches!(w, StabilityWarning::InexactFreeRotation { .. })),
        "{warnings:?}"
    );
    assert!(
        !warnings
            .iter()
            .any(|w| matches!(w, StabilityWarning::ExactFreeFlow { .. }))
    );
}

/// The predicted drift `D` that decides the switch is an upper bound of what the split loses
/// over the horizon: measured against `exact` on rods, plates and boxes at spins where it is
/// near and above the tolerance, the split's error stays below `D` (plus what rounding the
/// state costs `exact` itself, the tolerance). Where `D` is under the tolerance, so is the
/// split's error.
#[test]
fn the_predicted_drift_bounds_what_the_split_loses() {
    let steps = (ACCURACY_HORIZON / DT).round() as usize;
    for inertia in [ROD, PLATE, BOX, Vec3::new(0.3, 1.0, 1.3)] {
        let mass = MassProperties::new(Mass::new(1.0).unwrap(), inertia).unwrap();
        for speed in [0.1, 0.3, 1.0, 3.0] {
            for direction in directions() {
                let omega = direction * speed;
                let predicted = tumble_core::integrate::split_rotation_drift(
                    inertia.widen(),
                    omega.widen(),
                    DT.widen(),
                    ACCURACY_HORIZON.widen(),
                );
                let start = BodyState {
                    angular_velocity: omega,
                    ..Default::default()
                };
                let (mut split, mut exact) = (start, start);
                for _ in 0..steps {
                    Integrator::Splitting.step(&mut split, &mass, &Wrench::ZERO, DT);
                    Integrator::Exact.step(&mut exact, &mass, &Wrench::ZERO, DT);
                }
                let error = angle_between(split.rotation, exact.rotation);
                assert!(
                    error <= predicted + SPLIT_DRIFT_TOLERANCE.widen(),
                    "I = {inertia} at {speed} rad/s about {direction}: D = {predicted:e}, \
                     measured {error:e}"
                );
            }
        }
    }
}
