//! A failed write to standard output is an `error:` line and exit code 1, never a panic (exit
//! 101) and never a success with the output lost: a pipe whose reader is gone, and a full
//! device.

mod common;

use std::process::{Output, Stdio};

use common::tumble;

/// The commands that print to standard output, each with what it prints.
const PRINTING: &[&[&str]] = &[
    &["--help"],
    &["--version"],
    &["scenes"],
    &["run", "projectile", "--plan"],
    &["run", "thin_plate", "--checksum", "--steps", "10"],
    &["compare", "dzhanibekov"],
];

fn check_failed(args: &[&str], output: &Output, what: &str) {
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(
        output.status.code(),
        Some(1),
        "{args:?} into {what}: {stderr}"
    );
    let last = stderr.lines().last().unwrap_or_default();
    assert!(
        last.starts_with("error: writing") && last.contains("standard output"),
        "{args:?} into {what}: {stderr}"
    );
    assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
}

#[test]
fn a_closed_pipe_is_an_error() {
    for args in PRINTING {
        // The reader is closed before the command starts: its first write fails (EPIPE).
        let (reader, writer) = std::io::pipe().unwrap();
        drop(reader);
        let output = tumble()
            .args(*args)
            .stdout(Stdio::from(writer))
            .stderr(Stdio::piped())
            .output()
            .unwrap();
        check_failed(args, &output, "a closed pipe");
    }
}

#[test]
fn a_full_device_is_an_error() {
    let Ok(full) = std::fs::OpenOptions::new().write(true).open("/dev/full") else {
        eprintln!("skipped: this platform has no /dev/full");
        return;
    };
    for args in PRINTING {
        let output = tumble()
            .args(*args)
            .stdout(Stdio::from(full.try_clone().unwrap()))
            .stderr(Stdio::piped())
            .output()
            .unwrap();
        check_failed(args, &output, "/dev/full");
    }
}
