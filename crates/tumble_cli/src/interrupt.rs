//! SIGINT / SIGTERM (and SIGHUP): a flag that long loops poll, so that they return an error, drop
//! their temporary file and exit with [`exit::INTERRUPTED`].
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
pub fn install() {
    if let Err(e) = ctrlc::set_handler(|| {
        let again = INTERRUPTED.swap(true, Ordering::SeqCst);
        if again || !POLLED.load(Ordering::SeqCst) {
            std::process::exit(i32::from(exit::INTERRUPTED));
        }
    }) {
        tracing::warn!("cannot handle Ctrl-C ({e}); an interrupted run may leave a temporary file");
    }
}

/// While alive, a signal sets the flag instead of exiting: the holder polls [`Guard::interrupted`].
pub struct Guard(());

impl Guard {
    /// Starts polling.
    pub fn poll() -> Self {
        POLLED.store(true, Ordering::SeqCst);
        Self(())
    }

    /// Whether a signal arrived.
    #[inline]
    pub fn interrupted(&self) -> bool {
        INTERRUPTED.load(Ordering::Relaxed)
    }
}

impl Drop for Guard {
    fn drop(&mut self) {
        POLLED.store(false, Ordering::SeqCst);
    }
}
