//! Running a kernel written once against [`Lane`] on the path a [`Kernel`] selects: the one
//! place that calls into code compiled for an instruction set the x86_64 baseline lacks.

#[cfg(doc)]
use super::Kernel;
#[cfg(target_arch = "x86_64")]
use super::{Avx2, Avx4, Avx8, Avx512, Pair};
use super::{F64x4, Lane, Portable};

/// A batch kernel, generic in its lane type: what runs on every path.
pub(crate) trait LaneKernel {
    /// What the kernel returns.
    type Output;

    /// Runs the kernel with lanes of type `T`. An implementation is `#[inline(always)]`, so
    /// that it compiles into each path's function below, with that path's instruction set: a
    /// call into it from there would run baseline code.
    fn run<T: Lane>(self, cpu: T::Cpu) -> Self::Output;
}

/// Runs the [`LaneKernel`] `$kernel_fn` on the path the [`Kernel`] `$kernel` selects: four
/// bodies a value on the portable path ([`F64x4`]), eight as two 256-bit registers on AVX2
/// (`Pair<Avx4>`), eight in one 512-bit register on AVX-512 (`Avx8`). Every path gives the same
/// bits (see [`Lane`]).
///
/// A macro, not a function: the match on the path expands where the kernel is run, so that the
/// call goes from the batch's queue straight into the function compiled for the path (the
/// function it would be is inlined anyway), and a reader follows one call, not two.
macro_rules! run_on {
    ($kernel:expr, $kernel_fn:expr) => {{
        let kernel_fn = $kernel_fn;
        match $kernel {
            // Not paired: `wide`'s `f64x4` is already two SSE2 registers side by side, and a
            // pair of them spills so many values to the stack that it loses to one run of four
            // (the kernel rows of `tumble bench`).
            $crate::simd::Kernel::Portable => $crate::simd::dispatch::on_portable(kernel_fn),
            #[cfg(target_arch = "x86_64")]
            #[expect(
                unsafe_code,
                reason = "a call into code compiled for AVX2, proven by the token"
            )]
            // SAFETY: the `Avx2` token exists, so the CPU has AVX2, the only requirement of
            // calling a function compiled with `#[target_feature(enable = "avx2")]`.
            $crate::simd::Kernel::Avx2(cpu) => unsafe {
                $crate::simd::dispatch::on_avx2(cpu, kernel_fn)
            },
            #[cfg(target_arch = "x86_64")]
            #[expect(
                unsafe_code,
                reason = "a call into code compiled for AVX-512F, proven by the token"
            )]
            // SAFETY: the `Avx512` token exists, so the CPU has AVX-512F, the only requirement
            // of calling a function compiled with `#[target_feature(enable = "avx512f")]`.
            $crate::simd::Kernel::Avx512(cpu) => unsafe {
                $crate::simd::dispatch::on_avx512(cpu, kernel_fn)
            },
        }
    }};
}
pub(crate) use run_on;

/// The kernel on the x86_64 baseline (or any other target), four bodies a value. Not inlined,
/// as the other paths' functions cannot be: inlined into a batch loop (one per phase and
/// method), the kernel would bloat each past what the instruction cache and the register
/// allocator handle well, while one call per eight bodies costs nothing in comparison.
#[inline(never)]
pub(crate) fn on_portable<K: LaneKernel>(kernel_fn: K) -> K::Output {
    kernel_fn.run::<F64x4>(Portable)
}

/// The kernel compiled with AVX-512F enabled, on one 512-bit register ([`Avx8`]).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
pub(crate) fn on_avx512<K: LaneKernel>(cpu: Avx512, kernel_fn: K) -> K::Output {
    kernel_fn.run::<Avx8>(cpu)
}

/// The kernel compiled with AVX2 enabled: eight bodies as two 256-bit registers side by side
/// ([`Pair`] of [`Avx4`]). The pair spills some values to the stack, yet it beats two runs of
/// four one after the other per body-step (the kernel rows of `tumble bench`): each run's chain
/// of four dependent rotations leaves the core idle, and the other run fills it.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
pub(crate) fn on_avx2<K: LaneKernel>(cpu: Avx2, kernel_fn: K) -> K::Output {
    kernel_fn.run::<Pair<Avx4>>(cpu)
}
