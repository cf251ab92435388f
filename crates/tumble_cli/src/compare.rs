//! `tumble compare`: the scene in tumble and in rapier 0.36, side by side.

use glam::DQuat;
use tumble_core::exact::TorqueFreeTop;
use tumble_core::math::{Narrow, Quat, Real, Vec3, Widen, to_f64};
use tumble_core::{BodyState, Integrator};
use tumble_rapier::{ComparisonBody, ComparisonOptions, ComparisonScene, Load, compare};
use tumble_scene::text::terminal_safe;
use tumble_scene::{ForceDef, Scene};

use crate::exit::{self, Failure};

/// Builds the comparison and prints, per body, the largest difference to rapier and to the
/// exact solution where one exists, and the speed ratio.
///
/// A body that tumble quarantined, or whose state went non-finite in either engine, is named on
/// stderr and the command fails with [`exit::REJECTED`]: its differences are not a comparison.
pub fn run(scene: &Scene, integrator: Integrator, gyroscopic: bool) -> Result<(), Failure> {
    let states = scene.body_states();
    let mut bodies: Vec<ComparisonBody> = states
        .iter()
        .map(|s| {
            let mut b = ComparisonBody::new(s.name.clone(), s.mass, s.state);
            b.gravity_scale = s.gravity_scale;
            b.linear_damping = s.linear_damping;
            b.angular_damping = s.angular_damping;
            b
        })
        .collect();
    let index = |name: &str| states.iter().position(|s| s.name == name);
    for force in &scene.file().forces {
        match force {
            ForceDef::Constant { body, force, point } => {
                let i = index(body).ok_or_else(|| Failure::from("unknown body"))?;
                let f = glam::DVec3::from_array(*force).narrow();
                let p = point.map(|p| glam::DVec3::from_array(p).narrow());
                bodies[i].loads.push(Load::Force {
                    force: f,
                    local_point: p,
                });
            }
            ForceDef::Torque { body, torque } => {
                let i = index(body).ok_or_else(|| Failure::from("unknown body"))?;
                bodies[i]
                    .loads
                    .push(Load::Torque(glam::DVec3::from_array(*torque).narrow()));
            }
            ForceDef::Spring { .. } => {
                return Err(Failure::from(format!(
                    "scene `{}` has springs, which the rapier comparison does not model (rapier \
                     has no spring force generator); supported: free bodies, gravity, gravity \
                     scale, constant forces (at points) and torques, damping",
                    terminal_safe(scene.name())
                )));
            }
        }
    }
    let comparison = ComparisonScene {
        dt: scene.dt(),
        gravity: scene.gravity(),
        bodies,
    };
    // Exact solutions for bodies without loads or damping: the position is the parabola
    // x₀ + v₀t + ½ g s t²; the orientation is a steady rotation for a spherical body, or the
    // elliptic torque-free top for distinct moments (identity principal frame).
    let gravity = scene.gravity().unwrap_or(Vec3::ZERO).widen();
    let exact_for: Vec<Option<(Option<TorqueFreeTop>, bool)>> = comparison
        .bodies
        .iter()
        .map(|b| {
            let free = b.loads.is_empty() && b.linear_damping == 0.0 && b.angular_damping == 0.0;
            if !free {
                return None;
            }
            if b.mass.is_spherical() {
                return Some((None, true));
            }
            if b.mass.principal_frame() != Quat::IDENTITY {
                return None;
            }
            let w_body = b.state.rotation.inverse() * b.state.angular_velocity;
            TorqueFreeTop::new(
                b.mass.principal_inertia().widen(),
                w_body.widen(),
                b.state.rotation.widen(),
            )
            .ok()
            .map(|top| (Some(top), false))
        })
        .collect();
    let exact = |i: usize, t: f64| -> Option<BodyState> {
        let (top, spherical) = exact_for[i].as_ref()?;
        let b = &comparison.bodies[i];
        let q: DQuat = match top {
            Some(top) => top.orientation(t),
            None if *spherical => {
                DQuat::from_scaled_axis(b.state.angular_velocity.widen() * t)
                    * b.state.rotation.widen()
            }
            None => return None,
        };
        let x = b.state.position.widen()
            + b.state.linear_velocity.widen() * t
            + 0.5 * gravity * to_f64(b.gravity_scale) * t * t;
        Some(BodyState {
            position: x.narrow(),
            rotation: Quat::from_xyzw(q.x as Real, q.y as Real, q.z as Real, q.w as Real),
            ..Default::default()
        })
    };
    let options = ComparisonOptions {
        integrator,
        gyroscopic,
        rapier_solver_iterations: 4,
        steps: scene.steps().min(1_000_000) as usize,
    };
    let result = compare(&comparison, &options, Some(&exact));
    println!(
        "scene {} · tumble `{integrator}` vs rapier 0.36 (gyroscopic {}, 4 substeps) · {} steps of {} s",
        terminal_safe(scene.name()),
        if gyroscopic { "on" } else { "off" },
        options.steps,
        scene.dt()
    );
    println!(
        "{:<16} {:>11} {:>12} {:>11} {:>11} {:>21} {:>21}",
        "body",
        "Δx (m)",
        "Δangle (rad)",
        "Δv (m/s)",
        "Δω (rad/s)",
        "exact Δx tumble/rapier",
        "exact angle t/r"
    );
    let pair =
        |p: Option<(f64, f64)>| p.map_or("—".to_owned(), |(t, r)| format!("{t:.2e} / {r:.2e}"));
    for d in &result.bodies {
        println!(
            "{:<16} {:>11.3e} {:>12.3e} {:>11.3e} {:>11.3e} {:>21} {:>21}",
            d.name,
            d.position,
            d.angle,
            d.linear_velocity,
            d.angular_velocity,
            pair(d.exact_position),
            pair(d.exact_angle)
        );
    }
    println!(
        "time per step: tumble {:.0} ns, rapier {:.0} ns (rapier/tumble = {:.1})",
        result.tumble_ns_per_step,
        result.rapier_ns_per_step,
        result.speed_ratio()
    );
    let unclean: Vec<_> = result.bodies.iter().filter(|d| !d.is_clean()).collect();
    for d in &unclean {
        let name = terminal_safe(&d.name);
        if let Some(step) = d.tumble_rejected_at {
            tracing::error!(target: "tumble", "body `{name}`: tumble quarantined it at step {step}; its differences after that step compare a frozen state");
        }
        if let Some(step) = d.non_finite_at {
            tracing::error!(target: "tumble", "body `{name}`: a state went non-finite at step {step} (NaN in the table)");
        }
    }
    if !unclean.is_empty() {
        return Err(Failure::new(
            exit::REJECTED,
            format!(
                "{} of {} bodies did not run cleanly (named above); the comparison is not valid for them",
                unclean.len(),
                result.bodies.len()
            ),
        ));
    }
    Ok(())
}
