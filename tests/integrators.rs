//! Integrator tests: conservation, Dzhanibekov flips, stability at the extremes, divergence
//! detection, and observed order of convergence against the exact torque-free top.

#[path = "../crates/tumble_ecs/tests/common/stages.rs"]
mod several_stages;

mod integrators {
    pub(crate) mod batch;
    pub(crate) mod convergence;
    pub(crate) mod damping;
    pub(crate) mod exact;
    pub(crate) mod extremes;
    pub(crate) mod gyroscopic;
    pub(crate) mod harness;
    pub(crate) mod stability;
    pub(crate) mod stages;
    pub(crate) mod stiff_groups;
}
