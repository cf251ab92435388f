//! The end of a step: the new states, and the rounding of the state kept from moving the energy.

use glam::{DMat3, DQuat, DVec3};

use super::*;

impl ImplicitSpringSolver {
    /// Writes the end-of-step states from the converged `(v̄, Ω̄)`.
    pub(super) fn finish(
        &self,
        h: f64,
        bodies: &mut [GroupBody],
    ) -> Result<(), ImplicitSpringError> {
        let mut exact: Vec<Pose> = self
            .starts
            .iter()
            .enumerate()
            .map(|(i, s)| {
                let z = &self.z[6 * i..6 * i + 6];
                let vbar = v3(&z[..3]);
                let wbar = s.free * v3(&z[3..]);
                let turn = s.turn(h, wbar);
                let q1 = (s.q * turn).normalize();
                let pi1 = s.free * (2.0 * s.inertia * wbar - s.pi);
                // A method's turn keeps the world momentum: the end's body momentum is the
                // world's `L₁ = Q₀ (2 I Ω̄ − Π₀)` in the turned frame.
                let pi1 = if s.method.is_some() {
                    turn.inverse() * pi1
                } else {
                    pi1
                };
                Pose {
                    x: s.x + h * vbar,
                    q: q1,
                    v: 2.0 * vbar - s.v,
                    w: q1 * s.angular_velocity(pi1),
                }
            })
            .collect();
        self.restore_momenta(h, &mut exact);
        let mut out = Vec::with_capacity(bodies.len());
        for (end, body) in exact.iter().zip(bodies.iter()) {
            let rotation = (end.q * body.mass.principal_frame().widen().inverse()).normalize();
            let state = BodyState {
                position: end.x.narrow(),
                rotation: crate::math::quat_normalize(rotation.narrow()),
                linear_velocity: end.v.narrow(),
                angular_velocity: end.w.narrow(),
            };
            if !state.is_valid() {
                return Err(ImplicitSpringError::NonFinite);
            }
            out.push(state);
        }
        self.keep_energy_through_rounding(&exact, &mut out, bodies);
        for (body, state) in bodies.iter_mut().zip(out) {
            body.state = state;
        }
        Ok(())
    }

    /// Whether no spring of the group is tied to a fixed point: then only the bodies' loads
    /// change its momenta.
    fn ends_are_free(&self) -> bool {
        self.links
            .iter()
            .all(|l| l.ends.iter().all(|end| end.body < self.starts.len()))
    }

    /// Gives the end state exactly the momenta the scheme gives it, where they are known
    /// without the solve: for a group with no spring tied to a fixed point, no force at a body
    /// point and no locked axis, `P₁ = P₀ + h Σ F` and `L₁ = L₀ + h Σ (x̄ × F + τ)` (`x̄` a
    /// body's mean position), the momenta of an isolated group kept. (A locked axis takes up
    /// the torques along it, as a fixed point takes up forces: such a group's `L` is not the
    /// loads' alone, and is left as the solve gives it.) The scheme keeps them in exact
    /// arithmetic, but the solve stops at a tolerance and rounds terms as large as the
    /// springs' impulses, which at `ωΔt ≫ 1` are many times the momenta they change: that
    /// leaves a systematic defect of ~1e-15 of the momenta a step in `f64` at `ωΔt` 100
    /// (1e-11 after 10⁴ steps). A rigid change of the whole group's velocities (see
    /// [`RigidMotion`]) removes it: `δV = ΔP/M` and `δΩ = J⁻¹(ΔL − M X × δV)` change `P` by
    /// `M δV` and `L` by `M X × δV + J δΩ` (`X` the centre of mass, `J` the group's inertia
    /// about it), and nothing else.
    fn restore_momenta(&self, h: f64, exact: &mut [Pose]) {
        let held = |s: &Start| s.moment != DMat3::ZERO || s.free != DVec3::ONE;
        if !self.ends_are_free() || self.starts.iter().any(held) {
            return;
        }
        let pairs = self.starts.iter().zip(exact.iter());
        let Some((mass, centre)) = mass_and_centre(pairs.clone()) else {
            return;
        };
        let Some(inverse) = inverse_inertia_about(pairs, centre) else {
            return;
        };
        // Angular momenta about the start's centre of mass `X₀`, a fixed point: about the world
        // origin, a group far from it would sum terms `|X|/size` times larger, and their
        // rounding would be put into the bodies as a spin.
        let origin = self.starts.iter().map(|s| s.mass * s.x).sum::<DVec3>() / mass;
        let (mut p_gap, mut l_gap) = (DVec3::ZERO, DVec3::ZERO);
        for (s, p) in self.starts.iter().zip(exact.iter()) {
            let mean = 0.5 * (s.x + p.x) - origin;
            p_gap += s.mass * s.v + h * s.force - s.mass * p.v;
            l_gap += (s.x - origin).cross(s.mass * s.v)
                + s.q * s.pi
                + h * (mean.cross(s.force) + s.torque)
                - (p.x - origin).cross(s.mass * p.v)
                - p.q * (s.inertia * p.body_rate(s));
        }
        let dv = p_gap / mass;
        let dw = inverse * (l_gap - (centre - origin).cross(mass * dv));
        for (s, p) in self.starts.iter().zip(exact.iter_mut()) {
            p.v += dv + dw.cross(p.x - centre);
            // Only the free axes turn faster: a locked axis has no inertia, so the momentum
            // `Q I Qᵀ δΩ` is the same.
            p.w += p.q * (s.free * (p.q.inverse() * dw));
        }
    }

    /// Kinetic + elastic energy of the group (J) with body `i` at `poses[i]`.
    pub(super) fn energy(&self, poses: &[Pose]) -> f64 {
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
    pub(super) fn rounding_bound(&self, exact: &[Pose]) -> f64 {
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
    pub(super) fn sum_over_bodies(
        &self,
        poses: &[Pose],
        term: impl Fn(&Start, &Pose, DVec3) -> f64,
    ) -> f64 {
        self.starts
            .iter()
            .zip(poses)
            .map(|(s, p)| term(s, p, p.body_rate(s)))
            .sum()
    }

    /// Storing the end state in the engine's precision moves the group's energy: a rounded
    /// anchor changes a stiff spring's energy by `k |stretch| ulp(x)`, a random walk of percents
    /// over thousands of steps for a stiff, barely stretched `f32` chain. The step conserves the
    /// energy of its exact (`f64`) end state, so the rounded state gives it back by scaling the
    /// group's internal motion, `v ← v_rigid + s (v − v_rigid)`, `ω ← ω_rigid + s (ω − ω_rigid)`,
    /// `s = √(1 + ΔE/T_int)`, with `T_int` the kinetic energy of that motion. The rigid motion
    /// is that of the group as one body (see [`RigidMotion`]): the internal motion carries no
    /// linear momentum, and for a group no spring ties to a fixed point no angular momentum
    /// either, so the correction keeps both (where a fixed point holds the group, the rigid
    /// motion is its centre's translation alone: a single body's spin would be all of it). Only
    /// a correction rounding can explain (within four times [`Self::rounding_bound`]) is made.
    /// Bodies turned
    /// by a method's free flow are left out (the rigid motion and `T_int` are those of the
    /// others): a method's turn keeps the energy to the method's accuracy, not exactly, and
    /// scaling its spin would shift its phase.
    pub(super) fn keep_energy_through_rounding(
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
        let scaled = self
            .starts
            .iter()
            .zip(&rounded)
            .filter(|(s, _)| s.method.is_none());
        let Some(rigid) = RigidMotion::of(scaled.clone(), self.ends_are_free()) else {
            return;
        };
        let internal: f64 = scaled
            .map(|(s, p)| {
                let (u, eta) = rigid.internal(p);
                let eta = s.free * (p.q.inverse() * eta);
                0.5 * s.mass * u.length_squared() + 0.5 * (s.inertia * eta * eta).element_sum()
            })
            .sum();
        if !(internal > 0.0
            && missing.is_finite()
            && missing.abs() <= 4.0 * self.rounding_bound(exact)
            && internal + missing > 0.0)
        {
            return;
        }
        let scale = (1.0 + missing / internal).sqrt();
        for ((state, p), start) in out
            .iter_mut()
            .zip(&rounded)
            .zip(&self.starts)
            .filter(|(_, start)| start.method.is_none())
        {
            let (u, eta) = rigid.internal(p);
            let mut omega = rigid.spin + scale * eta;
            if start.free != DVec3::ONE {
                // A locked axis does not turn (its rate stays 0), whatever the group's spin does
                // along it; it has no inertia, so neither momentum nor energy changes.
                omega = p.q * (start.free * (p.q.inverse() * omega));
            }
            let corrected = BodyState {
                linear_velocity: (rigid.velocity_at(p.x) + scale * u).narrow(),
                angular_velocity: omega.narrow(),
                ..*state
            };
            if corrected.is_valid() {
                *state = corrected;
            }
        }
    }
}

/// The motion of a set of bodies as one rigid body: the centre of mass `X` moving at `V` and,
/// when its angular momentum is to be kept, the rate `Ω = J⁻¹ L` of the set's angular momentum
/// `L` about `X` under its inertia `J = Σ m (|r|² 1 − r rᵀ) + Q I Qᵀ` (`r = x − X`). A body's
/// internal motion is what is left: `u = v − V − Ω × r`, `η = ω − Ω`. Then `Σ m u = 0` and
/// `Σ (r × m u + Q I Qᵀ η) = L − J Ω = 0`, and the kinetic energy is the rigid motion's plus the
/// internal motion's (the cross terms are `V·Σ m u + Ω·(L − J Ω) = 0`), so scaling the internal
/// motion changes the energy and neither momentum. A locked axis (zero moment) carries neither
/// energy nor momentum, whatever `η` holds there.
#[derive(Debug, Clone, Copy)]
struct RigidMotion {
    centre: DVec3,
    velocity: DVec3,
    spin: DVec3,
}

impl RigidMotion {
    /// The rigid motion of `bodies` (`None` without mass); with `keep_spin` false, or where `J`
    /// cannot be inverted, a translation only (`Ω = 0`: the internal motion then carries the
    /// set's angular momentum about `X`).
    fn of<'a>(bodies: impl Bodies<'a>, keep_spin: bool) -> Option<Self> {
        let (mass, centre) = mass_and_centre(bodies.clone())?;
        let velocity = bodies.clone().map(|(s, p)| s.mass * p.v).sum::<DVec3>() / mass;
        let mut motion = Self {
            centre,
            velocity,
            spin: DVec3::ZERO,
        };
        if keep_spin && let Some(inverse) = inverse_inertia_about(bodies.clone(), centre) {
            let momentum: DVec3 = bodies
                .map(|(s, p)| {
                    (p.x - centre).cross(s.mass * (p.v - velocity)) + own_inertia(s, p) * p.w
                })
                .sum();
            motion.spin = inverse * momentum;
        }
        Some(motion)
    }

    /// The rigid motion's velocity at the world point `x`: `V + Ω × (x − X)`.
    fn velocity_at(&self, x: DVec3) -> DVec3 {
        self.velocity + self.spin.cross(x - self.centre)
    }

    /// A body's internal motion `(u, η)` (world frame).
    fn internal(&self, p: &Pose) -> (DVec3, DVec3) {
        (p.v - self.velocity_at(p.x), p.w - self.spin)
    }
}

/// A set of bodies, each its start and its end pose, walked once per sum (an iterator, not a
/// collected list: the step runs these sums for every group, and a list would be allocated
/// each time).
trait Bodies<'a>: Iterator<Item = (&'a Start, &'a Pose)> + Clone {}

impl<'a, I: Iterator<Item = (&'a Start, &'a Pose)> + Clone> Bodies<'a> for I {}

/// The total mass and the centre of mass of `bodies`; `None` without mass.
fn mass_and_centre<'a>(bodies: impl Bodies<'a>) -> Option<(f64, DVec3)> {
    let mass: f64 = bodies.clone().map(|(s, _)| s.mass).sum();
    (mass > 0.0).then(|| {
        let centre = bodies.map(|(s, p)| s.mass * p.x).sum::<DVec3>() / mass;
        (mass, centre)
    })
}

/// A body's inertia in the world frame, `Q I Qᵀ`.
fn own_inertia(s: &Start, p: &Pose) -> DMat3 {
    let frame = DMat3::from_quat(p.q);
    frame * DMat3::from_diagonal(s.inertia) * frame.transpose()
}

/// The inverse of the inertia of `bodies` about `centre` as one rigid body,
/// `J = Σ m (|r|² 1 − r rᵀ) + Q I Qᵀ` (`r = x − centre`); `None` where `J` is singular to
/// round-off (point masses on one line).
fn inverse_inertia_about<'a>(bodies: impl Bodies<'a>, centre: DVec3) -> Option<DMat3> {
    let inertia: DMat3 = bodies
        .map(|(s, p)| {
            let r = p.x - centre;
            s.mass
                * (DMat3::from_diagonal(DVec3::splat(r.length_squared()))
                    - DMat3::from_cols(r * r.x, r * r.y, r * r.z))
                + own_inertia(s, p)
        })
        .fold(DMat3::ZERO, |sum, j| sum + j);
    let det = inertia.determinant();
    let size = inertia.x_axis.x + inertia.y_axis.y + inertia.z_axis.z;
    (det.is_finite() && det > 1e-12 * size * size * size).then(|| inertia.inverse())
}

/// A body's end-of-step pose and velocities in `f64`, principal frame (see `finish`).
#[derive(Debug, Clone, Copy)]
pub(super) struct Pose {
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
pub(super) fn anchor_at(poses: &[Pose], end: &End) -> DVec3 {
    match poses.get(end.body) {
        Some(p) => p.x + p.q * end.local,
        None => end.fixed,
    }
}
