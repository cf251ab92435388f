//! Steps of several stages, one list for the tests of `tumble_ecs` and of `tumble` (which take
//! this file by its path).

use tumble_core::Integrator;

/// `(integrator, substeps)` settings whose step runs more than one stage: `yoshida4`'s
/// composition (its backward stage included), substeps of the plain step, and both at once.
pub(crate) const SEVERAL_STAGES: [(Integrator, u32); 5] = [
    (Integrator::Yoshida4, 1),
    (Integrator::Splitting, 3),
    (Integrator::Splitting, 4),
    (Integrator::Yoshida4, 2),
    (Integrator::Yoshida4, 3),
];
