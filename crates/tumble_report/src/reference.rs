//! Reference scenes with exact solutions (f64).

use glam::{DQuat, DVec3};
use tumble_core::math::{Quat, Real, Vec3, Widen, to_f64};
use tumble_core::{BodyState, Mass, MassProperties};
use tumble_reference::exact::TorqueFreeTop;

/// The load of a reference scene, evaluated at the state where the integrator samples it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Load {
    /// Torque-free, force-free.
    Free,
    /// Uniform gravity `g` (m/s²).
    Gravity(Vec3),
    /// A spring of stiffness `k` from the centre of mass to the world origin, rest length 0.
    Spring(Real),
    /// A constant world force through a body-local point.
    ForceAtPoint {
        /// Force (N), world frame.
        force: Vec3,
        /// Point, body frame.
        point: Vec3,
    },
}

impl Load {
    /// Potential energy (J), so that kinetic + potential is conserved.
    pub fn potential(&self, state: &BodyState, mass: &MassProperties) -> f64 {
        let x = state.position.widen();
        match *self {
            Load::Free => 0.0,
            Load::Gravity(g) => -to_f64(mass.mass()) * g.widen().dot(x),
            Load::Spring(k) => 0.5 * to_f64(k) * x.length_squared(),
            Load::ForceAtPoint { force, point } => {
                -force.widen().dot(x + (state.rotation * point).widen())
            }
        }
    }
}

/// Exact (or reference) state at time `t`: position of the centre of mass and orientation.
pub type Exact = Box<dyn Fn(f64) -> (DVec3, DQuat) + Send + Sync>;

/// One reference scene.
pub struct Case {
    /// Short name.
    pub name: &'static str,
    /// What it shows.
    pub description: &'static str,
    /// Mass properties.
    pub mass: MassProperties,
    /// Initial state.
    pub initial: BodyState,
    /// The load.
    pub load: Load,
    /// Horizon (s).
    pub horizon: f64,
    /// Exact solution.
    pub exact: Exact,
    /// True when the work–precision study runs rapier on the scene (not on the spring scene:
    /// rapier's springs, joint and force, are measured on the chain in [`crate::springs`]).
    pub rapier: bool,
}

/// Orientation of a spherical body (moment `inertia`) driven by the torque `(R p) × F` of a
/// constant world force at body point `p`, from rest: f64 RK4 with h = 1e-4 on `(q, L)`.
fn pendulum(point: DVec3, force: DVec3, inertia: f64, t: f64) -> DQuat {
    let f = |q: DQuat, l: DVec3| {
        let w = l / inertia;
        (
            DQuat::from_xyzw(w.x, w.y, w.z, 0.0) * q * 0.5,
            (q * point).cross(force),
        )
    };
    let steps = (t / 1e-4).round().max(1.0) as usize;
    let h = t / steps as f64;
    let (mut q, mut l) = (DQuat::IDENTITY, DVec3::ZERO);
    for _ in 0..steps {
        let (next, dl) = tumble_reference::rk4::step(q, l, h, f);
        q = next;
        l += dl;
    }
    q
}

fn top(name: &'static str, description: &'static str, inertia: Vec3, omega0: Vec3) -> Case {
    let exact_top = TorqueFreeTop::new(inertia.widen(), omega0.widen(), DQuat::IDENTITY)
        .expect("an asymmetric top with finite rates");
    Case {
        name,
        description,
        mass: MassProperties::new(Mass::new(1.0).expect("valid"), inertia).expect("valid"),
        initial: BodyState {
            angular_velocity: omega0,
            ..Default::default()
        },
        load: Load::Free,
        horizon: 10.0,
        exact: Box::new(move |t| (DVec3::ZERO, exact_top.orientation(t))),
        rapier: true,
    }
}

/// The reference scenes of the work–precision study.
pub fn cases() -> Vec<Case> {
    let sphere = MassProperties::solid_sphere(Mass::new(2.0).expect("valid"), 0.5).expect("valid");
    let (x0, v0, g) = (
        Vec3::new(0.0, 10.0, 0.0),
        Vec3::new(3.0, 12.0, -1.0),
        Vec3::new(0.0, -9.81, 0.0),
    );
    let (k, m) = (100.0 as Real, 1.0 as Real);
    let spring_x0 = Vec3::new(0.5, 0.0, 0.0);
    let force = Vec3::new(0.0, 0.0, 1.0);
    let point = Vec3::new(0.5, 0.0, 0.0);
    vec![
        top(
            "top-largest",
            "torque-free top, I = (1, 2, 3), ω₀ = (0.1, 0.1, 3): stable spin near the largest axis",
            Vec3::new(1.0, 2.0, 3.0),
            Vec3::new(0.1, 0.1, 3.0),
        ),
        top(
            "top-smallest",
            "torque-free top, ω₀ = (3, 0.1, 0.1): stable spin near the smallest axis",
            Vec3::new(1.0, 2.0, 3.0),
            Vec3::new(3.0, 0.1, 0.1),
        ),
        top(
            "dzhanibekov",
            "torque-free top, ω₀ = (1, 5, 1): flips about the middle axis every 1.79 s",
            Vec3::new(1.0, 2.0, 3.0),
            Vec3::new(1.0, 5.0, 1.0),
        ),
        top(
            "thin-plate",
            "torque-free thin asymmetric plate, I = (0.01, 1, 1.01), |ω₀| = 10 rad/s about a \
             tilted axis (0.3, 1, 0.5)",
            PLATE,
            Vec3::new(0.3, 1.0, 0.5).normalize() * 10.0,
        ),
        Case {
            name: "projectile",
            description: "uniform gravity: x = x₀ + v₀t + ½gt²",
            mass: sphere,
            initial: BodyState {
                position: x0,
                linear_velocity: v0,
                ..Default::default()
            },
            load: Load::Gravity(g),
            horizon: 5.0,
            exact: Box::new(move |t| {
                let x = x0.widen() + v0.widen() * t + 0.5 * g.widen() * t * t;
                (x, DQuat::IDENTITY)
            }),
            rapier: true,
        },
        Case {
            name: "spring",
            description: "undamped spring, √(k/m) = 10 rad/s: x = x₀ cos(√(k/m) t)",
            mass: MassProperties::solid_sphere(Mass::new(m).expect("valid"), 0.1).expect("valid"),
            initial: BodyState {
                position: spring_x0,
                ..Default::default()
            },
            load: Load::Spring(k),
            horizon: 10.0,
            exact: Box::new(move |t| {
                let w = to_f64(k / m).sqrt();
                (spring_x0.widen() * (w * t).cos(), DQuat::IDENTITY)
            }),
            rapier: false,
        },
        Case {
            name: "force-at-point",
            description: "sphere pushed by a constant world force at a rim point (no gravity): \
                          x = ½(F/m)t², rotation swings like a pendulum (f64 RK4 reference)",
            mass: sphere,
            initial: BodyState::default(),
            load: Load::ForceAtPoint { force, point },
            horizon: 3.0,
            exact: Box::new(move |t| {
                let x = 0.5 * (force.widen() / to_f64(sphere.mass())) * t * t;
                let inertia = to_f64(sphere.principal_inertia().x);
                (x, pendulum(point.widen(), force.widen(), inertia, t))
            }),
            rapier: true,
        },
    ]
}

/// Principal moments of the thin asymmetric plate (kg·m²), the `thin-plate` case and the
/// [`thin`](crate::thin) study.
pub const PLATE: Vec3 = Vec3::new(0.01, 1.0, 1.01);

/// f64 → f32 quaternion.
pub fn to_quat(q: DQuat) -> Quat {
    Quat::from_xyzw(q.x as Real, q.y as Real, q.z as Real, q.w as Real)
}
