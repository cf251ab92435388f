//! Work–precision: error at a fixed horizon against run time per body-step.

use std::time::Instant;
use tumble_core::math::{Real, Vec3, Widen, to_f64};

use serde::Serialize;
use tumble_core::invariants::{angular_momentum, kinetic_energy};
use tumble_core::rotation::angle_between;
use tumble_core::{BodyState, Integrator};
use tumble_ecs::prelude::{FreeFlow, SpringSolver};
use tumble_rapier::{
    ComparisonBody, ComparisonScene, ComparisonSpring, ComparisonSpringEnd, RapierScene,
    TumbleScene,
};

use crate::reference::{Case, Load, to_quat};

/// The method of one row: a tumble integrator or rapier with its defaults.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Method {
    /// A tumble integrator.
    Tumble(Integrator),
    /// rapier 0.36 with its defaults (4 substeps, gyroscopic term on).
    Rapier,
}

impl Method {
    /// Display name.
    pub fn name(self) -> String {
        match self {
            Method::Tumble(i) => i.name().to_owned(),
            Method::Rapier => "rapier".to_owned(),
        }
    }

    /// Every tumble integrator, then rapier.
    pub fn all() -> Vec<Method> {
        Integrator::ALL
            .iter()
            .map(|&i| Method::Tumble(i))
            .chain([Method::Rapier])
            .collect()
    }
}

/// One measured point.
#[derive(Debug, Clone, Serialize)]
pub struct Point {
    /// Scene name.
    pub scene: String,
    /// Method name.
    pub method: String,
    /// Time step (s).
    pub dt_s: f64,
    /// Steps to the horizon.
    pub steps: usize,
    /// Orientation error at the horizon (rad).
    pub orientation_error_rad: f64,
    /// Position error of the centre of mass at the horizon (m).
    pub position_error_m: f64,
    /// |E(T)/E(0) − 1| of kinetic + potential energy.
    pub energy_drift: f64,
    /// | |L(T)|/|L(0)| − 1 | for torque-free scenes.
    pub momentum_drift: Option<f64>,
    /// Wall time per body-step (ns), best of the repetitions: tumble through the ECS with the
    /// batch's copies in one world (the path users run), rapier with them in one pipeline.
    pub ns_per_body_step: f64,
    /// False when the run produced a non-finite state (or tumble's ECS quarantined the body).
    pub finite: bool,
}

/// Measurement effort.
#[derive(Debug, Clone, Copy)]
pub struct Effort {
    /// Identical bodies stepped together (for timing).
    pub batch: usize,
    /// Timed repetitions; the fastest counts.
    pub repetitions: usize,
}

fn energy(case: &Case, s: &BodyState) -> f64 {
    to_f64(kinetic_energy(s, &case.mass)) + case.load.potential(s, &case.mass)
}

/// `batch` copies of the case's body at step `dt`, with its load as the ECS and rapier see it:
/// gravity as the world's, a force at a point as the body's load, and (for tumble; `springs`)
/// a spring from the centre of mass to the world origin.
pub(crate) fn comparison_scene(
    case: &Case,
    dt: Real,
    batch: usize,
    springs: bool,
) -> ComparisonScene {
    let mut body = ComparisonBody::new(case.name, case.mass, case.initial);
    let gravity = match case.load {
        Load::Gravity(g) => Some(g),
        Load::ForceAtPoint { force, point } => {
            body = body.with_load(tumble_rapier::Load::Force {
                force,
                local_point: Some(point),
            });
            None
        }
        Load::Free | Load::Spring(_) => None,
    };
    let mut scene = ComparisonScene::new(dt, gravity, vec![body; batch]);
    if let (Load::Spring(k), true) = (case.load, springs) {
        scene.springs = (0..batch)
            .map(|a| ComparisonSpring {
                a,
                anchor_a: case.mass.local_center_of_mass(),
                b: ComparisonSpringEnd::World(Vec3::ZERO),
                stiffness: k,
                damping: 0.0,
                rest_length: 0.0,
            })
            .collect();
    }
    scene
}

/// The case through the ECS, as users run it: `batch` copies in one world, stepped by the
/// batched systems (springs explicit, so that the row measures the integrator itself; the
/// stiff-spring section measures the implicit step).
fn tumble_run(
    case: &Case,
    integrator: Integrator,
    dt: Real,
    steps: usize,
    batch: usize,
) -> (BodyState, f64) {
    let scene = comparison_scene(case, dt, batch, true);
    let mut world =
        TumbleScene::with_free_flow(&scene, integrator, SpringSolver::Explicit, FreeFlow::Method);
    let start = Instant::now();
    for _ in 0..steps {
        world.step();
    }
    let elapsed = start.elapsed().as_nanos() as f64;
    // A body the ECS quarantined (it went non-finite, or its energy ran away) keeps its last
    // valid state: for the report it diverged.
    let state = if world.is_rejected(0) {
        BodyState {
            position: Vec3::NAN,
            ..world.state(0)
        }
    } else {
        world.state(0)
    };
    (state, elapsed)
}

fn rapier_run(case: &Case, dt: Real, steps: usize, batch: usize) -> (BodyState, f64) {
    let scene = comparison_scene(case, dt, batch, false);
    let mut world = RapierScene::new(&scene, true, 4);
    let start = Instant::now();
    for _ in 0..steps {
        world.step();
    }
    (world.state(0), start.elapsed().as_nanos() as f64)
}

/// Measures one (scene, method, Δt) point.
pub fn measure(case: &Case, method: Method, dt: f64, effort: Effort) -> Point {
    let steps = (case.horizon / dt).round() as usize;
    let dt32 = dt as Real;
    let mut best = f64::INFINITY;
    let mut last = case.initial;
    for _ in 0..effort.repetitions.max(1) {
        let (state, ns) = match method {
            Method::Tumble(i) => tumble_run(case, i, dt32, steps, effort.batch),
            Method::Rapier => rapier_run(case, dt32, steps, effort.batch),
        };
        best = best.min(ns / (steps * effort.batch) as f64);
        last = state;
    }
    let t = steps as f64 * to_f64(dt32);
    let (x, q) = (case.exact)(t);
    let finite = last.is_finite();
    let e0 = energy(case, &case.initial);
    let l0 = to_f64(angular_momentum(&case.initial, &case.mass).length());
    let momentum_drift = (case.load == Load::Free)
        .then(|| (to_f64(angular_momentum(&last, &case.mass).length()) / l0 - 1.0).abs());
    Point {
        scene: case.name.to_owned(),
        method: method.name(),
        dt_s: to_f64(dt32),
        steps,
        orientation_error_rad: angle_between(last.rotation, to_quat(q)),
        position_error_m: (last.position.widen() - x).length(),
        energy_drift: (energy(case, &last) / e0 - 1.0).abs(),
        momentum_drift,
        ns_per_body_step: best,
        finite,
    }
}

/// The error that matters for a scene: orientation for rotating scenes, position otherwise.
pub fn headline_error(p: &Point) -> f64 {
    if p.scene.starts_with("top") || p.scene == "dzhanibekov" {
        p.orientation_error_rad
    } else {
        p.position_error_m.max(p.orientation_error_rad)
    }
}

/// Run time to simulate the scene's horizon for one body (µs): the work of a work–precision plot.
pub(crate) fn work_us(p: &Point) -> f64 {
    p.ns_per_body_step * p.steps as f64 / 1e3
}
