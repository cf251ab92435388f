//! Output files are safe (temporary file beside the output, exclusive, removed on every error and
//! on SIGINT/SIGTERM, rename last; no device, FIFO, directory, read-only file or input file is
//! replaced), big work shows itself, and every message is one line that names what the user gave.

mod common;

use std::path::Path;
use std::process::{Child, Command, ExitStatus, Output, Stdio};
use std::time::{Duration, Instant};

use common::{
    BadValues, bad_value_runs, error_line, failure, scene_path, scratch, scratch_dir, scratch_file,
    stderr, tumble, tumble_out, tumble_run,
};
use tumble_scene::{CSV_HEADER, MAX_SCENE_BYTES};

/// Names in `dir`, sorted.
fn listing(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

/// Waits for `child`, killing it after `limit` (so that a test of a refusal fails, rather than
/// hangs, on a build that starts the work instead).
fn wait_at_most(child: &mut Child, limit: Duration) -> ExitStatus {
    let start = Instant::now();
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            return status;
        }
        if start.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            panic!("still running after {limit:?}");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

fn run_to(out: &Path, extra: &[&str]) -> Output {
    tumble()
        // Quiet: the chain's stiff-group warning is not what these tests read.
        .args(["run", "spring_chain", "--steps", "20", "-q"])
        .args(extra)
        .arg("--out")
        .arg(out)
        .output()
        .unwrap()
}

#[cfg(unix)]
#[test]
fn devices_fifos_and_directories_are_refused_and_left_alone() {
    use std::os::unix::fs::FileTypeExt;
    let dir = scratch_dir();
    let fifo = dir.path().join("fifo.csv");
    assert!(
        Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .unwrap()
            .success()
    );
    let output = run_to(&fifo, &[]);
    assert!(failure(&output, 1).contains("fifo.csv: is not a regular file"));
    assert!(std::fs::metadata(&fifo).unwrap().file_type().is_fifo());
    let sub = dir.path().join("sub");
    std::fs::create_dir(&sub).unwrap();
    let output = run_to(&sub, &[]);
    assert!(error_line(&output).ends_with("sub: is a directory, expected a file"));
    // /dev/null last: a build that replaced devices fails on the FIFO before it gets here.
    let output = run_to(Path::new("/dev/null"), &[]);
    assert_eq!(
        failure(&output, 1),
        "error: /dev/null: is not a regular file (a device, FIFO or socket); tumble writes only regular files"
    );
    assert!(
        std::fs::metadata("/dev/null")
            .unwrap()
            .file_type()
            .is_char_device()
    );
    assert_eq!(listing(dir.path()), ["fifo.csv", "sub"]);
    assert!(listing(&sub).is_empty());
    // `gen` follows the same rules.
    let output = tumble_run(&["gen", "many", "--n", "10", "--out", "/dev/null"]);
    assert!(error_line(&output).contains("/dev/null: is not a regular file"));
}

#[cfg(unix)]
#[test]
fn nothing_planted_beside_the_output_is_followed_and_a_symlink_out_keeps_its_link() {
    let (dir, victim) = scratch_file("victim.txt", "precious");
    // The temporary name of old builds, planted as a link to another file.
    let out = dir.path().join("out.csv");
    std::os::unix::fs::symlink(&victim, dir.path().join("out.csv.partial")).unwrap();
    let output = run_to(&out, &[]);
    assert!(output.status.success(), "{}", stderr(&output));
    assert_eq!(std::fs::read_to_string(&victim).unwrap(), "precious");
    assert!(
        std::fs::read_to_string(&out)
            .unwrap()
            .starts_with(CSV_HEADER)
    );
    // A symlink `--out` replaces its target (a regular file) and stays a link.
    let target = dir.path().join("target.csv");
    std::fs::write(&target, "old").unwrap();
    let link = dir.path().join("link.csv");
    std::os::unix::fs::symlink("target.csv", &link).unwrap();
    let output = run_to(&link, &[]);
    assert!(output.status.success(), "{}", stderr(&output));
    assert!(
        std::fs::symlink_metadata(&link)
            .unwrap()
            .file_type()
            .is_symlink()
    );
    assert_eq!(
        std::fs::read_to_string(&target).unwrap(),
        std::fs::read_to_string(&out).unwrap()
    );
    // A dangling link creates its target.
    let dangling = dir.path().join("dangling.csv");
    std::os::unix::fs::symlink("created.csv", &dangling).unwrap();
    assert!(run_to(&dangling, &[]).status.success());
    assert!(dir.path().join("created.csv").is_file());
    // A link to a device is still a device.
    let to_null = dir.path().join("null.csv");
    std::os::unix::fs::symlink("/dev/null", &to_null).unwrap();
    let output = run_to(&to_null, &[]);
    assert!(error_line(&output).contains("null.csv: is not a regular file"));
}

#[test]
fn the_scene_file_is_never_the_output() {
    let dir = scratch_dir();
    let scene = dir.path().join("chain.toml");
    let text = std::fs::read_to_string(scene_path("spring_chain")).unwrap();
    std::fs::write(&scene, &text).unwrap();
    let output = tumble_out(&["run", "-q", scene.to_str().unwrap()], &scene);
    assert_eq!(output.status.code(), Some(1));
    assert!(
        error_line(&output).contains("chain.toml: is the input file"),
        "{}",
        stderr(&output)
    );
    assert_eq!(std::fs::read_to_string(&scene).unwrap(), text);
    // Another name for the same file (a hard link) is the same file.
    let other = dir.path().join("other.csv");
    std::fs::hard_link(&scene, &other).unwrap();
    let output = tumble_out(&["run", scene.to_str().unwrap()], &other);
    assert_eq!(output.status.code(), Some(1));
    assert_eq!(std::fs::read_to_string(&scene).unwrap(), text);
    assert_eq!(listing(dir.path()), ["chain.toml", "other.csv"]);
}

#[cfg(unix)]
#[test]
fn a_read_only_output_is_an_error_and_a_writable_one_keeps_its_mode() {
    use std::os::unix::fs::PermissionsExt;
    let (dir, out) = scratch_file("ro.csv", "keep");
    std::fs::set_permissions(&out, std::fs::Permissions::from_mode(0o444)).unwrap();
    let output = run_to(&out, &[]);
    assert!(failure(&output, 1).ends_with("ro.csv: is read-only"));
    assert_eq!(std::fs::read_to_string(&out).unwrap(), "keep");
    let mode = |p: &Path| std::fs::metadata(p).unwrap().permissions().mode() & 0o7777;
    assert_eq!(mode(&out), 0o444);
    let rw = dir.path().join("rw.csv");
    std::fs::write(&rw, "old").unwrap();
    // Giving the file away works only as root (as CI runs); the owner then stays too.
    let given_away = std::os::unix::fs::chown(&rw, Some(65534), Some(65534)).is_ok();
    std::fs::set_permissions(&rw, std::fs::Permissions::from_mode(0o640)).unwrap();
    assert!(run_to(&rw, &[]).status.success());
    assert_eq!(mode(&rw), 0o640);
    if given_away {
        use std::os::unix::fs::MetadataExt;
        let meta = std::fs::metadata(&rw).unwrap();
        assert_eq!((meta.uid(), meta.gid()), (65534, 65534));
    }
    assert!(
        std::fs::read_to_string(&rw)
            .unwrap()
            .starts_with(CSV_HEADER)
    );
    assert_eq!(listing(dir.path()), ["ro.csv", "rw.csv"]);
}

#[test]
fn names_up_to_255_bytes_work() {
    let dir = scratch_dir();
    let name = format!("{}.csv", "n".repeat(251));
    assert_eq!(name.len(), 255);
    let out = dir.path().join(&name);
    let output = run_to(&out, &[]);
    assert!(output.status.success(), "{}", stderr(&output));
    assert_eq!(listing(dir.path()), [name]);
}

#[test]
fn errors_name_the_given_path_escaped_on_one_line() {
    let dir = scratch_dir();
    let out = dir.path().join("no such dir").join("a\u{1b}[2Jb\nc.csv");
    let output = run_to(&out, &[]);
    let line = failure(&output, 1);
    assert!(
        line.contains("no such dir/a\\u{1b}[2Jb\\nc.csv: "),
        "{line}"
    );
    assert!(
        !line.contains(".tumble-") && !line.contains("partial"),
        "{line}"
    );
}

/// A run of 1e9 steps: 3e9 rows with `--every 1` (over 700 GB: refused without `--force`),
/// 3e4 rows (at most 8 MB) with `--every 100000`.
const LONG_RUN: [&str; 5] = ["run", "spring_chain", "--steps", "1000000000", "-q"];

/// Starts a long run writing to `out` and waits until its temporary file exists.
fn start_long_run(dir: &Path, out: &Path, extra: &[&str]) -> Child {
    let child = tumble()
        .args(LONG_RUN)
        .args(extra)
        .arg("--out")
        .arg(out)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    while listing(dir).iter().all(|n| !n.starts_with(".tumble-")) {
        assert!(
            start.elapsed() < Duration::from_secs(20),
            "no temporary file"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
    child
}

#[cfg(unix)]
#[test]
fn ending_signals_remove_the_temporary_file_and_exit_130() {
    let mut signals: Vec<String> = [
        "INT", "TERM", "USR1", "USR2", "ALRM", "QUIT", "IO", "TRAP", "SYS",
    ]
    .map(|name| format!("-{name}"))
    .into();
    #[cfg(target_os = "linux")]
    signals.extend(
        [
            libc::SIGPWR,
            libc::SIGSTKFLT,
            libc::SIGRTMIN(),
            libc::SIGRTMAX(),
        ]
        .map(|n| format!("-{n}")),
    );
    for signal in &signals {
        let dir = scratch_dir();
        let out = dir.path().join("long.csv");
        let mut child = start_long_run(dir.path(), &out, &["--every", "100000"]);
        assert!(
            Command::new("kill")
                .arg(signal)
                .arg(child.id().to_string())
                .status()
                .unwrap()
                .success()
        );
        let status = wait_at_most(&mut child, Duration::from_secs(20));
        assert_eq!(status.code(), Some(130), "{signal}");
        let mut message = String::new();
        std::io::Read::read_to_string(&mut child.stderr.take().unwrap(), &mut message).unwrap();
        assert!(
            message.starts_with("error: interrupted after step ")
                && message.trim_end().ends_with("long.csv was not written"),
            "{message}"
        );
        assert!(listing(dir.path()).is_empty(), "{:?}", listing(dir.path()));
    }
}

/// A signal where no loop polls (the quick report, which writes all its files at the end) ends
/// the process at once with exit code 130, and with the `error:` line every failure ends with
/// (it ended silently), having written nothing.
#[cfg(unix)]
#[test]
fn a_signal_outside_a_polling_loop_ends_with_an_error_line() {
    let dir = scratch_dir();
    let out = dir.path().join("report");
    let mut child = tumble()
        .args(["report", "--quick", "--out"])
        .arg(&out)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(Duration::from_millis(500));
    assert!(
        Command::new("kill")
            .arg("-TERM")
            .arg(child.id().to_string())
            .status()
            .unwrap()
            .success()
    );
    let status = wait_at_most(&mut child, Duration::from_secs(20));
    assert_eq!(status.code(), Some(130));
    let mut message = String::new();
    std::io::Read::read_to_string(&mut child.stderr.take().unwrap(), &mut message).unwrap();
    assert_eq!(
        message.lines().last(),
        Some("error: interrupted; no output file was written or changed"),
        "{message}"
    );
    // Not even the directory: it is made only when the files go in.
    assert!(!out.exists(), "{:?}", listing(dir.path()));
}

/// A run that crosses the file-size limit (`ulimit -f`, SIGXFSZ) fails with an `error:` line and
/// leaves no temporary file (the signal's default action killed it and left the file).
#[cfg(unix)]
#[test]
fn the_file_size_limit_is_an_error_that_leaves_nothing() {
    let dir = scratch_dir();
    let out = dir.path().join("big.csv");
    // 100 blocks of 512 bytes: far less than the trajectory.
    let output = Command::new("sh")
        .arg("-c")
        .arg("ulimit -f 100 && exec \"$0\" run spring_chain --steps 20000 --out \"$1\"")
        .arg(env!("CARGO_BIN_EXE_tumble"))
        .arg(&out)
        .env_remove("RUST_LOG")
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(1), "{stderr}");
    let last = stderr.lines().last().unwrap_or_default();
    assert!(
        last.starts_with("error: ") && last.contains("big.csv"),
        "{stderr}"
    );
    assert!(listing(dir.path()).is_empty(), "{:?}", listing(dir.path()));
}

#[test]
fn two_concurrent_runs_never_mix_their_files() {
    let dir = scratch_dir();
    let out = dir.path().join("shared.csv");
    let args = |scene: &'static str| ["run", scene, "--steps", "8000"];
    // Each run alone, for reference.
    let mut alone = Vec::new();
    for scene in ["spring_chain", "principal_spins"] {
        let reference = dir.path().join(format!("{scene}.csv"));
        let status = tumble()
            .args(args(scene))
            .arg("--out")
            .arg(&reference)
            .stdout(Stdio::null())
            .status()
            .unwrap();
        assert!(status.success());
        alone.push(std::fs::read(&reference).unwrap());
    }
    assert!(alone[0].len() > 1 << 20 && alone[1].len() > 1 << 20);
    for _ in 0..3 {
        let children: Vec<Child> = ["spring_chain", "principal_spins"]
            .into_iter()
            .map(|scene| {
                tumble()
                    .args(args(scene))
                    .arg("--out")
                    .arg(&out)
                    .stdout(Stdio::null())
                    .spawn()
                    .unwrap()
            })
            .collect();
        for mut child in children {
            assert!(wait_at_most(&mut child, Duration::from_secs(60)).success());
        }
        let written = std::fs::read(&out).unwrap();
        assert!(
            written == alone[0] || written == alone[1],
            "a mixed file of {} bytes",
            written.len()
        );
    }
    assert_eq!(
        listing(dir.path()),
        ["principal_spins.csv", "shared.csv", "spring_chain.csv"]
    );
}

#[test]
fn a_trajectory_bigger_than_the_free_space_is_refused_before_the_run() {
    let (dir, scene) = scratch("many.toml");
    let many = ["gen", "many", "--n", "1000", "--steps", "1000000000"];
    assert!(tumble_out(&many, &scene).status.success());
    let out = dir.path().join("huge.csv");
    let mut child = tumble()
        .arg("run")
        .arg(&scene)
        .arg("--out")
        .arg(&out)
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let status = wait_at_most(&mut child, Duration::from_secs(30));
    assert_eq!(status.code(), Some(1));
    let mut message = String::new();
    std::io::Read::read_to_string(&mut child.stderr.take().unwrap(), &mut message).unwrap();
    assert!(
        message.starts_with("error: ")
            && message.contains("huge.csv: the trajectory would take up to ")
            && message.contains("(1000000001000 rows of up to ")
            && message.contains(" free there")
            && message.contains("--force"),
        "{message}"
    );
    assert_eq!(listing(dir.path()), ["many.toml"]);
}

#[cfg(unix)]
#[test]
fn force_skips_the_free_space_check() {
    let dir = scratch_dir();
    let out = dir.path().join("forced.csv");
    let refused = tumble()
        .args(LONG_RUN)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert!(error_line(&refused).contains("more than the"));
    // With --force it starts writing, and Ctrl-C stops it cleanly.
    let mut child = start_long_run(dir.path(), &out, &["--force"]);
    let _ = Command::new("kill")
        .arg("-INT")
        .arg(child.id().to_string())
        .status();
    assert_eq!(
        wait_at_most(&mut child, Duration::from_secs(20)).code(),
        Some(130)
    );
    assert!(listing(dir.path()).is_empty());
}

#[test]
fn out_dash_writes_the_csv_to_stdout_and_the_summary_to_stderr() {
    let output = tumble_run(&["run", "projectile", "--steps", "3", "--out", "-"]);
    assert!(output.status.success(), "{}", stderr(&output));
    let csv = String::from_utf8(output.stdout.clone()).unwrap();
    let mut lines = csv.lines();
    assert_eq!(lines.next(), Some(CSV_HEADER));
    assert_eq!(lines.count(), 4, "{csv}");
    assert!(stderr(&output).contains("scene      projectile"));
    assert!(!Path::new("-").exists());
    let generated = tumble_run(&["gen", "many", "--n", "3", "--out", "-"]);
    assert!(generated.status.success());
    assert!(generated.stdout.starts_with(b"name = \"many-3\""));
    // An empty path is no file name.
    let output = tumble_run(&["run", "projectile", "--out", ""]);
    assert!(failure(&output, 2).contains("'--out <OUT>'"));
}

#[test]
fn gen_writes_only_what_run_accepts() {
    let cases: [BadValues; 2] = [
        (
            "--steps",
            "expected 1 to 1000000000 steps",
            &["0", "1000000001"],
        ),
        ("--n", "expected 1 to 200000 bodies", &["0", "200001", "-3"]),
    ];
    for (args, expected, output) in bad_value_runs(&["gen", "many"], &cases) {
        assert_eq!(output.status.code(), Some(1), "{args:?}");
        assert!(error_line(&output).starts_with(&expected), "{args:?}");
        assert!(output.stdout.is_empty());
    }
    // The cap fits under the loader's size limit.
    let at_cap = tumble_run(&["gen", "many", "--n", "200000", "--steps", "1000000000"]);
    assert!(at_cap.status.success());
    assert!((at_cap.stdout.len() as u64) < MAX_SCENE_BYTES);
}

#[test]
fn report_and_bench_name_an_output_that_is_not_a_directory_before_working() {
    let (_dir, file) = scratch_file("taken", "x");
    for command in ["report", "bench"] {
        let mut child = tumble()
            .args([command, "--quick", "--out"])
            .arg(&file)
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        let status = wait_at_most(&mut child, Duration::from_secs(60));
        assert_eq!(status.code(), Some(1), "{command}");
        let mut message = String::new();
        std::io::Read::read_to_string(&mut child.stderr.take().unwrap(), &mut message).unwrap();
        assert_eq!(
            message.trim_end(),
            format!(
                "error: {}: exists and is not a directory",
                file.to_string_lossy()
            ),
            "{command}"
        );
    }
    assert_eq!(std::fs::read_to_string(&file).unwrap(), "x");
}

/// A link planted by another user in a shared sticky directory is not followed (the kernel's
/// `protected_symlinks` rule, which cannot act when tumble reads the link itself): the run
/// fails and the link's target is untouched. The caller's own link there is followed as before.
/// Giving a link to another user needs root: elsewhere the test says so and skips.
#[cfg(unix)]
#[test]
fn a_link_planted_by_another_user_in_a_sticky_directory_is_not_followed() {
    use std::os::unix::fs::{MetadataExt, PermissionsExt, lchown, symlink};

    let dir = scratch_dir();
    let sticky = dir.path().join("sticky");
    std::fs::create_dir(&sticky).unwrap();
    std::fs::set_permissions(&sticky, std::fs::Permissions::from_mode(0o1777)).unwrap();
    let victim = dir.path().join("victim");
    std::fs::write(&victim, "precious").unwrap();
    std::fs::set_permissions(&victim, std::fs::Permissions::from_mode(0o600)).unwrap();
    let link = sticky.join("out.csv");
    symlink("../victim", &link).unwrap();
    let me = std::fs::symlink_metadata(&link).unwrap().uid();
    let other = if me == 65534 { 65533 } else { 65534 };
    if lchown(&link, Some(other), None).is_err() {
        eprintln!("skipped: giving the link to another user needs root");
        return;
    }
    let output = tumble()
        .args(["run", "projectile", "--out"])
        .arg(&link)
        .output()
        .unwrap();
    let line = failure(&output, 1);
    assert!(line.contains("belongs to another user"), "{line}");
    assert_eq!(std::fs::read_to_string(&victim).unwrap(), "precious");
    assert_eq!(std::fs::read_link(&link).unwrap(), Path::new("../victim"));
    assert_eq!(listing(&sticky), ["out.csv"]);
    // The caller's own link is followed: the target gets the trajectory.
    lchown(&link, Some(me), None).unwrap();
    let status = tumble()
        .args(["run", "projectile", "--out"])
        .arg(&link)
        .stdout(Stdio::null())
        .status()
        .unwrap();
    assert!(status.success());
    assert!(
        std::fs::read_to_string(&victim)
            .unwrap()
            .starts_with(CSV_HEADER)
    );
}

/// Every destination of `report` and `bench` is checked before the work: a directory that takes
/// no file, a read-only file of the set, a README without its markers. Each fails at once with
/// one line naming it, and nothing that was there changes.
#[cfg(unix)]
#[test]
fn report_and_bench_refuse_an_unwritable_destination_before_working() {
    use std::os::unix::fs::PermissionsExt;
    let dir = scratch_dir();
    let readme = dir.path().join("README.md");
    std::fs::write(&readme, "no markers here\n").unwrap();
    // Two pairs of one section's markers: which is the section is not clear, and replacing
    // the first left the second stale.
    let twice = dir.path().join("TWICE.md");
    std::fs::write(
        &twice,
        "<!-- report:begin -->\na\n<!-- report:end -->\n<!-- report:begin -->\nb\n<!-- report:end -->\n",
    )
    .unwrap();
    let read_only = dir.path().join("kept");
    std::fs::create_dir(&read_only).unwrap();
    let report_md = read_only.join("report.md");
    std::fs::write(&report_md, "old report").unwrap();
    std::fs::set_permissions(&report_md, std::fs::Permissions::from_mode(0o444)).unwrap();
    let bench_summary = read_only.join("bench-targets.md");
    std::fs::write(&bench_summary, "old targets").unwrap();
    std::fs::set_permissions(&bench_summary, std::fs::Permissions::from_mode(0o444)).unwrap();
    let fresh = dir.path().join("fresh");
    let cases: Vec<(&str, Vec<std::ffi::OsString>, String)> = vec![
        (
            "report",
            vec!["--out".into(), "/proc/self/report".into()],
            "error: /proc/self/report".into(),
        ),
        (
            "bench",
            vec!["--out".into(), "/proc/self/bench".into()],
            "error: /proc/self/bench".into(),
        ),
        (
            "report",
            vec!["--out".into(), read_only.clone().into()],
            format!("error: {}: is read-only", report_md.display()),
        ),
        (
            "bench",
            vec!["--out".into(), read_only.clone().into()],
            format!("error: {}: is read-only", bench_summary.display()),
        ),
        (
            "report",
            vec![
                "--out".into(),
                fresh.clone().into(),
                "--readme".into(),
                readme.clone().into(),
            ],
            format!("error: {}: no <!-- report:begin -->", readme.display()),
        ),
        (
            "report",
            vec![
                "--out".into(),
                fresh.clone().into(),
                "--readme".into(),
                twice.clone().into(),
            ],
            format!(
                "error: {}: more than one <!-- report:begin -->",
                twice.display()
            ),
        ),
        (
            "bench",
            vec!["--readme".into(), readme.clone().into()],
            format!("error: {}: no <!-- frame-budget:begin", readme.display()),
        ),
        (
            "bench",
            vec![
                "--out".into(),
                fresh.join("a/b/c").into(),
                "--readme".into(),
                readme.clone().into(),
            ],
            format!("error: {}: no <!-- frame-budget:begin", readme.display()),
        ),
    ];
    for (command, args, expected) in cases {
        let mut child = tumble()
            .args([command, "--quick"])
            .args(&args)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        // The quick report and bench take tens of seconds: a refusal takes a moment.
        let status = wait_at_most(&mut child, Duration::from_secs(20));
        let mut message = String::new();
        std::io::Read::read_to_string(&mut child.stderr.take().unwrap(), &mut message).unwrap();
        let mut out = String::new();
        std::io::Read::read_to_string(&mut child.stdout.take().unwrap(), &mut out).unwrap();
        assert_eq!(status.code(), Some(1), "{command} {args:?}: {message}");
        // One line: no progress line of a started measurement before it.
        assert!(
            message.starts_with(&expected) && message.lines().count() == 1,
            "{command} {args:?}: {message}"
        );
        assert!(out.is_empty(), "{command} {args:?}: {out}");
    }
    assert_eq!(std::fs::read_to_string(&report_md).unwrap(), "old report");
    assert_eq!(
        std::fs::read_to_string(&bench_summary).unwrap(),
        "old targets"
    );
    assert_eq!(
        std::fs::read_to_string(&readme).unwrap(),
        "no markers here\n"
    );
    assert_eq!(listing(&read_only), ["bench-targets.md", "report.md"]);
    // The missing directories were checked, not made: a refused run leaves none behind.
    assert!(!fresh.exists(), "a refused run made {}", fresh.display());
}

/// A link planted by another user in a shared sticky directory is not followed on the way to
/// the output either (`sticky/theirs/out.csv`, `theirs` a link to a directory): the kernel
/// follows such links itself, and guards them only where the system enables
/// `protected_symlinks`. Root only (giving a link away); elsewhere the test says so and skips.
#[cfg(unix)]
#[test]
fn a_directory_link_planted_in_a_sticky_directory_is_not_followed() {
    use std::os::unix::fs::{MetadataExt, PermissionsExt, lchown, symlink};

    let dir = scratch_dir();
    let sticky = dir.path().join("sticky");
    std::fs::create_dir(&sticky).unwrap();
    std::fs::set_permissions(&sticky, std::fs::Permissions::from_mode(0o1777)).unwrap();
    let elsewhere = dir.path().join("elsewhere");
    std::fs::create_dir(&elsewhere).unwrap();
    let link = sticky.join("theirs");
    symlink(&elsewhere, &link).unwrap();
    let me = std::fs::symlink_metadata(&link).unwrap().uid();
    let other = if me == 65534 { 65533 } else { 65534 };
    if lchown(&link, Some(other), None).is_err() {
        eprintln!("skipped: giving the link to another user needs root");
        return;
    }
    // Through the link as a directory, and again behind a `..` and a second, trusted link.
    let mine = dir.path().join("mine");
    symlink("sticky/theirs", &mine).unwrap();
    for out in [
        link.join("out.csv"),
        mine.join("../elsewhere/../sticky/theirs/out.csv"),
    ] {
        for command in [
            &["run", "projectile", "--out"][..],
            &["gen", "many", "--out"],
        ] {
            let output = tumble().args(command).arg(&out).output().unwrap();
            let line = failure(&output, 1);
            assert!(
                line.contains("belongs to another user"),
                "{command:?} {out:?}: {line}"
            );
            assert!(listing(&elsewhere).is_empty(), "{command:?} {out:?}");
        }
    }
    // The caller's own link there is followed.
    lchown(&link, Some(me), None).unwrap();
    let status = tumble()
        .args(["run", "projectile", "--out"])
        .arg(link.join("out.csv"))
        .stdout(Stdio::null())
        .status()
        .unwrap();
    assert!(status.success());
    assert_eq!(listing(&elsewhere), ["out.csv"]);
}

/// Memory exhausted under a limit (`ulimit -v`) is one `error:` line and exit code 1, not an
/// abort: the output is untouched and no temporary file is left.
#[cfg(unix)]
#[test]
fn exhausted_memory_is_an_error_line_and_leaves_nothing() {
    let dir = scratch_dir();
    let scene = dir.path().join("big.json");
    let generated = tumble()
        .args(["gen", "many", "--n", "100000", "--steps", "2", "--out"])
        .arg(&scene)
        .output()
        .unwrap();
    assert!(generated.status.success(), "{}", stderr(&generated));
    let out = dir.path().join("out.csv");
    std::fs::write(&out, "old").unwrap();
    // Room for the program (about 10 MB here), not for the 100 000 bodies (about 50 MB).
    let output = Command::new("sh")
        .arg("-c")
        .arg("ulimit -v 40000 && exec \"$0\" \"$@\"")
        .arg(env!("CARGO_BIN_EXE_tumble"))
        .arg("run")
        .arg(&scene)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    let message = stderr(&output);
    assert_eq!(output.status.code(), Some(1), "{message}");
    let last = message.lines().last().unwrap_or_default();
    assert!(
        last.starts_with("error: out of memory: an allocation of ") && last.ends_with(" use"),
        "{message}"
    );
    assert_eq!(std::fs::read_to_string(&out).unwrap(), "old");
    assert_eq!(listing(dir.path()), ["big.json", "out.csv"]);
}

/// A directory one may write in but not list (mode 0333) takes outputs: the directory is held
/// by path only (`O_PATH`) while the file is written, which needs no read permission. Run as
/// another user, which needs root: elsewhere the test says so and skips.
#[cfg(target_os = "linux")]
#[test]
fn a_directory_that_can_be_written_but_not_listed_takes_the_output() {
    use std::os::unix::fs::{PermissionsExt, chown};
    use std::os::unix::process::CommandExt;

    let dir = scratch_dir();
    std::fs::set_permissions(dir.path(), std::fs::Permissions::from_mode(0o755)).unwrap();
    let blind = dir.path().join("blind");
    std::fs::create_dir(&blind).unwrap();
    let nobody = 65534;
    if chown(&blind, Some(nobody), Some(nobody)).is_err() {
        eprintln!("skipped: giving the directory to another user needs root");
        return;
    }
    std::fs::set_permissions(&blind, std::fs::Permissions::from_mode(0o333)).unwrap();
    let output = match tumble()
        .args(["run", "projectile", "--out", "blind/out.csv"])
        .current_dir(dir.path())
        .uid(nobody)
        .gid(nobody)
        .output()
    {
        Ok(output) => output,
        Err(e) => {
            eprintln!("skipped: cannot run as another user ({e})");
            return;
        }
    };
    assert!(output.status.success(), "{}", stderr(&output));
    std::fs::set_permissions(&blind, std::fs::Permissions::from_mode(0o755)).unwrap();
    assert_eq!(listing(&blind), ["out.csv"]);
    let csv = std::fs::read_to_string(blind.join("out.csv")).unwrap();
    assert!(csv.starts_with(CSV_HEADER), "{csv}");
}
