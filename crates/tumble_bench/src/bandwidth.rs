//! The machine's memory bandwidth, measured in the same run as the engines: how fast one and two
//! threads can stream a buffer far larger than the caches (read + write, as a step does).

use std::time::Instant;

/// Bytes per buffer: far beyond any last-level cache.
const BUFFER_BYTES: usize = 256 << 20;

/// Copy bandwidth in GB/s (bytes read + bytes written per second), best of `repetitions`, with
/// the copy split over `threads` threads.
pub fn copy_bandwidth(threads: usize, repetitions: usize) -> f64 {
    let words = BUFFER_BYTES / 8;
    let source: Vec<u64> = (0..words as u64).collect();
    let mut target = vec![0u64; words];
    let chunk = words.div_ceil(threads.max(1));
    let mut best = f64::INFINITY;
    for _ in 0..repetitions.max(1) {
        let start = Instant::now();
        std::thread::scope(|s| {
            for (to, from) in target.chunks_mut(chunk).zip(source.chunks(chunk)) {
                s.spawn(move || to.copy_from_slice(from));
            }
        });
        best = best.min(start.elapsed().as_secs_f64());
        std::hint::black_box(&target);
    }
    assert_eq!(target[words - 1], words as u64 - 1, "copy completed");
    2.0 * BUFFER_BYTES as f64 / best / 1e9
}
