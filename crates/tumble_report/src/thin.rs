//! The thin asymmetric plate at every spin rate: each integrator's orientation, energy and `|L|`
//! error over 10 s at 60 Hz, against the closed-form top ([`tumble_reference::exact::TorqueFreeTop`]).
//!
//! The plate `I = (0.01, 1, 1.01)` is as thin and as asymmetric as a rigid body can be (the
//! triangle inequality bounds `I₃ − I₂` by `I₁`); it spins about an axis tilted from all three
//! principal axes, `ω̂ ∝ (0.3, 1, 0.5)`, at `|ω|Δt` = 0.1, 0.3, 1 and 3.

use glam::{DQuat, DVec3};
use serde::Serialize;
use tumble_core::math::{Real, Vec3, Widen, to_f64};
use tumble_core::rotation::angle_between;
use tumble_core::{BodyState, Integrator, Mass, MassProperties, Wrench};
use tumble_reference::exact::TorqueFreeTop;

pub use crate::reference::PLATE;
use crate::reference::to_quat;

/// The spin rates measured, as `|ω|Δt`.
pub const OMEGA_DTS: [Real; 4] = [0.1, 0.3, 1.0, 3.0];

/// Time step (s) and horizon (s).
const DT: Real = 1.0 / 60.0;
const HORIZON: f64 = 10.0;

/// One integrator at one spin rate.
#[derive(Debug, Clone, Serialize)]
pub struct ThinRow {
    /// Integrator name.
    pub integrator: String,
    /// `|ω|Δt`.
    pub omega_dt: f64,
    /// Largest orientation error over the run (rad).
    pub orientation_error_rad: f64,
    /// Largest `|E/E₀ − 1|` over the run.
    pub energy_drift: f64,
    /// Largest `|L − L₀|/|L₀|` (world vector) over the run.
    pub momentum_drift: f64,
    /// The state stayed finite.
    pub finite: bool,
}

/// Energy and world momentum of `state` in f64.
fn invariants(state: &BodyState, inertia: DVec3) -> (f64, DVec3) {
    let q = state.rotation.widen().normalize();
    let w = q.conjugate() * state.angular_velocity.widen();
    let m = inertia * w;
    (0.5 * w.dot(m), q * m)
}

/// Runs `integrator` on the plate at `omega_dt`.
pub fn run(integrator: Integrator, omega_dt: Real) -> ThinRow {
    let omega0 = Vec3::new(0.3, 1.0, 0.5).normalize() * (omega_dt / DT);
    let mass = MassProperties::new(Mass::new(1.0).expect("valid"), PLATE).expect("valid");
    let top = TorqueFreeTop::new(PLATE.widen(), omega0.widen(), DQuat::IDENTITY)
        .expect("finite rates, positive moments");
    let mut state = BodyState {
        angular_velocity: omega0,
        ..Default::default()
    };
    let (e0, l0) = invariants(&state, PLATE.widen());
    let mut row = ThinRow {
        integrator: integrator.name().to_owned(),
        omega_dt: to_f64(omega_dt),
        orientation_error_rad: 0.0,
        energy_drift: 0.0,
        momentum_drift: 0.0,
        finite: true,
    };
    let steps = (HORIZON / DT.widen()).round() as usize;
    for k in 1..=steps {
        if integrator
            .try_step(&mut state, &mass, &Wrench::ZERO, DT)
            .is_err()
        {
            row.finite = false;
            break;
        }
        let t = k as f64 * DT.widen();
        let error = angle_between(state.rotation, to_quat(top.orientation(t)));
        let (e, l) = invariants(&state, PLATE.widen());
        row.orientation_error_rad = row.orientation_error_rad.max(error);
        row.energy_drift = row.energy_drift.max((e / e0 - 1.0).abs());
        row.momentum_drift = row.momentum_drift.max((l - l0).length() / l0.length());
    }
    row
}

/// Every integrator at every spin rate of [`OMEGA_DTS`].
pub fn table() -> Vec<ThinRow> {
    OMEGA_DTS
        .iter()
        .flat_map(|&w| Integrator::ALL.iter().map(move |&i| run(i, w)))
        .collect()
}
