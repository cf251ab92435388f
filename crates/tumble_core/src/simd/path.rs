//! Which compilation of the batched kernel runs: the widest the CPU has, or the one the
//! environment variable [`KERNEL_ENV`] forces.

use std::fmt;
use std::sync::OnceLock;

use thiserror::Error;

#[cfg(target_arch = "x86_64")]
use super::{Avx2, Avx512};

/// The environment variable that forces a kernel path: `TUMBLE_KERNEL=portable|avx2|avx512`.
/// Read once, at the first batched step (or the first call of [`KernelPath::selected`]);
/// unset or empty means the widest path the CPU has.
pub const KERNEL_ENV: &str = "TUMBLE_KERNEL";

/// A compilation of the batched `splitting` free rotation, by instruction set. Every path gives
/// the same bits (see [`Integrator::stage_batch`](crate::Integrator::stage_batch)); they differ
/// in speed only.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum KernelPath {
    /// Four bodies per `wide::f64x4` (SSE2 pairs on x86_64): every CPU.
    Portable,
    /// Four bodies per 256-bit register: x86_64 with AVX2.
    Avx2,
    /// Eight bodies per 512-bit register: x86_64 with AVX-512F.
    Avx512,
}

impl KernelPath {
    /// Every path, narrowest first.
    pub const ALL: [KernelPath; 3] = [KernelPath::Portable, KernelPath::Avx2, KernelPath::Avx512];

    /// The name [`KERNEL_ENV`] takes: `portable`, `avx2` or `avx512`.
    pub fn name(self) -> &'static str {
        match self {
            KernelPath::Portable => "portable",
            KernelPath::Avx2 => "avx2",
            KernelPath::Avx512 => "avx512",
        }
    }

    /// The path named `name` (as [`name`](Self::name) spells it).
    pub fn from_name(name: &str) -> Option<KernelPath> {
        KernelPath::ALL.into_iter().find(|path| path.name() == name)
    }

    /// True when this CPU runs the path.
    pub fn is_available(self) -> bool {
        Kernel::detect(self).is_some()
    }

    /// The paths this CPU runs, narrowest first (always starts with `Portable`).
    pub fn available() -> Vec<KernelPath> {
        KernelPath::ALL
            .into_iter()
            .filter(|path| path.is_available())
            .collect()
    }

    /// The path batched steps take: the one [`KERNEL_ENV`] names, or the widest the CPU has
    /// when it is unset or empty. An error when the variable names no path or one this CPU
    /// lacks (then batched `splitting` steps panic with the same message: call this first to
    /// report it properly).
    pub fn selected() -> Result<KernelPath, KernelError> {
        Kernel::selection().clone().map(Kernel::path)
    }
}

impl fmt::Display for KernelPath {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// The path batched steps take ([`KernelPath::selected`]), for a benchmark or a CLI to print.
///
/// # Panics
///
/// When [`KERNEL_ENV`] names no path or one this CPU lacks; [`KernelPath::selected`] returns
/// that as an error instead.
pub fn kernel_path() -> KernelPath {
    Kernel::selected().path()
}

/// Why [`KERNEL_ENV`] cannot be followed.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum KernelError {
    /// The variable names no kernel path.
    #[error("{KERNEL_ENV}={value:?} names no kernel path; expected one of: portable, avx2, avx512")]
    Unknown {
        /// The variable's value.
        value: String,
    },
    /// The variable names a path this CPU cannot run.
    #[error("{KERNEL_ENV}={path}, but this CPU runs only: {}", list(.available))]
    Unavailable {
        /// The path asked for.
        path: KernelPath,
        /// The paths this CPU runs.
        available: Vec<KernelPath>,
    },
    /// The variable is not valid Unicode.
    #[error("{KERNEL_ENV} is not valid Unicode; expected one of: portable, avx2, avx512")]
    NotUnicode,
}

fn list(paths: &[KernelPath]) -> String {
    paths
        .iter()
        .map(|p| p.name())
        .collect::<Vec<_>>()
        .join(", ")
}

#[cfg(test)]
thread_local! {
    /// The kernel [`Kernel::forced`] makes this thread's batches take.
    static FORCED: std::cell::Cell<Option<Kernel>> = const { std::cell::Cell::new(None) };
}

/// A kernel path with the proof that this CPU runs it: what the batch loop dispatches on.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Kernel {
    /// [`KernelPath::Portable`].
    Portable,
    /// [`KernelPath::Avx2`], with its proof.
    #[cfg(target_arch = "x86_64")]
    Avx2(Avx2),
    /// [`KernelPath::Avx512`], with its proof.
    #[cfg(target_arch = "x86_64")]
    Avx512(Avx512),
}

impl Kernel {
    /// `path` with its proof, if this CPU runs it.
    pub(crate) fn detect(path: KernelPath) -> Option<Kernel> {
        match path {
            KernelPath::Portable => Some(Kernel::Portable),
            #[cfg(target_arch = "x86_64")]
            KernelPath::Avx2 => Avx2::detect().map(Kernel::Avx2),
            #[cfg(target_arch = "x86_64")]
            KernelPath::Avx512 => Avx512::detect().map(Kernel::Avx512),
            #[cfg(not(target_arch = "x86_64"))]
            KernelPath::Avx2 | KernelPath::Avx512 => None,
        }
    }

    /// The path this is.
    pub(crate) fn path(self) -> KernelPath {
        match self {
            Kernel::Portable => KernelPath::Portable,
            #[cfg(target_arch = "x86_64")]
            Kernel::Avx2(_) => KernelPath::Avx2,
            #[cfg(target_arch = "x86_64")]
            Kernel::Avx512(_) => KernelPath::Avx512,
        }
    }

    /// Every kernel this CPU runs, narrowest first.
    #[cfg(test)]
    pub(crate) fn available() -> Vec<Kernel> {
        KernelPath::ALL
            .into_iter()
            .filter_map(Kernel::detect)
            .collect()
    }

    /// The kernel batched steps take (see [`KernelPath::selected`]).
    ///
    /// # Panics
    ///
    /// With the [`KernelError`]'s message when [`KERNEL_ENV`] cannot be followed.
    #[inline]
    pub(crate) fn selected() -> Kernel {
        #[cfg(test)]
        if let Some(kernel) = FORCED.get() {
            return kernel;
        }
        match Kernel::selection() {
            Ok(kernel) => *kernel,
            Err(error) => panic!("{error}"),
        }
    }

    /// Runs `f` with [`selected`](Self::selected) returning this kernel on this thread: unit
    /// tests step batches on every path the CPU has in one process.
    #[cfg(test)]
    pub(crate) fn forced<R>(self, f: impl FnOnce() -> R) -> R {
        let before = FORCED.replace(Some(self));
        let result = f();
        FORCED.set(before);
        result
    }

    /// [`KERNEL_ENV`], read and checked once per process.
    fn selection() -> &'static Result<Kernel, KernelError> {
        static SELECTION: OnceLock<Result<Kernel, KernelError>> = OnceLock::new();
        SELECTION.get_or_init(|| Kernel::from_env(std::env::var(KERNEL_ENV)))
    }

    /// The kernel for a value of [`KERNEL_ENV`] (as `std::env::var` returns it).
    fn from_env(value: Result<String, std::env::VarError>) -> Result<Kernel, KernelError> {
        let name = match value {
            Ok(name) if !name.is_empty() => name,
            Ok(_) | Err(std::env::VarError::NotPresent) => return Ok(Kernel::widest()),
            Err(std::env::VarError::NotUnicode(_)) => return Err(KernelError::NotUnicode),
        };
        let path = KernelPath::from_name(&name).ok_or(KernelError::Unknown { value: name })?;
        Kernel::detect(path).ok_or_else(|| KernelError::Unavailable {
            path,
            available: KernelPath::available(),
        })
    }

    /// The widest kernel this CPU runs.
    fn widest() -> Kernel {
        KernelPath::ALL
            .into_iter()
            .rev()
            .find_map(Kernel::detect)
            .unwrap_or(Kernel::Portable)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::env::VarError;

    #[test]
    fn the_variable_picks_the_path_or_says_why_not() {
        let widest = Kernel::widest().path();
        assert_eq!(widest, *KernelPath::available().last().unwrap());
        assert_eq!(
            Kernel::from_env(Err(VarError::NotPresent)).unwrap().path(),
            widest
        );
        assert_eq!(Kernel::from_env(Ok(String::new())).unwrap().path(), widest);
        for path in KernelPath::ALL {
            let chosen = Kernel::from_env(Ok(path.name().to_owned()));
            match chosen {
                Ok(kernel) => assert_eq!(kernel.path(), path),
                Err(error) => {
                    assert!(!path.is_available());
                    let message = error.to_string();
                    assert!(message.contains("TUMBLE_KERNEL=") && message.contains("portable"));
                }
            }
        }
        let error = Kernel::from_env(Ok("sse9".to_owned())).unwrap_err();
        assert_eq!(
            error,
            KernelError::Unknown {
                value: "sse9".to_owned()
            }
        );
        assert!(
            error.to_string().contains("TUMBLE_KERNEL=\"sse9\""),
            "{error}"
        );
        let missing = KernelError::Unavailable {
            path: KernelPath::Avx512,
            available: vec![KernelPath::Portable, KernelPath::Avx2],
        };
        assert_eq!(
            missing.to_string(),
            "TUMBLE_KERNEL=avx512, but this CPU runs only: portable, avx2"
        );
    }
}
