//! The serde model of a scene file.

use serde::{Deserialize, Deserializer, Serialize};

use exact_fns as exact;

/// A whole scene file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    /// Scene name: non-empty, at most [`crate::MAX_NAME_BYTES`] bytes, no control or format
    /// characters (it is printed to terminals and reports).
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
    /// Seconds per step, > 0, and neither 0 nor infinite once rounded to the engine precision.
    pub dt: f64,
    /// Number of steps, 1..=1e9.
    pub steps: u64,
    /// Integrator name (default: `splitting`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub integrator: Option<String>,
    /// How springs are stepped: `auto` (default: implicit for the groups that are stiff for
    /// `dt`), `explicit` or `implicit`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub springs: Option<String>,
    /// Which free rotation a split integrator gives each body: `auto` (default: the exact free
    /// flow for a body while its split errs by more than the limit, see
    /// `tumble_core::integrate::FreeFlow`) or `method` (the integrator's own flow for every
    /// body).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub free_flow: Option<String>,
    /// Substeps per step, `1..=`[`crate::MAX_SUBSTEPS`] (default 1): the force stage runs in
    /// each (see `PhysicsSettings::substeps`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub substeps: Option<u64>,
    /// Uniform gravity; absent means no gravity system at all.
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        deserialize_with = "exact::option"
    )]
    pub gravity: Option<[f64; 3]>,
}

/// A parry shape, one key.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, rename_all = "snake_case")]
pub enum ShapeDef {
    /// Radius.
    Ball(f64),
    /// Half extents.
    #[serde(deserialize_with = "exact::array")]
    Cuboid([f64; 3]),
    /// `[half_height, radius]` along y.
    #[serde(deserialize_with = "exact::array")]
    Capsule([f64; 2]),
    /// `[half_height, radius]` along y.
    #[serde(deserialize_with = "exact::array")]
    Cylinder([f64; 2]),
    /// `[half_height, radius]` along y.
    #[serde(deserialize_with = "exact::array")]
    Cone([f64; 2]),
    /// Points of a convex hull.
    #[serde(deserialize_with = "exact::points")]
    ConvexHull(Vec<[f64; 3]>),
}

/// `[[bodies]]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BodyDef {
    /// Unique name, with the rules of the scene name, and since it is a CSV cell: no comma or
    /// quote, and no leading `=`, `+`, `-` or `@` (a spreadsheet would run the cell as a
    /// formula).
    pub name: String,
    /// Mass (kg), with `inertia`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mass: Option<f64>,
    /// Principal moments (kg·m²), body frame, with `mass`.
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        deserialize_with = "exact::option"
    )]
    pub inertia: Option<[f64; 3]>,
    /// A parry shape, with `density`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shape: Option<ShapeDef>,
    /// Density (kg/m³), with `shape`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub density: Option<f64>,
    /// Position of the body origin (m).
    #[serde(
        default,
        deserialize_with = "exact::array",
        skip_serializing_if = "is_origin"
    )]
    pub position: [f64; 3],
    /// Unit quaternion `[x, y, z, w]`.
    #[serde(
        default = "identity",
        deserialize_with = "exact::array",
        skip_serializing_if = "is_identity"
    )]
    pub rotation: [f64; 4],
    /// Linear velocity of the centre of mass (m/s).
    #[serde(
        default,
        deserialize_with = "exact::array",
        skip_serializing_if = "is_origin"
    )]
    pub linear_velocity: [f64; 3],
    /// Angular velocity, world frame (rad/s).
    #[serde(
        default,
        deserialize_with = "exact::array",
        skip_serializing_if = "is_origin"
    )]
    pub angular_velocity: [f64; 3],
    /// Gravity scale (default 1).
    #[serde(default = "one", skip_serializing_if = "is_one")]
    pub gravity_scale: f64,
    /// Linear damping `c_lin` (1/s): `v̇ = −c_lin v`, the body's `Damping`.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub linear_damping: f64,
    /// Angular damping `c_ang` (1/s): `ω̇ = −c_ang ω`, the body's `Damping`.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub angular_damping: f64,
}

fn identity() -> [f64; 4] {
    [0.0, 0.0, 0.0, 1.0]
}

fn one() -> f64 {
    1.0
}

// Defaults are not written (a large scene's file is a third smaller, and as much faster to
// read). `==` keeps `-0.0` unwritten too, which reads back as `0.0`: the same in every use.
fn is_zero(x: &f64) -> bool {
    *x == 0.0
}

fn is_one(x: &f64) -> bool {
    *x == 1.0
}

fn is_origin(v: &[f64; 3]) -> bool {
    v.iter().all(is_zero)
}

fn is_identity(q: &[f64; 4]) -> bool {
    *q == identity()
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
        #[serde(deserialize_with = "exact::array")]
        force: [f64; 3],
        /// Body-local point.
        #[serde(
            default,
            skip_serializing_if = "Option::is_none",
            deserialize_with = "exact::option"
        )]
        point: Option<[f64; 3]>,
    },
    /// Constant world-frame torque.
    Torque {
        /// Body name.
        body: String,
        /// Torque (N·m).
        #[serde(deserialize_with = "exact::array")]
        torque: [f64; 3],
    },
    /// Damped spring between `a` and `b`, or `a` and the world point `anchor_b`.
    Spring {
        /// First body.
        a: String,
        /// Anchor on `a` (body-local).
        #[serde(default, deserialize_with = "exact::array")]
        anchor_a: [f64; 3],
        /// Second body, or none for a world anchor.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        b: Option<String>,
        /// Anchor on `b` (body-local) or in the world.
        #[serde(default, deserialize_with = "exact::array")]
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

/// Fixed-length arrays read with their length checked: serde's `[T; N]` (through toml) stops
/// after `N` elements and silently drops the rest, so `[1, 2, 3, "junk"]` read as a position.
/// Extra elements are counted without being parsed (`IgnoredAny`), so a 1e6-element array
/// costs one pass and no allocation.
mod exact_impl {
    use serde::de::{self, IgnoredAny, SeqAccess, Visitor};
    use std::fmt;

    pub(crate) struct Exact<const N: usize>;

    impl<'de, const N: usize> Visitor<'de> for Exact<N> {
        type Value = [f64; N];

        fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
            write!(f, "an array of {N} numbers")
        }

        fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<[f64; N], A::Error> {
            let mut out = [0.0; N];
            let mut got = 0usize;
            while got < N {
                match seq.next_element::<f64>()? {
                    Some(x) => out[got] = x,
                    None => break,
                }
                got += 1;
            }
            if got == N {
                while seq.next_element::<IgnoredAny>()?.is_some() {
                    got += 1;
                }
            }
            if got != N {
                return Err(de::Error::custom(format_args!(
                    "expected {N} numbers, got {got}"
                )));
            }
            Ok(out)
        }
    }
}

/// `deserialize_with` helpers for arrays of exact length (see `exact_impl`).
pub(crate) mod exact_fns {
    use super::*;
    use exact_impl::Exact;

    /// `[f64; N]`, exactly `N` elements.
    pub(crate) fn array<'de, D: Deserializer<'de>, const N: usize>(
        d: D,
    ) -> Result<[f64; N], D::Error> {
        d.deserialize_seq(Exact::<N>)
    }

    /// `Option<[f64; N]>`: present means exactly `N` elements.
    pub(crate) fn option<'de, D: Deserializer<'de>, const N: usize>(
        d: D,
    ) -> Result<Option<[f64; N]>, D::Error> {
        array(d).map(Some)
    }

    /// Points `[[x, y, z], …]`, each of exactly 3 numbers.
    pub(crate) fn points<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<[f64; 3]>, D::Error> {
        struct Point([f64; 3]);
        impl<'de> Deserialize<'de> for Point {
            fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
                array(d).map(Point)
            }
        }
        let points = Vec::<Point>::deserialize(d)?;
        Ok(points.into_iter().map(|p| p.0).collect())
    }
}
