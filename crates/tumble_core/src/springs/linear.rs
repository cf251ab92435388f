//! The linear algebra of the implicit spring step: 6×6 block inverses (the block-Jacobi
//! preconditioner) and BiCGSTAB (the Newton system is not symmetric: the gyroscopic block is not).
//!
//! Hand-written because the systems are small, sparse and matrix-free (the operator is applied
//! spring by spring), and a dependency on a general sparse solver would be heavier than these
//! hundred lines.

/// A 6×6 matrix, row-major.
pub(crate) type Block = [[f64; 6]; 6];

/// Inverts `m` by Gauss–Jordan elimination with partial pivoting, in place; `None` if singular.
///
/// In place: the column of the identity that a step would fill is the column it empties, so
/// the pivot row is scaled and subtracted over six entries instead of twelve (half the work
/// of eliminating on `[m | 1]`), and the row exchanges become column exchanges of the result,
/// undone at the end. Each column's step is compiled with the column a constant
/// ([`eliminate`]), so the compiler unrolls and vectorizes every row operation and skips the
/// pivot row without a branch, which a loop over the columns (the column a variable) does not
/// (the Newton solve of a spring group inverts one block per body and factorization).
pub(crate) fn invert(m: &Block) -> Option<Block> {
    let mut inverse = [[0.0; 6]; 6];
    invert_into(m, &mut inverse).then_some(inverse)
}

/// [`invert`] into `inverse` (the factorization's pivots, written where they are kept rather
/// than moved there); false, `inverse` unspecified, if `m` is singular.
pub(crate) fn invert_into(m: &Block, inverse: &mut Block) -> bool {
    let a = inverse;
    *a = *m;
    let mut swapped = [0usize; 6];
    let eliminated = eliminate::<0>(a, &mut swapped).is_some()
        && eliminate::<1>(a, &mut swapped).is_some()
        && eliminate::<2>(a, &mut swapped).is_some()
        && eliminate::<3>(a, &mut swapped).is_some()
        && eliminate::<4>(a, &mut swapped).is_some()
        && eliminate::<5>(a, &mut swapped).is_some();
    if !eliminated {
        return false;
    }
    for col in (0..6).rev() {
        let other = swapped[col];
        if other != col {
            for row in a.iter_mut() {
                row.swap(col, other);
            }
        }
    }
    true
}

/// Step `COL` of [`invert`]: picks the pivot of column `COL` (the largest of its rows from
/// `COL` on), moves it to row `COL`, scales that row and subtracts it from the other five;
/// `None` if the column has no usable pivot.
#[inline(always)]
fn eliminate<const COL: usize>(a: &mut Block, swapped: &mut [usize; 6]) -> Option<()> {
    let mut pivot = COL;
    let mut best = a[COL][COL].abs();
    for (r, row) in a.iter().enumerate().skip(COL + 1) {
        if row[COL].abs() > best {
            best = row[COL].abs();
            pivot = r;
        }
    }
    if !(best > 0.0 && best.is_finite()) {
        return None;
    }
    a.swap(COL, pivot);
    swapped[COL] = pivot;
    let scale = 1.0 / a[COL][COL];
    let mut pivot_row = a[COL];
    pivot_row[COL] = 1.0;
    for x in &mut pivot_row {
        *x *= scale;
    }
    for (r, row) in a.iter_mut().enumerate() {
        if r == COL {
            continue;
        }
        let f = row[COL];
        row[COL] = 0.0;
        for (x, p) in row.iter_mut().zip(&pivot_row) {
            *x -= f * p;
        }
    }
    a[COL] = pivot_row;
    Some(())
}

/// `m x` for a 6×6 block.
#[inline]
pub(crate) fn block_mul(m: &Block, x: &[f64]) -> [f64; 6] {
    let mut y = [0.0; 6];
    for (yi, row) in y.iter_mut().zip(m) {
        *yi = row.iter().zip(x).map(|(a, b)| a * b).sum();
    }
    y
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// Scratch vectors of BiCGSTAB, kept between solves so a step does not allocate.
#[derive(Debug, Default, Clone)]
pub(crate) struct Krylov {
    r: Vec<f64>,
    r0: Vec<f64>,
    p: Vec<f64>,
    v: Vec<f64>,
    s: Vec<f64>,
    t: Vec<f64>,
    y: Vec<f64>,
    z: Vec<f64>,
}

impl Krylov {
    /// Solves `A x = b` by right-preconditioned BiCGSTAB (van der Vorst 1992), starting from
    /// `x = 0`, until `|r| ≤ tol |b|` or `max_iterations`. `apply(u, out)` computes `out = A u`,
    /// `precondition(u, out)` computes `out ≈ A⁻¹ u`. Returns the iterations taken.
    pub(crate) fn solve(
        &mut self,
        b: &[f64],
        x: &mut [f64],
        tol: f64,
        max_iterations: usize,
        mut apply: impl FnMut(&[f64], &mut [f64]),
        mut precondition: impl FnMut(&[f64], &mut [f64]),
    ) -> usize {
        let n = b.len();
        for buffer in [
            &mut self.r,
            &mut self.r0,
            &mut self.p,
            &mut self.v,
            &mut self.s,
            &mut self.t,
            &mut self.y,
            &mut self.z,
        ] {
            buffer.clear();
            buffer.resize(n, 0.0);
        }
        x.fill(0.0);
        self.r.copy_from_slice(b);
        self.r0.copy_from_slice(b);
        let target = tol * dot(b, b).sqrt();
        if target == 0.0 {
            return 0;
        }
        let (mut rho, mut alpha, mut omega) = (1.0, 1.0, 1.0);
        for iteration in 1..=max_iterations {
            let rho_next = dot(&self.r0, &self.r);
            if rho_next == 0.0 || !rho_next.is_finite() {
                return iteration;
            }
            let beta = (rho_next / rho) * (alpha / omega);
            rho = rho_next;
            for i in 0..n {
                self.p[i] = self.r[i] + beta * (self.p[i] - omega * self.v[i]);
            }
            precondition(&self.p, &mut self.y);
            apply(&self.y, &mut self.v);
            let r0v = dot(&self.r0, &self.v);
            if r0v == 0.0 || !r0v.is_finite() {
                return iteration;
            }
            alpha = rho / r0v;
            for i in 0..n {
                self.s[i] = self.r[i] - alpha * self.v[i];
            }
            if dot(&self.s, &self.s).sqrt() <= target {
                for (xi, yi) in x.iter_mut().zip(&self.y) {
                    *xi += alpha * yi;
                }
                return iteration;
            }
            precondition(&self.s, &mut self.z);
            apply(&self.z, &mut self.t);
            let tt = dot(&self.t, &self.t);
            omega = if tt > 0.0 {
                dot(&self.t, &self.s) / tt
            } else {
                0.0
            };
            for (i, xi) in x.iter_mut().enumerate() {
                *xi += alpha * self.y[i] + omega * self.z[i];
                self.r[i] = self.s[i] - omega * self.t[i];
            }
            if dot(&self.r, &self.r).sqrt() <= target || omega == 0.0 {
                return iteration;
            }
        }
        max_iterations
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn block_inverse_times_block_is_the_identity() {
        let mut m = [[0.0; 6]; 6];
        for (i, row) in m.iter_mut().enumerate() {
            for (j, v) in row.iter_mut().enumerate() {
                *v = if i == j {
                    4.0 + i as f64
                } else {
                    0.3 * (i as f64 - j as f64)
                };
            }
        }
        // Zeros on the diagonal make every column pivot.
        m[0][0] = 0.0;
        m[3][3] = 0.0;
        let inv = invert(&m).unwrap();
        for j in 0..6 {
            let column: Vec<f64> = inv.iter().map(|row| row[j]).collect();
            let e = block_mul(&m, &column);
            for (i, v) in e.iter().enumerate() {
                let want = if i == j { 1.0 } else { 0.0 };
                assert!((v - want).abs() < 1e-14, "{i},{j}: {v}");
            }
        }
        assert!(invert(&[[0.0; 6]; 6]).is_none());
    }

    /// A non-symmetric, diagonally dominant tridiagonal system is solved to the tolerance.
    #[test]
    fn bicgstab_solves_a_nonsymmetric_system() {
        let n = 60;
        let apply = |u: &[f64], out: &mut [f64]| {
            for i in 0..n {
                let left = if i > 0 { -u[i - 1] } else { 0.0 };
                let right = if i + 1 < n { -0.5 * u[i + 1] } else { 0.0 };
                out[i] = 3.0 * u[i] + left + right;
            }
        };
        let want: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin()).collect();
        let mut b = vec![0.0; n];
        apply(&want, &mut b);
        let mut x = vec![0.0; n];
        let mut krylov = Krylov::default();
        let iterations = krylov.solve(&b, &mut x, 1e-12, 200, apply, |u, out| {
            out.copy_from_slice(u)
        });
        assert!(iterations < 200);
        for (a, b) in x.iter().zip(&want) {
            assert!((a - b).abs() < 1e-10, "{a} vs {b}");
        }
    }
}
