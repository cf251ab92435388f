//! Springs in both engines: tumble's explicit and implicit spring steps and rapier's two ways
//! (`SpringJoint`, a force added by hand) against the exact oscillator, and the anchor mapping
//! (body origin vs centre of mass) checked by convergence in Δt.

use tumble_core::math::{Quat, Real, Vec3, to_f64};
use tumble_core::{BodyState, Mass, MassProperties};
use tumble_ecs::prelude::SpringSolver;
use tumble_rapier::{
    ComparisonBody, ComparisonOptions, ComparisonScene, ComparisonSpring, ComparisonSpringEnd,
    RapierSprings, compare,
};

const DT: Real = 1.0 / 60.0;
/// Initial stretch of the two-body spring (m).
const STRETCH: f64 = 0.1;
const REST: Real = 1.0;

fn unit_mass() -> MassProperties {
    MassProperties::new(Mass::new(1.0).unwrap(), Vec3::new(0.1, 0.1, 0.1)).unwrap()
}

/// Two unit masses on a spring through their centres, stretched by [`STRETCH`], at rest:
/// `√(k/μ)Δt = omega_dt` with `μ = ½`.
fn two_bodies(omega_dt: Real) -> ComparisonScene {
    let half = 0.5 * (REST + STRETCH as Real);
    let at = |x: Real| BodyState {
        position: Vec3::new(x, 0.0, 0.0),
        ..Default::default()
    };
    ComparisonScene {
        springs: vec![ComparisonSpring {
            a: 0,
            anchor_a: Vec3::ZERO,
            b: ComparisonSpringEnd::Body {
                body: 1,
                anchor: Vec3::ZERO,
            },
            stiffness: 0.5 * (omega_dt / DT).powi(2),
            damping: 0.0,
            rest_length: REST,
        }],
        ..ComparisonScene::new(
            DT,
            None,
            vec![
                ComparisonBody::new("left", unit_mass(), at(-half)),
                ComparisonBody::new("right", unit_mass(), at(half)),
            ],
        )
    }
}

fn options(
    springs: SpringSolver,
    rapier_springs: RapierSprings,
    steps: usize,
) -> ComparisonOptions {
    ComparisonOptions {
        springs,
        rapier_springs,
        steps,
        ..ComparisonOptions::default()
    }
}

/// Largest position error (m) of (tumble, rapier) against the exact oscillator
/// `x = ±(L₀ + A cos ωt)/2` over `steps` steps.
fn oscillator_errors(
    omega_dt: Real,
    springs: SpringSolver,
    rapier_springs: RapierSprings,
    steps: usize,
) -> (f64, f64) {
    let scene = two_bodies(omega_dt);
    let omega = to_f64(omega_dt) / to_f64(DT);
    let exact = move |i: usize, t: f64| {
        let half = 0.5 * (to_f64(REST) + STRETCH * (omega * t).cos());
        let x = if i == 0 { -half } else { half };
        Some(BodyState {
            position: Vec3::new(x as Real, 0.0, 0.0),
            ..Default::default()
        })
    };
    let result = compare(
        &scene,
        &options(springs, rapier_springs, steps),
        Some(&exact),
    );
    let mut worst = (0.0_f64, 0.0_f64);
    for body in &result.bodies {
        assert!(body.is_clean(), "{body:?}");
        let (t, r) = body.exact_position.unwrap();
        worst = (worst.0.max(t), worst.1.max(r));
    }
    eprintln!(
        "{springs} / rapier {rapier_springs}: exact Δx tumble {:.3e} rapier {:.3e}",
        worst.0, worst.1
    );
    worst
}

/// At `ωΔt = 0.1` over 600 steps (ωt = 60 rad, 9.5 periods) both tumble modes are second
/// order: the explicit step's phase lags `(ωΔt)³/24` per step, the implicit midpoint's
/// `(ωΔt)³/12`; each body moves with amplitude `A/2`, so the error stays below
/// `n (ωΔt)³/12 · A/2 = 2.5e-3` m (asserted with a factor 1.5).
///
/// rapier's springs are first order: its joint is implicit Euler in the spring per substep
/// (energy × `1/(1 + (ωΔt/4)²)` per substep, ≈ `1 − (ωΔt)²/4` per step), the hand-written force
/// is held over the step's four substeps (energy × ≈ `1 + (3/8)(ωΔt)²` per step). Either way the
/// amplitude drifts by `O(ωΔt)` of itself per radian of motion: over `ωt` the error is
/// `O(ωΔt · ωt · A/2)`, asserted with the coefficient ¼ over 120 steps (ωt = 12; the expected
/// drifts are 1/8 and 3/16: 0.0075 m and 0.011 m).
#[test]
fn low_stiffness_all_four_follow_the_exact_oscillator() {
    let omega_dt = 0.1;
    let w = to_f64(omega_dt);
    let (n_tumble, n_rapier) = (600usize, 120usize);
    let second_order = 1.5 * n_tumble as f64 * w.powi(3) / 12.0 * STRETCH / 2.0;
    let first_order = 0.25 * w * (w * n_rapier as f64) * STRETCH / 2.0;
    for (springs, rapier_springs) in [
        (SpringSolver::Explicit, RapierSprings::Joint),
        (SpringSolver::Implicit, RapierSprings::Force),
    ] {
        let (tumble, _) = oscillator_errors(omega_dt, springs, rapier_springs, n_tumble);
        assert!(
            tumble < second_order,
            "tumble {springs}: {tumble} m ≥ {second_order} m"
        );
        let (_, rapier) = oscillator_errors(omega_dt, springs, rapier_springs, n_rapier);
        assert!(
            rapier < first_order,
            "rapier {rapier_springs}: {rapier} m ≥ {first_order} m"
        );
    }
}

/// A body with its centre of mass off its origin, spinning, on a spring at an off-centre anchor
/// to a world point and on a second spring to another body's off-centre anchor. Anchors are
/// relative to the body origin in both engines; mapped wrongly (e.g. taken from the centre of
/// mass), the engines would differ by `O(1)` whatever the step. Mapped right they differ by
/// the methods' own errors, `O(Δt)` here (rapier is first order): quartering Δt over the same
/// 0.5 s must shrink the largest difference at least 2.5×.
#[test]
fn off_centre_anchors_agree_to_first_order_in_dt() {
    let difference = |dt: Real, rapier_springs: RapierSprings| {
        let steps = (0.5 / to_f64(dt)).round() as usize;
        let shifted = unit_mass()
            .with_center_of_mass(Vec3::new(0.1, -0.05, 0.08))
            .unwrap();
        let spinning = BodyState {
            rotation: Quat::from_rotation_z(0.3),
            angular_velocity: Vec3::new(0.5, -0.3, 1.0),
            linear_velocity: Vec3::new(0.0, 0.2, 0.0),
            ..Default::default()
        };
        let other = BodyState {
            position: Vec3::new(1.2, 0.1, 0.0),
            angular_velocity: Vec3::new(0.0, 0.4, -0.2),
            ..Default::default()
        };
        let k = 0.5 * (0.1 / (1.0 / 60.0 as Real)).powi(2);
        let spring = |a, anchor_a, b| ComparisonSpring {
            a,
            anchor_a,
            b,
            stiffness: k,
            damping: 0.0,
            rest_length: 0.5,
        };
        let scene = ComparisonScene {
            springs: vec![
                spring(
                    0,
                    Vec3::new(-0.2, 0.1, 0.0),
                    ComparisonSpringEnd::World(Vec3::new(-1.0, 0.0, 0.0)),
                ),
                spring(
                    0,
                    Vec3::new(0.2, 0.05, 0.1),
                    ComparisonSpringEnd::Body {
                        body: 1,
                        anchor: Vec3::new(-0.1, 0.1, -0.05),
                    },
                ),
            ],
            ..ComparisonScene::new(
                dt,
                None,
                vec![
                    ComparisonBody::new("shifted", shifted, spinning),
                    ComparisonBody::new("other", unit_mass(), other),
                ],
            )
        };
        let result = compare(
            &scene,
            &options(SpringSolver::Explicit, rapier_springs, steps),
            None,
        );
        result
            .bodies
            .iter()
            .map(|b| {
                assert!(b.is_clean(), "{b:?}");
                to_f64(b.position)
            })
            .fold(0.0, f64::max)
    };
    for rapier_springs in RapierSprings::ALL {
        let coarse = difference(1.0 / 60.0, rapier_springs);
        let fine = difference(1.0 / 240.0, rapier_springs);
        eprintln!("rapier {rapier_springs}: max Δx {coarse:.3e} at 1/60, {fine:.3e} at 1/240");
        assert!(
            coarse < 0.02,
            "{rapier_springs}: {coarse} m apart at Δt = 1/60"
        );
        assert!(
            fine * 2.5 < coarse,
            "{rapier_springs}: {coarse} m at 1/60, {fine} m at 1/240: not converging together"
        );
    }
}

/// The energy series of a comparison: one value per step plus the initial one; tumble's turns
/// NaN once it quarantines a body (here the explicit step at `ωΔt = 3` diverges).
#[test]
fn energy_series_are_recorded_and_a_quarantine_shows_as_nan() {
    let result = compare(
        &two_bodies(3.0),
        &options(SpringSolver::Explicit, RapierSprings::Joint, 200),
        None,
    );
    assert_eq!(result.tumble_energy.len(), 201);
    assert_eq!(result.rapier_energy.len(), 201);
    let e0 = 0.5 * 0.5 * (3.0 * 60.0_f64).powi(2) * STRETCH * STRETCH;
    assert!(
        (result.tumble_energy[0] / e0 - 1.0).abs() < 1e-5,
        "{}",
        result.tumble_energy[0]
    );
    assert!(result.bodies.iter().any(|b| b.tumble_rejected_at.is_some()));
    assert!(result.tumble_energy.last().unwrap().is_nan());
    // rapier's joint is implicit in the spring: finite, and it never gains energy.
    assert!(
        result
            .rapier_energy
            .iter()
            .all(|e| e.is_finite() && *e <= result.rapier_energy[0] * (1.0 + 1e-4)),
        "{:?}",
        &result.rapier_energy[..10]
    );
}
