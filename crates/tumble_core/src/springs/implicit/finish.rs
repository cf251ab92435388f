//! The end of a step: the new states, and the rounding of the state kept from moving the energy.

use glam::{DQuat, DVec3};

use super::*;

impl ImplicitSpringSolver {
    /// Writes the end-of-step states from the converged `(v̄, Ω̄)`.
    pub(super) fn finish(
        &self,
        h: f64,
        bodies: &mut [GroupBody],
    ) -> Result<(), ImplicitSpringError> {
        let mut exact = Vec::with_capacity(bodies.len());
        let mut out = Vec::with_capacity(bodies.len());
        for (i, (s, body)) in self.starts.iter().zip(bodies.iter()).enumerate() {
            let z = &self.z[6 * i..6 * i + 6];
            let vbar = v3(&z[..3]);
            let wbar = s.free * v3(&z[3..]);
            let turn = s.turn(h, wbar);
            let q1 = (s.q * turn).normalize();
            let pi1 = s.free * (2.0 * s.inertia * wbar - s.pi);
            // A method's turn keeps the world momentum: the end's body momentum is the world's
            // `L₁ = Q₀ (2 I Ω̄ − Π₀)` in the turned frame.
            let pi1 = if s.method.is_some() {
                turn.inverse() * pi1
            } else {
                pi1
            };
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
    /// energy of its exact (`f64`) end state, so the rounded state's velocities relative to the
    /// group's centre of mass are scaled by `s = √(1 + ΔE/T_rel)` to give it back (`T_rel` the
    /// kinetic energy relative to the centre of mass): linear momentum is kept, and only a
    /// correction rounding can explain (within four times [`Self::rounding_bound`]) is made.
    /// Bodies turned by a method's free flow are left out (the group's centre and `T_rel` are
    /// those of the others).
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
        // Only the bodies the midpoint turns are scaled: a method's turn keeps the energy to the
        // method's accuracy, not exactly, and scaling its spin would shift its phase.
        let midpoint = |s: &Start| s.method.is_none();
        let mass: f64 = self
            .starts
            .iter()
            .filter(|s| midpoint(s))
            .map(|s| s.mass)
            .sum();
        if mass <= 0.0 {
            return;
        }
        let centre = self
            .starts
            .iter()
            .zip(&rounded)
            .filter(|(s, _)| midpoint(s))
            .map(|(s, p)| s.mass * p.v)
            .sum::<DVec3>()
            / mass;
        let relative: f64 = self
            .starts
            .iter()
            .zip(&rounded)
            .filter(|(s, _)| midpoint(s))
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
        for ((state, p), _) in out
            .iter_mut()
            .zip(&rounded)
            .zip(&self.starts)
            .filter(|(_, start)| midpoint(start))
        {
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
