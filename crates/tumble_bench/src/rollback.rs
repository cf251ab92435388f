//! What a rollback costs: capturing and restoring a [`RollbackSnapshot`] of a loaded spring
//! world (chains with gravity, a force at a point of every body and damping), in µs and bytes
//! per body, next to one step of the same world. GGRS rolls back up to 8 frames: one restore
//! and up to 8 steps inside one render frame.

use std::time::Instant;

use serde::Serialize;
use tumble_ecs::prelude::SpringSolver;
use tumble_ecs::state::RollbackSnapshot;
use tumble_rapier::presets::ChainStart;

use crate::engines::Engine;
use crate::measure::median;
use crate::springs::{Loads, SpringWorld};

/// rapier's snapshot size per body, from its issue #991 (serialized `RigidBodySet`,
/// colliders and the rest of the pipeline state): the comparison the rollback issue names.
pub const RAPIER_BYTES_PER_BODY: f64 = 1100.0;

/// One world size.
#[derive(Debug, Clone, Serialize)]
pub struct RollbackRow {
    /// Bodies in the world (chains of ten).
    pub bodies: usize,
    /// Snapshot bytes per body (records, generators and buffers at capacity).
    pub bytes_per_body: f64,
    /// Capture into a reused snapshot (µs, median).
    pub capture_us: f64,
    /// Restore into the same world (µs, median).
    pub restore_us: f64,
    /// One step of the world (µs, median).
    pub step_us: f64,
}

/// Times capture, restore and a step at each size, `repetitions` times each, interleaved.
pub fn run(
    sizes: &[usize],
    repetitions: usize,
    mut progress: impl FnMut(&str),
) -> Vec<RollbackRow> {
    sizes
        .iter()
        .map(|&bodies| {
            progress(&format!("{bodies} bodies · rollback capture and restore"));
            let mut world = SpringWorld::new(
                bodies / 10,
                0.5,
                ChainStart::Relaxed,
                SpringSolver::Explicit,
                Loads::GravityForcesDamping,
            );
            world.step();
            let mut snapshot = RollbackSnapshot::capture(world.world_mut());
            let (mut capture, mut restore, mut step) = (Vec::new(), Vec::new(), Vec::new());
            for _ in 0..repetitions.max(1) {
                let start = Instant::now();
                snapshot.capture_into(world.world_mut());
                capture.push(start.elapsed().as_secs_f64() * 1e6);
                let start = Instant::now();
                world.step();
                step.push(start.elapsed().as_secs_f64() * 1e6);
                let start = Instant::now();
                snapshot
                    .restore(world.world_mut())
                    .expect("the bench world keeps its entities");
                restore.push(start.elapsed().as_secs_f64() * 1e6);
            }
            RollbackRow {
                bodies,
                bytes_per_body: snapshot.bytes() as f64 / bodies as f64,
                capture_us: median(capture),
                restore_us: median(restore),
                step_us: median(step),
            }
        })
        .collect()
}
