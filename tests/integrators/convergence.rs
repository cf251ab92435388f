//! Observed order of convergence on the torque-free asymmetric top, I = diag(1, 2, 3), 4 s.
//!
//! The error is the orientation angle at the horizon against a reference. Each method is
//! measured in its asymptotic window: large enough steps that the f32 round-off floor of the
//! state (≈ 1e-7 rad per step) is far below the truncation error, small enough that `|ω|Δt` is
//! in the asymptotic regime. The slope of log(error) against log(Δt), fitted by least squares,
//! must be within ±0.3 of the nominal order. `exact` has no truncation error: its error must stay
//! at the round-off floor at every step.

use tumble::core::rotation::angle_between;
use tumble::math::{Quat, Real, Vec3, Widen, to_f64};
use tumble_reference::rk4::free_body;

use tumble::prelude::*;

const I: Vec3 = Vec3::new(1.0, 2.0, 3.0);
const HORIZON: f64 = 4.0;

fn orientation_error(integrator: Integrator, omega0: Vec3, steps_per_second: u32) -> f64 {
    let mass = MassProperties::new(Mass::new(1.0).unwrap(), I).unwrap();
    let dt = 1.0 / steps_per_second as Real;
    let mut state = BodyState {
        angular_velocity: omega0,
        ..Default::default()
    };
    for _ in 0..(HORIZON as u32 * steps_per_second) {
        integrator.step(&mut state, &mass, &Wrench::ZERO, dt);
    }
    let (e, _) = free_body(I.widen(), omega0.widen(), &[HORIZON])[0];
    // Rounding the reference to f32 costs ≈ 6e-8 rad, far below the errors measured here.
    angle_between(
        state.rotation,
        Quat::from_xyzw(e.x as Real, e.y as Real, e.z as Real, e.w as Real),
    )
}

/// Least-squares slope of log(error) against log(Δt).
fn observed_order(errors: &[(u32, f64)]) -> f64 {
    let pts: Vec<(f64, f64)> = errors
        .iter()
        .map(|&(n, e)| ((1.0 / to_f64(n)).ln(), e.ln()))
        .collect();
    let k = pts.len() as f64;
    let (sx, sy) = pts
        .iter()
        .fold((0.0, 0.0), |(a, b), &(x, y)| (a + x, b + y));
    let (mx, my) = (sx / k, sy / k);
    let num: f64 = pts.iter().map(|&(x, y)| (x - mx) * (y - my)).sum();
    let den: f64 = pts.iter().map(|&(x, _)| (x - mx) * (x - mx)).sum();
    num / den
}

#[test]
fn every_integrator_converges_at_its_nominal_order() {
    let slow = Vec3::new(0.6, 1.5, 0.9);
    let fast = Vec3::new(1.2, 3.0, 1.8);
    for &integrator in Integrator::ALL {
        // (initial rate, steps per second) windows, chosen per order as explained above.
        // Yoshida's error constant is ~20× smaller than RK4's, so it meets the f32 floor
        // (≈ 1e-5 rad after 64 steps) at larger steps.
        let (omega0, rates): (Vec3, &[u32]) = match (integrator.order(), integrator) {
            (1, _) => (slow, &[32, 64, 128, 256]),
            (2, _) => (slow, &[4, 8, 16]),
            (_, Integrator::Yoshida4) => (fast, &[4, 6, 8]),
            _ => (fast, &[12, 16, 24]),
        };
        let errors: Vec<(u32, f64)> = rates
            .iter()
            .map(|&n| (n, orientation_error(integrator, omega0, n)))
            .collect();
        if integrator.is_exact_torque_free() {
            // No truncation error to converge: only the state's rounding, at most a few ε per
            // step (plus the f64 reference's 1e-12 and its rounding to the build precision).
            for &(n, error) in &errors {
                let steps = HORIZON * f64::from(n);
                let floor = steps * 4.0 * to_f64(Real::EPSILON) + 1e-11;
                assert!(
                    error <= floor,
                    "{integrator}: {error:e} rad at {n} steps/s, above the round-off floor {floor:e}"
                );
            }
            continue;
        }
        let order = observed_order(&errors);
        eprintln!("{integrator}: observed order {order:.2} from {errors:?}");
        assert!(
            (order - to_f64(integrator.order())).abs() <= 0.3,
            "{integrator}: observed order {order:.2} (nominal {}), errors {errors:?}",
            integrator.order()
        );
    }
}
