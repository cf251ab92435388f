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
//! cannot be written fails in a moment rather than after minutes of measurement.

use std::io::Write;
use std::path::Path;

use super::{OutputError, OutputFile, create_directory};

/// Files written in full first and renamed into place together by [`commit`](Self::commit).
#[derive(Debug, Default)]
pub struct OutputSet {
    files: Vec<OutputFile>,
}

impl OutputSet {
    /// An empty set.
    pub fn new() -> Self {
        Self::default()
    }

    /// Checks, before any work, that `path` could be written now: its directory exists (it is
    /// created if absent) and takes a new file, and an existing `path` may be replaced (the rules
    /// of [`OutputFile::create`]). Nothing visible is left behind.
    pub fn check(path: &Path) -> Result<(), OutputError> {
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            create_directory(dir)?;
        }
        OutputFile::create(path, &[]).map(drop)
    }

    /// Writes `bytes` into a temporary file that will replace `path` and syncs it to disk; the
    /// output itself is not touched until [`commit`](Self::commit). A path added twice keeps the
    /// bytes added last.
    pub fn add(&mut self, path: &Path, bytes: &[u8]) -> Result<(), OutputError> {
        let mut file = OutputFile::create(path, &[])?;
        file.write_all(bytes)
            .and_then(|()| file.flush())
            .and_then(|()| file.file().sync_all())
            .map_err(|e| OutputError::io(path, e))?;
        self.files.retain(|f| f.path() != path);
        self.files.push(file);
        Ok(())
    }

    /// The paths added so far, in order.
    pub fn paths(&self) -> impl Iterator<Item = &Path> {
        self.files.iter().map(OutputFile::path)
    }

    /// Checks every destination again, then renames every file into place (in the order added).
    /// An error in the checks leaves every output untouched.
    pub fn commit(self) -> Result<(), OutputError> {
        for file in &self.files {
            file.check_destination()?;
        }
        for file in self.files {
            file.commit()?;
        }
        Ok(())
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
    fn a_place_that_takes_no_file_fails_the_check() {
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("file");
        std::fs::write(&file, "x").unwrap();
        let err = OutputSet::check(&file.join("report.md")).unwrap_err();
        assert!(matches!(err, OutputError::NotDirectory { .. }), "{err}");
        // Not even root can create a file here.
        let err = OutputSet::check(Path::new("/proc/self/report.md")).unwrap_err();
        assert!(matches!(err, OutputError::Io { .. }), "{err}");
        assert_eq!(std::fs::read_to_string(&file).unwrap(), "x");
    }
}
