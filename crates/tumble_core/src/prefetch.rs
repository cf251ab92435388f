//! A hint to the CPU to fetch memory that a loop will read soon.
//!
//! The one `unsafe` call here pays for itself where worlds outgrow the caches (the batch loops
//! prefetch a few dozen bodies ahead; figures in `report/bench-avx512.md`); smaller worlds are
//! unchanged.
#![expect(
    unsafe_code,
    reason = "`_mm_prefetch`, an x86_64 baseline intrinsic that never faults"
)]

/// Asks the CPU to bring the cache line holding `value` into the nearest cache; a no-op where
/// the architecture has no such hint. Never faults, changes no result.
#[inline(always)]
pub fn prefetch<T>(value: &T) {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: SSE is part of the x86_64 baseline, the only requirement of `_mm_prefetch`; a
    // prefetch never faults and `value` is a valid reference anyway.
    unsafe {
        use std::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
        _mm_prefetch::<_MM_HINT_T0>(std::ptr::from_ref(value).cast());
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = value;
}
