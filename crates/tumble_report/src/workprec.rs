//! Work–precision: error at a fixed horizon against run time per body-step.

use std::time::Instant;
use tumble_core::math::{Real, Widen, to_f64};

use serde::Serialize;
use tumble_core::invariants::{angular_momentum, kinetic_energy};
use tumble_core::rotation::angle_between;
use tumble_core::{BodyState, Integrator};
use tumble_rapier::{ComparisonBody, ComparisonScene, RapierScene};

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
    /// Wall time per body-step (ns), best of the repetitions.
    pub ns_per_body_step: f64,
    /// False when the run produced a non-finite state.
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

fn tumble_run(
    case: &Case,
    integrator: Integrator,
    dt: Real,
    steps: usize,
    batch: usize,
) -> (BodyState, f64) {
    let mut states = vec![case.initial; batch];
    let start = Instant::now();
    // A load that does not depend on the state is applied the way the ECS applies gravity to a
    // body without an accumulator (one whole step); a state-dependent one is sampled where the
    // method wants it, as the force systems do.
    if let Load::Free | Load::Gravity(_) = case.load {
        let wrench = case.load.wrench(&case.initial, &case.mass);
        for _ in 0..steps {
            for s in &mut states {
                integrator.step(s, &case.mass, &wrench, dt);
            }
        }
    } else {
        for _ in 0..steps {
            for s in &mut states {
                integrator.step_with(s, &case.mass, dt, |s| case.load.wrench(s, &case.mass));
            }
        }
    }
    (states[0], start.elapsed().as_nanos() as f64)
}

fn rapier_run(case: &Case, dt: Real, steps: usize, batch: usize) -> (BodyState, f64) {
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
    let scene = ComparisonScene::new(dt, gravity, vec![body; batch]);
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
