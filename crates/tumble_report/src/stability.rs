//! The stability matrix: extreme scenes × integrator × setting, run through the ECS schedule a
//! game would run, with tumble's stability prediction checked against what happened.

use bevy_ecs::prelude::*;
use tumble_core::math::{Quat, Real, Vec3, to_f64};

use serde::Serialize;
use tumble_core::invariants::kinetic_energy;
use tumble_core::{Integrator, Mass, MassProperties};
use tumble_ecs::components::body_state;
use tumble_ecs::prelude::*;
use tumble_rapier::TumbleScene;

/// One cell of the matrix.
#[derive(Debug, Clone, Serialize)]
pub struct Cell {
    /// Scene name.
    pub scene: String,
    /// Integrator name.
    pub integrator: String,
    /// Spring step (`PhysicsSettings::springs`: `auto`, `explicit`), `—` without springs.
    pub springs: String,
    /// The swept setting, e.g. `"|ω|Δt = 5"`.
    pub setting: String,
    /// Every body stayed finite and was never quarantined.
    pub finite: bool,
    /// Largest `||q| − 1|` over the run.
    pub max_quaternion_error: f64,
    /// Final / initial total energy, kinetic plus spring potential plus gravity potential (NaN
    /// when not finite).
    pub energy_ratio: f64,
    /// Smallest and largest `E/E₀` over the run, checked after every step (NaN when not
    /// finite).
    pub energy_range: [f64; 2],
    /// tumble's planning-time stability prediction warned.
    pub warned: bool,
    /// The step refuses the setting (a first-order method on a stiff spring group, which it
    /// cannot combine with the implicit spring step): not run.
    pub refused: bool,
}

impl Cell {
    /// Stable: finite, unit quaternions, energy bounded within a factor of 100 either way.
    ///
    /// A symplectic method's energy oscillates rather than drifts, with an amplitude that grows
    /// near the edge of its stable region (for a spring at `ωΔt = h`, up to
    /// `(1 + h/2)/(1 − h/2)`: 79 at `h = 1.95`), so a tight band would call stable runs unstable;
    /// an unstable run leaves any fixed band exponentially (or, exactly at the edge, as `n²`).
    pub fn stable(&self) -> bool {
        self.finite && self.max_quaternion_error < 1e-5 && (1e-2..1e2).contains(&self.energy_ratio)
    }

    /// The verdict on the total energy, for scenes whose energy is conserved by the physics:
    ///
    /// - `right`: stable, and `E/E₀` within `1 ± 5 %` after every step;
    /// - `dissipative`: stable, never above `1.05 E₀`, but more than 5 % lost (numerical
    ///   damping);
    /// - `bounded`: stable (a method near the edge of its stable region swings by up to ×100 and
    ///   comes back), but more than 5 % gained at some step;
    /// - `unstable`: not [`stable`](Self::stable);
    /// - `refused`: the step refuses the setting (see [`Cell::refused`]).
    pub fn verdict(&self) -> &'static str {
        let [low, high] = self.energy_range;
        if self.refused {
            "refused"
        } else if !self.stable() {
            "unstable"
        } else if high <= 1.0 + ENERGY_BAND && low >= 1.0 - ENERGY_BAND {
            "right"
        } else if high <= 1.0 + ENERGY_BAND {
            "dissipative"
        } else {
            "bounded"
        }
    }
}

/// Largest relative change of the total energy a run may show and still be called `right`.
pub const ENERGY_BAND: f64 = 0.05;

fn sphere(m: Real) -> MassProps {
    MassProps(MassProperties::solid_sphere(Mass::new(m).expect("valid"), 0.1).expect("valid"))
}

fn run(
    world: &mut World,
    steps: usize,
    name: &str,
    integrator: Integrator,
    setting: String,
) -> Cell {
    let warnings = check_stability(world);
    let warned = warnings.iter().any(|w| w.is_instability());
    let refused = warnings
        .iter()
        .any(|w| matches!(w, StabilityWarning::CannotCombine { .. }));
    let springs = if world.query::<&Spring>().iter(world).next().is_some() {
        world.resource::<PhysicsSettings>().springs.name()
    } else {
        "—"
    };
    let floor = gravity_floor(world);
    let e0 = total_energy(world, floor);
    let mut physics = PhysicsRunner::new(world);
    let mut max_q = 0.0_f64;
    let mut finite = !refused;
    let mut range = [1.0_f64, 1.0];
    for _ in 0..if refused { 0 } else { steps } {
        physics.step(world);
        world.clear_trackers();
        let mut q = world.query::<(&Pose, Option<&Rejected>)>();
        for (t, rejected) in q.iter(world) {
            max_q = max_q.max(to_f64((t.rotation.length() - 1.0).abs()));
            finite &= rejected.is_none() && t.translation.is_finite();
        }
        if !finite {
            break;
        }
        let ratio = total_energy(world, floor) / e0;
        range = [range[0].min(ratio), range[1].max(ratio)];
    }
    let e1 = total_energy(world, floor);
    Cell {
        scene: name.to_owned(),
        integrator: integrator.name().to_owned(),
        springs: springs.to_owned(),
        setting,
        finite,
        max_quaternion_error: max_q,
        energy_ratio: if finite { e1 / e0 } else { f64::NAN },
        energy_range: if finite { range } else { [f64::NAN; 2] },
        warned,
        refused,
    }
}

/// Kinetic energy of every body plus the potential `½ k (|d| − L₀)²` of every spring and the
/// gravity potential `m |g| (h − floor)`, `h` the height along `−g` (J).
fn total_energy(world: &mut World, floor: f64) -> f64 {
    let g = world.get_resource::<Gravity>().map_or(Vec3::ZERO, |g| g.0);
    let gravity: f64 = world
        .query_filtered::<(&Pose, &MassProps), With<RigidBody>>()
        .iter(world)
        .map(|(t, m)| {
            let height = -to_f64(g.dot(t.center_of_mass(m)));
            to_f64(m.mass()) * (height - floor * to_f64(g.length()))
        })
        .sum();
    gravity + elastic_and_kinetic(world)
}

/// The floor of the gravity potential: 1 m below the lowest centre of mass at the start, so a
/// falling scene starts with energy to lose and its `E/E₀` means something (the potential's zero
/// is arbitrary; with it at the bodies' own height `E₀` could be 0).
fn gravity_floor(world: &mut World) -> f64 {
    let Some(g) = world.get_resource::<Gravity>().map(|g| g.0) else {
        return 0.0;
    };
    let down = g.normalize_or_zero();
    world
        .query_filtered::<(&Pose, &MassProps), With<RigidBody>>()
        .iter(world)
        .map(|(t, m)| -to_f64(down.dot(t.center_of_mass(m))))
        .fold(f64::INFINITY, f64::min)
        - 1.0
}

/// Kinetic energy of every body plus the potential `½ k (|d| − L₀)²` of every spring (J).
fn elastic_and_kinetic(world: &mut World) -> f64 {
    let mut q = world.query_filtered::<(&Pose, &Velocity, &MassProps), With<RigidBody>>();
    let kinetic: f64 = q
        .iter(world)
        .map(|(t, v, m)| to_f64(kinetic_energy(&body_state(t, v, m), m)))
        .sum();
    let springs: Vec<Spring> = world.query::<&Spring>().iter(world).copied().collect();
    let mut poses = world.query::<&Pose>();
    let point = |poses: &mut QueryState<&Pose>, world: &World, e: Entity, p: Vec3| {
        poses
            .get(world, e)
            .map(|t| t.transform_point(p))
            .unwrap_or(Vec3::NAN)
    };
    let potential: f64 = springs
        .iter()
        .map(|s| {
            let a = point(&mut poses, world, s.a, s.anchor_a);
            let b = match s.b {
                SpringEnd::World(p) => p,
                SpringEnd::Body { body, anchor } => point(&mut poses, world, body, anchor),
            };
            let stretch = to_f64((a - b).length() - s.rest_length);
            0.5 * to_f64(s.stiffness) * stretch * stretch
        })
        .sum();
    kinetic + potential
}

fn world(dt: Real, integrator: Integrator) -> World {
    springs_world(dt, integrator, SpringSolver::Auto)
}

fn springs_world(dt: Real, integrator: Integrator, springs: SpringSolver) -> World {
    let mut w = World::new();
    w.insert_resource(
        PhysicsSettings::new(dt, integrator)
            .expect("valid dt")
            .with_springs(springs)
            .with_free_flow(FreeFlow::Method),
    );
    w
}

/// One body of principal moments `inertia` spinning at `|ω|Δt = omega_dt` about `axis`, at 60 Hz.
fn spinning(
    integrator: Integrator,
    scene: &str,
    inertia: Vec3,
    axis: Vec3,
    omega_dt: Real,
    steps: usize,
) -> Cell {
    let dt = 1.0 / 60.0;
    let mut w = world(dt, integrator);
    let mass = MassProperties::new(Mass::new(1.0).expect("valid"), inertia).expect("valid");
    w.spawn((
        RigidBody,
        MassProps(mass),
        Velocity::angular(axis.normalize() * omega_dt / dt),
    ));
    run(
        &mut w,
        steps,
        scene,
        integrator,
        format!("|ω|Δt = {omega_dt}"),
    )
}

/// Thin rod (I = (1e-4, 1, 1)) spinning at `|ω|Δt` about a tilted axis.
fn thin_rod(integrator: Integrator, omega_dt: Real, steps: usize) -> Cell {
    let rod = Vec3::new(1e-4, 1.0, 1.0);
    spinning(
        integrator,
        "thin-rod",
        rod,
        Vec3::new(0.3, 1.0, 0.2),
        omega_dt,
        steps,
    )
}

/// The thin asymmetric plate ([`crate::thin::PLATE`]) spinning at `|ω|Δt` about a tilted axis.
fn thin_plate(integrator: Integrator, omega_dt: Real, steps: usize) -> Cell {
    let axis = Vec3::new(0.3, 1.0, 0.5);
    spinning(
        integrator,
        "thin-plate",
        crate::thin::PLATE,
        axis,
        omega_dt,
        steps,
    )
}

/// A mass on a stiff spring to a world anchor, √(k/m)Δt = `omega_dt`.
fn stiff_spring(
    integrator: Integrator,
    springs: SpringSolver,
    omega_dt: Real,
    steps: usize,
) -> Cell {
    let (dt, m) = (1.0 / 60.0 as Real, 1.0 as Real);
    let mut w = springs_world(dt, integrator, springs);
    let body = w
        .spawn((RigidBody, sphere(m), Pose::from_translation(Vec3::X)))
        .id();
    let k = m * (omega_dt / dt).powi(2);
    w.spawn(Spring::new(
        body,
        Vec3::ZERO,
        SpringEnd::World(Vec3::ZERO),
        k,
        0.0,
    ));
    run(
        &mut w,
        steps,
        "stiff-spring",
        integrator,
        format!("√(k/m)Δt = {omega_dt}"),
    )
}

/// 1e9 kg and 1 kg on a spring with √(k/m_light)Δt = 1.
fn mass_ratio(integrator: Integrator, dt: Real, steps: usize) -> Cell {
    let mut w = world(dt, integrator);
    let heavy = w.spawn((RigidBody, sphere(1e9))).id();
    let light = w
        .spawn((
            RigidBody,
            sphere(1.0),
            // Stretched by half the rest length: the spring never passes through zero length,
            // where the force of `½k(|d| − L₀)²` flips direction.
            Pose::from_translation(Vec3::new(1.5, 0.0, 0.0)),
        ))
        .id();
    let k = (1.0 / dt).powi(2);
    let end = SpringEnd::on_body(heavy, Vec3::ZERO);
    w.spawn(Spring::new(light, Vec3::ZERO, end, k, 1.0));
    run(
        &mut w,
        steps,
        "mass-ratio-1e9",
        integrator,
        format!("Δt = 1/{:.0}", 1.0 / dt),
    )
}

/// A tumbling asymmetric body 1e5 m from the origin.
fn far_away(integrator: Integrator, dt: Real, steps: usize) -> Cell {
    let mut w = world(dt, integrator);
    let mass = MassProperties::new(Mass::new(1.0).expect("valid"), Vec3::new(1.0, 2.0, 3.0))
        .expect("valid");
    w.spawn((
        RigidBody,
        MassProps(mass),
        Pose {
            translation: Vec3::splat(1e5),
            rotation: Quat::from_rotation_x(0.4),
        },
        Velocity {
            linear: Vec3::new(0.5, 0.0, 0.0),
            angular: Vec3::new(0.2, 2.0, 0.2),
        },
    ));
    run(
        &mut w,
        steps,
        "far-1e5-m",
        integrator,
        format!("Δt = 1/{:.0}", 1.0 / dt),
    )
}

/// A tumbling asymmetric body for a long run.
fn long_run(integrator: Integrator, steps: usize) -> Cell {
    let mut w = world(1.0 / 60.0, integrator);
    let mass = MassProperties::new(Mass::new(1.0).expect("valid"), Vec3::new(0.2, 1.0, 1.1))
        .expect("valid");
    w.spawn((
        RigidBody,
        MassProps(mass),
        Velocity::angular(Vec3::new(1.5, 0.3, -0.5)),
    ));
    run(
        &mut w,
        steps,
        "long-run",
        integrator,
        format!("{steps} steps"),
    )
}

/// Every cell of the matrix. `quick` shortens the runs (1e5 instead of 1e6 steps for the long
/// run, 2000 instead of 20000 for the others).
pub fn matrix(quick: bool, mut progress: impl FnMut()) -> Vec<Cell> {
    let steps = if quick { 2_000 } else { 20_000 };
    let long = if quick { 100_000 } else { 1_000_000 };
    let mut cells = Vec::new();
    for &integrator in Integrator::ALL {
        for omega_dt in [0.1, 1.0, 5.0, 10.0] {
            cells.push(thin_rod(integrator, omega_dt, steps));
        }
        for omega_dt in crate::thin::OMEGA_DTS {
            cells.push(thin_plate(integrator, omega_dt, steps));
        }
        for springs in [SpringSolver::Explicit, SpringSolver::Auto] {
            for omega_dt in [0.5, 1.0, 1.5, 2.0, 2.5, 10.0, 100.0] {
                cells.push(stiff_spring(integrator, springs, omega_dt, steps));
            }
        }
        for dt in [1.0 / 30.0, 1.0 / 60.0, 1.0 / 240.0] {
            cells.push(mass_ratio(integrator, dt, steps));
            cells.push(far_away(integrator, dt, steps));
        }
        cells.push(long_run(integrator, long));
        progress();
    }
    // Spring networks with the default integrator: the spring step is what differs.
    let chain_steps = if quick { 300 } else { 3_000 };
    for springs in [SpringSolver::Explicit, SpringSolver::Auto] {
        for omega_dt in [0.5, 1.0, 2.0, 5.0, 10.0, 30.0, 100.0] {
            cells.push(stiff_chain(springs, omega_dt, chain_steps));
        }
        cells.push(cloth(springs, 10.0, if quick { 60 } else { 600 }));
    }
    cells
}

/// The report's stiff chain ([`tumble_rapier::presets::spring_chain`], stretched) with the default integrator and the
/// given spring step.
fn stiff_chain(springs: SpringSolver, omega_dt: Real, steps: usize) -> Cell {
    let integrator = Integrator::default();
    let chain = tumble_rapier::presets::spring_chain(
        omega_dt,
        tumble_rapier::presets::ChainStart::Stretched,
        1,
    );
    let mut scene = TumbleScene::with_free_flow(&chain, integrator, springs, FreeFlow::Method);
    run(
        scene.world_mut(),
        steps,
        "stiff-chain",
        integrator,
        format!("√(k/μ)Δt = {omega_dt}"),
    )
}

/// A 16 × 16 cloth of 10 g bodies joined to their neighbours, two corners held, falling under
/// gravity; `√(k/μ)Δt = omega_dt` for two neighbours.
fn cloth(springs: SpringSolver, omega_dt: Real, steps: usize) -> Cell {
    let (dt, n, spacing, m) = (1.0 / 60.0 as Real, 16, 0.1 as Real, 0.01 as Real);
    let integrator = Integrator::default();
    let mut w = springs_world(dt, integrator, springs);
    w.insert_resource(Gravity::EARTH_Y_DOWN);
    let k = 0.5 * m * (omega_dt / dt).powi(2);
    let mass = MassProperties::solid_sphere(Mass::new(m).expect("valid"), 0.02).expect("valid");
    let grid: Vec<Entity> = (0..n * n)
        .map(|c| {
            let (i, j) = ((c / n) as Real, (c % n) as Real);
            w.spawn((
                RigidBody,
                MassProps(mass),
                Pose::from_translation(Vec3::new(i * spacing, 0.0, j * spacing)),
            ))
            .id()
        })
        .collect();
    let mut link = |a: Entity, b: SpringEnd, rest: Real| {
        w.spawn(Spring::new(a, Vec3::ZERO, b, k, rest));
    };
    for i in 0..n {
        for j in 0..n {
            for (p, q) in [(i + 1, j), (i, j + 1)] {
                if p < n && q < n {
                    let end = SpringEnd::on_body(grid[p * n + q], Vec3::ZERO);
                    link(grid[i * n + j], end, spacing);
                }
            }
        }
    }
    for i in [0, n - 1] {
        let corner = Vec3::new(i as Real * spacing, 0.0, 0.0);
        link(grid[i * n], SpringEnd::World(corner), 0.0);
    }
    run(
        &mut w,
        steps,
        "cloth-16x16",
        integrator,
        format!("√(k/μ)Δt = {omega_dt}"),
    )
}
