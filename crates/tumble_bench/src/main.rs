//! `tumble-bench`: the throughput benchmark (the same as `tumble bench`).

tumble_scene::tool_main!(
    /// tumble's throughput: ECS vs raw loop vs rapier, 1 and 2 threads, N = 1 … 10⁶.
    tumble_bench::BenchOptions,
    tumble_bench::run_and_write
);
