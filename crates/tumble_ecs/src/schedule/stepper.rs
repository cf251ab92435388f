//! `FixedStepper` and `interpolate`.

use thiserror::Error;
use tumble_core::math::{Real, Vec3, to_f64};

use crate::components::{PhysicsSettings, Pose};

/// Invalid stepper input.
#[derive(Debug, Clone, Copy, PartialEq, Error)]
pub enum StepperError {
    /// At least one step per frame must be allowed.
    #[error("max steps per frame must be >= 1")]
    ZeroStepCap,
    /// A frame time must be >= 0 and finite.
    #[error("frame time must be >= 0 and finite, got {0}")]
    BadFrameTime(f64),
}

/// Fixed-step accumulator: turns frame times into whole steps of the world's
/// [`PhysicsSettings`] time step. The step comes from the settings at every frame, never from a
/// copy of its own, so that the frames and the physics cannot disagree on it (a stepper with
/// its own `Δt` ran the physics at half or twice game time, silently, wherever the two
/// differed) and a time step changed mid-run is followed at once. `Copy`: a game that rolls back
/// saves it with its [`RollbackSnapshot`](crate::state::RollbackSnapshot) (it lives outside the
/// world).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FixedStepper {
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

/// How far (a fraction of a step) the physics may run ahead of the frames' time: a frame that
/// brings the accumulated time within it of a whole number of steps runs that many. The step is
/// stored in the engine's precision (`1/60` in `f32` is 0.016666668, longer than the `f64` frame
/// of a 60 Hz display by 5e-8 of itself): without it, frames of exactly one step each ran a
/// step late from the first frame on; with it they run one step each, and the debt of
/// 5e-8 a step reaches the slack after ~2·10⁵ frames (an hour at 60 Hz), where one frame runs
/// none. Rendering sees at most this much of a step ahead of the frame (`alpha` is 0 then).
const WHOLE_STEP_SLACK: f64 = 1e-2;

impl FixedStepper {
    /// A stepper that runs at most `max_steps_per_frame` steps per frame.
    pub fn new(max_steps_per_frame: u32) -> Result<Self, StepperError> {
        if max_steps_per_frame == 0 {
            return Err(StepperError::ZeroStepCap);
        }
        Ok(Self {
            max_steps_per_frame,
            accumulator: 0.0,
            dropped_time: 0.0,
        })
    }

    /// Adds a frame's elapsed time (s) and returns how many steps of `settings`' time step to
    /// run and the interpolation factor. Time is accumulated in f64 so that long sessions do
    /// not drift.
    pub fn advance(
        &mut self,
        frame_time: f64,
        settings: &PhysicsSettings,
    ) -> Result<FrameSteps, StepperError> {
        if !(frame_time.is_finite() && frame_time >= 0.0) {
            return Err(StepperError::BadFrameTime(frame_time));
        }
        let dt = to_f64(settings.dt());
        self.accumulator += frame_time;
        let whole = (self.accumulator / dt + WHOLE_STEP_SLACK).floor().max(0.0);
        let cap = to_f64(self.max_steps_per_frame);
        let steps = whole.min(cap);
        self.accumulator -= steps * dt;
        if whole > cap {
            // Keep less than one step of backlog: drop the rest and remember how much.
            let keep = self.accumulator.rem_euclid(dt);
            self.dropped_time += self.accumulator - keep;
            self.accumulator = keep;
        }
        Ok(FrameSteps {
            steps: steps as u32,
            alpha: (self.accumulator / dt).clamp(0.0, 1.0) as Real,
        })
    }

    /// Total simulated time dropped by the step cap so far (s).
    pub fn dropped_time(&self) -> f64 {
        self.dropped_time
    }
}

/// Interpolates a pose for rendering: linear in translation, spherical (slerp) in rotation.
pub fn interpolate(previous: &Pose, current: &Pose, alpha: Real) -> Pose {
    Pose {
        translation: Vec3::lerp(previous.translation, current.translation, alpha),
        rotation: previous.rotation.slerp(current.rotation, alpha),
    }
}
