//! The exact Newton matrix of the step: body blocks, spring couplings and the turning of the
//! torques, assembled into the sparse factorization or applied matrix-free.

use glam::{DMat3, DVec3};

use super::*;

impl ImplicitSpringSolver {
    /// `∂T/∂Ω̄` of the total torque on body `i` (its springs' forces and its loads held at the
    /// current iterate's values): with `c = Σ b × Q₀ᵀf + Q₀ᵀτ + c_points` the start-frame torque
    /// and `T = F (1 − [hΩ̄/2]×) c`, `∂T/∂Ω̄ = F (½h [c]× + (1 − [hΩ̄/2]×) ∂c/∂Ω̄)`, where the
    /// mean arm turns with `Ω̄`, `∂b/∂Ω̄ = −½h D [b]×` (`D = (1 − [hΩ̄/2]×)⁻¹`, see `evaluate`), so
    /// `∂(b × f₀)/∂Ω̄ = ½h [f₀]× D [b]×`. The forces at body points enter `c` but not its
    /// derivative (see the module docs).
    pub(super) fn turning_torque_jacobian(&self, h: f64, i: usize, w: DVec3) -> DMat3 {
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
        if s.method.is_some() {
            // Unturned torques (see `evaluate`): only the arms turn.
            return free * (0.5 * h) * by_turn;
        }
        let unturn = DMat3::IDENTITY - skew(0.5 * h * w);
        free * (0.5 * h) * (skew(c) + unturn * by_turn)
    }

    /// The mass and gyroscopic 6×6 block of body `i` at the current iterate.
    pub(super) fn body_block(&self, h: f64, i: usize) -> Block {
        let s = &self.starts[i];
        let w = s.free * v3(&self.z[6 * i + 3..6 * i + 6]);
        let mut block = [[0.0; 6]; 6];
        for (a, row) in block.iter_mut().take(3).enumerate() {
            row[a] = s.mass;
        }
        // ∂/∂Ω̄ of I Ω̄ + ½ h Ω̄ × I Ω̄ = I + ½ h ([Ω̄]× I − [I Ω̄]×).
        let inertia = DMat3::from_diagonal(s.inertia);
        let gyro = if s.method.is_none() {
            0.5 * h * (skew(w) * inertia - skew(s.inertia * w))
        } else {
            DMat3::ZERO
        };
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
    pub(super) fn end_jacobian(&self, h: f64, body: usize, b: DVec3, du: &[f64]) -> DVec3 {
        let s = &self.starts[body];
        let turn = self.cayley_derivative[body] * (s.free * v3(&du[3..])).cross(b);
        h * v3(&du[..3]) + h * (s.r * turn)
    }

    /// `Eᵀ f`: the generalized force of a world force `f` at the end with mean arm `b`
    /// (force; principal torque `F (1 − [hΩ̄/2]×) (b × Q₀ᵀ f)`, see `evaluate`).
    pub(super) fn end_transpose(&self, h: f64, body: usize, b: DVec3, f: DVec3) -> (DVec3, DVec3) {
        let s = &self.starts[body];
        (
            h * f,
            h * (self.unturn[body] * b.cross(s.r.transpose() * f)),
        )
    }

    /// `out = J u`: the Newton matrix (the body blocks of [`Self::build_blocks`] and the
    /// springs' `¼ GᵀKG`, applied spring by spring) times `u`.
    pub(super) fn apply_jacobian(&self, h: f64, u: &[f64], out: &mut [f64]) {
        debug_assert!(self.linearized, "linearize first");
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
    pub(super) fn build_blocks(&mut self, h: f64) {
        self.linearize(h);
        // The storage of the last factorization's diagonal, which this matrix replaces: a
        // group's blocks are held once, here or in the factorization.
        let mut blocks = std::mem::take(&mut self.blocks);
        if blocks.capacity() == 0 {
            blocks = self.lu.take_diagonal();
        }
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
    pub(super) fn factor(&mut self, h: f64) {
        let mut lu = std::mem::take(&mut self.lu);
        lu.reset(std::mem::take(&mut self.blocks));
        self.assemble_springs(h, &mut lu);
        if !self.analyzed {
            // The pattern is the group's graph, the same for every Newton iteration of a solve
            // (and of the next step's, while the springs stay).
            lu.analyze_unless_known();
            self.analyzed = true;
        }
        self.factored = lu.factor().is_ok();
        self.lu = lu;
        if self.factored {
            return;
        }
        // Block Jacobi where the direct factorization failed (a singular pivot): each body's
        // diagonal block inverted, or its mass and inertia where that block is singular too.
        // The body blocks went into the factorization: built again (the same function of the
        // iterate), for the preconditioner and the matrix-free products.
        self.build_blocks(h);
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
    pub(super) fn assemble_springs(&self, h: f64, blocks: &mut impl BlockSink) {
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
    pub(super) fn end_factors(&self, h: f64, i: usize, b: DVec3) -> EndFactors {
        debug_assert!(self.linearized, "linearize first");
        let s = &self.starts[i];
        let free = DMat3::from_diagonal(s.free);
        EndFactors {
            move_by_turn: -h * (s.r * self.cayley_derivative[i] * skew(b)) * free,
            torque_of_force: h * self.unturn[i] * skew(b) * s.r.transpose(),
        }
    }

    pub(super) fn apply_preconditioner(&self, u: &[f64], out: &mut [f64]) {
        for (i, p) in self.preconditioner.iter().enumerate() {
            let y = block_mul(p, &u[6 * i..6 * i + 6]);
            out[6 * i..6 * i + 6].copy_from_slice(&y);
        }
    }
}

/// A spring end's factors of the Newton matrix, see `ImplicitSpringSolver::end_factors`.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct EndFactors {
    move_by_turn: DMat3,
    torque_of_force: DMat3,
}

/// Adds the block `sign · Eₑᵀ K G_f` of the Newton matrix that spring end `e` receives from end
/// `f` to `block` (`K` = ¼ of the spring's stiffness matrix): `G_f = [h 1, G_turn,f]` maps the
/// update of end `f`'s body to its anchor's motion, `Eₑᵀ = [h 1; E_turn,e]` maps a world force at
/// end `e` to its body's generalized force. The 3×3 parts are `h² K`, `h K G_turn,f`,
/// `h E_turn,e K` and `E_turn,e (K G_turn,f)`; each end's `K G_turn` and `E_turn K` are formed
/// once and shared by the blocks of its spring.
pub(super) fn add_coupling(
    block: &mut Block,
    h: f64,
    k: DMat3,
    e: &EndProducts,
    f: &EndProducts,
    sign: f64,
) {
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
pub(super) trait BlockSink {
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
pub(super) struct DiagonalBlocks {
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
pub(super) struct EndProducts<'a> {
    /// `E_turn`.
    torque: &'a DMat3,
    /// `E_turn K`.
    torque_k: &'a DMat3,
    /// `K G_turn`.
    k_turn: &'a DMat3,
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
            rotation: GroupRotation::Midpoint,
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
        let columns: Vec<Vec<f64>> = (0..n)
            .map(|j| {
                let mut x = vec![0.0; n];
                x[j] = 1.0;
                solver.lu.solve_in_place(&mut x);
                x
            })
            .collect();
        // The body blocks went into the factorization; built again for the product.
        solver.build_blocks(h);
        for (j, x) in columns.iter().enumerate() {
            let mut unit = vec![0.0; n];
            unit[j] = 1.0;
            let mut back = vec![0.0; n];
            solver.apply_jacobian(h, x, &mut back);
            for (i, (b, u)) in back.iter().zip(&unit).enumerate() {
                assert!((b - u).abs() < 1e-9, "(J LU⁻¹)[{i}][{j}] = {b:e}");
            }
        }
    }
}
