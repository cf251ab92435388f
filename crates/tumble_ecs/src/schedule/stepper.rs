//! `FixedStepper` and `interpolate`.

use thiserror::Error;
use tumble_core::math::{Real, Vec3, to_f64};

use crate::components::Pose;

/// Invalid stepper input.
#[derive(Debug, Clone, Copy, PartialEq, Error)]
pub enum StepperError {
    /// The fixed step must be > 0 and finite.
    #[error("fixed time step must be > 0 and finite, got {0}")]
    NonPositiveTimeStep(Real),
    /// At least one step per frame must be allowed.
    #[error("max steps per frame must be >= 1")]
    ZeroStepCap,
    /// A frame time must be >= 0 and finite.
    #[error("frame time must be >= 0 and finite, got {0}")]
    BadFrameTime(f64),
}

/// Fixed-step accumulator. `Copy`: a game that rolls back saves it with its
/// [`RollbackSnapshot`](crate::state::RollbackSnapshot) (it lives outside the world).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FixedStepper {
    dt: f64,
    max_steps_per_frame: u32,
    accumulator: f64,
    dropped_time: f64,
}

/// What one frame should do.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrameSteps {
    /// Number of fixed steps to run this frame (≤ the cap).
    pub steps: u32,
    /// Interpolation factor `α ∈ [0, 1)` between the previous and the current physics state.
    pub alpha: Real,
}

impl FixedStepper {
    /// A stepper with fixed step `dt` (s) and at most `max_steps_per_frame` steps per frame.
    pub fn new(dt: Real, max_steps_per_frame: u32) -> Result<Self, StepperError> {
        if !(dt.is_finite() && dt > 0.0) {
            return Err(StepperError::NonPositiveTimeStep(dt));
        }
        if max_steps_per_frame == 0 {
            return Err(StepperError::ZeroStepCap);
        }
        Ok(Self {
            dt: to_f64(dt),
            max_steps_per_frame,
            accumulator: 0.0,
            dropped_time: 0.0,
        })
    }

    /// Adds a frame's elapsed time (s) and returns how many steps to run and the interpolation
    /// factor. Time is accumulated in f64 so that long sessions do not drift.
    pub fn advance(&mut self, frame_time: f64) -> Result<FrameSteps, StepperError> {
        if !(frame_time.is_finite() && frame_time >= 0.0) {
            return Err(StepperError::BadFrameTime(frame_time));
        }
        self.accumulator += frame_time;
        let whole = (self.accumulator / self.dt).floor();
        let cap = to_f64(self.max_steps_per_frame);
        let steps = whole.min(cap);
        self.accumulator -= steps * self.dt;
        if whole > cap {
            // Keep less than one step of backlog: drop the rest and remember how much.
            let keep = self.accumulator % self.dt;
            self.dropped_time += self.accumulator - keep;
            self.accumulator = keep;
        }
        Ok(FrameSteps {
            steps: steps as u32,
            alpha: (self.accumulator / self.dt).clamp(0.0, 1.0) as Real,
        })
    }

    /// Total simulated time dropped by the step cap so far (s).
    pub fn dropped_time(&self) -> f64 {
        self.dropped_time
    }

    /// The fixed step (s).
    pub fn dt(&self) -> Real {
        self.dt as Real
    }
}

/// Interpolates a pose for rendering: linear in translation, spherical (slerp) in rotation.
pub fn interpolate(previous: &Pose, current: &Pose, alpha: Real) -> Pose {
    Pose {
        translation: Vec3::lerp(previous.translation, current.translation, alpha),
        rotation: previous.rotation.slerp(current.rotation, alpha),
    }
}
