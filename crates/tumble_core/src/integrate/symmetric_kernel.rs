//! The `splitting` free flow as one lane-generic kernel: the same code steps one body (`f64`)
//! or [`LANES`] (SIMD), so a body's result does not depend on how it was batched.
//!
//! The axes are relabelled per body so that the symmetric pair is always `(y, z)` and the odd
//! axis `x` (see [`super::splitting`] for the splitting itself): a cyclic relabelling is a proper
//! rotation `P` (120° or 240° about `(1,1,1)`), folded into the principal frame, `F' = F P`.
//! With that, every lane runs the same branch-free sequence
//!
//! ```text
//! Q = q F',  m = I' ⊙ Qᵀω  (+ free ⊙ QᵀJ after a kick),
//! rotate about z by ½h (r_z − r_y) m_z,   about m by h r_y |m|,
//! rotate about x by h (r_x − r_y) m_x,    about z by ½h (r_z − r_y) m_z,
//! ω' = Q (r ⊙ m),  q' = normalize(Q F'ᵀ)
//! ```
//!
//! The kick before the second half drift of a step under torque, `L += J` with the angular
//! impulse `J = Δt τ`, is folded into the body momentum (`m += Qᵀ J` on the free axes) instead of
//! being applied to `ω` first: the same motion without a round trip through the world inverse
//! inertia and the engine's precision in between.
//!
//! A rotation by a zero angle is the exact identity (`sin 0 = 0`, `cos 0 = 1`), so locked axes
//! (`r = 0`) and symmetric bodies need no branches.

use super::frame::reciprocal;
use super::lane_input::{LaneInput, LaneInputs, RotatedLanes};
use super::lanes::{Quat4, Rotor, Vec3L, conjugate, mul, rotate};
use super::rk4::rk4_flow;
use crate::mass::MassProperties;
use crate::math::{Quat, Real, Vec3, Widen};
use crate::simd::{Counted, LANES, Lane, LaneKernel, OpCounts, Portable, counted, sin_cos};

/// `(sin θ/2, cos θ/2)` of `angle` θ, and `(cos θ, sin θ)` from them by the double-angle
/// formulas.
#[inline(always)]
fn half_and_whole<T: Lane>(angle: T) -> ((T, T), (T, T)) {
    let cpu = angle.cpu();
    let (s, c) = sin_cos(T::splat(cpu, 0.5) * angle);
    ((s, c), (c * c - s * s, T::splat(cpu, 2.0) * s * c))
}

/// The principal orientation `Q` and body momentum `m` a free flow advances.
struct Free<T> {
    q: Quat4<T>,
    m: Vec3L<T>,
}

impl<T: Lane> Free<T> {
    /// `Q ← Q exp(θ e_x)`, `m ← exp(−θ e_x) m`.
    #[inline(always)]
    fn rotate_x(&mut self, angle: T) {
        let ((s, c), (cos, sin)) = half_and_whole(angle);
        let [x, y, z, w] = self.q;
        self.q = [c * x + w * s, c * y + z * s, c * z - y * s, c * w - x * s];
        let [m0, m1, m2] = self.m;
        self.m = [m0, cos * m1 + sin * m2, cos * m2 - sin * m1];
    }

    /// `Q ← Q exp(θ e_y)`, `m ← exp(−θ e_y) m`.
    #[inline(always)]
    fn rotate_y(&mut self, angle: T) {
        let ((s, c), (cos, sin)) = half_and_whole(angle);
        let [x, y, z, w] = self.q;
        self.q = [c * x - z * s, c * y + w * s, c * z + x * s, c * w - y * s];
        let [m0, m1, m2] = self.m;
        self.m = [cos * m0 - sin * m2, m1, cos * m2 + sin * m0];
    }

    /// `Q ← Q exp(θ e_z)`, `m ← exp(−θ e_z) m`.
    #[inline(always)]
    fn rotate_z(&mut self, angle: T) {
        let ((s, c), (cos, sin)) = half_and_whole(angle);
        let [x, y, z, w] = self.q;
        self.q = [c * x + y * s, c * y - x * s, c * z + w * s, c * w - z * s];
        let [m0, m1, m2] = self.m;
        self.m = [cos * m0 + sin * m1, cos * m1 - sin * m0, m2];
    }

    /// Flow of the Casimir `½ k |m|²` for `h`: `Q ← Q exp(h k m)`; `m` is unchanged.
    #[inline(always)]
    fn rotate_about_momentum(&mut self, k: T, h: T) {
        let [m0, m1, m2] = self.m;
        let cpu = h.cpu();
        let length = (m0 * m0 + m1 * m1 + m2 * m2).sqrt();
        let (s, c) = sin_cos(T::splat(cpu, 0.5) * h * k * length);
        let zero = T::splat(cpu, 0.0);
        let scale = T::select(length.gt(zero), s / length, zero);
        self.q = mul(self.q, [m0 * scale, m1 * scale, m2 * scale, c]);
    }
}

/// A free flow under way: the body in its relabelled principal frame `F'`, its reciprocal
/// moments `r` (0 on a locked axis), and `F'` to return through.
pub(super) struct Flowing<T> {
    free: Free<T>,
    r: Vec3L<T>,
    frame: Quat4<T>,
}

impl<T: Lane> Flowing<T> {
    /// `Q = q F'`, `m = I' ⊙ Qᵀω`; when `kicks`, plus `Qᵀ J` on the free axes (`I' > 0`) of
    /// every lane whose impulse `J` is not zero (or is NaN, which must show), so that a lane
    /// without a torque gets the bits of a flow without a kick.
    #[inline(always)]
    pub(super) fn start(input: &LaneInput<T>, kicks: bool) -> Self {
        let inertia = input.inertia;
        // Written out, not `inertia.map(reciprocal)`: inside a `#[target_feature]` function
        // every helper must inline, and `map` need not.
        let r = [
            reciprocal(inertia[0]),
            reciprocal(inertia[1]),
            reciprocal(inertia[2]),
        ];
        let frame = mul(input.frame, input.relabel);
        let q = mul(input.rotation, frame);
        // One rotor for ω and, after a kick, J: the same bits as rotating each alone.
        let to_body = Rotor::new(conjugate(q));
        let body = to_body.apply(input.omega);
        let mut m = [
            inertia[0] * body[0],
            inertia[1] * body[1],
            inertia[2] * body[2],
        ];
        if kicks {
            let j = input.impulse;
            let cpu = j[0].cpu();
            let zero = T::splat(cpu, 0.0);
            let kicked = (j[0] * j[0] + j[1] * j[1] + j[2] * j[2]).beyond(0.0);
            let body_j = to_body.apply(j);
            // Written out, not a loop over the axes: see `reciprocal` above.
            let free = [
                T::select(inertia[0].gt(zero), body_j[0], zero),
                T::select(inertia[1].gt(zero), body_j[1], zero),
                T::select(inertia[2].gt(zero), body_j[2], zero),
            ];
            m = [
                T::select(kicked, m[0] + free[0], m[0]),
                T::select(kicked, m[1] + free[1], m[1]),
                T::select(kicked, m[2] + free[2], m[2]),
            ];
        }
        Self {
            free: Free { q, m },
            r,
            frame,
        }
    }

    /// The symmetric + residual Strang flow over `h`, `R(h/2) ∘ S(h) ∘ R(h/2)` (see
    /// [`super::splitting`]): the odd axis is `x`, the symmetric pair `(y, z)`.
    #[inline(always)]
    pub(super) fn symmetric_flow(&mut self, h: T) {
        let (free, r) = (&mut self.free, self.r);
        let half = T::splat(h.cpu(), 0.5) * h;
        let residual = r[2] - r[1];
        free.rotate_z(half * residual * free.m[2]);
        free.rotate_about_momentum(r[1], h);
        free.rotate_x(h * (r[0] - r[1]) * free.m[0]);
        free.rotate_z(half * residual * free.m[2]);
    }

    /// Strang 1-2-3-2-1 over `h`: the exact flows of `½ r_x m_x²` for `h/2`, of `½ r_y m_y²` for
    /// `h/2`, of `½ r_z m_z²` for `h`, then back (`splitting-xyz`, see [`super::splitting`]).
    #[inline(always)]
    pub(super) fn xyz_flow(&mut self, h: T) {
        let (free, r) = (&mut self.free, self.r);
        let half = T::splat(h.cpu(), 0.5) * h;
        free.rotate_x(half * r[0] * free.m[0]);
        free.rotate_y(half * r[1] * free.m[1]);
        free.rotate_z(h * r[2] * free.m[2]);
        free.rotate_y(half * r[1] * free.m[1]);
        free.rotate_x(half * r[0] * free.m[0]);
    }

    /// `flow` over `h` (its kick, if any, is [`start`](Self::start)'s).
    #[inline(always)]
    pub(super) fn flow(&mut self, h: T, flow: LaneFlow) {
        match flow {
            LaneFlow::Symmetric { .. } => self.symmetric_flow(h),
            LaneFlow::Composed(weights) => {
                // Indexed, not iterated: inside a `#[target_feature]` function every helper
                // must inline.
                let mut k = 0;
                while k < weights.len() {
                    self.symmetric_flow(T::splat(h.cpu(), weights[k].widen()) * h);
                    k += 1;
                }
            }
            LaneFlow::Xyz { .. } => self.xyz_flow(h),
            LaneFlow::Rk4 { .. } => rk4_flow(&mut self.free.q, &mut self.free.m, self.r, h),
        }
    }
}

/// Which free flow a kernel call runs: `splitting`'s symmetric-top flow (alone, or composed as
/// in `yoshida4`), `splitting-xyz`'s axis-by-axis flow, or `rk4`'s.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum LaneFlow {
    /// One symmetric-top flow over `h` (`splitting`), after the kick of the inputs' angular
    /// impulse when `kicks`.
    Symmetric {
        /// Fold the impulse into the momentum first.
        kicks: bool,
    },
    /// The symmetric-top flows over `c h` for each weight `c` in turn, without a kick: the free
    /// rotation of a whole composed step without torque (`yoshida4`'s triple jump, see
    /// `stages`).
    Composed(&'static [Real]),
    /// The Strang splitting 1-2-3-2-1 over `h` (`splitting-xyz`, see `splitting`), after the
    /// kick when `kicks`.
    Xyz {
        /// Fold the impulse into the momentum first.
        kicks: bool,
    },
    /// One RK4 step of the rotation at constant momentum over `h` (`rk4`, see `rk4`), after
    /// the kick when `kicks`.
    Rk4 {
        /// Fold the impulse into the momentum first.
        kicks: bool,
    },
}

impl LaneFlow {
    /// True when the flow folds the inputs' angular impulse into the momentum first.
    #[inline(always)]
    pub(super) fn kicks(self) -> bool {
        matches!(
            self,
            LaneFlow::Symmetric { kicks: true }
                | LaneFlow::Xyz { kicks: true }
                | LaneFlow::Rk4 { kicks: true }
        )
    }

    /// The composed flow's weights (none for the other flows).
    #[inline(always)]
    pub(super) fn weights(self) -> &'static [Real] {
        match self {
            LaneFlow::Composed(weights) => weights,
            _ => &[],
        }
    }

    /// True when the flow runs in the relabelled frame whose odd axis is `x` (the symmetric-top
    /// flows); the others run in the principal frame as it is.
    #[inline(always)]
    pub(super) fn relabels(self) -> bool {
        matches!(self, LaneFlow::Symmetric { .. } | LaneFlow::Composed(_))
    }

    /// The same flow with or without the kick.
    #[inline(always)]
    pub(super) fn with_kick(self, kicks: bool) -> Self {
        match self {
            LaneFlow::Symmetric { .. } => LaneFlow::Symmetric { kicks },
            LaneFlow::Xyz { .. } => LaneFlow::Xyz { kicks },
            LaneFlow::Rk4 { .. } => LaneFlow::Rk4 { kicks },
            composed => composed,
        }
    }
}

/// The floating-point operations of one body's free rotation through this kernel (after a kick
/// when `kicks`), counted by running it on a lane that counts: a body with distinct moments at
/// game rates (I = (1, 2, 3), |ω| ≈ 1 rad/s, Δt = 1/60), whose angles take the sine's
/// small-angle path, as almost every step does. A SIMD path runs the same operations on four or
/// eight bodies per instruction.
pub fn symmetric_rotation_flops(kicks: bool) -> OpCounts {
    use crate::mass::Mass;
    let mass = MassProperties::new(Mass::new(1.0).expect("positive"), Vec3::new(1.0, 2.0, 3.0))
        .expect("valid moments");
    let input = LaneInput::new(
        Quat::from_xyzw(0.1, 0.2, 0.3, 0.927_361_8).normalize(),
        Vec3::new(0.3, 1.0, 0.2),
        &mass,
    )
    .with_impulse(Vec3::new(0.01, 0.0, -0.02));
    let one = OneInput {
        input: &input,
        h: 1.0 / 60.0,
    };
    let rotation = SymmetricLanes::<_, ANY>::new(one, LaneFlow::Symmetric { kicks });
    counted(|| rotation.run::<Counted>(Portable)).1
}

/// The turn `C` of `flow` over `h` from the identity (`Q₁ = Q₀ C`, unnormalized) of a body with
/// body momentum `m` and reciprocal moments `r` in its (unrelabelled) principal frame, in `f64`:
/// the flows multiply `Q` on the right, so the turn depends on `m` and `h` alone (see
/// `momentum_flow`). For the flows that do not relabel.
pub(super) fn turn_from_momentum(flow: LaneFlow, m: [f64; 3], r: [f64; 3], h: f64) -> [f64; 4] {
    debug_assert!(!flow.relabels());
    let mut flowing = Flowing {
        free: Free {
            q: [0.0, 0.0, 0.0, 1.0],
            m,
        },
        r,
        frame: [0.0, 0.0, 0.0, 1.0],
    };
    flowing.flow(h, flow.with_kick(false));
    flowing.free.q
}

/// One body through the kernel (`f64` lanes): the new `(q, ω)` after `flow`, rounded to the
/// engine precision once.
#[inline]
pub(super) fn rotate_symmetric_one(input: &LaneInput, h: Real, flow: LaneFlow) -> (Quat, Vec3) {
    let one = OneInput {
        input,
        h: h.widen(),
    };
    SymmetricLanes::<_, ANY>::new(one, flow)
        .run::<f64>(Portable)
        .lane(0)
}

/// The kinds of [`LaneFlow`] as constants: one compilation of the kernel per kind of flow, its
/// kind a constant (one compilation holding every kind's code runs the hot `splitting` flow
/// measurably slower: the free-body rows of `tumble bench`). [`ANY`] takes the flow's kind as
/// it comes (the one-body step, which compiles the kernel once for every kind).
pub(super) const SYMMETRIC: u8 = 0;
pub(super) const COMPOSED: u8 = 1;
pub(super) const XYZ: u8 = 2;
pub(super) const RK4: u8 = 3;
pub(super) const ANY: u8 = 4;

/// `flow` with its kind made the constant `KIND` (its kick and weights kept), or as it is for
/// [`ANY`].
#[inline(always)]
fn of_kind<const KIND: u8>(flow: LaneFlow) -> LaneFlow {
    let kicks = flow.kicks();
    match KIND {
        SYMMETRIC => LaneFlow::Symmetric { kicks },
        COMPOSED => LaneFlow::Composed(flow.weights()),
        XYZ => LaneFlow::Xyz { kicks },
        RK4 => LaneFlow::Rk4 { kicks },
        _ => flow,
    }
}

/// Where a rotation kernel reads its bodies and their spans `h`: a queued batch of [`LANES`]
/// ([`QueuedInputs`]) or one body ([`OneInput`]).
pub(super) trait RotationInputs {
    /// How many bodies.
    const BODIES: usize;

    /// Bodies `start..start + T::WIDTH` as lanes (their angular impulses when `kicks`), and
    /// their spans.
    fn load<T: Lane>(&self, cpu: T::Cpu, start: usize, kicks: bool) -> (LaneInput<T>, T);
}

/// A queued batch's inputs, component by component, and each body's span.
pub(super) struct QueuedInputs<'a> {
    /// The bodies, [`LANES`] of them.
    pub inputs: &'a LaneInputs,
    /// Each body's span.
    pub h: [Real; LANES],
}

impl RotationInputs for QueuedInputs<'_> {
    const BODIES: usize = LANES;

    /// One vector load per input component of the run.
    #[inline(always)]
    fn load<T: Lane>(&self, cpu: T::Cpu, start: usize, kicks: bool) -> (LaneInput<T>, T) {
        let input = self.inputs.load::<T>(cpu, start, true, kicks, false);
        (input, T::load_real(cpu, &self.h[start..]))
    }
}

/// One body's inputs and span, in `f64`.
pub(super) struct OneInput<'a> {
    /// The body.
    pub input: &'a LaneInput,
    /// Its span.
    pub h: f64,
}

impl RotationInputs for OneInput<'_> {
    const BODIES: usize = 1;

    /// The body in every lane of `T` (`f64`, or a lane that counts).
    #[inline(always)]
    fn load<T: Lane>(&self, cpu: T::Cpu, _: usize, _: bool) -> (LaneInput<T>, T) {
        let lane = |x: f64| T::splat(cpu, x);
        let one = self.input;
        let input = LaneInput {
            rotation: one.rotation.map(lane),
            omega: one.omega.map(lane),
            frame: one.frame.map(lane),
            relabel: one.relabel.map(lane),
            inertia: one.inertia.map(lane),
            impulse: one.impulse.map(lane),
            spherical: lane(one.spherical),
        };
        (input, lane(self.h))
    }
}

/// The free rotations of flow kind `KIND` (see [`of_kind`]) of the bodies of `S`, each over its
/// own `h` (after the kick of its impulse for a kicking flow), run on a kernel path by
/// [`run_on!`](crate::simd::run_on): lane `i` of a queued batch's result is bit-identical to
/// [`rotate_symmetric_one`]`(&inputs.get(i), h[i], flow)` on every path.
pub(super) struct SymmetricLanes<S, const KIND: u8> {
    inputs: S,
    flow: LaneFlow,
}

impl<S: RotationInputs, const KIND: u8> SymmetricLanes<S, KIND> {
    /// The rotations of `inputs` under `flow` (of kind `KIND`, unless that is [`ANY`]).
    #[inline(always)]
    pub(super) fn new(inputs: S, flow: LaneFlow) -> Self {
        Self { inputs, flow }
    }
}

impl<S: RotationInputs, const KIND: u8> LaneKernel for SymmetricLanes<S, KIND> {
    type Output = RotatedLanes;

    /// The free rotation, run by run of `T::WIDTH` bodies: the kick (when the flow has one)
    /// and the flow of `Q` and `m` (see the module documentation), then the new world angular
    /// velocity `ω' = Q (r ⊙ m)` and orientation `q' = normalize(Q F'ᵀ)` (unit, f64), rounded
    /// to the engine precision.
    #[inline(always)]
    fn run<T: Lane>(self, cpu: T::Cpu) -> RotatedLanes {
        let flow = of_kind::<KIND>(self.flow);
        let mut out = RotatedLanes::new();
        let mut start = 0;
        while start < S::BODIES {
            let (input, h) = self.inputs.load::<T>(cpu, start, flow.kicks());
            let mut flowing = Flowing::start(&input, flow.kicks());
            flowing.flow(h, flow);
            let Flowing {
                free: Free { q, m },
                r,
                frame,
            } = flowing;
            let omega = rotate(q, [r[0] * m[0], r[1] * m[1], r[2] * m[2]]);
            let [x, y, z, w] = mul(q, conjugate(frame));
            let inv = T::splat(cpu, 1.0) / (x * x + y * y + z * z + w * w).sqrt();
            out.store(start, [x * inv, y * inv, z * inv, w * inv], omega);
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

    /// The lanes of `flow` on `kernel`, through the compilation of its kind (as a batch's
    /// queue runs them).
    fn rotate_symmetric_lanes(
        kernel: Kernel,
        inputs: &LaneInputs,
        h: [Real; LANES],
        flow: LaneFlow,
    ) -> RotatedLanes {
        let queued = QueuedInputs { inputs, h };
        match flow {
            LaneFlow::Symmetric { .. } => {
                run_on!(kernel, SymmetricLanes::<_, SYMMETRIC>::new(queued, flow))
            }
            LaneFlow::Composed(_) => {
                run_on!(kernel, SymmetricLanes::<_, COMPOSED>::new(queued, flow))
            }
            LaneFlow::Xyz { .. } => run_on!(kernel, SymmetricLanes::<_, XYZ>::new(queued, flow)),
            LaneFlow::Rk4 { .. } => run_on!(kernel, SymmetricLanes::<_, RK4>::new(queued, flow)),
        }
    }

    /// Every compilation of the lane kernel the CPU runs (portable, and AVX2 or AVX-512 where
    /// it has them) and the scalar kernel agree bit for bit, on bodies that exercise every
    /// relabelling, a locked axis, the wide-angle sine path and (lane 6) an angle beyond the
    /// polynomial's range, which must not change its neighbours' bits; with and without the
    /// kick, whose impulse is zero in two lanes (they must get the unkicked bits) and falls on
    /// the locked axis of lane 3.
    #[test]
    fn lane_kernels_match_the_scalar_kernel() {
        let bodies: Vec<(Vec3, Vec3)> = vec![
            (Vec3::new(1.0, 2.0, 3.0), Vec3::new(0.3, 5.0, 0.1)),
            (Vec3::new(2.0, 1.0, 2.05), Vec3::new(-40.0, 1.0, 3.0)),
            (Vec3::new(3.0, 3.1, 0.2), Vec3::new(1.0, 1.0, 90.0)),
            (Vec3::new(0.0, 1.0, 1.5), Vec3::new(2.0, -1.0, 0.5)),
            (Vec3::splat(0.7), Vec3::new(0.01, 0.02, -0.03)),
            (Vec3::new(1.0, 2.0, 3.0), Vec3::new(-0.2, 0.0, 0.0)),
            (Vec3::new(1.0, 29.0, 30.0), Vec3::new(1e8, -3e7, 2e7)),
            (Vec3::new(5.0, 0.5, 4.6), Vec3::new(7.0, 0.1, -7.0)),
        ];
        let bodies_in: [(Quat, Vec3, MassProperties); LANES] = std::array::from_fn(|i| {
            let (inertia, omega) = bodies[i];
            let mass = MassProperties::new(Mass::new(1.0).unwrap(), inertia)
                .unwrap()
                .with_principal_frame(Quat::from_rotation_x(0.2 * i as Real))
                .unwrap();
            (Quat::from_rotation_y(i as Real), omega, mass)
        });
        let impulses: [Vec3; LANES] = std::array::from_fn(|i| match i {
            0 | 5 => Vec3::ZERO,
            3 => Vec3::new(0.4, 0.0, 0.0),
            _ => Vec3::new(0.05 * i as Real, -0.02, 0.01 * (i * i) as Real),
        });
        let owned: [LaneInput; LANES] = std::array::from_fn(|i| {
            let (rotation, omega, mass) = bodies_in[i];
            LaneInput::new(rotation, omega, &mass).with_impulse(impulses[i])
        });
        let h = SPANS;
        let expected = |flow: LaneFlow| -> Vec<(Quat, Vec3)> {
            (0..LANES)
                .map(|i| rotate_symmetric_one(&owned[i], h[i], flow))
                .collect()
        };
        let mut inputs = LaneInputs::default();
        for (lane, &(rotation, omega, mass)) in bodies_in.iter().enumerate() {
            inputs.set(lane, rotation, omega, &mass, impulses[lane], true);
            assert_eq!(inputs.get(lane), owned[lane], "lane {lane}");
        }
        let inputs = &inputs;
        let lanes = |r: RotatedLanes| (0..LANES).map(|i| r.lane(i)).collect::<Vec<_>>();
        let kernels = Kernel::available();
        assert_eq!(kernels[0].path(), KernelPath::Portable);
        let flows = [
            LaneFlow::Symmetric { kicks: false },
            LaneFlow::Symmetric { kicks: true },
            LaneFlow::Composed(&super::super::stages::TRIPLE_JUMP),
            LaneFlow::Xyz { kicks: false },
            LaneFlow::Xyz { kicks: true },
            LaneFlow::Rk4 { kicks: false },
            LaneFlow::Rk4 { kicks: true },
        ];
        for flow in flows {
            for &kernel in &kernels {
                assert_eq!(
                    bits(&lanes(rotate_symmetric_lanes(kernel, inputs, h, flow))),
                    bits(&expected(flow)),
                    "{} {flow:?}",
                    kernel.path()
                );
            }
        }
        // A zero impulse is no kick, bit for bit; a non-zero one changes the motion.
        let (unkicked, kicked) = (
            expected(LaneFlow::Symmetric { kicks: false }),
            expected(LaneFlow::Symmetric { kicks: true }),
        );
        for lane in 0..LANES {
            let same = bits(&unkicked[lane..=lane]) == bits(&kicked[lane..=lane]);
            assert_eq!(same, impulses[lane] == Vec3::ZERO, "lane {lane}");
        }
    }

    /// The operation count is the kernel's: four sines and cosines (each two polynomials of
    /// about 25 flops and the double angle), five quaternion products (28 flops each), the
    /// rotations in and out (about 45 each) and three reciprocal moments. A kick adds the
    /// rotation of `J` without its rotor's setup (33 flops: 6 of `2 b·v`, 9 of the cross product,
    /// 6 per component), 5 for `|J|²` and 3 adds, 41 in all, and no division. Bounds on the
    /// total catch a count of nothing, of one sine only, or of a kernel that doubled.
    #[test]
    fn the_kernel_flops_are_counted() {
        let free = symmetric_rotation_flops(false);
        let kicked = symmetric_rotation_flops(true);
        assert!((300..=600).contains(&free.total()), "{free:?}");
        assert_eq!((free.sqrt, free.div), (2, 7), "{free:?}");
        let extra = OpCounts {
            add: kicked.add - free.add,
            mul: kicked.mul - free.mul,
            div: kicked.div - free.div,
            sqrt: kicked.sqrt - free.sqrt,
        };
        assert_eq!(extra.total(), 41, "{free:?} → {kicked:?}");
        assert_eq!(extra.div, 0, "the kick shares the rotor of ω");
    }

    /// The kick folded into the body momentum is the kick `ω += I⁻¹ J` applied first: the two
    /// agree to the rounding of `ω` to the engine's precision.
    #[test]
    fn the_folded_kick_is_the_kick_applied_first() {
        let mass = MassProperties::new(Mass::new(2.0).unwrap(), Vec3::new(0.4, 0.5, 0.8))
            .unwrap()
            .with_principal_frame(Quat::from_rotation_z(0.4))
            .unwrap();
        let rotation = Quat::from_rotation_y(1.1) * Quat::from_rotation_x(0.3);
        let (omega, impulse, h) = (Vec3::new(1.0, -2.0, 0.5), Vec3::new(0.3, 0.1, -0.2), 0.01);
        let folded = LaneInput::new(rotation, omega, &mass).with_impulse(impulse);
        let (q_folded, w_folded) =
            rotate_symmetric_one(&folded, h, LaneFlow::Symmetric { kicks: true });
        let kicked = omega + mass.world_inv_inertia_mul(rotation, impulse);
        let first = LaneInput::new(rotation, kicked, &mass);
        let (q_first, w_first) =
            rotate_symmetric_one(&first, h, LaneFlow::Symmetric { kicks: false });
        // ω ≈ 3 rad/s rounded once more on the second path: a few ulps of it.
        let tolerance = 16.0 * Real::EPSILON * 4.0;
        assert!(
            (w_folded - w_first).length() < tolerance,
            "{w_folded} vs {w_first}"
        );
        assert!(q_folded.dot(q_first).abs() > 1.0 - tolerance);
        assert!((w_folded - omega).length() > 0.1, "the kick acted");
    }
}
