//! The factors of [`super::SparseLu`] in its own storage: a copy of faer's simplicial `L` and
//! `U` after a factorisation with partial pivoting, the triangular solves over them, and the
//! refactorisation of new values along the same pivot sequence (no search for pivots, no
//! depth-first search for the pattern).
//!
//! Layout (faer's): `P A Q = L U` with rows and columns numbered in pivot order. Column `j` of
//! `L` starts with its unit diagonal, then the rows below it; column `j` of `U` holds the rows
//! above the diagonal in an order in which each row's value is final before it is used (the
//! topological order of the depth-first search that found them), then the diagonal.
//!
//! **Refactorisation.** With the pivot sequence fixed, column `j` of the factors is the
//! left-looking elimination of column `Q_j` of the new matrix: scatter it into a dense work
//! vector in pivot order, subtract `L_k u_kj` for each `k` of `U`'s column in the stored order,
//! read `U`'s column and the pivot off the work vector and divide the rest by the pivot. The
//! pattern of that elimination depends only on the pattern of `A` and the pivot sequence, so it
//! is the stored one (faer keeps every structural entry, zero or not). A pivot smaller than
//! [`REFACTOR_PIVOT_RATIO`] times the largest entry below it in its column (threshold partial
//! pivoting) or not finite rejects the refactorisation: the caller then factors afresh with
//! pivoting.

use faer::sparse::linalg::lu::simplicial::SimplicialLu;

/// A refactorisation's pivot must be at least this fraction of the largest entry below it in
/// its column (the threshold of threshold partial pivoting: growth per column at most
/// `1 / REFACTOR_PIVOT_RATIO`); else the matrix is factored afresh with partial pivoting.
pub const REFACTOR_PIVOT_RATIO: f64 = 0.1;

/// `L` and `U` in compressed columns, in pivot order, and a work vector.
#[derive(Debug, Default)]
pub(crate) struct LuFactors {
    l_ptr: Vec<usize>,
    l_idx: Vec<u32>,
    l_val: Vec<f64>,
    u_ptr: Vec<usize>,
    u_idx: Vec<u32>,
    u_val: Vec<f64>,
    work: Vec<f64>,
    /// Whether the storage holds the factors of a successful factorisation.
    valid: bool,
}

impl LuFactors {
    /// Storage for an `n x n` matrix (the work vector; the factors grow at the first copy).
    pub(crate) fn new(n: usize) -> Self {
        LuFactors {
            work: vec![0.0; n],
            ..Default::default()
        }
    }

    /// Entries of `L` and `U` (0 before the first copy).
    pub(crate) fn nnz(&self) -> usize {
        if self.valid {
            self.l_val.len() + self.u_val.len()
        } else {
            0
        }
    }

    /// Copies faer's factors (after a successful factorisation). Reuses the storage; it grows
    /// only when a new pivot sequence fills more than every earlier one.
    pub(crate) fn copy_from(&mut self, lu: &SimplicialLu<usize, f64>) {
        let (l, u) = (lu.l_factor_unsorted(), lu.u_factor_unsorted());
        copy_csc(
            l.col_ptr(),
            l.row_idx(),
            l.val(),
            (&mut self.l_ptr, &mut self.l_idx, &mut self.l_val),
        );
        copy_csc(
            u.col_ptr(),
            u.row_idx(),
            u.val(),
            (&mut self.u_ptr, &mut self.u_idx, &mut self.u_val),
        );
        self.valid = true;
    }

    /// Refactors along the stored pivot sequence: column `j` eliminates column `col_perm[j]`
    /// of the matrix `(col_ptr, row_idx, vals)`, whose row `r` is pivot row `row_perm_inv[r]`.
    /// Returns `false` (the factors are then invalid) when a pivot fails the threshold test,
    /// is at most `pivot_floor` in magnitude, or is not finite.
    pub(crate) fn refactor(
        &mut self,
        (col_ptr, row_idx, vals): (&[usize], &[usize], &[f64]),
        col_perm: &[usize],
        row_perm_inv: &[usize],
        pivot_floor: f64,
    ) -> bool {
        if !self.valid {
            return false;
        }
        self.valid = false;
        let w = &mut self.work;
        for (j, &c) in col_perm.iter().enumerate() {
            for k in col_ptr[c]..col_ptr[c + 1] {
                w[row_perm_inv[row_idx[k]]] = vals[k];
            }
            let (u0, u1) = (self.u_ptr[j], self.u_ptr[j + 1]);
            // the rows above the diagonal, in an order in which each is final when used
            for p in u0..u1 - 1 {
                let k = self.u_idx[p] as usize;
                let ukj = w[k];
                self.u_val[p] = ukj;
                w[k] = 0.0;
                if ukj != 0.0 {
                    let (l0, l1) = (self.l_ptr[k] + 1, self.l_ptr[k + 1]);
                    for (&i, &l) in self.l_idx[l0..l1].iter().zip(&self.l_val[l0..l1]) {
                        w[i as usize] -= l * ukj;
                    }
                }
            }
            let pivot = w[j];
            w[j] = 0.0;
            let (l0, l1) = (self.l_ptr[j] + 1, self.l_ptr[j + 1]);
            // one pass: L's column divided by the pivot, the work vector cleared, and the
            // largest multiplier, which the threshold test bounds by 1 / REFACTOR_PIVOT_RATIO
            // (|l_ij| <= 1 / ratio is |pivot| >= ratio |w_i|)
            let inv = pivot.recip();
            let mut largest = 0.0f64;
            for (&i, l) in self.l_idx[l0..l1].iter().zip(&mut self.l_val[l0..l1]) {
                *l = w[i as usize] * inv;
                w[i as usize] = 0.0;
                largest = largest.max(l.abs());
            }
            let ok = pivot.is_finite()
                && pivot.abs() > pivot_floor
                && largest.is_finite()
                && largest * REFACTOR_PIVOT_RATIO <= 1.0;
            if !ok {
                return false;
            }
            self.u_val[u1 - 1] = pivot;
        }
        self.valid = true;
        true
    }

    /// Solves `L U y = y` in place (`y` in pivot order).
    pub(crate) fn solve_in_place(&self, y: &mut [f64]) {
        solve_with(
            (&self.l_ptr, &self.l_idx, &self.l_val),
            (&self.u_ptr, &self.u_idx, &self.u_val),
            y,
        );
    }
}

/// Solves `L U y = y` in place over the compressed columns of `L` and `U`.
pub(crate) fn solve_with(
    (l_ptr, l_idx, l_val): (&[usize], &[u32], &[f64]),
    (u_ptr, u_idx, u_val): (&[usize], &[u32], &[f64]),
    y: &mut [f64],
) {
    let n = l_ptr.len().saturating_sub(1);
    for j in 0..n {
        let yj = y[j];
        let (l0, l1) = (l_ptr[j] + 1, l_ptr[j + 1]);
        for (&i, &l) in l_idx[l0..l1].iter().zip(&l_val[l0..l1]) {
            y[i as usize] -= l * yj;
        }
    }
    // (columns last to first, and each column's entries last to first: the factor is read
    // as one descending stream, which the hardware prefetcher follows, where a zig-zag of
    // forward reads within backward columns defeats it on factors larger than the cache)
    for j in (0..n).rev() {
        let (u0, u1) = (u_ptr[j], u_ptr[j + 1]);
        let yj = y[j] * u_val[u1 - 1].recip();
        y[j] = yj;
        for (&k, &u) in u_idx[u0..u1 - 1]
            .iter()
            .rev()
            .zip(u_val[u0..u1 - 1].iter().rev())
        {
            y[k as usize] -= u * yj;
        }
    }
}

/// Copies a compressed-column matrix into `(ptr, idx, val)`, reusing their storage.
fn copy_csc(
    ptr: &[usize],
    idx: &[usize],
    val: &[f64],
    (p, i, v): (&mut Vec<usize>, &mut Vec<u32>, &mut Vec<f64>),
) {
    let nnz = ptr.last().copied().unwrap_or(0);
    // room for twice the fill on growth: a later pivot sequence that fills a little more
    // (after a refactorisation is rejected) then needs no allocation
    if i.capacity() < nnz {
        i.reserve_exact(2 * nnz - i.len());
        v.reserve_exact(2 * nnz - v.len());
    }
    p.clear();
    p.extend_from_slice(ptr);
    i.clear();
    // (the dimension fits in u32: checked when the pattern is analysed)
    i.extend(idx[..nnz].iter().map(|&x| x as u32));
    v.clear();
    v.extend_from_slice(&val[..nnz]);
}
