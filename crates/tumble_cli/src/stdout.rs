//! Standard output, written with every error reported: a pipe closed early (`| head`), a full
//! device (`> /dev/full`) or any other failed write is an `error:` line and exit code
//! [`ERROR`](crate::exit::ERROR), never a panic and never a success with lost output.

use std::io::{self, Write};

use crate::exit::{self, Failure};

/// The failure for a write to standard output that did not happen.
pub(crate) fn failed(e: &io::Error) -> Failure {
    Failure::new(
        exit::ERROR,
        format!("writing to standard output failed: {e}"),
    )
}

/// Writes `text` to standard output and flushes it.
pub(crate) fn print(text: &str) -> Result<(), Failure> {
    write_all(&mut open()?, text).map_err(|e| failed(&e))
}

/// Standard output as a buffered writer of its own (a duplicate of its descriptor), whose
/// every failed write is reported: Rust's `Stdout` reports success, by design, for writes to a
/// closed standard output (`EBADF`), and output written there would be lost with exit code 0.
/// Closed, it fails here; open read-only, its first write fails. Flush it before it is dropped.
pub(crate) fn open() -> Result<Box<dyn Write>, Failure> {
    if closed_at_start() {
        return Err(Failure::new(
            exit::ERROR,
            "standard output is closed: nothing written to it could be read".to_owned(),
        ));
    }
    #[cfg(unix)]
    {
        use std::os::fd::AsFd;
        let own = io::stdout().as_fd().try_clone_to_owned();
        let own = own.map_err(|e| failed(&e))?;
        Ok(Box::new(io::BufWriter::new(std::fs::File::from(own))))
    }
    #[cfg(windows)]
    {
        use std::os::windows::io::AsHandle;
        let own = io::stdout().as_handle().try_clone_to_owned();
        let own = own.map_err(|e| failed(&e))?;
        Ok(Box::new(io::BufWriter::new(std::fs::File::from(own))))
    }
    #[cfg(not(any(unix, windows)))]
    {
        Ok(Box::new(io::stdout().lock()))
    }
}

/// Whether standard output was closed when the program started. Rust's runtime opens
/// `/dev/null` read–write on a standard descriptor it finds closed before `main`, so that
/// writes there then succeed and are lost; a shell's `> /dev/null` opens it write-only, so a
/// read–write `/dev/null` on descriptor 1 is taken for a closed standard output (as
/// `1<> /dev/null` would be). Linux only (where `/proc` shows a descriptor's file and flags);
/// elsewhere false.
fn closed_at_start() -> bool {
    #[cfg(target_os = "linux")]
    {
        let null = std::fs::read_link("/proc/self/fd/1")
            .is_ok_and(|file| file == std::path::Path::new("/dev/null"));
        null && std::fs::read_to_string("/proc/self/fdinfo/1").is_ok_and(|info| {
            info.lines()
                .find_map(|line| line.strip_prefix("flags:"))
                .and_then(|flags| u32::from_str_radix(flags.trim(), 8).ok())
                .is_some_and(|flags| flags & 0o3 == 0o2)
        })
    }
    #[cfg(not(target_os = "linux"))]
    {
        false
    }
}

/// Writes `text` to `out` and flushes it.
pub(crate) fn write_all(out: &mut impl Write, text: &str) -> io::Result<()> {
    out.write_all(text.as_bytes())?;
    out.flush()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A writer that takes `room` bytes and then fails as a full device does.
    struct Full {
        room: usize,
    }

    impl Write for Full {
        fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
            if self.room == 0 {
                return Err(io::Error::from_raw_os_error(28)); // ENOSPC
            }
            let n = buf.len().min(self.room);
            self.room -= n;
            Ok(n)
        }

        fn flush(&mut self) -> io::Result<()> {
            Ok(())
        }
    }

    #[test]
    fn a_full_device_is_an_error_not_a_success() {
        let text = "checksum   step 10: 0123456789abcdef\n";
        assert!(write_all(&mut Full { room: 1000 }, text).is_ok());
        let e = write_all(&mut Full { room: 5 }, text).unwrap_err();
        let failure = failed(&e);
        assert_eq!(failure.code, exit::ERROR);
        assert!(
            failure
                .message
                .starts_with("writing to standard output failed")
        );
    }
}
