//! A small LU with threshold partial pivoting on preallocated row-major buffers, for the
//! 10-100 unknowns of the stage equations, which exploits their sparsity.
//!
//! The Jacobian of the stage equations is mostly zeros (for the (2,2) scheme on a double
//! pendulum, 90 of 400 entries are nonzero: identity blocks, the sparse `Phi_q` and the
//! constraint curvature). Three things keep the work proportional to the nonzeros:
//! - a fixed symmetric ordering chosen by the caller ([`SmallLu::with_ordering`]): the
//!   Galerkin scheme puts the `s` displacement unknowns of each coordinate together (their
//!   block of the Jacobian is `s x s` when the Hessians are sparse) and the multipliers last, so
//!   the elimination of the displacements fills in little and leaves a small Schur complement
//!   on the multipliers;
//! - threshold pivoting: the diagonal pivot is kept unless another entry of its column is more
//!   than `1 / PIVOT_THRESHOLD` times larger (then the largest is taken, as in partial
//!   pivoting); this keeps the ordering while bounding the growth of the factors (the usual
//!   compromise of sparse LU codes);
//! - the elimination updates a row only in the columns where the pivot row is nonzero, and
//!   [`SmallLu::factor`] records the nonzero pattern of `L` and `U` so that [`SmallLu::solve`]
//!   touches only those entries.

/// A diagonal pivot is kept if it is at least this fraction of the largest entry of its column.
const PIVOT_THRESHOLD: f64 = 0.1;

/// LU of an `n x n` matrix with a fixed row and column ordering.
///
/// The caller writes the matrix in its own numbering through [`SmallLu::entry`] (after
/// [`SmallLu::clear`]); it is stored in the ordered numbering, row-major. Row interchanges are
/// kept in a permutation vector (rows never move in memory), so the nonzero lists recorded
/// during the elimination (`L` by columns, `U` by rows) stay valid for [`SmallLu::solve`].
#[derive(Clone, Debug)]
pub(crate) struct SmallLu {
    n: usize,
    /// `rows[i]`: the caller's row stored at row `i` of the ordered matrix.
    rows: Vec<usize>,
    /// `cols[j]`: the caller's column (unknown) at column `j` of the ordered matrix.
    cols: Vec<usize>,
    /// Inverse of `rows` / `cols`.
    rpos: Vec<usize>,
    cpos: Vec<usize>,
    /// The ordered matrix (row-major), factored in place: multipliers below and `U` on and
    /// above the diagonal, each in the (physical) row it was computed in.
    f: Vec<f64>,
    /// `rp[k]`: the physical row of the `k`-th pivot.
    rp: Vec<usize>,
    /// Physical rows with a nonzero multiplier in column `k` (`l_start` delimits columns).
    l_idx: Vec<usize>,
    l_start: Vec<usize>,
    /// Nonzero columns right of the diagonal of the `k`-th pivot row, and their values.
    u_idx: Vec<usize>,
    u_val: Vec<f64>,
    u_start: Vec<usize>,
    /// Scratch vectors of the solve.
    y: Vec<f64>,
    x: Vec<f64>,
}

impl SmallLu {
    /// An LU of `n x n` matrices in the natural ordering.
    #[cfg(test)]
    pub fn new(n: usize) -> Self {
        Self::with_ordering((0..n).collect(), (0..n).collect())
    }

    /// An LU that factors `P_r A P_c` where row `i` of the ordered matrix is row `rows[i]` of
    /// `A` and column `j` is column `cols[j]`. Both must be permutations of `0..n`.
    pub fn with_ordering(rows: Vec<usize>, cols: Vec<usize>) -> Self {
        let n = rows.len();
        debug_assert_eq!(cols.len(), n);
        let mut rpos = vec![0; n];
        let mut cpos = vec![0; n];
        for (i, &r) in rows.iter().enumerate() {
            rpos[r] = i;
        }
        for (j, &c) in cols.iter().enumerate() {
            cpos[c] = j;
        }
        SmallLu {
            n,
            rows,
            cols,
            rpos,
            cpos,
            f: vec![0.0; n * n],
            rp: (0..n).collect(),
            l_idx: vec![0; n * n],
            l_start: vec![0; n + 1],
            u_idx: vec![0; n * n],
            u_val: vec![0.0; n * n],
            u_start: vec![0; n + 1],
            y: vec![0.0; n],
            x: vec![0.0; n],
        }
    }

    /// Sets the matrix to zero (before it is written by [`SmallLu::entry`]).
    pub fn clear(&mut self) {
        self.f.fill(0.0);
    }

    /// The entry `(r, c)` of the matrix, in the caller's numbering.
    #[inline]
    pub fn entry(&mut self, r: usize, c: usize) -> &mut f64 {
        &mut self.f[self.rpos[r] * self.n + self.cpos[c]]
    }

    /// Factors the matrix in place; `Err(i)` if pivot `i` (in the ordered numbering) is
    /// negligible.
    pub fn factor(&mut self) -> Result<(), usize> {
        let n = self.n;
        let a = &mut self.f;
        let mut mx = [0.0f64; 4];
        let chunks = a.chunks_exact(4);
        let rest = chunks.remainder();
        for c in chunks {
            for (m, x) in mx.iter_mut().zip(c) {
                *m = m.max(x.abs());
            }
        }
        for x in rest {
            mx[0] = mx[0].max(x.abs());
        }
        let scale = mx[0].max(mx[1]).max(mx[2].max(mx[3]));
        let tol = 1e-14 * scale.max(f64::MIN_POSITIVE) * n as f64;
        for (k, r) in self.rp.iter_mut().enumerate() {
            *r = k;
        }
        let (mut nl, mut nu) = (0, 0);
        for k in 0..n {
            let diag = a[self.rp[k] * n + k].abs();
            let mut p = k;
            let mut best = diag;
            for i in k + 1..n {
                let v = a[self.rp[i] * n + k].abs();
                if v > best {
                    best = v;
                    p = i;
                }
            }
            if best.is_nan() || best <= tol {
                return Err(k);
            }
            if diag < PIVOT_THRESHOLD * best {
                self.rp.swap(k, p);
            }
            let pk = self.rp[k];
            // the nonzeros of the pivot row right of the diagonal: the row of U
            self.u_start[k] = nu;
            for (j, &v) in a[pk * n..(pk + 1) * n].iter().enumerate().skip(k + 1) {
                if v != 0.0 {
                    self.u_idx[nu] = j;
                    self.u_val[nu] = v;
                    nu += 1;
                }
            }
            let (uc, uv) = (
                &self.u_idx[self.u_start[k]..nu],
                &self.u_val[self.u_start[k]..nu],
            );
            let inv = 1.0 / a[pk * n + k];
            self.l_start[k] = nl;
            for &ph in &self.rp[k + 1..] {
                let row = &mut a[ph * n..(ph + 1) * n];
                let f = row[k];
                if f != 0.0 {
                    let f = f * inv;
                    row[k] = f;
                    for (&j, &v) in uc.iter().zip(uv) {
                        row[j] -= f * v;
                    }
                    self.l_idx[nl] = ph;
                    nl += 1;
                }
            }
        }
        self.l_start[n] = nl;
        self.u_start[n] = nu;
        Ok(())
    }

    /// Solves `A x = b` in place after [`SmallLu::factor`] (`b` and `x` in the caller's
    /// numbering).
    pub fn solve(&mut self, b: &mut [f64]) {
        let n = self.n;
        let a = &self.f;
        let (y, x) = (&mut self.y, &mut self.x);
        for (yi, &r) in y.iter_mut().zip(&self.rows) {
            *yi = b[r];
        }
        // forward: L z = P y, column by column (z_k ends in y[rp[k]])
        for k in 0..n {
            let yk = y[self.rp[k]];
            if yk != 0.0 {
                for &ph in &self.l_idx[self.l_start[k]..self.l_start[k + 1]] {
                    y[ph] -= a[ph * n + k] * yk;
                }
            }
        }
        // backward: U x = z, row by row
        for k in (0..n).rev() {
            let (lo, hi) = (self.u_start[k], self.u_start[k + 1]);
            let mut s = 0.0;
            for (&j, &v) in self.u_idx[lo..hi].iter().zip(&self.u_val[lo..hi]) {
                s += v * x[j];
            }
            let pk = self.rp[k];
            x[k] = (y[pk] - s) / a[pk * n + k];
        }
        for (&xj, &c) in x.iter().zip(&self.cols) {
            b[c] = xj;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fill(lu: &mut SmallLu, a: &[f64]) {
        let n = lu.n;
        lu.clear();
        for i in 0..n {
            for j in 0..n {
                *lu.entry(i, j) = a[i * n + j];
            }
        }
    }

    #[test]
    fn solves_with_pivoting() {
        let mut lu = SmallLu::new(3);
        let a = [0.0, 2.0, 1.0, 1.0, 1.0, 0.0, 3.0, 0.0, 1.0];
        fill(&mut lu, &a);
        lu.factor().unwrap();
        let x = [1.0, -2.0, 0.5];
        let mut b: Vec<f64> = (0..3)
            .map(|i| (0..3).map(|j| a[i * 3 + j] * x[j]).sum())
            .collect();
        lu.solve(&mut b);
        for i in 0..3 {
            assert!((b[i] - x[i]).abs() < 1e-14);
        }
        let mut s = SmallLu::new(2);
        fill(&mut s, &[1.0, 2.0, 2.0, 4.0]);
        assert!(s.factor().is_err());
    }

    /// Sparse matrices with fill-in and pivoting: the solution satisfies `A x = b`.
    #[test]
    fn solves_sparse_systems_with_fill_in() {
        for (n, seed) in [(7usize, 1u64), (20, 2), (31, 3)] {
            let mut state = seed;
            let mut rnd = || {
                state = state
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                ((state >> 11) as f64) / ((1u64 << 53) as f64)
            };
            // a scrambled ordering: reversed rows, rotated columns
            let mut lu = SmallLu::with_ordering(
                (0..n).rev().collect(),
                (0..n).map(|j| (j + 3) % n).collect(),
            );
            let mut a = vec![0.0; n * n];
            for i in 0..n {
                for j in 0..n {
                    // a sparse pattern plus a permuted diagonal (the system stays regular)
                    a[i * n + j] = if rnd() < 0.2 { rnd() - 0.5 } else { 0.0 };
                }
                a[i * n + (i * 3 + 1) % n] += 2.0;
            }
            fill(&mut lu, &a);
            lu.factor().unwrap();
            let x: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin()).collect();
            let mut b: Vec<f64> = (0..n)
                .map(|i| (0..n).map(|j| a[i * n + j] * x[j]).sum())
                .collect();
            lu.solve(&mut b);
            for i in 0..n {
                assert!(
                    (b[i] - x[i]).abs() < 1e-12,
                    "n = {n}: x[{i}] off by {:e}",
                    b[i] - x[i]
                );
            }
        }
    }
}
