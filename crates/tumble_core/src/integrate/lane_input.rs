//! What the lane kernels read and write: a body's inputs as one value (`T = f64`) or as
//! [`LANES`] bodies component by component, and their results, shared by the free-flow kernel
//! (`symmetric_kernel`) and the kick–drift kernel (`kick_drift_kernel`).

use crate::mass::MassProperties;
use crate::math::{Narrow, Quat, Real, Vec3, Widen};
use crate::simd::{LANES, Lane};

use super::lanes::{Quat4, Vec3L};

/// Inputs of a lane kernel for one body (`T = f64`) or a run of bodies (a SIMD lane type).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(super) struct LaneInput<T = f64> {
    /// Body orientation `q`.
    pub rotation: Quat4<T>,
    /// World angular velocity `ω`.
    pub omega: Vec3L<T>,
    /// Principal frame `F`.
    pub frame: Quat4<T>,
    /// The relabelling `P` (identity, or 120° / 240° about `(1,1,1)`).
    pub relabel: Quat4<T>,
    /// Relabelled principal moments `I'`.
    pub inertia: Vec3L<T>,
    /// Angular impulse `J` (world frame) of the kick just before a free flow (zero when there
    /// is none; read only by a kicking flow), or the torque `τ` a kick–drift step holds.
    pub impulse: Vec3L<T>,
    /// 1 for a spherical body, 0 otherwise (read by the kick–drift kernel).
    pub spherical: T,
}

/// The relabellings `P`: `x' = a`, for the odd axis `a` = x, y, z (exact in any precision).
const RELABEL: [[Real; 4]; 3] = [
    [0.0, 0.0, 0.0, 1.0],
    [0.5, 0.5, 0.5, 0.5],
    [-0.5, -0.5, -0.5, 0.5],
];

/// The relabelling `P` and the moments in its frame: [`relabelled_inertia`] with its `P` when
/// `relabel`, else the identity and the moments as they are.
#[inline(always)]
fn relabelling(mass: &MassProperties, relabel: bool) -> ([Real; 4], [Real; 3]) {
    if relabel {
        (RELABEL[mass.odd_axis()], relabelled_inertia(mass))
    } else {
        (RELABEL[0], mass.principal_inertia().to_array())
    }
}

/// A body's principal moments relabelled `(a, a+1, a+2) → (x, y, z)` for its odd axis `a`
/// ([`MassProperties::odd_axis`]: the pair of axes with the closest reciprocal moments is the
/// symmetric pair).
#[inline(always)]
fn relabelled_inertia(mass: &MassProperties) -> [Real; 3] {
    let i = mass.principal_inertia();
    match mass.odd_axis() {
        0 => [i.x, i.y, i.z],
        1 => [i.y, i.z, i.x],
        _ => [i.z, i.x, i.y],
    }
}

impl LaneInput {
    /// Builds the inputs for one body, relabelled so that its odd axis is `x` (see the module
    /// documentation).
    #[inline]
    pub(super) fn new(rotation: Quat, omega: Vec3, mass: &MassProperties) -> Self {
        Self::for_flow(rotation, omega, mass, true)
    }

    /// Builds the inputs for one body, relabelled so that its odd axis is `x` when `relabel`
    /// (see [`LaneFlow::relabels`]), else in its principal frame as it is.
    #[inline]
    pub(super) fn for_flow(
        rotation: Quat,
        omega: Vec3,
        mass: &MassProperties,
        relabel: bool,
    ) -> Self {
        let f = mass.principal_frame().widen();
        let (q, w) = (rotation.widen(), omega.widen());
        let (relabel, inertia) = relabelling(mass, relabel);
        Self {
            rotation: [q.x, q.y, q.z, q.w],
            omega: [w.x, w.y, w.z],
            frame: [f.x, f.y, f.z, f.w],
            relabel: relabel.map(Widen::widen),
            inertia: inertia.map(Widen::widen),
            impulse: [0.0; 3],
            spherical: if mass.is_spherical() { 1.0 } else { 0.0 },
        }
    }

    /// The same inputs after a kick of angular impulse `impulse` (world frame).
    #[inline]
    pub(super) fn with_impulse(self, impulse: Vec3) -> Self {
        let j = impulse.widen();
        Self {
            impulse: [j.x, j.y, j.z],
            ..self
        }
    }
}

/// The inputs of [`LANES`] bodies, component by component (`rotation[k][i]` is component `k` of
/// body `i`), in the engine precision: the kernel loads each component of all bodies with one
/// vector load and widens it with one vector conversion (every value is exact in `Real`, the
/// relabelling's `0, ±½, 1` included).
pub(super) type LaneInputs = LaneInput<[Real; LANES]>;

impl LaneInputs {
    /// Puts one body's inputs into lane `lane` (what [`LaneInput::new`] and
    /// [`with_impulse`](LaneInput::with_impulse) make of them).
    #[inline(always)]
    pub(super) fn set(
        &mut self,
        lane: usize,
        rotation: Quat,
        omega: Vec3,
        mass: &MassProperties,
        impulse: Vec3,
        relabel: bool,
    ) {
        let (relabel, inertia) = relabelling(mass, relabel);
        let frame = mass.principal_frame();
        for (k, (q, (f, p))) in [rotation.x, rotation.y, rotation.z, rotation.w]
            .into_iter()
            .zip(
                [frame.x, frame.y, frame.z, frame.w]
                    .into_iter()
                    .zip(relabel),
            )
            .enumerate()
        {
            self.rotation[k][lane] = q;
            self.frame[k][lane] = f;
            self.relabel[k][lane] = p;
        }
        for (k, ((w, i), j)) in [omega.x, omega.y, omega.z]
            .into_iter()
            .zip(inertia)
            .zip([impulse.x, impulse.y, impulse.z])
            .enumerate()
        {
            self.omega[k][lane] = w;
            self.inertia[k][lane] = i;
            self.impulse[k][lane] = j;
        }
        self.spherical[lane] = if mass.is_spherical() { 1.0 } else { 0.0 };
    }

    /// The inputs in lane `lane`.
    #[inline(always)]
    pub(super) fn get(&self, lane: usize) -> LaneInput {
        LaneInput {
            rotation: self.rotation.map(|c| c[lane].widen()),
            omega: self.omega.map(|c| c[lane].widen()),
            frame: self.frame.map(|c| c[lane].widen()),
            relabel: self.relabel.map(|c| c[lane].widen()),
            inertia: self.inertia.map(|c| c[lane].widen()),
            impulse: self.impulse.map(|c| c[lane].widen()),
            spherical: self.spherical[lane].widen(),
        }
    }

    /// Copies lane 0 into lanes `from..LANES` (the filler of a partial batch; lanes are
    /// independent, so any valid input will do).
    #[inline(always)]
    pub(super) fn fill_from_first(&mut self, from: usize) {
        let fill = |c: &mut [Real; LANES]| {
            let first = c[0];
            c[from..].fill(first);
        };
        self.rotation.iter_mut().for_each(fill);
        self.omega.iter_mut().for_each(fill);
        self.frame.iter_mut().for_each(fill);
        self.relabel.iter_mut().for_each(fill);
        self.inertia.iter_mut().for_each(fill);
        self.impulse.iter_mut().for_each(fill);
        fill(&mut self.spherical);
    }
}

impl LaneInputs {
    /// Bodies `start .. start + T::WIDTH` as lanes: each component with one vector load, widened
    /// exactly; the relabelling, the impulse and the spherical flag only where the kernel reads
    /// them (the others are zero).
    // Plain indexing, no closures: inside a `#[target_feature]` function every helper must
    // inline, and a closure is compiled without the feature.
    #[inline(always)]
    #[allow(clippy::needless_range_loop)]
    pub(super) fn load<T: Lane>(
        &self,
        cpu: T::Cpu,
        start: usize,
        relabel: bool,
        impulse: bool,
        spherical: bool,
    ) -> LaneInput<T> {
        let zero = T::splat(cpu, 0.0);
        let mut input = LaneInput::<T> {
            rotation: [zero; 4],
            omega: [zero; 3],
            frame: [zero; 4],
            relabel: [zero; 4],
            inertia: [zero; 3],
            impulse: [zero; 3],
            spherical: zero,
        };
        for k in 0..4 {
            input.rotation[k] = T::load_real(cpu, &self.rotation[k][start..]);
            input.frame[k] = T::load_real(cpu, &self.frame[k][start..]);
            if relabel {
                input.relabel[k] = T::load_real(cpu, &self.relabel[k][start..]);
            }
        }
        for k in 0..3 {
            input.omega[k] = T::load_real(cpu, &self.omega[k][start..]);
            input.inertia[k] = T::load_real(cpu, &self.inertia[k][start..]);
            if impulse {
                input.impulse[k] = T::load_real(cpu, &self.impulse[k][start..]);
            }
        }
        if spherical {
            input.spherical = T::load_real(cpu, &self.spherical[start..]);
        }
        input
    }
}

/// Rounds a kernel result to the engine's precision.
#[inline(always)]
pub(super) fn to_real(q: [f64; 4], w: [f64; 3]) -> (Quat, Vec3) {
    (
        Quat::from_xyzw(q[0].narrow(), q[1].narrow(), q[2].narrow(), q[3].narrow()),
        Vec3::new(w[0].narrow(), w[1].narrow(), w[2].narrow()),
    )
}

/// The results of a lane kernel, component by component (structure of arrays,
/// already rounded to the engine precision): the kernel stores each component of a run of
/// bodies with one vector store, and a reader that picks one body's scalars out of them is
/// served by store forwarding (four scalar stores read back as one vector stall instead).
#[derive(Debug, Clone, Copy)]
pub(super) struct RotatedLanes {
    /// New orientations: `rotation[k][i]` is component `k` (x, y, z, w) of body `i`.
    pub rotation: [[Real; LANES]; 4],
    /// New world angular velocities: `omega[k][i]` is component `k` of body `i`.
    pub omega: [[Real; LANES]; 3],
}

impl RotatedLanes {
    /// No results yet.
    #[inline(always)]
    pub(super) fn new() -> Self {
        Self {
            rotation: [[0.0; LANES]; 4],
            omega: [[0.0; LANES]; 3],
        }
    }

    /// Stores the results of bodies `start .. start + T::WIDTH`, rounded lane-wise to the
    /// engine precision exactly as [`to_real`] rounds one body.
    #[inline(always)]
    #[allow(clippy::needless_range_loop)]
    pub(super) fn store<T: Lane>(&mut self, start: usize, q: Quat4<T>, w: Vec3L<T>) {
        for k in 0..4 {
            q[k].store_real(&mut self.rotation[k][start..]);
        }
        for k in 0..3 {
            w[k].store_real(&mut self.omega[k][start..]);
        }
    }

    /// Body `i`'s new orientation and world angular velocity.
    #[inline(always)]
    pub(super) fn lane(&self, i: usize) -> (Quat, Vec3) {
        let [qx, qy, qz, qw] = &self.rotation;
        let [wx, wy, wz] = &self.omega;
        (
            Quat::from_xyzw(qx[i], qy[i], qz[i], qw[i]),
            Vec3::new(wx[i], wy[i], wz[i]),
        )
    }
}

/// What the lane kernels' tests share.
#[cfg(test)]
pub(super) mod fixtures {
    use super::LANES;
    use crate::math::{Quat, Real, Vec3, Widen};

    /// A span per lane: game steps, wide steps and fine steps side by side.
    pub(in crate::integrate) const SPANS: [Real; LANES] = [
        1.0 / 60.0,
        0.1,
        0.05,
        1.0 / 240.0,
        0.2,
        1.0 / 60.0,
        1.0 / 60.0,
        0.01,
    ];

    /// The bits of kernel results, in order.
    pub(in crate::integrate) fn bits(results: &[(Quat, Vec3)]) -> Vec<u64> {
        results
            .iter()
            .flat_map(|(q, w)| {
                q.to_array()
                    .into_iter()
                    .chain(w.to_array())
                    .map(|x| x.widen().to_bits())
            })
            .collect()
    }
}
