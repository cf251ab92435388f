//! The parts of a scene as its checks accept them (`checks` makes them, `build` and `spawn`
//! use them): a leaf below the modules that check and build, so neither needs the other's.

use tumble_core::MassProperties;
use tumble_core::math::{Real, Vec3};
use tumble_ecs::prelude::{Damping, Pose, Velocity};

/// A body as its checks accepted it: what the world spawns.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct ValidBody {
    pub(crate) mass: MassProperties,
    pub(crate) transform: Pose,
    pub(crate) velocity: Velocity,
    pub(crate) gravity_scale: Real,
    pub(crate) damping: Damping,
}

/// A force generator of a [`Scene`](crate::Scene) as its checks accepted it: bodies by their index in file
/// order ([`Scene::body_states`](crate::Scene::body_states)), vectors and numbers in the engine precision.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SceneForce {
    /// A constant force on `body`, at its centre of mass or at `point` (body frame).
    Constant {
        /// The body's index.
        body: usize,
        /// The force (N), world frame.
        force: Vec3,
        /// Where it acts, body coordinates relative to the origin; `None`: the centre of mass.
        point: Option<Vec3>,
    },
    /// A constant torque on `body`.
    Torque {
        /// The body's index.
        body: usize,
        /// The torque (N·m), world frame.
        torque: Vec3,
    },
    /// A spring from `anchor_a` on body `a` to `anchor_b` on body `b` (body coordinates), or to
    /// the world point `anchor_b` when `b` is `None`.
    Spring {
        /// The first body's index.
        a: usize,
        /// The anchor on `a`.
        anchor_a: Vec3,
        /// The other body's index, or `None` for a world point.
        b: Option<usize>,
        /// The anchor on `b`, or the world point.
        anchor_b: Vec3,
        /// Stiffness (N/m), `>= 0`.
        k: Real,
        /// Damping (N·s/m), `>= 0`.
        c: Real,
        /// Rest length (m), `>= 0`.
        rest: Real,
    },
}

/// Largest accepted step count.
pub const MAX_STEPS: u64 = 1_000_000_000;

/// Most substeps per step a scene may ask for: each costs a whole step, so beyond this a smaller
/// `dt` is the honest setting.
pub const MAX_SUBSTEPS: u32 = 1000;
