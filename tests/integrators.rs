//! Integrator tests: conservation, Dzhanibekov flips, stability at the extremes, divergence
//! detection, and observed order of convergence against the exact torque-free top.

#[path = "../crates/tumble_ecs/tests/common/stages.rs"]
mod several_stages;

mod integrators {
    pub mod batch;
    pub mod convergence;
    pub mod damping;
    pub mod exact;
    pub mod extremes;
    pub mod gyroscopic;
    pub mod harness;
    pub mod stability;
    pub mod stages;
}
