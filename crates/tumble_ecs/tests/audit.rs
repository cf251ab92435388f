//! The energy audit: divergence is caught while the state is still finite, the quarantined
//! bodies keep the last state that passed, and honest physics (stable springs near the limit,
//! work done by gravity, forces, torques and game code) is never flagged.

mod common;

use bevy_ecs::prelude::*;
use tumble_core::Integrator;
use tumble_core::math::{Quat, Real, Vec3};
use tumble_ecs::prelude::*;

const DT: Real = 1.0 / 60.0;

/// Principal moments of an asymmetric unit body.
const ASYMMETRIC: Vec3 = Vec3::new(1.0, 2.0, 3.0);

fn world(integrator: Integrator) -> World {
    let mut world = World::new();
    // The audit watches the explicit spring step (the implicit one conserves energy by
    // construction and would take these stiff chains by default).
    world.insert_resource(
        PhysicsSettings::new(DT, integrator)
            .unwrap()
            .with_springs(SpringSolver::Explicit),
    );
    world.insert_resource(Parallelism::SINGLE_THREAD);
    world
}

/// [`world`] with the energy audited at every step.
fn audited_world(integrator: Integrator) -> World {
    let mut world = world(integrator);
    world.insert_resource(EnergyAudit::Always);
    world
}

/// A unit body at rest on the x axis at `x`, turned by `0.3 x` about z, spinning at `omega`.
fn body(world: &mut World, x: Real, inertia: Vec3, omega: Vec3) -> Entity {
    common::unit_body(
        world,
        Vec3::new(x, 0.0, 0.0),
        Quat::from_rotation_z(0.3 * x),
        inertia,
        Vec3::ZERO,
        omega,
    )
}

/// A chain of `n` asymmetric bodies joined by springs at off-centre anchors, the first one tied
/// to the world; stiffness chosen so that the nominal `√(k/μ)Δt` of a body-body spring is
/// `omega_dt`. Returns the bodies.
fn chain(world: &mut World, n: usize, x0: Real, omega_dt: Real) -> Vec<Entity> {
    // μ = ½ for two unit masses.
    let k = 0.5 * (omega_dt / DT).powi(2);
    let inertia = Vec3::new(0.02, 0.03, 0.04);
    let bodies: Vec<Entity> = (0..n)
        .map(|i| body(world, x0 + i as Real, inertia, Vec3::new(0.1, 0.2, 0.3)))
        .collect();
    let wall = Vec3::new(x0 - 1.0, 0.1, 0.0);
    common::tie_chain(world, &bodies, wall, k, (Vec3::new(-0.1, 0.0, 0.05), 0.7));
    bodies
}

fn run(world: &mut World, steps: usize) {
    let mut physics = PhysicsRunner::new(world);
    for _ in 0..steps {
        physics.step(world);
        world.clear_trackers();
    }
}

fn errors(world: &World) -> Vec<BodyError> {
    world
        .get_resource::<PhysicsErrors>()
        .map(|e| e.bodies.clone())
        .unwrap_or_default()
}

#[test]
fn an_unstable_spring_chain_is_quarantined_before_its_state_is_garbage() {
    let mut w = world(Integrator::Splitting);
    let bodies = chain(&mut w, 4, 0.0, 2.5);
    let mut physics = PhysicsRunner::new(&mut w);
    let bits = |w: &World, b: Entity| {
        let (t, v) = (w.get::<Pose>(b).unwrap(), w.get::<Velocity>(b).unwrap());
        let mut out = Vec::new();
        for x in [t.translation, v.linear, v.angular] {
            out.extend(x.to_array().map(Real::to_bits));
        }
        out.extend(t.rotation.to_array().map(Real::to_bits));
        out
    };
    let mut quarantined_at = None;
    for step in 0..600 {
        let before: Vec<_> = bodies.iter().map(|&b| bits(&w, b)).collect();
        physics.step(&mut w);
        w.clear_trackers();
        if !errors(&w).is_empty() {
            // The step that created the energy is undone: every body of the group holds its
            // state from before that step, bit for bit.
            let after: Vec<_> = bodies.iter().map(|&b| bits(&w, b)).collect();
            assert_eq!(
                after, before,
                "step {step}: the kept state is the pre-step one"
            );
            quarantined_at = Some(step);
            break;
        }
    }
    assert!(quarantined_at.is_some(), "a spring at ωΔt = 2.5 diverges");
    let errors = errors(&w);
    assert!(
        errors
            .iter()
            .all(|e| matches!(e.kind, BodyErrorKind::EnergyGrew { .. })),
        "{errors:?}"
    );
    for &b in &bodies {
        assert!(
            w.get::<Rejected>(b).is_some(),
            "the whole group is quarantined"
        );
    }
    // Quarantined bodies are never stepped again.
    let kept: Vec<_> = bodies.iter().map(|&b| bits(&w, b)).collect();
    for _ in 0..10 {
        physics.step(&mut w);
        w.clear_trackers();
    }
    let later: Vec<_> = bodies.iter().map(|&b| bits(&w, b)).collect();
    assert_eq!(later, kept);
}

#[test]
fn stable_springs_near_the_limit_and_soft_chains_are_never_flagged() {
    for omega_dt in [0.5, 1.0, 1.9] {
        let mut w = world(Integrator::Splitting);
        // One world-anchored body: its spring's ωΔt is exactly the nominal one (μ = m).
        let b = body(&mut w, 0.0, Vec3::ONE, Vec3::ZERO);
        let (wall, k) = (
            SpringEnd::World(Vec3::new(-1.0, 0.0, 0.0)),
            (omega_dt / DT).powi(2),
        );
        w.spawn(Spring::new(b, Vec3::ZERO, wall, k, 0.5));
        run(&mut w, 10_000);
        assert!(errors(&w).is_empty(), "ωΔt = {omega_dt}: {:?}", errors(&w));
    }
    let mut w = world(Integrator::Splitting);
    chain(&mut w, 10, 0.0, 0.5);
    run(&mut w, 10_000);
    assert!(errors(&w).is_empty(), "{:?}", errors(&w));
}

#[derive(Component)]
struct Thruster;

/// Game code's own force system, inside `PhysicsSet::Forces`: positive work every step.
fn thrust(mut bodies: Query<&mut ForceAccumulator, With<Thruster>>) {
    for mut acc in &mut bodies {
        acc.add_force(Vec3::new(3.0, 0.0, 0.0));
        acc.add_torque(Vec3::new(0.0, 0.0, 0.2));
    }
}

#[test]
fn work_of_gravity_forces_torques_and_game_code_is_credited() {
    for integrator in [
        Integrator::Splitting,
        Integrator::SymplecticEuler,
        Integrator::Yoshida4,
    ] {
        let mut w = audited_world(integrator);
        w.insert_resource(Gravity(Vec3::new(0.0, -9.81, 0.0)));
        let a = body(&mut w, 0.0, ASYMMETRIC, Vec3::new(0.0, 0.0, 2.0));
        let b = body(&mut w, 1.0, ASYMMETRIC, Vec3::ZERO);
        let free = body(&mut w, 5.0, Vec3::ONE, Vec3::ZERO);
        w.entity_mut(a).insert(Thruster);
        let end = SpringEnd::on_body(b, Vec3::ZERO);
        w.spawn(Spring::new(a, Vec3::new(0.2, 0.0, 0.0), end, 50.0, 1.0).with_damping(0.5));
        w.spawn(ConstantForce {
            body: b,
            force: Vec3::new(0.0, 12.0, 1.0),
            local_point: Some(Vec3::new(0.0, 0.1, 0.2)),
        });
        w.spawn(ConstantTorque {
            body: b,
            torque: Vec3::new(0.1, 0.0, 0.0),
        });
        let mut forces = ForceSystems::default();
        forces.add(thrust);
        w.insert_resource(forces);
        let mut physics = PhysicsRunner::new(&mut w);
        for step in 0..3000 {
            // Game code kicks a body between steps, and adds a force before one.
            if step % 500 == 0 {
                w.get_mut::<Velocity>(free).unwrap().linear += Vec3::new(0.0, 30.0, 0.0);
                w.entity_mut(free).insert(ForceAccumulator {
                    force: Vec3::new(100.0, 0.0, 0.0),
                    torque: Vec3::new(0.0, 5.0, 0.0),
                });
            }
            physics.step(&mut w);
            w.clear_trackers();
        }
        assert!(errors(&w).is_empty(), "{integrator}: {:?}", errors(&w));
        let v = w.get::<Velocity>(a).unwrap().linear;
        assert!(v.x > 50.0, "the thruster did work: {v:?}");
    }
}

/// A body at rest on its spring's world anchor (the spring relaxed: the group holds nothing)
/// that a load sets moving is never flagged: the first step's error in the energy the load
/// gives it is no creation. It was quarantined at the first step (and every corner of the
/// bundled cloth with two substeps), the bound being relative to the energy at the start
/// alone. Every integrator, one and two substeps, gravity or a constant force, soft and stiff
/// springs.
#[test]
fn a_group_at_rest_that_a_load_sets_moving_is_never_flagged() {
    for &integrator in Integrator::ALL {
        for substeps in [1, 2] {
            // Up to ωΔt 1.2: inside the stable region of every method (the fourth-order
            // compositions' is the narrowest, ωΔt < 1.57).
            for (gravity, omega_dt) in [(true, 0.05), (false, 0.05), (true, 1.2), (false, 1.2)] {
                let case =
                    format!("{integrator}, {substeps} substeps, gravity {gravity}, ωΔt {omega_dt}");
                let mut w = audited_world(integrator);
                w.resource_mut::<PhysicsSettings>()
                    .set_substeps(std::num::NonZeroU32::new(substeps).unwrap())
                    .unwrap();
                let a = body(&mut w, 0.0, Vec3::ONE, Vec3::ZERO);
                let k = (omega_dt / DT).powi(2);
                w.spawn(Spring::new(
                    a,
                    Vec3::ZERO,
                    SpringEnd::World(Vec3::ZERO),
                    k,
                    0.0,
                ));
                if gravity {
                    w.insert_resource(Gravity(Vec3::new(0.0, -9.81, 0.0)));
                } else {
                    w.spawn(ConstantForce {
                        body: a,
                        force: Vec3::new(0.0, -10.0, 3.0),
                        local_point: None,
                    });
                }
                run(&mut w, 300);
                assert!(errors(&w).is_empty(), "{case}: {:?}", errors(&w));
            }
        }
    }
}

#[test]
fn an_exploding_explicit_spin_is_caught_before_it_is_non_finite() {
    let mut w = audited_world(Integrator::SymplecticEuler);
    let spinning = body(&mut w, 0.0, ASYMMETRIC, Vec3::new(0.5, 20.0, 0.5));
    run(&mut w, 2000);
    let errors = errors(&w);
    assert_eq!(errors.len(), 1, "{errors:?}");
    assert!(matches!(errors[0].kind, BodyErrorKind::EnergyGrew { .. }));
    let omega = w.get::<Velocity>(spinning).unwrap().angular;
    assert!(omega.length() < 100.0, "kept a sane state: {omega:?}");
}

#[test]
fn a_diverging_group_harms_no_other_body() {
    let stepped = |with_stiff: bool| {
        let mut w = world(Integrator::Splitting);
        let soft = chain(&mut w, 3, 0.0, 0.4);
        if with_stiff {
            chain(&mut w, 3, 50.0, 3.0);
        }
        run(&mut w, 800);
        let rejected = w.query::<&Rejected>().iter(&w).count();
        let poses: Vec<Pose> = soft.iter().map(|&e| *w.get::<Pose>(e).unwrap()).collect();
        (rejected, poses)
    };
    let (none, alone) = stepped(false);
    let (three, beside) = stepped(true);
    assert_eq!((none, three), (0, 3));
    assert_eq!(alone, beside, "bit-identical next to a quarantined group");
}

#[test]
fn the_audit_is_planned_only_where_energy_can_blow_up() {
    let plan = |integrator, springs: bool, mode: Option<EnergyAudit>| {
        let mut w = world(integrator);
        if let Some(mode) = mode {
            w.insert_resource(mode);
        }
        if springs {
            chain(&mut w, 2, 0.0, 0.5);
        } else {
            body(&mut w, 0.0, ASYMMETRIC, Vec3::Y);
        }
        PhysicsPlan::for_world(&mut w).contains(PhysicsSystem::AuditEnergy)
    };
    assert!(
        !plan(Integrator::Splitting, false, None),
        "free bodies, bounded method"
    );
    assert!(plan(Integrator::Splitting, true, None), "springs");
    assert!(
        !plan(Integrator::SymplecticEuler, false, None),
        "predicted, not audited"
    );
    assert!(!plan(Integrator::Splitting, true, Some(EnergyAudit::Never)));
    assert!(plan(
        Integrator::Splitting,
        false,
        Some(EnergyAudit::Always)
    ));
}

/// The audit finds bodies by entity index in a table it keeps between steps: despawned bodies
/// (whose indices the allocator may hand out again), new bodies, and springs still pointing at
/// the dead entities must neither confuse the groups nor the balance.
#[test]
fn despawned_and_new_bodies_keep_the_groups_right() {
    let stepped = |churn: bool| {
        let mut w = audited_world(Integrator::Splitting);
        // `gone` first: once it is despawned, the kept bodies take its places in the audit's
        // order, where the springs left pointing at its dead entities must not find them.
        let gone = chain(&mut w, 3, 20.0, 0.5);
        let kept = chain(&mut w, 4, 0.0, 0.5);
        let mut physics = PhysicsRunner::new(&mut w);
        let mut step = |w: &mut World| {
            physics.step(w);
            w.clear_trackers();
        };
        for _ in 0..30 {
            step(&mut w);
        }
        let mut unstable = Vec::new();
        if churn {
            // The springs of `gone` stay, pointing at dead entities.
            for &e in &gone {
                w.despawn(e);
            }
            unstable = chain(&mut w, 3, 40.0, 3.0);
        }
        for _ in 0..600 {
            step(&mut w);
        }
        let poses: Vec<Pose> = kept.iter().map(|&e| *w.get::<Pose>(e).unwrap()).collect();
        let quarantined: Vec<bool> = unstable
            .iter()
            .map(|&e| w.get::<Rejected>(e).is_some())
            .collect();
        (poses, quarantined, errors(&w))
    };
    let (alone, _, quiet) = stepped(false);
    let (churned, quarantined, errors) = stepped(true);
    assert!(quiet.is_empty(), "{quiet:?}");
    assert_eq!(
        quarantined, [true; 3],
        "the new unstable chain is caught: {errors:?}"
    );
    assert!(
        errors
            .iter()
            .all(|e| matches!(e.kind, BodyErrorKind::EnergyGrew { .. })),
        "{errors:?}"
    );
    assert_eq!(
        alone, churned,
        "the kept chain steps bit for bit as without the churn"
    );
}

/// The audit's sums over a group follow entity order, not the order its queries visit tables
/// in: a chain whose bodies and springs game code has spread over several tables (components
/// of its own) keeps the same account, bit for bit, as the same chain in one table each; and
/// so does either with the audit's passes split over the thread pool (each body a run of its
/// own), table by table where the tables are in entity order, by entity where they are not.
#[test]
fn the_account_does_not_depend_on_the_tables_bodies_sit_in() {
    #[derive(Component)]
    struct Tag<const N: usize>;
    let account = |spread: bool, threaded: bool| {
        let mut world = audited_world(Integrator::Splitting);
        if threaded {
            world.insert_resource(Parallelism {
                enabled: true,
                min_bodies: 0,
                min_batch: 1,
            });
        }
        let bodies = chain(&mut world, 9, 0.0, 0.5);
        if spread {
            for (k, &b) in bodies.iter().enumerate() {
                match k % 3 {
                    0 => {}
                    1 => {
                        world.entity_mut(b).insert(Tag::<1>);
                    }
                    _ => {
                        world.entity_mut(b).insert(Tag::<2>);
                    }
                }
            }
            let springs: Vec<Entity> = world
                .query_filtered::<Entity, With<Spring>>()
                .iter(&world)
                .collect();
            for &s in springs.iter().skip(1).step_by(2) {
                world.entity_mut(s).insert(Tag::<3>);
            }
        }
        run(&mut world, 300);
        assert!(errors(&world).is_empty(), "{:?}", errors(&world));
        let accounts = world
            .resource::<tumble_ecs::audit::EnergyLedger>()
            .saved_accounts();
        let created = accounts
            .iter()
            .find(|a| a.members == bodies.len())
            .unwrap_or_else(|| panic!("the chain's account: {accounts:?}"))
            .created;
        assert_ne!(
            created, 0.0,
            "an account that never moved would show nothing"
        );
        created.to_bits()
    };
    let alone = account(false, false);
    assert_eq!(alone, account(true, false));
    assert_eq!(alone, account(false, true));
    assert_eq!(alone, account(true, true));
}

#[derive(Component)]
struct Breaks;

/// Game code that breaks a body's rotation inside the force stage, after the stage's first
/// half drift: the integrate system refuses the body in the stage's last phase.
fn break_rotation(mut bodies: Query<&mut Pose, With<Breaks>>) {
    for mut pose in &mut bodies {
        pose.rotation *= 2.0;
    }
}

/// A body refused in a step's last stage keeps its state (the broken one game code left); the
/// audit must not judge its group's energy across the refusal and quarantine the partner (it
/// did: the refusal is a deferred command, so the audit's end pass still saw the body, with the
/// energy of its broken rotation). One stage a step (`splitting`, `symplectic-euler`, and
/// `splitting` with the spring solved implicitly, whose step leaves the body out of its group)
/// and three (`yoshida4`, whose first stage refuses).
#[test]
fn a_body_refused_in_the_last_stage_does_not_quarantine_its_partner() {
    for (integrator, springs) in [
        (Integrator::Splitting, SpringSolver::Explicit),
        (Integrator::SymplecticEuler, SpringSolver::Explicit),
        (Integrator::Yoshida4, SpringSolver::Explicit),
        (Integrator::Splitting, SpringSolver::Implicit),
    ] {
        let mut w = audited_world(integrator);
        let settings = w.resource::<PhysicsSettings>().with_springs(springs);
        w.insert_resource(settings);
        let a = body(&mut w, 0.0, ASYMMETRIC, Vec3::new(0.3, 1.0, 0.2));
        let b = body(&mut w, 1.0, ASYMMETRIC, Vec3::new(0.0, 0.5, 0.0));
        let end = SpringEnd::on_body(b, Vec3::new(0.0, 0.1, 0.0));
        w.spawn(Spring::new(a, Vec3::new(0.2, 0.0, 0.0), end, 50.0, 0.5));
        let mut forces = ForceSystems::default();
        forces.add(break_rotation);
        w.insert_resource(forces);
        let mut physics = PhysicsRunner::new(&mut w);
        for step in 0..20 {
            if step == 10 {
                w.entity_mut(a).insert(Breaks);
            }
            physics.step(&mut w);
            w.clear_trackers();
        }
        let refused = w.get::<Rejected>(a).expect("the broken body is refused");
        assert!(
            matches!(
                refused.0.kind,
                BodyErrorKind::Invalid {
                    component: "Pose",
                    ..
                }
            ),
            "{integrator}: {}",
            refused.0
        );
        if let Some(r) = w.get::<Rejected>(b) {
            panic!("{integrator}: the partner was refused: {}", r.0);
        }
        assert_eq!(errors(&w).len(), 1, "{integrator}: {:?}", errors(&w));
    }
}
