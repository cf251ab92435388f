//! Helpers shared by the tests of the `tumble` binary.

#![allow(
    dead_code,
    reason = "each test binary uses its own part of these helpers"
)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The binary, with the caller's `RUST_LOG` removed: messages are compared line by line and the
/// caller's log settings must not add any.
pub(crate) fn tumble() -> Command {
    let mut command = Command::new(env!("CARGO_BIN_EXE_tumble"));
    command.env_remove("RUST_LOG");
    command
}

/// The path of a bundled scene file.
pub(crate) fn scene_path(name: &str) -> String {
    format!("{}/../../scenes/{name}.toml", env!("CARGO_MANIFEST_DIR"))
}

/// A fresh temporary directory under the build's own scratch folder (`CARGO_TARGET_TMPDIR`),
/// not the system's: `/tmp` may be a small RAM disk, and a test about files must not fail
/// because the runner gave `/tmp` a few megabytes.
pub(crate) fn scratch_dir() -> tempfile::TempDir {
    tempfile::tempdir_in(env!("CARGO_TARGET_TMPDIR")).unwrap()
}

/// A fresh temporary directory and the path `name` in it (not created).
pub(crate) fn scratch(name: &str) -> (tempfile::TempDir, PathBuf) {
    let dir = scratch_dir();
    let path = dir.path().join(name);
    (dir, path)
}

/// Runs the binary with `args` and `--out out`.
pub(crate) fn tumble_out(args: &[&str], out: &Path) -> Output {
    tumble().args(args).arg("--out").arg(out).output().unwrap()
}

/// What the command printed on stdout, lossily.
pub(crate) fn stdout(output: &Output) -> String {
    String::from_utf8_lossy(&output.stdout).into_owned()
}

/// What the command printed on stderr, lossily.
pub(crate) fn stderr(output: &Output) -> String {
    String::from_utf8_lossy(&output.stderr).into_owned()
}

/// The one line on stderr of a failed command.
pub(crate) fn error_line(output: &Output) -> String {
    let text = stderr(output);
    assert_eq!(text.lines().count(), 1, "one line: {text}");
    text.trim_end().to_owned()
}

/// The final `error:` line of a run that also logged warnings or quarantines before it.
pub(crate) fn last_error_line(output: &Output) -> String {
    let text = stderr(output);
    let errors: Vec<&str> = text.lines().filter(|l| l.starts_with("error: ")).collect();
    assert_eq!(errors.len(), 1, "one error line: {text}");
    errors[0].to_owned()
}

/// A flag, the message tumble gives for a bad value of it, and bad values.
pub(crate) type BadValues<'a> = (&'a str, &'a str, &'a [&'a str]);

/// Runs `command FLAG VALUE` for every bad value of `cases`; gives the arguments added, the
/// line tumble must print (`error: FLAG: MESSAGE, got VALUE`) and the output of each run.
pub(crate) fn bad_value_runs(
    command: &[&str],
    cases: &[BadValues],
) -> Vec<([String; 2], String, Output)> {
    let mut runs = Vec::new();
    for &(flag, message, values) in cases {
        for value in values {
            let output = tumble().args(command).args([flag, value]).output().unwrap();
            let expected = format!("error: {flag}: {message}, got {value}");
            runs.push(([flag.to_owned(), (*value).to_owned()], expected, output));
        }
    }
    runs
}

/// Runs the binary with `args`.
pub(crate) fn tumble_run(args: &[&str]) -> Output {
    tumble().args(args).output().unwrap()
}

/// The one error line of a run that must fail with exit code `code`.
pub(crate) fn failure(output: &Output, code: i32) -> String {
    assert_eq!(output.status.code(), Some(code), "{}", stderr(output));
    error_line(output)
}

/// A fresh temporary directory holding the file `name` with `contents`, and its path.
pub(crate) fn scratch_file(name: &str, contents: &str) -> (tempfile::TempDir, PathBuf) {
    let (dir, path) = scratch(name);
    std::fs::write(&path, contents).unwrap();
    (dir, path)
}
