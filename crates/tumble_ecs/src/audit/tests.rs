//! The start of a step reuses the energies the last step ended with only where nothing changed:
//! a world that reuses them and one that measures every energy afresh keep the same accounts,
//! bit for bit, whatever game code changes between the steps.

use bevy_ecs::prelude::*;
use bevy_ecs::schedule::IntoScheduleConfigs;
use tumble_core::math::{Quat, Real, Vec3};

use super::EnergyLedger;
use crate::prelude::*;

const DT: Real = 1.0 / 60.0;

/// The bodies and springs game code changes.
struct Handles {
    chain: Vec<Entity>,
    free: Entity,
    post: Entity,
    springs: Vec<Entity>,
}

/// An audited spring world: a chain of five asymmetric bodies tied to the world and, at its
/// far end, to a static post; a free body; gravity.
fn spring_world(parallelism: Parallelism, integrator: Integrator) -> (World, Handles) {
    let mut world = World::new();
    world.insert_resource(
        PhysicsSettings::new(DT, integrator)
            .unwrap()
            .with_springs(SpringSolver::Explicit),
    );
    world.insert_resource(parallelism);
    world.insert_resource(EnergyAudit::Always);
    world.insert_resource(Gravity(Vec3::new(0.0, -9.81, 0.0)));
    let mass = |m: Real| {
        let inertia = Vec3::new(0.02, 0.03, 0.04) * m;
        MassProps(MassProperties::new(Mass::new(m).unwrap(), inertia).unwrap())
    };
    let spawn = |world: &mut World, x: Real, m: Real| {
        world
            .spawn((
                RigidBody,
                mass(m),
                Pose {
                    translation: Vec3::new(x, 0.0, 0.0),
                    rotation: Quat::from_rotation_z(0.3 * x),
                },
                Velocity {
                    linear: Vec3::ZERO,
                    angular: Vec3::new(0.1, 0.2, 0.3),
                },
            ))
            .id()
    };
    let bodies: Vec<Entity> = (0..5).map(|i| spawn(&mut world, i as Real, 1.0)).collect();
    let free = spawn(&mut world, 10.0, 2.0);
    let post = world
        .spawn((
            RigidBody,
            Static,
            mass(1.0),
            Pose {
                translation: Vec3::new(5.5, 0.5, 0.0),
                rotation: Quat::from_rotation_x(0.4),
            },
            Velocity::default(),
        ))
        .id();
    // ωΔt ≈ 0.5 for a body–body spring: stable but far from exact, so the integrator's energy
    // error, the account the audit keeps, is large enough for a stale start energy to show.
    let k = 0.5 * (0.5 / DT).powi(2);
    let mut springs = vec![
        world
            .spawn(Spring::new(
                bodies[0],
                Vec3::new(-0.1, 0.05, 0.0),
                SpringEnd::World(Vec3::new(-1.0, 0.1, 0.0)),
                k,
                0.8,
            ))
            .id(),
    ];
    for pair in bodies.windows(2) {
        let end = SpringEnd::on_body(pair[1], Vec3::new(-0.1, 0.0, 0.05));
        springs.push(
            world
                .spawn(Spring::new(pair[0], Vec3::new(0.1, 0.05, 0.0), end, k, 0.7))
                .id(),
        );
    }
    let end = SpringEnd::on_body(post, Vec3::new(0.0, -0.2, 0.1));
    springs.push(
        world
            .spawn(Spring::new(bodies[4], Vec3::ZERO, end, k, 1.4))
            .id(),
    );
    let handles = Handles {
        chain: bodies,
        free,
        post,
        springs,
    };
    (world, handles)
}

/// What game code does before step `step`: kicks, pushes, turns, re-weighs, retunes, moves the
/// static post, a change undone before the step (the same bits as before: nothing to measure
/// again), and changes of the spring graph: a spring removed, a body and a spring added, the
/// post made kinematic.
fn game_code(world: &mut World, step: usize, handles: &Handles) {
    let Handles {
        chain: bodies,
        free,
        post,
        springs,
    } = handles;
    let (free, post) = (*free, *post);
    match step {
        150 => {
            world.despawn(springs[1]);
        }
        250 => {
            let extra = world
                .spawn((
                    RigidBody,
                    *world.get::<MassProps>(free).unwrap(),
                    Pose {
                        translation: Vec3::new(11.0, 0.2, 0.0),
                        rotation: Quat::IDENTITY,
                    },
                    Velocity::default(),
                ))
                .id();
            let end = SpringEnd::on_body(free, Vec3::new(0.1, 0.0, 0.0));
            world.spawn(Spring::new(extra, Vec3::ZERO, end, 100.0, 0.8));
        }
        210 => {
            // The first spring cut and the last one doubled: as many springs as before, each
            // unwritten one one place earlier in entity order, and the new one, last, the same
            // as the last one was. (The empty entity takes the cut spring's index first.)
            world.despawn(springs[0]);
            world.spawn_empty();
            let last = *world.get::<Spring>(*springs.last().unwrap()).unwrap();
            world.spawn(last);
        }
        330 => {
            world.entity_mut(post).remove::<Static>().insert(Kinematic);
        }
        _ => {}
    }
    match step % 40 {
        5 => world.get_mut::<Pose>(post).unwrap().translation.z += 0.01,
        3 => world.get_mut::<Velocity>(bodies[2]).unwrap().linear += Vec3::new(0.0, 3.0, 0.0),
        7 => world.get_mut::<Velocity>(free).unwrap().angular *= 1.5,
        11 => world.get_mut::<Pose>(bodies[1]).unwrap().translation.x += 0.05,
        13 => {
            let mut t = world.get_mut::<Pose>(bodies[3]).unwrap();
            t.rotation = (t.rotation * Quat::from_rotation_y(0.2)).normalize();
        }
        17 => {
            let m = world.get::<MassProps>(bodies[0]).unwrap().0;
            // Heavier, the same moments: only the mass shows the change.
            let heavier =
                MassProperties::new(Mass::new(1.5 * m.mass()).unwrap(), m.principal_inertia())
                    .unwrap();
            world.entity_mut(bodies[0]).insert(MassProps(heavier));
        }
        19 => world.get_mut::<Spring>(springs[2]).unwrap().stiffness *= 0.5,
        23 => world.get_mut::<Spring>(springs[3]).unwrap().rest_length += 0.1,
        29 => world.get_mut::<Spring>(springs[5]).unwrap().anchor_a.y += 0.05,
        31 => {
            let mut v = world.get_mut::<Velocity>(bodies[4]).unwrap();
            let before = *v;
            v.linear.z += 1.0;
            *v = before;
        }
        37 => world.get_mut::<Pose>(bodies[4]).unwrap().translation.y -= 0.02,
        _ => {}
    }
}

/// Every body and spring measured on its own, by as many threads as the pool has.
const THREADED: Parallelism = Parallelism {
    enabled: true,
    min_bodies: 0,
    min_batch: 1,
};

#[test]
fn reused_start_energies_are_the_energies_measured_afresh() {
    compare_with_fresh(Parallelism::SINGLE_THREAD, Integrator::Splitting);
}

/// The same with the reusing world's audit passes (and its steps) split over the thread pool
/// (with the `parallel` feature), the fresh one on one thread: the accounts agree bit for bit.
#[test]
fn the_audit_gives_the_same_accounts_on_any_number_of_threads() {
    compare_with_fresh(THREADED, Integrator::Splitting);
}

/// The same in steps of three stages (`yoshida4`), whose loads the audit adds stage by stage.
#[test]
fn a_composed_step_gives_the_same_accounts_on_any_number_of_threads() {
    compare_with_fresh(THREADED, Integrator::Yoshida4);
}

fn compare_with_fresh(parallelism: Parallelism, integrator: Integrator) {
    let (mut reusing, handles) = spring_world(parallelism, integrator);
    let (mut fresh, _) = spring_world(Parallelism::SINGLE_THREAD, integrator);
    let (plan_r, plan_f) = (
        PhysicsPlan::for_world(&mut reusing),
        PhysicsPlan::for_world(&mut fresh),
    );
    let (mut schedule_r, mut schedule_f) = (plan_r.build_schedule(), plan_f.build_schedule());
    let mut quiet_steps_reused = 0;
    for step in 0..400 {
        game_code(&mut reusing, step, &handles);
        game_code(&mut fresh, step, &handles);
        let (restarts, partial) = {
            let ledger = reusing.resource::<EnergyLedger>();
            (ledger.restarts, ledger.partial_restarts)
        };
        fresh.resource_mut::<EnergyLedger>().forget_measurements();
        plan_r.run_step(&mut schedule_r, &mut reusing);
        plan_f.run_step(&mut schedule_f, &mut fresh);
        let ledger = reusing.resource::<EnergyLedger>();
        let accounts = ledger.saved_accounts();
        let fresh_accounts = fresh.resource::<EnergyLedger>().saved_accounts();
        assert_eq!(accounts.len(), fresh_accounts.len(), "step {step}");
        for (r, f) in accounts.iter().zip(fresh_accounts) {
            assert_eq!(
                r.created.to_bits(),
                f.created.to_bits(),
                "step {step}: {r:?} against {f:?}"
            );
        }
        if step > 0 && step % 40 == 0 {
            // No game code ran before this step: every body's energy was reused, and the
            // groups of the last step with them.
            assert!(ledger.bodies.iter().all(|b| b.still), "step {step}");
            assert_eq!(ledger.restarts, restarts + 1, "step {step}");
            quiet_steps_reused += 1;
        }
        // (Moving the post changes a spring's fixed end while it is static; a kinematic
        // post's group is not balanced, and its pose is nothing the audit measures.)
        let post_moved = step % 40 == 5 && step < 330;
        if matches!(step % 40, 3 | 11 | 17 | 19)
            || matches!(step, 150 | 210 | 250 | 330)
            || post_moved
        {
            assert_eq!(ledger.restarts, restarts, "step {step}: a change was seen");
        }
        // A kicked, pushed or turned body keeps the groups: only its energy is measured again
        // (and a velocity written back as it was: a write is a write, `memo`). A new mass,
        // spring or anchor regroups.
        if matches!(step % 40, 3 | 7 | 11 | 13 | 31 | 37) {
            assert_eq!(ledger.partial_restarts, partial + 1, "step {step}");
        }
        if matches!(step % 40, 17 | 19 | 23 | 29)
            || matches!(step, 150 | 210 | 250 | 330)
            || post_moved
        {
            assert_eq!(ledger.partial_restarts, partial, "step {step}: regrouped");
        }
        if step % 40 == 3 {
            let kicked = ledger.slot(handles.chain[2]).unwrap();
            assert!(
                !ledger.bodies[kicked].still,
                "step {step}: the kick was seen"
            );
        }
        reusing.clear_trackers();
        fresh.clear_trackers();
    }
    assert_eq!(quiet_steps_reused, 9);
    assert_eq!(fresh.resource::<EnergyLedger>().restarts, 0);
    assert!(
        reusing
            .get_resource::<PhysicsErrors>()
            .is_none_or(|e| e.is_empty()),
        "a stable chain is never flagged"
    );
    let created = reusing.resource::<EnergyLedger>().saved_accounts();
    assert!(
        created.iter().any(|a| a.created.abs() > 1e-6),
        "the accounts are not trivially zero: {created:?}"
    );
}

/// What [`rewrite_during_the_step`] changes in the next step it runs in.
#[derive(Resource, Default)]
struct MidStep {
    /// A spring to lengthen.
    spring: Option<Entity>,
    /// A body to make half as heavy (its springs then the stiffest of its group).
    body: Option<Entity>,
}

/// A force system that rewrites a spring and a body's mass in the middle of a step (after the
/// audit's start pass has resolved the springs and taken the masses, before its end pass),
/// once each time [`MidStep`] names them; exclusive, so that the mass is inserted at once.
fn rewrite_during_the_step(world: &mut World) {
    let MidStep { spring, body } = std::mem::take(&mut *world.resource_mut::<MidStep>());
    if let Some(spring) = spring {
        world.get_mut::<Spring>(spring).unwrap().rest_length += 0.1;
    }
    if let Some(body) = body {
        let m = world.get::<MassProps>(body).unwrap().0;
        let heavier =
            MassProperties::new(Mass::new(0.5 * m.mass()).unwrap(), m.principal_inertia()).unwrap();
        world.entity_mut(body).insert(MassProps(heavier));
    }
}

/// A spring or a mass a force system rewrites during a step is taken afresh at the next start
/// (its link resolved again, its group's stiffness bound from the new mass), as a world that
/// measures everything afresh takes it: the same accounts and bounds, step after step.
#[test]
fn springs_and_masses_rewritten_during_a_step_are_seen_at_the_next_start() {
    let (mut reusing, handles) = spring_world(Parallelism::SINGLE_THREAD, Integrator::Splitting);
    let (mut fresh, _) = spring_world(Parallelism::SINGLE_THREAD, Integrator::Splitting);
    let (plan_r, plan_f) = (
        PhysicsPlan::for_world(&mut reusing),
        PhysicsPlan::for_world(&mut fresh),
    );
    let (mut schedule_r, mut schedule_f) = (plan_r.build_schedule(), plan_f.build_schedule());
    for (world, schedule) in [
        (&mut reusing, &mut schedule_r),
        (&mut fresh, &mut schedule_f),
    ] {
        world.init_resource::<MidStep>();
        schedule.add_systems(rewrite_during_the_step.in_set(PhysicsSet::Forces));
    }
    for step in 0..120 {
        for world in [&mut reusing, &mut fresh] {
            let mut mid = world.resource_mut::<MidStep>();
            match step {
                20 | 60 => mid.spring = Some(handles.springs[3]),
                40 | 80 => mid.body = Some(handles.chain[2]),
                _ => {}
            }
        }
        fresh.resource_mut::<EnergyLedger>().forget_measurements();
        plan_r.run_step(&mut schedule_r, &mut reusing);
        plan_f.run_step(&mut schedule_f, &mut fresh);
        let (r, f) = (
            reusing.resource::<EnergyLedger>(),
            fresh.resource::<EnergyLedger>(),
        );
        let accounts = |l: &EnergyLedger| {
            let saved = l.saved_accounts();
            saved
                .iter()
                .map(|a| a.created.to_bits())
                .collect::<Vec<_>>()
        };
        assert_eq!(accounts(r), accounts(f), "step {step}");
        let bounds = |l: &EnergyLedger| {
            l.groups
                .iter()
                .map(|g| g.omega_dt.to_bits())
                .collect::<Vec<_>>()
        };
        assert_eq!(bounds(r), bounds(f), "step {step}");
        reusing.clear_trackers();
        fresh.clear_trackers();
    }
    assert!(
        reusing
            .get_resource::<PhysicsErrors>()
            .is_none_or(|e| e.is_empty()),
        "a stable chain is never flagged"
    );
}
