//! Plain-data runs of one body (no ECS), the way the report and the raw benchmark loop do.

use tumble::core::invariants::{angular_momentum, kinetic_energy};
use tumble::math::{Real, Vec3, to_f64};

use tumble::prelude::*;

/// Summary of a torque-free run.
pub(crate) struct Run {
    /// Sign changes of the body rate about the middle principal axis (y).
    pub flips: u32,
    /// Final / initial kinetic energy − 1.
    pub energy_drift: f64,
    /// Largest |E/E₀ − 1| seen during the run.
    pub max_energy_drift: f64,
    /// Final / initial |L| − 1.
    pub momentum_drift: f64,
    /// Largest angle (deg) between the body-frame ω and its initial direction.
    pub max_axis_deviation_deg: f64,
    /// Final state.
    pub state: BodyState,
    /// True when the run stayed finite.
    pub finite: bool,
}

/// Body-frame angular velocity for a body whose principal frame is its body frame.
pub(crate) fn body_rate(state: &BodyState) -> Vec3 {
    tumble::core::integrate::rotate_inv(state.rotation, state.angular_velocity)
}

/// Runs a torque-free body with principal moments `inertia` from body rate `omega0`.
pub(crate) fn torque_free(
    integrator: Integrator,
    inertia: Vec3,
    omega0: Vec3,
    dt: Real,
    steps: usize,
) -> Run {
    let mass = MassProperties::new(Mass::new(1.0).unwrap(), inertia).unwrap();
    let mut state = BodyState {
        angular_velocity: omega0,
        ..Default::default()
    };
    let e0 = to_f64(kinetic_energy(&state, &mass));
    let l0 = to_f64(angular_momentum(&state, &mass).length());
    let axis0 = omega0.normalize();
    let mut flips = 0;
    let mut positive = omega0.y > 0.0;
    let mut max_energy_drift = 0.0_f64;
    let mut max_axis_deviation_deg = 0.0_f64;
    let mut finite = true;
    for _ in 0..steps {
        if integrator
            .try_step(&mut state, &mass, &Wrench::ZERO, dt)
            .is_err()
        {
            finite = false;
            break;
        }
        let w = body_rate(&state);
        if (w.y > 0.0) != positive {
            flips += 1;
            positive = w.y > 0.0;
        }
        let e = to_f64(kinetic_energy(&state, &mass));
        max_energy_drift = max_energy_drift.max((e / e0 - 1.0).abs());
        let cos = to_f64(w.normalize().dot(axis0)).clamp(-1.0, 1.0);
        max_axis_deviation_deg = max_axis_deviation_deg.max(cos.acos().to_degrees());
    }
    Run {
        flips,
        energy_drift: to_f64(kinetic_energy(&state, &mass)) / e0 - 1.0,
        max_energy_drift,
        momentum_drift: to_f64(angular_momentum(&state, &mass).length()) / l0 - 1.0,
        max_axis_deviation_deg,
        state,
        finite,
    }
}
