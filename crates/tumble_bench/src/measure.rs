//! Timing: interleaved repetitions, the median kept, steps sized so each timing is long enough
//! to mean something and short enough for a large world.

use std::time::Instant;

use crate::engines::Engine;

/// How much work one timing gets.
#[derive(Debug, Clone, Copy)]
pub struct Effort {
    /// Body-steps per timing (steps = this / bodies, at least `min_steps`).
    pub body_steps: usize,
    /// Fewest steps per timing.
    pub min_steps: usize,
    /// Most steps per timing (bounds the single-body runs).
    pub max_steps: usize,
    /// Timings per engine; the median is kept.
    pub repetitions: usize,
}

impl Effort {
    /// Steps per timing for `bodies` bodies.
    pub fn steps(&self, bodies: usize) -> usize {
        (self.body_steps / bodies.max(1)).clamp(self.min_steps, self.max_steps)
    }
}

/// Nanoseconds per step of `steps` steps of `engine`.
pub fn time_steps(engine: &mut dyn Engine, steps: usize) -> f64 {
    let start = Instant::now();
    for _ in 0..steps {
        engine.step();
    }
    start.elapsed().as_nanos() as f64 / steps as f64
}

/// Median of `values` (which must not be empty).
pub fn median(mut values: Vec<f64>) -> f64 {
    values.sort_by(f64::total_cmp);
    let n = values.len();
    if n % 2 == 1 {
        values[n / 2]
    } else {
        0.5 * (values[n / 2 - 1] + values[n / 2])
    }
}

/// Times every engine `effort.repetitions` times, interleaved (so that a slow spell of a shared
/// machine hits all of them alike), after one warm-up step each; returns the median ns per
/// body-step of each.
pub fn compare(engines: &mut [&mut dyn Engine], bodies: usize, effort: &Effort) -> Vec<f64> {
    let steps = effort.steps(bodies);
    for engine in engines.iter_mut() {
        engine.step();
    }
    let mut samples = vec![Vec::new(); engines.len()];
    for _ in 0..effort.repetitions.max(1) {
        for (engine, samples) in engines.iter_mut().zip(&mut samples) {
            samples.push(time_steps(*engine, steps) / bodies as f64);
        }
    }
    samples.into_iter().map(median).collect()
}
