//! The engine-neutral description of a scene both engines can run.

use tumble_core::math::{Real, Vec3, Widen};
use tumble_core::{BodyState, MassProperties};

/// A constant load on one body, sampled once per step at the current pose.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Load {
    /// A world-frame force through a body-local point (`None` = the centre of mass).
    Force {
        /// Force (N), world frame.
        force: Vec3,
        /// Point of application in body coordinates, or the centre of mass.
        local_point: Option<Vec3>,
    },
    /// A world-frame torque (N·m).
    Torque(Vec3),
}

/// One free rigid body.
#[derive(Debug, Clone, PartialEq)]
pub struct ComparisonBody {
    /// Name used in reports.
    pub name: String,
    /// Mass properties (with centre of mass and principal frame).
    pub mass: MassProperties,
    /// Initial state; `position` is the centre of mass.
    pub state: BodyState,
    /// Gravity scale (1 = normal).
    pub gravity_scale: Real,
    /// Linear damping coefficient (1/s): tumble's `Damping` (a split flow), rapier's linear
    /// damping (Padé, `v ← v/(1 + Δt c)`; see the crate docs for the difference).
    pub linear_damping: Real,
    /// Angular damping coefficient (1/s), mapped as the linear one.
    pub angular_damping: Real,
    /// Constant loads.
    pub loads: Vec<Load>,
}

impl ComparisonBody {
    /// A body at rest-free defaults: no gravity scaling, no damping, no loads.
    pub fn new(name: impl Into<String>, mass: MassProperties, state: BodyState) -> Self {
        Self {
            name: name.into(),
            mass,
            state,
            gravity_scale: 1.0,
            linear_damping: 0.0,
            angular_damping: 0.0,
            loads: Vec::new(),
        }
    }

    /// Adds a load.
    pub fn with_load(mut self, load: Load) -> Self {
        self.loads.push(load);
        self
    }
}

/// The second end of a [`ComparisonSpring`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ComparisonSpringEnd {
    /// A point fixed in the world (m).
    World(Vec3),
    /// A point of another body.
    Body {
        /// Index of the body in [`ComparisonScene::bodies`].
        body: usize,
        /// Anchor in that body's coordinates, relative to its origin (as `anchor_a`).
        anchor: Vec3,
    },
}

/// A damped linear spring, in the convention of tumble's `Spring` (`tumble_ecs::forces`).
///
/// Anchors are body coordinates relative to the body *origin*, not the centre of mass: with
/// centre of mass `x`, rotation `R` and local centre of mass `c`, the anchor `a` sits at
/// `p = x + R (a − c)` in the world. (rapier's joint anchors use the same convention: its body
/// origin is at `x − R c`.) With `d = p_a − p_b`, `ℓ = |d|`, `n = d/ℓ` and the relative anchor
/// velocity `u = ṗ_a − ṗ_b`, the force on `a` is `F_a = −(k (ℓ − L₀) + c (u·n)) n`, and `b`
/// receives `−F_a`; the elastic energy is `½ k (ℓ − L₀)²`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ComparisonSpring {
    /// Index of the first body in [`ComparisonScene::bodies`].
    pub a: usize,
    /// Anchor on `a`, body coordinates relative to its origin.
    pub anchor_a: Vec3,
    /// The other end.
    pub b: ComparisonSpringEnd,
    /// Stiffness `k` (N/m).
    pub stiffness: Real,
    /// Damping `c` (N·s/m), along the spring's axis.
    pub damping: Real,
    /// Rest length `L₀` (m).
    pub rest_length: Real,
}

/// A scene of bodies, free or joined by springs.
#[derive(Debug, Clone, PartialEq)]
pub struct ComparisonScene {
    /// Time step (s).
    pub dt: Real,
    /// Uniform gravity, or none.
    pub gravity: Option<Vec3>,
    /// The bodies.
    pub bodies: Vec<ComparisonBody>,
    /// Springs between bodies or to world points (body indices into `bodies`).
    pub springs: Vec<ComparisonSpring>,
}

impl ComparisonScene {
    /// A scene of free bodies, without springs.
    pub fn new(dt: Real, gravity: Option<Vec3>, bodies: Vec<ComparisonBody>) -> Self {
        Self {
            dt,
            gravity,
            bodies,
            springs: Vec::new(),
        }
    }

    /// The world position of a body-local anchor (relative to the body origin) of body `i` in
    /// state `state`: `x + R (a − c)`, in `f64`.
    ///
    /// # Panics
    /// If `i` is not an index of `bodies`.
    pub fn anchor_point(&self, i: usize, state: &BodyState, anchor: Vec3) -> glam::DVec3 {
        let c = self.bodies[i].mass.local_center_of_mass().widen();
        state.position.widen() + state.rotation.widen() * (anchor.widen() - c)
    }

    /// Total mechanical energy (J) of the scene in the states `states` (one per body, in scene
    /// order), in `f64`, the same sum for both engines:
    ///
    /// `E = Σ_bodies (½ m |v|² + ½ Σ_i I_i w_i² − m s g·x) + Σ_springs ½ k (ℓ − L₀)²`,
    ///
    /// with `w` the angular velocity in the body's principal frame, `s` the gravity scale and the
    /// gravity potential's zero at the origin. Damping and constant loads are not counted (their
    /// work is not a potential).
    ///
    /// # Panics
    /// If `states` is shorter than `bodies` or a spring names a body index outside `bodies`.
    pub fn total_energy(&self, states: &[BodyState]) -> f64 {
        let g = self.gravity.unwrap_or(Vec3::ZERO).widen();
        let bodies: f64 = self
            .bodies
            .iter()
            .zip(states)
            .map(|(body, s)| {
                let m = body.mass.mass().widen();
                let frame = s.rotation.widen() * body.mass.principal_frame().widen();
                let w = frame.inverse() * s.angular_velocity.widen();
                let inertia = body.mass.principal_inertia().widen();
                let kinetic = 0.5 * m * s.linear_velocity.widen().length_squared()
                    + 0.5 * (inertia * w * w).element_sum();
                kinetic - m * body.gravity_scale.widen() * g.dot(s.position.widen())
            })
            .sum();
        let springs: f64 = self
            .springs
            .iter()
            .map(|spring| {
                let pa = self.anchor_point(spring.a, &states[spring.a], spring.anchor_a);
                let pb = match spring.b {
                    ComparisonSpringEnd::World(p) => p.widen(),
                    ComparisonSpringEnd::Body { body, anchor } => {
                        self.anchor_point(body, &states[body], anchor)
                    }
                };
                let stretch = (pa - pb).length() - spring.rest_length.widen();
                0.5 * spring.stiffness.widen() * stretch * stretch
            })
            .sum();
        bodies + springs
    }
}
