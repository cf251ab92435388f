//! SIGINT / SIGTERM (and SIGHUP, and on Unix every other signal whose default action ends the
//! process and that another process can send: SIGUSR1, SIGUSR2, SIGALRM, SIGVTALRM, SIGPROF,
//! SIGXCPU, SIGQUIT, SIGIO, SIGTRAP, SIGSYS, SIGABRT, and on Linux SIGPWR, SIGSTKFLT and the
//! real-time signals SIGRTMIN–SIGRTMAX; not the faults SIGSEGV, SIGBUS, SIGILL and SIGFPE,
//! whose handler would return to the faulting instruction, nor SIGKILL): a flag that long
//! loops poll, so that they return an error, drop their temporary file and exit with
//! [`exit::INTERRUPTED`]. SIGXFSZ (a write past the file-size limit, `ulimit -f`) is caught and
//! ignored, so that the write fails with `EFBIG` and takes the ordinary error path, which
//! removes the temporary file, instead of killing the process and leaving it.
//!
//! Only the loops that poll (`run`, `gen`) can stop cleanly. Elsewhere (`report`, `bench`, or a
//! second Ctrl-C while a loop winds down) the handler exits at once with the same code, as the
//! default action of the signal would.

use std::sync::atomic::{AtomicBool, Ordering};

use crate::exit;

static INTERRUPTED: AtomicBool = AtomicBool::new(false);
static POLLED: AtomicBool = AtomicBool::new(false);

/// Installs the handler (once, at start-up). A failure to install is logged, not fatal: the
/// signals then keep their default action.
pub(crate) fn install() {
    if let Err(e) = ctrlc::set_handler(on_signal) {
        tracing::warn!("cannot handle Ctrl-C ({e}); an interrupted run may leave a temporary file");
    }
    #[cfg(unix)]
    install_other_signals();
}

/// What every ending signal does: set the flag for a loop that polls, or exit at once.
fn on_signal() {
    let again = INTERRUPTED.swap(true, Ordering::SeqCst);
    if again || !POLLED.load(Ordering::SeqCst) {
        // No destructor runs from here: remove what an unwinding exit would have removed.
        tumble_scene::output::remove_live_temporary_files();
        // The one `error:` line every failure ends with (this runs on a thread of its own,
        // not in the signal's context, so it may write; a closed stderr is no reason to stay).
        let _ = std::io::Write::write_all(
            &mut std::io::stderr(),
            b"error: interrupted; no output file was written or changed\n",
        );
        std::process::exit(i32::from(exit::INTERRUPTED));
    }
}

/// The Unix signals ctrlc leaves at their default action (see the module docs).
#[cfg(unix)]
fn install_other_signals() {
    use signal_hook::consts::signal::{
        SIGABRT, SIGALRM, SIGIO, SIGPROF, SIGQUIT, SIGSYS, SIGTRAP, SIGUSR1, SIGUSR2, SIGVTALRM,
        SIGXCPU, SIGXFSZ,
    };
    // A handler of its own replaces the default action (terminate): the write that crossed
    // the limit then fails with EFBIG.
    let ignored = std::sync::Arc::new(AtomicBool::new(false));
    if let Err(e) = signal_hook::flag::register(SIGXFSZ, ignored) {
        tracing::warn!(
            "cannot handle SIGXFSZ ({e}); a run over `ulimit -f` may leave a temporary file"
        );
    }
    let mut ending = vec![
        SIGUSR1, SIGUSR2, SIGALRM, SIGVTALRM, SIGPROF, SIGXCPU, SIGQUIT, SIGIO, SIGTRAP, SIGSYS,
        SIGABRT,
    ];
    #[cfg(target_os = "linux")]
    ending.extend(
        [libc::SIGPWR, libc::SIGSTKFLT]
            .into_iter()
            .chain(libc::SIGRTMIN()..=libc::SIGRTMAX()),
    );
    match signal_hook::iterator::Signals::new(ending) {
        Ok(mut signals) => {
            std::thread::spawn(move || {
                for _ in signals.forever() {
                    on_signal();
                }
            });
        }
        Err(e) => tracing::warn!(
            "cannot handle SIGUSR1 and the like ({e}); such a signal may leave a temporary file"
        ),
    }
}

/// While alive, a signal sets the flag instead of exiting: the holder polls [`Guard::interrupted`].
pub(crate) struct Guard(());

impl Guard {
    /// Starts polling.
    pub(crate) fn poll() -> Self {
        POLLED.store(true, Ordering::SeqCst);
        Self(())
    }

    /// Whether a signal arrived.
    #[inline]
    pub(crate) fn interrupted(&self) -> bool {
        INTERRUPTED.load(Ordering::Relaxed)
    }
}

impl Drop for Guard {
    fn drop(&mut self) {
        POLLED.store(false, Ordering::SeqCst);
    }
}
