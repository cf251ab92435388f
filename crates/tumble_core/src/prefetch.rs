//! A hint to the CPU to fetch memory that a loop will read soon.
//!
//! The one `unsafe` call here pays for itself where worlds outgrow the caches: with the batch
//! loops prefetching [`PREFETCH_AHEAD`](crate::integrate::PREFETCH_AHEAD) bodies ahead, a
//! million-body ECS step fell from 53 to 40 ns per body (the `ecs_vs_raw` example of
//! `tumble_bench`); smaller worlds are unchanged.

/// Asks the CPU to bring the cache line holding `value` into the nearest cache; a no-op where
/// the architecture has no such hint. Never faults, changes no result.
#[inline(always)]
pub fn prefetch<T>(value: &T) {
    #[cfg(target_arch = "x86_64")]
    #[allow(unsafe_code)]
    // SAFETY: SSE is part of the x86_64 baseline, the only requirement of `_mm_prefetch`; a
    // prefetch never faults and `value` is a valid reference anyway.
    unsafe {
        use std::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
        _mm_prefetch::<_MM_HINT_T0>(std::ptr::from_ref(value).cast());
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = value;
}
