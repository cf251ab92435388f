//! Newton's method on the step's equations: the residual, the stopping rule, the trust region
//! and the backtracking (see the module docs of `springs::implicit`).

use glam::{DMat3, DVec3};

use super::*;

impl ImplicitSpringSolver {
    /// One Newton solve of the whole step `h`.
    pub(super) fn solve(
        &mut self,
        bodies: &mut [GroupBody],
        springs: &[GroupSpring],
        h: f64,
        stats: &mut SolveStats,
    ) -> Result<(), ImplicitSpringError> {
        self.prepare(bodies, springs)?;
        self.start_iterate();
        let tolerance = self.update_tolerance();
        let scale = self.energy_scale(h);
        let mut norm = self.evaluate(h);
        stats.residual_evaluations += 1;
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
                stats.factorizations += 1;
            }
            let delta = self.newton_update(h, refactor, stats);
            let mut step = self.turn_limited_step(h, &delta);
            let full = (self.kinetic_norm(&delta) / scale).sqrt();
            if step == 1.0 && full <= tolerance {
                // The whole update is within the tolerance: take it and stop. Backtracking
                // guards against overshoot far from the solution; on an update this small its
                // trial evaluation could only tell round-off from round-off, and it would be the
                // solve's last (`finish` works from the iterate alone).
                self.take_whole(delta);
                update = full;
                break;
            }
            let (accepted, stagnating) = self.backtrack(h, &delta, &mut step, &mut norm, stats);
            self.delta = delta;
            let chord = !refactor && self.factored;
            if chord && (!accepted || stagnating) {
                // The stale matrix's step went nowhere: retake the iteration with a fresh one,
                // linearized at the iterate (the last evaluation was of a rejected trial).
                if !accepted {
                    norm = self.evaluate(h);
                    stats.residual_evaluations += 1;
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
            if update <= tolerance {
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
                if left <= tolerance {
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
        self.check_converged(update, tolerance, iterations)?;
        self.finish(h, bodies)
    }

    /// The tolerance on the update's energy-weighted norm. A method's turn enters the Newton
    /// matrix by the Cayley rotation's derivative, an approximation: the iteration converges
    /// linearly, and what it leaves unconverged the momenta lose. Converging a hundred times
    /// further keeps them to round-off, for a few more evaluations (the contraction per
    /// iteration is about `(h|Ω̄|)²`).
    fn update_tolerance(&self) -> f64 {
        if self.starts.iter().any(|s| s.method.is_some()) {
            METHOD_TURN_TOLERANCE * self.tolerance
        } else {
            self.tolerance
        }
    }

    /// Moves the iterate by the whole update `delta` (`z + 1·δ`, the bits of an accepted
    /// trial at step 1) and gives its buffer back.
    fn take_whole(&mut self, delta: Vec<f64>) {
        for (z, d) in self.z.iter_mut().zip(&delta) {
            *z += d;
        }
        self.delta = delta;
    }

    /// The solve's verdict on its last update: a non-finite update or iterate, or an update
    /// still above `tolerance` after `iterations`, is an error.
    fn check_converged(
        &self,
        update: f64,
        tolerance: f64,
        iterations: usize,
    ) -> Result<(), ImplicitSpringError> {
        if !update.is_finite() || self.z.iter().any(|v| !v.is_finite()) {
            return Err(ImplicitSpringError::NonFinite);
        }
        if update > tolerance {
            return Err(ImplicitSpringError::NotConverged {
                iterations,
                update,
                tolerance,
            });
        }
        Ok(())
    }

    /// The first iterate, the start's velocities `(v, Ω)` of every body, and the working
    /// buffers sized for it.
    fn start_iterate(&mut self) {
        let n = self.starts.len() * 6;
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
        ] {
            buffer.clear();
            buffer.resize(n, 0.0);
        }
    }

    /// The Newton update `δ` solving `J δ = −r` at the iterate (`J` the last factorized matrix
    /// in a chord step). Takes `self.delta`'s buffer; the caller puts it back.
    fn newton_update(&mut self, h: f64, refactor: bool, stats: &mut SolveStats) -> Vec<f64> {
        let mut delta = std::mem::take(&mut self.delta);
        if self.factored {
            // A direct solve with the factorization, in place: of the exact Newton matrix after
            // a refactor, of a recent one in a chord step.
            for (d, r) in delta.iter_mut().zip(&self.residual) {
                *d = -r;
            }
            self.lu.solve_in_place(&mut delta);
            stats.linear_iterations += 1;
        } else {
            // The right-hand side apart, sized here: only this (rare) path needs it.
            let mut rhs = std::mem::take(&mut self.rhs);
            rhs.clear();
            rhs.extend(self.residual.iter().map(|r| -r));
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
            self.rhs = rhs;
        }
        delta
    }

    /// The longest fraction (≤ 1) of the update `delta` within the trust region on the
    /// rotation: an update may change any body's Cayley angle `2 atan(h|Ω̄|/2)` by at most
    /// `MAX_TURN` (radians), so Newton does not jump across the region where the map from Ω̄ to
    /// the rotation is far from linear.
    fn turn_limited_step(&self, h: f64, delta: &[f64]) -> f64 {
        let mut step: f64 = 1.0;
        for (d, z) in delta.chunks_exact(6).zip(self.z.chunks_exact(6)) {
            let w = h * v3(&z[3..]).length();
            let allowed = MAX_TURN * (1.0 + 0.25 * w * w);
            let change = h * v3(&d[3..]).length();
            if change > allowed {
                step = step.min(allowed / change);
            }
        }
        step
    }

    /// Backtracking on the residual norm (a full Newton step can overshoot far from the
    /// solution: large rotations make the spring geometry strongly nonlinear): halves `step`
    /// until the iterate `z + step·δ` does not raise the residual norm `norm`, at most 12 times.
    /// On success the iterate and `norm` move there; returns whether it did and whether the
    /// accepted step stagnates (tiny, and hardly lowering the residual).
    fn backtrack(
        &mut self,
        h: f64,
        delta: &[f64],
        step: &mut f64,
        norm: &mut f64,
        stats: &mut SolveStats,
    ) -> (bool, bool) {
        for _ in 0..12 {
            for ((t, z), d) in self.trial.iter_mut().zip(&self.z).zip(delta) {
                *t = z + *step * d;
            }
            std::mem::swap(&mut self.z, &mut self.trial);
            std::mem::swap(&mut self.residual, &mut self.trial_residual);
            let trial_norm = self.evaluate(h);
            stats.residual_evaluations += 1;
            if trial_norm.is_finite() && trial_norm <= *norm {
                let stagnating =
                    *step < STAGNANT_STEP && trial_norm > (1.0 - STAGNANT_DECREASE) * *norm;
                *norm = trial_norm;
                return (true, stagnating);
            }
            std::mem::swap(&mut self.z, &mut self.trial);
            std::mem::swap(&mut self.residual, &mut self.trial_residual);
            *step *= 0.5;
        }
        (false, false)
    }

    /// Reads the bodies and springs into the `f64` principal-frame working data.
    pub(super) fn prepare(
        &mut self,
        bodies: &[GroupBody],
        springs: &[GroupSpring],
    ) -> Result<(), ImplicitSpringError> {
        self.analyzed = false;
        self.read_starts(bodies)?;
        self.read_links(bodies, springs)?;
        self.lin.clear();
        self.lin.resize(self.links.len(), Linearized::default());
        self.sort_ends_by_body(bodies.len());
        Ok(())
    }

    /// Each body's start in its principal frame.
    fn read_starts(&mut self, bodies: &[GroupBody]) -> Result<(), ImplicitSpringError> {
        self.starts.clear();
        // Exact sizes: grown by doubling, a group of a million bodies would hold up to twice
        // its starts, three times while a doubling copies them.
        self.starts.reserve_exact(bodies.len());
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
                method: match body.rotation {
                    GroupRotation::Midpoint => None,
                    GroupRotation::Method(integrator) => {
                        GroupRotation::of(integrator)?;
                        Some(integrator)
                    }
                },
                odd: m.odd_axis(),
            });
        }
        Ok(())
    }

    /// Each spring as a link between its two ends' principal-frame anchors, with its start
    /// geometry.
    fn read_links(
        &mut self,
        bodies: &[GroupBody],
        springs: &[GroupSpring],
    ) -> Result<(), ImplicitSpringError> {
        self.links.clear();
        self.links.reserve_exact(springs.len());
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
        Ok(())
    }

    /// A counting sort of the spring ends by body: body `i`'s ends are
    /// `ends_of[ends_start[i]..ends_start[i + 1]]`, as `(link, end)`, in link order.
    fn sort_ends_by_body(&mut self, len: usize) {
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
    }

    pub(super) fn anchor_start(&self, end: &End) -> DVec3 {
        match self.starts.get(end.body) {
            Some(s) => s.x + s.q * end.local,
            None => end.fixed,
        }
    }

    /// The group's energy scale (J): kinetic + elastic energy at the start plus the work the
    /// loads can do in a step, so the tolerance is relative to what the step moves.
    pub(super) fn energy_scale(&self, h: f64) -> f64 {
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
    pub(super) fn kinetic_norm(&self, delta: &[f64]) -> f64 {
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

    /// Computes the residual at `self.z` into `self.residual` (and what the linearization at
    /// `self.z` needs besides, see [`Self::linearize`]) and returns its norm, scaled per body by
    /// `1/√m`, `1/√I`.
    pub(super) fn evaluate(&mut self, h: f64) -> f64 {
        self.linearized = false;
        self.cayley.clear();
        self.unturn.clear();
        for (i, s) in self.starts.iter().enumerate() {
            let z = &self.z[6 * i..6 * i + 6];
            let vbar = v3(&z[..3]);
            let wbar = s.free * v3(&z[3..]);
            let cay = DMat3::from_quat(s.turn(h, wbar));
            self.cayley.push(cay);
            let u = skew(0.5 * h * wbar);
            // A method's turn keeps the world momentum: the torques act unturned, and there is
            // no gyroscopic term (it is in the turn).
            let midpoint = s.method.is_none();
            self.unturn.push(if midpoint {
                DMat3::from_diagonal(s.free) * (DMat3::IDENTITY - u)
            } else {
                DMat3::from_diagonal(s.free)
            });
            let r = &mut self.residual[6 * i..6 * i + 6];
            put(&mut r[..3], s.mass * (vbar - s.v) - 0.5 * h * s.force);
            // External torque: the world torque and the forces at body points taken like spring
            // ends (start frame, mean arm), turned by `1 − [hΩ̄/2]×` (see the module docs).
            let torque = self.unturn[i] * (s.r.transpose() * s.torque + point_torque(s, &cay));
            let iw = s.inertia * wbar;
            let gyroscopic = if midpoint {
                0.5 * h * wbar.cross(iw)
            } else {
                DVec3::ZERO
            };
            let rot = iw - s.pi + gyroscopic - 0.5 * h * torque;
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
                -link.k * ((lbar - link.rest) / lbar) * dbar
            } else {
                DVec3::ZERO
            };
            (lin.dbar, lin.d1, lin.lbar, lin.l1) = (dbar, d1, lbar, l1);
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

    /// The parts of the Newton matrix at the last evaluated iterate that the residual does not
    /// need: each body's Cayley derivative and each spring's stiffness `−2 ∂F̄/∂d₁`. Only an
    /// iteration that assembles the matrix needs them, so trial evaluations (the backtracking,
    /// the chord steps) skip their cost. Computed once per evaluation, from the values the
    /// evaluation left, so they are the same bits whenever asked for.
    pub(super) fn linearize(&mut self, h: f64) {
        if self.linearized {
            return;
        }
        self.linearized = true;
        self.cayley_derivative.clear();
        for (i, s) in self.starts.iter().enumerate() {
            // From (1 − [w/2]×) cay(w) a = (1 + [w/2]×) a: d(cay(w) a) = −(1 − [w/2]×)⁻¹ [b]× dw,
            // and (1 − [u]×)⁻¹ = 1 + ([u]× + [u]×²)/(1 + |u|²).
            let wbar = s.free * v3(&self.z[6 * i + 3..6 * i + 6]);
            let u = skew(0.5 * h * wbar);
            let uu = (0.5 * h * wbar).length_squared();
            self.cayley_derivative
                .push(DMat3::IDENTITY + (u + u * u) * (1.0 / (1.0 + uu)));
        }
        for (link, lin) in self.links.iter().zip(self.lin.iter_mut()) {
            let (dbar, d1, lbar, l1) = (lin.dbar, lin.d1, lin.lbar, lin.l1);
            lin.k = if lbar > 0.0 {
                let ratio = (lbar - link.rest) / lbar;
                let mut k = DMat3::from_diagonal(DVec3::splat(link.k * ratio));
                if l1 > 0.0 {
                    k += (link.k * link.rest / (lbar * lbar * l1)) * outer(dbar, d1);
                }
                k
            } else {
                DMat3::from_diagonal(DVec3::splat(link.k))
            };
        }
    }
}
