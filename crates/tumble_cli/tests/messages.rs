//! The CLI talks: tumble's own messages for bad numbers, one line per error, named arguments,
//! log output on stderr (`RUST_LOG`, `-v`, `-q`), documented exit codes, a progress bar on a
//! terminal.

mod common;

use std::path::Path;
use std::process::Command;

use common::{
    BadValues, bad_value_runs, error_line, failure, last_error_line, scratch, scratch_dir,
    scratch_file, stderr, tumble, tumble_out, tumble_run,
};
use tumble_scene::CSV_HEADER;

/// The bundled chain at a step of 0.2 s with the explicit spring step: √(k/μ)Δt ≈ 9, far outside
/// its stable region.
const EXPLICIT_CHAIN: [&str; 6] = [
    "run",
    "spring_chain",
    "--dt",
    "0.2",
    "--springs",
    "explicit",
];

#[test]
fn negative_numbers_reach_tumbles_own_checks() {
    let cases: [BadValues; 4] = [
        ("--dt", "expected a time step > 0", &["-1"]),
        // Past `u64` too: tumble's own message and exit code 1, as for any other value out of
        // range (it was clap's "too large", exit 2).
        (
            "--steps",
            "expected 1 to 1000000000 steps",
            &["-5", "18446744073709551616"],
        ),
        ("--every", "expected a value >= 1", &["-2", "0"]),
        (
            "--substeps",
            "expected 1 to 1000 substeps",
            &["0", "-3", "1001"],
        ),
    ];
    for (args, expected, output) in bad_value_runs(&["run", "projectile"], &cases) {
        assert_eq!(output.status.code(), Some(1), "{args:?}");
        assert_eq!(error_line(&output), expected);
    }
    // Any count of at least 1 is a valid `--every`, the largest `u64` included.
    let output = tumble_run(&["run", "projectile", "--every", "18446744073709551615"]);
    assert!(output.status.success(), "{}", stderr(&output));
}

#[test]
fn usage_errors_are_one_line_with_exit_code_2() {
    let output = tumble_run(&["run", "projectile", "--bogus"]);
    assert_eq!(
        failure(&output, 2),
        "error: unexpected argument '--bogus' found (see --help)"
    );
    // A missing argument is named on the one line (clap puts it on a line of its own).
    for command in ["run", "compare"] {
        assert_eq!(
            failure(&tumble_run(&[command]), 2),
            "error: the following required arguments were not provided: <SCENE> (see --help)"
        );
    }
    // A value that is not a number: clap's message, on one line, naming the flag.
    let output = tumble_run(&["run", "projectile", "--dt", "fast"]);
    assert!(failure(&output, 2).contains("'--dt <DT>'"));
    // A negative size for the benchmark is a bad value of its flag, not an unknown argument.
    let output = tumble_run(&["bench", "--max-bodies", "-1"]);
    assert!(failure(&output, 2).starts_with("error: invalid value '-1' for '--max-bodies"));
    // So is an empty benchmark: no world to time (it panicked on an empty size list).
    let output = tumble_run(&["bench", "--quick", "--max-bodies", "0"]);
    assert!(failure(&output, 2).starts_with("error: invalid value '0' for '--max-bodies"));
    // Help is not an error.
    assert!(tumble().arg("--help").output().unwrap().status.success());
}

#[cfg(unix)]
#[test]
fn non_utf8_arguments_are_named_and_non_utf8_paths_work() {
    use std::ffi::OsString;
    use std::os::unix::ffi::OsStringExt;
    let dir = scratch_dir();
    let bad = |prefix: &str, suffix: &str| {
        let mut bytes = prefix.as_bytes().to_vec();
        bytes.push(0xff);
        bytes.extend_from_slice(suffix.as_bytes());
        OsString::from_vec(bytes)
    };
    // A scene file and an output whose names are not UTF-8 are ordinary files.
    let scene = dir.path().join(bad("scene", ".toml"));
    std::fs::copy(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/projectile.toml"),
        &scene,
    )
    .unwrap();
    let out = dir.path().join(bad("out", ".csv"));
    let output = tumble()
        .arg("run")
        .arg(&scene)
        .args(["--steps", "3", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(output.status.success(), "{}", stderr(&output));
    assert!(
        std::fs::read_to_string(&out)
            .unwrap()
            .starts_with(CSV_HEADER)
    );
    // A missing one is named (lossily) on one line.
    let missing = dir.path().join(bad("missing", ".toml"));
    let output = tumble().arg("run").arg(&missing).output().unwrap();
    assert!(failure(&output, 1).contains("missing\u{fffd}.toml"));
    // Values that must be text say which flag they belong to.
    for (flag, value, code) in [("--integrator", "rk", 1), ("--steps", "1", 2)] {
        let output = tumble()
            .args(["run", "projectile", flag])
            .arg(bad(value, ""))
            .output()
            .unwrap();
        assert_eq!(
            failure(&output, code),
            format!("error: {flag}: the value {value}\u{fffd} is not valid UTF-8")
        );
    }
}

#[test]
fn warnings_reach_stderr_and_follow_rust_log_and_the_flags() {
    // √(k/μ)Δt ≈ 9 for this chain: with the explicit spring step the planner warns before the
    // run (by default the implicit step takes such a chain, see below).
    let args = [&EXPLICIT_CHAIN[..], &["--steps", "3"]].concat();
    let output = tumble().args(&args).output().unwrap();
    let text = stderr(&output);
    assert!(
        text.contains("WARN") && text.contains("outside the stable region"),
        "{text}"
    );
    let quiet = tumble().arg("-q").args(&args).output().unwrap();
    assert!(!stderr(&quiet).contains("WARN"), "{}", stderr(&quiet));
    let off = tumble()
        .args(&args)
        .env("RUST_LOG", "off")
        .output()
        .unwrap();
    assert!(!stderr(&off).contains("WARN"), "{}", stderr(&off));
    // A malformed RUST_LOG is an error naming it, its control and bidi characters escaped
    // (the filter parser's own message echoed them raw, and the run went on without it).
    let hostile = "\u{1b}[2J\u{1b}]0;pwned\u{7}\u{202e}=x";
    let bad = tumble()
        .args(&args)
        .env("RUST_LOG", hostile)
        .output()
        .unwrap();
    let line = failure(&bad, 1);
    assert!(line.starts_with("error: RUST_LOG `"), "{line}");
    assert!(
        line.contains("\\u{1b}") && line.contains("\\u{202e}"),
        "{line}"
    );
    assert!(!stderr(&bad).contains('\u{1b}') && !stderr(&bad).contains('\u{202e}'));
    // Bytes that are not UTF-8 are no filter either (they were ignored without a word).
    #[cfg(unix)]
    {
        use std::os::unix::ffi::OsStrExt;
        let bytes = std::ffi::OsStr::from_bytes(b"\xff\xfe=trace");
        let bad = tumble()
            .args(&args)
            .env("RUST_LOG", bytes)
            .output()
            .unwrap();
        let line = failure(&bad, 1);
        assert!(line.starts_with("error: RUST_LOG `"), "{line}");
        assert!(line.contains("not valid Unicode"), "{line}");
    }
    // -vv lowers the level: the warnings stay; -q and -v together are a usage error.
    let verbose = tumble().arg("-vv").args(&args).output().unwrap();
    assert!(stderr(&verbose).contains("WARN"));
    let both = tumble().args(["-q", "-v"]).args(&args).output().unwrap();
    assert_eq!(both.status.code(), Some(2));
}

#[test]
fn a_rejected_body_exits_3_and_its_rows_stop() {
    let (_dir, out) = scratch("chain.csv");
    let unstable = [
        &["-q"][..],
        &EXPLICIT_CHAIN,
        &["--steps", "50", "--allow-unstable"],
    ]
    .concat();
    let output = tumble_out(&unstable, &out);
    assert_eq!(output.status.code(), Some(3), "{}", stderr(&output));
    assert_eq!(
        last_error_line(&output),
        "error: 3 of 3 bodies were rejected; their CSV rows stop at the step they were rejected on"
    );
    assert!(String::from_utf8_lossy(&output.stdout).contains("rejected   3 bodies"));
    let csv = std::fs::read_to_string(&out).unwrap();
    let last_step: u64 = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').next().unwrap().parse().unwrap())
        .max()
        .unwrap();
    assert!(last_step < 50, "rows up to step {last_step}");
    for line in csv.lines().skip(1) {
        // Not only finite: the energy audit stops the chain before its state is garbage (the
        // chain starts within 3 m of the origin; an unchecked run reaches 1e19 m).
        assert!(
            line.split(',')
                .skip(3)
                .all(|x| x.parse::<f64>().unwrap().abs() < 1e3),
            "{line}"
        );
    }
}

#[test]
fn a_predicted_divergence_is_refused_with_exit_4_unless_allowed() {
    let (_dir, out) = scratch("chain.csv");
    let output = tumble_out(&EXPLICIT_CHAIN, &out);
    assert_eq!(output.status.code(), Some(4), "{}", stderr(&output));
    let text = stderr(&output);
    // Each warning names the spring as the scene file does, before the refusal.
    assert!(text.contains("forces[0] (spring)"), "{text}");
    assert!(
        last_error_line(&output).contains("--allow-unstable"),
        "{text}"
    );
    assert!(!out.exists(), "nothing is written for a refused run");
    // Quarantines are named with their step and the state kept.
    let allowed =
        tumble_run(&[&EXPLICIT_CHAIN[..], &["--steps", "5", "--allow-unstable"]].concat());
    assert_eq!(allowed.status.code(), Some(3));
    let text = stderr(&allowed);
    assert!(
        text.contains("body `m1` quarantined at step 1: energy grew")
            && text.contains("it keeps its last valid state: position [1.2"),
        "{text}"
    );
}

/// By default the same chain at the same step takes the implicit spring step: no refusal, no
/// quarantine, exit 0, and one warning that says the implicit solve steps its bodies and how
/// it turns them (by `splitting`: its springs hold the links at their centres, so they do not
/// turn them); `--plan` says the same. A first-order method cannot be combined with the implicit step: refused
/// (exit 4), naming the method and what to choose instead, nothing run.
#[test]
fn by_default_a_stiff_chain_runs_on_the_implicit_step() {
    let output = tumble_run(&["run", "spring_chain", "--dt", "0.2", "--steps", "200"]);
    assert!(output.status.success(), "{}", stderr(&output));
    let text = stderr(&output);
    let warnings: Vec<&str> = text.lines().filter(|l| l.contains("WARN")).collect();
    assert_eq!(warnings.len(), 1, "{text}");
    assert!(
        warnings[0].contains("stepped by the implicit spring solve")
            && warnings[0]
                .contains("rotation by `splitting` for 3, by the implicit midpoint for 0"),
        "{text}"
    );
    let plan = tumble_run(&["run", "spring_chain", "--dt", "0.2", "--plan"]);
    let plan = String::from_utf8_lossy(&plan.stdout);
    assert!(
        plan.contains("solve_implicit_springs")
            && plan.contains("(rotation by `splitting` for 3, by the implicit midpoint for 0)"),
        "{plan}"
    );
    let first_order = tumble_run(&[
        "run",
        "spring_chain",
        "--dt",
        "0.2",
        "--integrator",
        "symplectic-euler",
        "--steps",
        "5",
    ]);
    assert_eq!(
        first_order.status.code(),
        Some(4),
        "{}",
        stderr(&first_order)
    );
    let text = stderr(&first_order);
    assert!(
        text.contains("which `symplectic-euler` cannot step")
            && text.contains("springs = `explicit`")
            && text.contains("nothing was run"),
        "{text}"
    );
}

#[test]
fn the_summary_gives_total_energy_and_never_an_unexplained_nan() {
    let output = tumble_run(&["run", "spring_chain", "--steps", "100"]);
    assert!(output.status.success(), "{}", stderr(&output));
    let text = String::from_utf8_lossy(&output.stdout);
    let energy = text.lines().find(|l| l.starts_with("energy")).unwrap();
    assert!(energy.contains("kinetic + spring + gravity"), "{energy}");
    assert!(energy.contains("not conserved: damping"), "{energy}");
    assert!(text.lines().any(|l| l.starts_with("|L|")), "{text}");
    assert!(!text.contains("NaN") && !text.contains("inf"), "{text}");
}

/// A world that starts with no energy (one body at rest, no gravity): `compare` gives the change
/// from zero, not a ratio to it (which printed `E/E₀ = NaN`).
#[test]
fn compare_from_zero_energy_prints_no_nan() {
    let scene = "name = \"still\"\n[world]\ndt = 0.01\nsteps = 5\n[[bodies]]\nname = \"a\"\n\
                 mass = 1.0\ninertia = [1.0, 1.0, 1.0]\n";
    let (_dir, path) = scratch_file("still.toml", scene);
    let output = tumble_run(&["compare", path.to_str().unwrap()]);
    assert!(output.status.success(), "{}", stderr(&output));
    let text = String::from_utf8_lossy(&output.stdout);
    let energy = text
        .lines()
        .find(|l| l.starts_with("total energy"))
        .unwrap();
    assert!(energy.contains("from 0"), "{energy}");
    assert!(!text.contains("NaN") && !text.contains("inf"), "{text}");
}

/// A spring anchored far outside the body overflows the bodies' `f32` states: the table gives
/// the differences it can (in `f64`, finite for any two finite states) and never prints `inf`
/// or `NaN`, and the run is an error naming the bodies.
#[test]
fn compare_names_differences_past_the_largest_number() {
    let scene = "name = \"far\"\n[world]\ndt = 0.01\nsteps = 50\n\
                 [[bodies]]\nname = \"a\"\nmass = 1.0\ninertia = [1.0, 1.0, 1.0]\n\
                 [[bodies]]\nname = \"b\"\nmass = 1.0\ninertia = [1.0, 1.0, 1.0]\n\
                 position = [1.0, 0.0, 0.0]\n\
                 [[forces]]\ntype = \"spring\"\na = \"a\"\nb = \"b\"\nstiffness = 10.0\n\
                 anchor_a = [1e38, 0.0, 0.0]\n";
    let (_dir, path) = scratch_file("far.toml", scene);
    let output = tumble_run(&["compare", path.to_str().unwrap()]);
    let text = String::from_utf8_lossy(&output.stdout);
    assert!(!text.contains("NaN") && !text.contains("inf"), "{text}");
    if tumble_core::math::DOUBLE_PRECISION {
        // An `f64` state holds these numbers: the differences are finite.
        return;
    }
    assert!(
        text.lines()
            .filter(|l| l.starts_with("a ") || l.starts_with("b "))
            .all(|l| !l.contains("overflow")),
        "{text}"
    );
    assert_eq!(output.status.code(), Some(3), "{}", stderr(&output));
}

/// `compare` steps tumble with the scene's substeps and says so in its header: it stepped one
/// substep whatever the file said, without a word.
#[test]
fn compare_steps_the_scene_s_substeps() {
    let scene = |substeps: u32| {
        format!(
            "name = \"m\"\n[world]\ndt = 0.016666668\nsteps = 30\nsubsteps = {substeps}\n\
             [[bodies]]\nname = \"a\"\nmass = 0.01\ninertia = [1.6e-6, 1.6e-6, 1.6e-6]\n\
             [[forces]]\ntype = \"spring\"\na = \"a\"\nanchor_b = [0.0, 0.0, 0.0]\nstiffness = 0.1\n\
             [[forces]]\ntype = \"constant\"\nbody = \"a\"\nforce = [0.0, -0.1, 0.0]\n"
        )
    };
    let energy = |substeps: u32| {
        let (_dir, path) = scratch_file("m.toml", &scene(substeps));
        let output = tumble_run(&["compare", path.to_str().unwrap()]);
        let text = String::from_utf8_lossy(&output.stdout).into_owned();
        assert_eq!(output.status.code(), Some(0), "{text}{}", stderr(&output));
        let header = text.lines().next().unwrap().to_owned();
        assert_eq!(header.contains(", 2 substeps,"), substeps == 2, "{header}");
        text.lines()
            .find(|l| l.starts_with("total energy"))
            .and_then(|l| l.split("; rapier").next())
            .unwrap()
            .to_owned()
    };
    assert_ne!(energy(1), energy(2), "the substeps change tumble's run");
}

/// Two finite states far apart: their difference is finite even where its square is past the
/// precision's largest number (`f32`: beyond about 1.8e19), so the table prints it, never
/// `overflow`. Gravity 1e30 m/s² for half a second: the engines' step biases differ by about
/// 1e27 m.
#[test]
fn compare_prints_a_finite_difference_whose_square_overflows() {
    let scene = "name = \"fast\"\n[world]\ndt = 0.01\nsteps = 50\ngravity = [1e30, 0.0, 0.0]\n\
                 [[bodies]]\nname = \"a\"\nmass = 1.0\ninertia = [1.0, 1.0, 1.0]\n";
    let (_dir, path) = scratch_file("fast.toml", scene);
    let output = tumble_run(&["compare", path.to_str().unwrap()]);
    let text = String::from_utf8_lossy(&output.stdout);
    assert_eq!(output.status.code(), Some(0), "{text}{}", stderr(&output));
    let row = text
        .lines()
        .find(|l| l.starts_with("a "))
        .unwrap_or_else(|| panic!("{text}"));
    assert!(
        !row.contains("overflow") && !row.contains("not finite"),
        "{row}"
    );
    assert!(row.contains("e2"), "a difference of order 1e2x m: {row}");
}

#[cfg(target_os = "linux")]
#[test]
fn long_runs_show_a_progress_bar_on_a_terminal_only() {
    let args = "run projectile --steps 2000000";
    // `script` (util-linux) gives the run a pseudo-terminal.
    let on_terminal = Command::new("script")
        .args([
            "-qec",
            &format!("{} {args}", env!("CARGO_BIN_EXE_tumble")),
            "/dev/null",
        ])
        .env_remove("RUST_LOG")
        .stdin(std::process::Stdio::null())
        .output()
        .unwrap();
    assert!(on_terminal.status.success());
    let shown = String::from_utf8_lossy(&on_terminal.stdout);
    assert!(shown.contains("/2,000,000 steps ["), "{shown}");
    let piped = tumble().args(args.split(' ')).output().unwrap();
    assert!(piped.status.success());
    assert!(piped.stderr.is_empty(), "{}", stderr(&piped));
    // A short run shows none, even on a terminal.
    let short = Command::new("script")
        .args([
            "-qec",
            &format!(
                "{} run projectile --steps 1000",
                env!("CARGO_BIN_EXE_tumble")
            ),
            "/dev/null",
        ])
        .stdin(std::process::Stdio::null())
        .output()
        .unwrap();
    assert!(!String::from_utf8_lossy(&short.stdout).contains("steps ["));
}

#[test]
fn compare_never_reports_a_quarantined_body_as_agreement() {
    let (_dir, scene) = scratch_file(
        "thin.toml",
        "name = \"thin\"\n[world]\ndt = 0.016666668\nsteps = 300\n\
         integrator = \"symplectic-euler\"\n[[bodies]]\nname = \"thin\"\nmass = 1.0\n\
         inertia = [0.01, 1.0, 1.005]\nangular_velocity = [1.0, 60.0, 1.0]\n",
    );
    // Predicted: refused.
    let refused = tumble().arg("compare").arg(&scene).output().unwrap();
    assert_eq!(refused.status.code(), Some(4), "{}", stderr(&refused));
    // Allowed: the explicit spin diverges, tumble quarantines it, and compare says so.
    let output = tumble()
        .arg("compare")
        .arg(&scene)
        .arg("--allow-unstable")
        .output()
        .unwrap();
    assert_eq!(output.status.code(), Some(3), "{}", stderr(&output));
    let text = stderr(&output);
    assert!(
        text.contains("body `thin`: tumble quarantined it at step"),
        "{text}"
    );
    assert!(last_error_line(&output).contains("did not run cleanly"));
}

/// A scene's `[world] substeps` outside 1..=1000 names the file, the line and the field; a good
/// value shows in the plan (the stages of a step) and in the summary.
#[test]
fn substeps_are_checked_and_shown() {
    let (_dir, bad) = scratch_file(
        "bad.toml",
        "name = \"s\"\n[world]\ndt = 0.01\nsteps = 10\nsubsteps = 0\n\n[[bodies]]\nname = \"b\"\nmass = 1.0\ninertia = [1.0, 1.0, 1.0]\n",
    );
    let output = tumble().arg("run").arg(&bad).output().unwrap();
    let line = failure(&output, 1);
    assert!(
        line.contains("bad.toml:")
            && line.ends_with("world.substeps: expected 1 to 1000 substeps, got 0"),
        "{line}"
    );
    let plan = tumble_run(&[
        "run",
        "projectile",
        "--plan",
        "--substeps",
        "2",
        "--integrator",
        "yoshida4",
    ]);
    assert!(plan.status.success());
    let text = String::from_utf8_lossy(&plan.stdout);
    assert!(text.contains("(× 6 stages per step)"), "{text}");
    assert!(
        text.contains("stages per step: 6 (2 substep(s) × 3 of `yoshida4`), h/Δt = 0.675604, -0.851207, 0.675604"),
        "{text}"
    );
    let run = tumble_run(&["run", "projectile", "--substeps", "3", "--steps", "5"]);
    assert!(run.status.success());
    assert!(String::from_utf8_lossy(&run.stdout).contains("(splitting, 3 substeps)"));
}

/// A scene name that is neither bundled nor a file says which names exist; `many` says how to
/// generate it.
#[test]
fn an_unknown_scene_name_says_what_exists() {
    for (name, expected) in [
        (
            "many",
            "run `tumble gen many --n 100000 --out many.toml` first",
        ),
        (
            "projectil",
            "neither a file nor a bundled scene (projectile, ",
        ),
    ] {
        let out = common::tumble().args(["run", name]).output().unwrap();
        assert_eq!(out.status.code(), Some(1), "{name}");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(
            stderr.starts_with(&format!("error: {name}: no such scene: "))
                && stderr.contains(expected),
            "{stderr}"
        );
        assert_eq!(stderr.lines().count(), 1, "{stderr}");
    }
}

/// Many bodies with the same planning warning print five lines and a count, not one line
/// each; `-v` prints them all.
#[test]
fn repeated_warnings_are_counted_not_listed() {
    // Twenty bodies 10¹³ m out, moving 1 m/s: rounding eats their motion in both precisions.
    let mut scene = String::from("name = \"far\"\n[world]\ndt = 0.0166\nsteps = 1\n");
    for i in 0..20 {
        scene.push_str(&format!(
            "[[bodies]]\nname = \"b{i}\"\nmass = 1.0\ninertia = [1.0, 1.0, 1.0]\n\
             position = [1e13, {i}.0, 0.0]\nlinear_velocity = [1.0, 0.0, 0.0]\n"
        ));
    }
    let (_dir, path) = scratch_file("far.toml", &scene);
    let warnings = |verbose: bool| {
        let mut args = vec!["run", path.to_str().unwrap()];
        if verbose {
            args.push("-v");
        }
        let output = tumble_run(&args);
        assert!(output.status.success(), "{}", stderr(&output));
        stderr(&output)
            .lines()
            .filter(|l| l.contains("WARN"))
            .map(str::to_owned)
            .collect::<Vec<_>>()
    };
    let all = warnings(true);
    assert_eq!(all.len(), 20, "{all:?}");
    let counted = warnings(false);
    assert_eq!(counted.len(), 6, "{counted:?}");
    assert_eq!(counted[..5], all[..5]);
    assert!(
        counted[5]
            .ends_with("… and 15 more with the same warning as body `b0` (-v lists them all)"),
        "{counted:?}"
    );
}
