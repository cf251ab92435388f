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

/// What is registered: where to find it when the process must end at once.
#[derive(Debug)]
enum Entry {
    /// A temporary file by its path.
    File(CString),
    /// A temporary file by its name in a directory held open: found even if the directory
    /// was moved or replaced since.
    #[cfg(unix)]
    FileIn(std::os::fd::OwnedFd, CString),
    /// A directory made for outputs.
    Directory(CString),
}

/// The live temporary files and directories, by registration number.
static LIVE: Mutex<Vec<(u64, Entry)>> = Mutex::new(Vec::new());
static NEXT: AtomicU64 = AtomicU64::new(0);

/// A registered temporary file; dropping it deregisters the path.
#[derive(Debug)]
pub(crate) struct LiveTemporary(Option<u64>);

impl LiveTemporary {
    /// Registers `path` (a path that cannot be a C string, with a NUL byte, is not registered:
    /// no file can have it).
    #[cfg_attr(unix, allow(dead_code))]
    pub(crate) fn register(path: &Path) -> Self {
        Self::register_entry(c_string(path).map(Entry::File))
    }

    /// Registers the file `name` in the directory `dir` (held open: a duplicate of it is kept).
    #[cfg(unix)]
    pub(crate) fn register_in(dir: std::os::fd::BorrowedFd<'_>, name: &Path) -> Self {
        let entry = dir
            .try_clone_to_owned()
            .ok()
            .zip(c_string(name))
            .map(|(dir, name)| Entry::FileIn(dir, name));
        Self::register_entry(entry)
    }

    /// Registers a directory made for outputs: removed at such an exit if it is empty then.
    pub(crate) fn register_directory(path: &Path) -> Self {
        Self::register_entry(c_string(path).map(Entry::Directory))
    }

    fn register_entry(entry: Option<Entry>) -> Self {
        let Some(entry) = entry else {
            return Self(None);
        };
        let id = NEXT.fetch_add(1, Ordering::Relaxed);
        if let Ok(mut live) = LIVE.lock() {
            live.push((id, entry));
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

/// Unlinks every temporary file still registered, then removes every registered directory
/// that is empty then (the newest first: a directory's files and subdirectories were made
/// after it), allocating nothing, for an exit that will not run destructors. Does nothing if
/// the registry is busy (an exit from inside a registration): waiting there could wait forever.
pub fn remove_live_temporary_files() {
    let Ok(mut live) = LIVE.try_lock() else {
        return;
    };
    for (_, entry) in live.iter().rev() {
        #[cfg(unix)]
        {
            let _ = match entry {
                Entry::File(path) => rustix::fs::unlink(path.as_c_str()),
                Entry::FileIn(dir, name) => {
                    rustix::fs::unlinkat(dir, name.as_c_str(), rustix::fs::AtFlags::empty())
                }
                Entry::Directory(path) => rustix::fs::rmdir(path.as_c_str()),
            };
        }
        #[cfg(not(unix))]
        {
            let _ = entry;
        }
    }
    live.clear();
}

/// `path` as a C string; `None` for a path with a NUL byte (no file can have it).
fn c_string(path: &Path) -> Option<CString> {
    CString::new(path.as_os_str().as_encoded_bytes()).ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn live_files_and_empty_made_directories_are_removed_and_finished_ones_left() {
        let dir = tempfile::tempdir().unwrap();
        let (kept, left) = (dir.path().join("kept"), dir.path().join("left"));
        std::fs::write(&kept, "a").unwrap();
        std::fs::write(&left, "b").unwrap();
        let finished = LiveTemporary::register(&kept);
        drop(finished);
        let _live = LiveTemporary::register(&left);
        // Directories made for outputs go when empty once the files are gone; one holding
        // anything else stays. (One test calls the removal: it empties the whole registry.)
        let (empty, full) = (dir.path().join("empty"), dir.path().join("full"));
        let inner = empty.join("inner");
        std::fs::create_dir_all(&inner).unwrap();
        std::fs::create_dir(&full).unwrap();
        let temporary = inner.join(".t");
        std::fs::write(&temporary, "x").unwrap();
        std::fs::write(full.join("kept"), "y").unwrap();
        let _made = [
            LiveTemporary::register_directory(&empty),
            LiveTemporary::register_directory(&inner),
            LiveTemporary::register(&temporary),
            LiveTemporary::register_directory(&full),
        ];
        // A file registered in a directory held open goes even after the directory moved.
        #[cfg(unix)]
        let (_in_moved, in_moved) = {
            let held = dir.path().join("held");
            std::fs::create_dir(&held).unwrap();
            std::fs::write(held.join(".u"), "z").unwrap();
            let fd = rustix::fs::open(
                &held,
                rustix::fs::OFlags::RDONLY | rustix::fs::OFlags::DIRECTORY,
                rustix::fs::Mode::empty(),
            )
            .unwrap();
            let live = LiveTemporary::register_in(std::os::fd::AsFd::as_fd(&fd), Path::new(".u"));
            let moved = dir.path().join("moved");
            std::fs::rename(&held, &moved).unwrap();
            (live, moved.join(".u"))
        };
        remove_live_temporary_files();
        #[cfg(unix)]
        assert!(!in_moved.exists(), "found by its directory, not its path");
        assert!(kept.exists());
        assert!(!left.exists());
        assert!(!empty.exists(), "its file and subdirectory went first");
        assert!(
            full.join("kept").exists(),
            "a directory with other files stays"
        );
    }
}
