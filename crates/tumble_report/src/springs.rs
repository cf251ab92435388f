//! Springs against rapier: the stiff chain ([`tumble_rapier::presets::spring_chain`], stretched) at several `ωΔt` in
//! tumble (explicit and implicit spring step) and in rapier 0.36 (its `SpringJoint`, and a spring
//! force added by hand each step), with the total energy of each after every step.

use serde::Serialize;
use tumble_core::math::{Real, to_f64};
use tumble_ecs::prelude::SpringSolver;
use tumble_rapier::{Comparison, ComparisonOptions, RapierSprings, compare};

use tumble_rapier::presets::{ChainStart, spring_chain};

/// The nominal `√(k/μ)Δt` of the chain runs: inside the explicit step's stable region, at its
/// edge, and far beyond it (the bundled `stiff_chain` scene).
pub const OMEGA_DTS: [Real; 3] = [0.5, 2.0, 10.0];

/// One variant: an engine and the way it steps springs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Variant {
    /// tumble with the given spring step.
    Tumble(SpringSolver),
    /// rapier with the given spring construction.
    Rapier(RapierSprings),
}

impl Variant {
    /// The four variants, in the order of the report's table.
    pub const ALL: [Variant; 4] = [
        Variant::Tumble(SpringSolver::Explicit),
        Variant::Tumble(SpringSolver::Implicit),
        Variant::Rapier(RapierSprings::Joint),
        Variant::Rapier(RapierSprings::Force),
    ];

    /// The name used in tables, plots and `results.json`, e.g. `tumble explicit`.
    pub fn name(self) -> String {
        match self {
            Variant::Tumble(s) => format!("tumble {s}"),
            Variant::Rapier(r) => format!("rapier {r}"),
        }
    }
}

/// The energy of one variant on the chain at one `ωΔt`.
#[derive(Debug, Clone, Serialize)]
pub struct SpringRun {
    /// [`Variant::name`].
    pub variant: String,
    /// Nominal `√(k/μ)Δt`.
    pub omega_dt: f64,
    /// `E/E₀` before the first step and after every step (`E` =
    /// [`ComparisonScene::total_energy`](tumble_rapier::ComparisonScene::total_energy)); NaN
    /// (`null` in JSON) from the step the engine quarantined a body or a state went non-finite.
    pub energy_ratio: Vec<f64>,
    /// The step from which the run stopped being valid (quarantined or non-finite), if it did.
    pub failed_at: Option<usize>,
    /// Mean wall time per step of the engine (µs).
    pub us_per_step: f64,
}

impl SpringRun {
    /// `E/E₀` after the last step, or NaN when the run failed.
    pub fn final_ratio(&self) -> f64 {
        self.energy_ratio.last().copied().unwrap_or(f64::NAN)
    }

    /// Largest `|E − E₀|/E₀` over the valid part of the run.
    pub fn max_deviation(&self) -> f64 {
        self.energy_ratio
            .iter()
            .filter(|r| r.is_finite())
            .map(|r| (r - 1.0).abs())
            .fold(0.0, f64::max)
    }
}

/// A run of one variant out of a comparison that ran it.
fn extract(result: &Comparison, variant: Variant, omega_dt: Real) -> SpringRun {
    let (energy, ns) = match variant {
        Variant::Tumble(_) => (&result.tumble_energy, result.tumble_ns_per_step),
        Variant::Rapier(_) => (&result.rapier_energy, result.rapier_ns_per_step),
    };
    let e0 = energy[0];
    SpringRun {
        variant: variant.name(),
        omega_dt: to_f64(omega_dt),
        energy_ratio: energy.iter().map(|e| e / e0).collect(),
        failed_at: energy.iter().position(|e| !e.is_finite()),
        us_per_step: ns / 1e3,
    }
}

/// Every variant on the chain at every `ωΔt` of [`OMEGA_DTS`], `steps` steps each. Each
/// comparison runs one tumble and one rapier variant side by side (explicit with the joint,
/// implicit with the force); a variant's numbers do not depend on its partner.
pub fn spring_runs(steps: usize, mut progress: impl FnMut()) -> Vec<SpringRun> {
    let mut runs = Vec::new();
    for omega_dt in OMEGA_DTS {
        let chain = spring_chain(omega_dt, ChainStart::Stretched, 1);
        for (tumble, rapier) in [
            (SpringSolver::Explicit, RapierSprings::Joint),
            (SpringSolver::Implicit, RapierSprings::Force),
        ] {
            let options = ComparisonOptions {
                steps,
                springs: tumble,
                rapier_springs: rapier,
                ..ComparisonOptions::default()
            };
            let result = compare(&chain, &options, None);
            runs.push(extract(&result, Variant::Tumble(tumble), omega_dt));
            runs.push(extract(&result, Variant::Rapier(rapier), omega_dt));
            progress();
        }
    }
    let order = |r: &SpringRun| {
        Variant::ALL
            .iter()
            .position(|v| v.name() == r.variant)
            .unwrap_or(usize::MAX)
    };
    runs.sort_by(|a, b| {
        order(a)
            .cmp(&order(b))
            .then(a.omega_dt.total_cmp(&b.omega_dt))
    });
    runs
}
