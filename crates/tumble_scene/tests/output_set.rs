//! An [`OutputSet`] meets a real write error (the file size limit, `ulimit -f`, which fails a
//! write with `EFBIG` as a full disk fails it with `ENOSPC`) half-way through its files: every old
//! file stays as it was and no temporary file is left.
//!
//! The limit applies to a whole process, so the test runs itself again in a child under it: the
//! shell ignores `SIGXFSZ` (an ignored signal stays ignored across `exec`), so the write returns
//! the error instead of killing the child.

#![cfg(unix)]

use std::path::Path;
use std::process::Command;

use tumble_scene::output::{OutputError, OutputSet};

/// Set in the child: the directory it writes into.
const CHILD_DIR: &str = "TUMBLE_OUTPUT_SET_CHILD_DIR";
/// The limit in the child, in blocks of 512 bytes (POSIX `ulimit -f`).
const LIMIT_BLOCKS: usize = 8;

fn listing(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

#[test]
fn a_write_error_half_way_leaves_every_old_file() {
    let dir = tempfile::tempdir().unwrap();
    for name in ["report.md", "results.json", "plot.svg"] {
        std::fs::write(dir.path().join(name), format!("old {name}")).unwrap();
    }
    let child = Command::new("sh")
        .arg("-c")
        .arg(format!(
            "trap '' XFSZ; ulimit -f {LIMIT_BLOCKS} && exec \"$0\" \"$@\""
        ))
        .arg(std::env::current_exe().unwrap())
        .args(["--exact", "child_writes_past_the_limit", "--nocapture"])
        .env(CHILD_DIR, dir.path())
        // Pipes, not the parent's stdout and stderr: those may be files (a CI log) already
        // past the child's size limit, and the harness's own output would fail there.
        .output()
        .unwrap();
    assert!(
        child.status.success(),
        "the child failed: {}\n{}{}",
        child.status,
        String::from_utf8_lossy(&child.stdout),
        String::from_utf8_lossy(&child.stderr)
    );
    for name in ["report.md", "results.json", "plot.svg"] {
        let text = std::fs::read_to_string(dir.path().join(name)).unwrap();
        assert_eq!(text, format!("old {name}"));
    }
    assert_eq!(
        listing(dir.path()),
        ["plot.svg", "report.md", "results.json"]
    );
}

/// The child's half of the test above; without its variable (a plain `cargo test`) it has
/// nothing to do.
#[test]
fn child_writes_past_the_limit() {
    let Some(dir) = std::env::var_os(CHILD_DIR) else {
        return;
    };
    let dir = Path::new(&dir);
    let mut set = OutputSet::new();
    set.add(&dir.join("plot.svg"), b"new plot").unwrap();
    let too_big = vec![b'x'; 2 * LIMIT_BLOCKS * 512];
    let err = set.add(&dir.join("results.json"), &too_big).unwrap_err();
    match &err {
        OutputError::Io { source, .. } => {
            assert_eq!(source.raw_os_error(), Some(27), "EFBIG expected: {err}")
        }
        other => panic!("expected an I/O error, got {other}"),
    }
    assert!(err.to_string().contains("results.json"), "{err}");
    assert!(
        !err.to_string().contains(".tumble-"),
        "a temporary name: {err}"
    );
    drop(set);
}
