//! Output files written safely: one rule for every file tumble writes (trajectories, generated
//! scenes, the report's and the benchmark's files).
//!
//! [`OutputFile::create`] checks the output path, then opens a temporary file in the output's
//! directory with a unique, unpredictable name, exclusively (`O_EXCL`: never through a planted
//! file or symlink). The caller writes into it; [`OutputFile::commit`] renames it over the output
//! as the last step. Dropped without a commit (an error, Ctrl-C), the temporary file is removed.
//! On Unix the output's directory is held open from the start, and the rename and the removal
//! are made relative to it: a directory moved or replaced while tumble writes neither receives
//! the output ([`OutputError::DirectoryMoved`]) nor keeps the temporary file.
//! So the output is either the old file or the complete new one, never a mix; two writers to the
//! same output each have their own temporary file, and the last rename wins.
//!
//! The output path must name a regular file or nothing:
//! - a directory, a device (`/dev/null`), a FIFO or a socket is refused: replacing it by a
//!   regular file would destroy it;
//! - a symbolic link is resolved (up to 40 links), and its final target must be a regular file
//!   or absent: the target is replaced (or created), the link stays. A link in a shared sticky
//!   directory (world-writable with the sticky bit, as `/tmp`) is followed only if it belongs to
//!   the user running tumble or to the directory's owner — the kernel's `protected_symlinks`
//!   rule, which cannot apply here since tumble reads the link itself: otherwise another user
//!   could plant a link there and make a run (as root, say) replace any file. The same holds
//!   for every link in the directories on the way (`/tmp/theirs/out.csv`), which the kernel
//!   follows itself but guards only where the system enables the rule;
//! - an existing file without write permission is refused, as a shell redirect would refuse it
//!   (also for root, who could write it: read-only is taken as the owner's intent);
//! - an existing file keeps its permission bits (and its owner and group where the process may
//!   set them); a new one gets `0o666` less the umask;
//! - a path that is one of the run's input files (same device and inode) is refused.
//!
//! Every error names the path the caller gave, made safe for a terminal
//! ([`path_for_terminal`]). Outputs of several files (the report, the benchmark) go through an
//! [`OutputSet`]: all written before any is replaced.

use std::fs::{File, Metadata, OpenOptions};
use std::io::{self, Write};
use std::path::{Path, PathBuf};

use thiserror::Error;

use crate::text::path_for_terminal;

mod live;
mod sections;
mod set;
pub use live::remove_live_temporary_files;
pub use sections::with_sections;
pub use set::OutputSet;

/// Most symbolic links followed when resolving an output path (Linux's `MAXSYMLINKS`).
pub const MAX_SYMLINKS: usize = 40;

/// Why an output file or directory cannot be written.
#[derive(Debug, Error)]
pub enum OutputError {
    /// The output names a directory.
    #[error("{}: is a directory, expected a file", path_for_terminal(.path))]
    IsDirectory {
        /// The path the caller gave.
        path: PathBuf,
    },
    /// The output names something else that is not a regular file.
    #[error(
        "{}: is not a regular file (a device, FIFO or socket); tumble writes only regular files",
        path_for_terminal(.path)
    )]
    NotRegularFile {
        /// The path the caller gave.
        path: PathBuf,
    },
    /// An output directory names an existing file that is not a directory.
    #[error("{}: exists and is not a directory", path_for_terminal(.path))]
    NotDirectory {
        /// The path the caller gave.
        path: PathBuf,
    },
    /// The output exists and has no write permission.
    #[error("{}: is read-only", path_for_terminal(.path))]
    ReadOnly {
        /// The path the caller gave.
        path: PathBuf,
    },
    /// The output is one of the run's input files.
    #[error(
        "{}: is the input file {}; refusing to overwrite it",
        path_for_terminal(.path),
        path_for_terminal(.input)
    )]
    IsInput {
        /// The path the caller gave.
        path: PathBuf,
        /// The input it resolves to.
        input: PathBuf,
    },
    /// More than [`MAX_SYMLINKS`] symbolic links, or a loop.
    #[error("{}: too many levels of symbolic links", path_for_terminal(.path))]
    SymlinkLoop {
        /// The path the caller gave.
        path: PathBuf,
    },
    /// A symbolic link on the way that another user planted in a shared sticky directory.
    #[error(
        "{}: the symbolic link {} belongs to another user (uid {owner}) in a shared sticky \
         directory; tumble does not follow it, as the kernel's protected_symlinks rule would \
         not: remove it or write elsewhere",
        path_for_terminal(.path),
        path_for_terminal(.link)
    )]
    UntrustedLink {
        /// The path the caller gave.
        path: PathBuf,
        /// The link refused.
        link: PathBuf,
        /// The link's owner.
        owner: u32,
    },
    /// The output's directory was moved or replaced (by another directory, or a link to
    /// one) while tumble wrote: the output is not written into either, and the temporary file
    /// is removed from where it was made.
    #[error(
        "{}: its directory was moved or replaced while tumble wrote; nothing was written",
        path_for_terminal(.path)
    )]
    DirectoryMoved {
        /// The path the caller gave.
        path: PathBuf,
    },
    /// The output path is empty.
    #[error("the output path is empty")]
    EmptyPath,
    /// A Markdown file to update lacks a section's markers (see [`with_sections`]).
    #[error(
        "{}: no <!-- {name}:begin --> … <!-- {name}:end --> markers",
        path_for_terminal(.path)
    )]
    MissingMarkers {
        /// The file.
        path: std::path::PathBuf,
        /// The section's name.
        name: String,
    },
    /// A Markdown file to update holds a section's marker more than once: which pair is the
    /// section is not clear, and replacing one would leave the other stale.
    #[error(
        "{}: more than one <!-- {name}:begin --> or <!-- {name}:end --> marker; expected one pair",
        path_for_terminal(.path)
    )]
    RepeatedMarkers {
        /// The file.
        path: std::path::PathBuf,
        /// The section's name.
        name: String,
    },
    /// An I/O error while checking, writing or renaming.
    #[error("{}: {source}", path_for_terminal(.path))]
    Io {
        /// The path the caller gave.
        path: PathBuf,
        /// What the operating system said.
        source: io::Error,
    },
}

impl OutputError {
    /// An I/O error on the output `path`.
    pub fn io(path: &Path, source: io::Error) -> Self {
        Self::Io {
            path: path.to_owned(),
            source,
        }
    }

    /// The path the caller gave.
    pub fn path(&self) -> &Path {
        match self {
            Self::IsDirectory { path }
            | Self::NotRegularFile { path }
            | Self::NotDirectory { path }
            | Self::ReadOnly { path }
            | Self::IsInput { path, .. }
            | Self::SymlinkLoop { path }
            | Self::UntrustedLink { path, .. }
            | Self::DirectoryMoved { path }
            | Self::MissingMarkers { path, .. }
            | Self::RepeatedMarkers { path, .. }
            | Self::Io { path, .. } => path,
            Self::EmptyPath => Path::new(""),
        }
    }
}

/// A file being written: a temporary file beside the output, renamed over it by
/// [`commit`](Self::commit) (see the [module](self) documentation for the rules).
#[derive(Debug)]
pub struct OutputFile {
    file: File,
    temp: Temporary,
    target: PathBuf,
    path: PathBuf,
    // Declared after `temp`, so dropped after it: the file is gone before it leaves the list.
    _live: live::LiveTemporary,
}

/// Where the temporary file is, to rename or remove it. On Unix its directory is held open,
/// and both are done relative to it: a directory moved or replaced while tumble writes (by a
/// link, say) can then neither receive the output nor keep the temporary file.
#[cfg(unix)]
#[derive(Debug)]
struct Temporary {
    /// The output's directory, as it was when the temporary file was made in it.
    dir: std::os::fd::OwnedFd,
    /// That directory's path, to check that it still names it.
    dir_path: PathBuf,
    /// The temporary file's name in it.
    name: PathBuf,
    /// Renamed over the output: nothing to remove.
    committed: bool,
}

#[cfg(not(unix))]
#[derive(Debug)]
struct Temporary(tempfile::TempPath);

#[cfg(unix)]
impl Drop for Temporary {
    fn drop(&mut self) {
        if !self.committed {
            let _ = rustix::fs::unlinkat(&self.dir, &self.name, rustix::fs::AtFlags::empty());
        }
    }
}

/// How the output's directory is held: on Linux as a path only (`O_PATH`), which needs no
/// read permission on it (a directory one may write in but not list still takes outputs) and
/// serves the `*at` calls; elsewhere opened for reading.
#[cfg(target_os = "linux")]
const HOLD_DIRECTORY: rustix::fs::OFlags = rustix::fs::OFlags::PATH;
#[cfg(all(unix, not(target_os = "linux")))]
const HOLD_DIRECTORY: rustix::fs::OFlags = rustix::fs::OFlags::RDONLY;

/// The same device and inode.
#[cfg(unix)]
fn same_inode(a: &rustix::fs::Stat, b: &rustix::fs::Stat) -> bool {
    (a.st_dev, a.st_ino) == (b.st_dev, b.st_ino)
}

impl OutputFile {
    /// Checks `path` and opens the temporary file that will replace it. `inputs` are the files
    /// the run reads (e.g. the scene file); `path` may not resolve to any of them.
    pub fn create(path: &Path, inputs: &[&Path]) -> Result<Self, OutputError> {
        if path.as_os_str().is_empty() {
            return Err(OutputError::EmptyPath);
        }
        let target = resolve_links(path)?;
        let existing = metadata_if_exists(path, &target)?;
        if let Some(meta) = &existing {
            check_replaceable(path, &target, meta)?;
            for input in inputs {
                // An input that cannot be examined cannot be the same file as an existing output.
                if same_file::is_same_file(&target, input).unwrap_or(false) {
                    return Err(OutputError::IsInput {
                        path: path.to_owned(),
                        input: input.to_path_buf(),
                    });
                }
            }
        }
        let dir = match target.parent() {
            Some(dir) if !dir.as_os_str().is_empty() => dir,
            _ => Path::new("."),
        };
        // A short fixed-length name: an output name at the file system's limit (255 bytes)
        // still works, which `<name>.partial` would not. The random part makes it unpredictable
        // and `tempfile` creates it with O_EXCL, so nothing planted there is ever opened.
        let mut builder = tempfile::Builder::new();
        builder.prefix(".tumble-").suffix(".tmp");
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            // What a shell redirect would create; the umask applies.
            builder.permissions(std::fs::Permissions::from_mode(0o666));
        }
        #[cfg(unix)]
        let dir_fd = rustix::fs::open(
            dir,
            HOLD_DIRECTORY | rustix::fs::OFlags::DIRECTORY | rustix::fs::OFlags::CLOEXEC,
            rustix::fs::Mode::empty(),
        )
        .map_err(|e| OutputError::io(path, e.into()))?;
        let temp = builder
            .tempfile_in(dir)
            .map_err(|e| OutputError::io(path, without_temp_path(e)))?;
        if let Some(meta) = &existing {
            #[cfg(unix)]
            {
                use std::os::unix::fs::MetadataExt;
                // Best effort: the owner and group stay when we may set them (root may; others
                // only to a group of theirs). Before the mode, since a change of owner clears
                // the set-id bits.
                let _ =
                    std::os::unix::fs::fchown(temp.as_file(), Some(meta.uid()), Some(meta.gid()));
            }
            // Set explicitly: the mode given at creation is reduced by the umask.
            temp.as_file()
                .set_permissions(meta.permissions())
                .map_err(|e| OutputError::io(path, e))?;
        }
        let (file, temp_path) = temp.into_parts();
        #[cfg(unix)]
        let (temp, _live) = {
            let name = PathBuf::from(temp_path.file_name().unwrap_or_default());
            // The file must be in the directory held open: one moved or replaced between the
            // open and the file's creation would hold neither the file nor, later, the output.
            let made_here =
                rustix::fs::statat(&dir_fd, &name, rustix::fs::AtFlags::SYMLINK_NOFOLLOW)
                    .ok()
                    .zip(rustix::fs::fstat(&file).ok())
                    .is_some_and(|(there, made)| same_inode(&there, &made));
            if !made_here {
                // Removed where it was made, by its path.
                drop(temp_path);
                return Err(OutputError::DirectoryMoved {
                    path: path.to_owned(),
                });
            }
            // From here on it is removed relative to the directory, never by its path.
            let _ = temp_path.keep();
            let _live = live::LiveTemporary::register_in(std::os::fd::AsFd::as_fd(&dir_fd), &name);
            let temp = Temporary {
                dir: dir_fd,
                dir_path: dir.to_owned(),
                name,
                committed: false,
            };
            (temp, _live)
        };
        #[cfg(not(unix))]
        let (temp, _live) = {
            let _live = live::LiveTemporary::register(&temp_path);
            (Temporary(temp_path), _live)
        };
        Ok(Self {
            file,
            temp,
            target,
            path: path.to_owned(),
            _live,
        })
    }

    /// The path the caller gave.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The file that will be replaced: the path with its symbolic links resolved.
    pub fn target(&self) -> &Path {
        &self.target
    }

    /// The temporary file (to write into, or to query its file system).
    pub fn file(&self) -> &File {
        &self.file
    }

    /// Flushes the data to disk and renames the temporary file over the output. On error the
    /// temporary file is removed and the output is left as it was; so too if the output's
    /// directory was moved or replaced while tumble wrote ([`OutputError::DirectoryMoved`]).
    pub fn commit(self) -> Result<(), OutputError> {
        let Self {
            file,
            mut temp,
            target,
            path,
            _live,
        } = self;
        // Durable before visible: after a crash the output is the old file or the whole new one.
        file.sync_all().map_err(|e| OutputError::io(&path, e))?;
        check_destination(&path, &target)?;
        #[cfg(unix)]
        {
            let still_there = rustix::fs::stat(&temp.dir_path)
                .ok()
                .zip(rustix::fs::fstat(&temp.dir).ok())
                .is_some_and(|(named, held)| same_inode(&named, &held));
            if !still_there {
                return Err(OutputError::DirectoryMoved { path });
            }
            let name = target.file_name().unwrap_or_default();
            rustix::fs::renameat(&temp.dir, &temp.name, &temp.dir, name)
                .map_err(|e| OutputError::io(&path, e.into()))?;
            temp.committed = true;
        }
        #[cfg(not(unix))]
        temp.0
            .persist(&target)
            .map_err(|e| OutputError::io(&path, without_temp_path(e.error)))?;
        Ok(())
    }
}

impl OutputFile {
    /// Checks again that the output may be replaced (it may have changed while we wrote).
    pub(crate) fn check_destination(&self) -> Result<(), OutputError> {
        check_destination(&self.path, &self.target)
    }
}

/// The output may have been replaced while we wrote: checked again just before the rename.
fn check_destination(path: &Path, target: &Path) -> Result<(), OutputError> {
    match metadata_if_exists(path, target)? {
        Some(meta) => check_replaceable(path, target, &meta),
        None => Ok(()),
    }
}

// Through the plain file: `NamedTempFile`'s own writes wrap an error with the temporary path,
// which would hide the operating system's error code and name a file the user never saw.
impl Write for OutputFile {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        self.file.write(buf)
    }

    fn flush(&mut self) -> io::Result<()> {
        self.file.flush()
    }
}

/// Writes `bytes` to `path` through an [`OutputFile`] (checked, atomic).
pub fn write_atomically(path: &Path, bytes: &[u8], inputs: &[&Path]) -> Result<(), OutputError> {
    let mut file = OutputFile::create(path, inputs)?;
    file.write_all(bytes)
        .map_err(|e| OutputError::io(path, e))?;
    file.commit()
}

/// Writes `text` to standard output and flushes it: a pipe closed early or a full device is an
/// error naming standard output, never a panic (as `println!` gives) and never a silent loss.
pub fn print_to_stdout(text: &str) -> Result<(), OutputError> {
    let mut out = io::stdout().lock();
    out.write_all(text.as_bytes())
        .and_then(|()| out.flush())
        .map_err(|e| OutputError::io(Path::new("standard output"), e))
}

/// Makes sure `path` is a directory, creating it (and its parents) if absent; an existing
/// non-directory is an error that names it.
pub fn create_directory(path: &Path) -> Result<(), OutputError> {
    match std::fs::metadata(path) {
        Ok(meta) if meta.is_dir() => Ok(()),
        Ok(_) => Err(OutputError::NotDirectory {
            path: path.to_owned(),
        }),
        Err(e) if e.kind() == io::ErrorKind::NotFound => {
            std::fs::create_dir_all(path).map_err(|e| OutputError::io(path, e))
        }
        Err(e) => Err(OutputError::io(path, e)),
    }
}

/// The operating system's error without the temporary path `tempfile` adds to it (`… at path
/// "…"`): messages name the output the user gave, not a random name they never saw.
fn without_temp_path(e: io::Error) -> io::Error {
    if e.raw_os_error().is_some() {
        return e;
    }
    match e.to_string().split_once(" at path ") {
        Some((message, _)) => io::Error::new(e.kind(), message.to_owned()),
        None => e,
    }
}

/// `path` with the symbolic links of its last component followed; links in the directories
/// above are left to the operating system to follow (they lead the temporary file and the
/// rename to the same directory), after [`check_directory_links`] has checked them.
fn resolve_links(path: &Path) -> Result<PathBuf, OutputError> {
    let mut current = path.to_path_buf();
    for _ in 0..=MAX_SYMLINKS {
        #[cfg(unix)]
        check_directory_links(path, &current)?;
        match std::fs::symlink_metadata(&current) {
            Ok(meta) if meta.file_type().is_symlink() => {
                #[cfg(unix)]
                check_link_is_trusted(path, &current, &meta)?;
                let link = std::fs::read_link(&current).map_err(|e| OutputError::io(path, e))?;
                current = match current.parent() {
                    Some(parent) if link.is_relative() => parent.join(link),
                    _ => link,
                };
            }
            Ok(_) => return Ok(current),
            Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(current),
            Err(e) => return Err(OutputError::io(path, e)),
        }
    }
    Err(OutputError::SymlinkLoop {
        path: path.to_owned(),
    })
}

/// The links in the directories on the way to `current` (a step of resolving the output
/// `path`), each checked as [`check_link_is_trusted`] checks the last component's: the kernel
/// follows these itself, and applies its `protected_symlinks` rule to them only where the
/// system enables it, so a link another user planted in a shared sticky directory, as a
/// directory of the path (`/tmp/dir/out.csv` with `/tmp/dir` theirs), would redirect the output
/// as surely as one at its end. The directories are walked as the kernel walks them: a link's
/// target is walked in its place, a `..` goes up from where the walk is.
#[cfg(unix)]
fn check_directory_links(path: &Path, current: &Path) -> Result<(), OutputError> {
    use std::ffi::OsString;
    use std::path::Component;
    /// What is left to walk, last first.
    enum Step {
        Root,
        Up,
        Name(OsString),
    }
    let Some(dir) = current.parent() else {
        return Ok(());
    };
    let push_all = |pending: &mut Vec<Step>, p: &Path| {
        for c in p.components().rev() {
            pending.push(match c {
                Component::RootDir | Component::Prefix(_) => Step::Root,
                Component::ParentDir => Step::Up,
                Component::CurDir => continue,
                Component::Normal(name) => Step::Name(name.to_owned()),
            });
        }
    };
    let mut walked = if dir.is_absolute() {
        PathBuf::from("/")
    } else {
        std::env::current_dir().map_err(|e| OutputError::io(path, e))?
    };
    let mut pending = Vec::new();
    push_all(&mut pending, dir);
    let mut links = 0;
    while let Some(step) = pending.pop() {
        let name = match step {
            Step::Root => {
                walked = PathBuf::from("/");
                continue;
            }
            Step::Up => {
                walked.pop();
                continue;
            }
            Step::Name(name) => name,
        };
        let next = walked.join(&name);
        match std::fs::symlink_metadata(&next) {
            Ok(meta) if meta.file_type().is_symlink() => {
                links += 1;
                if links > MAX_SYMLINKS {
                    return Err(OutputError::SymlinkLoop {
                        path: path.to_owned(),
                    });
                }
                check_link_is_trusted(path, &next, &meta)?;
                let target = std::fs::read_link(&next).map_err(|e| OutputError::io(path, e))?;
                push_all(&mut pending, &target);
            }
            Ok(_) => walked = next,
            // Nothing further exists to follow: the write itself reports what is missing.
            Err(_) => return Ok(()),
        }
    }
    Ok(())
}

/// The kernel's `protected_symlinks` rule for a link tumble is about to follow: in a directory
/// that is world-writable and sticky, only a link owned by the follower (the effective user) or
/// by the directory's owner is followed.
#[cfg(unix)]
fn check_link_is_trusted(
    path: &Path,
    link: &Path,
    link_meta: &Metadata,
) -> Result<(), OutputError> {
    use std::os::unix::fs::MetadataExt;
    let dir = match link.parent() {
        Some(dir) if !dir.as_os_str().is_empty() => dir,
        _ => Path::new("."),
    };
    let dir_meta = std::fs::metadata(dir).map_err(|e| OutputError::io(path, e))?;
    let shared_sticky = dir_meta.mode() & 0o1000 != 0 && dir_meta.mode() & 0o002 != 0;
    let follower = rustix::process::geteuid().as_raw();
    let owner = link_meta.uid();
    if shared_sticky && owner != follower && owner != dir_meta.uid() {
        return Err(OutputError::UntrustedLink {
            path: path.to_owned(),
            link: link.to_owned(),
            owner,
        });
    }
    Ok(())
}

fn metadata_if_exists(path: &Path, target: &Path) -> Result<Option<Metadata>, OutputError> {
    match std::fs::symlink_metadata(target) {
        Ok(meta) => Ok(Some(meta)),
        Err(e) if e.kind() == io::ErrorKind::NotFound => Ok(None),
        Err(e) => Err(OutputError::io(path, e)),
    }
}

fn check_replaceable(path: &Path, target: &Path, meta: &Metadata) -> Result<(), OutputError> {
    let path = path.to_owned();
    if meta.is_dir() {
        return Err(OutputError::IsDirectory { path });
    }
    if meta.file_type().is_symlink() {
        // Replaced by a link since it was resolved: resolve again rather than guess.
        return Err(OutputError::io(
            &path,
            io::Error::other("changed into a symbolic link while being written"),
        ));
    }
    if !meta.is_file() {
        return Err(OutputError::NotRegularFile { path });
    }
    if meta.permissions().readonly() {
        return Err(OutputError::ReadOnly { path });
    }
    // Write permission as the kernel sees it (owner, group, ACLs); nothing is truncated.
    OpenOptions::new()
        .write(true)
        .open(target)
        .map(drop)
        .map_err(|e| match e.kind() {
            io::ErrorKind::PermissionDenied => OutputError::ReadOnly { path: path.clone() },
            _ => OutputError::io(&path, e),
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn commit_replaces_the_output_and_a_dropped_file_leaves_nothing() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("out.csv");
        std::fs::write(&out, "old").unwrap();
        let mut file = OutputFile::create(&out, &[]).unwrap();
        file.write_all(b"new").unwrap();
        assert_eq!(std::fs::read_to_string(&out).unwrap(), "old");
        file.commit().unwrap();
        assert_eq!(std::fs::read_to_string(&out).unwrap(), "new");
        let mut file = OutputFile::create(&out, &[]).unwrap();
        file.write_all(b"partial").unwrap();
        drop(file);
        assert_eq!(std::fs::read_to_string(&out).unwrap(), "new");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[test]
    fn directories_and_inputs_are_refused_naming_the_given_path() {
        let dir = tempfile::tempdir().unwrap();
        let err = OutputFile::create(dir.path(), &[]).unwrap_err();
        assert!(matches!(err, OutputError::IsDirectory { .. }), "{err}");
        let input = dir.path().join("scene\u{1b}.toml");
        std::fs::write(&input, "x").unwrap();
        let err = OutputFile::create(&input, &[&input]).unwrap_err();
        assert!(matches!(err, OutputError::IsInput { .. }), "{err}");
        assert!(err.to_string().contains("scene\\u{1b}.toml"), "{err}");
        let err = create_directory(&input).unwrap_err();
        assert!(matches!(err, OutputError::NotDirectory { .. }), "{err}");
        let err = OutputFile::create(Path::new(""), &[]).unwrap_err();
        assert_eq!(err.to_string(), "the output path is empty");
    }

    /// The output's directory moved away while tumble wrote, or replaced by a link to another
    /// one: the commit refuses to write into either, and neither a commit nor a drop leaves
    /// the temporary file in the moved directory (it was removed by a path that no longer led
    /// to it).
    #[cfg(unix)]
    #[test]
    fn a_directory_moved_while_writing_gets_no_output_and_keeps_no_temporary_file() {
        let root = tempfile::tempdir().unwrap();
        let (dir, moved, other) = (
            root.path().join("od"),
            root.path().join("od2"),
            root.path().join("other"),
        );
        for (commit, relink) in [(true, false), (false, false), (true, true)] {
            std::fs::create_dir(&dir).unwrap();
            std::fs::create_dir_all(&other).unwrap();
            let mut file = OutputFile::create(&dir.join("out.csv"), &[]).unwrap();
            file.write_all(b"rows").unwrap();
            std::fs::rename(&dir, &moved).unwrap();
            if relink {
                std::os::unix::fs::symlink(&other, &dir).unwrap();
            }
            if commit {
                let err = file.commit().unwrap_err();
                assert!(matches!(err, OutputError::DirectoryMoved { .. }), "{err}");
                assert!(
                    err.to_string()
                        .contains("od/out.csv: its directory was moved")
                );
            } else {
                drop(file);
            }
            let left: Vec<_> = std::fs::read_dir(&moved).unwrap().collect();
            assert!(left.is_empty(), "{left:?}");
            assert_eq!(std::fs::read_dir(&other).unwrap().count(), 0);
            std::fs::remove_dir(&moved).unwrap();
            if relink {
                std::fs::remove_file(&dir).unwrap();
            }
        }
        // Untouched, the same directory by another path still commits.
        std::fs::create_dir(&dir).unwrap();
        let mut file = OutputFile::create(&dir.join("./out.csv"), &[]).unwrap();
        file.write_all(b"rows").unwrap();
        file.commit().unwrap();
        assert_eq!(
            std::fs::read_to_string(dir.join("out.csv")).unwrap(),
            "rows"
        );
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1);
    }

    #[cfg(unix)]
    #[test]
    fn a_symlink_loop_is_an_error() {
        let dir = tempfile::tempdir().unwrap();
        let (a, b) = (dir.path().join("a"), dir.path().join("b"));
        std::os::unix::fs::symlink(&b, &a).unwrap();
        std::os::unix::fs::symlink(&a, &b).unwrap();
        let err = OutputFile::create(&a, &[]).unwrap_err();
        assert!(matches!(err, OutputError::SymlinkLoop { .. }), "{err}");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 2);
    }
}
