//! What the benches share: criterion's settings and the harness's `main`.

use std::time::Duration;

use criterion::Criterion;

/// A bench binary's body (what `criterion_group!` and `criterion_main!` expand to): runs
/// `target` with 20 samples of `seconds` seconds of measurement each (the command line may
/// override both), then prints criterion's summary.
pub(crate) fn run(target: fn(&mut Criterion), seconds: u64) {
    let mut criterion = Criterion::default()
        .sample_size(20)
        .measurement_time(Duration::from_secs(seconds))
        .configure_from_args();
    target(&mut criterion);
    Criterion::default().configure_from_args().final_summary();
}
