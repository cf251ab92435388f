//! The exact flow against the closed-form top of `tumble_reference::exact` (an independent derivation:
//! Euler angles about the largest or smallest axis by case, the phase by Gauss–Legendre
//! quadrature, checked there against RK4 at h = 1e-4), in f64.

use glam::{DQuat, DVec3};

use super::exact_free_flow;
use crate::integrate::drift_kick_drift::FreeBody;
use tumble_reference::exact::TorqueFreeTop;

/// Angle of `a* b`, in radians, from its sine and cosine halves (`acos` of a dot product near 1
/// would floor at `2√ε ≈ 3e-8`).
fn angle(a: DQuat, b: DQuat) -> f64 {
    let d = a.conjugate() * b;
    2.0 * d.xyz().length().atan2(d.w.abs())
}

fn reciprocal(i: DVec3) -> DVec3 {
    DVec3::new(1.0 / i.x, 1.0 / i.y, 1.0 / i.z)
}

/// Orientation and body rates of the reference at time `t`.
type Reference = Box<dyn Fn(f64) -> (DQuat, DVec3)>;

/// The closed-form top (`tumble_reference::exact`).
fn closed_form(inertia: DVec3, omega0: DVec3, q0: DQuat) -> Reference {
    let top = TorqueFreeTop::new(inertia, omega0, q0).unwrap();
    Box::new(move |t| (top.orientation(t), top.body_angular_velocity(t)))
}

/// Classic RK4 at h = 1e-4 (`tumble_reference::rk4`), from `q0`: its own error is `≈ h⁴|ω|⁵t`, below
/// 1e-10 for the rates used with it. It stands in where the closed form's phase quadrature is
/// the harder problem: a thin body circling its largest axis, whose `φ̇` about that axis peaks
/// at `M/I₁` (the exact flow takes the smallest axis, where `φ̇` stays within `[M/I₃, M/I₂]`).
fn runge_kutta(inertia: DVec3, omega0: DVec3, q0: DQuat, h: f64, steps: usize) -> Reference {
    let times: Vec<f64> = (1..=steps).map(|k| k as f64 * h).collect();
    let path = tumble_reference::rk4::free_body(inertia, omega0, &times);
    Box::new(move |t| {
        let k = (t / h).round() as usize - 1;
        (q0 * path[k].0, path[k].1)
    })
}

/// Runs `steps` exact flows of `h` from the body rates `omega0` and orientation `q0`, and
/// returns the largest orientation and body-rate errors against the closed form on the way.
fn worst_errors(inertia: DVec3, omega0: DVec3, q0: DQuat, h: f64, steps: usize) -> (f64, f64) {
    let reference = closed_form(inertia, omega0, q0);
    worst_errors_against(&reference, inertia, omega0, q0, h, steps)
}

/// Asserts that the orientation error `dq` (rad) and the body-rate error `dw` are both below
/// `tolerance`.
fn assert_within((dq, dw): (f64, f64), tolerance: f64, case: String) {
    assert!(
        dq < tolerance && dw < tolerance,
        "{case}: orientation {dq:e} rad, rates {dw:e}"
    );
}

/// [`worst_errors`] against any reference.
fn worst_errors_against(
    reference: &Reference,
    inertia: DVec3,
    omega0: DVec3,
    q0: DQuat,
    h: f64,
    steps: usize,
) -> (f64, f64) {
    let r = reciprocal(inertia);
    let mut body = FreeBody {
        q: q0,
        m: inertia * omega0,
    };
    let (mut worst_q, mut worst_w) = (0.0f64, 0.0f64);
    for k in 1..=steps {
        exact_free_flow(&mut body, r, h);
        let t = k as f64 * h;
        let (q, w) = reference(t);
        worst_q = worst_q.max(angle(body.q, q));
        worst_w = worst_w.max((r * body.m - w).length() / omega0.length());
    }
    (worst_q, worst_w)
}

fn tilted() -> DQuat {
    DQuat::from_axis_angle(DVec3::new(0.3, -0.5, 0.8).normalize(), 0.9)
}

#[test]
fn matches_the_closed_form_at_any_step_and_spin() {
    // (inertia, body rates): both polhode cases, permuted axes (odd and even sorts), the thin
    // asymmetric body at |ω|Δt from 0.1 to 3 about tilted axes, and the Dzhanibekov handle.
    let cases = [
        (DVec3::new(1.0, 2.0, 3.0), DVec3::new(1.0, 5.0, 1.0)),
        (DVec3::new(1.0, 2.0, 3.0), DVec3::new(4.0, 1.0, 0.5)),
        (DVec3::new(1.0, 2.0, 3.0), DVec3::new(0.3, 1.0, 4.0)),
        (DVec3::new(3.0, 1.0, 2.0), DVec3::new(0.5, 4.0, -1.0)),
        (DVec3::new(2.0, 3.0, 1.0), DVec3::new(-2.0, 0.7, 3.0)),
        (DVec3::new(1.02, 1e-4, 1.0), DVec3::new(0.5, -30.0, 2.0)),
        (DVec3::new(0.02, 0.03, 0.04), DVec3::new(3.0, -2.0, 5.0)),
    ];
    for (inertia, omega0) in cases {
        for omega_dt in [0.1, 0.3, 1.0, 3.0] {
            let h = omega_dt / omega0.length();
            let steps = (2.0 / h).ceil() as usize;
            let (dq, dw) = worst_errors(inertia, omega0, tilted(), h, steps.min(400));
            // Round-off: ≈ ε per flow and the reference's 1e-13; 1e-10 leaves room for
            // the phase's growth over hundreds of flows, and is 1e5× below the target.
            assert_within(
                (dq, dw),
                1e-10,
                format!("I = {inertia}, ω₀ = {omega0}, |ω|Δt = {omega_dt}"),
            );
        }
    }
}

#[test]
fn the_thin_asymmetric_body_circling_its_largest_axis() {
    // I = (1e-4, 1, 1.02) with M² > 2EI₂: the long-axis rate swings up to 12.7 rad/s.
    let inertia = DVec3::new(1e-4, 1.0, 1.02);
    let omega0 = DVec3::new(6.0, 0.8, 0.5);
    for omega_dt in [0.1, 0.3, 1.0, 3.0] {
        let h = omega_dt / omega0.length();
        let steps = (2.0 / h).ceil() as usize;
        let reference = runge_kutta(inertia, omega0, tilted(), h, steps);
        let (dq, dw) = worst_errors_against(&reference, inertia, omega0, tilted(), h, steps);
        eprintln!("thin, |ω|Δt = {omega_dt}: {dq:e} rad, rates {dw:e}");
        assert_within((dq, dw), 1e-9, format!("|ω|Δt = {omega_dt}"));
    }
}

#[test]
fn one_long_flow_equals_many_short_ones() {
    // Exactness at any span: one flow of 7.3 s (many periods) against the reference.
    let inertia = DVec3::new(1.0, 2.0, 3.0);
    let omega0 = DVec3::new(1.0, 5.0, 1.0);
    let (dq, dw) = worst_errors(inertia, omega0, tilted(), 7.3, 1);
    assert!(dq < 1e-11 && dw < 1e-11, "{dq:e} {dw:e}");
}

#[test]
fn near_the_separatrix_and_near_axis_spins() {
    for (inertia, omega0, tolerance) in [
        // 1 − m ≈ 2e-6: the middle-axis rate flips rarely, the phase runs near K. Each flow
        // reads the invariants off a momentum rounded to ε, and the period's sensitivity to them
        // is 1/(1 − m): after N flows the error may reach N ε/(1 − m) ≈ 1.1e-8.
        (
            DVec3::new(1.0, 2.0, 3.0),
            DVec3::new(0.01, 10.0, 0.01),
            200.0 * f64::EPSILON / 2e-6,
        ),
        // A wobble of 1e-9 about the smallest and largest axes.
        (
            DVec3::new(1.0, 2.0, 3.0),
            DVec3::new(5.0, 1e-9, 1e-9),
            1e-11,
        ),
        (
            DVec3::new(1.0, 2.0, 3.0),
            DVec3::new(1e-9, 1e-9, 5.0),
            1e-11,
        ),
    ] {
        let (dq, dw) = worst_errors(inertia, omega0, tilted(), 0.05, 200);
        assert_within((dq, dw), tolerance, format!("I = {inertia}, ω₀ = {omega0}"));
    }
}

#[test]
fn symmetric_spherical_and_steady_bodies() {
    for (inertia, omega0) in [
        (DVec3::new(1.0, 1.0, 2.0), DVec3::new(1.0, 2.0, 3.0)),
        (DVec3::new(2.0, 1.0, 1.0), DVec3::new(1.0, 2.0, 3.0)),
        (DVec3::new(1e-4, 1.0, 1.0), DVec3::new(20.0, 3.0, -1.0)),
        (DVec3::new(1.5, 1.5, 1.5), DVec3::new(1.0, 2.0, 3.0)),
        (DVec3::new(1.0, 2.0, 3.0), DVec3::new(0.0, 4.0, 0.0)),
        (DVec3::new(1.0, 2.0, 3.0), DVec3::new(0.0, 0.0, -4.0)),
        (DVec3::new(1.0, 1.0, 3.0), DVec3::new(2.0, -1.0, 0.0)),
        (DVec3::new(1.0, 2.0, 3.0), DVec3::ZERO),
    ] {
        let (dq, dw) = worst_errors(inertia, omega0, tilted(), 0.37, 40);
        assert_within((dq, dw), 1e-12, format!("I = {inertia}, ω₀ = {omega0}"));
    }
}

#[test]
fn keeps_the_world_momentum_and_the_energy() {
    let inertia = DVec3::new(1e-4, 1.0, 1.02);
    let r = reciprocal(inertia);
    let mut body = FreeBody {
        q: tilted(),
        m: inertia * DVec3::new(6.0, 0.8, 0.5),
    };
    let world = body.q * body.m;
    let energy = |m: DVec3| (r * m).dot(m);
    let e0 = energy(body.m);
    for _ in 0..10_000 {
        exact_free_flow(&mut body, r, 0.1);
    }
    let drift = (body.q * body.m - world).length() / world.length();
    let energy_drift = (energy(body.m) - e0).abs() / e0;
    // Nothing is conserved by construction but by the closed form: each flow rounds, a few ε
    // (4 ε per flow bounds a drift that could even be biased).
    let bound = 10_000.0 * 4.0 * f64::EPSILON;
    assert!(
        drift < bound && energy_drift < bound,
        "{drift:e} {energy_drift:e}"
    );
}

#[test]
fn a_locked_axis_holds_the_body_rates() {
    // r₃ = 0: no rotation about axis 3; the body turns steadily about its fixed ω.
    let r = DVec3::new(1.0, 0.5, 0.0);
    let m = DVec3::new(2.0, -1.0, 0.0);
    let mut body = FreeBody { q: tilted(), m };
    let omega_world = tilted() * (r * m);
    exact_free_flow(&mut body, r, 1.3);
    assert_eq!(body.m, m);
    let expected = DQuat::from_scaled_axis(omega_world * 1.3) * tilted();
    assert!(angle(body.q, expected) < 1e-14);
}

#[test]
fn the_addition_theorems_agree_with_the_general_path() {
    // Both polhode cases, near the separatrix, thin bodies, forward and backward spans.
    let cases = [
        (DVec3::new(1.0, 0.5, 1.0 / 3.0), DVec3::new(1.0, 10.0, 3.0)),
        (DVec3::new(1.0, 0.5, 1.0 / 3.0), DVec3::new(4.0, 1.0, 0.5)),
        (
            DVec3::new(1.0, 0.5, 1.0 / 3.0),
            DVec3::new(0.01, 20.0, 0.03),
        ),
        (
            DVec3::new(100.0, 1.0, 1.0 / 1.01),
            DVec3::new(0.06, 0.8, 0.5),
        ),
        (
            DVec3::new(100.0, 1.0, 1.0 / 1.01),
            DVec3::new(0.03, 1.0, 0.5),
        ),
    ];
    let mut short_taken = 0;
    for (r, m) in cases {
        let polhode = super::Polhode::new(m, r);
        for h in [1e-3, 0.01, 0.05, -0.02, 0.2] {
            let Some((s_short, j_short)) = polhode.advance_short(m, h) else {
                continue;
            };
            short_taken += 1;
            let (s_any, j_any) = polhode.advance_any(m, h);
            let ds = (s_short - s_any).length() / m.length();
            let dj = (j_short - j_any).abs() / j_any.abs().max(1e-300);
            assert!(
                ds < 1e-13 && (dj < 1e-11 || (j_short - j_any).abs() < 1e-15),
                "r = {r}, m = {m}, h = {h}: momentum {ds:e}, integral {j_short:e} vs {j_any:e}"
            );
        }
    }
    assert!(short_taken >= 15, "the short path ran {short_taken} times");
}

#[test]
fn two_flows_at_once_give_the_bits_of_one_at_a_time() {
    // Both polhode cases, the separatrix (D = d₁₂m₁² − d₂₃m₃² = 0 exactly), a thin
    // body, a steady spin, a locked axis; short spans and spans that are not.
    let bodies = [
        (DVec3::new(1.0, 0.5, 1.0 / 3.0), DVec3::new(1.0, 10.0, 3.0)),
        (DVec3::new(1.0, 0.5, 1.0 / 3.0), DVec3::new(4.0, 1.0, 0.5)),
        (DVec3::new(1.0, 0.5, 0.375), DVec3::new(1.0, 2.0, 2.0)),
        (
            DVec3::new(100.0, 1.0, 1.0 / 1.01),
            DVec3::new(0.06, 0.8, 0.5),
        ),
        (DVec3::new(1.0, 0.5, 1.0 / 3.0), DVec3::new(0.0, 0.0, 2.0)),
        (DVec3::new(0.0, 0.5, 1.0 / 3.0), DVec3::new(0.3, 1.0, 2.0)),
    ];
    let q = DQuat::from_rotation_y(0.7) * DQuat::from_rotation_x(-0.4);
    for (i, &(ra, ma)) in bodies.iter().enumerate() {
        for &(rb, mb) in &bodies[i..] {
            for h in [1e-3, 0.05, -0.02, 0.7, 40.0] {
                let (mut a, mut b) = (FreeBody { q, m: ma }, FreeBody { q, m: mb });
                let (mut a1, mut b1) = (a, b);
                super::exact_free_flow_pair([&mut a, &mut b], [ra, rb], h);
                exact_free_flow(&mut a1, ra, h);
                exact_free_flow(&mut b1, rb, h);
                let bits = |f: FreeBody| {
                    (
                        f.q.to_array().map(f64::to_bits),
                        f.m.to_array().map(f64::to_bits),
                    )
                };
                for (pair, one) in [(a, a1), (b, b1)] {
                    assert_eq!(bits(pair), bits(one), "r = {ra}, {rb}; h = {h}");
                }
            }
        }
    }
}
