//! The rotation of the four kick–drift methods (`symplectic-euler`, `symplectic-euler-linear`,
//! `lclamp`, `implicit-gyroscopic`) as one lane-generic kernel: the same code steps one body
//! (`f64`) or [`LANES`] of them (SIMD), so a body's result does not depend on how it was
//! batched, and the single-body step is this kernel on `f64`.
//!
//! Every method kicks the angular velocity in the principal frame and then turns the
//! orientation by the new velocity:
//!
//! ```text
//! Q = q F,  b = Qᵀ ω,  t = Qᵀ τ          (principal frame F, moments I, reciprocals r)
//! Δ = the method's kick of b under t       (its own file: `symplectic_euler`, `lclamp`,
//!                                           `implicit_gyroscopic`)
//! Δ_k = −b_k on a locked axis (r_k = 0),   so that ω' has no rate about it
//! ω' = ω + Q Δ
//! q' = normalize(exp(½ h ω') q)            (or normalize(q + ½ h (ω', 0) q), linearized)
//! ```
//!
//! Only the increment `Δ` is rotated back to the world, so a torque-free spin about a principal
//! axis keeps its rate (`Δ` is round-off of it, below half an ulp of `ω` in the engine
//! precision). Everything runs in `f64` and is rounded to the engine precision once.

use super::Integrator;
use super::frame::reciprocal;
use super::implicit_gyroscopic::implicit_kick;
use super::lane_input::{LaneInput, LaneInputs, RotatedLanes, to_real};
use super::lanes::{PrincipalBody, Quat4, Rotor, Vec3L, conjugate, mul, normalize};
use super::lclamp::clamped_kick;
use super::symplectic_euler::explicit_kick;
use crate::mass::MassProperties;
use crate::math::{Quat, Real, Vec3, Widen};
use crate::simd::{LANES, Lane, LaneKernel, sin_cos};
use crate::state::{BodyState, Wrench};

/// Which of the four kick–drift methods a kernel runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum KickDrift {
    /// `symplectic-euler`: explicit gyroscopic kick, exact turn.
    Explicit,
    /// `symplectic-euler-linear`: explicit gyroscopic kick, linearized turn.
    ExplicitLinear,
    /// `lclamp`: explicit kick with `|L|` rescaled, exact turn.
    Clamped,
    /// `implicit-gyroscopic`: one Newton step of backward Euler, exact turn.
    Implicit,
}

impl KickDrift {
    /// The kernel of `integrator`, if it is a kick–drift method.
    pub(super) fn of(integrator: Integrator) -> Option<Self> {
        match integrator {
            Integrator::SymplecticEuler => Some(Self::Explicit),
            Integrator::SymplecticEulerLinear => Some(Self::ExplicitLinear),
            Integrator::Lclamp => Some(Self::Clamped),
            Integrator::ImplicitGyroscopic => Some(Self::Implicit),
            _ => None,
        }
    }
}

/// `normalize(exp(½ h ω) q)`: the exact turn by `ω` over `h` (the identity for `ω = 0`).
#[inline(always)]
fn turn_exactly<T: Lane>(q: Quat4<T>, omega: Vec3L<T>, h: T) -> Quat4<T> {
    let [w0, w1, w2] = omega;
    let cpu = h.cpu();
    let zero = T::splat(cpu, 0.0);
    let length = (w0 * w0 + w1 * w1 + w2 * w2).sqrt();
    let (s, c) = sin_cos(T::splat(cpu, 0.5) * h * length);
    let scale = T::select(length.gt(zero), s / length, zero);
    normalize(mul([w0 * scale, w1 * scale, w2 * scale, c], q))
}

/// `normalize(q + ½ h (ω, 0) q)`: the linearized turn.
#[inline(always)]
fn turn_linearized<T: Lane>(q: Quat4<T>, omega: Vec3L<T>, h: T) -> Quat4<T> {
    let half = T::splat(h.cpu(), 0.5) * h;
    let [x, y, z, w] = mul([omega[0], omega[1], omega[2], T::splat(h.cpu(), 0.0)], q);
    normalize([
        q[0] + x * half,
        q[1] + y * half,
        q[2] + z * half,
        q[3] + w * half,
    ])
}

/// One kick–drift rotation over `h` in lanes: the new orientation (unit, f64) and world angular
/// velocity. See the module documentation for the sequence.
#[inline(always)]
pub(super) fn kick_drift_rotation<T: Lane>(
    input: &LaneInput<T>,
    h: T,
    method: KickDrift,
) -> (Quat4<T>, Vec3L<T>) {
    let cpu = h.cpu();
    let zero = T::splat(cpu, 0.0);
    let inertia = input.inertia;
    let q = mul(input.rotation, input.frame);
    let to_body = Rotor::new(conjugate(q));
    let omega = to_body.apply(input.omega);
    let body = PrincipalBody {
        omega,
        torque: to_body.apply(input.impulse),
        inertia,
        // Written out, not `map`: inside a `#[target_feature]` function every helper must
        // inline, and `map` need not.
        r: [
            reciprocal(inertia[0]),
            reciprocal(inertia[1]),
            reciprocal(inertia[2]),
        ],
        gyroscopic: T::splat(cpu, 0.5).gt(input.spherical),
    };
    let kick = match method {
        KickDrift::Explicit | KickDrift::ExplicitLinear => explicit_kick(&body, h),
        KickDrift::Clamped => clamped_kick(&body, h),
        KickDrift::Implicit => implicit_kick(&body, h),
    };
    let change = [
        T::select(inertia[0].gt(zero), kick[0], -omega[0]),
        T::select(inertia[1].gt(zero), kick[1], -omega[1]),
        T::select(inertia[2].gt(zero), kick[2], -omega[2]),
    ];
    let world = Rotor::new(q).apply(change);
    let next = [
        input.omega[0] + world[0],
        input.omega[1] + world[1],
        input.omega[2] + world[2],
    ];
    let rotation = match method {
        KickDrift::ExplicitLinear => turn_linearized(input.rotation, next, h),
        _ => turn_exactly(input.rotation, next, h),
    };
    (rotation, next)
}

/// One body through the kernel (`f64` lanes): its new `(q, ω)`, rounded to the engine precision
/// once.
#[inline]
pub(super) fn kick_drift_one(input: &LaneInput, h: Real, method: KickDrift) -> (Quat, Vec3) {
    let (q, w) = kick_drift_rotation::<f64>(input, h.widen(), method);
    to_real(q, w)
}

/// The translation of a kick–drift step, in the engine precision: `v ← v + h m⁻¹ F`,
/// `x ← x + h v`.
#[inline(always)]
pub(super) fn kick_drift_translation(
    state: &mut BodyState,
    mass: &MassProperties,
    force: Vec3,
    h: Real,
) {
    state.linear_velocity += (h * mass.inv_mass()) * force;
    state.position += h * state.linear_velocity;
}

/// A body's kernel inputs under `torque`: its principal frame as it is (the kick–drift kernel
/// does not relabel), the torque where a free flow takes its impulse.
#[inline(always)]
pub(super) fn kick_drift_input(
    state: &BodyState,
    mass: &MassProperties,
    torque: Vec3,
) -> LaneInput {
    LaneInput::for_flow(state.rotation, state.angular_velocity, mass, false).with_impulse(torque)
}

/// One whole kick–drift step of one body over `h` under a constant `wrench`: the translation,
/// then the rotation through the kernel.
#[inline]
pub(super) fn kick_drift_step(
    state: &mut BodyState,
    mass: &MassProperties,
    wrench: &Wrench,
    h: Real,
    method: KickDrift,
) {
    kick_drift_translation(state, mass, wrench.force, h);
    (state.rotation, state.angular_velocity) =
        kick_drift_one(&kick_drift_input(state, mass, wrench.torque), h, method);
}

/// The methods as constants: one compilation of the kernel per method, its method a constant
/// (as for the free flows' kinds, see `symmetric_kernel`).
pub(super) const EXPLICIT: u8 = 0;
pub(super) const EXPLICIT_LINEAR: u8 = 1;
pub(super) const CLAMPED: u8 = 2;
pub(super) const IMPLICIT: u8 = 3;

/// The method `METHOD`.
#[inline(always)]
fn method_of<const METHOD: u8>() -> KickDrift {
    match METHOD {
        EXPLICIT => KickDrift::Explicit,
        EXPLICIT_LINEAR => KickDrift::ExplicitLinear,
        CLAMPED => KickDrift::Clamped,
        _ => KickDrift::Implicit,
    }
}

/// [`LANES`] bodies' kick–drift rotations by the method `METHOD` (SIMD lanes), each over its
/// own `h`, run on a kernel path by [`run_on!`](crate::simd::run_on): lane `i` of the result is
/// bit-identical to [`kick_drift_one`]`(&inputs.get(i), h[i], method)` on every path.
pub(super) struct KickDriftLanes<'a, const METHOD: u8> {
    /// The bodies, their torques as the load.
    pub(super) inputs: &'a LaneInputs,
    /// Each body's span.
    pub(super) h: [Real; LANES],
}

impl<const METHOD: u8> LaneKernel for KickDriftLanes<'_, METHOD> {
    type Output = RotatedLanes;

    /// Runs the kernel over the batch in runs of `T::WIDTH` bodies.
    #[inline(always)]
    fn run<T: Lane>(self, cpu: T::Cpu) -> RotatedLanes {
        let method = method_of::<METHOD>();
        let mut out = RotatedLanes::new();
        let mut start = 0;
        while start < LANES {
            let input = self.inputs.load::<T>(cpu, start, false, true, true);
            let h = T::load_real(cpu, &self.h[start..]);
            let (q, w) = kick_drift_rotation::<T>(&input, h, method);
            out.store(start, q, w);
            start += T::WIDTH;
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::super::lane_input::fixtures::{SPANS, bits};
    use super::*;
    use crate::integrate::KernelPath;
    use crate::mass::Mass;
    use crate::simd::{Kernel, run_on};
    use glam::{DMat3, DQuat, DVec3};

    /// The lanes of `method` on `kernel`, through the compilation of that method (as a batch's
    /// queue runs them).
    fn kick_drift_lanes(
        kernel: Kernel,
        inputs: &LaneInputs,
        h: [Real; LANES],
        method: KickDrift,
    ) -> RotatedLanes {
        match method {
            KickDrift::Explicit => run_on!(kernel, KickDriftLanes::<EXPLICIT> { inputs, h }),
            KickDrift::ExplicitLinear => {
                run_on!(kernel, KickDriftLanes::<EXPLICIT_LINEAR> { inputs, h })
            }
            KickDrift::Clamped => run_on!(kernel, KickDriftLanes::<CLAMPED> { inputs, h }),
            KickDrift::Implicit => run_on!(kernel, KickDriftLanes::<IMPLICIT> { inputs, h }),
        }
    }

    const METHODS: [KickDrift; 4] = [
        KickDrift::Explicit,
        KickDrift::ExplicitLinear,
        KickDrift::Clamped,
        KickDrift::Implicit,
    ];

    /// Eight bodies that exercise a spherical body, a locked axis (whose Newton matrix is
    /// singular), a zero rate, a zero torque, the wide-angle sine path and (lane 6) an angle
    /// beyond the polynomial's range.
    fn bodies() -> [(Quat, Vec3, MassProperties, Vec3); LANES] {
        let cases: [(Vec3, Vec3, Vec3); LANES] = [
            (
                Vec3::new(1.0, 2.0, 3.0),
                Vec3::new(0.3, 5.0, 0.1),
                Vec3::ZERO,
            ),
            (
                Vec3::new(2.0, 1.0, 2.05),
                Vec3::new(-40.0, 1.0, 3.0),
                Vec3::X,
            ),
            (Vec3::new(3.0, 3.1, 0.2), Vec3::new(1.0, 1.0, 90.0), Vec3::Y),
            (Vec3::new(0.0, 1.0, 1.5), Vec3::new(2.0, -1.0, 0.5), Vec3::Z),
            (Vec3::splat(0.7), Vec3::new(0.01, 0.02, -0.03), Vec3::ONE),
            (
                Vec3::new(1.0, 2.0, 3.0),
                Vec3::ZERO,
                Vec3::new(0.0, -2.0, 0.5),
            ),
            (
                Vec3::new(1.0, 29.0, 30.0),
                Vec3::new(1e8, -3e7, 2e7),
                Vec3::X,
            ),
            (
                Vec3::new(5.0, 0.5, 4.6),
                Vec3::new(7.0, 0.1, -7.0),
                Vec3::ZERO,
            ),
        ];
        std::array::from_fn(|i| {
            let (inertia, omega, torque) = cases[i];
            let mass = MassProperties::new(Mass::new(1.0).unwrap(), inertia)
                .unwrap()
                .with_principal_frame(Quat::from_rotation_x(0.2 * i as Real))
                .unwrap();
            (Quat::from_rotation_y(i as Real), omega, mass, torque)
        })
    }

    /// Every compilation of the kernel the CPU runs (portable, and AVX2 or AVX-512 where it has
    /// them) and the one-body kernel agree bit for bit, for each method; a lane beyond the
    /// sine's range does not change its neighbours' bits.
    #[test]
    fn lane_kernels_match_the_one_body_kernel() {
        let bodies = bodies();
        let h = SPANS;
        let mut inputs = LaneInputs::default();
        for (lane, &(rotation, omega, mass, torque)) in bodies.iter().enumerate() {
            inputs.set(lane, rotation, omega, &mass, torque, false);
            let state = BodyState {
                rotation,
                angular_velocity: omega,
                ..BodyState::default()
            };
            let one = kick_drift_input(&state, &mass, torque);
            assert_eq!(inputs.get(lane), one, "lane {lane}");
        }
        let kernels = Kernel::available();
        assert_eq!(kernels[0].path(), KernelPath::Portable);
        for method in METHODS {
            let expected: Vec<_> = (0..LANES)
                .map(|i| kick_drift_one(&inputs.get(i), h[i], method))
                .collect();
            for &kernel in &kernels {
                let lanes = kick_drift_lanes(kernel, &inputs, h, method);
                let got: Vec<_> = (0..LANES).map(|i| lanes.lane(i)).collect();
                assert_eq!(
                    bits(&got),
                    bits(&expected),
                    "{method:?} on {}",
                    kernel.path()
                );
            }
        }
    }

    /// Each method's formula, written out independently with `glam`'s f64 types: the new world
    /// rate and orientation (see the method files).
    fn reference(method: KickDrift, input: &LaneInput, h: f64) -> (DQuat, DVec3) {
        let quat = |q: [f64; 4]| DQuat::from_xyzw(q[0], q[1], q[2], q[3]);
        let (q, frame) = (quat(input.rotation), quat(input.frame));
        let (omega, inertia, torque) = (
            DVec3::from(input.omega),
            DVec3::from(input.inertia),
            DVec3::from(input.impulse),
        );
        // The kernel rotates by `q v q* / |q|²`, a rotation even for the inputs' f32 rounding.
        let principal = (q * frame).normalize();
        let b = principal.conjugate() * omega;
        let t = principal.conjugate() * torque;
        let r = inertia
            .to_array()
            .map(|i| if i > 0.0 { 1.0 / i } else { 0.0 });
        let r = DVec3::from(r);
        let spherical = input.spherical == 1.0;
        let mut next = match method {
            KickDrift::Explicit | KickDrift::ExplicitLinear => {
                let gyro = if spherical {
                    DVec3::ZERO
                } else {
                    b.cross(inertia * b)
                };
                b + h * r * (t - gyro)
            }
            KickDrift::Clamped => {
                let n = b + h * r * (t - b.cross(inertia * b));
                n * ((inertia * b + h * t).length() / (inertia * n).length())
            }
            KickDrift::Implicit => {
                let w = b + h * r * t;
                let skew = |a: DVec3| {
                    DMat3::from_cols(
                        DVec3::new(0.0, a.z, -a.y),
                        DVec3::new(-a.z, 0.0, a.x),
                        DVec3::new(a.y, -a.x, 0.0),
                    )
                };
                let diag = DMat3::from_diagonal(inertia);
                let jacobian = diag + (skew(w) * diag - skew(inertia * w)) * h;
                if spherical || jacobian.determinant() == 0.0 {
                    w
                } else {
                    w - jacobian.inverse() * (h * w.cross(inertia * w))
                }
            }
        };
        for k in 0..3 {
            if inertia[k] == 0.0 {
                next[k] = 0.0;
            }
        }
        let world = principal * next;
        let turned = match method {
            KickDrift::ExplicitLinear => {
                (q + DQuat::from_xyzw(world.x, world.y, world.z, 0.0) * q * (0.5 * h)).normalize()
            }
            _ => (DQuat::from_scaled_axis(world * h) * q).normalize(),
        };
        (turned, world)
    }

    /// The kernel computes each method's formula: on the eight bodies (the one beyond the
    /// sine's range aside, where only the rate is compared), the new rate and orientation agree
    /// with the written-out reference to f64 round-off of their size.
    #[test]
    fn the_kernel_computes_each_method() {
        for (lane, &(rotation, omega, mass, torque)) in bodies().iter().enumerate() {
            let state = BodyState {
                rotation,
                angular_velocity: omega,
                ..BodyState::default()
            };
            let input = kick_drift_input(&state, &mass, torque);
            for method in METHODS {
                let h = 1.0 / 60.0;
                let (q, w) = kick_drift_rotation::<f64>(&input, h, method);
                let (q_ref, w_ref) = reference(method, &input, h);
                let scale = 1.0 + w_ref.length();
                let rate_error = (DVec3::from(w) - w_ref).length() / scale;
                assert!(rate_error < 1e-13, "{method:?} lane {lane}: {rate_error:e}");
                if lane != 6 {
                    let q = DQuat::from_array(q);
                    let turn_error = (q - q_ref).length().min((q + q_ref).length());
                    assert!(turn_error < 1e-13, "{method:?} lane {lane}: {turn_error:e}");
                }
            }
        }
    }
}
