//! The energy audit: a step that creates energy out of nothing is a divergence, even while every
//! number is still finite.
//!
//! An integrator outside its stable region (a spring with `√(k/μ)Δt ≥ 2`, an explicit
//! gyroscopic term on a fast asymmetric spin) grows the energy geometrically; the state stays
//! finite for many steps, long enough to write positions of 10²⁰ m as if they were state. The
//! audit catches that at the step where it happens, quarantines the bodies involved and puts
//! them back to the state they had before that step.
//!
//! ## The balance
//!
//! Bodies joined by springs share their energy, so the audit works on *groups*: the connected
//! components of the spring graph (a lone body is its own group). For a group, with `T` the
//! kinetic energy `Σ ½m|v|² + ½ωᵀIω` and `V` the elastic energy `Σ ½k(|d| − L₀)²` of its
//! springs, each step must satisfy
//!
//! ```text
//! (T + V)_end − (T + V)_start = W_ext + e_step
//! W_ext = Δt Σ_bodies ( F·(v_start + v_end)/2 + τ·(ω_start + ω_end)/2 )
//! ```
//!
//! where `F`, `τ` are every load on the body except the springs (gravity, constant forces and
//! torques, forces game code or its own systems added) and `e_step` is the integrator's energy
//! error. The `(v_start + v_end)/2` form is the drift–kick–drift displacement exactly, so a
//! constant force credits exactly the work the step did. In a step of several stages (substeps,
//! `yoshida4`; see [`crate::integrate`]) the balance is still closed once per step, with `F`, `τ`
//! the loads of the stages weighted by their spans, `Σ (h/Δt) F_stage`, and `ω_max Δt` below
//! measured on the step's stability span (`Stages::stability_span`). Spring dampers and
//! [`Damping`](crate::components::Damping) are velocity flows at the start and end of the step
//! ([`crate::springs`]); they only remove energy, are not credited, and lower `D`. The audit keeps the running sum `D = Σ e_step` per group
//! (the energy the integrator made up; changes game code makes between steps are not part of
//! it) and rejects the group when
//!
//! ```text
//! D > (A − 1) · E + ε,      E = max((T + V)_start − D, (T + V)_start − D + W_ext)
//! ```
//!
//! `E` is the most energy the group should hold during the step: at its start, or at its end
//! had the step been exact. The second matters for a group at rest and relaxed that a load
//! sets moving (a body hanging from its anchor, the corners of a cloth): it holds nothing at
//! the start, and the first step's error in the energy the load gives it — for a stable spring
//! at most `(ωΔt)²/4 ≤ 1` times the load's work — must not be taken for created energy.
//!
//! `A` is twice the largest ratio of energies on one orbit of a *stable* linear spring under the
//! method's position update, with `x = min(ω_max Δt, 1.99)/2`:
//!
//! - drift–kick–drift (Störmer–Verlet, the midpoint methods): the step conserves
//!   `½(1 − x²)|v|² + ½ω²|d|²` exactly, so the energy swings within `[1, 1/(1 − x²)]` times it;
//!   `A = 2/(1 − x²)`;
//! - kick–drift (symplectic Euler and the other start-of-step methods): it conserves
//!   `½(|v|² + ω²|d|² − ωΔt ω d·v)`, a swing of `(1 + x)/(1 − x)`; `A = 2(1 + x)/(1 − x)`.
//!
//! A stable spring's energy swings up to that factor and comes back, and must never be flagged.
//! `ω_max` is the stiffest spring of the group (`√(k/μ)`, `μ` the reduced mass of its ends); the
//! factor 2 covers the extra compliance of off-centre anchors and the O(Δt²) error of the
//! rotation. A group without springs has `A = 2`: a free body may not double its energy on its
//! own. `ε` is round-off: `64 ε_Real` times the energy and work magnitudes of the step.
//!
//! Unstable integration grows `D` geometrically, so it crosses the bound within a few periods;
//! the group is then rejected *before* its state is garbage, and keeps the last state that
//! passed.
//!
//! ## What is audited, and what it costs
//!
//! [`EnergyAudit::Auto`] (the default) audits a world with springs: whether a spring network is
//! inside the stable region depends on the state (off-centre anchors change the effective mass
//! as the bodies turn), so only a check of what happened is safe. Other worlds pay nothing: the
//! audit's systems are not in their plan. The other divergence the planner knows, an explicit
//! gyroscopic term on a fast asymmetric spin (`symplectic-euler`, `symplectic-euler-linear`), is
//! predicted from the spins at planning time ([`check_stability`](crate::stability)); insert
//! [`EnergyAudit::Always`] to have such a run audited as well (the `tumble` CLI does when it runs
//! a world despite a warning). [`EnergyAudit::Never`] turns the audit off.
//!
//! The audit costs one pass over the bodies and the springs at the start of the step, one over
//! the bodies' accumulators before the springs add to them (the plan runs the springs right
//! after it, so the other loads are read as they are, not recomputed as the sum less every
//! spring's force), and one at the end. The end pass measures one kinetic and one elastic
//! energy per body and spring; the start pass reuses them where nothing wrote the body or
//! spring since that pass (its change ticks, `memo`), and measures afresh only what game code
//! changed. When
//! the spring graph is as the last step left it (the same bodies, masses and springs), the
//! start also keeps the last step's groups (`EnergyLedger::restart`); when nothing changed at
//! all, it takes each group's `T + V` from the sum its end pass closed with: the same number,
//! added in the same order. The per-body and per-spring work of the passes (each body's start,
//! load, work and kinetic energy, each spring's elastic energy) runs on the compute pool's
//! threads as [`Parallelism`](crate::parallel::Parallelism) allows, each table of bodies zipped
//! with the ledger's entries where the tables visit the bodies in entity index order (by entity
//! lookup, on one thread, where they do not); each item is worked by the same code on any
//! thread, and the sums over groups are added on one thread in the ledger's order, so the
//! accounts are the same bits on any number of threads. In a loaded spring world the audit is
//! still the largest single part of the step (`cargo bench --bench audit` measures the ratio on
//! a 10⁴-body chain). Bodies are found by
//! entity index in a table the ledger keeps, not by hashing; it allocates only when the world
//! grows. The ledger's bodies and springs are in entity index order, and every sum over a group
//! follows it: which tables game code's own components spread the bodies over, and in which
//! order a query visits them, does not change a bit of an account.
//!
//! Not audited: a group holding a [`Kinematic`](crate::components::Kinematic) body (game code moves it and does work the
//! audit cannot see). [`Static`](crate::components::Static) bodies are fixed anchors.

mod ledger;
mod memo;
mod restart;
mod systems;

use bevy_ecs::prelude::*;

pub use ledger::{EnergyLedger, LedgerState, SavedAccount};
pub use systems::{audit_energy, audit_energy_start, audit_external_loads};

/// Whether a world's steps are audited for energy created by the integrator (see the module
/// docs). Insert it as a resource to override the default, [`EnergyAudit::Auto`].
#[derive(Resource, Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum EnergyAudit {
    /// Audit worlds with springs.
    #[default]
    Auto,
    /// Audit every world with dynamic bodies.
    Always,
    /// Never audit.
    Never,
}

impl EnergyAudit {
    /// Whether a world with (or without) springs is audited.
    pub fn applies(self, has_springs: bool) -> bool {
        match self {
            EnergyAudit::Always => true,
            EnergyAudit::Never => false,
            EnergyAudit::Auto => has_springs,
        }
    }
}

#[cfg(test)]
mod tests;
