//! Rollback netcode with GGRS: a two-player spring-chain game run in GGRS's `SyncTestSession`,
//! which rolls the world back 7 frames on every frame, resimulates them from a tumble
//! `RollbackSnapshot` and checks each frame's `WorldChecksum` against the first simulation.
//! Then the same inputs without GGRS, to show the rollbacks left the trajectory untouched.

#[path = "game.rs"]
mod game;

use tumble::prelude::*;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let frames = 1200;
    let check_distance = 7;
    let synced = game::sync_test(Integrator::default(), frames, check_distance)?;
    let straight = game::straight(Integrator::default(), frames);
    let a = world_checksum(&synced.world);
    let b = world_checksum(&straight.world);
    println!(
        "{frames} frames, check distance {check_distance}: {} frames simulated, {} rollbacks, \
         {} re-plans, every resimulated checksum matched",
        synced.advanced,
        synced.loaded,
        synced.replans()
    );
    println!("final checksum with rollbacks    {a}");
    println!("final checksum without rollbacks {b}");
    if a != b {
        return Err("the rolled-back run ended in a different state".into());
    }
    Ok(())
}
