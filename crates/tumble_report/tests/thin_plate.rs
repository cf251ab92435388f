//! The report's thin-plate table: `exact` and `exact4` stay at the storage floor at every spin
//! rate, and are the only methods that do at `|ω|Δt = 3`.

use tumble_core::Integrator;
use tumble_core::math::{Real, to_f64};
use tumble_report::thin::{OMEGA_DTS, run};

/// The storage floor of 600 steps at `|ω|Δt`: each step rounds `q` (16 ε per step bounds it, see
/// `tests/integrators/exact.rs`) and re-reads the invariants `E`, `|L|` from a rounded `ω`, a
/// random walk of `ε √N` in the rates whose phase error grows with the angle turned,
/// `|ω| T = N |ω|Δt`; plus the closed form's 1e-9.
fn floor(omega_dt: Real) -> f64 {
    let (eps, n) = (to_f64(Real::EPSILON), 600.0_f64);
    16.0 * eps * n + eps * n.sqrt() * n * to_f64(omega_dt) + 1e-9
}

#[test]
fn exact_is_at_the_storage_floor_at_every_spin_rate() {
    for (omega_dt, integrator) in OMEGA_DTS
        .into_iter()
        .flat_map(|w| [(w, Integrator::Exact), (w, Integrator::Exact4)])
    {
        let row = run(integrator, omega_dt);
        eprintln!("{row:?}");
        assert!(row.finite);
        let floor = floor(omega_dt);
        assert!(
            row.orientation_error_rad <= floor,
            "|ω|Δt = {omega_dt}: {:e} rad (floor {floor:e})",
            row.orientation_error_rad
        );
        assert!(row.energy_drift <= floor && row.momentum_drift <= floor);
    }
}

#[test]
fn at_three_radians_per_step_only_exact_is_right() {
    let exact = run(Integrator::Exact, 3.0).orientation_error_rad;
    for integrator in Integrator::ALL.iter().copied() {
        if integrator.is_exact_torque_free() {
            continue;
        }
        let row = run(integrator, 3.0);
        eprintln!("{row:?}");
        assert!(
            !row.finite || row.orientation_error_rad > 100.0 * exact,
            "{integrator}: {:e} rad against exact's {exact:e}",
            row.orientation_error_rad
        );
    }
}
