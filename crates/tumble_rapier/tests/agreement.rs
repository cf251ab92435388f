//! tumble against rapier 0.36: where both should agree they do, to round-off; where they
//! differ, tumble is closer to the exact solution, by at least the factor asserted.

use glam::DQuat;
use tumble_core::math::{Narrow, Quat, Real, Vec3, Widen, to_f64};
use tumble_core::{BodyState, Integrator, Mass, MassProperties};
use tumble_rapier::{ComparisonBody, ComparisonOptions, ComparisonScene, Load, compare};
use tumble_reference::rk4::free_body;

/// Round-off unit of the comparison: rapier runs in f32 whatever tumble's precision.
const RAPIER_EPS: f64 = f32::EPSILON as f64;

fn mass(m: Real, inertia: [Real; 3]) -> MassProperties {
    MassProperties::new(Mass::new(m).unwrap(), inertia.into()).unwrap()
}

/// Rapier with one solver iteration is a plain symplectic Euler step with the linearized
/// rotation update `q ← normalize((1 + ½Δt ω) q)`: tumble's `symplectic-euler-linear`.
fn textbook(steps: usize) -> ComparisonOptions {
    ComparisonOptions {
        integrator: Integrator::SymplecticEulerLinear,
        gyroscopic: true,
        rapier_solver_iterations: 1,
        steps,
        ..ComparisonOptions::default()
    }
}

#[test]
fn projectile_agrees_to_round_off() {
    let state = BodyState {
        position: Vec3::new(0.0, 10.0, 0.0),
        linear_velocity: Vec3::new(3.0, 12.0, -1.0),
        ..Default::default()
    };
    let scene = ComparisonScene {
        dt: 1.0 / 60.0,
        gravity: Some(Vec3::new(0.0, -9.81, 0.0)),
        bodies: vec![ComparisonBody::new(
            "ball",
            mass(2.0, [0.1, 0.1, 0.1]),
            state,
        )],
        springs: Vec::new(),
    };
    let result = compare(&scene, &textbook(600), None);
    let d = &result.bodies[0];
    // rapier runs in f32 whatever tumble's precision. 600 steps, positions up to ~60 m: f32 round-off of order n·ε·|x| ≈ 4e-3 m at worst.
    assert!(
        d.position < 600.0 * RAPIER_EPS * 60.0,
        "position difference {}",
        d.position
    );
    assert!(
        d.linear_velocity < 600.0 * RAPIER_EPS * 60.0,
        "velocity {}",
        d.linear_velocity
    );
}

fn spin_and_push_scene() -> ComparisonScene {
    let q0 = Quat::from_rotation_x(0.3);
    let spin = BodyState {
        rotation: q0,
        angular_velocity: q0 * Vec3::new(0.0, 0.0, 4.0),
        ..Default::default()
    };
    let pushed = BodyState {
        position: Vec3::new(5.0, 0.0, 0.0),
        ..Default::default()
    };
    ComparisonScene {
        dt: 1.0 / 60.0,
        gravity: None,
        bodies: vec![
            ComparisonBody::new("spinner", mass(1.0, [1.0, 2.0, 3.0]), spin),
            ComparisonBody::new("pushed", mass(3.0, [1.0, 1.0, 1.0]), pushed).with_load(
                Load::Force {
                    force: Vec3::new(1.5, -0.5, 0.25),
                    local_point: None,
                },
            ),
        ],
        springs: Vec::new(),
    }
}

#[test]
fn principal_axis_spin_and_force_at_com_agree_to_round_off() {
    let result = compare(&spin_and_push_scene(), &textbook(600), None);
    let (spin, push) = (&result.bodies[0], &result.bodies[1]);
    // The same linearized rotation about the same axis, but the gyroscopic terms round
    // differently (rapier rescales |L|): ω may drift apart by ~2ε|ω| per step, n·2ε|ω| ≈ 6e-4
    // after n = 600 steps, and the orientations by the integral of that, ½n²·2ε|ω|Δt ≈ 3e-3 rad.
    let (n, eps, w, dt) = (600.0, to_f64(RAPIER_EPS), 4.0, 1.0 / 60.0);
    assert!(
        to_f64(spin.angular_velocity) < n * 2.0 * eps * w,
        "{spin:?}"
    );
    assert!(spin.angle < 0.5 * n * n * 2.0 * eps * w * dt, "{spin:?}");
    // The same kick-then-drift update; positions up to ~60 m.
    assert!(push.position < 600.0 * RAPIER_EPS * 60.0, "{push:?}");
    // In f32 both engines do the same arithmetic (< 1e-5 apart). An f64 tumble leaves only
    // rapier's own f32 round-off: ≤ ½ε|v| per step with |v| ≤ 5.3 m/s (a = 0.53 m/s², 10 s).
    let v_tol = if tumble_core::math::DOUBLE_PRECISION {
        600.0 * 0.5 * RAPIER_EPS * 5.3
    } else {
        1e-5
    };
    assert!(push.linear_velocity < v_tol, "{push:?}");
}

#[test]
fn where_the_defaults_differ_tumble_is_exact() {
    let scene = spin_and_push_scene();
    let q0 = scene.bodies[0].state.rotation;
    let omega = scene.bodies[0].state.angular_velocity;
    let (x0, f, m) = (Vec3::new(5.0, 0.0, 0.0), Vec3::new(1.5, -0.5, 0.25), 3.0);
    let exact = move |i: usize, t: f64| {
        Some(if i == 0 {
            let q = DQuat::from_scaled_axis(omega.widen() * t) * q0.widen();
            BodyState {
                rotation: Quat::from_xyzw(q.x as Real, q.y as Real, q.z as Real, q.w as Real),
                ..Default::default()
            }
        } else {
            let x = x0.widen() + 0.5 * (f.widen() / m) * t * t;
            BodyState {
                position: x.narrow(),
                ..Default::default()
            }
        })
    };
    let options = ComparisonOptions {
        steps: 600,
        ..ComparisonOptions::default()
    };
    let result = compare(&scene, &options, Some(&exact));
    let (spin, push) = (&result.bodies[0], &result.bodies[1]);
    let (tumble_angle, rapier_angle) = spin.exact_angle.unwrap();
    // rapier's linearized rotation loses (|ω|Δt/4)³/3 per substep, 2.3e-6 rad over 4 substeps:
    // 1.4e-3 rad in 10 s. tumble's exact rotation is off by round-off only.
    assert!(
        tumble_angle * 10.0 < rapier_angle,
        "spin: tumble {tumble_angle} rapier {rapier_angle}"
    );
    let (tumble_pos, rapier_pos) = push.exact_position.unwrap();
    // Drift–kick–drift is exact for a constant force; rapier's symplectic Euler in 4 substeps is
    // off by ½ (F/m) (Δt/4) t = 0.011 m after 10 s.
    assert!(tumble_pos < 1e-4, "push: tumble {tumble_pos}");
    assert!(
        tumble_pos * 10.0 < rapier_pos,
        "push: tumble {tumble_pos} rapier {rapier_pos}"
    );
}

/// Largest orientation error of tumble (default) and rapier (defaults) against the exact top.
fn top_errors(omega0: Vec3, seconds: f64) -> (f64, f64) {
    let dt = 1.0 / 60.0;
    let steps = (seconds * 60.0) as usize;
    let inertia = Vec3::new(1.0, 2.0, 3.0);
    let state = BodyState {
        angular_velocity: omega0,
        ..Default::default()
    };
    let scene = ComparisonScene {
        dt,
        gravity: None,
        bodies: vec![ComparisonBody::new(
            "top",
            mass(1.0, inertia.to_array()),
            state,
        )],
        springs: Vec::new(),
    };
    let times: Vec<f64> = (1..=steps).map(|n| n as f64 / 60.0).collect();
    let exact = free_body(inertia.widen(), omega0.widen(), &times);
    let lookup = move |_: usize, t: f64| {
        let n = (t * 60.0).round() as usize;
        let (q, _) = exact[n - 1];
        let q = Quat::from_xyzw(q.x as Real, q.y as Real, q.z as Real, q.w as Real);
        Some(BodyState {
            rotation: q,
            ..Default::default()
        })
    };
    let options = ComparisonOptions {
        steps,
        ..ComparisonOptions::default()
    };
    let result = compare(&scene, &options, Some(&lookup));
    let errors = result.bodies[0].exact_angle.unwrap();
    eprintln!(
        "ω₀ = {omega0}, {seconds} s: max orientation error tumble {:.3e} rad, rapier {:.3e} rad; \
         rapier/tumble time per step {:.1}",
        errors.0,
        errors.1,
        result.speed_ratio()
    );
    errors
}

/// [`top_errors`], asserting that tumble's error is less than a tenth of rapier's; returns
/// tumble's.
fn tumble_ten_times_closer(omega0: Vec3, seconds: f64) -> f64 {
    let (tumble, rapier) = top_errors(omega0, seconds);
    assert!(
        tumble * 10.0 < rapier,
        "tumble {tumble} rad vs rapier {rapier} rad"
    );
    tumble
}

#[test]
fn middle_axis_spin_tumble_is_closer_to_exact() {
    // rapier's explicit gyroscopic step shifts the flip phase by radians within 20 s; the
    // splitting keeps the phase to a few hundredths of a radian.
    let tumble = tumble_ten_times_closer(Vec3::new(1.0, 5.0, 1.0), 20.0);
    assert!(tumble < 0.1, "tumble error {tumble}");
}

#[test]
fn stable_spin_about_largest_axis_tumble_is_closer_to_exact() {
    tumble_ten_times_closer(Vec3::new(0.01, 0.01, 10.0), 120.0);
}

#[test]
fn default_tumble_build_does_not_link_rapier() {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let out = std::process::Command::new(cargo)
        .args(["tree", "-p", "tumble", "-e", "normal", "--offline"])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("cargo tree runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let tree = String::from_utf8_lossy(&out.stdout);
    assert!(tree.contains("tumble_ecs"), "unexpected tree:\n{tree}");
    // Crate names, not paths: a checkout directory may itself be called `…rapier…`.
    assert!(
        !tree.contains("rapier3d ") && !tree.contains("tumble_rapier "),
        "rapier leaked into tumble's default tree:\n{tree}"
    );
}

/// A body tumble quarantines never reads as agreement: the comparison names the step, and a
/// non-finite state shows as NaN instead of being dropped by `max`.
#[test]
fn a_quarantined_body_is_reported_not_hidden() {
    let state = BodyState {
        angular_velocity: Vec3::new(1.0, 60.0, 1.0),
        ..Default::default()
    };
    let scene = ComparisonScene {
        dt: 1.0 / 60.0,
        gravity: None,
        bodies: vec![
            ComparisonBody::new("thin", mass(1.0, [0.01, 1.0, 1.005]), state),
            ComparisonBody::new("calm", mass(1.0, [1.0, 1.0, 1.0]), BodyState::default()),
        ],
        springs: Vec::new(),
    };
    let options = ComparisonOptions {
        integrator: Integrator::SymplecticEuler,
        steps: 2000,
        ..Default::default()
    };
    let result = compare(&scene, &options, None);
    let (thin, calm) = (&result.bodies[0], &result.bodies[1]);
    assert!(
        thin.tumble_rejected_at.is_some(),
        "the explicit step diverges and is quarantined"
    );
    assert!(!thin.is_clean());
    assert!(calm.is_clean(), "{calm:?}");
}
