//! The report's measurements follow theory where theory is clear, and its JSON has the
//! documented shape.

use std::str::FromStr;

use tumble_core::Integrator;
use tumble_report::output::{Machine, Results};
use tumble_report::reference::cases;
use tumble_report::stability::matrix;
use tumble_report::workprec::{Effort, Method, measure};
use tumble_scene::text::replace_between_markers;

const EFFORT: Effort = Effort {
    batch: 1,
    repetitions: 1,
};

fn case(name: &str) -> tumble_report::reference::Case {
    cases().into_iter().find(|c| c.name == name).unwrap()
}

/// Error ratio per halving of Δt, from 1/`n` to 1/(2`n`).
fn ratio(scene: &str, integrator: Integrator, n: f64) -> f64 {
    let c = case(scene);
    let coarse = measure(&c, Method::Tumble(integrator), 1.0 / n, EFFORT);
    let fine = measure(&c, Method::Tumble(integrator), 0.5 / n, EFFORT);
    coarse.orientation_error_rad / fine.orientation_error_rad
}

/// Asserts that the JSON object `value` (at `path`) has every key of `keys`.
fn assert_has_keys(value: &serde_json::Value, path: &str, keys: &[&str]) {
    for key in keys {
        assert!(value.get(key).is_some(), "{path}.{key}");
    }
}

#[test]
fn error_falls_with_the_methods_order() {
    // Order p: 2^p per halving, on the stable top where the error (≫ the f32 floor of ≈1e-5 rad
    // over 10 s) is in the asymptotic range: rk4 from Δt = 1/15 s, splitting from 1/30 s.
    let rk4 = ratio("top-largest", Integrator::Rk4, 15.0);
    assert!((11.0..23.0).contains(&rk4), "rk4: {rk4} (theory 16)");
    let splitting = ratio("top-largest", Integrator::Splitting, 30.0);
    assert!(
        (3.2..5.0).contains(&splitting),
        "splitting: {splitting} (theory 4)"
    );
    let xyz = ratio("top-largest", Integrator::SplittingXyz, 60.0);
    assert!((3.2..5.0).contains(&xyz), "splitting-xyz: {xyz} (theory 4)");
}

#[test]
fn drift_kick_drift_is_exact_on_the_projectile_and_rapier_is_not() {
    let c = case("projectile");
    let tumble = measure(
        &c,
        Method::Tumble(Integrator::Splitting),
        1.0 / 60.0,
        EFFORT,
    );
    let rapier = measure(&c, Method::Rapier, 1.0 / 60.0, EFFORT);
    let euler = measure(
        &c,
        Method::Tumble(Integrator::SymplecticEuler),
        1.0 / 60.0,
        EFFORT,
    );
    // Symplectic Euler's bias ½ g Δt t = ½·9.81·(1/60)·5 = 0.41 m.
    assert!((euler.position_error_m - 0.409).abs() < 0.01, "{euler:?}");
    // rapier's 4 substeps cut the bias 4×.
    assert!((rapier.position_error_m - 0.102).abs() < 0.01, "{rapier:?}");
    // 300 steps of f32 round-off at ~50 m.
    assert!(tumble.position_error_m < 1e-3, "{tumble:?}");
}

#[test]
fn results_json_has_the_documented_shape() {
    let c = case("top-largest");
    let points = vec![measure(
        &c,
        Method::Tumble(Integrator::Splitting),
        1.0 / 60.0,
        EFFORT,
    )];
    let cells = matrix(true, || {}).into_iter().take(3).collect();
    let energy = tumble_report::energy::traces(2);
    let springs = tumble_report::springs::spring_runs(3, || {});
    let thin = tumble_report::thin::table();
    let results = Results::new(Machine::detect(true), points, cells, energy, springs, thin);
    let json: serde_json::Value = serde_json::to_value(&results).unwrap();
    assert_eq!(json["schema"], 1);
    let machine = ["cpu", "cores", "os", "tumble_version", "quick", "precision"];
    assert_has_keys(&json["machine"], "machine", &machine);
    let p = &json["work_precision"][0];
    let point = [
        "scene",
        "method",
        "dt_s",
        "steps",
        "orientation_error_rad",
        "position_error_m",
        "energy_drift",
        "momentum_drift",
        "ns_per_body_step",
        "finite",
    ];
    assert_has_keys(p, "work_precision[]", &point);
    assert!(p["orientation_error_rad"].as_f64().unwrap() < 1e-3);
    let cell = [
        "scene",
        "integrator",
        "setting",
        "finite",
        "max_quaternion_error",
        "energy_ratio",
        "energy_range",
        "springs",
        "warned",
    ];
    assert_has_keys(&json["stability"][0], "stability[]", &cell);
    assert_eq!(json["units"]["ns_per_body_step"], "ns");
    let e = &json["energy"][0];
    assert_eq!(
        e["relative_energy"].as_array().unwrap().len(),
        3,
        "t = 0, 1, 2 s"
    );
    assert!(e.get("spin").is_some() && e.get("method").is_some());
    let runs = json["springs"].as_array().unwrap();
    assert_eq!(runs.len(), 12, "4 variants × 3 ωΔt");
    let run = [
        "variant",
        "omega_dt",
        "energy_ratio",
        "failed_at",
        "us_per_step",
    ];
    assert_has_keys(&runs[0], "springs[]", &run);
    assert_eq!(runs[0]["energy_ratio"].as_array().unwrap().len(), 4);
    // The explicit chain at ωΔt = 10 is quarantined at step 2: null from there, not a number.
    let explicit = runs
        .iter()
        .find(|r| r["variant"] == "tumble explicit" && r["omega_dt"] == 10.0)
        .unwrap();
    assert_eq!(explicit["failed_at"], 2);
    assert!(explicit["energy_ratio"][3].is_null(), "{explicit}");
}

#[test]
fn stability_predictions_agree_with_the_matrix() {
    let springs = ["stiff-spring", "stiff-chain", "cloth-16x16"];
    for cell in matrix(true, || {}) {
        if springs.contains(&cell.scene.as_str()) {
            // Warned exactly where the run is unstable (at √(k/m)Δt = 2 exactly the amplitude
            // grows linearly: finite, but the energy leaves any bound).
            assert_eq!(cell.warned, !cell.stable(), "{cell:?}");
            // The implicit spring step (`auto` on these stiff scenes) keeps the total energy
            // within 5 % at every step, at every stiffness; a first-order method cannot be
            // combined with it and is refused there (warned, not run).
            if cell.springs == "auto" {
                let first_order = !Integrator::from_str(&cell.integrator)
                    .unwrap()
                    .turns_at_constant_momentum();
                let expected = if first_order && cell.refused {
                    "refused"
                } else {
                    "right"
                };
                assert_eq!(cell.verdict(), expected, "{cell:?}");
                assert!(!cell.refused || (first_order && cell.warned), "{cell:?}");
            }
        }
        if cell.integrator == "splitting" && cell.springs != "explicit" {
            assert!(cell.finite && cell.max_quaternion_error < 1e-6, "{cell:?}");
        }
    }
}

#[test]
fn readme_markers_are_replaced() {
    let text = "intro\n<!-- report:begin -->\nold\n<!-- report:end -->\nrest";
    let new = replace_between_markers(text, "report", "| new |\n").unwrap();
    assert_eq!(
        new,
        "intro\n<!-- report:begin -->\n| new |\n<!-- report:end -->\nrest"
    );
    assert!(replace_between_markers("no markers", "report", "x").is_none());
}

/// Storing the state in `f32` rounds every stored number in an `f64` build and changes nothing
/// in an `f32` build, where the state already is `f32`.
#[test]
fn f32_storage_rounds_exactly_what_the_f32_build_stores() {
    use bevy_ecs::prelude::*;
    use tumble_core::math::{DOUBLE_PRECISION, Quat, Real, Vec3};
    use tumble_ecs::prelude::{Pose, RigidBody, Velocity};
    let mut world = World::new();
    let tenth = 0.1 as Real;
    let body = world
        .spawn((
            RigidBody,
            Pose::from_translation(Vec3::splat(tenth)),
            Velocity::new(Vec3::splat(tenth), Vec3::splat(tenth)),
        ))
        .id();
    world.get_mut::<Pose>(body).unwrap().rotation =
        Quat::from_xyzw(tenth, 0.0, 0.0, (1.0 - tenth * tenth).sqrt());
    tumble_report::storage::store_as_f32(&mut world);
    let stored = 0.1f32 as Real;
    let (pose, velocity) = (
        world.get::<Pose>(body).unwrap(),
        world.get::<Velocity>(body).unwrap(),
    );
    for x in [
        pose.translation.x,
        pose.rotation.x,
        velocity.linear.y,
        velocity.angular.z,
    ] {
        assert_eq!(x.to_bits(), stored.to_bits());
    }
    assert_eq!(stored == tenth, !DOUBLE_PRECISION);
}

/// The table has a row per scene in an `f64` build, with the storage cost measured (finite and
/// non-zero on the spinning tops: thousands of roundings do move them), and none in an `f32`
/// build.
#[test]
fn the_f32_storage_table_measures_every_scene_in_f64_only() {
    let cases = cases();
    let rows = tumble_report::storage::storage_table(&cases);
    if !tumble_core::math::DOUBLE_PRECISION {
        assert!(rows.is_empty());
        return;
    }
    assert_eq!(rows.len(), cases.len());
    for r in &rows {
        assert!(
            r.f64_error_rad.is_finite() && r.f64_error_m.is_finite(),
            "{r:?}"
        );
        assert!(
            r.f32_storage_rad.is_finite() && r.f32_storage_m.is_finite(),
            "{r:?}"
        );
    }
    for top in ["top-largest", "top-smallest", "dzhanibekov"] {
        let r = rows.iter().find(|r| r.scene == top).unwrap();
        // f32 rounding is 6e-8 relative per number; thousands of steps leave far more than the
        // f64 state's own 1e-16, and far less than a radian.
        assert!(r.f32_storage_rad > 1e-9 && r.f32_storage_rad < 0.5, "{r:?}");
    }
}
