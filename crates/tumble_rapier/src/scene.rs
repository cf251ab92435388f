//! The engine-neutral description of a scene both engines can run.

use tumble_core::math::{Real, Vec3};
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

/// A scene of free bodies.
#[derive(Debug, Clone, PartialEq)]
pub struct ComparisonScene {
    /// Time step (s).
    pub dt: Real,
    /// Uniform gravity, or none.
    pub gravity: Option<Vec3>,
    /// The bodies.
    pub bodies: Vec<ComparisonBody>,
}
