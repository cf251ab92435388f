//! The serde model of a scene file.

use serde::{Deserialize, Serialize};

/// A whole scene file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    /// Scene name.
    pub name: String,
    /// Time step, step count, integrator, gravity.
    pub world: WorldDef,
    /// Bodies.
    #[serde(default)]
    pub bodies: Vec<BodyDef>,
    /// Force generators.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub forces: Vec<ForceDef>,
}

/// `[world]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WorldDef {
    /// Seconds per step, > 0.
    pub dt: f64,
    /// Number of steps, 1..=1e9.
    pub steps: u64,
    /// Integrator name (default: `splitting`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub integrator: Option<String>,
    /// Uniform gravity; absent means no gravity system at all.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gravity: Option<[f64; 3]>,
}

/// A parry shape, one key.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, rename_all = "snake_case")]
pub enum ShapeDef {
    /// Radius.
    Ball(f64),
    /// Half extents.
    Cuboid([f64; 3]),
    /// `[half_height, radius]` along y.
    Capsule([f64; 2]),
    /// `[half_height, radius]` along y.
    Cylinder([f64; 2]),
    /// `[half_height, radius]` along y.
    Cone([f64; 2]),
    /// Points of a convex hull.
    ConvexHull(Vec<[f64; 3]>),
}

/// `[[bodies]]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BodyDef {
    /// Unique name.
    pub name: String,
    /// Mass (kg), with `inertia`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mass: Option<f64>,
    /// Principal moments (kg·m²), body frame, with `mass`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub inertia: Option<[f64; 3]>,
    /// A parry shape, with `density`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shape: Option<ShapeDef>,
    /// Density (kg/m³), with `shape`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub density: Option<f64>,
    /// Position of the body origin (m).
    #[serde(default)]
    pub position: [f64; 3],
    /// Unit quaternion `[x, y, z, w]`.
    #[serde(default = "identity")]
    pub rotation: [f64; 4],
    /// Linear velocity of the centre of mass (m/s).
    #[serde(default)]
    pub linear_velocity: [f64; 3],
    /// Angular velocity, world frame (rad/s).
    #[serde(default)]
    pub angular_velocity: [f64; 3],
    /// Gravity scale (default 1).
    #[serde(default = "one")]
    pub gravity_scale: f64,
    /// Padé linear damping (1/s).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub linear_damping: f64,
    /// Padé angular damping (1/s).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub angular_damping: f64,
}

fn identity() -> [f64; 4] {
    [0.0, 0.0, 0.0, 1.0]
}

fn one() -> f64 {
    1.0
}

fn is_zero(x: &f64) -> bool {
    *x == 0.0
}

/// `[[forces]]`, tagged by `type`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum ForceDef {
    /// Constant world-frame force, optionally at a body-local point.
    Constant {
        /// Body name.
        body: String,
        /// Force (N).
        force: [f64; 3],
        /// Body-local point.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        point: Option<[f64; 3]>,
    },
    /// Constant world-frame torque.
    Torque {
        /// Body name.
        body: String,
        /// Torque (N·m).
        torque: [f64; 3],
    },
    /// Damped spring between `a` and `b`, or `a` and the world point `anchor_b`.
    Spring {
        /// First body.
        a: String,
        /// Anchor on `a` (body-local).
        #[serde(default)]
        anchor_a: [f64; 3],
        /// Second body, or none for a world anchor.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        b: Option<String>,
        /// Anchor on `b` (body-local) or in the world.
        #[serde(default)]
        anchor_b: [f64; 3],
        /// Stiffness (N/m).
        stiffness: f64,
        /// Damping (N·s/m).
        #[serde(default)]
        damping: f64,
        /// Rest length (m).
        #[serde(default)]
        rest_length: f64,
    },
}
