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

use super::linear::{Block, block_mul, invert_into};

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

/// `pool[c] −= pool[a] pool[b]`, `c` neither `a` nor `b`, the blocks read in place.
#[inline]
fn subtract_in_pool(pool: &mut [Block], c: usize, a: usize, b: usize) {
    let (before, rest) = pool.split_at_mut(c);
    let (target, after) = rest.split_first_mut().expect("the target is in the pool");
    let block = |k: usize| if k < c { &before[k] } else { &after[k - c - 1] };
    subtract_product(target, block(a), block(b));
}

/// The target of a Schur update on a body's diagonal block (not in the pool).
const DIAGONAL: u32 = u32::MAX;

/// `a ← a b` for 6×6 blocks, in place: row `i` of the product needs only row `i` of `a`.
fn multiply_right(a: &mut Block, b: &Block) {
    for ai in a.iter_mut() {
        let mut ci = [0.0; 6];
        for (k, &aik) in ai.iter().enumerate() {
            for (cij, bkj) in ci.iter_mut().zip(&b[k]) {
                *cij += aik * bkj;
            }
        }
        *ai = ci;
    }
}

/// An entry of a row or of a pivot: the column (or row) body and where its block sits in
/// [`BlockLu`]'s block pool. Eight bytes, so that a body's short list costs little: a chain's
/// rows hold two entries, and a vector of whole blocks would reserve four (1.2 kB) for them.
type Entry = (u32, u32);

/// One eliminated body: the multipliers `A_ip P` of the bodies below it and the blocks `A_pj`
/// of the bodies after it (both over the bodies still present when it went), as ranges of
/// [`BlockLu`]'s pivot entries, their blocks in the pool. Its pivot inverse `P` is kept in
/// its diagonal block's place, which elimination no longer reads once the body is gone.
#[derive(Debug, Clone, Copy, Default)]
struct Pivot {
    body: u32,
    /// `entries[upper..lower]` are the upper blocks, `entries[lower..end]` the multipliers.
    upper: u32,
    lower: u32,
    end: u32,
}

/// The factorization, with its working storage kept between factorizations (no allocation once
/// warm for a group of the same shape).
#[derive(Debug, Clone, Default)]
pub(crate) struct BlockLu {
    /// Off-diagonal entries by row: `rows[i]` holds `(j, block of A_ij)`; the pattern is
    /// symmetric.
    rows: Vec<Vec<Entry>>,
    /// The diagonal blocks; once factored, each eliminated body's pivot inverse.
    diagonal: Vec<Block>,
    /// Every off-diagonal block: the matrix's, the multipliers that replace the lower ones as
    /// their bodies go, and the fill.
    pool: Vec<Block>,
    /// Scratch of `analyze`: the bodies already ordered.
    eliminated: Vec<bool>,
    pivots: Vec<Pivot>,
    /// The pivots' entries, in elimination order (see [`Pivot`]).
    pivot_entries: Vec<Entry>,
    /// The elimination order, from [`BlockLu::analyze`].
    order: Vec<usize>,
    /// Per body, where column `j` sits in the row being updated (`usize::MAX`: absent).
    slot: Vec<usize>,
    /// The symbolic graph of `analyze`.
    graph: Vec<Vec<usize>>,
    /// The Schur updates of the pivot being eliminated: `(i, target, A_ip P, A_pj)`, the
    /// target block of the pool or [`DIAGONAL`] for body `i`'s own.
    targets: Vec<(u32, u32, u32, u32)>,
    queue: BinaryHeap<Reverse<(usize, usize)>>,
    /// The pattern `order` was chosen for: the body count, then each row's length and columns
    /// (see [`BlockLu::analyze_unless_known`]).
    analyzed_pattern: Vec<u32>,
    /// Scratch: the present pattern, in the form of `analyzed_pattern`.
    pattern: Vec<u32>,
}

/// A block pivot could not be inverted.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct SingularPivot;

/// A body or block index as an entry stores it. Groups are bounded far below `u32::MAX`
/// bodies and blocks by memory (a block is 288 bytes).
#[inline]
fn narrow(i: usize) -> u32 {
    u32::try_from(i).expect("fewer than 2³² bodies and blocks in a group")
}

impl BlockLu {
    /// Starts a matrix of `diagonal.len()` bodies: the diagonal blocks `diagonal`, taken over
    /// (not copied: a group's blocks are held once), no off-diagonal blocks.
    pub(crate) fn reset(&mut self, diagonal: Vec<Block>) {
        let n = diagonal.len();
        self.diagonal = diagonal;
        self.rows.resize_with(n.max(self.rows.len()), Vec::new);
        for row in &mut self.rows {
            row.clear();
        }
        self.pool.clear();
        self.slot.clear();
        self.slot.resize(n, usize::MAX);
        self.pivots.clear();
        self.pivot_entries.clear();
    }

    /// Hands the diagonal blocks' storage back (emptied) for the next matrix: the
    /// factorization it held is gone.
    pub(crate) fn take_diagonal(&mut self) -> Vec<Block> {
        self.pivots.clear();
        let mut diagonal = std::mem::take(&mut self.diagonal);
        diagonal.clear();
        diagonal
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

    /// A new zero block in the pool, and its index.
    fn new_block(&mut self) -> u32 {
        self.pool.push([[0.0; 6]; 6]);
        narrow(self.pool.len() - 1)
    }

    /// The block `(i, j)` (`i ≠ j`), zero when first named, to add to before
    /// [`factor`](Self::factor); `(j, i)` enters the pattern too, which stays symmetric.
    pub(crate) fn entry(&mut self, i: usize, j: usize) -> &mut Block {
        let (ci, cj) = (narrow(i), narrow(j));
        if !self.rows[j].iter().any(|(c, _)| *c == ci) {
            let block = self.new_block();
            self.rows[j].push((ci, block));
        }
        let block = match self.rows[i].iter().find(|(c, _)| *c == cj) {
            Some(&(_, block)) => block,
            None => {
                let block = self.new_block();
                self.rows[i].push((cj, block));
                block
            }
        };
        &mut self.pool[block as usize]
    }

    /// [`analyze`](Self::analyze), unless the present pattern is the one the present order was
    /// chosen for (the same bodies and blocks, listed in the same order): the order is a
    /// function of the pattern alone, and a group whose springs stay the same keeps its pattern
    /// from one step to the next. Costs one pass over the pattern.
    pub(crate) fn analyze_unless_known(&mut self) {
        let n = self.diagonal.len();
        self.pattern.clear();
        self.pattern.push(narrow(n));
        for row in &self.rows[..n] {
            self.pattern.push(narrow(row.len()));
            self.pattern.extend(row.iter().map(|&(j, _)| j));
        }
        if self.pattern != self.analyzed_pattern || self.order.len() != n {
            self.analyze();
            std::mem::swap(&mut self.pattern, &mut self.analyzed_pattern);
        }
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
            adjacent.extend(row.iter().map(|(j, _)| *j as usize));
        }
        self.slot.clear();
        self.slot.resize(n, usize::MAX);
        self.queue.clear();
        self.queue
            .extend((0..n).map(|i| Reverse((self.graph[i].len(), i))));
        self.order.clear();
        self.eliminated.clear();
        self.eliminated.resize(n, false);
        let mut fill = 0;
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
                        fill += 1;
                    }
                }
                self.queue.push(Reverse((adjacent.len(), i)));
            }
            self.graph[p] = neighbours;
            self.graph[p].clear();
        }
        self.slot.fill(usize::MAX);
        // The symbolic graph and the queue are needed again only when the pattern changes:
        // released, not kept beside the factorization (a body's list costs more than its
        // entry in the factorization).
        self.graph = Vec::new();
        self.queue = BinaryHeap::new();
        // Every block a factorization of this pattern holds: the matrix's and the fill. Sized
        // exactly (a pool grown by doubling holds up to twice its blocks).
        let blocks = self.pool.len() + fill;
        self.pool.shrink_to(blocks);
        self.pool.reserve_exact(blocks - self.pool.len());
    }

    /// Factors the matrix in place, in the order of the last [`BlockLu::analyze`].
    pub(crate) fn factor(&mut self) -> Result<(), SingularPivot> {
        debug_assert_eq!(self.order.len(), self.diagonal.len(), "analyze first");
        let Self {
            rows,
            diagonal,
            pool,
            pivots,
            pivot_entries: entries,
            order,
            slot,
            targets,
            ..
        } = self;
        pivots.clear();
        entries.clear();
        // Sized once: a pivot per body, and each block of the pool (the matrix's and the
        // fill, counted by `analyze`) is one pivot's upper block or multiplier.
        pivots.reserve_exact(order.len());
        entries.reserve_exact(pool.capacity());
        for &p in order.iter() {
            let mut inverse = [[0.0; 6]; 6];
            if !invert_into(&diagonal[p], &mut inverse) {
                return Err(SingularPivot);
            }
            diagonal[p] = inverse;
            // Row p becomes the pivot's upper blocks A_pj; each A_jp leaves row j (p is gone
            // from the remaining matrix), its block overwritten by the multiplier A_jp P.
            let upper = entries.len();
            entries.extend_from_slice(&rows[p]);
            rows[p].clear();
            let lower = entries.len();
            let column = narrow(p);
            for k in upper..lower {
                let j = entries[k].0;
                let row = &mut rows[j as usize];
                let at = row
                    .iter()
                    .position(|(c, _)| *c == column)
                    .expect("the pattern is symmetric");
                let block = row[at].1;
                multiply_right(&mut pool[block as usize], &diagonal[p]);
                entries.push((j, block));
                row.swap_remove(at);
            }
            let end = entries.len();
            pivots.push(Pivot {
                body: narrow(p),
                upper: narrow(upper),
                lower: narrow(lower),
                end: narrow(end),
            });
            // Schur complement: A_ij −= (A_ip P) A_pj over all remaining neighbours i, j of p.
            // The fill blocks first, so that the updates read the pool's blocks in place (a
            // target `(i, j)` is never `(i, p)` or `(p, j)`); in the same order as the updates,
            // so every block keeps its place in the pool.
            targets.clear();
            for &(i, l_ip) in &entries[lower..end] {
                let row = &mut rows[i as usize];
                for (at, (j, _)) in row.iter().enumerate() {
                    slot[*j as usize] = at;
                }
                for &(j, a_pj) in &entries[upper..lower] {
                    let target = if i == j {
                        DIAGONAL
                    } else if slot[j as usize] != usize::MAX {
                        row[slot[j as usize]].1
                    } else {
                        pool.push([[0.0; 6]; 6]);
                        let block = narrow(pool.len() - 1);
                        slot[j as usize] = row.len();
                        row.push((j, block));
                        block
                    };
                    targets.push((i, target, l_ip, a_pj));
                }
                for (j, _) in row.iter() {
                    slot[*j as usize] = usize::MAX;
                }
            }
            for &(i, target, l_ip, a_pj) in targets.iter() {
                if target == DIAGONAL {
                    let (l, a) = (&pool[l_ip as usize], &pool[a_pj as usize]);
                    subtract_product(&mut diagonal[i as usize], l, a);
                } else {
                    subtract_in_pool(pool, target as usize, l_ip as usize, a_pj as usize);
                }
            }
        }
        Ok(())
    }

    /// `y ← A⁻¹ y` with the factorization, in place (forward elimination, then back
    /// substitution: a body's entry is read for the last time just before its solution
    /// replaces it).
    pub(crate) fn solve_in_place(&self, y: &mut [f64]) {
        for pivot in &self.pivots {
            let p = pivot.body as usize;
            let yp: [f64; 6] = y[6 * p..6 * p + 6].try_into().expect("six entries");
            for &(i, l) in &self.pivot_entries[pivot.lower as usize..pivot.end as usize] {
                let i = i as usize;
                let d = block_mul(&self.pool[l as usize], &yp);
                for (a, b) in y[6 * i..6 * i + 6].iter_mut().zip(d) {
                    *a -= b;
                }
            }
        }
        for pivot in self.pivots.iter().rev() {
            let p = pivot.body as usize;
            let mut r: [f64; 6] = y[6 * p..6 * p + 6].try_into().expect("six entries");
            for &(j, a) in &self.pivot_entries[pivot.upper as usize..pivot.lower as usize] {
                let j = j as usize;
                let d = block_mul(&self.pool[a as usize], &y[6 * j..6 * j + 6]);
                for (x, b) in r.iter_mut().zip(d) {
                    *x -= b;
                }
            }
            y[6 * p..6 * p + 6].copy_from_slice(&block_mul(&self.diagonal[p], &r));
        }
    }

    /// `out = A⁻¹ u` with the factorization ([`Self::solve_in_place`] on a copy).
    #[cfg(test)]
    pub(crate) fn solve(&self, u: &[f64], out: &mut [f64]) {
        out.copy_from_slice(u);
        self.solve_in_place(out);
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
            lu.reset(diagonal.clone());
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
            // `analyze` counted the fill exactly: the pool was sized once.
            assert_eq!(lu.pool.len(), lu.pool.capacity(), "{width}×{height}");
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

    /// A chain's elimination (leaves first) makes no fill: its factorization holds the two
    /// blocks of each link and nothing else, and a second factorization of the same pattern
    /// reuses that storage.
    #[test]
    fn a_chain_is_factored_without_fill_in_its_own_blocks() {
        let n = 50;
        let diagonal: Vec<Block> = (0..n).map(|i| block(i as u64, true)).collect();
        let mut lu = BlockLu::default();
        for round in 0..2 {
            lu.reset(diagonal.clone());
            for i in 1..n {
                lu.add(i - 1, i, &block(1000 + i as u64, false));
                lu.add(i, i - 1, &block(2000 + i as u64, false));
            }
            if round == 0 {
                lu.analyze();
            }
            let capacity = lu.pool.capacity();
            lu.factor().expect("diagonally dominant");
            assert_eq!(lu.pool.len(), 2 * (n - 1), "round {round}: fill on a chain");
            assert_eq!(
                lu.pool.capacity(),
                capacity,
                "round {round}: the factorization grew"
            );
            let entries = lu.pivot_entries.len();
            assert_eq!(entries, 2 * (n - 1), "round {round}");
        }
    }

    #[test]
    fn a_singular_pivot_is_reported() {
        let mut lu = BlockLu::default();
        lu.reset(vec![[[0.0; 6]; 6]]);
        lu.analyze();
        assert_eq!(lu.factor(), Err(SingularPivot));
    }
}
