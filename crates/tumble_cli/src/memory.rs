//! Memory exhausted is an `error:` line and exit code [`exit::ERROR`](crate::exit::ERROR), not an
//! abort: the process allocator is [`System`] behind a check for a failed allocation.
//!
//! Rust's own handler for a failed allocation prints a line of its own and aborts (SIGABRT,
//! a core dump where they are on), and the hook to replace it is unstable. Under a memory limit
//! (`ulimit -v`, a container's) a scene too large for it would end that way, leaving its
//! temporary output file. Here a failed allocation writes one line, built on the stack (the
//! heap has just said no), removes the live temporary files
//! ([`remove_live_temporary_files`]) and exits. The check is one comparison with null per
//! allocation; steps allocate nothing, so the hot loops never see it.

// A global allocator is an `unsafe impl` by definition; nothing else here is unsafe. There is
// no safe way on stable Rust to act on a failed allocation that infallible collections make.
#![expect(
    unsafe_code,
    reason = "a GlobalAlloc impl that forwards to System and exits on a null result"
)]

use std::alloc::{GlobalAlloc, Layout, System};
use std::io::Write;
use std::sync::atomic::{AtomicBool, Ordering};

use tumble_scene::output::remove_live_temporary_files;

use crate::exit;

/// [`System`], exiting with an `error:` line when an allocation fails.
pub(crate) struct ExitWhenExhausted;

// SAFETY: every method forwards to `System` with the caller's arguments unchanged, so `System`'s
// guarantees hold; a null result never returns (the process exits), which the contract allows.
unsafe impl GlobalAlloc for ExitWhenExhausted {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        // SAFETY: forwarded as received; the caller upholds `alloc`'s contract.
        let p = unsafe { System.alloc(layout) };
        if p.is_null() {
            exhausted(layout.size());
        }
        p
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        // SAFETY: forwarded as received; the caller upholds `alloc_zeroed`'s contract.
        let p = unsafe { System.alloc_zeroed(layout) };
        if p.is_null() {
            exhausted(layout.size());
        }
        p
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: forwarded as received; `ptr` came from this allocator, i.e. from `System`.
        unsafe { System.dealloc(ptr, layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        // SAFETY: forwarded as received; `ptr` came from this allocator, i.e. from `System`.
        let p = unsafe { System.realloc(ptr, layout, new_size) };
        if p.is_null() {
            exhausted(new_size);
        }
        p
    }
}

static EXHAUSTED: AtomicBool = AtomicBool::new(false);

/// Says that `size` bytes could not be had, removes the live temporary files and exits; never
/// allocates.
#[cold]
fn exhausted(size: usize) -> ! {
    if !EXHAUSTED.swap(true, Ordering::SeqCst) {
        let mut line = [0u8; 160];
        let len = exhausted_line(size, &mut line);
        // Unbuffered, and its lock allocates nothing.
        let _ = std::io::stderr().write_all(&line[..len]);
        remove_live_temporary_files();
    }
    std::process::exit(i32::from(exit::ERROR))
}

/// Writes `error: out of memory: … <size> bytes …` into `out`; returns its length.
fn exhausted_line(size: usize, out: &mut [u8; 160]) -> usize {
    let head = b"error: out of memory: an allocation of ";
    let tail = b" bytes failed; the scene needs more memory than this process may use\n";
    let mut digits = [0u8; 20];
    let mut n = size;
    let mut start = digits.len();
    loop {
        start -= 1;
        digits[start] = b'0' + (n % 10) as u8;
        n /= 10;
        if n == 0 {
            break;
        }
    }
    let mut len = 0;
    for part in [&head[..], &digits[start..], &tail[..]] {
        out[len..len + part.len()].copy_from_slice(part);
        len += part.len();
    }
    len
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_line_names_the_size() {
        let mut line = [0u8; 160];
        for (size, digits) in [(0, "0"), (7, "7"), (usize::MAX, "18446744073709551615")] {
            let len = exhausted_line(size, &mut line);
            let text = std::str::from_utf8(&line[..len]).unwrap();
            assert_eq!(
                text,
                format!(
                    "error: out of memory: an allocation of {digits} bytes failed; the scene \
                     needs more memory than this process may use\n"
                )
            );
        }
    }
}
