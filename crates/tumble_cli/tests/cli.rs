//! The `tumble` binary: CSV exactly as specified, bit-identical to the library, clean failures.

mod common;

use common::{
    scene_path, scratch, scratch_dir, scratch_file, stdout, tumble, tumble_out, tumble_run,
};
use tumble_core::math::Real;
use tumble_ecs::prelude::*;
use tumble_scene::{CSV_HEADER, load_scene};

/// The systems `tumble run SCENE --plan` prints.
fn plan_of(scene: &str) -> String {
    stdout(&tumble_run(&["run", scene, "--plan"]))
}

#[test]
fn run_writes_the_specified_csv_bit_identical_to_the_library() {
    let (_dir, out) = scratch("chain.csv");
    let chain = scene_path("spring_chain");
    let args = ["run", &chain, "--steps", "50", "--every", "10"];
    assert!(tumble_out(&args, &out).status.success());
    let csv = std::fs::read_to_string(&out).unwrap();
    let mut lines = csv.lines();
    assert_eq!(lines.next(), Some(CSV_HEADER));
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len(), 3 * 6, "steps 0, 10, …, 50 for 3 bodies");
    assert!(rows.iter().all(|r| r.len() == 16));
    assert_eq!(rows[0][0], "0");
    // The library, stepped the same way, gives the same bits.
    let scene = load_scene(std::path::Path::new(&scene_path("spring_chain"))).unwrap();
    let mut built = scene.build();
    for _ in 0..50 {
        built.step();
    }
    for (k, (name, e)) in built.bodies.iter().enumerate() {
        let row = &rows[5 * 3 + k];
        assert_eq!((row[0], row[2]), ("50", name.as_str()));
        let t = built.world.get::<Pose>(*e).unwrap();
        let v = built.world.get::<Velocity>(*e).unwrap();
        let values: Vec<Real> = row[3..].iter().map(|x| x.parse().unwrap()).collect();
        let expected = [
            t.translation.x,
            t.translation.y,
            t.translation.z,
            t.rotation.x,
            t.rotation.y,
            t.rotation.z,
            t.rotation.w,
            v.linear.x,
            v.linear.y,
            v.linear.z,
            v.angular.x,
            v.angular.y,
            v.angular.z,
        ];
        for (a, b) in values.iter().zip(expected) {
            assert_eq!(a.to_bits(), b.to_bits(), "{name}");
        }
    }
}

#[test]
fn bad_scene_exits_non_zero_with_file_and_line_and_writes_nothing() {
    let (dir, bad) = scratch_file("bad.toml", "name = \"x\"\n[world]\ndt = -1.0\nsteps = 5\n");
    let out = dir.path().join("never.csv");
    let output = tumble()
        .args(["run"])
        .arg(&bad)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert!(!output.status.success());
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(stderr.contains("bad.toml:3: world.dt"), "{stderr}");
    assert_eq!(stderr.lines().count(), 1, "one line: {stderr}");
    assert!(!out.exists());
    let output = tumble_run(&["run", &scene_path("projectile"), "--dt", "0"]);
    assert!(!output.status.success());
    // A bad flag is named as the flag, not as a line of a file the user never wrote.
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(
        stderr.trim(),
        "error: --dt: expected a time step > 0, got 0"
    );
    for (flag, value, expected) in [
        ("--steps", "0", "error: --steps: expected 1 to"),
        (
            "--integrator",
            "magic",
            "error: --integrator: unknown integrator `magic`",
        ),
    ] {
        let output = tumble_run(&["run", "projectile", flag, value]);
        assert!(!output.status.success());
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(stderr.starts_with(expected), "{stderr}");
    }
    // The file's substeps, valid with its own step, too short under `--dt`: the flag is blamed
    // and the file's field named, never the scene's `name` as if it were the file.
    let (_dir, path) = scratch_file(
        "sub.toml",
        "name = \"SCENE-NAME\"\n[world]\ndt = 0.01\nsteps = 5\nsubsteps = 9\n\
         [[bodies]]\nname = \"a\"\nmass = 1.0\ninertia = [1.0, 1.0, 1.0]\n",
    );
    let shortest = 8.0 * tumble_core::error::TIME_STEP_RANGE.0;
    let output = tumble()
        .arg("run")
        .arg(&path)
        .args(["--dt", &shortest.to_string()])
        .output()
        .unwrap();
    assert_eq!(output.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        stderr.starts_with("error: --dt: with the scene file's `world.substeps`: 9 substeps"),
        "{stderr}"
    );
    assert!(!stderr.contains("SCENE-NAME"), "{stderr}");
}

#[test]
fn scenes_lists_the_bundled_scenes_and_plan_prints_the_systems() {
    let out = tumble().arg("scenes").output().unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    for name in [
        "projectile",
        "dzhanibekov",
        "spring_chain",
        "thin_rod",
        "thin_plate",
        "long_run",
        "stiff_chain",
        "cloth",
    ] {
        assert!(text.contains(name), "{text}");
    }
    let plan = plan_of("spinning_top");
    assert!(
        plan.contains("apply_constant_forces") && !plan.contains("apply_springs"),
        "{plan}"
    );
    // The projectile's bodies have no accumulator: gravity needs no system of its own.
    let plan = plan_of("projectile");
    let (systems, methods) = plan
        .split_once("method: ")
        .unwrap_or_else(|| panic!("{plan}"));
    assert!(
        systems.trim_end().ends_with("integrate_without_forces"),
        "{plan}"
    );
    assert_eq!(methods.trim_end(), "`splitting` (free flow `auto`)");
    assert!(!plan.contains("apply_gravity"), "{plan}");
}

#[test]
fn compare_reports_rapier_and_exact_differences() {
    let out = tumble_run(&["compare", "dzhanibekov"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&out.stdout);
    let row = text
        .lines()
        .find(|l| l.starts_with("t-handle"))
        .expect(&text);
    // The last column is "tumble / rapier" max orientation error against the exact top.
    let cells: Vec<&str> = row.split_whitespace().collect();
    let (ours, theirs): (f64, f64) = (
        cells[cells.len() - 3].parse().unwrap(),
        cells[cells.len() - 1].parse().unwrap(),
    );
    assert!(ours * 10.0 < theirs, "{row}");
    assert!(text.contains("rapier/tumble"), "{text}");
}

/// Springs are compared too: rapier's `SpringJoint` by default, the hand-written force on
/// request; the header names both engines' spring modes, and each engine's energy is printed.
#[test]
fn compare_accepts_springs_and_names_the_rapier_spring_mode() {
    for (flags, tumble_mode, rapier_mode) in [
        (&[][..], "springs `auto`", "springs `joint` = SpringJoint"),
        (
            &["--springs", "implicit", "--rapier-springs", "force"][..],
            "springs `implicit`",
            "springs `force` = add_force_at_point",
        ),
    ] {
        let out = tumble()
            .args(["compare", "spring_chain"])
            .args(flags)
            .output()
            .unwrap();
        let text = String::from_utf8_lossy(&out.stdout);
        assert!(
            out.status.success(),
            "{flags:?}: {}{text}",
            String::from_utf8_lossy(&out.stderr)
        );
        let header = text.lines().next().unwrap_or_default();
        assert!(header.contains(tumble_mode), "{header}");
        assert!(header.contains(rapier_mode), "{header}");
        assert!(
            text.lines().any(|l| l.starts_with("total energy")
                && l.contains("tumble")
                && l.contains("rapier")),
            "{text}"
        );
        for body in ["m1", "m2", "m3"] {
            assert!(text.lines().any(|l| l.starts_with(body)), "{text}");
        }
    }
    let out = tumble_run(&["compare", "spring_chain", "--rapier-springs", "spring"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        String::from_utf8_lossy(&out.stderr)
            .contains("--rapier-springs: unknown rapier spring mode"),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn gen_many_writes_a_valid_scene() {
    let dir = scratch_dir();
    let out = dir.path().join("many.toml");
    let status = tumble()
        .args(["gen", "many", "--n", "1000", "--steps", "5", "--out"])
        .arg(&out)
        .status()
        .unwrap();
    assert!(status.success());
    let scene = load_scene(&out).unwrap();
    assert_eq!(scene.file().bodies.len(), 1000);
    let run = tumble().args(["run"]).arg(&out).output().unwrap();
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    assert!(String::from_utf8_lossy(&run.stdout).contains("bodies     1000"));
    // The generator's headline size fits under the loader's size limit.
    let big = tumble_run(&["gen", "many", "--n", "100000"]);
    assert!(big.status.success());
    assert!((big.stdout.len() as u64) < tumble_scene::MAX_SCENE_BYTES);
}

/// The bundled thin plate runs under `exact` without a word. Under `splitting` with the default
/// `--free-flow auto` it takes the exact free flow, says so on stderr, and writes `exact`'s
/// trajectory; with `--free-flow method` it keeps the split and the planner names `exact`.
#[test]
fn the_thin_plate_runs_exactly_and_splitting_gives_way_or_is_told() {
    let out = tumble_run(&["run", "thin_plate"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(!stderr.contains("WARN"), "{stderr}");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("(exact)"), "{stdout}");

    let csv = |integrator: &str, free_flow: &str| {
        let out = tumble_run(&[
            "run",
            "thin_plate",
            "--integrator",
            integrator,
            "--free-flow",
            free_flow,
            "--out",
            "-",
        ]);
        let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
        assert!(out.status.success(), "{stderr}");
        (out.stdout, stderr)
    };
    let (exact, _) = csv("exact", "auto");
    let (auto, stderr) = csv("splitting", "auto");
    assert!(
        stderr.contains("body `plate`") && stderr.contains("exact free flow"),
        "{stderr}"
    );
    assert!(
        auto == exact,
        "the plate under `auto` is not stepped as `exact` steps it"
    );
    let (split, stderr) = csv("splitting", "method");
    assert!(
        stderr.contains("body `plate`") && stderr.contains("`exact`"),
        "{stderr}"
    );
    assert!(split != exact);
    let out = tumble_run(&["run", "thin_plate", "--integrator", "splitting", "--plan"]);
    let plan = String::from_utf8_lossy(&out.stdout);
    assert!(
        plan.contains("1 body takes the exact free flow (`exact`) now, first body `plate`"),
        "{plan}"
    );
    let out = tumble_run(&["run", "thin_plate", "--free-flow", "exactly"]);
    assert!(!out.status.success());
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("--free-flow: expected one of"),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// `--checksum` prints the library's `world_checksum` at step 0, at every recorded step and at
/// the end, the same on every run; with the trajectory on stdout it goes to stderr with the
/// summary.
#[test]
fn checksum_prints_the_library_checksum_at_every_recorded_step() {
    let run = || {
        let out = tumble_run(&[
            "run",
            &scene_path("spring_chain"),
            "--steps",
            "25",
            "--every",
            "10",
            "--checksum",
        ]);
        assert!(out.status.success());
        String::from_utf8_lossy(&out.stdout)
            .lines()
            .filter(|l| l.starts_with("checksum"))
            .map(str::to_owned)
            .collect::<Vec<_>>()
    };
    let lines = run();
    assert_eq!(lines, run(), "two runs, the same checksums");
    let steps: Vec<&str> = lines
        .iter()
        .map(|l| l.split_whitespace().nth(2).unwrap())
        .collect();
    assert_eq!(steps, ["0:", "10:", "20:", "25:"]);
    let scene = load_scene(std::path::Path::new(&scene_path("spring_chain"))).unwrap();
    let mut built = scene.build();
    for _ in 0..25 {
        built.step();
    }
    let expected = world_checksum(&built.world).to_string();
    assert!(lines[3].ends_with(&expected), "{} vs {expected}", lines[3]);
    // With the CSV on stdout, the checksums go to stderr.
    let out = tumble_run(&[
        "run",
        &scene_path("spring_chain"),
        "--steps",
        "5",
        "--checksum",
        "--out",
        "-",
    ]);
    assert!(String::from_utf8_lossy(&out.stderr).contains("checksum   step 5: "));
    assert!(!String::from_utf8_lossy(&out.stdout).contains("checksum"));
}
