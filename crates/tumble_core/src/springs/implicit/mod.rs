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
//! of outside loads keeps `L` exactly, up to the solver's tolerance and rounding; where the
//! momenta the step must end with are known without the solve (no spring tied to a fixed point,
//! no force at a body point, no locked axis, which takes up the torques along it), the end
//! state is given them exactly by one rigid change of the group's velocities, so that only the
//! rounding of the stored state is left. The scheme is symmetric (swapping the ends of the step and `h → −h` maps it to
//! itself: `T`'s world impulse `h (Q₀ b) × F̄` is symmetric in the ends), hence second order. On a linear spring it is the implicit midpoint rule:
//! unit amplification and the phase `2 atan(ωh/2)` per step, so a spring far too stiff for the
//! step oscillates slower than it should, bounded, with its energy kept.
//!
//! Torque-free, it is the implicit midpoint rule on Euler's equations with a Cayley attitude
//! update, which conserves `|Π|`, the kinetic energy and the world angular momentum `Q Π`.
//!
//! # A method's turn
//!
//! [`GroupRotation::Method`] turns a body by a drift–kick–drift method's torque-free flow
//! instead of the Cayley rotation (see [`crate::integrate`]): with `Π̄ = I Ω̄` the step's mean
//! body momentum in the start frame (so `L̄ = Q₀ Π̄` is its mean world momentum),
//!
//! ```text
//! Q₁ = Q₀ C,   C = the method's free flow over h from body momentum Π̄ (Q₁ = Q₀ C)
//! I Ω̄ − Π₀ = ½ h (T_ext + Σ b × Q₀ᵀF̄),   b = (a + C a)/2,   Π₁ = Cᵀ (2 I Ω̄ − Π₀)
//! ```
//!
//! with no gyroscopic term and no turning factor: the flow keeps `L` by itself. The world
//! momentum changes by `Q₀(2IΩ̄ − 2Π₀) = h Σ (Q₀ b) × F̄`, the torque of `F̄` at the arm
//! `(Q₀a + Q₁a)/2`, so with the translation's `h x̄ × F̄` each end adds `h p̄ × F̄` again and a
//! spring's two ends cancel: linear and angular momentum are kept exactly, as under the
//! midpoint. Torque-free, `Π̄ = Π₀` and the step is the method's own free flow. The energy is
//! not kept exactly: only the Cayley rotation makes the anchors' displacement `h Ω̄ × b` of the
//! rate whose kinetic energy changes (`cay(w) a − a = w × b`); a flow turns them by its own
//! map, and the balance closes to the method's accuracy (second order, measured). Where springs
//! turn a body stiffly that error is that of an explicit rotation under stiff torques, and
//! unstable: the caller gives such bodies [`GroupRotation::Midpoint`] (the ECS layer does, by
//! [`turning_compliance`](super::turning_compliance)). The Newton matrix keeps the Cayley
//! rotation's derivative for the turn, an approximation: the iteration converges linearly
//! there, and a group with a method's turn converges a hundred times past the tolerance, so
//! that the momenta stay at round-off.
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
use crate::integrate::{Integrator, free_turn};
use crate::mass::MassProperties;
use crate::math::{Narrow, Real, Vec3, Widen};
use crate::state::{BodyState, Wrench};

mod finish;
mod jacobian;
mod newton;

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
    /// How the step turns the body: the energy-exact Cayley midpoint, or a method's free
    /// rotation at the step's mean momentum (see the module docs).
    pub rotation: GroupRotation,
}

/// How the implicit step turns a body of the group (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum GroupRotation {
    /// The Cayley rotation by the mean body rate, with Euler's equations at the midpoint:
    /// kinetic plus elastic energy conserved exactly at any step.
    #[default]
    Midpoint,
    /// The torque-free rotation of a drift–kick–drift method (see
    /// [`Integrator::turns_at_constant_momentum`]) at the step's mean world momentum `L̄`:
    /// torque-free, exactly that method's step; momenta conserved exactly, energy to the
    /// method's accuracy.
    Method(Integrator),
}

impl GroupRotation {
    /// The rotation of `integrator` in a stiff group: [`GroupRotation::Method`], or
    /// [`ImplicitSpringError::CannotCombine`] for a method without a free rotation at constant
    /// momentum (the first-order methods).
    pub fn of(integrator: Integrator) -> Result<Self, ImplicitSpringError> {
        if integrator.turns_at_constant_momentum() {
            Ok(GroupRotation::Method(integrator))
        } else {
            Err(ImplicitSpringError::CannotCombine { integrator })
        }
    }
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
    /// The body's method cannot run inside the implicit step: a first-order method updates
    /// `ω` with its own gyroscopic term, not by a free rotation at constant momentum (see
    /// [`GroupRotation::of`]).
    #[error(
        "`{integrator}` cannot step a stiff spring group (its gyroscopic update is not a free \
         rotation at constant momentum): choose `splitting`, `splitting-xyz`, `yoshida4`, `rk4`, \
         `exact` or `exact4`, or springs = `explicit` with a time step small enough for them"
    )]
    CannotCombine {
        /// The method.
        integrator: Integrator,
    },
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
    /// Evaluations of the step's residual: one at the first iterate and one per trial iterate
    /// (an update taken whole when it is already within the tolerance needs none).
    pub residual_evaluations: usize,
    /// Newton matrices assembled and factorized (a chord iteration reuses the last one).
    pub factorizations: usize,
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
    /// The method whose free rotation turns the body, `None` for the Cayley midpoint.
    method: Option<Integrator>,
    /// `splitting`'s odd axis of the body (see [`free_turn`]).
    odd: usize,
}

impl Start {
    /// The body-frame angular velocity `I⁻¹ Π` of a body momentum, 0 on a locked axis.
    fn angular_velocity(&self, pi: DVec3) -> DVec3 {
        self.free * pi / self.inertia.max(DVec3::splat(f64::MIN_POSITIVE))
    }

    /// The turn `Q₀ᵀQ₁` of the step at the mean body rate `Ω̄` (masked): `cay(hΩ̄)`, or the
    /// method's free rotation over `h` from the mean body momentum `I Ω̄`.
    fn turn(&self, h: f64, wbar: DVec3) -> DQuat {
        match self.method {
            None => cayley(h * wbar),
            Some(method) => {
                let r = self.angular_velocity(DVec3::ONE);
                free_turn(method, self.inertia * wbar, r, self.odd, h)
                    .unwrap_or_else(|| cayley(h * wbar))
            }
        }
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
    /// `−2 ∂F̄/∂d₁ = k ((1 − L₀/ℓ̄) 1 + (L₀/ℓ̄²) d̄ n₁ᵀ)` (world frame), once
    /// [`ImplicitSpringSolver::linearize`] has run.
    k: DMat3,
    /// The mean separation `d̄ = (d₀ + d₁)/2` of the anchors (world frame).
    dbar: DVec3,
    /// The separation `d₁` at the end of the step.
    d1: DVec3,
    /// `ℓ̄ = (|d₀| + |d₁|)/2`.
    lbar: f64,
    /// `|d₁|`.
    l1: f64,
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
    /// Per body, `(1 − [hΩ̄/2]×)⁻¹`: the derivative of the Cayley rotation (see `linearize`).
    cayley_derivative: Vec<DMat3>,
    /// True when `cayley_derivative` and the springs' `k` are those of the last evaluation.
    linearized: bool,
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
            linearized: false,
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

/// The fraction of [`ImplicitSpringSolver::tolerance`] a group with a method's turn converges
/// to (see `solve`).
const METHOD_TURN_TOLERANCE: f64 = 1e-2;

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
}
