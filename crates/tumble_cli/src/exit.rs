//! Exit codes, in one place (the guide's CLI page, `docs/cli.md`, has the same table), and the
//! error type every command returns.

use std::fmt;
use std::io::Write;
use std::process::ExitCode;

/// The command did what was asked.
pub(crate) const SUCCESS: u8 = 0;
/// An error: bad input (scene file, flag value) or I/O (unreadable scene, unwritable output).
pub(crate) const ERROR: u8 = 1;
/// A usage error found by the argument parser (unknown flag, missing value).
pub(crate) const USAGE: u8 = 2;
/// The run finished, but a body was rejected (quarantined) or diverged.
pub(crate) const REJECTED: u8 = 3;
/// tumble predicts the step unstable for the scene, or its method cannot step it (a first-order
/// integrator on a stiff spring group): refused unless `--allow-unstable`.
pub(crate) const UNSTABLE: u8 = 4;
/// Interrupted by a signal that ends the process (SIGINT, SIGTERM, SIGHUP, SIGUSR1, …: see
/// `interrupt`; 128 + SIGINT, as shells report it); nothing was written.
pub(crate) const INTERRUPTED: u8 = 130;

/// A failed command: the one-line message for stderr and the exit code.
#[derive(Debug)]
pub struct Failure {
    /// One of the codes above (never [`SUCCESS`]).
    pub code: u8,
    /// The message, without the `error: ` prefix; one line.
    pub message: String,
}

impl Failure {
    /// A failure with exit code `code`.
    pub fn new(code: u8, message: impl Into<String>) -> Self {
        Self {
            code,
            message: message.into(),
        }
    }

    /// Prints `error: <message>` on stderr, on one line, and gives the exit code.
    pub fn report(&self) -> ExitCode {
        // A message built from a library error may hold a line break: keep it to one line.
        let message = self.message.replace(['\n', '\r'], " ");
        // A closed stderr must not turn the report into a panic: the exit code still tells.
        let _ = writeln!(std::io::stderr(), "error: {message}");
        ExitCode::from(self.code)
    }
}

/// Any displayable error is a plain error (exit code [`ERROR`]).
impl<E: fmt::Display> From<E> for Failure {
    fn from(e: E) -> Self {
        Self::new(ERROR, e.to_string())
    }
}
