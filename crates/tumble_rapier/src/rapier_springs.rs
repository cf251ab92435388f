//! How a [`ComparisonSpring`](crate::ComparisonSpring) is built in rapier: as rapier's
//! `SpringJoint`, or as a force written by hand and added every step.

use std::fmt;
use std::str::FromStr;

use glam::DVec3;
use tumble_core::BodyState;

use crate::scene::{ComparisonScene, ComparisonSpring, ComparisonSpringEnd};

/// The two ways a rapier user writes a spring.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum RapierSprings {
    /// rapier's `SpringJoint` (`SpringJointBuilder::new(L₀, k, c)`, anchors as given, rapier's
    /// default spring model `MotorModel::ForceBased`): a soft constraint solved in the velocity
    /// solver, implicit in the spring (rapier documents that it adds numerical damping, so even an
    /// undamped spring loses energy). A spring to a world point is a joint to a fixed body there.
    /// What a rapier user would pick (the default).
    #[default]
    Joint,
    /// The force `F_a = −(k (ℓ − L₀) + c (u·n)) n` computed from the poses at the start of each
    /// step and added with `add_force_at_point` to both bodies (opposite signs), held over the
    /// step and its substeps: an explicit spring, what a user without joints writes (rapier issue
    /// #241: it gains energy).
    Force,
}

impl RapierSprings {
    /// Both choices, in declaration order.
    pub const ALL: [RapierSprings; 2] = [RapierSprings::Joint, RapierSprings::Force];

    /// The name used on the command line and in reports.
    pub fn name(self) -> &'static str {
        match self {
            RapierSprings::Joint => "joint",
            RapierSprings::Force => "force",
        }
    }

    /// What the choice builds in rapier, for reports.
    pub fn description(self) -> &'static str {
        match self {
            RapierSprings::Joint => "SpringJoint, force-based model",
            RapierSprings::Force => "add_force_at_point each step",
        }
    }
}

impl fmt::Display for RapierSprings {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A name that is not a [`RapierSprings`].
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct UnknownRapierSprings(pub String);

impl fmt::Display for UnknownRapierSprings {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "unknown rapier spring mode `{}`; expected `joint` or `force`",
            self.0.escape_debug()
        )
    }
}

impl std::error::Error for UnknownRapierSprings {}

impl FromStr for RapierSprings {
    type Err = UnknownRapierSprings;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        RapierSprings::ALL
            .into_iter()
            .find(|m| m.name() == s)
            .ok_or_else(|| UnknownRapierSprings(s.to_owned()))
    }
}

/// The world anchor point and its velocity `v + ω × (p − x)` of one end, in `f64`.
fn anchor_motion(
    scene: &ComparisonScene,
    states: &[BodyState],
    body: usize,
    anchor: tumble_core::math::Vec3,
) -> (DVec3, DVec3) {
    use tumble_core::math::Widen;
    let s = &states[body];
    let p = scene.anchor_point(body, s, anchor);
    let v = s.linear_velocity.widen() + s.angular_velocity.widen().cross(p - s.position.widen());
    (p, v)
}

/// The force of one spring on its first end and the two world anchor points:
/// `(F_a, p_a, p_b)`, `F_a = −(k (ℓ − L₀) + c (u·n)) n` (zero at `ℓ = 0`), in `f64`.
pub(crate) fn spring_force(
    scene: &ComparisonScene,
    states: &[BodyState],
    spring: &ComparisonSpring,
) -> (DVec3, DVec3, DVec3) {
    use tumble_core::math::Widen;
    let (pa, va) = anchor_motion(scene, states, spring.a, spring.anchor_a);
    let (pb, vb) = match spring.b {
        ComparisonSpringEnd::World(p) => (p.widen(), DVec3::ZERO),
        ComparisonSpringEnd::Body { body, anchor } => anchor_motion(scene, states, body, anchor),
    };
    let d = pa - pb;
    let length = d.length();
    if length <= 0.0 {
        return (DVec3::ZERO, pa, pb);
    }
    let n = d / length;
    let magnitude = spring.stiffness.widen() * (length - spring.rest_length.widen())
        + spring.damping.widen() * (va - vb).dot(n);
    (-magnitude * n, pa, pb)
}
