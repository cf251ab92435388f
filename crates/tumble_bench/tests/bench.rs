//! The benchmark runs end to end on small worlds, its JSON has the documented shape, the
//! engines agree bit for bit (checked inside the run), and the targets are evaluated.

use tumble_bench::{BenchOptions, output, run_bench};
use tumble_scene::text::replace_between_markers;

fn small() -> BenchOptions {
    BenchOptions {
        quick: true,
        max_bodies: Some(100),
        rapier_max_bodies: 10,
        out: None,
        readme: None,
    }
}

#[test]
fn small_run_measures_every_engine_and_writes_json() {
    let mut lines = Vec::new();
    let results = run_bench(&small(), |l| lines.push(l.to_owned()));
    assert!(lines.iter().any(|l| l.contains("bandwidth")));
    // Sizes 1, 10, 100 × two integrators.
    assert_eq!(results.rows.len(), 6);
    for row in &results.rows {
        for ns in [row.raw_1t, row.raw_2t, row.ecs_1t, row.ecs_2t] {
            assert!(ns.is_finite() && ns > 0.0, "{row:?}");
        }
        assert_eq!(row.rapier.is_some(), row.bodies <= 10, "{row:?}");
    }
    assert!(results.bandwidth_gb_s.iter().all(|b| *b > 0.1));
    // The fixed cost per step: a one-body world for each integrator.
    for integrator in tumble_bench::INTEGRATORS {
        assert!(
            results
                .rows
                .iter()
                .any(|r| r.bodies == 1 && r.integrator == integrator.name())
        );
    }
    // Targets that need big worlds are left out; the run's own duration is in, and met.
    let seconds = results
        .targets
        .iter()
        .find(|t| t.name.contains("--quick"))
        .expect("the quick run's duration is a target");
    assert!(seconds.value > 0.0 && seconds.value == results.seconds);
    assert!(!results.targets.iter().any(|t| t.name.contains("100000")));
    let json: serde_json::Value = serde_json::to_value(&results).unwrap();
    assert_eq!(json["schema"], 5);
    // Every integrator timed through the ECS and the raw loop, against the default.
    assert_eq!(results.methods.len(), tumble_core::Integrator::ALL.len());
    for row in &results.methods {
        let times = [
            row.raw_1t,
            row.ecs_1t,
            row.raw_2t,
            row.ecs_2t,
            row.splitting_ecs_1t,
        ];
        assert!(
            times.iter().all(|ns| ns.is_finite() && *ns > 0.0),
            "{row:?}"
        );
    }
    assert!(
        (0.5..=2.2).contains(&results.two_copy_ceiling),
        "{}",
        results.two_copy_ceiling
    );
    // Where, when and on which kernel path it ran.
    assert!(json["cpu"].as_str().is_some_and(|c| !c.is_empty()));
    assert!(
        json["date"]
            .as_str()
            .is_some_and(|d| d.len() == 20 && d.ends_with('Z'))
    );
    assert!(json["widest_kernel_path"].is_string());
    // The trajectory CSV: every body at every recorded step, at a finite rate.
    let csv = &results.csv[0];
    assert_eq!(csv.rows, csv.bodies as u64 * csv.recorded_steps);
    assert!(csv.megabytes_per_second.is_finite() && csv.megabytes_per_second > 0.0);
    assert!((40.0..200.0).contains(&csv.bytes_per_row), "{csv:?}");
    assert!(json["rows"][0]["ecs_1t"].is_number());
    assert!(json["rows"][0]["rapier"].is_number());
    let table = output::markdown(&results);
    assert!(table.contains("| bodies |") && table.contains("splitting"));
    assert!(table.contains("Threads: two independent one-thread loops"));
    // The kernel's count: the same as counting it directly, with every kind in the total.
    let f = results.kernel_flops;
    let counted = tumble_core::integrate::symmetric_rotation_flops(false);
    assert_eq!(
        (f.add, f.mul, f.div, f.sqrt),
        (counted.add, counted.mul, counted.div, counted.sqrt)
    );
    assert_eq!(f.total, f.add + f.mul + f.div + f.sqrt);
    assert!(table.contains(&format!("free rotation is {} flops per body-step", f.total)));
    assert!(json["kernel_flops"]["total"].as_u64() == Some(f.total));
    assert!(table.contains("**trajectory CSV**") && table.contains("rapier SpringJoint"));
    // The frame budget: the largest world of each kind, as bodies per 60 Hz frame, from the
    // same rows (100 free bodies here: 1/60 s over its ns per body-step).
    let budget = tumble_bench::budget::frame_budget(&results);
    let free = results
        .rows
        .iter()
        .filter(|r| r.integrator == "splitting")
        .max_by_key(|r| r.bodies)
        .unwrap();
    assert!(budget.contains(&format!("| free bodies under gravity | {} |", free.bodies)));
    assert!(budget.contains("spring chains, explicit (ωΔt 0.5)"));
    assert!(budget.contains("spring chains, implicit (ωΔt 10)"));
    assert!(budget.contains(&results.kernel_path));
    let row = budget
        .lines()
        .find(|l| l.starts_with("| free bodies"))
        .unwrap();
    let one: f64 = row
        .split('|')
        .nth(3)
        .unwrap()
        .trim()
        .replace('\u{2009}', "")
        .parse()
        .unwrap();
    let expected = 1e9 / 60.0 / free.ecs_1t;
    assert!((one / expected - 1.0).abs() < 0.01, "{row}: {expected}");
}

#[test]
fn the_frame_budget_replaces_only_between_its_markers() {
    let name = tumble_bench::budget::SECTION;
    let replace = |text, section| replace_between_markers(text, name, section);
    let text = "intro\n<!-- frame-budget:begin -->\nold\n<!-- frame-budget:end -->\noutro\n";
    let new = replace(text, "new\n").unwrap();
    assert_eq!(
        new,
        "intro\n<!-- frame-budget:begin -->\nnew\n<!-- frame-budget:end -->\noutro\n"
    );
    assert!(replace("no markers", "x").is_none());
}

#[test]
fn bytes_per_body_step_counts_the_ecs_data() {
    // Pose (32) + Velocity (24) read and written, MassProps read, two change ticks, in
    // f32; the vectors double in an `f64` build, the ticks do not.
    let bytes = tumble_bench::bytes_per_body_step();
    let (low, high) = if tumble_core::math::DOUBLE_PRECISION {
        (280, 450)
    } else {
        (150, 250)
    };
    assert!((low..=high).contains(&bytes), "{bytes}");
}
