//! `tumble compare`: the scene in tumble and in rapier 0.36, side by side.

use std::fmt::Write as _;

use glam::{DQuat, DVec3};
use tumble_core::math::{Narrow, Quat, Real, Vec3, Widen, to_f64};
use tumble_core::{BodyState, Integrator};
use tumble_ecs::prelude::{FreeFlow, SpringSolver};
use tumble_rapier::{
    Comparison, ComparisonBody, ComparisonOptions, ComparisonScene, ComparisonSpring,
    ComparisonSpringEnd, Load, RapierSprings, compare,
};
use tumble_reference::exact::TorqueFreeTop;
use tumble_scene::text::terminal_safe;
use tumble_scene::{Scene, SceneForce};

use crate::exit::{self, Failure};

/// How `tumble compare` runs the two engines.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Settings {
    /// tumble's integrator.
    pub integrator: Integrator,
    /// rapier's gyroscopic term.
    pub gyroscopic: bool,
    /// tumble's spring step.
    pub springs: SpringSolver,
    /// rapier's springs: its `SpringJoint` or a force added by hand.
    pub rapier_springs: RapierSprings,
    /// tumble's choice of free rotation for split methods.
    pub free_flow: FreeFlow,
}

/// Builds the comparison and prints, per body, the largest difference to rapier and to the
/// exact solution where one exists, each engine's total energy, and the speed ratio.
///
/// A body that either engine quarantined, or whose state went non-finite in either engine, is
/// named on stderr and the command fails with [`exit::REJECTED`]: its differences are not a
/// comparison.
pub(crate) fn run(scene: &Scene, settings: Settings) -> Result<(), Failure> {
    let Settings {
        integrator,
        gyroscopic,
        springs,
        rapier_springs,
        free_flow,
    } = settings;
    let comparison = comparison_scene(scene);
    let mut sprung = vec![false; comparison.bodies.len()];
    for spring in &comparison.springs {
        sprung[spring.a] = true;
        if let ComparisonSpringEnd::Body { body, .. } = spring.b {
            sprung[body] = true;
        }
    }
    let exact = ExactSolutions::of(&comparison, scene.gravity().unwrap_or(Vec3::ZERO).widen());
    let exact = |i: usize, t: f64| exact.at(i, t);
    let options = ComparisonOptions {
        integrator,
        gyroscopic,
        rapier_solver_iterations: 4,
        steps: scene.steps().min(1_000_000) as usize,
        springs,
        rapier_springs,
        free_flow,
        substeps: scene.settings().substeps(),
    };
    let result = compare(&comparison, &options, Some(&exact));
    let (tumble_springs, rapier_springs) = if comparison.springs.is_empty() {
        (String::new(), String::new())
    } else {
        (
            format!(", springs `{springs}`"),
            format!(
                ", springs `{rapier_springs}` = {}",
                rapier_springs.description()
            ),
        )
    };
    let mut out = String::new();
    let _ = writeln!(
        out,
        "scene {} · tumble `{integrator}`{}{tumble_springs} vs rapier 0.36 (gyroscopic {}, 4 substeps{rapier_springs}) · {} steps of {} s",
        terminal_safe(scene.name()),
        match options.substeps.get() {
            1 => String::new(),
            n => format!(", {n} substeps"),
        },
        if gyroscopic { "on" } else { "off" },
        options.steps,
        tumble_core::error::compact(scene.dt())
    );
    let _ = writeln!(
        out,
        "{:<16} {:>11} {:>12} {:>11} {:>11} {:>21} {:>21}",
        "body",
        "Δx (m)",
        "Δangle (rad)",
        "Δv (m/s)",
        "Δω (rad/s)",
        "exact Δx tumble/rapier",
        "exact angle t/r"
    );
    let pair = |p: Option<(f64, f64)>| {
        p.map_or("—".to_owned(), |(t, r)| {
            format!("{} / {}", difference(t, 2), difference(r, 2))
        })
    };
    for d in &result.bodies {
        let _ = writeln!(
            out,
            "{:<16} {:>11} {:>12} {:>11} {:>11} {:>21} {:>21}",
            d.name,
            difference(d.position, 3),
            difference(d.angle, 3),
            difference(d.linear_velocity, 3),
            difference(d.angular_velocity, 3),
            pair(d.exact_position),
            pair(d.exact_angle)
        );
    }
    print_energy(&mut out, &result);
    let _ = writeln!(
        out,
        "time per step: tumble {:.0} ns, rapier {:.0} ns (rapier/tumble = {:.2})",
        result.tumble_ns_per_step,
        result.rapier_ns_per_step,
        result.speed_ratio()
    );
    crate::stdout::print(&out)?;
    report_unclean(&result)
}

/// Exact solutions for the bodies without loads, springs or damping: the position is the
/// parabola `x₀ + v₀t + ½ g s t²`; the orientation is a steady rotation for a spherical body, or
/// the elliptic torque-free top for distinct moments (identity principal frame).
struct ExactSolutions<'a> {
    scene: &'a ComparisonScene,
    gravity: DVec3,
    /// Per body: the top (`None` for a spherical body) and whether it is spherical; `None`
    /// where no exact solution is known.
    tops: Vec<Option<(Option<TorqueFreeTop>, bool)>>,
}

impl<'a> ExactSolutions<'a> {
    fn of(comparison: &'a ComparisonScene, gravity: DVec3) -> Self {
        let mut sprung = vec![false; comparison.bodies.len()];
        for spring in &comparison.springs {
            sprung[spring.a] = true;
            if let ComparisonSpringEnd::Body { body, .. } = spring.b {
                sprung[body] = true;
            }
        }
        let tops = comparison
            .bodies
            .iter()
            .zip(&sprung)
            .map(|(b, &sprung)| {
                let free = !sprung
                    && b.loads.is_empty()
                    && b.linear_damping == 0.0
                    && b.angular_damping == 0.0;
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
        Self {
            scene: comparison,
            gravity,
            tops,
        }
    }

    /// Body `i`'s exact position and orientation at time `t`, if known.
    fn at(&self, i: usize, t: f64) -> Option<BodyState> {
        let (top, spherical) = self.tops[i].as_ref()?;
        let b = &self.scene.bodies[i];
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
            + 0.5 * self.gravity * to_f64(b.gravity_scale) * t * t;
        Some(BodyState {
            position: x.narrow(),
            rotation: Quat::from_xyzw(q.x as Real, q.y as Real, q.z as Real, q.w as Real),
            ..Default::default()
        })
    }
}

/// A difference for the table, with `digits` after the point: `overflow` where it is past the
/// largest number (two states that are each finite can differ by more), `not finite` where a
/// state was not, never a bare `inf` or `NaN`.
fn difference(x: impl Into<f64>, digits: usize) -> String {
    let x: f64 = x.into();
    if x.is_finite() {
        format!("{x:.digits$e}")
    } else if x.is_infinite() {
        "overflow".to_owned()
    } else {
        "not finite".to_owned()
    }
}

/// Names the bodies that did not run cleanly in either engine; an error if any did not.
fn report_unclean(result: &Comparison) -> Result<(), Failure> {
    let unclean: Vec<_> = result.bodies.iter().filter(|d| !d.is_clean()).collect();
    for d in &unclean {
        let name = terminal_safe(&d.name);
        if let Some(step) = d.tumble_rejected_at {
            tracing::error!(target: "tumble", "body `{name}`: tumble quarantined it at step {step}; its differences after that step compare a frozen state");
        }
        if let Some(step) = d.rapier_quarantined_at {
            tracing::error!(target: "tumble", "body `{name}`: rapier quarantined it at step {step} (its state went non-finite; rapier froze it); its differences after that step compare a frozen state");
        }
        if let Some(step) = d.non_finite_at {
            tracing::error!(target: "tumble", "body `{name}`: a state went non-finite at step {step} (`not finite` in the table)");
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

/// The scene as both engines run it: bodies with their loads and damping, and the springs.
fn comparison_scene(scene: &Scene) -> ComparisonScene {
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
    let mut spring_defs = Vec::new();
    for force in scene.forces() {
        match force {
            SceneForce::Constant { body, force, point } => {
                bodies[body].loads.push(Load::Force {
                    force,
                    local_point: point,
                });
            }
            SceneForce::Torque { body, torque } => {
                bodies[body].loads.push(Load::Torque(torque));
            }
            SceneForce::Spring {
                a,
                anchor_a,
                b,
                anchor_b,
                k,
                c,
                rest,
            } => spring_defs.push(ComparisonSpring {
                a,
                anchor_a,
                b: match b {
                    Some(body) => ComparisonSpringEnd::Body {
                        body,
                        anchor: anchor_b,
                    },
                    None => ComparisonSpringEnd::World(anchor_b),
                },
                stiffness: k,
                damping: c,
                rest_length: rest,
            }),
        }
    }
    ComparisonScene {
        springs: spring_defs,
        ..ComparisonScene::new(scene.dt(), scene.gravity(), bodies)
    }
}

/// Prints each engine's total energy (kinetic + spring + gravity, [`ComparisonScene::total_energy`])
/// before and after, with the largest relative change over the run, or the step after which it
/// stopped meaning anything (a quarantined or non-finite body).
fn print_energy(out: &mut String, result: &Comparison) {
    let describe = |series: &[f64]| {
        let e0 = series[0];
        let end = series.last().copied().unwrap_or(e0);
        match series.iter().position(|e| !e.is_finite()) {
            Some(step) => {
                format!("{e0:.6e} J → not valid from step {step} (quarantined or non-finite)")
            }
            None if e0 == 0.0 => {
                // No ratio to a zero start (it would print NaN): the largest change itself.
                let worst = series.iter().map(|e| e.abs()).fold(0.0, f64::max);
                format!("0 → {end:.6e} J (from 0: max |E − E₀| = {worst:.2e} J)")
            }
            None => {
                let worst = series
                    .iter()
                    .map(|e| ((e - e0) / e0).abs())
                    .fold(0.0, f64::max);
                format!(
                    "{e0:.6e} → {end:.6e} J (E/E₀ = {:.6}, max |E − E₀|/E₀ = {worst:.2e})",
                    end / e0
                )
            }
        }
    };
    let _ = writeln!(
        out,
        "total energy (kinetic + spring + gravity): tumble {}; rapier {}",
        describe(&result.tumble_energy),
        describe(&result.rapier_energy)
    );
}

#[cfg(test)]
mod tests {
    use super::*;
    use tumble_rapier::presets::{ChainStart, spring_chain};

    /// `scenes/stiff_chain.toml` is the report's and the bench's chain at ωΔt = 10 (the file
    /// holds its numbers to 9 digits).
    #[test]
    fn the_bundled_stiff_chain_is_the_preset() {
        let text = include_str!("../../../scenes/stiff_chain.toml");
        let scene = Scene::parse("stiff_chain.toml", text).expect("a valid scene");
        let file = comparison_scene(&scene);
        let preset = spring_chain(10.0, ChainStart::Stretched, 1);
        let close = |a: Real, b: Real| (a - b).abs() <= 1e-6 * (1.0 + b.abs());
        let close3 = |a: Vec3, b: Vec3| (0..3).all(|k| close(a[k], b[k]));
        assert_eq!(file.bodies.len(), preset.bodies.len());
        assert_eq!(file.springs.len(), preset.springs.len());
        assert!(close(file.dt, preset.dt));
        for (f, p) in file.bodies.iter().zip(&preset.bodies) {
            assert_eq!(f.mass, p.mass, "{}", f.name);
            assert!(close3(f.state.position, p.state.position), "{}", f.name);
            assert!(
                f.state.rotation.angle_between(p.state.rotation) <= 1e-6,
                "{}",
                f.name
            );
            assert!(close3(f.state.linear_velocity, p.state.linear_velocity));
            assert!(close3(f.state.angular_velocity, p.state.angular_velocity));
        }
        for (f, p) in file.springs.iter().zip(&preset.springs) {
            assert_eq!((f.a, f.b), (p.a, p.b));
            assert!(close3(f.anchor_a, p.anchor_a));
            assert!(close(f.stiffness, p.stiffness) && close(f.rest_length, p.rest_length));
            assert_eq!(f.damping, p.damping);
        }
    }
}
