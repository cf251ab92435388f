//! The energy-conserving implicit step of a group of rigid bodies joined by springs.
//!
//! # The scheme
//!
//! Per body, with `h = Δt`, principal moments `I`, the orientation `Q` (principal frame → world),
//! the body-frame angular momentum `Π = I Ω`, and as unknowns the mean linear velocity `v̄` and the
//! mean body-frame angular velocity `Ω̄` of the step:
//!
//! ```text
//! x₁ = x₀ + h v̄                     v₁ = 2 v̄ − v₀
//! Q₁ = Q₀ cay(h Ω̄)                  Π₁ = 2 I Ω̄ − Π₀
//! m (v̄ − v₀)               = ½ h (F_ext + Σ F̄)
//! I Ω̄ − Π₀ + ½ h Ω̄ × I Ω̄   = ½ h (T_ext + Σ b × Q₀ᵀ F̄)
//! ```
//!
//! `cay(w)` is the Cayley rotation (angle `2 atan(|w|/2)` about `w`; quaternion `(w/2, 1)`
//! normalized), so `cay(hΩ̄) a − a = h Ω̄ × b` exactly with `b = (a + cay(hΩ̄) a)/2` for every body
//! point `a`. The spring force is Gonzalez's discrete gradient of `V = ½ k (ℓ − L₀)²`:
//!
//! ```text
//! F̄ = −k (ℓ̄ − L₀)/ℓ̄ · d̄,   d̄ = (d₀ + d₁)/2,   ℓ̄ = (ℓ₀ + ℓ₁)/2
//! ```
//!
//! on end `a` (and `−F̄` on end `b`). Its torque about the body's centre of mass, in the
//! principal frame, is
//!
//! ```text
//! T = (1 − [hΩ̄/2]×) (b × Q₀ᵀF̄)
//! ```
//!
//! with the mean arm `b`: the torque of `F̄` at the anchor's mean position, taken in the start
//! frame and turned by `1 − [hΩ̄/2]×`, the factor that makes the rotation's momentum change
//! exactly that torque's impulse in the world (below).
//!
//! **Why it conserves energy at any step.** The translational kinetic energy changes by
//! `m v̄·(v₁ − v₀) = h v̄·ΣF`; the rotational by `½(Π₀ + Π₁)·I⁻¹(Π₁ − Π₀) = Ω̄·(Π₁ − Π₀) = h Ω̄·T`
//! (the gyroscopic term is orthogonal to `Ω̄`). So the work on an anchor is
//! `h v̄·F̄ + h Ω̄·T = F̄·(h v̄ + Q₀(h Ω̄ × b)) = F̄·Δp` (`Ω̄·(Ω̄ × c) = 0`), the anchor's exact
//! displacement, and summed over both ends
//! `F̄·Δd = −k (ℓ̄ − L₀)/ℓ̄ · (ℓ₁² − ℓ₀²)/2 = −ΔV`. Kinetic plus elastic energy is therefore
//! conserved exactly, for any stiffness and step, up to the solver's tolerance; a constant force
//! through the centre of mass does exactly its work `h v̄·F`, and a constant world force at a
//! body point ([`GroupBody::load_moment`]), whose torque is taken like a spring end's (mean
//! arm, start frame, turned by `1 − [hΩ̄/2]×`), exactly its work `F·Δp` and the angular impulse
//! `h p̄ × F` (the point's torque is left out of the Newton matrix, which only slows
//! convergence where such loads rival the springs); a constant world torque `τ`, taken the same
//! way, gives exactly the angular impulse `h τ`.
//!
//! **Why it conserves momentum.** Linear momentum: the pair forces cancel. Angular momentum
//! `L = Σ x × m v + Q Π` (world): with `x̄ = x₀ + ½ h v̄` the translation adds `h x̄ × F` per body.
//! The rotation adds `Q₁Π₁ − Q₀Π₀ = Q₀ (cay(hΩ̄) Π₁ − Π₀) = h Q₀ (1 − [hΩ̄/2]×)⁻¹ T` (from the
//! momentum equation and `cay = (1 − [u]×)⁻¹(1 + [u]×)`, `u = hΩ̄/2`), which the factor in `T`
//! turns into `h (Q₀ b) × F̄`: the torque of `F̄` at the arm `Q₀ b = (Q₀a + Q₁a)/2`. So an end
//! adds `h (x̄ + Q₀ b) × F̄ = h p̄ × F̄`, `p̄ = (p₀ + p₁)/2` its anchor's mean position, and a spring
//! between two bodies `h (p̄_a − p̄_b) × F̄ = h d̄ × F̄ = 0`, since `F̄` is along `d̄`. A group free
//! of outside loads keeps `L` exactly, up to the solver's tolerance and the rounding of the
//! state. The scheme is symmetric (swapping the ends of the step and `h → −h` maps it to
//! itself: `T`'s world impulse `h (Q₀ b) × F̄` is symmetric in the ends), hence second order. On a linear spring it is the implicit midpoint rule:
//! unit amplification and the phase `2 atan(ωh/2)` per step, so a spring far too stiff for the
//! step oscillates slower than it should, bounded, with its energy kept.
//!
//! Torque-free, it is the implicit midpoint rule on Euler's equations with a Cayley attitude
//! update, which conserves `|Π|`, the kinetic energy and the world angular momentum `Q Π`.
//!
//! # The solve
//!
//! The unknowns `(v̄, Ω̄)` of all bodies of the group solve a nonlinear system by Newton's method
//! with its exact matrix: the mass and gyroscopic blocks, each spring's coupling `¼ Eᵀ K G` with
//! `K = k ((1 − L₀/ℓ̄) 1 + (L₀/ℓ̄²) d̄ d₁ᵀ/ℓ₁)` (the discrete-gradient force's derivative, not
//! symmetric and indefinite for a compressed spring), `G` the anchor's Jacobian and `Eᵀ` the
//! map of a force at the anchor to the body's force and torque, and the turning of the torques'
//! factor and arms with `Ω̄` (in closed form, `turning_torque_jacobian`).
//!
//! Each Newton system is solved directly (module `springs::sparse`: block elimination in
//! minimum-degree order, no fill on a chain or a tree); where a pivot is singular, by BiCGSTAB
//! with a block-Jacobi preconditioner instead of failing. A step that does not reduce the residual
//! is shortened (backtracking), and a trust region limits each update's change of rotation.
//! Iteration stops when the error left, estimated from the contraction of the last two updates,
//! is below [`ImplicitSpringSolver::tolerance`] in the kinetic-energy norm, relative to the
//! group's energy.

use glam::{DMat3, DQuat, DVec3};
use thiserror::Error;

use super::linear::{Block, Krylov, block_mul, invert};
use super::sparse::BlockLu;
use crate::mass::MassProperties;
use crate::math::{Narrow, Real, Vec3, Widen};
use crate::state::{BodyState, Wrench};

/// One body of a spring group as the implicit step sees it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GroupBody {
    /// The state (centre-of-mass position), replaced by the state at the end of the step.
    pub state: BodyState,
    /// Mass properties.
    pub mass: MassProperties,
    /// Force (through the centre of mass) and torque (world frame) held constant over the step:
    /// gravity, constant forces and whatever game code added.
    pub load: Wrench,
    /// Forces of `load.force` that act at body points rather than through the centre of mass,
    /// as their moment `P = Σ aᵢ Fᵢᵀ` (`aᵢ` the point's arm from the centre of mass in the body
    /// frame, `Fᵢ` the world force; in `f64`, zero for none). Their torque `Σ (R aᵢ) × Fᵢ` turns
    /// with the body, so the solve takes it like a spring end's (see the module docs): it does
    /// exactly the work `Fᵢ·Δpᵢ` and keeps the step symmetric. `load.torque` must not contain
    /// it.
    pub load_moment: DMat3,
}

/// The second end of a [`GroupSpring`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum LinkEnd {
    /// A point of another body of the group: its index and the anchor in body coordinates
    /// (relative to the body origin, as [`GroupSpring::anchor_a`]).
    Body {
        /// Index into the group's bodies.
        index: usize,
        /// Anchor in that body's coordinates.
        anchor: Vec3,
    },
    /// A point fixed in the world over the step (a world anchor, or a static or kinematic body).
    Fixed(Vec3),
}

/// An undamped linear spring of the group (damping is a separate flow, outside this step).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GroupSpring {
    /// Index of the first body.
    pub a: usize,
    /// Anchor on `a` in body coordinates (relative to the body origin, not the centre of mass).
    pub anchor_a: Vec3,
    /// The other end.
    pub b: LinkEnd,
    /// Stiffness `k` (N/m).
    pub stiffness: Real,
    /// Rest length `L₀` (m).
    pub rest_length: Real,
}

/// Why an implicit spring step failed (the bodies keep their states).
#[derive(Debug, Clone, Copy, PartialEq, Error)]
pub enum ImplicitSpringError {
    /// Newton's method did not reach the tolerance.
    #[error(
        "implicit spring step did not converge in {iterations} iterations (update {update:.3e} \
         of the energy scale, tolerance {tolerance:.1e})"
    )]
    NotConverged {
        /// Newton iterations taken.
        iterations: usize,
        /// Size of the last update relative to the energy scale.
        update: f64,
        /// The tolerance it had to reach.
        tolerance: f64,
    },
    /// A value became NaN or infinite.
    #[error("implicit spring step produced a non-finite value")]
    NonFinite,
    /// A spring names a body index outside the group.
    #[error("spring names body {index} of a group of {len}")]
    BadIndex {
        /// The index.
        index: usize,
        /// The group's size.
        len: usize,
    },
}

/// How a step went.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct SolveStats {
    /// Newton iterations.
    pub newton_iterations: usize,
    /// Linear solves, summed over the Newton iterations: one direct solve per Newton iteration,
    /// or the BiCGSTAB iterations of one where the direct factorization met a singular pivot.
    pub linear_iterations: usize,
    /// Times a step was split in two because Newton's method did not converge.
    pub splits: usize,
}

/// The default [`ImplicitSpringSolver::tolerance`]: a step's energy error is about twice it,
/// relative. Set below what storing the state costs anyway: rounding an `f32` state moves a
/// group's energy by ~1e-7 of it each step, an `f64` state by ~1e-16.
#[cfg(not(feature = "f64"))]
pub const DEFAULT_TOLERANCE: f64 = 1e-8;
/// The default [`ImplicitSpringSolver::tolerance`]: a step's energy error is about twice it,
/// relative. Set below what storing the state costs anyway: rounding an `f32` state moves a
/// group's energy by ~1e-7 of it each step, an `f64` state by ~1e-16.
#[cfg(feature = "f64")]
pub const DEFAULT_TOLERANCE: f64 = 1e-10;

/// How many times a step may be halved, recursively, before the implicit step gives up
/// (`2^MAX_SPLITS` pieces at most).
pub const MAX_SPLITS: u32 = 8;

/// A body's data for one step, in `f64`, principal frame.
#[derive(Debug, Clone, Copy, Default)]
struct Start {
    x: DVec3,
    v: DVec3,
    /// Principal frame → world at the start.
    q: DQuat,
    r: DMat3,
    /// Body-frame momentum `Π₀ = I Ω₀`.
    pi: DVec3,
    mass: f64,
    inertia: DVec3,
    /// 1 for a free axis, 0 for a locked (zero-moment) one.
    free: DVec3,
    force: DVec3,
    torque: DVec3,
    /// `P` of [`GroupBody::load_moment`] with the arms in the principal frame.
    moment: DMat3,
    /// Inertia scale of the locked-axis rows (keeps the block well conditioned).
    lock_scale: f64,
}

impl Start {
    /// The body-frame angular velocity `I⁻¹ Π` of a body momentum, 0 on a locked axis.
    fn angular_velocity(&self, pi: DVec3) -> DVec3 {
        self.free * pi / self.inertia.max(DVec3::splat(f64::MIN_POSITIVE))
    }
}

/// One spring end after the start geometry is known.
#[derive(Debug, Clone, Copy, Default)]
struct End {
    /// Body index, or `usize::MAX` for a fixed end.
    body: usize,
    /// Anchor relative to the centre of mass, principal frame.
    local: DVec3,
    /// A fixed end's world point.
    fixed: DVec3,
}

#[derive(Debug, Clone, Copy, Default)]
struct Link {
    ends: [End; 2],
    k: f64,
    rest: f64,
    d0: DVec3,
    l0: f64,
}

/// What the residual pass leaves for the Jacobian: per spring, the mean anchors and stiffness.
#[derive(Debug, Clone, Copy, Default)]
struct Linearized {
    /// Mean anchors `b = (a + cay(hΩ̄) a)/2` (principal frame at the start) of both ends: the
    /// anchors' displacement is `h v̄ + Q₀ (hΩ̄ × b)`, and `b` is the torques' lever arm (see
    /// `evaluate`).
    b: [DVec3; 2],
    /// `−2 ∂F̄/∂d₁ = k ((1 − L₀/ℓ̄) 1 + (L₀/ℓ̄²) d̄ n₁ᵀ)` (world frame).
    k: DMat3,
    /// The force on end `a`, `F̄`.
    force: DVec3,
}

/// The implicit spring step with its scratch memory (reused, so a step does not allocate once
/// the buffers have grown to the group's size).
#[derive(Debug, Clone)]
pub struct ImplicitSpringSolver {
    /// Relative tolerance of the Newton update in the kinetic-energy norm (default
    /// [`DEFAULT_TOLERANCE`]).
    pub tolerance: f64,
    /// Newton iterations of one solve before the step is split (default 20; see [`Self::step`]).
    pub max_newton: usize,
    starts: Vec<Start>,
    links: Vec<Link>,
    lin: Vec<Linearized>,
    z: Vec<f64>,
    trial: Vec<f64>,
    residual: Vec<f64>,
    trial_residual: Vec<f64>,
    delta: Vec<f64>,
    rhs: Vec<f64>,
    blocks: Vec<Block>,
    preconditioner: Vec<Block>,
    /// Per body, `cay(hΩ̄)` as a matrix.
    cayley: Vec<DMat3>,
    /// The spring ends on each body: body `i`'s are
    /// `ends_of[ends_start[i]..ends_start[i + 1]]`, as (spring, end).
    ends_of: Vec<(usize, usize)>,
    ends_start: Vec<usize>,
    /// Scratch of the counting sort.
    cursor: Vec<usize>,
    /// Per body, `F (1 − [hΩ̄/2]×)` (`F` masking locked axes): what turns the start-frame
    /// torque `b × Q₀ᵀf` into the one the step applies (see `evaluate`).
    unturn: Vec<DMat3>,
    /// Per body, `(1 − [hΩ̄/2]×)⁻¹`: the derivative of the Cayley rotation (see `evaluate`).
    cayley_derivative: Vec<DMat3>,
    krylov: Krylov,
    /// The direct factorization of the Newton matrix (the preconditioner when it exists).
    lu: BlockLu,
    /// True when `lu` holds a factorization of the current Newton matrix.
    factored: bool,
    /// True when `lu` holds the elimination order of the current group.
    analyzed: bool,
    /// The states at the start of the step, restored if it fails part-way.
    saved: Vec<BodyState>,
}

impl Default for ImplicitSpringSolver {
    fn default() -> Self {
        Self {
            tolerance: DEFAULT_TOLERANCE,
            max_newton: 20,
            starts: Vec::new(),
            links: Vec::new(),
            lin: Vec::new(),
            z: Vec::new(),
            trial: Vec::new(),
            residual: Vec::new(),
            trial_residual: Vec::new(),
            delta: Vec::new(),
            rhs: Vec::new(),
            blocks: Vec::new(),
            preconditioner: Vec::new(),
            cayley: Vec::new(),
            ends_of: Vec::new(),
            ends_start: Vec::new(),
            cursor: Vec::new(),
            unturn: Vec::new(),
            cayley_derivative: Vec::new(),
            krylov: Krylov::default(),
            lu: BlockLu::default(),
            factored: false,
            analyzed: false,
            saved: Vec::new(),
        }
    }
}

/// Largest `h|ω|` (rad) of any body at the start of a piece of a step: faster spins start split
/// (see [`ImplicitSpringSolver::step`]).
const PIECE_TURN: f64 = 3.0;

/// Relative size (kinetic-energy norm) of the previous Newton update above which an iteration
/// refactors the Newton matrix; below it, the iteration is a chord step with the last
/// factorization. A chord step converges linearly and stops at the tolerance, where Newton's
/// quadratic step overshoots it by orders: in `f32` that costs nothing (storing the state moves
/// the energy by ~1e-7 per step, ten times the tolerance), in `f64` it would be the largest
/// error of the step, so there every iteration refactors.
#[cfg(not(feature = "f64"))]
const REFACTOR_ABOVE: f64 = 0.3;
/// See the `f32` constant: in `f64` every iteration is a Newton step.
#[cfg(feature = "f64")]
const REFACTOR_ABOVE: f64 = 0.0;

/// A chord step that shrinks the update by less than this factor is followed by a refactor.
const CHORD_RATE: f64 = 0.25;

/// Largest change of `h|Ω̄|` (rad) of any body in one Newton iteration.
const MAX_TURN: f64 = 0.5;

/// A Newton iteration whose accepted step length is below this fraction of the full update…
const STAGNANT_STEP: f64 = 0.02;

/// …and that lowers the residual norm by less than this fraction counts as stagnating.
const STAGNANT_DECREASE: f64 = 0.01;

/// The Cayley rotation `cay(w)` as a unit quaternion: `(w/2, 1)` normalized.
#[inline]
fn cayley(w: DVec3) -> DQuat {
    let half = 0.5 * w;
    DQuat::from_xyzw(half.x, half.y, half.z, 1.0).normalize()
}

/// The start-frame torque (principal frame) of the forces a body feels at its points, from
/// their moment `P = Σ aᵢ Fᵢᵀ` (arms in the principal frame): `Σ (C aᵢ) × (Q₀ᵀ Fᵢ)` with the mean
/// arm `C a = (a + cay(hΩ̄) a)/2`, i.e. the axial vector of `X = C P Q₀`, `Tₖ = εₖₐᵦ Xₐᵦ`.
fn point_torque(s: &Start, cayley: &DMat3) -> DVec3 {
    if s.moment == DMat3::ZERO {
        return DVec3::ZERO;
    }
    let mean = 0.5 * (DMat3::IDENTITY + *cayley);
    crate::math::axial_vector(mean * s.moment * s.r)
}

fn v3(z: &[f64]) -> DVec3 {
    DVec3::new(z[0], z[1], z[2])
}

fn put(z: &mut [f64], v: DVec3) {
    z[0] = v.x;
    z[1] = v.y;
    z[2] = v.z;
}

fn add(z: &mut [f64], v: DVec3) {
    z[0] += v.x;
    z[1] += v.y;
    z[2] += v.z;
}

impl ImplicitSpringSolver {
    /// Advances `bodies` by one step `dt` under `springs` and their loads (see the module docs).
    /// On error the bodies keep their states.
    ///
    /// Where Newton's method does not converge from the start of the step (a step so large that
    /// the bodies turn by radians in it), the step is split in two halves, recursively, up to
    /// [`MAX_SPLITS`] times: each half is the same energy-conserving map, so the composition
    /// conserves energy too (and stays symmetric).
    pub fn step(
        &mut self,
        bodies: &mut [GroupBody],
        springs: &[GroupSpring],
        dt: Real,
    ) -> Result<SolveStats, ImplicitSpringError> {
        let h = dt.widen();
        let mut stats = SolveStats::default();
        // Start split where the bodies already spin too fast for one Cayley rotation per step
        // (saves the failed attempts at the coarser levels); deeper splits still follow where
        // the spin grows within the step. A function of the state only, so the result is too.
        let spin = bodies
            .iter()
            .map(|b| b.state.angular_velocity.widen().length())
            .fold(0.0, f64::max)
            * h;
        let mut depth = 0;
        while depth < MAX_SPLITS && spin > PIECE_TURN * f64::from(1u32 << depth) {
            depth += 1;
        }
        let pieces = 1u32 << depth;
        stats.splits += pieces as usize - 1;
        self.saved.clear();
        self.saved.extend(bodies.iter().map(|b| b.state));
        for _ in 0..pieces {
            if let Err(e) = self.advance(bodies, springs, h / f64::from(pieces), depth, &mut stats)
            {
                // Pieces already taken are undone: the bodies keep their states.
                for (body, state) in bodies.iter_mut().zip(&self.saved) {
                    body.state = *state;
                }
                return Err(e);
            }
        }
        Ok(stats)
    }

    fn advance(
        &mut self,
        bodies: &mut [GroupBody],
        springs: &[GroupSpring],
        h: f64,
        depth: u32,
        stats: &mut SolveStats,
    ) -> Result<(), ImplicitSpringError> {
        match self.solve(bodies, springs, h, stats) {
            Err(ImplicitSpringError::NotConverged { .. }) if depth < MAX_SPLITS => {
                stats.splits += 1;
                self.advance(bodies, springs, 0.5 * h, depth + 1, stats)?;
                self.advance(bodies, springs, 0.5 * h, depth + 1, stats)
            }
            other => other,
        }
    }

    /// One Newton solve of the whole step `h`.
    fn solve(
        &mut self,
        bodies: &mut [GroupBody],
        springs: &[GroupSpring],
        h: f64,
        stats: &mut SolveStats,
    ) -> Result<(), ImplicitSpringError> {
        self.prepare(bodies, springs)?;
        let n = bodies.len() * 6;
        self.z.clear();
        for s in &self.starts {
            let omega = s.angular_velocity(s.pi);
            self.z
                .extend_from_slice(&[s.v.x, s.v.y, s.v.z, omega.x, omega.y, omega.z]);
        }
        for buffer in [
            &mut self.residual,
            &mut self.trial_residual,
            &mut self.delta,
            &mut self.trial,
            &mut self.rhs,
        ] {
            buffer.clear();
            buffer.resize(n, 0.0);
        }
        let scale = self.energy_scale(h);
        let mut norm = self.evaluate(h);
        let mut update = f64::INFINITY;
        let mut iterations = 0;
        let (mut previous_full, mut previous_step) = (f64::INFINITY, 0.0);
        let mut previous_chord = None;
        // Whether this iteration takes a fresh Newton matrix (and its factorization): always
        // the first; afterwards only while the updates are large or the last chord step did not
        // contract well. In between, a chord step reuses the last factorization as the matrix:
        // near the solution the matrix barely changes from one iterate to the next, so the chord
        // step contracts the error by about that change, for one evaluation and one triangular
        // solve instead of an assembly and a factorization (five times the work).
        let mut refactor = true;
        while iterations < self.max_newton {
            iterations += 1;
            stats.newton_iterations += 1;
            if refactor {
                self.build_blocks(h);
                self.factor(h);
            }
            for (b, r) in self.rhs.iter_mut().zip(&self.residual) {
                *b = -r;
            }
            let rhs = std::mem::take(&mut self.rhs);
            let mut delta = std::mem::take(&mut self.delta);
            if self.factored {
                // A direct solve with the factorization: of the exact Newton matrix after a
                // refactor, of a recent one in a chord step.
                self.lu.solve(&rhs, &mut delta);
                stats.linear_iterations += 1;
            } else {
                // A singular pivot: BiCGSTAB on the exact Newton matrix (the body blocks
                // follow the iterate) with block Jacobi.
                if !refactor {
                    self.build_blocks(h);
                }
                let mut krylov = std::mem::take(&mut self.krylov);
                stats.linear_iterations += krylov.solve(
                    &rhs,
                    &mut delta,
                    1e-9,
                    400,
                    |u, out| self.apply_jacobian(h, u, out),
                    |u, out| self.apply_preconditioner(u, out),
                );
                self.krylov = krylov;
            }
            self.rhs = rhs;
            // Backtrack on the residual norm: a full Newton step can overshoot far from the
            // solution (large rotations make the spring geometry strongly nonlinear).
            // Trust region on the rotation: an update may change any body's Cayley angle
            // `2 atan(h|Ω̄|/2)` by at most `MAX_TURN` (radians), so Newton does not jump across
            // the region where the map from Ω̄ to the rotation is far from linear.
            let mut step: f64 = 1.0;
            for (d, z) in delta.chunks_exact(6).zip(self.z.chunks_exact(6)) {
                let w = h * v3(&z[3..]).length();
                let allowed = MAX_TURN * (1.0 + 0.25 * w * w);
                let change = h * v3(&d[3..]).length();
                if change > allowed {
                    step = step.min(allowed / change);
                }
            }
            let mut accepted = false;
            let mut stagnating = false;
            for _ in 0..12 {
                for ((t, z), d) in self.trial.iter_mut().zip(&self.z).zip(&delta) {
                    *t = z + step * d;
                }
                std::mem::swap(&mut self.z, &mut self.trial);
                std::mem::swap(&mut self.residual, &mut self.trial_residual);
                let trial_norm = self.evaluate(h);
                if trial_norm.is_finite() && trial_norm <= norm {
                    stagnating =
                        step < STAGNANT_STEP && trial_norm > (1.0 - STAGNANT_DECREASE) * norm;
                    norm = trial_norm;
                    accepted = true;
                    break;
                }
                std::mem::swap(&mut self.z, &mut self.trial);
                std::mem::swap(&mut self.residual, &mut self.trial_residual);
                step *= 0.5;
            }
            let full = (self.kinetic_norm(&delta) / scale).sqrt();
            self.delta = delta;
            let chord = !refactor && self.factored;
            if chord && (!accepted || stagnating) {
                // The stale matrix's step went nowhere: retake the iteration with a fresh one,
                // linearized at the iterate (the last evaluation was of a rejected trial).
                if !accepted {
                    norm = self.evaluate(h);
                }
                refactor = true;
                continue;
            }
            if !accepted {
                // No decrease at any step length: converged if the proposed update is already at
                // the tolerance (the residual is at round-off), failed otherwise.
                update = full;
                break;
            }
            update = step * full;
            if update <= self.tolerance {
                break;
            }
            // Near the solution Newton's method contracts at a falling rate, a chord iteration
            // at a steady one: with the rate θ = |δₖ|/|δₖ₋₁| of two full steps of the same kind,
            // the error left after δₖ is at most θ/(1 − θ)·|δₖ| (the tail of a geometric
            // series), so the step is done once that is within the tolerance; it saves the last
            // iteration, whose only use would be to show the update is small. (A chord step
            // after a Newton step is not measured by the Newton step's rate: it contracts by
            // how much the matrix has aged, which the first chord step does not show yet.)
            let rate = full / previous_full;
            let same_kind = previous_chord == Some(chord);
            previous_chord = Some(chord);
            refactor = !self.factored
                || full > REFACTOR_ABOVE
                || step < 1.0
                || (chord && rate > CHORD_RATE);
            if same_kind && step == 1.0 && previous_step == 1.0 && rate < 0.5 {
                let left = rate / (1.0 - rate) * update;
                if left <= self.tolerance {
                    update = left;
                    break;
                }
            }
            previous_full = full;
            previous_step = step;
            if stagnating {
                // Stuck on a tiny step in a valley of the residual that holds no solution
                // nearby: typically the bodies must turn by about π or more within the step,
                // which one Cayley rotation cannot. Give up now; the caller splits the step.
                break;
            }
        }
        if !update.is_finite() || self.z.iter().any(|v| !v.is_finite()) {
            return Err(ImplicitSpringError::NonFinite);
        }
        if update > self.tolerance {
            return Err(ImplicitSpringError::NotConverged {
                iterations,
                update,
                tolerance: self.tolerance,
            });
        }
        self.finish(h, bodies)
    }

    /// Reads the bodies and springs into the `f64` principal-frame working data.
    fn prepare(
        &mut self,
        bodies: &[GroupBody],
        springs: &[GroupSpring],
    ) -> Result<(), ImplicitSpringError> {
        self.analyzed = false;
        self.starts.clear();
        for body in bodies {
            let m = &body.mass;
            let q = (body.state.rotation.widen() * m.principal_frame().widen()).normalize();
            let inertia = m.principal_inertia().widen();
            let free = DVec3::select(inertia.cmpgt(DVec3::ZERO), DVec3::ONE, DVec3::ZERO);
            let omega = q.inverse() * body.state.angular_velocity.widen();
            self.starts.push(Start {
                x: body.state.position.widen(),
                v: body.state.linear_velocity.widen(),
                q,
                r: DMat3::from_quat(q),
                pi: free * inertia * omega,
                mass: m.mass().widen(),
                inertia,
                free,
                force: body.load.force.widen(),
                torque: body.load.torque.widen(),
                moment: DMat3::from_quat(m.principal_frame().widen().inverse()) * body.load_moment,
                lock_scale: inertia.max_element(),
            });
        }
        self.links.clear();
        let len = bodies.len();
        for spring in springs {
            let end_of = |index: usize, anchor: Vec3| -> Result<End, ImplicitSpringError> {
                let body = bodies
                    .get(index)
                    .ok_or(ImplicitSpringError::BadIndex { index, len })?;
                let m = &body.mass;
                let local = m.principal_frame().widen().inverse()
                    * (anchor - m.local_center_of_mass()).widen();
                Ok(End {
                    body: index,
                    local,
                    fixed: DVec3::ZERO,
                })
            };
            let a = end_of(spring.a, spring.anchor_a)?;
            let b = match spring.b {
                LinkEnd::Body { index, anchor } => end_of(index, anchor)?,
                LinkEnd::Fixed(p) => End {
                    body: usize::MAX,
                    local: DVec3::ZERO,
                    fixed: p.widen(),
                },
            };
            let mut link = Link {
                ends: [a, b],
                k: spring.stiffness.widen(),
                rest: spring.rest_length.widen(),
                ..Link::default()
            };
            link.d0 = self.anchor_start(&link.ends[0]) - self.anchor_start(&link.ends[1]);
            link.l0 = link.d0.length();
            self.links.push(link);
        }
        self.lin.clear();
        self.lin.resize(self.links.len(), Linearized::default());
        // Counting sort of the spring ends by body.
        self.ends_start.clear();
        self.ends_start.resize(len + 1, 0);
        for link in &self.links {
            for end in link.ends.iter().filter(|end| end.body < len) {
                self.ends_start[end.body + 1] += 1;
            }
        }
        for i in 0..len {
            self.ends_start[i + 1] += self.ends_start[i];
        }
        self.ends_of.clear();
        self.ends_of.resize(self.ends_start[len], (0, 0));
        self.cursor.clear();
        self.cursor.extend_from_slice(&self.ends_start);
        for (k, link) in self.links.iter().enumerate() {
            for (e, end) in link
                .ends
                .iter()
                .enumerate()
                .filter(|(_, end)| end.body < len)
            {
                self.ends_of[self.cursor[end.body]] = (k, e);
                self.cursor[end.body] += 1;
            }
        }
        Ok(())
    }

    fn anchor_start(&self, end: &End) -> DVec3 {
        match self.starts.get(end.body) {
            Some(s) => s.x + s.q * end.local,
            None => end.fixed,
        }
    }

    /// The group's energy scale (J): kinetic + elastic energy at the start plus the work the
    /// loads can do in a step, so the tolerance is relative to what the step moves.
    fn energy_scale(&self, h: f64) -> f64 {
        let kinetic: f64 = self
            .starts
            .iter()
            .map(|s| {
                let omega = s.angular_velocity(s.pi);
                0.5 * s.mass * s.v.length_squared() + 0.5 * s.pi.dot(omega)
            })
            .sum();
        let elastic: f64 = self
            .links
            .iter()
            .map(|l| 0.5 * l.k * (l.l0 - l.rest).powi(2))
            .sum();
        let loads: f64 = self
            .starts
            .iter()
            .map(|s| h * h * (s.force.length_squared() / s.mass))
            .sum();
        (kinetic + elastic + loads).max(f64::MIN_POSITIVE)
    }

    /// `Σ m |δv|² + δΩ·I δΩ`: twice the kinetic energy of an update (J).
    fn kinetic_norm(&self, delta: &[f64]) -> f64 {
        let sum: f64 = self
            .starts
            .iter()
            .zip(delta.chunks_exact(6))
            .map(|(s, d)| {
                let dv = v3(&d[..3]);
                let dw = v3(&d[3..]);
                s.mass * dv.length_squared() + dw.dot(s.inertia * dw)
            })
            .sum();
        sum
    }

    /// Computes the residual at `self.z` into `self.residual` (and the linearization for the
    /// Jacobian) and returns its norm, scaled per body by `1/√m`, `1/√I`.
    fn evaluate(&mut self, h: f64) -> f64 {
        self.cayley.clear();
        self.unturn.clear();
        self.cayley_derivative.clear();
        for (i, s) in self.starts.iter().enumerate() {
            let z = &self.z[6 * i..6 * i + 6];
            let vbar = v3(&z[..3]);
            let wbar = s.free * v3(&z[3..]);
            let cay = DMat3::from_quat(cayley(h * wbar));
            self.cayley.push(cay);
            // From (1 − [w/2]×) cay(w) a = (1 + [w/2]×) a: d(cay(w) a) = −(1 − [w/2]×)⁻¹ [b]× dw,
            // and (1 − [u]×)⁻¹ = 1 + ([u]× + [u]×²)/(1 + |u|²).
            let u = skew(0.5 * h * wbar);
            let uu = (0.5 * h * wbar).length_squared();
            self.cayley_derivative
                .push(DMat3::IDENTITY + (u + u * u) * (1.0 / (1.0 + uu)));
            self.unturn
                .push(DMat3::from_diagonal(s.free) * (DMat3::IDENTITY - u));
            let r = &mut self.residual[6 * i..6 * i + 6];
            put(&mut r[..3], s.mass * (vbar - s.v) - 0.5 * h * s.force);
            // External torque: the world torque and the forces at body points taken like spring
            // ends (start frame, mean arm), turned by `1 − [hΩ̄/2]×` (see the module docs).
            let torque = self.unturn[i] * (s.r.transpose() * s.torque + point_torque(s, &cay));
            let iw = s.inertia * wbar;
            let rot = iw - s.pi + 0.5 * h * wbar.cross(iw) - 0.5 * h * torque;
            // A locked axis has no equation of motion: its row pins Ω̄ to 0.
            let rot = DVec3::select(s.free.cmpgt(DVec3::ZERO), rot, s.lock_scale * v3(&z[3..]));
            put(&mut r[3..], rot);
        }
        for (link, lin) in self.links.iter().zip(self.lin.iter_mut()) {
            let mut p1 = [DVec3::ZERO; 2];
            for (e, end) in link.ends.iter().enumerate() {
                match self.starts.get(end.body) {
                    Some(s) => {
                        let z = &self.z[6 * end.body..6 * end.body + 6];
                        let rotated = self.cayley[end.body] * end.local;
                        lin.b[e] = 0.5 * (end.local + rotated);
                        p1[e] = s.x + h * v3(&z[..3]) + s.r * rotated;
                    }
                    None => p1[e] = end.fixed,
                }
            }
            let d1 = p1[0] - p1[1];
            let l1 = d1.length();
            let dbar = 0.5 * (link.d0 + d1);
            let lbar = 0.5 * (link.l0 + l1);
            let force = if lbar > 0.0 {
                let ratio = (lbar - link.rest) / lbar;
                lin.k = DMat3::from_diagonal(DVec3::splat(link.k * ratio));
                if l1 > 0.0 {
                    lin.k += (link.k * link.rest / (lbar * lbar * l1)) * outer(dbar, d1);
                }
                -link.k * ratio * dbar
            } else {
                lin.k = DMat3::from_diagonal(DVec3::splat(link.k));
                DVec3::ZERO
            };
            lin.force = force;
            for (e, end) in link.ends.iter().enumerate() {
                if let Some(s) = self.starts.get(end.body) {
                    let f = if e == 0 { force } else { -force };
                    let torque = self.unturn[end.body] * lin.b[e].cross(s.r.transpose() * f);
                    let r = &mut self.residual[6 * end.body..6 * end.body + 6];
                    add(&mut r[..3], -0.5 * h * f);
                    add(&mut r[3..], -0.5 * h * torque);
                }
            }
        }
        self.starts
            .iter()
            .zip(self.residual.chunks_exact(6))
            .map(|(s, r)| {
                let inv_i = DVec3::ONE / s.inertia.max(DVec3::splat(s.lock_scale));
                v3(&r[..3]).length_squared() / s.mass + v3(&r[3..]).dot(inv_i * v3(&r[3..]))
            })
            .sum::<f64>()
    }

    /// `∂T/∂Ω̄` of the total torque on body `i` (its springs' forces and its loads held at the
    /// current iterate's values): with `c = Σ b × Q₀ᵀf + Q₀ᵀτ + c_points` the start-frame torque
    /// and `T = F (1 − [hΩ̄/2]×) c`, `∂T/∂Ω̄ = F (½h [c]× + (1 − [hΩ̄/2]×) ∂c/∂Ω̄)`, where the
    /// mean arm turns with `Ω̄`, `∂b/∂Ω̄ = −½h D [b]×` (`D = (1 − [hΩ̄/2]×)⁻¹`, see `evaluate`), so
    /// `∂(b × f₀)/∂Ω̄ = ½h [f₀]× D [b]×`. The forces at body points enter `c` but not its
    /// derivative (see the module docs).
    fn turning_torque_jacobian(&self, h: f64, i: usize, w: DVec3) -> DMat3 {
        let s = &self.starts[i];
        let to_start = s.r.transpose();
        let mut c = to_start * s.torque + point_torque(s, &self.cayley[i]);
        let mut by_turn = DMat3::ZERO;
        for &(link, e) in &self.ends_of[self.ends_start[i]..self.ends_start[i + 1]] {
            let lin = &self.lin[link];
            let f0 = to_start * if e == 0 { lin.force } else { -lin.force };
            let b = lin.b[e];
            c += b.cross(f0);
            by_turn += skew(f0) * self.cayley_derivative[i] * skew(b);
        }
        let free = DMat3::from_diagonal(s.free);
        let unturn = DMat3::IDENTITY - skew(0.5 * h * w);
        free * (0.5 * h) * (skew(c) + unturn * by_turn)
    }

    /// The mass and gyroscopic 6×6 block of body `i` at the current iterate.
    fn body_block(&self, h: f64, i: usize) -> Block {
        let s = &self.starts[i];
        let w = s.free * v3(&self.z[6 * i + 3..6 * i + 6]);
        let mut block = [[0.0; 6]; 6];
        for (a, row) in block.iter_mut().take(3).enumerate() {
            row[a] = s.mass;
        }
        // ∂/∂Ω̄ of I Ω̄ + ½ h Ω̄ × I Ω̄ = I + ½ h ([Ω̄]× I − [I Ω̄]×).
        let inertia = DMat3::from_diagonal(s.inertia);
        let gyro = 0.5 * h * (skew(w) * inertia - skew(s.inertia * w));
        let m = inertia + gyro;
        for a in 0..3 {
            if s.free[a] > 0.0 {
                for c in 0..3 {
                    block[3 + a][3 + c] = m.col(c)[a];
                }
            } else {
                block[3 + a][3 + a] = s.lock_scale;
            }
        }
        block
    }

    /// `G u` for one spring end: the change of the anchor's end position `x₁ + Q₀ cay(hΩ̄) a`,
    /// `h δv − h Q₀ (1 − [hΩ̄/2]×)⁻¹ (b × δΩ)`.
    fn end_jacobian(&self, h: f64, body: usize, b: DVec3, du: &[f64]) -> DVec3 {
        let s = &self.starts[body];
        let turn = self.cayley_derivative[body] * (s.free * v3(&du[3..])).cross(b);
        h * v3(&du[..3]) + h * (s.r * turn)
    }

    /// `Eᵀ f`: the generalized force of a world force `f` at the end with mean arm `b`
    /// (force; principal torque `F (1 − [hΩ̄/2]×) (b × Q₀ᵀ f)`, see `evaluate`).
    fn end_transpose(&self, h: f64, body: usize, b: DVec3, f: DVec3) -> (DVec3, DVec3) {
        let s = &self.starts[body];
        (
            h * f,
            h * (self.unturn[body] * b.cross(s.r.transpose() * f)),
        )
    }

    /// `out = J u`: the Newton matrix (the body blocks of [`Self::build_blocks`] and the
    /// springs' `¼ GᵀKG`, applied spring by spring) times `u`.
    fn apply_jacobian(&self, h: f64, u: &[f64], out: &mut [f64]) {
        for (i, block) in self.blocks.iter().enumerate() {
            let y = block_mul(block, &u[6 * i..6 * i + 6]);
            out[6 * i..6 * i + 6].copy_from_slice(&y);
        }
        for (link, lin) in self.links.iter().zip(&self.lin) {
            let mut dd = DVec3::ZERO;
            for (e, end) in link.ends.iter().enumerate() {
                if end.body < self.starts.len() {
                    let du = &u[6 * end.body..6 * end.body + 6];
                    let g = self.end_jacobian(h, end.body, lin.b[e], du);
                    dd += if e == 0 { g } else { -g };
                }
            }
            let f = 0.25 * h * (lin.k * dd) / h;
            for (e, end) in link.ends.iter().enumerate() {
                if end.body < self.starts.len() {
                    let (lin_part, rot_part) =
                        self.end_transpose(h, end.body, lin.b[e], if e == 0 { f } else { -f });
                    let o = &mut out[6 * end.body..6 * end.body + 6];
                    add(&mut o[..3], lin_part);
                    add(&mut o[3..], rot_part);
                }
            }
        }
    }

    /// The body blocks of the Newton matrix at the current iterate: mass, inertia and
    /// gyroscopic terms, and the turning of the torques' frame and arms with `Ω̄`.
    fn build_blocks(&mut self, h: f64) {
        let mut blocks = std::mem::take(&mut self.blocks);
        blocks.clear();
        blocks.extend((0..self.starts.len()).map(|i| self.body_block(h, i)));
        // The torques turn with Ω̄ too (forces held): the factor 1 − [hΩ̄/2]× and the mean arms
        // (a + cay(hΩ̄) a)/2 depend on Ω̄, a body's own 3×3 block (not symmetric); see
        // `turning_torque_jacobian`.
        for (i, block) in blocks.iter_mut().enumerate() {
            let s = &self.starts[i];
            let w = s.free * v3(&self.z[6 * i + 3..6 * i + 6]);
            let turning = self.turning_torque_jacobian(h, i, w);
            for a in 0..3 {
                for c in 0..3 {
                    if s.free[a] > 0.0 && s.free[c] > 0.0 {
                        block[3 + a][3 + c] -= 0.5 * h * turning.col(c)[a];
                    }
                }
            }
        }
        self.blocks = blocks;
    }

    /// Factors the Newton matrix at the current iterate: the body blocks of
    /// [`Self::build_blocks`] plus the springs' part `¼ GᵀKG`, by [`BlockLu`]; where a pivot is
    /// singular, block Jacobi instead (each body's diagonal block inverted, or its mass and
    /// inertia where that block is singular too).
    fn factor(&mut self, h: f64) {
        let mut lu = std::mem::take(&mut self.lu);
        lu.reset(&self.blocks);
        self.assemble_springs(h, &mut lu);
        if !self.analyzed {
            // The pattern is the group's graph, the same for every Newton iteration of a solve.
            lu.analyze();
            self.analyzed = true;
        }
        self.factored = lu.factor().is_ok();
        self.lu = lu;
        if self.factored {
            return;
        }
        // Block Jacobi where the direct factorization failed (a singular pivot): each body's
        // diagonal block inverted, or its mass and inertia where that block is singular too.
        let mut diagonal = DiagonalBlocks {
            blocks: std::mem::take(&mut self.preconditioner),
            off_diagonal: [[0.0; 6]; 6],
        };
        diagonal.blocks.clear();
        diagonal.blocks.extend_from_slice(&self.blocks);
        self.assemble_springs(h, &mut diagonal);
        let mut preconditioner = diagonal.blocks;
        for (s, block) in self.starts.iter().zip(preconditioner.iter_mut()) {
            *block = invert(block).unwrap_or_else(|| {
                let mut d = [[0.0; 6]; 6];
                for (a, row) in d.iter_mut().enumerate() {
                    row[a] = 1.0 / if a < 3 { s.mass } else { s.lock_scale };
                }
                d
            });
        }
        self.preconditioner = preconditioner;
    }

    /// Adds the springs' part `¼ GᵀKG` of the Newton matrix into `blocks`: a body's own ends
    /// (and both ends of a spring with both on one body) on its diagonal block `(i, i)`, the
    /// coupling of the two ends of a spring between two bodies off it. Per spring the products
    /// `K G_f` and `E_e K` are formed once per end and shared by the blocks (see
    /// [`add_coupling`]).
    fn assemble_springs(&self, h: f64, blocks: &mut impl BlockSink) {
        let len = self.starts.len();
        for (link, lin) in self.links.iter().zip(&self.lin) {
            let k = 0.25 * lin.k;
            // Each end's factors, and `K G_turn`, `E_turn K`, as separate locals (not gathered
            // in a struct, which the compiler would copy around by `memcpy`).
            let [a, b] = [link.ends[0].body, link.ends[1].body];
            let (a_in, b_in) = (a < len, b < len);
            let factors = |on: bool, body: usize, e: usize| {
                if on {
                    self.end_factors(h, body, lin.b[e])
                } else {
                    EndFactors::default()
                }
            };
            let (fa, fb) = (factors(a_in, a, 0), factors(b_in, b, 1));
            let (k_turn_a, k_turn_b) = (k * fa.move_by_turn, k * fb.move_by_turn);
            let (torque_k_a, torque_k_b) = (fa.torque_of_force * k, fb.torque_of_force * k);
            let end_a = EndProducts {
                torque: &fa.torque_of_force,
                torque_k: &torque_k_a,
                k_turn: &k_turn_a,
            };
            let end_b = EndProducts {
                torque: &fb.torque_of_force,
                torque_k: &torque_k_b,
                k_turn: &k_turn_b,
            };
            if a_in {
                add_coupling(blocks.block(a, a), h, k, &end_a, &end_a, 1.0);
            }
            if b_in {
                add_coupling(blocks.block(b, b), h, k, &end_b, &end_b, 1.0);
            }
            if a_in && b_in {
                // (A spring with both ends on one body couples them on its diagonal block.)
                add_coupling(blocks.block(a, b), h, k, &end_a, &end_b, -1.0);
                add_coupling(blocks.block(b, a), h, k, &end_b, &end_a, -1.0);
            }
        }
    }

    /// The two 3×3 factors of a spring end's blocks of the Newton matrix (see [`add_coupling`]) on
    /// body `i`, with mean anchor `b` (see [`Linearized`]): `G_turn = −h R D [b]× F`, how the
    /// body's turn moves the anchor (see `end_jacobian`), and
    /// `E_turn = h F (1 − [hΩ̄/2]×) [b]× Rᵀ`, the torque of a world force at the anchor (see
    /// `end_transpose`); `F` masks locked axes, `R` is the start frame.
    fn end_factors(&self, h: f64, i: usize, b: DVec3) -> EndFactors {
        let s = &self.starts[i];
        let free = DMat3::from_diagonal(s.free);
        EndFactors {
            move_by_turn: -h * (s.r * self.cayley_derivative[i] * skew(b)) * free,
            torque_of_force: h * self.unturn[i] * skew(b) * s.r.transpose(),
        }
    }

    fn apply_preconditioner(&self, u: &[f64], out: &mut [f64]) {
        for (i, p) in self.preconditioner.iter().enumerate() {
            let y = block_mul(p, &u[6 * i..6 * i + 6]);
            out[6 * i..6 * i + 6].copy_from_slice(&y);
        }
    }

    /// Writes the end-of-step states from the converged `(v̄, Ω̄)`.
    fn finish(&self, h: f64, bodies: &mut [GroupBody]) -> Result<(), ImplicitSpringError> {
        let mut exact = Vec::with_capacity(bodies.len());
        let mut out = Vec::with_capacity(bodies.len());
        for (i, (s, body)) in self.starts.iter().zip(bodies.iter()).enumerate() {
            let z = &self.z[6 * i..6 * i + 6];
            let vbar = v3(&z[..3]);
            let wbar = s.free * v3(&z[3..]);
            let q1 = (s.q * cayley(h * wbar)).normalize();
            let pi1 = s.free * (2.0 * s.inertia * wbar - s.pi);
            let omega1 = s.angular_velocity(pi1);
            let end = Pose {
                x: s.x + h * vbar,
                q: q1,
                v: 2.0 * vbar - s.v,
                w: q1 * omega1,
            };
            let rotation = (q1 * body.mass.principal_frame().widen().inverse()).normalize();
            let state = BodyState {
                position: end.x.narrow(),
                rotation: crate::math::quat_normalize(rotation.narrow()),
                linear_velocity: end.v.narrow(),
                angular_velocity: end.w.narrow(),
            };
            if !state.is_valid() {
                return Err(ImplicitSpringError::NonFinite);
            }
            exact.push(end);
            out.push(state);
        }
        self.keep_energy_through_rounding(&exact, &mut out, bodies);
        for (body, state) in bodies.iter_mut().zip(out) {
            body.state = state;
        }
        Ok(())
    }

    /// Kinetic + elastic energy of the group (J) with body `i` at `poses[i]`.
    fn energy(&self, poses: &[Pose]) -> f64 {
        let kinetic = self.sum_over_bodies(poses, |s, p, w| {
            0.5 * s.mass * p.v.length_squared() + 0.5 * (s.inertia * w * w).element_sum()
        });
        let elastic: f64 = self
            .links
            .iter()
            .map(|l| {
                let stretch =
                    (anchor_at(poses, &l.ends[0]) - anchor_at(poses, &l.ends[1])).length() - l.rest;
                0.5 * l.k * stretch * stretch
            })
            .sum();
        kinetic + elastic
    }

    /// How far rounding the end state to the engine's precision `ε` can move the group's
    /// energy: `Σ_springs k |ℓ − L₀| ε (|p_a| + |p_b| + |a_a| + |a_b|)` for the anchors (a
    /// rounded position and rotation each move an anchor by about `ε` times its distance from
    /// the origin and its lever arm) plus `Σ_bodies ε (m|v|² + |ω| |Iω|)` for the velocities.
    fn rounding_bound(&self, exact: &[Pose]) -> f64 {
        let eps = Real::EPSILON.widen();
        let anchor = |end: &End| {
            let reach = match exact.get(end.body) {
                Some(p) => p.x.length() + end.local.length(),
                None => end.fixed.length(),
            };
            (anchor_at(exact, end), reach)
        };
        let springs: f64 = self
            .links
            .iter()
            .map(|l| {
                let ((pa, ra), (pb, rb)) = (anchor(&l.ends[0]), anchor(&l.ends[1]));
                l.k * ((pa - pb).length() - l.rest).abs() * eps * (ra + rb)
            })
            .sum();
        let bodies = self.sum_over_bodies(exact, |s, p, w| {
            eps * (s.mass * p.v.length_squared() + w.length() * (s.inertia * w).length())
        });
        springs + bodies
    }

    /// `Σ term(start, pose, ω_body)` over the bodies, `ω_body` the body-frame rate at `pose`.
    fn sum_over_bodies(&self, poses: &[Pose], term: impl Fn(&Start, &Pose, DVec3) -> f64) -> f64 {
        self.starts
            .iter()
            .zip(poses)
            .map(|(s, p)| term(s, p, p.body_rate(s)))
            .sum()
    }

    /// Storing the end state in the engine's precision moves the group's energy: a rounded
    /// anchor changes a stiff spring's energy by `k |stretch| ulp(x)`, a random walk of percents
    /// over thousands of steps for a stiff, barely stretched `f32` chain. The step conserves the
    /// energy of its exact (`f64`) end state, so the rounded state's velocities relative to the
    /// group's centre of mass are scaled by `s = √(1 + ΔE/T_rel)` to give it back (`T_rel` the
    /// kinetic energy relative to the centre of mass): linear momentum is kept, and only a
    /// correction rounding can explain (within four times [`Self::rounding_bound`]) is made.
    fn keep_energy_through_rounding(
        &self,
        exact: &[Pose],
        out: &mut [BodyState],
        bodies: &[GroupBody],
    ) {
        let rounded: Vec<Pose> = out
            .iter()
            .zip(bodies)
            .map(|(state, body)| Pose {
                x: state.position.widen(),
                q: (state.rotation.widen() * body.mass.principal_frame().widen()).normalize(),
                v: state.linear_velocity.widen(),
                w: state.angular_velocity.widen(),
            })
            .collect();
        let target = self.energy(exact);
        let missing = target - self.energy(&rounded);
        let mass: f64 = self.starts.iter().map(|s| s.mass).sum();
        let centre = self
            .starts
            .iter()
            .zip(&rounded)
            .map(|(s, p)| s.mass * p.v)
            .sum::<DVec3>()
            / mass;
        let relative: f64 = self
            .starts
            .iter()
            .zip(&rounded)
            .map(|(s, p)| {
                let w = p.body_rate(s);
                0.5 * s.mass * (p.v - centre).length_squared()
                    + 0.5 * (s.inertia * w * w).element_sum()
            })
            .sum();
        if !(relative > 0.0
            && missing.is_finite()
            && missing.abs() <= 4.0 * self.rounding_bound(exact)
            && relative + missing > 0.0)
        {
            return;
        }
        let s = (1.0 + missing / relative).sqrt();
        for (state, p) in out.iter_mut().zip(&rounded) {
            let corrected = BodyState {
                linear_velocity: (centre + s * (p.v - centre)).narrow(),
                angular_velocity: (s * p.w).narrow(),
                ..*state
            };
            if corrected.is_valid() {
                *state = corrected;
            }
        }
    }
}

/// A body's end-of-step pose and velocities in `f64`, principal frame (see `finish`).
#[derive(Debug, Clone, Copy)]
struct Pose {
    x: DVec3,
    q: DQuat,
    v: DVec3,
    /// World-frame angular velocity.
    w: DVec3,
}

impl Pose {
    /// The angular velocity in the principal frame, 0 on a locked axis of `s`'s body.
    fn body_rate(&self, s: &Start) -> DVec3 {
        s.free * (self.q.inverse() * self.w)
    }
}

/// The world point of a spring end with the bodies at `poses`.
fn anchor_at(poses: &[Pose], end: &End) -> DVec3 {
    match poses.get(end.body) {
        Some(p) => p.x + p.q * end.local,
        None => end.fixed,
    }
}

/// A spring end's factors of the Newton matrix, see `ImplicitSpringSolver::end_factors`.
#[derive(Debug, Clone, Copy, Default)]
struct EndFactors {
    move_by_turn: DMat3,
    torque_of_force: DMat3,
}

/// Adds the block `sign · Eₑᵀ K G_f` of the Newton matrix that spring end `e` receives from end
/// `f` to `block` (`K` = ¼ of the spring's stiffness matrix): `G_f = [h 1, G_turn,f]` maps the
/// update of end `f`'s body to its anchor's motion, `Eₑᵀ = [h 1; E_turn,e]` maps a world force at
/// end `e` to its body's generalized force. The 3×3 parts are `h² K`, `h K G_turn,f`,
/// `h E_turn,e K` and `E_turn,e (K G_turn,f)`; each end's `K G_turn` and `E_turn K` are formed
/// once and shared by the blocks of its spring.
fn add_coupling(block: &mut Block, h: f64, k: DMat3, e: &EndProducts, f: &EndProducts, sign: f64) {
    let parts = [
        [(sign * h * h) * k, (sign * h) * *f.k_turn],
        [(sign * h) * *e.torque_k, sign * (*e.torque * *f.k_turn)],
    ];
    for (r, row) in block.iter_mut().enumerate() {
        for (c, x) in row.iter_mut().enumerate() {
            *x += parts[r / 3][c / 3].col(c % 3)[r % 3];
        }
    }
}

/// Where the assembly of the Newton matrix adds its blocks.
trait BlockSink {
    /// The block of row body `i` and column body `j`.
    fn block(&mut self, i: usize, j: usize) -> &mut Block;
}

impl BlockSink for BlockLu {
    fn block(&mut self, i: usize, j: usize) -> &mut Block {
        if i == j {
            self.diagonal_mut(i)
        } else {
            self.entry(i, j)
        }
    }
}

/// The diagonal blocks alone (block Jacobi): the coupling blocks are dropped.
struct DiagonalBlocks {
    blocks: Vec<Block>,
    off_diagonal: Block,
}

impl BlockSink for DiagonalBlocks {
    fn block(&mut self, i: usize, j: usize) -> &mut Block {
        if i == j {
            &mut self.blocks[i]
        } else {
            &mut self.off_diagonal
        }
    }
}

/// A spring end's products for the assembly of the Newton matrix, by reference (see
/// `assemble_springs`).
struct EndProducts<'a> {
    /// `E_turn`.
    torque: &'a DMat3,
    /// `E_turn K`.
    torque_k: &'a DMat3,
    /// `K G_turn`.
    k_turn: &'a DMat3,
}

fn skew(v: DVec3) -> DMat3 {
    DMat3::from_cols(
        DVec3::new(0.0, v.z, -v.y),
        DVec3::new(-v.z, 0.0, v.x),
        DVec3::new(v.y, -v.x, 0.0),
    )
}

fn outer(a: DVec3, b: DVec3) -> DMat3 {
    DMat3::from_cols(a * b.x, a * b.y, a * b.z)
}

#[cfg(test)]
mod jacobian_tests {
    use super::*;
    use crate::mass::Mass;
    use crate::math::Quat;

    /// An asymmetric body (I = (0.02, 0.03, 0.04)) of mass `m` at `x`, turned by `q`, moving at
    /// (0.1, 0.2, −0.1) and turning at `w`, under `load`.
    fn test_body(m: Real, load: Wrench, x: Vec3, q: Quat, w: Vec3) -> GroupBody {
        GroupBody {
            state: BodyState {
                position: x,
                rotation: q,
                linear_velocity: Vec3::new(0.1, 0.2, -0.1),
                angular_velocity: w,
            },
            mass: MassProperties::new(Mass::new(m).unwrap(), Vec3::new(0.02, 0.03, 0.04)).unwrap(),
            load,
            load_moment: DMat3::ZERO,
        }
    }

    /// Three poses and angular velocities `(x, q, ω)` of the bodies of the Newton-matrix tests.
    fn test_poses() -> [(Vec3, Quat, Vec3); 3] {
        [
            (
                Vec3::ZERO,
                Quat::from_rotation_z(0.3),
                Vec3::new(1.0, 2.0, -1.0),
            ),
            (
                Vec3::new(0.9, 0.1, 0.0),
                Quat::from_rotation_x(0.5),
                Vec3::new(-2.0, 0.5, 3.0),
            ),
            (
                Vec3::new(0.4, 0.8, 0.1),
                Quat::from_rotation_y(-0.4),
                Vec3::new(0.3, 0.0, 1.0),
            ),
        ]
    }

    /// The Newton matrix against central differences of the residual, column by column.
    #[test]
    fn jacobian_matches_finite_differences() {
        let load = Wrench {
            force: Vec3::new(0.0, -9.8, 0.0),
            torque: Vec3::new(0.01, 0.0, 0.02),
        };
        let [first, second, _] = test_poses();
        let bodies = [first, second].map(|(x, q, w)| test_body(1.0, load, x, q, w));
        let springs = [
            GroupSpring {
                a: 0,
                anchor_a: Vec3::new(0.1, 0.05, 0.0),
                b: LinkEnd::Body {
                    index: 1,
                    anchor: Vec3::new(-0.1, 0.0, 0.05),
                },
                stiffness: 5000.0,
                rest_length: 0.6,
            },
            GroupSpring {
                a: 0,
                anchor_a: Vec3::new(-0.1, 0.0, 0.0),
                b: LinkEnd::Fixed(Vec3::new(-0.5, 0.0, 0.0)),
                stiffness: 3000.0,
                rest_length: 0.2,
            },
        ];
        let h = 1.0 / 60.0;
        let mut solver = ImplicitSpringSolver::default();
        solver.prepare(&bodies, &springs).unwrap();
        let n = 12;
        // A slow turn (h|Ω̄| ≈ 0.13) and a fast one (≈ 3.3: the half rotation far from linear).
        for spin in [1.0, 25.0] {
            solver.z = vec![
                0.2, -0.1, 0.3, 4.0, -3.0, 5.0, -0.3, 0.2, 0.1, -6.0, 2.0, 7.0,
            ];
            for body in solver.z.chunks_exact_mut(6) {
                for w in &mut body[3..] {
                    *w *= spin;
                }
            }
            solver.residual = vec![0.0; n];
            solver.evaluate(h);
            solver.build_blocks(h);
            solver.factor(h);
            let base = solver.z.clone();
            for j in 0..n {
                let mut unit = vec![0.0; n];
                unit[j] = 1.0;
                let mut analytic = vec![0.0; n];
                solver.apply_jacobian(h, &unit, &mut analytic);
                let eps = 1e-6;
                let mut plus = base.clone();
                plus[j] += eps;
                solver.z = plus;
                solver.evaluate(h);
                let r_plus = solver.residual.clone();
                let mut minus = base.clone();
                minus[j] -= eps;
                solver.z = minus;
                solver.evaluate(h);
                let r_minus = solver.residual.clone();
                solver.z = base.clone();
                solver.evaluate(h);
                solver.build_blocks(h);
                solver.factor(h);
                for i in 0..n {
                    let numeric = (r_plus[i] - r_minus[i]) / (2.0 * eps);
                    let scale = numeric.abs().max(analytic[i].abs()).max(1e-3);
                    assert!(
                        (numeric - analytic[i]).abs() <= 1e-5 * scale + 1e-8,
                        "spin ×{spin}: J[{i}][{j}]: numeric {numeric:e}, analytic {:e}",
                        analytic[i]
                    );
                }
            }
        }
    }

    /// The direct factorization inverts the Newton matrix that `apply_jacobian` applies, on a
    /// group with a self-spring, two springs between one pair, a world spring and a loop of
    /// three bodies (fill-in).
    #[test]
    fn the_factorization_inverts_the_newton_matrix() {
        let bodies = test_poses().map(|(x, q, w)| test_body(1.3, Wrench::default(), x, q, w));
        let spring = |a: usize, anchor_a: Vec3, b: LinkEnd, stiffness: Real| GroupSpring {
            a,
            anchor_a,
            b,
            stiffness,
            rest_length: 0.5,
        };
        let to = |index: usize, anchor: Vec3| LinkEnd::Body { index, anchor };
        let springs = [
            spring(
                0,
                Vec3::new(0.1, 0.05, 0.0),
                to(1, Vec3::new(-0.1, 0.0, 0.05)),
                5e5,
            ),
            spring(
                0,
                Vec3::new(0.0, -0.1, 0.0),
                to(1, Vec3::new(0.0, 0.1, 0.0)),
                2e5,
            ),
            spring(
                1,
                Vec3::new(0.1, 0.0, 0.0),
                to(2, Vec3::new(0.0, -0.1, 0.0)),
                3e5,
            ),
            spring(
                2,
                Vec3::new(-0.1, 0.0, 0.0),
                to(0, Vec3::new(0.0, 0.1, 0.0)),
                4e5,
            ),
            spring(
                1,
                Vec3::new(0.0, 0.0, 0.1),
                to(1, Vec3::new(0.0, 0.0, -0.1)),
                1e5,
            ),
            spring(2, Vec3::ZERO, LinkEnd::Fixed(Vec3::new(0.0, 2.0, 0.0)), 1e5),
        ];
        let h = 1.0 / 60.0;
        let mut solver = ImplicitSpringSolver::default();
        solver.prepare(&bodies, &springs).unwrap();
        let n = 18;
        solver.z = (0..n).map(|k| (k as f64 * 0.7).sin() * 3.0).collect();
        solver.residual = vec![0.0; n];
        solver.evaluate(h);
        solver.build_blocks(h);
        solver.factor(h);
        assert!(solver.factored, "the test matrix is regular");
        for j in 0..n {
            let mut unit = vec![0.0; n];
            unit[j] = 1.0;
            let mut x = vec![0.0; n];
            solver.lu.solve(&unit, &mut x);
            let mut back = vec![0.0; n];
            solver.apply_jacobian(h, &x, &mut back);
            for (i, (b, u)) in back.iter().zip(&unit).enumerate() {
                assert!((b - u).abs() < 1e-9, "(J LU⁻¹)[{i}][{j}] = {b:e}");
            }
        }
    }
}
