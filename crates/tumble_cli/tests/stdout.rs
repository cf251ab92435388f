//! A failed write to standard output is an `error:` line and exit code 1, never a panic (exit
//! 101) and never a success with the output lost: a pipe whose reader is gone, a full device, a
//! standard output opened read-only, and one closed (which Rust's runtime turns into
//! `/dev/null` before `main`, where writes would succeed unread).

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
        (last.starts_with("error: writing") || last.starts_with("error: standard output"))
            && last.contains("standard output"),
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

#[cfg(unix)]
#[test]
fn a_read_only_standard_output_is_an_error() {
    for args in PRINTING {
        let read_only = std::fs::File::open("/dev/null").unwrap();
        let output = tumble()
            .args(*args)
            .stdout(Stdio::from(read_only))
            .stderr(Stdio::piped())
            .output()
            .unwrap();
        check_failed(args, &output, "a read-only descriptor");
    }
}

/// A closed standard output (`>&-`) is an error; `> /dev/null`, output the caller discards on
/// purpose, is a success.
#[cfg(target_os = "linux")]
#[test]
fn a_closed_standard_output_is_an_error_and_dev_null_is_not() {
    let shell = |redirect: &str, args: &[&str]| {
        std::process::Command::new("sh")
            .arg("-c")
            .arg(format!("exec \"$0\" \"$@\" {redirect}"))
            .arg(env!("CARGO_BIN_EXE_tumble"))
            .args(args)
            .stderr(Stdio::piped())
            .output()
            .unwrap()
    };
    for args in PRINTING {
        check_failed(args, &shell(">&-", args), "a closed descriptor");
        let discarded = shell("> /dev/null", args);
        assert!(
            discarded.status.success(),
            "{args:?} into /dev/null: {}",
            String::from_utf8_lossy(&discarded.stderr)
        );
    }
}
