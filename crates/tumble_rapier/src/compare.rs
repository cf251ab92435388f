//! Stepping both engines side by side and measuring their differences.

use std::time::Instant;
use tumble_core::math::{Vec3, Widen, to_f64};

use tumble_core::rotation::angle_between;
use tumble_core::{BodyState, Integrator};
use tumble_ecs::prelude::{FreeFlow, SpringSolver};

use crate::rapier_side::RapierScene;
use crate::rapier_springs::RapierSprings;
use crate::scene::ComparisonScene;
use crate::tumble_side::TumbleScene;

/// How to run a comparison.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ComparisonOptions {
    /// tumble's integrator.
    pub integrator: Integrator,
    /// rapier's gyroscopic term (its default is on).
    pub gyroscopic: bool,
    /// rapier's solver iterations, which are substeps for free bodies (its default is 4).
    pub rapier_solver_iterations: usize,
    /// Number of steps.
    pub steps: usize,
    /// How tumble steps the springs (`PhysicsSettings::springs`; default `auto`).
    pub springs: SpringSolver,
    /// How the springs are built in rapier (default: its `SpringJoint`).
    pub rapier_springs: RapierSprings,
    /// Which free rotation tumble's split methods give each body
    /// (`PhysicsSettings::free_flow`; default `auto`).
    pub free_flow: FreeFlow,
    /// tumble's substeps per step (`PhysicsSettings::substeps`; default 1). [`compare`] panics
    /// if `scene.dt` divided by it is too short a step for the precision.
    pub substeps: std::num::NonZeroU32,
}

impl Default for ComparisonOptions {
    fn default() -> Self {
        Self {
            integrator: Integrator::default(),
            gyroscopic: true,
            rapier_solver_iterations: 4,
            steps: 600,
            springs: SpringSolver::Auto,
            rapier_springs: RapierSprings::Joint,
            free_flow: FreeFlow::Auto,
            substeps: std::num::NonZeroU32::MIN,
        }
    }
}

/// Largest differences seen for one body over the run.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct BodyDifference {
    /// Body name.
    pub name: String,
    /// max |x_tumble − x_rapier| (m), centre of mass, in `f64` (two finite states can differ by
    /// more than the precision's largest number, and their difference's square overflows it
    /// far sooner).
    pub position: f64,
    /// max orientation angle between the engines (rad).
    pub angle: f64,
    /// max |v_tumble − v_rapier| (m/s), in `f64`.
    pub linear_velocity: f64,
    /// max |ω_tumble − ω_rapier| (rad/s), in `f64`.
    pub angular_velocity: f64,
    /// Against the exact solution, when one was given: (tumble, rapier) max position error (m).
    pub exact_position: Option<(f64, f64)>,
    /// Against the exact solution: (tumble, rapier) max orientation error (rad).
    pub exact_angle: Option<(f64, f64)>,
    /// The first step after which tumble had quarantined the body (its state is then frozen,
    /// so the differences above stop meaning anything from that step on).
    pub tumble_rejected_at: Option<usize>,
    /// The first step after which rapier had quarantined the body (its state went non-finite;
    /// rapier froze it at its last valid pose, see [`RapierScene::is_quarantined`]).
    pub rapier_quarantined_at: Option<usize>,
    /// The first step after which either engine's state of the body was not finite (the
    /// differences are then NaN, never silently dropped by `max`).
    pub non_finite_at: Option<usize>,
}

impl BodyDifference {
    /// True when the run of this body is trustworthy: never quarantined by either engine,
    /// always finite.
    pub fn is_clean(&self) -> bool {
        self.tumble_rejected_at.is_none()
            && self.rapier_quarantined_at.is_none()
            && self.non_finite_at.is_none()
    }
}

/// `max` that keeps a NaN: `f64::max` and `f32::max` return the other operand when one is NaN,
/// which would report 0 for a body whose state went bad.
fn max_keep_nan<T: PartialOrd + Copy>(current: T, next: T) -> T {
    #[allow(clippy::eq_op)]
    let next_is_nan = next != next;
    if next_is_nan || next > current {
        next
    } else {
        current
    }
}

/// The result of [`compare`].
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Comparison {
    /// One entry per body, in scene order.
    pub bodies: Vec<BodyDifference>,
    /// Mean wall time per step of tumble's schedule (ns).
    pub tumble_ns_per_step: f64,
    /// Mean wall time per step of rapier's pipeline (ns).
    pub rapier_ns_per_step: f64,
    /// tumble's total energy ([`ComparisonScene::total_energy`], J) before the first step
    /// (index 0) and after every step; NaN from the step on which tumble quarantined any body
    /// (its frozen state no longer belongs to the run) or a state went non-finite.
    pub tumble_energy: Vec<f64>,
    /// rapier's total energy, computed the same way from its states; NaN from the step on
    /// which rapier quarantined any body or a state went non-finite.
    pub rapier_energy: Vec<f64>,
}

impl Comparison {
    /// How many times slower rapier's step is than tumble's.
    pub fn speed_ratio(&self) -> f64 {
        self.rapier_ns_per_step / self.tumble_ns_per_step
    }
}

/// An exact solution: the state of body `i` at time `t`, when the scene has one.
pub(crate) type ExactSolution<'a> = &'a dyn Fn(usize, f64) -> Option<BodyState>;

/// Runs `scene` in both engines for `options.steps` steps, recording after every step the
/// largest per-body differences (and errors against `exact`, where it knows the body).
pub fn compare(
    scene: &ComparisonScene,
    options: &ComparisonOptions,
    exact: Option<ExactSolution<'_>>,
) -> Comparison {
    let mut tumble = TumbleScene::with_free_flow(
        scene,
        options.integrator,
        options.springs,
        options.free_flow,
    );
    if options.substeps.get() > 1 {
        tumble
            .world_mut()
            .resource_mut::<tumble_ecs::prelude::PhysicsSettings>()
            .set_substeps(options.substeps)
            .expect("substeps of a step the precision can take (see ComparisonOptions)");
    }
    let mut rapier = RapierScene::with_springs(
        scene,
        options.gyroscopic,
        options.rapier_solver_iterations,
        options.rapier_springs,
    );
    let n = scene.bodies.len();
    let initial: Vec<BodyState> = scene.bodies.iter().map(|b| b.state).collect();
    let e0 = scene.total_energy(&initial);
    let mut tumble_energy = Vec::with_capacity(options.steps + 1);
    let mut rapier_energy = Vec::with_capacity(options.steps + 1);
    tumble_energy.push(e0);
    rapier_energy.push(e0);
    let (mut tumble_states, mut rapier_states) = (initial.clone(), initial);
    let (mut tumble_valid, mut rapier_valid) = (true, true);
    let mut bodies: Vec<BodyDifference> = scene
        .bodies
        .iter()
        .map(|b| BodyDifference {
            name: b.name.clone(),
            ..Default::default()
        })
        .collect();
    let (mut tumble_ns, mut rapier_ns) = (0u128, 0u128);
    for step in 1..=options.steps {
        let start = Instant::now();
        tumble.step();
        tumble_ns += start.elapsed().as_nanos();
        let start = Instant::now();
        rapier.step();
        rapier_ns += start.elapsed().as_nanos();
        let t = to_f64(scene.dt) * step as f64;
        for i in 0..n {
            tumble_states[i] = tumble.state(i);
            rapier_states[i] = rapier.state(i);
            tumble_valid &= !tumble.is_rejected(i);
            rapier_valid &= !rapier.is_quarantined(i);
        }
        tumble_energy.push(if tumble_valid {
            scene.total_energy(&tumble_states)
        } else {
            f64::NAN
        });
        rapier_energy.push(if rapier_valid {
            scene.total_energy(&rapier_states)
        } else {
            f64::NAN
        });
        for (i, diff) in bodies.iter_mut().enumerate() {
            diff.record(
                step,
                (&tumble_states[i], tumble.is_rejected(i)),
                (&rapier_states[i], rapier.is_quarantined(i)),
                exact.and_then(|f| f(i, t)),
            );
        }
    }
    let steps = options.steps.max(1) as f64;
    Comparison {
        bodies,
        tumble_ns_per_step: tumble_ns as f64 / steps,
        rapier_ns_per_step: rapier_ns as f64 / steps,
        tumble_energy,
        rapier_energy,
    }
}

impl BodyDifference {
    /// Takes in step `step`: tumble's state `a` (and whether tumble has rejected the body),
    /// rapier's `b` (and whether it is quarantined), and the exact solution's state where there
    /// is one.
    fn record(
        &mut self,
        step: usize,
        (a, tumble_rejected): (&BodyState, bool),
        (b, rapier_quarantined): (&BodyState, bool),
        reference: Option<BodyState>,
    ) {
        if self.tumble_rejected_at.is_none() && tumble_rejected {
            self.tumble_rejected_at = Some(step);
        }
        if self.rapier_quarantined_at.is_none() && rapier_quarantined {
            self.rapier_quarantined_at = Some(step);
        }
        if self.non_finite_at.is_none() && !(a.is_finite() && b.is_finite()) {
            self.non_finite_at = Some(step);
        }
        let apart = |x: Vec3, y: Vec3| (x.widen() - y.widen()).length();
        self.position = max_keep_nan(self.position, apart(a.position, b.position));
        self.angle = max_keep_nan(self.angle, angle_between(a.rotation, b.rotation));
        self.linear_velocity = max_keep_nan(
            self.linear_velocity,
            apart(a.linear_velocity, b.linear_velocity),
        );
        self.angular_velocity = max_keep_nan(
            self.angular_velocity,
            apart(a.angular_velocity, b.angular_velocity),
        );
        if let Some(reference) = reference {
            let pos = |s: &BodyState| apart(s.position, reference.position);
            let (pt, pr) = self.exact_position.unwrap_or((0.0, 0.0));
            self.exact_position = Some((max_keep_nan(pt, pos(a)), max_keep_nan(pr, pos(b))));
            let (at, ar) = self.exact_angle.unwrap_or((0.0, 0.0));
            self.exact_angle = Some((
                max_keep_nan(at, angle_between(a.rotation, reference.rotation)),
                max_keep_nan(ar, angle_between(b.rotation, reference.rotation)),
            ));
        }
    }
}
