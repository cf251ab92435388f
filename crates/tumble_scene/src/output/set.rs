//! Several output files that replace their old versions together or not at all (the report's
//! directory, the benchmark's files and the README they update).
//!
//! Each file goes through an [`OutputFile`] (checked, temporary file beside it). [`OutputSet`]
//! writes *and syncs* every one before the first rename, then checks every destination again,
//! then renames them all: a full disk, a file size limit, a file made read-only or an error in the
//! caller's own work leaves every old file as it was, and the renames themselves need no space.
//! Dropped without [`commit`](OutputSet::commit), every temporary file is removed.
//!
//! [`OutputSet::check`] runs the same checks on a destination before any work, so a place that
//! cannot be written fails in a moment rather than after minutes of measurement. It creates
//! nothing: a directory the outputs need is made when the first file goes into it, and removed
//! again (if still empty) when the set is dropped without a commit, or by
//! [`remove_live_temporary_files`](super::remove_live_temporary_files) when the process ends
//! without unwinding.

use std::io::Write;
use std::path::{Path, PathBuf};

use super::live::LiveTemporary;
use super::{OutputError, OutputFile};

/// Files written in full first and renamed into place together by [`commit`](Self::commit).
#[derive(Debug, Default)]
pub struct OutputSet {
    files: Vec<OutputFile>,
    /// The directories this set made for its files, outermost first: removed again unless the
    /// set commits.
    made: Vec<(PathBuf, LiveTemporary)>,
}

impl OutputSet {
    /// An empty set.
    pub fn new() -> Self {
        Self::default()
    }

    /// Checks, before any work, that `path` could be written now: its directory exists and
    /// takes a new file, and an existing `path` may be replaced (the rules of
    /// [`OutputFile::create`]), or its directory is missing and the nearest directory above it
    /// that exists takes a new entry. Nothing is left behind, not even a directory.
    pub fn check(path: &Path) -> Result<(), OutputError> {
        let dir = directory_of(path);
        let existing = nearest_existing(dir)?;
        if existing == dir {
            return OutputFile::create(path, &[]).map(drop);
        }
        // A directory made and removed at once shows that one can be made there.
        tempfile::Builder::new()
            .prefix(".tumble-")
            .tempdir_in(existing)
            .map(drop)
            .map_err(|e| OutputError::io(dir, e))
    }

    /// Writes `bytes` into a temporary file that will replace `path` and syncs it to disk,
    /// making its directory (and the ones above it) where missing; the output itself is not
    /// touched until [`commit`](Self::commit). A path added twice keeps the bytes added last.
    pub fn add(&mut self, path: &Path, bytes: &[u8]) -> Result<(), OutputError> {
        self.make_directory(directory_of(path))?;
        let mut file = OutputFile::create(path, &[])?;
        file.write_all(bytes)
            .and_then(|()| file.flush())
            .and_then(|()| file.file().sync_all())
            .map_err(|e| OutputError::io(path, e))?;
        self.files.retain(|f| f.path() != path);
        self.files.push(file);
        Ok(())
    }

    /// Makes `dir` and every missing directory above it, one at a time, as [`add`](Self::add)
    /// does for a file's directory: removed again (if empty) unless the set commits. For work
    /// that needs the outputs' directory before their files (a private staging directory there).
    pub fn make_directory(&mut self, dir: &Path) -> Result<(), OutputError> {
        let existing = nearest_existing(dir)?;
        let missing: Vec<&Path> = dir
            .ancestors()
            .take_while(|a| *a != existing && !a.as_os_str().is_empty())
            .collect();
        for a in missing.into_iter().rev() {
            match std::fs::create_dir(a) {
                Ok(()) => {
                    let live = LiveTemporary::register_directory(a);
                    self.made.push((a.to_owned(), live));
                }
                // Made by someone else meanwhile: theirs, not removed.
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists && a.is_dir() => {}
                Err(e) => return Err(OutputError::io(a, e)),
            }
        }
        Ok(())
    }

    /// The paths added so far, in order.
    pub fn paths(&self) -> impl Iterator<Item = &Path> {
        self.files.iter().map(OutputFile::path)
    }

    /// Checks every destination again, then renames every file into place (in the order added).
    /// An error in the checks leaves every output untouched.
    pub fn commit(mut self) -> Result<(), OutputError> {
        let files = std::mem::take(&mut self.files);
        for file in &files {
            file.check_destination()?;
        }
        for file in files {
            file.commit()?;
        }
        // The directories now hold the outputs: kept.
        self.made.clear();
        Ok(())
    }
}

impl Drop for OutputSet {
    /// Removes the temporary files, then the directories the set made, innermost first (each
    /// only if empty: whatever else was put there stays).
    fn drop(&mut self) {
        self.files.clear();
        while let Some((dir, _live)) = self.made.pop() {
            let _ = std::fs::remove_dir(&dir);
        }
    }
}

/// The directory `path` goes into (`.` for a bare name).
fn directory_of(path: &Path) -> &Path {
    match path.parent() {
        Some(dir) if !dir.as_os_str().is_empty() => dir,
        _ => Path::new("."),
    }
}

/// `dir`, or the nearest directory above it that exists; an error if that is not a directory.
fn nearest_existing(dir: &Path) -> Result<&Path, OutputError> {
    let mut at = dir;
    loop {
        match std::fs::metadata(at) {
            Ok(meta) if meta.is_dir() => return Ok(at),
            Ok(_) => {
                return Err(OutputError::NotDirectory {
                    path: at.to_owned(),
                });
            }
            // Missing, or under something that is not a directory (found further up).
            Err(e)
                if matches!(
                    e.kind(),
                    std::io::ErrorKind::NotFound | std::io::ErrorKind::NotADirectory
                ) =>
            {
                at = match at.parent() {
                    Some(up) if !up.as_os_str().is_empty() => up,
                    _ => Path::new("."),
                };
            }
            Err(e) => return Err(OutputError::io(at, e)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn listing(dir: &Path) -> Vec<String> {
        let mut names: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        names
    }

    #[test]
    fn nothing_is_replaced_before_commit_and_everything_after() {
        let dir = tempfile::tempdir().unwrap();
        let (a, b) = (dir.path().join("a.md"), dir.path().join("sub/b.json"));
        std::fs::write(&a, "old a").unwrap();
        OutputSet::check(&a).unwrap();
        OutputSet::check(&b).unwrap();
        let mut set = OutputSet::new();
        set.add(&a, b"new a").unwrap();
        set.add(&b, b"first b").unwrap();
        set.add(&b, b"new b").unwrap();
        assert_eq!(std::fs::read_to_string(&a).unwrap(), "old a");
        assert!(!b.exists());
        assert_eq!(set.paths().collect::<Vec<_>>(), [a.as_path(), b.as_path()]);
        set.commit().unwrap();
        assert_eq!(std::fs::read_to_string(&a).unwrap(), "new a");
        assert_eq!(std::fs::read_to_string(&b).unwrap(), "new b");
        assert_eq!(listing(dir.path()), ["a.md", "sub"]);
        assert_eq!(listing(&dir.path().join("sub")), ["b.json"]);
    }

    #[test]
    fn a_failed_file_or_a_dropped_set_leaves_every_old_file() {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().unwrap();
        let (a, b) = (dir.path().join("a.md"), dir.path().join("b.md"));
        std::fs::write(&a, "old a").unwrap();
        std::fs::write(&b, "old b").unwrap();
        std::fs::set_permissions(&b, std::fs::Permissions::from_mode(0o444)).unwrap();
        let err = OutputSet::check(&b).unwrap_err();
        assert!(matches!(err, OutputError::ReadOnly { .. }), "{err}");
        let mut set = OutputSet::new();
        set.add(&a, b"new a").unwrap();
        let err = set.add(&b, b"new b").unwrap_err();
        assert!(matches!(err, OutputError::ReadOnly { .. }), "{err}");
        drop(set);
        assert_eq!(std::fs::read_to_string(&a).unwrap(), "old a");
        assert_eq!(std::fs::read_to_string(&b).unwrap(), "old b");
        assert_eq!(listing(dir.path()), ["a.md", "b.md"]);

        // Made read-only after its bytes were written: the check before the renames refuses it,
        // and the file added before it is not replaced either.
        std::fs::set_permissions(&b, std::fs::Permissions::from_mode(0o644)).unwrap();
        let mut set = OutputSet::new();
        set.add(&a, b"new a").unwrap();
        set.add(&b, b"new b").unwrap();
        std::fs::set_permissions(&b, std::fs::Permissions::from_mode(0o444)).unwrap();
        let err = set.commit().unwrap_err();
        assert!(matches!(err, OutputError::ReadOnly { .. }), "{err}");
        assert_eq!(std::fs::read_to_string(&a).unwrap(), "old a");
        assert_eq!(std::fs::read_to_string(&b).unwrap(), "old b");
        assert_eq!(listing(dir.path()), ["a.md", "b.md"]);
    }

    #[test]
    fn directories_are_made_when_files_go_in_and_only_kept_by_a_commit() {
        let dir = tempfile::tempdir().unwrap();
        let deep = dir.path().join("a/b/c");
        let (report, plot) = (deep.join("report.md"), dir.path().join("a/plot.svg"));
        // The check makes nothing, however deep the missing directories go.
        OutputSet::check(&report).unwrap();
        OutputSet::check(&plot).unwrap();
        assert!(listing(dir.path()).is_empty());
        // A directory made for work before the files, then the set dropped: gone again.
        let mut set = OutputSet::new();
        set.make_directory(&deep).unwrap();
        assert!(deep.is_dir());
        drop(set);
        assert!(listing(dir.path()).is_empty());
        // Files added, then the set dropped (the work failed after them): nothing is left.
        let mut set = OutputSet::new();
        set.add(&report, b"r").unwrap();
        set.add(&plot, b"p").unwrap();
        assert!(deep.is_dir());
        drop(set);
        assert!(listing(dir.path()).is_empty(), "{:?}", listing(dir.path()));
        // A directory that held something else before the set is not removed with its own.
        std::fs::create_dir(dir.path().join("a")).unwrap();
        std::fs::write(dir.path().join("a/mine"), "m").unwrap();
        let mut set = OutputSet::new();
        set.add(&report, b"r").unwrap();
        drop(set);
        assert_eq!(listing(&dir.path().join("a")), ["mine"]);
        // Committed: the directories and files stay.
        let mut set = OutputSet::new();
        set.add(&report, b"r").unwrap();
        set.add(&plot, b"p").unwrap();
        set.commit().unwrap();
        assert_eq!(std::fs::read_to_string(&report).unwrap(), "r");
        assert_eq!(listing(&dir.path().join("a")), ["b", "mine", "plot.svg"]);
    }

    #[test]
    fn a_place_that_takes_no_file_fails_the_check() {
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("file");
        std::fs::write(&file, "x").unwrap();
        let err = OutputSet::check(&file.join("report.md")).unwrap_err();
        assert!(matches!(err, OutputError::NotDirectory { .. }), "{err}");
        let err = OutputSet::check(&file.join("deeper/report.md")).unwrap_err();
        assert!(matches!(err, OutputError::NotDirectory { .. }), "{err}");
        // A missing directory under one that takes no entry.
        let err = OutputSet::check(Path::new("/proc/self/new/report.md")).unwrap_err();
        assert!(matches!(err, OutputError::Io { .. }), "{err}");
        // Not even root can create a file here.
        let err = OutputSet::check(Path::new("/proc/self/report.md")).unwrap_err();
        assert!(matches!(err, OutputError::Io { .. }), "{err}");
        assert_eq!(std::fs::read_to_string(&file).unwrap(), "x");
    }
}
