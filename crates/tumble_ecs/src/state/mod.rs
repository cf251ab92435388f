//! A world's state for netcode, replays and saves: the checksum, rollback snapshots and
//! serde snapshots.
//!
//! ## The world checksum
//!
//! [`WorldChecksum`]: one 128-bit number for everything the next step depends on, for lockstep
//! and rollback netcode (a peer compares it frame by frame; GGRS asks for one per frame).
//!
//! It is the XXH3-128 hash (seed 0; the `xxhash-rust` crate, whose output is fixed by the
//! XXH3 specification) of a byte stream laid out in a fixed order, every number by its IEEE
//! bit pattern in little-endian order:
//!
//! 1. the tag `tumble-checksum-1`;
//! 2. the step settings: `dt`, the integrator's and the spring step's names, the substeps, the
//!    stage cursor, and gravity (a presence byte, then its vector);
//! 3. every rigid body, in increasing `Entity::to_bits` order: the entity, `Pose`,
//!    `Velocity`, `MassProps` (mass, principal moments and frame, centre of mass), then one
//!    presence byte and the values for each of `ForceAccumulator`, `HeldLoad`, `GravityScale`,
//!    `Damping`, and one byte each for `Static`, `Kinematic` and `Rejected`;
//! 4. every force generator, by kind (`ConstantForce`, `ConstantTorque`, `Spring`, then —
//!    only in a world that has some, behind its name — `ConstantLocalForce`), each kind in
//!    increasing entity order, with all its fields.
//!
//! Equal worlds give equal checksums on every run, thread count and platform (no pointer, no
//! iteration order, no `Hash` implementation of std enters it); a world built in `f32` and the
//! same world in `f64` differ, as their bits do. Derived state the plan recomputes (the spring
//! classification, scratch buffers) is left out.
//!
//! ## Rollback snapshots
//!
//! Rollback snapshots: save what the next step depends on, and put it back in place, for
//! rollback netcode (GGRS saves the state every frame and loads one up to 8 frames back when a
//! remote input arrives late) and for any "try it and undo" game logic.
//!
//! A [`RollbackSnapshot`] holds exactly what the [`WorldChecksum`](crate::state) covers —
//! every rigid body's pose, velocity, mass properties, accumulated and held loads, gravity scale,
//! damping, kind and quarantine; every force generator; the settings, gravity, the energy-audit
//! mode and the stage cursor — plus the energy audit's running accounts (they decide whether a
//! later step quarantines a spring group; the checksum leaves them out because their sums follow
//! storage order). So, by construction and by test:
//!
//! ```text
//! capture at frame n  →  any steps and game changes  →  restore  ⇒  world_checksum equal to frame n's
//! ```
//!
//! and the steps that follow are bit for bit the steps that followed frame `n`.
//!
//! **In place, not respawned.** Unlike the serde `Snapshot` (module `snapshot`, feature
//! `serde`; it spawns a saved world into another), a rollback snapshot writes back into the
//! entities it was taken from: entity ids stay, no schedule is rebuilt (the
//! [`PhysicsRunner`](crate::schedule) re-plans only when a plan input differs, e.g. a restore
//! that removes gravity), and a restore of an unchanged archetype layout is one linear pass
//! over the bodies. Components that were added or
//! removed since the capture (an accumulator, damping, a quarantine) are put back as they were.
//! Entities are the game's: a restore into a world whose bodies or generators are not the
//! captured ones fails with a [`RollbackError`] and changes nothing.
//!
//! **Compact.** One body is one `Copy` record ([`BodyRecord`], [`RollbackSnapshot::bytes`]
//! counts them; `tumble bench` reports bytes per body and the time to capture and restore 10⁴
//! bodies next to rapier's ≈ 1.1 KB per body). State outside the world — a
//! [`FixedStepper`](crate::schedule::FixedStepper)'s accumulator — is `Copy` and saved by the
//! game alongside.
//!
//! Not saved: the [`PhysicsErrors`](crate::components::PhysicsErrors) log (a report, not state) and
//! derived state the plan recomputes (the spring classification, scratch buffers).
//!
//! ## Saving and resuming
//!
//! Saving a world and resuming it (feature `serde`).
//!
//! A [`Snapshot`] holds every physics component and resource of a world: bodies (pose, velocity,
//! mass properties, accumulator, gravity scale, damping, static / kinematic marker, quarantine),
//! force generators, gravity, settings, the threading policy and the error log. Serialize it with
//! any serde format; [`Snapshot::restore`] spawns it into a world, remapping entity references.
//! Resuming from a snapshot taken between two steps gives **bit-identical** results to running
//! straight through (tested over 10⁴ steps): floats are saved exactly, mass properties are
//! restored without recomputation, and entities are respawned in their original order, so force
//! generators sum in the same order. The serde format must round-trip floats exactly, as binary
//! formats do; with `serde_json`, enable its `float_roundtrip` feature (its default parser may be
//! one ulp off for `f64`).

mod checksum;
mod record;
mod rollback;
#[cfg(feature = "serde")]
mod snapshot;

pub use checksum::{WorldChecksum, world_checksum};
pub use record::{BodyRecord, Parts};
pub use rollback::{RollbackError, RollbackSnapshot};
#[cfg(feature = "serde")]
pub use snapshot::{BodyKind, BodySnapshot, SNAPSHOT_VERSION, Snapshot, SnapshotError};
