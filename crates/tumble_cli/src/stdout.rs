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
    write_all(&mut io::stdout().lock(), text).map_err(|e| failed(&e))
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
