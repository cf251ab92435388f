//! A direct solve of the implicit spring step's Newton matrix: block Gaussian elimination on the
//! group's body graph, bodies eliminated in minimum-degree order.
//!
//! The Newton matrix of a spring group has one 6×6 block per body on the diagonal and one per
//! pair of bodies joined by a spring off it, so its block pattern is the group's graph. Eliminating
//! a body couples all of its remaining neighbours (fill); taking at each step a body with the
//! fewest remaining neighbours (Markowitz / minimum degree) keeps that fill small: none at all on a
//! chain or a tree (every leaf has one neighbour), a few blocks per body on a grid (a cloth).
//!
//! Used as the preconditioner of BiCGSTAB: exact when it is built from the current Jacobian (one
//! Krylov iteration), still a good one when a Newton iteration reuses an older factorization. A
//! pivot block that cannot be inverted (a compressed spring can make a Schur complement singular)
//! makes [`BlockLu::factor`] fail, and the caller falls back to block Jacobi.
//!
//! Hand-written: the blocks are 6×6 and the graphs small, and the crates that factor general
//! sparse matrices (faer, nalgebra-sparse) would add large dependencies to the engine core for a
//! few hundred lines that need nothing but 6×6 products.

use std::cmp::Reverse;
use std::collections::BinaryHeap;

use super::linear::{Block, block_mul, invert};

/// `c −= a b` for 6×6 blocks, in place.
#[inline]
fn subtract_product(c: &mut Block, a: &Block, b: &Block) {
    for (ci, ai) in c.iter_mut().zip(a) {
        for (k, &aik) in ai.iter().enumerate() {
            if aik != 0.0 {
                for (cij, bkj) in ci.iter_mut().zip(&b[k]) {
                    *cij -= aik * bkj;
                }
            }
        }
    }
}

/// `a b` for 6×6 blocks.
fn product(a: &Block, b: &Block) -> Block {
    let mut c = [[0.0; 6]; 6];
    for (ci, ai) in c.iter_mut().zip(a) {
        for (k, &aik) in ai.iter().enumerate() {
            for (cij, bkj) in ci.iter_mut().zip(&b[k]) {
                *cij += aik * bkj;
            }
        }
    }
    c
}

/// One eliminated body: its pivot inverse, the multipliers `A_ip P` of the bodies below it and
/// the blocks `A_pj` of the bodies after it (both over the bodies still present when it went).
#[derive(Debug, Clone, Default)]
struct Pivot {
    body: usize,
    inverse: Block,
    lower: Vec<(usize, Block)>,
    upper: Vec<(usize, Block)>,
}

/// The factorization, with its working storage kept between factorizations (no allocation once
/// warm for a group of the same shape).
#[derive(Debug, Clone, Default)]
pub(crate) struct BlockLu {
    /// Off-diagonal blocks by row: `rows[i]` holds `(j, A_ij)`; the pattern is symmetric.
    rows: Vec<Vec<(usize, Block)>>,
    diagonal: Vec<Block>,
    /// Scratch of `analyze`: the bodies already ordered.
    eliminated: Vec<bool>,
    pivots: Vec<Pivot>,
    pivot_count: usize,
    scratch: Vec<f64>,
    /// The elimination order, from [`BlockLu::analyze`].
    order: Vec<usize>,
    /// Per body, where column `j` sits in the row being updated (`usize::MAX`: absent).
    slot: Vec<usize>,
    /// The symbolic graph of `analyze`.
    graph: Vec<Vec<usize>>,
    queue: BinaryHeap<Reverse<(usize, usize)>>,
}

/// A block pivot could not be inverted.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct SingularPivot;

impl BlockLu {
    /// Starts a matrix of `n` bodies: the diagonal blocks `diagonal`, no off-diagonal blocks.
    pub(crate) fn reset(&mut self, diagonal: &[Block]) {
        let n = diagonal.len();
        self.diagonal.clear();
        self.diagonal.extend_from_slice(diagonal);
        self.rows.resize_with(n.max(self.rows.len()), Vec::new);
        for row in &mut self.rows {
            row.clear();
        }
        self.slot.clear();
        self.slot.resize(n, usize::MAX);
        self.pivot_count = 0;
    }

    /// Adds `block` to the off-diagonal entry `(i, j)`, `i ≠ j`, and makes `(j, i)` present.
    #[cfg(test)]
    pub(crate) fn add(&mut self, i: usize, j: usize, block: &Block) {
        for (x, y) in self.entry(i, j).iter_mut().zip(block) {
            for (u, v) in x.iter_mut().zip(y) {
                *u += v;
            }
        }
    }

    /// The diagonal block of body `i`, to add to before [`factor`](Self::factor).
    pub(crate) fn diagonal_mut(&mut self, i: usize) -> &mut Block {
        &mut self.diagonal[i]
    }

    /// The block `(i, j)` (`i ≠ j`), zero when first named, to add to before
    /// [`factor`](Self::factor); `(j, i)` enters the pattern too, which stays symmetric.
    pub(crate) fn entry(&mut self, i: usize, j: usize) -> &mut Block {
        if !self.rows[j].iter().any(|(c, _)| *c == i) {
            self.rows[j].push((i, [[0.0; 6]; 6]));
        }
        let row = &mut self.rows[i];
        let at = match row.iter().position(|(c, _)| *c == j) {
            Some(at) => at,
            None => {
                row.push((j, [[0.0; 6]; 6]));
                row.len() - 1
            }
        };
        &mut row[at].1
    }

    /// Chooses the elimination order from the present pattern (call after the `add`s; the
    /// order holds for every matrix of the same pattern). Each step eliminates a remaining body
    /// with the fewest remaining neighbours, counting the fill of earlier steps (the lowest index
    /// among equals, so the order, and the bits, depend on the pattern alone).
    pub(crate) fn analyze(&mut self) {
        let n = self.diagonal.len();
        self.graph.resize_with(n.max(self.graph.len()), Vec::new);
        for (adjacent, row) in self.graph.iter_mut().zip(&self.rows) {
            adjacent.clear();
            adjacent.extend(row.iter().map(|(j, _)| *j));
        }
        self.slot.clear();
        self.slot.resize(n, usize::MAX);
        self.queue.clear();
        self.queue
            .extend((0..n).map(|i| Reverse((self.graph[i].len(), i))));
        self.order.clear();
        self.eliminated.clear();
        self.eliminated.resize(n, false);
        while let Some(Reverse((degree, p))) = self.queue.pop() {
            if self.eliminated[p] || degree != self.graph[p].len() {
                continue; // a stale entry: p went already, or its degree changed since
            }
            self.eliminated[p] = true;
            self.order.push(p);
            let neighbours = std::mem::take(&mut self.graph[p]);
            for &i in &neighbours {
                // i loses p and gains every other neighbour of p it lacked (the fill).
                let adjacent = &mut self.graph[i];
                adjacent.retain(|&j| j != p);
                for &j in adjacent.iter() {
                    self.slot[j] = i;
                }
                for &j in &neighbours {
                    if j != i && self.slot[j] != i {
                        adjacent.push(j);
                    }
                }
                self.queue.push(Reverse((adjacent.len(), i)));
            }
            self.graph[p] = neighbours;
            self.graph[p].clear();
        }
        self.slot.fill(usize::MAX);
    }

    /// Factors the matrix in place, in the order of the last [`BlockLu::analyze`].
    pub(crate) fn factor(&mut self) -> Result<(), SingularPivot> {
        debug_assert_eq!(self.order.len(), self.diagonal.len(), "analyze first");
        let Self {
            rows,
            diagonal,
            pivots,
            pivot_count,
            order,
            slot,
            ..
        } = self;
        *pivot_count = 0;
        for &p in order.iter() {
            if pivots.len() <= *pivot_count {
                pivots.push(Pivot::default());
            }
            let pivot = &mut pivots[*pivot_count];
            *pivot_count += 1;
            pivot.body = p;
            pivot.inverse = invert(&diagonal[p]).ok_or(SingularPivot)?;
            // Row p becomes the pivot's upper blocks A_pj (the vectors trade places, no block
            // is copied); each A_jp leaves row j (p is gone from the remaining matrix) as the
            // multiplier A_jp P.
            pivot.upper.clear();
            std::mem::swap(&mut pivot.upper, &mut rows[p]);
            pivot.lower.clear();
            for &(j, _) in &pivot.upper {
                let at = rows[j]
                    .iter()
                    .position(|(c, _)| *c == p)
                    .expect("the pattern is symmetric");
                pivot
                    .lower
                    .push((j, product(&rows[j][at].1, &pivot.inverse)));
                rows[j].swap_remove(at);
            }
            // Schur complement: A_ij −= (A_ip P) A_pj over all remaining neighbours i, j of p.
            for (i, l_ip) in &pivot.lower {
                let row = &mut rows[*i];
                for (at, (j, _)) in row.iter().enumerate() {
                    slot[*j] = at;
                }
                for (j, a_pj) in &pivot.upper {
                    if i == j {
                        subtract_product(&mut diagonal[*i], l_ip, a_pj);
                    } else if slot[*j] != usize::MAX {
                        subtract_product(&mut row[slot[*j]].1, l_ip, a_pj);
                    } else {
                        slot[*j] = row.len();
                        row.push((*j, [[0.0; 6]; 6]));
                        subtract_product(&mut row.last_mut().expect("pushed").1, l_ip, a_pj);
                    }
                }
                for (j, _) in row.iter() {
                    slot[*j] = usize::MAX;
                }
            }
        }
        Ok(())
    }

    /// `out = A⁻¹ u` with the factorization (forward elimination, then back substitution).
    pub(crate) fn solve(&mut self, u: &[f64], out: &mut [f64]) {
        let y = &mut self.scratch;
        y.clear();
        y.extend_from_slice(u);
        for pivot in &self.pivots[..self.pivot_count] {
            let p = pivot.body;
            let yp: [f64; 6] = y[6 * p..6 * p + 6].try_into().expect("six entries");
            for (i, l) in &pivot.lower {
                let d = block_mul(l, &yp);
                for (a, b) in y[6 * i..6 * i + 6].iter_mut().zip(d) {
                    *a -= b;
                }
            }
        }
        for pivot in self.pivots[..self.pivot_count].iter().rev() {
            let p = pivot.body;
            let mut r: [f64; 6] = y[6 * p..6 * p + 6].try_into().expect("six entries");
            for (j, a) in &pivot.upper {
                let d = block_mul(a, &out[6 * j..6 * j + 6]);
                for (x, b) in r.iter_mut().zip(d) {
                    *x -= b;
                }
            }
            out[6 * p..6 * p + 6].copy_from_slice(&block_mul(&pivot.inverse, &r));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A deterministic pseudo-random block, diagonally dominant where `dominant`.
    fn block(seed: u64, dominant: bool) -> Block {
        let mut state = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        let mut b = [[0.0; 6]; 6];
        for (r, row) in b.iter_mut().enumerate() {
            for (c, x) in row.iter_mut().enumerate() {
                state = state
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                *x = ((state >> 11) as f64 / (1u64 << 53) as f64) - 0.5;
                if dominant && r == c {
                    *x += 8.0;
                }
            }
        }
        b
    }

    /// Factors a grid's matrix (fill included) and checks `A (A⁻¹ u) = u`.
    #[test]
    fn solves_a_grid_and_a_chain_to_round_off() {
        for (width, height) in [(10, 1), (5, 4), (7, 7)] {
            let n = width * height;
            let diagonal: Vec<Block> = (0..n).map(|i| block(i as u64, true)).collect();
            let mut edges = Vec::new();
            for y in 0..height {
                for x in 0..width {
                    let i = y * width + x;
                    if x + 1 < width {
                        edges.push((i, i + 1));
                    }
                    if y + 1 < height {
                        edges.push((i, i + width));
                    }
                }
            }
            let mut lu = BlockLu::default();
            lu.reset(&diagonal);
            let mut off = Vec::new();
            for (k, &(i, j)) in edges.iter().enumerate() {
                let (a, b) = (
                    block(1000 + 2 * k as u64, false),
                    block(1001 + 2 * k as u64, false),
                );
                lu.add(i, j, &a);
                lu.add(j, i, &b);
                off.push((i, j, a));
                off.push((j, i, b));
            }
            lu.analyze();
            lu.factor().expect("diagonally dominant");
            let u: Vec<f64> = (0..6 * n).map(|k| (k as f64 * 0.37).sin()).collect();
            let mut x = vec![0.0; 6 * n];
            lu.solve(&u, &mut x);
            let mut ax = vec![0.0; 6 * n];
            for i in 0..n {
                let y = block_mul(&diagonal[i], &x[6 * i..6 * i + 6]);
                ax[6 * i..6 * i + 6].copy_from_slice(&y);
            }
            for (i, j, a) in &off {
                let y = block_mul(a, &x[6 * j..6 * j + 6]);
                for (s, t) in ax[6 * i..6 * i + 6].iter_mut().zip(y) {
                    *s += t;
                }
            }
            let error = ax
                .iter()
                .zip(&u)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            assert!(error < 1e-12, "{width}×{height}: |A x − u| = {error:e}");
        }
    }

    #[test]
    fn a_singular_pivot_is_reported() {
        let mut lu = BlockLu::default();
        lu.reset(&[[[0.0; 6]; 6]]);
        lu.analyze();
        assert_eq!(lu.factor(), Err(SingularPivot));
    }
}
