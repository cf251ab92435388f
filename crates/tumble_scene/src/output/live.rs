//! The temporary files alive now, so that an exit that cannot unwind still removes them: a
//! signal while `report` or `bench` writes, memory exhausted (the CLI's allocator exits at
//! once; see `tumble_cli`), anything that ends the process without dropping an [`OutputFile`].
//!
//! Each temporary file registers its path, already as a C string, when it is created and leaves
//! when it is renamed or removed; [`remove_live_temporary_files`] unlinks what is left without
//! allocating.
//!
//! [`OutputFile`]: super::OutputFile

use std::ffi::CString;
use std::path::Path;
use std::sync::Mutex;
use std::sync::atomic::{AtomicU64, Ordering};

/// The paths of the live temporary files, by registration number.
static LIVE: Mutex<Vec<(u64, CString)>> = Mutex::new(Vec::new());
static NEXT: AtomicU64 = AtomicU64::new(0);

/// A registered temporary file; dropping it deregisters the path.
#[derive(Debug)]
pub(crate) struct LiveTemporary(Option<u64>);

impl LiveTemporary {
    /// Registers `path` (a path that cannot be a C string, with a NUL byte, is not registered:
    /// no file can have it).
    pub(crate) fn register(path: &Path) -> Self {
        let Ok(c_path) = CString::new(path.as_os_str().as_encoded_bytes()) else {
            return Self(None);
        };
        let id = NEXT.fetch_add(1, Ordering::Relaxed);
        if let Ok(mut live) = LIVE.lock() {
            live.push((id, c_path));
        }
        Self(Some(id))
    }
}

impl Drop for LiveTemporary {
    fn drop(&mut self) {
        if let Some(id) = self.0
            && let Ok(mut live) = LIVE.lock()
        {
            live.retain(|(i, _)| *i != id);
        }
    }
}

/// Unlinks every temporary file still registered, allocating nothing, for an exit that will not
/// run destructors. Does nothing if the registry is busy (an exit from inside a registration):
/// waiting there could wait forever.
pub fn remove_live_temporary_files() {
    let Ok(mut live) = LIVE.try_lock() else {
        return;
    };
    for (_, path) in live.iter() {
        #[cfg(unix)]
        {
            let _ = rustix::fs::unlink(path.as_c_str());
        }
        #[cfg(not(unix))]
        {
            let _ = path;
        }
    }
    live.clear();
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn live_files_are_removed_and_finished_ones_left() {
        let dir = tempfile::tempdir().unwrap();
        let (kept, left) = (dir.path().join("kept"), dir.path().join("left"));
        std::fs::write(&kept, "a").unwrap();
        std::fs::write(&left, "b").unwrap();
        let finished = LiveTemporary::register(&kept);
        drop(finished);
        let _live = LiveTemporary::register(&left);
        remove_live_temporary_files();
        assert!(kept.exists());
        assert!(!left.exists());
    }
}
