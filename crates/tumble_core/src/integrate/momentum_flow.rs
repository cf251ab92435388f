//! A method's torque-free rotation of one body over a span, from its body momentum, in `f64`:
//! what the implicit spring step turns the bodies of a stiff group by (see
//! [`crate::springs::implicit`]).
//!
//! The drift–kick–drift methods (`splitting`, `splitting-xyz`, `yoshida4`, `rk4`, `exact`,
//! `exact4`) advance the orientation by a free flow that keeps the world momentum `L`: a turn
//! `Q₁ = Q₀ C` of the principal frame that depends on the body momentum `m = Q₀ᵀ L` and the
//! span alone (every sub-flow multiplies `Q` on the right), so it is computed here from the
//! identity. The first-order methods update `ω` with a gyroscopic term and have no such flow.

use glam::{DQuat, DVec3};

use super::Integrator;
use super::drift_kick_drift::FreeBody;
use super::exact_flow::exact_free_flow;
use super::splitting::symmetric_free_flow;
use super::symmetric_kernel::{LaneFlow, turn_from_momentum};

/// The turn `C` of `integrator`'s torque-free rotation over `h` (`Q₁ = Q₀ C`, in the principal
/// frame) of a body with body momentum `m`, reciprocal principal moments `r` (0 on a locked
/// axis) and `splitting`'s odd axis `odd`; `None` for a method without a free flow at constant
/// momentum (see [`Integrator::turns_at_constant_momentum`]). `yoshida4` and `exact4` turn by
/// their stage's flow (`splitting`'s and `exact`'s): the composition is of whole stages.
pub(crate) fn free_turn(
    integrator: Integrator,
    m: DVec3,
    r: DVec3,
    odd: usize,
    h: f64,
) -> Option<DQuat> {
    let mut body = FreeBody {
        q: DQuat::IDENTITY,
        m,
    };
    match integrator {
        Integrator::Splitting | Integrator::Yoshida4 => symmetric_free_flow(&mut body, r, odd, h),
        Integrator::SplittingXyz => body.q = lane_turn(LaneFlow::Xyz { kicks: false }, m, r, h),
        Integrator::Rk4 => body.q = lane_turn(LaneFlow::Rk4 { kicks: false }, m, r, h),
        Integrator::Exact | Integrator::Exact4 => exact_free_flow(&mut body, r, h),
        Integrator::SymplecticEuler
        | Integrator::SymplecticEulerLinear
        | Integrator::Lclamp
        | Integrator::ImplicitGyroscopic => return None,
    }
    Some(body.q.normalize())
}

/// The turn of a lane flow that does not relabel ([`turn_from_momentum`]).
fn lane_turn(flow: LaneFlow, m: DVec3, r: DVec3, h: f64) -> DQuat {
    DQuat::from_array(turn_from_momentum(flow, m.to_array(), r.to_array(), h))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mass::{Mass, MassProperties};
    use crate::math::{Real, Vec3, Widen};
    use crate::state::{BodyState, Wrench};

    /// Each method's turn from the momentum is its own torque-free step: the same orientation
    /// (to the rounding of the engine's state) as a whole torque-free step of the method.
    #[test]
    fn the_turn_is_the_method_s_torque_free_step() {
        let inertia = Vec3::new(0.8, 1.0, 1.7);
        let mass = MassProperties::new(Mass::new(2.0).unwrap(), inertia).unwrap();
        let omega = Vec3::new(0.7, -1.3, 2.1);
        let h: Real = 0.05;
        let eps = Real::EPSILON.widen();
        for &method in Integrator::ALL {
            let state = BodyState {
                angular_velocity: omega,
                ..BodyState::default()
            };
            let odd = mass.odd_axis();
            let frame = mass.principal_frame();
            let m = (mass.principal_inertia() * (frame.inverse() * omega)).widen();
            let r = DVec3::ONE / mass.principal_inertia().widen();
            let turn = free_turn(method, m, r, odd, h.widen());
            assert_eq!(
                turn.is_some(),
                method.turns_at_constant_momentum(),
                "{method}"
            );
            let Some(turn) = turn else { continue };
            let mut stepped = state;
            // One stage of the method: a composition's stage turns by its stage's flow.
            let stage = match method {
                Integrator::Yoshida4 => Integrator::Splitting,
                Integrator::Exact4 => Integrator::Exact,
                other => other,
            };
            stage.whole_stage(&mut stepped, &mass, &Wrench::ZERO, h);
            let expected = stepped.rotation;
            let f = frame.widen();
            let got = f * turn * f.inverse();
            // The angle of `expected⁻¹ got` from its vector part (well conditioned near 0).
            let apart = expected.widen().inverse() * got;
            let angle = 2.0 * apart.xyz().length().min(1.0).asin();
            assert!(angle < 8.0 * eps, "{method}: {angle:e} rad apart");
        }
    }
}
