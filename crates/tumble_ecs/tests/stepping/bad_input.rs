//! Bad data is rejected with a typed error naming the entity, and never harms another body.

use bevy_ecs::prelude::*;
use tumble_core::math::{Quat, Real, Vec3};

use tumble_ecs::prelude::*;

use super::util::{mass_props, run_steps, spawn_body, world_with};

const STEPS: usize = 200;

/// The healthy body every case runs beside: gravity, a spring, a spin.
fn spawn_good(world: &mut World) -> Entity {
    let good = world
        .spawn((
            RigidBody,
            mass_props(1.5, [1.0, 2.0, 3.0]),
            Pose::from_translation(Vec3::new(0.0, 2.0, 0.0)),
            Velocity {
                linear: Vec3::X,
                angular: Vec3::new(0.3, 1.0, 0.2),
            },
            ForceAccumulator::default(),
        ))
        .id();
    world.spawn(Spring {
        a: good,
        anchor_a: Vec3::new(0.1, 0.0, 0.0),
        b: SpringEnd::World(Vec3::ZERO),
        stiffness: 20.0,
        damping: 0.1,
        rest_length: 1.0,
    });
    good
}

fn base_world() -> World {
    let mut world = world_with(1.0 / 60.0, Integrator::SymplecticEuler);
    world.insert_resource(Gravity(Vec3::new(0.0, -9.81, 0.0)));
    world
}

/// Final state of the good body when it is alone.
fn reference() -> (Pose, Velocity) {
    let mut world = base_world();
    let good = spawn_good(&mut world);
    let mut physics = PhysicsRunner::new(&mut world);
    run_steps(&mut world, &mut physics, STEPS);
    (
        *world.get::<Pose>(good).unwrap(),
        *world.get::<Velocity>(good).unwrap(),
    )
}

/// Runs the good body beside a bad one made by `make_bad`, optionally corrupted after `STEPS/2`
/// steps by `corrupt`; checks the good body is bit-identical to the reference and the bad one is
/// rejected with an error naming it.
fn check_case(
    name: &str,
    make_bad: impl FnOnce(&mut World) -> Entity,
    corrupt: impl FnOnce(&mut World, Entity),
    expect: impl Fn(&BodyErrorKind) -> bool,
) {
    let (ref_t, ref_v) = reference();
    let mut world = base_world();
    let good = spawn_good(&mut world);
    let bad = make_bad(&mut world);
    let mut physics = PhysicsRunner::new(&mut world);
    run_steps(&mut world, &mut physics, STEPS / 2);
    corrupt(&mut world, bad);
    run_steps(&mut world, &mut physics, STEPS - STEPS / 2);

    let t = world.get::<Pose>(good).unwrap();
    let v = world.get::<Velocity>(good).unwrap();
    assert_eq!(
        (*t, *v),
        (ref_t, ref_v),
        "{name}: the good body was disturbed"
    );
    let rejected = world
        .get::<Rejected>(bad)
        .unwrap_or_else(|| panic!("{name}: not rejected"));
    assert_eq!(rejected.0.entity, bad, "{name}: error must name the entity");
    assert!(
        expect(&rejected.0.kind),
        "{name}: unexpected error {}",
        rejected.0
    );
    let message = rejected.0.to_string();
    assert!(
        message.contains(&bad.to_string()),
        "{name}: message `{message}` lacks the entity"
    );
    let errors = world.resource::<PhysicsErrors>();
    assert!(
        errors.bodies.iter().any(|e| e.entity == bad),
        "{name}: not recorded"
    );
    assert!(
        errors.bodies.iter().all(|e| e.entity != good),
        "{name}: good body blamed"
    );
    assert!(world.get::<Rejected>(good).is_none());
}

fn invalid(component: &'static str) -> impl Fn(&BodyErrorKind) -> bool {
    move |k| matches!(k, BodyErrorKind::Invalid { component: c, .. } if *c == component)
}

fn spawn_bad(world: &mut World, t: Pose, v: Velocity, acc: Option<ForceAccumulator>) -> Entity {
    let mut e = world.spawn((RigidBody, mass_props(1.0, [1.0, 1.0, 1.0]), t, v));
    if let Some(acc) = acc {
        e.insert(acc);
    }
    e.id()
}

fn no_corruption(_: &mut World, _: Entity) {}

/// A unit body at rest at `x` on the x axis, with an accumulator.
fn loaded_body_at(world: &mut World, x: Real) -> Entity {
    world
        .spawn((
            RigidBody,
            mass_props(1.0, [1.0, 1.0, 1.0]),
            Pose::from_translation(Vec3::new(x, 0.0, 0.0)),
            Velocity::ZERO,
            ForceAccumulator::default(),
        ))
        .id()
}

#[test]
fn nan_translation_on_insert() {
    check_case(
        "nan translation",
        |w| {
            spawn_bad(
                w,
                Pose::from_translation(Vec3::new(Real::NAN, 0.0, 0.0)),
                Velocity::ZERO,
                None,
            )
        },
        no_corruption,
        invalid("Pose"),
    );
}

#[test]
fn infinite_velocity_on_insert() {
    check_case(
        "inf velocity",
        |w| {
            spawn_bad(
                w,
                Pose::IDENTITY,
                Velocity::angular(Vec3::new(0.0, Real::INFINITY, 0.0)),
                Some(ForceAccumulator::default()),
            )
        },
        no_corruption,
        invalid("Velocity"),
    );
}

#[test]
fn non_unit_and_zero_quaternions_on_insert() {
    for q in [
        Quat::from_xyzw(0.0, 0.0, 0.0, 2.0),
        Quat::from_xyzw(0.0, 0.0, 0.0, 0.0),
    ] {
        check_case(
            "non-unit quaternion",
            |w| spawn_bad(w, Pose::from_rotation(q), Velocity::ZERO, None),
            no_corruption,
            |k| {
                matches!(
                    k,
                    BodyErrorKind::Invalid {
                        component: "Pose",
                        source: tumble_core::InvalidInput::NonUnitQuaternion { .. }
                    }
                )
            },
        );
    }
}

#[test]
fn nan_force_on_insert() {
    check_case(
        "nan force",
        |w| {
            let acc = ForceAccumulator {
                force: Vec3::new(0.0, Real::NAN, 0.0),
                torque: Vec3::ZERO,
            };
            spawn_bad(w, Pose::IDENTITY, Velocity::ZERO, Some(acc))
        },
        no_corruption,
        invalid("ForceAccumulator"),
    );
}

#[test]
fn nan_written_by_game_code_after_spawn() {
    check_case(
        "nan written through &mut Pose",
        |w| spawn_bad(w, Pose::IDENTITY, Velocity::linear(Vec3::Y), None),
        |w, bad| w.get_mut::<Pose>(bad).unwrap().translation.x = Real::NAN,
        invalid("Pose"),
    );
}

#[test]
fn nan_torque_added_by_game_code() {
    check_case(
        "nan torque through add_torque",
        |w| {
            spawn_bad(
                w,
                Pose::IDENTITY,
                Velocity::ZERO,
                Some(ForceAccumulator::default()),
            )
        },
        |w, bad| {
            w.get_mut::<ForceAccumulator>(bad)
                .unwrap()
                .add_torque(Vec3::splat(Real::NAN))
        },
        invalid("ForceAccumulator"),
    );
}

#[test]
fn diverging_explicit_step_is_caught_before_nan_reaches_components() {
    // The explicit gyroscopic step is unstable for fast spins near the middle axis of a thin body:
    // it overflows f32 within the run. The body must be quarantined with finite data.
    check_case(
        "diverged",
        |w| {
            w.spawn((
                RigidBody,
                mass_props(1.0, [0.01, 1.0, 1.005]),
                Velocity::angular(Vec3::new(1.0, 60.0, 1.0)),
            ))
            .id()
        },
        no_corruption,
        // The world has a spring, so it is energy-audited: the audit sees the spin's energy
        // grow and stops it first, long before f32 overflows.
        |k| matches!(k, BodyErrorKind::EnergyGrew { .. }),
    );
}

#[test]
fn quarantined_body_keeps_finite_state_and_can_be_revived() {
    let mut world = base_world();
    let spin = Velocity::angular(Vec3::new(1.0, 60.0, 1.0));
    let bad = spawn_body(&mut world, 1.0, [0.01, 1.0, 1.005], spin);
    let mut physics = PhysicsRunner::new(&mut world);
    run_steps(&mut world, &mut physics, STEPS);
    assert!(world.get::<Rejected>(bad).is_some());
    let t = *world.get::<Pose>(bad).unwrap();
    let v = *world.get::<Velocity>(bad).unwrap();
    assert!(t.translation.is_finite() && t.rotation.is_finite());
    assert!(v.linear.is_finite() && v.angular.is_finite());
    assert!((t.rotation.length() - 1.0).abs() < 1e-6);
    // Frozen while rejected.
    run_steps(&mut world, &mut physics, 10);
    assert_eq!(*world.get::<Pose>(bad).unwrap(), t);
    // Inserting valid data lifts the quarantine.
    world.entity_mut(bad).insert(Velocity::ZERO);
    world.flush();
    assert!(world.get::<Rejected>(bad).is_none());
    run_steps(&mut world, &mut physics, 10);
    assert!(
        world.get::<Pose>(bad).unwrap().translation.y < t.translation.y,
        "falls again"
    );
}

#[test]
fn bad_time_steps_are_rejected() {
    for dt in [0.0, -0.01, Real::NAN, Real::INFINITY, Real::NEG_INFINITY] {
        let err = PhysicsSettings::new(dt, Integrator::SymplecticEuler).unwrap_err();
        assert!(
            matches!(err, tumble_core::InvalidInput::NonPositiveTimeStep(_)),
            "{dt}"
        );
        let mut settings = PhysicsSettings::default();
        assert!(settings.set_dt(dt).is_err());
        assert_eq!(
            settings.dt(),
            1.0 / 60.0,
            "a failed set_dt leaves Δt unchanged"
        );
    }
}

/// A positive step whose parts would underflow (a subnormal `Δt`: half a step rounds to
/// nothing) or whose stages would overflow is refused too; the range's ends are accepted.
#[test]
fn time_steps_the_precision_cannot_take_are_rejected() {
    let (min, max) = tumble_core::error::TIME_STEP_RANGE;
    for dt in [Real::MIN_POSITIVE, min * 0.99, max * 1.01, Real::MAX] {
        let err = PhysicsSettings::new(dt, Integrator::Yoshida4).unwrap_err();
        assert!(
            matches!(err, tumble_core::InvalidInput::TimeStepOutOfRange(_)),
            "{dt}: {err}"
        );
    }
    for dt in [min, max] {
        let settings = PhysicsSettings::new(dt, Integrator::Yoshida4).unwrap();
        // Every stage, and half of it, is a normal, finite number.
        for span in settings.stages().spans(dt) {
            for part in [span.h, 0.5 * span.h, 0.25 * span.h] {
                assert!(part.is_normal(), "{dt}: a part {part} of a stage");
            }
        }
    }
}

/// Substeps that cut a valid step into parts the precision cannot take are refused by every
/// way of setting them (the constructor, the setters of the count and of `Δt`), which then
/// leave the settings unchanged; the shortest substep accepted steps with normal parts.
#[test]
fn substeps_too_short_for_the_precision_are_rejected() {
    use std::num::NonZeroU32;
    use tumble_core::InvalidInput;
    let (min, _) = tumble_core::error::TIME_STEP_RANGE;
    // `min` is a power of two, so `8 min / 8` is exactly `min` and `8 min / 9` is below it.
    let dt = 8.0 * min;
    let n = |k: u32| NonZeroU32::new(k).unwrap();
    let settings = PhysicsSettings::new(dt, Integrator::Yoshida4).unwrap();
    let err = settings.with_substeps(n(9)).unwrap_err();
    assert_eq!(
        err,
        InvalidInput::SubstepOutOfRange { dt, substeps: 9 },
        "{err}"
    );
    assert!(err.to_string().contains("9 substeps"), "{err}");
    let mut changed = settings;
    assert!(changed.set_substeps(n(1000)).is_err());
    assert_eq!(changed, settings, "a failed set_substeps changes nothing");

    let shortest = settings.with_substeps(n(8)).unwrap();
    assert_eq!(shortest.substeps(), n(8));
    for span in shortest.stages().spans(dt) {
        for part in [span.h, 0.5 * span.h, 0.25 * span.h] {
            assert!(part.is_normal(), "a part {part} of a substep's stage");
        }
    }
    // Halving Δt under eight substeps would make each too short: refused, Δt kept.
    let mut halved = shortest;
    assert!(matches!(
        halved.set_dt(0.5 * dt),
        Err(InvalidInput::SubstepOutOfRange { substeps: 8, .. })
    ));
    assert_eq!(halved, shortest, "a failed set_dt changes nothing");
    // The everyday case is untouched.
    let mut game = PhysicsSettings::default();
    game.set_substeps(n(1000)).unwrap();
    game.set_dt(1.0 / 240.0).unwrap();
    assert_eq!((game.substeps(), game.dt()), (n(1000), 1.0 / 240.0));
}

#[test]
fn bad_mass_data_cannot_be_constructed() {
    use tumble_core::InvalidInput;
    assert_eq!(Mass::new(-2.0), Err(InvalidInput::NonPositiveMass(-2.0)));
    assert!(matches!(
        Mass::new(0.0),
        Err(InvalidInput::NonPositiveMass(_))
    ));
    let one = Mass::new(1.0).unwrap();
    assert!(matches!(
        MassProperties::new(one, Vec3::new(-1.0, 1.0, 1.0)),
        Err(InvalidInput::NegativeInertia(_))
    ));
    assert!(matches!(
        MassProperties::new(one, Vec3::new(1.0, Real::INFINITY, 1.0)),
        Err(InvalidInput::NonFinite { .. })
    ));
    assert_eq!(
        MassProperties::new(one, Vec3::ZERO),
        Err(InvalidInput::ZeroInertia)
    );
}

/// A non-finite translation or velocity written by game code between steps is found by every
/// integrator's batched step (the value reaches the stepped state, whose check fails) and named
/// by field, on bodies that take each path of a batch: lanes of eight, a lone body, the spherical
/// shortcut, the exact switch of a fast thin body, a body with an accumulator and a torque, an
/// offset centre of mass. The bad body keeps what game code wrote; every other body steps to
/// the same bits as in a world without it.
#[test]
fn a_non_finite_state_is_named_by_every_integrator() {
    type Corrupt = fn(&mut Pose, &mut Velocity, Real);
    let fields: [(&str, Corrupt); 3] = [
        ("translation", |p, _, x| p.translation.y = x),
        ("linear velocity", |_, v, x| v.linear.z = x),
        ("angular velocity", |_, v, x| v.angular.x = x),
    ];
    let offset = MassProps(
        MassProperties::new(Mass::new(2.0).unwrap(), Vec3::new(1.0, 2.0, 2.5))
            .unwrap()
            .with_center_of_mass(Vec3::new(0.1, -0.2, 0.05))
            .unwrap(),
    );
    // (mass, angular velocity, accumulator): the body kinds of a batch.
    let kinds: [(MassProps, Vec3, bool); 5] = [
        (
            mass_props(1.0, [1.0, 2.0, 3.0]),
            Vec3::new(0.3, 1.0, 0.2),
            false,
        ),
        (
            mass_props(1.0, [1.0, 1.0, 1.0]),
            Vec3::new(0.3, 1.0, 0.2),
            false,
        ),
        (
            mass_props(1.0, [0.01, 1.0, 1.005]),
            Vec3::new(40.0, 0.5, 0.3),
            false,
        ),
        (
            mass_props(1.5, [1.0, 2.0, 3.0]),
            Vec3::new(0.3, -1.0, 0.2),
            true,
        ),
        (offset, Vec3::new(0.5, 0.2, -0.4), true),
    ];
    for &integrator in Integrator::ALL {
        for (kind, &(mass, omega, with_forces)) in kinds.iter().enumerate() {
            // Nine bodies of this kind (a lane batch of eight and one alone), the bad one fifth.
            let spawn_world = || {
                let mut world = world_with(1.0 / 60.0, integrator);
                world.insert_resource(Gravity(Vec3::new(0.0, -9.81, 0.0)));
                let bodies: Vec<Entity> = (0..9)
                    .map(|i| {
                        let pose = Pose::from_translation(Vec3::new(i as Real, 1.0, 0.0));
                        let velocity = Velocity {
                            linear: Vec3::new(0.5, 0.1 * i as Real, 0.0),
                            angular: omega * (1.0 + 0.05 * i as Real),
                        };
                        let mut body = world.spawn((RigidBody, mass, pose, velocity));
                        if with_forces {
                            body.insert(ForceAccumulator::default());
                        }
                        body.id()
                    })
                    .collect();
                let physics = PhysicsRunner::new(&mut world);
                (world, physics, bodies)
            };
            let (mut reference, mut physics, bodies) = spawn_world();
            for _ in 0..3 {
                if with_forces {
                    for &body in &bodies {
                        reference
                            .entity_mut(body)
                            .apply_torque(Vec3::new(0.0, 0.2, 0.1));
                    }
                }
                physics.step(&mut reference);
                reference.clear_trackers();
            }
            for (field, corrupt) in fields {
                for bad_value in [Real::NAN, Real::INFINITY, Real::NEG_INFINITY] {
                    let case = format!("{integrator}, body kind {kind}, {field} = {bad_value}");
                    let (mut world, mut physics, bodies) = spawn_world();
                    let bad = bodies[4];
                    let mut written = None;
                    for step in 0..3 {
                        if step == 1 {
                            let mut pose = *world.get::<Pose>(bad).unwrap();
                            let mut velocity = *world.get::<Velocity>(bad).unwrap();
                            corrupt(&mut pose, &mut velocity, bad_value);
                            // Through `&mut`, as game code writes: no insert hook sees it.
                            *world.get_mut::<Pose>(bad).unwrap() = pose;
                            *world.get_mut::<Velocity>(bad).unwrap() = velocity;
                            written = Some((pose, velocity));
                        }
                        if with_forces {
                            for &body in &bodies {
                                world
                                    .entity_mut(body)
                                    .apply_torque(Vec3::new(0.0, 0.2, 0.1));
                            }
                        }
                        physics.step(&mut world);
                        world.clear_trackers();
                    }
                    let rejected = world
                        .get::<Rejected>(bad)
                        .unwrap_or_else(|| panic!("{case}: not rejected"));
                    assert!(
                        matches!(
                            &rejected.0.kind,
                            BodyErrorKind::Invalid {
                                source: tumble_core::InvalidInput::NonFinite { field: f, .. },
                                ..
                            } if *f == field
                        ),
                        "{case}: {}",
                        rejected.0
                    );
                    let (pose, velocity) = written.unwrap();
                    let kept = (
                        *world.get::<Pose>(bad).unwrap(),
                        *world.get::<Velocity>(bad).unwrap(),
                    );
                    assert_eq!(
                        state_bits(kept),
                        state_bits((pose, velocity)),
                        "{case}: bad body written"
                    );
                    for &good in bodies.iter().filter(|&&b| b != bad) {
                        assert!(
                            world.get::<Rejected>(good).is_none(),
                            "{case}: good body blamed"
                        );
                        assert_eq!(
                            (world.get::<Pose>(good), world.get::<Velocity>(good)),
                            (reference.get::<Pose>(good), reference.get::<Velocity>(good)),
                            "{case}: a good body was disturbed"
                        );
                    }
                }
            }
        }
    }
}

/// A body's pose and velocity bit for bit (a NaN is not equal to itself).
fn state_bits((pose, velocity): (Pose, Velocity)) -> Vec<String> {
    let vectors = [pose.translation, velocity.linear, velocity.angular];
    let values = vectors.iter().flat_map(|v| v.to_array());
    values
        .chain(pose.rotation.to_array())
        .map(|x| x.to_bits().to_string())
        .collect()
}

/// Bad data written by game code into one body of a stiff (implicit) spring group is refused
/// for that body alone, naming the field, as on the explicit path: the rest of the group steps
/// on without it (its springs to the refused body exert nothing, as to any quarantined body),
/// and the refused body keeps what game code wrote.
#[test]
fn bad_data_in_a_stiff_group_is_refused_for_its_body_alone() {
    type Corrupt = fn(&mut World, Entity);
    let cases: [(&str, Corrupt, &str); 4] = [
        (
            "nan velocity",
            |w, e| w.get_mut::<Velocity>(e).unwrap().linear.y = Real::NAN,
            "Velocity",
        ),
        (
            "infinite translation",
            |w, e| w.get_mut::<Pose>(e).unwrap().translation.x = Real::INFINITY,
            "Pose",
        ),
        (
            "non-unit rotation",
            |w, e| w.get_mut::<Pose>(e).unwrap().rotation = Quat::from_xyzw(0.0, 0.0, 0.0, 2.0),
            "Pose",
        ),
        (
            "nan force",
            |w, e| w.entity_mut(e).apply_force(Vec3::new(0.0, Real::NAN, 0.0)),
            "ForceAccumulator",
        ),
    ];
    for (name, corrupt, component) in cases {
        let mut world = world_with(1.0 / 60.0, Integrator::Splitting);
        world.resource_mut::<PhysicsSettings>().springs = SpringSolver::Implicit;
        world.insert_resource(Gravity(Vec3::new(0.0, -9.81, 0.0)));
        let bodies: Vec<Entity> = (0..5)
            .map(|i| {
                world
                    .spawn((
                        RigidBody,
                        mass_props(1.0, [0.02, 0.03, 0.04]),
                        Pose::from_translation(Vec3::new(0.5 * i as Real, 0.0, 0.0)),
                        Velocity::angular(Vec3::new(0.3, -0.2, 0.1)),
                        ForceAccumulator::default(),
                    ))
                    .id()
            })
            .collect();
        for pair in bodies.windows(2) {
            world.spawn(Spring {
                a: pair[0],
                anchor_a: Vec3::new(0.2, 0.02, 0.0),
                b: SpringEnd::Body {
                    body: pair[1],
                    anchor: Vec3::new(-0.2, 0.0, 0.01),
                },
                stiffness: 1.0e5,
                damping: 0.0,
                rest_length: 0.1,
            });
        }
        let mut physics = PhysicsRunner::new(&mut world);
        run_steps(&mut world, &mut physics, 3);
        let bad = bodies[2];
        corrupt(&mut world, bad);
        let written = (
            *world.get::<Pose>(bad).unwrap(),
            *world.get::<Velocity>(bad).unwrap(),
        );
        run_steps(&mut world, &mut physics, 20);
        let rejected = world
            .get::<Rejected>(bad)
            .unwrap_or_else(|| panic!("{name}: not rejected"));
        assert!(
            matches!(&rejected.0.kind, BodyErrorKind::Invalid { component: c, .. } if *c == component),
            "{name}: {}",
            rejected.0
        );
        assert_eq!(
            state_bits((
                *world.get::<Pose>(bad).unwrap(),
                *world.get::<Velocity>(bad).unwrap()
            )),
            state_bits(written),
            "{name}: the refused body was written"
        );
        for &good in bodies.iter().filter(|&&b| b != bad) {
            assert!(
                world.get::<Rejected>(good).is_none(),
                "{name}: {good} was refused with the bad body: {}",
                world.get::<Rejected>(good).unwrap().0
            );
            let pose = world.get::<Pose>(good).unwrap();
            let velocity = world.get::<Velocity>(good).unwrap();
            assert!(
                pose.translation.is_finite() && velocity.linear.is_finite(),
                "{name}: {good} went bad"
            );
        }
        // The rest of the group kept moving: under gravity it fell.
        assert!(
            world.get::<Pose>(bodies[0]).unwrap().translation.y < -0.01,
            "{name}"
        );
    }
}

/// Bad data game code writes into a body tumble never integrates — a kinematic body it moves,
/// a static anchor — is refused for that body, naming the field, and harms none of the bodies
/// its springs pull: explicit springs with dampers and implicit (stiff) ones alike. Those
/// springs exert nothing while their end is bad, as a quarantined body's.
#[test]
fn bad_data_in_a_fixed_body_harms_none_of_its_springs_bodies() {
    type Corrupt = fn(&mut World, Entity);
    let cases: [(&str, Corrupt, &str); 3] = [
        (
            "nan translation",
            |w, e| w.get_mut::<Pose>(e).unwrap().translation.y = Real::NAN,
            "Pose",
        ),
        (
            "infinite velocity",
            |w, e| w.get_mut::<Velocity>(e).unwrap().linear.x = Real::INFINITY,
            "Velocity",
        ),
        (
            "non-unit rotation",
            |w, e| w.get_mut::<Pose>(e).unwrap().rotation = Quat::from_xyzw(0.0, 0.0, 0.0, 3.0),
            "Pose",
        ),
    ];
    for solver in [SpringSolver::Explicit, SpringSolver::Implicit] {
        for fixed_kind in ["kinematic", "static"] {
            for (name, corrupt, component) in cases {
                let case = format!("{solver:?} springs, {fixed_kind} anchor, {name}");
                let mut world = world_with(1.0 / 60.0, Integrator::Splitting);
                world.resource_mut::<PhysicsSettings>().springs = solver;
                world.insert_resource(Gravity(Vec3::new(0.0, -9.81, 0.0)));
                let mut anchor = world.spawn((RigidBody, Pose::IDENTITY, Velocity::ZERO));
                if fixed_kind == "kinematic" {
                    anchor.insert(Kinematic);
                } else {
                    anchor.insert(Static);
                }
                let anchor = anchor.id();
                let body = world
                    .spawn((
                        RigidBody,
                        mass_props(1.0, [0.02, 0.03, 0.04]),
                        Pose::from_translation(Vec3::new(0.5, 0.0, 0.0)),
                        Velocity::angular(Vec3::new(0.3, -0.2, 0.1)),
                        ForceAccumulator::default(),
                    ))
                    .id();
                world.spawn(Spring {
                    a: body,
                    anchor_a: Vec3::new(-0.1, 0.02, 0.0),
                    b: SpringEnd::Body {
                        body: anchor,
                        anchor: Vec3::new(0.05, 0.0, 0.0),
                    },
                    // √(k/m)Δt = 0.5 explicit (inside its stable region), 2.4 implicit.
                    stiffness: if solver == SpringSolver::Explicit {
                        900.0
                    } else {
                        2.0e4
                    },
                    damping: 1.0,
                    rest_length: 0.3,
                });
                let mut physics = PhysicsRunner::new(&mut world);
                run_steps(&mut world, &mut physics, 3);
                corrupt(&mut world, anchor);
                run_steps(&mut world, &mut physics, 5);
                let rejected = world
                    .get::<Rejected>(anchor)
                    .unwrap_or_else(|| panic!("{case}: the anchor was not refused"));
                assert!(
                    matches!(&rejected.0.kind, BodyErrorKind::Invalid { component: c, .. } if *c == component),
                    "{case}: {}",
                    rejected.0
                );
                if let Some(r) = world.get::<Rejected>(body) {
                    panic!("{case}: the pulled body was refused: {}", r.0);
                }
                let pose = world.get::<Pose>(body).unwrap();
                let velocity = world.get::<Velocity>(body).unwrap();
                assert!(
                    pose.translation.is_finite()
                        && velocity.linear.is_finite()
                        && velocity.angular.is_finite(),
                    "{case}: the pulled body went bad"
                );
            }
        }
    }
}

/// A spring whose force overflows the precision (`k (ℓ − L₀)` past its largest number, both
/// ends finite) refuses the bodies it pulls, loudly, with a force that is not finite: it is not
/// left out of the step as if it were not there (the bodies then stood still, and the run
/// reported success). To a world point and between two bodies; a healthy body beside them
/// steps on untouched.
#[test]
fn a_spring_force_past_the_precision_refuses_its_bodies() {
    for between_bodies in [false, true] {
        let case = if between_bodies {
            "two bodies"
        } else {
            "a world point"
        };
        let mut world = world_with(1.0 / 60.0, Integrator::Splitting);
        world.resource_mut::<PhysicsSettings>().springs = SpringSolver::Explicit;
        let body = loaded_body_at;
        let a = body(&mut world, 0.0);
        let healthy = body(&mut world, 5.0);
        // `k ℓ` is ten times the precision's largest number, `ℓ` itself is finite.
        let far = Real::MAX / 2.0;
        let (b, spring_end) = if between_bodies {
            let b = body(&mut world, far);
            (Some(b), SpringEnd::on_body(b, Vec3::ZERO))
        } else {
            (None, SpringEnd::World(Vec3::new(far, 0.0, 0.0)))
        };
        world.spawn(Spring::new(a, Vec3::ZERO, spring_end, 20.0, 0.0));
        let mut physics = PhysicsRunner::new(&mut world);
        run_steps(&mut world, &mut physics, 2);
        for pulled in std::iter::once(a).chain(b) {
            let rejected = world
                .get::<Rejected>(pulled)
                .unwrap_or_else(|| panic!("{case}: a pulled body was not refused"));
            assert!(
                matches!(
                    &rejected.0.kind,
                    BodyErrorKind::Invalid {
                        component: "ForceAccumulator",
                        ..
                    }
                ),
                "{case}: {}",
                rejected.0
            );
            assert!(
                world
                    .resource::<PhysicsErrors>()
                    .bodies
                    .iter()
                    .any(|e| e.entity == pulled),
                "{case}: not recorded"
            );
        }
        assert!(world.get::<Rejected>(healthy).is_none(), "{case}");
        assert_eq!(
            world.get::<Pose>(healthy).unwrap().translation,
            Vec3::new(5.0, 0.0, 0.0),
            "{case}"
        );
    }
}

/// A negative or NaN damping rate written by game code is refused for its body, naming the
/// field, on the explicit and the implicit path: the damping flow treats such a rate as no
/// damping (never growth), so without the check it would be ignored silently.
#[test]
fn a_bad_damping_rate_is_refused_not_ignored() {
    for solver in [SpringSolver::Explicit, SpringSolver::Implicit] {
        for (field, bad) in [("linear", Real::NAN), ("angular", -0.5)] {
            let case = format!("{solver:?}, {field} = {bad}");
            let mut world = world_with(1.0 / 60.0, Integrator::Splitting);
            world.resource_mut::<PhysicsSettings>().springs = solver;
            let spawn = |world: &mut World, x: Real| {
                world
                    .spawn((
                        RigidBody,
                        mass_props(1.0, [0.02, 0.03, 0.04]),
                        Pose::from_translation(Vec3::new(x, 0.0, 0.0)),
                        Velocity::angular(Vec3::new(0.3, -0.2, 0.1)),
                        ForceAccumulator::default(),
                        Damping {
                            linear: 0.1,
                            angular: 0.1,
                        },
                    ))
                    .id()
            };
            let (a, b) = (spawn(&mut world, 0.0), spawn(&mut world, 0.6));
            world.spawn(Spring {
                a,
                anchor_a: Vec3::new(0.1, 0.0, 0.0),
                b: SpringEnd::Body {
                    body: b,
                    anchor: Vec3::new(-0.1, 0.0, 0.0),
                },
                stiffness: if solver == SpringSolver::Explicit {
                    400.0
                } else {
                    2.0e4
                },
                damping: 0.0,
                rest_length: 0.3,
            });
            let mut physics = PhysicsRunner::new(&mut world);
            run_steps(&mut world, &mut physics, 2);
            let mut damping = world.get_mut::<Damping>(a).unwrap();
            if field == "linear" {
                damping.linear = bad;
            } else {
                damping.angular = bad;
            }
            run_steps(&mut world, &mut physics, 2);
            let rejected = world
                .get::<Rejected>(a)
                .unwrap_or_else(|| panic!("{case}: not refused"));
            assert!(
                matches!(
                    &rejected.0.kind,
                    BodyErrorKind::Invalid {
                        component: "Damping",
                        source: tumble_core::InvalidInput::Negative { field: f, .. },
                    } if *f == field
                ),
                "{case}: {}",
                rejected.0
            );
            assert!(
                world.get::<Rejected>(b).is_none(),
                "{case}: its partner was refused"
            );
        }
    }
}

/// A non-finite `Gravity` written by game code is left out of the step and recorded once, as a
/// `WorldError` naming the resource; no body is quarantined for it (bodies with and without
/// accumulators, in an audited spring pair). A valid gravity applies again at once.
#[test]
fn a_bad_gravity_is_left_out_not_carried_into_every_body() {
    let mut world = world_with(1.0 / 60.0, Integrator::Splitting);
    world.insert_resource(Gravity(Vec3::new(0.0, -9.81, 0.0)));
    let free = spawn_body(&mut world, 1.0, [1.0, 2.0, 3.0], Velocity::ZERO);
    let loaded = world
        .spawn((
            RigidBody,
            mass_props(1.0, [0.02, 0.03, 0.04]),
            Pose::from_translation(Vec3::new(1.0, 0.0, 0.0)),
            Velocity::ZERO,
            ForceAccumulator::default(),
        ))
        .id();
    let partner = world
        .spawn((
            RigidBody,
            mass_props(1.0, [0.02, 0.03, 0.04]),
            Pose::from_translation(Vec3::new(1.5, 0.0, 0.0)),
            Velocity::ZERO,
            ForceAccumulator::default(),
        ))
        .id();
    world.spawn(Spring::new(
        loaded,
        Vec3::ZERO,
        SpringEnd::on_body(partner, Vec3::ZERO),
        100.0,
        0.5,
    ));
    let mut physics = PhysicsRunner::new(&mut world);
    run_steps(&mut world, &mut physics, 3);
    let falling = world.get::<Velocity>(free).unwrap().linear.y;
    assert!(falling < 0.0);
    world.resource_mut::<Gravity>().0.y = Real::NAN;
    run_steps(&mut world, &mut physics, 4);
    for body in [free, loaded, partner] {
        if let Some(r) = world.get::<Rejected>(body) {
            panic!("{body} was refused for the world's gravity: {}", r.0);
        }
        let v = world.get::<Velocity>(body).unwrap();
        assert!(v.linear.is_finite(), "{body}");
    }
    // No gravity while it is bad: the free body keeps its vertical velocity, bit for bit.
    assert_eq!(world.get::<Velocity>(free).unwrap().linear.y, falling);
    let errors = world.resource::<PhysicsErrors>();
    assert_eq!(
        errors.world.len(),
        1,
        "one record for one bad value: {errors:?}"
    );
    let message = errors.world[0].to_string();
    assert!(
        message.contains("Gravity") && message.contains("not finite"),
        "{message}"
    );
    world.resource_mut::<Gravity>().0 = Vec3::new(Real::INFINITY, 0.0, 0.0);
    run_steps(&mut world, &mut physics, 2);
    assert_eq!(
        world.resource::<PhysicsErrors>().world.len(),
        2,
        "a new bad value"
    );
    world.resource_mut::<Gravity>().0 = Vec3::new(0.0, -9.81, 0.0);
    run_steps(&mut world, &mut physics, 1);
    assert!(
        world.get::<Velocity>(free).unwrap().linear.y < falling,
        "gravity applies again"
    );
}

/// A non-finite `GravityScale` written by game code refuses its body before it steps, naming
/// the scale (not the accumulator gravity is added to, nor a divergence): the body keeps the
/// state it had, its spring partner and the healthy body step on as in a world without it.
/// Bodies with and without an accumulator (gravity added by `apply_gravity`, or inside the
/// integration), alone, on an explicit spring or in a stiff group (which the first-order method
/// cannot step), under a drift–kick–drift, a first-order and a composed method.
#[test]
fn a_bad_gravity_scale_is_named_and_its_body_keeps_its_state() {
    #[derive(Debug, Clone, Copy, PartialEq)]
    enum Partner {
        None,
        Explicit,
        Stiff,
    }
    let steps = 6;
    for integrator in [
        Integrator::Splitting,
        Integrator::SymplecticEuler,
        Integrator::Yoshida4,
    ] {
        let base_world = || {
            let mut world = world_with(1.0 / 60.0, integrator);
            world.insert_resource(Gravity(Vec3::new(0.0, -9.81, 0.0)));
            world
        };
        let good_alone = {
            let mut world = base_world();
            let good = spawn_good(&mut world);
            let mut physics = PhysicsRunner::new(&mut world);
            run_steps(&mut world, &mut physics, steps);
            (
                *world.get::<Pose>(good).unwrap(),
                *world.get::<Velocity>(good).unwrap(),
            )
        };
        for (accumulator, partner) in [
            (false, Partner::None),
            (true, Partner::None),
            (true, Partner::Explicit),
            (true, Partner::Stiff),
        ] {
            if partner == Partner::Stiff && integrator == Integrator::SymplecticEuler {
                continue;
            }
            for bad in [Real::NAN, Real::INFINITY, Real::NEG_INFINITY] {
                let case = format!("{integrator}, accumulator {accumulator}, {partner:?}, {bad}");
                let mut world = base_world();
                let good = spawn_good(&mut world);
                let v = Velocity {
                    linear: Vec3::new(0.5, 1.0, 0.0),
                    angular: Vec3::new(0.2, -0.4, 0.3),
                };
                let t = Pose::from_translation(Vec3::new(5.0, 0.0, 0.0));
                let body = spawn_bad(
                    &mut world,
                    t,
                    v,
                    accumulator.then(ForceAccumulator::default),
                );
                world.entity_mut(body).insert(GravityScale(0.5));
                let other = (partner != Partner::None).then(|| {
                    let other = spawn_body(&mut world, 1.0, [1.0, 1.0, 1.0], Velocity::ZERO);
                    world.get_mut::<Pose>(other).unwrap().translation = Vec3::new(5.5, 0.0, 0.0);
                    world.entity_mut(other).insert(ForceAccumulator::default());
                    let stiffness = if partner == Partner::Stiff {
                        1.0e7
                    } else {
                        10.0
                    };
                    world.spawn(Spring::new(
                        body,
                        Vec3::ZERO,
                        SpringEnd::on_body(other, Vec3::ZERO),
                        stiffness,
                        0.5,
                    ));
                    other
                });
                let mut physics = PhysicsRunner::new(&mut world);
                run_steps(&mut world, &mut physics, steps / 2);
                let before = (
                    *world.get::<Pose>(body).unwrap(),
                    *world.get::<Velocity>(body).unwrap(),
                );
                world.get_mut::<GravityScale>(body).unwrap().0 = bad;
                run_steps(&mut world, &mut physics, steps - steps / 2);
                let rejected = world
                    .get::<Rejected>(body)
                    .unwrap_or_else(|| panic!("{case}: not refused"));
                assert!(
                    invalid("GravityScale")(&rejected.0.kind),
                    "{case}: {}",
                    rejected.0
                );
                let after = (
                    *world.get::<Pose>(body).unwrap(),
                    *world.get::<Velocity>(body).unwrap(),
                );
                assert_eq!(after, before, "{case}: the refused body moved");
                let good_now = (
                    *world.get::<Pose>(good).unwrap(),
                    *world.get::<Velocity>(good).unwrap(),
                );
                assert_eq!(
                    good_now, good_alone,
                    "{case}: the healthy body was disturbed"
                );
                if let Some(other) = other {
                    if let Some(r) = world.get::<Rejected>(other) {
                        panic!("{case}: its spring partner was refused: {}", r.0);
                    }
                    assert!(world.get::<Velocity>(other).unwrap().linear.is_finite());
                }
                let errors = &world.resource::<PhysicsErrors>().bodies;
                assert_eq!(errors.len(), 1, "{case}: {errors:?}");
            }
        }
    }
}

/// Without a gravity field the scale is unused: a non-finite one harms nothing and refuses
/// nothing (with and without an accumulator).
#[test]
fn a_bad_gravity_scale_without_gravity_is_unused() {
    for accumulator in [false, true] {
        let mut world = world_with(1.0 / 60.0, Integrator::Splitting);
        let v = Velocity {
            linear: Vec3::new(0.5, 1.0, 0.0),
            angular: Vec3::new(0.2, -0.4, 0.3),
        };
        let body = spawn_bad(
            &mut world,
            Pose::default(),
            v,
            accumulator.then(ForceAccumulator::default),
        );
        world.entity_mut(body).insert(GravityScale(Real::NAN));
        let mut physics = PhysicsRunner::new(&mut world);
        run_steps(&mut world, &mut physics, 3);
        assert!(world.get::<Rejected>(body).is_none(), "{accumulator}");
        let t = world.get::<Pose>(body).unwrap();
        assert!(
            (t.translation.x - 0.025).abs() < 1e-5,
            "{accumulator}: {t:?}"
        );
    }
}

/// A body refused in an early stage of a composed step (`yoshida4`: three runs of the schedule
/// a step) leaves its stiff group part-way: its spring stops acting, which the energy audit must
/// not charge to the integrator. Its partner steps on, unrefused (it was quarantined for
/// "energy grew" when the audit judged the group's balance across the refusal).
#[test]
fn a_body_refused_mid_step_does_not_quarantine_its_stiff_partner() {
    let mut world = world_with(1.0 / 60.0, Integrator::Yoshida4);
    world.insert_resource(Gravity(Vec3::new(0.0, -9.81, 0.0)));
    let spawn = |world: &mut World, x: Real| {
        world
            .spawn((
                RigidBody,
                mass_props(1.0, [1.0, 1.0, 1.0]),
                Pose::from_translation(Vec3::new(x, 0.0, 0.0)),
                // Moving together: frozen, the refused body would stretch the spring by its
                // partner's motion.
                Velocity::linear(Vec3::new(0.5, 1.0, 0.0)),
                ForceAccumulator::default(),
            ))
            .id()
    };
    let (bad, partner) = (spawn(&mut world, 0.0), spawn(&mut world, 0.5));
    world.spawn(Spring::new(
        bad,
        Vec3::ZERO,
        SpringEnd::on_body(partner, Vec3::ZERO),
        1.0e7,
        0.5,
    ));
    let mut physics = PhysicsRunner::new(&mut world);
    run_steps(&mut world, &mut physics, 3);
    world
        .entity_mut(bad)
        .apply_force(Vec3::new(0.0, Real::NAN, 0.0));
    run_steps(&mut world, &mut physics, 3);
    let refused = world.get::<Rejected>(bad).expect("the bad body is refused");
    assert!(
        invalid("ForceAccumulator")(&refused.0.kind),
        "{}",
        refused.0
    );
    if let Some(r) = world.get::<Rejected>(partner) {
        panic!("the partner was refused: {}", r.0);
    }
    assert!(world.get::<Velocity>(partner).unwrap().linear.is_finite());
}

/// A non-finite force game code applies between steps is one incident, one record: the
/// stage's first phase refuses the body, and the later phase that finds the same force (its
/// quarantine still a deferred command) records nothing more. It was recorded twice: the two
/// errors differ once the force stage adds to the bad force between the phases. With and
/// without gravity and a constant force (which add to it), in one stage and in three.
#[test]
fn a_non_finite_force_is_recorded_once() {
    for integrator in [
        Integrator::Splitting,
        Integrator::SymplecticEuler,
        Integrator::Yoshida4,
    ] {
        for gravity in [false, true] {
            let case = format!("{integrator}, loaded {gravity}");
            let mut world = world_with(1.0 / 60.0, integrator);
            let v = Velocity::linear(Vec3::new(0.5, 1.0, 0.0));
            let body = spawn_bad(&mut world, Pose::default(), v, Some(Default::default()));
            if gravity {
                world.insert_resource(Gravity(Vec3::new(0.0, -9.81, 0.0)));
                world.spawn(ConstantForce {
                    body,
                    force: Vec3::new(2.0, 0.0, 0.0),
                    local_point: None,
                });
            }
            let mut physics = PhysicsRunner::new(&mut world);
            run_steps(&mut world, &mut physics, 2);
            world
                .entity_mut(body)
                .apply_force(Vec3::new(0.0, Real::NAN, 0.0));
            run_steps(&mut world, &mut physics, 2);
            let refused = world.get::<Rejected>(body).expect("refused");
            assert!(invalid("ForceAccumulator")(&refused.0.kind), "{case}");
            let errors = &world.resource::<PhysicsErrors>().bodies;
            assert_eq!(errors.len(), 1, "{case}: {errors:?}");
        }
    }
}

#[derive(Component)]
struct Sabotaged;

/// Game code's force system that writes a non-finite force into the sabotaged bodies, in the
/// force stage: after a drift–kick–drift method's first half drift.
fn sabotage(mut bodies: Query<&mut ForceAccumulator, With<Sabotaged>>) {
    for mut acc in &mut bodies {
        acc.add_force(Vec3::new(Real::NAN, 0.0, 0.0));
    }
}

/// A body refused in the second half of a drift–kick–drift stage — a force made bad in the
/// force stage, or a kick that overflows — keeps, to the bit, the state the stage found it in,
/// not the one its first half drift had reached (which a quarantine would report as the
/// body's last valid state); its neighbour in the same table steps on.
#[test]
fn a_body_refused_after_its_first_half_drift_keeps_the_state_before_it() {
    let midpoint = Integrator::ALL
        .iter()
        .copied()
        .filter(|m| m.samples_forces_at_midpoint());
    for integrator in midpoint {
        for overflow in [false, true] {
            let case = format!("{integrator}, overflow {overflow}");
            // A kick of `g Δt` past the precision's largest number, from a finite half drift.
            let dt = if overflow {
                tumble_core::error::TIME_STEP_RANGE.1 / 2.0
            } else {
                1.0 / 60.0
            };
            let mut world = world_with(dt, integrator);
            world.insert_resource(Gravity(Vec3::new(0.0, -1.0e3, 0.0)));
            let moving = |world: &mut World, x: Real| {
                world
                    .spawn((
                        RigidBody,
                        mass_props(1.0, [1.0, 2.0, 3.0]),
                        Pose::from_translation(Vec3::new(x, 0.0, 0.0)),
                        Velocity {
                            linear: Vec3::new(1.0, 0.5, 0.25),
                            angular: Vec3::new(0.3, 1.0, 0.2),
                        },
                        ForceAccumulator::default(),
                    ))
                    .id()
            };
            let bad = moving(&mut world, 0.0);
            let neighbour = moving(&mut world, 3.0);
            if !overflow {
                world.entity_mut(bad).insert(Sabotaged);
                let mut forces = ForceSystems::default();
                forces.add(sabotage);
                world.insert_resource(forces);
            }
            let before = (
                *world.get::<Pose>(bad).unwrap(),
                *world.get::<Velocity>(bad).unwrap(),
            );
            let mut physics = PhysicsRunner::new(&mut world);
            run_steps(&mut world, &mut physics, 1);
            let refused = world.get::<Rejected>(bad).expect("refused");
            let expected = if overflow {
                matches!(refused.0.kind, BodyErrorKind::Diverged(_))
            } else {
                invalid("ForceAccumulator")(&refused.0.kind)
            };
            assert!(expected, "{case}: {}", refused.0);
            let after = (
                *world.get::<Pose>(bad).unwrap(),
                *world.get::<Velocity>(bad).unwrap(),
            );
            assert_eq!(state_bits(after), state_bits(before), "{case}");
            if !overflow {
                assert!(world.get::<Rejected>(neighbour).is_none(), "{case}");
                let moved = world.get::<Pose>(neighbour).unwrap().translation;
                assert!(moved.x > 3.0 && moved.is_finite(), "{case}: {moved}");
            }
        }
    }
}

#[derive(Resource)]
struct Reshuffle {
    gone: Entity,
    bad: Entity,
}

/// Game code with the whole world, in the force stage: despawns one body and spawns another
/// of the same table (the bad body moves into the freed row), and makes the bad body's force
/// non-finite.
fn reshuffle(world: &mut World) {
    let Some(Reshuffle { gone, bad }) = world.remove_resource::<Reshuffle>() else {
        return;
    };
    world.despawn(gone);
    world.spawn((
        RigidBody,
        mass_props(1.0, [1.0, 2.0, 3.0]),
        Pose::from_translation(Vec3::new(9.0, 0.0, 0.0)),
        Velocity::ZERO,
        ForceAccumulator::default(),
    ));
    world
        .get_mut::<ForceAccumulator>(bad)
        .unwrap()
        .add_force(Vec3::new(Real::NAN, 0.0, 0.0));
}

/// A body put back after a refused second half takes its own saved state or none: where game
/// code rearranged its table between the halves, the row it now sits in was saved for another
/// body, whose state it must not take.
#[test]
fn a_refused_body_never_takes_the_saved_state_of_another() {
    let mut world = world_with(1.0 / 60.0, Integrator::Splitting);
    let body = |world: &mut World, x: Real| {
        world
            .spawn((
                RigidBody,
                mass_props(1.0, [1.0, 2.0, 3.0]),
                Pose::from_translation(Vec3::new(x, 0.0, 0.0)),
                Velocity::linear(Vec3::new(0.0, x, 0.0)),
                ForceAccumulator::default(),
            ))
            .id()
    };
    let _first = body(&mut world, 1.0);
    let gone = body(&mut world, 2.0);
    let bad = body(&mut world, 3.0);
    let mut forces = ForceSystems::default();
    forces.add(reshuffle);
    world.insert_resource(forces);
    let mut physics = PhysicsRunner::new(&mut world);
    world.insert_resource(Reshuffle { gone, bad });
    run_steps(&mut world, &mut physics, 1);
    assert!(world.get::<Rejected>(bad).is_some(), "refused");
    let pose = world.get::<Pose>(bad).unwrap();
    assert!(pose.translation.is_finite());
    assert!(
        (pose.translation.x - 3.0).abs() < 1e-3,
        "the bad body kept a state of its own, not the one saved for its new row: {pose:?}"
    );
}

/// A spring longer than the square root of the precision's largest number (1.8e19 m in `f32`)
/// has a finite length and force although its squared length overflows: the explicit step
/// pushes its bodies with it (it refused both, its force `NaN`), and the damper acts along it.
#[test]
fn a_spring_whose_squared_length_overflows_still_pulls() {
    let far = 2.0 * Real::MAX.sqrt();
    let spring = Spring::new(
        Entity::from_raw_u32(1).unwrap(),
        Vec3::ZERO,
        SpringEnd::World(Vec3::ZERO),
        1.0,
        0.0,
    );
    let d = Vec3::new(far, far, 0.0);
    assert_eq!(d.length_squared(), Real::INFINITY);
    let force = tumble_ecs::forces::spring_force(&spring, d);
    let expected = -d; // k = 1, L₀ = 0: −k |d| n = −d.
    assert!(force.is_finite(), "{force}");
    assert!(
        (force - expected).abs().max_element() <= 4.0 * Real::EPSILON * far,
        "{force} vs {expected}"
    );

    let mut world = world_with(1.0 / 60.0, Integrator::Splitting);
    world.resource_mut::<PhysicsSettings>().springs = SpringSolver::Explicit;
    let body = loaded_body_at;
    let (a, b) = (body(&mut world, 0.0), body(&mut world, far));
    world.spawn(
        Spring::new(a, Vec3::ZERO, SpringEnd::on_body(b, Vec3::ZERO), 1.0, 0.0).with_damping(0.1),
    );
    let mut physics = PhysicsRunner::new(&mut world);
    run_steps(&mut world, &mut physics, 2);
    for (end, sign) in [(a, 1.0), (b, -1.0)] {
        if let Some(r) = world.get::<Rejected>(end) {
            panic!("refused: {}", r.0);
        }
        let v = world.get::<Velocity>(end).unwrap().linear;
        assert!(v.is_finite() && sign * v.x > 0.0, "pulled together: {v}");
    }
}
