//! Sparse LU factorisation on a fixed pattern (faer's simplicial left-looking LU with partial
//! pivoting, columns in a COLAMD order), with power-of-two equilibration and a scale-invariant
//! pivot test.

use super::lu_factors::LuFactors;
pub use super::lu_factors::REFACTOR_PIVOT_RATIO;
use crate::{pow2_inverse, LinalgError, LuError, Scratch};
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::perm::PermRef;
use faer::sparse::linalg::amd;
use faer::sparse::linalg::lu::simplicial::{
    factorize_simplicial_numeric_lu, factorize_simplicial_numeric_lu_scratch, SimplicialLu,
};
use faer::sparse::linalg::lu::{factorize_symbolic_lu, LuSymbolicParams};
use faer::sparse::linalg::{LuError as FaerLuError, SupernodalThreshold};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat, SymbolicSparseColMatRef};

/// A pivot of the equilibrated matrix at most this (times the dimension) counts as zero.
pub const SPARSE_PIVOT_TOL: f64 = 1e-14;

/// Square-root (Ruiz) equilibration sweeps before the final row and column scaling (one
/// suffices for the stage matrices and for the unit tests' rows and columns scaled by up to
/// 1e+-12; each sweep costs two passes over the entries, a sizeable part of a factorisation).
const EQUILIBRATION_SWEEPS: usize = 1;

/// A general square `n x n` matrix on a fixed sparsity pattern, and its LU factorisation.
///
/// The pattern is given once to [`SparseLu::new`], which computes a fill-reducing column order
/// (COLAMD) and allocates every buffer. A caller then writes values through
/// [`SparseLu::slot`] / [`SparseLu::values_mut`], calls [`SparseLu::factor`] and
/// [`SparseLu::solve_in_place`]. The first numeric factorisation is faer's simplicial
/// left-looking LU with partial pivoting. Every later one first refactors the new values along
/// that pivot sequence (no pivot search and no search for the pattern, which the pivot sequence
/// and the pattern of `A` fix); a pivot below [`REFACTOR_PIVOT_RATIO`] times the largest entry
/// under it in its column, or below the singularity floor, rejects the refactorisation, and the
/// matrix is factored afresh with partial pivoting (whose pivot sequence the next
/// refactorisation follows). The factors live in storage that is reused from one factorisation
/// to the next, so after the first factorisation neither `factor` nor `solve_in_place`
/// allocates (unless a new pivot sequence fills more than twice the first one).
///
/// **Equilibration and singularity test.** The matrix factored is `D_r A D_c`: every row,
/// then every column of the row-scaled matrix, is scaled by the power of two that brings its
/// largest entry into `[1, 2)` (exact: no rounding), after a sweep of the same
/// alternation with square roots of the maxima (Ruiz's scaling, which balances rows against
/// columns when both are badly scaled). The pivots are then chosen by magnitude in
/// that matrix (scaled partial pivoting), and a pivot `|u_jj| <= pivot_tol n` means a singular
/// matrix, whatever the units of the equations and unknowns. The error names the original row
/// and column of the failing pivot. The solve undoes the scaling (`x = D_c y`,
/// `D_r A D_c y = D_r b`).
///
/// ```
/// use mbd_linalg::SparseLu;
/// // [[0, 2, 0], [1, 0, 3], [0, 4, 5]]
/// let entries = [(0, 1, 2.0), (1, 0, 1.0), (1, 2, 3.0), (2, 1, 4.0), (2, 2, 5.0)];
/// let pattern: Vec<(usize, usize)> = entries.iter().map(|&(r, c, _)| (r, c)).collect();
/// let mut lu = SparseLu::new(3, &pattern)?;
/// for (r, c, v) in entries {
///     let k = lu.slot(r, c).expect("in the pattern");
///     lu.values_mut()[k] = v;
/// }
/// lu.factor()?;
/// let mut b = [2.0, 4.0, 9.0]; // A [1, 1, 1]
/// lu.solve_in_place(&mut b);
/// assert!(b.iter().all(|x| (x - 1.0).abs() < 1e-14));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug)]
pub struct SparseLu {
    n: usize,
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    values: Vec<f64>,
    scaled: Vec<f64>,
    rscale: Vec<f64>,
    cscale: Vec<f64>,
    rmax: Vec<f64>,
    /// Column order: pivot `j` eliminates original column `col_perm[j]`.
    col_perm: Vec<usize>,
    col_perm_inv: Vec<usize>,
    /// Row order of the last factorisation: pivot `j` is original row `row_perm[j]`.
    row_perm: Vec<usize>,
    row_perm_inv: Vec<usize>,
    lu: SimplicialLu<usize, f64>,
    /// The factors in this type's storage (solves and refactorisations along the last pivot
    /// sequence, `lu_factors.rs`), and the permuted right-hand side of a solve.
    factors: LuFactors,
    y: Vec<f64>,
    mem: Scratch,
    factored: bool,
    factorizations: usize,
    /// Factorisations done afresh with partial pivoting (the rest were refactorisations).
    pivoted: usize,
    /// Relative pivot threshold of the equilibrated matrix (default [`SPARSE_PIVOT_TOL`]).
    pub pivot_tol: f64,
}

/// The approximate-minimum-degree order of the pattern of `A + A^T` (faer's AMD), as
/// (forward, inverse) permutations.
fn symmetric_amd(
    a: SymbolicSparseColMatRef<'_, usize>,
) -> Result<(Vec<usize>, Vec<usize>), LinalgError> {
    let n = a.ncols();
    let (mut perm, mut perm_inv) = (vec![0usize; n], vec![0usize; n]);
    let req = amd::order_scratch::<usize>(n, a.compute_nnz());
    let mut mem = MemBuffer::try_new(req)
        .map_err(|_| LinalgError::Analysis("sparse LU: no memory for the AMD order".into()))?;
    amd::order(
        &mut perm,
        &mut perm_inv,
        a,
        amd::Control::default(),
        MemStack::new(&mut mem),
    )
    .map_err(|e| LinalgError::Analysis(format!("sparse LU: the AMD order failed: {e:?}")))?;
    Ok((perm, perm_inv))
}

/// The fill-reducing column order [`SparseLu`] computes from the pattern.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[non_exhaustive]
pub enum ColumnOrder {
    /// COLAMD on the pattern of `A` (the default): an order for `A`'s columns that bounds the
    /// fill of `U` (and of `L` under any row pivoting), suited to unsymmetric patterns.
    #[default]
    Colamd,
    /// Approximate minimum degree on the pattern of `A + A^T`: the order a symmetric
    /// factorisation would use. Where the pattern is symmetric and the pivots mostly stay on
    /// the diagonal (a saddle-point matrix whose blocks are all sparse), it can fill much less
    /// than COLAMD; where partial pivoting leaves the diagonal it can fill much more.
    SymmetricAmd,
}

impl SparseLu {
    /// Analyses the pattern: `n` unknowns, entries `(row, col)` (repeats are merged), columns
    /// in the [`ColumnOrder::Colamd`] order. Allocates; done once per pattern.
    pub fn new(n: usize, entries: &[(usize, usize)]) -> Result<Self, LinalgError> {
        Self::with_order(n, entries, ColumnOrder::Colamd)
    }

    /// [`SparseLu::new`] with the column order `order`.
    pub fn with_order(
        n: usize,
        entries: &[(usize, usize)],
        order: ColumnOrder,
    ) -> Result<Self, LinalgError> {
        if u32::try_from(n).is_err() {
            // (the factors store their row indices as u32, half the memory traffic of a solve)
            return Err(LinalgError::Analysis(format!(
                "sparse LU: dimension {n} above the largest supported, {}",
                u32::MAX
            )));
        }
        let mut e: Vec<(usize, usize)> = Vec::with_capacity(entries.len());
        for &(r, c) in entries {
            if r >= n || c >= n {
                return Err(LinalgError::PatternEntry {
                    what: "sparse LU pattern entry",
                    dim: n,
                    index: r.max(c),
                });
            }
            e.push((c, r));
        }
        e.sort_unstable();
        e.dedup();
        let mut col_ptr = vec![0usize; n + 1];
        let mut row_idx = Vec::with_capacity(e.len());
        for &(c, r) in &e {
            col_ptr[c + 1] += 1;
            row_idx.push(r);
        }
        for c in 0..n {
            col_ptr[c + 1] += col_ptr[c];
        }
        let (col_perm, col_perm_inv) = if n == 0 {
            (Vec::new(), Vec::new())
        } else {
            let sym = SymbolicSparseColMat::<usize>::new_checked(
                n,
                n,
                col_ptr.clone(),
                None,
                row_idx.clone(),
            );
            match order {
                ColumnOrder::Colamd => {
                    let params = LuSymbolicParams {
                        supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SIMPLICIAL,
                        ..Default::default()
                    };
                    let symbolic = factorize_symbolic_lu(sym.as_ref(), params).map_err(|e| {
                        LinalgError::Analysis(format!("sparse LU symbolic analysis failed: {e:?}"))
                    })?;
                    let (f, i) = symbolic.col_perm().arrays();
                    (f.to_vec(), i.to_vec())
                }
                ColumnOrder::SymmetricAmd => symmetric_amd(sym.as_ref())?,
            }
        };
        let req = factorize_simplicial_numeric_lu_scratch::<usize, f64>(n, n);
        let nnz = row_idx.len();
        Ok(SparseLu {
            n,
            col_ptr,
            row_idx,
            values: vec![0.0; nnz],
            scaled: vec![0.0; nnz],
            rscale: vec![1.0; n],
            cscale: vec![1.0; n],
            rmax: vec![0.0; n],
            col_perm,
            col_perm_inv,
            row_perm: (0..n).collect(),
            row_perm_inv: (0..n).collect(),
            lu: SimplicialLu::new(),
            factors: LuFactors::new(n),
            y: vec![0.0; n],
            mem: Scratch(MemBuffer::new(req)),
            factored: false,
            factorizations: 0,
            pivoted: 0,
            pivot_tol: SPARSE_PIVOT_TOL,
        })
    }

    /// Dimension `n`.
    pub fn dim(&self) -> usize {
        self.n
    }

    /// Stored entries of the matrix.
    pub fn nnz(&self) -> usize {
        self.values.len()
    }

    /// Entries of `L` and `U` of the last successful factorisation (0 before it).
    pub fn factor_nnz(&self) -> usize {
        self.factors.nnz()
    }

    /// Number of numeric factorisations attempted.
    pub fn factorizations(&self) -> usize {
        self.factorizations
    }

    /// The value slot of entry `(row, col)`, `None` outside the pattern.
    pub fn slot(&self, row: usize, col: usize) -> Option<usize> {
        if col >= self.n {
            return None;
        }
        let s = &self.row_idx[self.col_ptr[col]..self.col_ptr[col + 1]];
        s.binary_search(&row).ok().map(|k| self.col_ptr[col] + k)
    }

    /// The values, in the order of [`SparseLu::slot`].
    pub fn values_mut(&mut self) -> &mut [f64] {
        self.factored = false;
        &mut self.values
    }

    /// The values (read-only).
    pub fn values(&self) -> &[f64] {
        &self.values
    }

    /// Sets every value to zero.
    pub fn clear(&mut self) {
        self.factored = false;
        self.values.fill(0.0);
    }

    /// Whether the last [`SparseLu::factor`] succeeded and no value changed since.
    pub fn is_factored(&self) -> bool {
        self.factored
    }

    /// Factors the matrix (see the type's documentation for the equilibration and the pivot
    /// test). Errors name the original row and column: a non-finite entry, an all-zero row or
    /// column (reported with an entry of its pattern, or its own index if the pattern is empty),
    /// or a negligible pivot (the row chosen for it and the column it eliminates).
    pub fn factor(&mut self) -> Result<(), LuError> {
        self.factored = false;
        self.factorizations += 1;
        let n = self.n;
        if n == 0 {
            self.factored = true;
            return Ok(());
        }
        let (col_ptr, row_idx, values) = (&self.col_ptr, &self.row_idx, &self.values);
        for c in 0..n {
            for k in col_ptr[c]..col_ptr[c + 1] {
                if !values[k].is_finite() {
                    return Err(LuError::NonFinite {
                        row: row_idx[k],
                        col: c,
                    });
                }
            }
        }
        // equilibration: sweeps of square-root (Ruiz) scaling, then one of full row and
        // column scaling, every factor a power of two
        let (rs, cs) = (&mut self.rscale, &mut self.cscale);
        let rmax = &mut self.rmax;
        rs.fill(1.0);
        cs.fill(1.0);
        for sweep in 0..=EQUILIBRATION_SWEEPS {
            let full = sweep == EQUILIBRATION_SWEEPS;
            rmax.fill(0.0);
            for c in 0..n {
                for k in col_ptr[c]..col_ptr[c + 1] {
                    let r = row_idx[k];
                    rmax[r] = rmax[r].max((values[k] * cs[c]).abs() * rs[r]);
                }
            }
            for r in 0..n {
                if rmax[r] == 0.0 {
                    let col = (0..n)
                        .find(|&c| row_idx[col_ptr[c]..col_ptr[c + 1]].contains(&r))
                        .unwrap_or(r);
                    return Err(LuError::Singular { row: r, col });
                }
                rs[r] *= if full {
                    pow2_inverse(rmax[r])
                } else {
                    pow2_inverse(rmax[r].sqrt())
                };
            }
            for c in 0..n {
                let mut m = 0.0f64;
                for k in col_ptr[c]..col_ptr[c + 1] {
                    m = m.max((values[k] * rs[row_idx[k]]).abs() * cs[c]);
                }
                if m == 0.0 {
                    let row = row_idx[col_ptr[c]..col_ptr[c + 1]]
                        .first()
                        .copied()
                        .unwrap_or(c);
                    return Err(LuError::Singular { row, col: c });
                }
                cs[c] *= if full {
                    pow2_inverse(m)
                } else {
                    pow2_inverse(m.sqrt())
                };
            }
        }
        for c in 0..n {
            let sc = cs[c];
            for k in col_ptr[c]..col_ptr[c + 1] {
                self.scaled[k] = values[k] * rs[row_idx[k]] * sc;
            }
        }
        let tol = self.pivot_tol * n as f64;
        // along the last pivot sequence if its pivots still pass (no pivot search, no
        // pattern search); else afresh with partial pivoting
        if self.factors.refactor(
            (&self.col_ptr, &self.row_idx, &self.scaled),
            &self.col_perm,
            &self.row_perm_inv,
            tol,
        ) {
            self.factored = true;
            return Ok(());
        }
        self.pivoted += 1;
        let sym = SymbolicSparseColMatRef::new_checked(n, n, &self.col_ptr, None, &self.row_idx);
        let mat = SparseColMatRef::new(sym, &self.scaled);
        let cp = PermRef::new_checked(&self.col_perm, &self.col_perm_inv, n);
        let stack = MemStack::new(&mut self.mem.0);
        let res = factorize_simplicial_numeric_lu(
            &mut self.row_perm,
            &mut self.row_perm_inv,
            &mut self.lu,
            mat,
            cp,
            stack,
        );
        match res {
            Ok(()) => {}
            Err(FaerLuError::SymbolicSingular { index }) => {
                // no row left with a nonzero in the column eliminated at step `index`: name
                // that column and a row that has not been paired with a pivot
                let col = self.col_perm[index];
                let row = (0..n).find(|&i| self.row_perm_inv[i] >= n).unwrap_or(col);
                return Err(LuError::Singular { row, col });
            }
            Err(FaerLuError::Generic(e)) => {
                // out of memory: report the first column (nothing better is known)
                let _ = e;
                return Err(LuError::Singular {
                    row: self.col_perm[0],
                    col: self.col_perm[0],
                });
            }
        }
        let u = self.lu.u_factor_unsorted();
        for j in 0..n {
            let (ri, vals) = (u.row_idx_of_col_raw(j), u.val_of_col(j));
            // the diagonal is the last entry of each column of U
            let piv = match (ri.last(), vals.last()) {
                (Some(&r), Some(&v)) if r == j => v,
                _ => 0.0,
            };
            if !(piv.abs() > tol) {
                return Err(LuError::Singular {
                    row: self.row_perm[j],
                    col: self.col_perm[j],
                });
            }
        }
        self.factors.copy_from(&self.lu);
        self.factored = true;
        Ok(())
    }

    /// Solves `A x = b` in place with the last factorisation (call [`SparseLu::factor`]
    /// first; an unfactored matrix leaves `b` unchanged).
    pub fn solve_in_place(&mut self, b: &mut [f64]) {
        let n = self.n;
        if !self.factored || b.len() != n || n == 0 {
            return;
        }
        // P A Q = L U of the equilibrated matrix D_r A D_c: y = P D_r b, L U z = y, x = D_c Q z
        for (y, &r) in self.y.iter_mut().zip(&self.row_perm) {
            *y = b[r] * self.rscale[r];
        }
        self.factors.solve_in_place(&mut self.y);
        for (&y, &c) in self.y.iter().zip(&self.col_perm) {
            b[c] = y * self.cscale[c];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rng(seed: u64) -> impl FnMut() -> f64 {
        let mut state = seed;
        move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 11) as f64) / ((1u64 << 53) as f64) - 0.5
        }
    }

    /// A random sparse `n x n` matrix (dense row-major copy) with a permuted dominant entry in
    /// each row, so it is regular.
    fn random(n: usize, seed: u64) -> Vec<f64> {
        let mut rnd = rng(seed);
        let mut a = vec![0.0; n * n];
        for i in 0..n {
            for j in 0..n {
                if rnd() < -0.3 {
                    a[i * n + j] = rnd();
                }
            }
            a[i * n + (i * 7 + 3) % n] += 3.0;
        }
        a
    }

    fn load(a: &[f64], n: usize) -> SparseLu {
        load_ordered(a, n, ColumnOrder::Colamd)
    }

    fn load_ordered(a: &[f64], n: usize, order: ColumnOrder) -> SparseLu {
        let pattern: Vec<(usize, usize)> = (0..n * n)
            .filter(|&k| a[k] != 0.0)
            .map(|k| (k / n, k % n))
            .collect();
        let mut lu = SparseLu::with_order(n, &pattern, order).unwrap();
        for &(r, c) in &pattern {
            let k = lu.slot(r, c).unwrap();
            lu.values_mut()[k] = a[r * n + c];
        }
        lu
    }

    /// New values on the same pattern are factored along the last pivot sequence (no new
    /// pivoted factorisation) and solve as accurately as a fresh factorisation, also where the
    /// pattern holds explicit zeros; the factors keep their size.
    #[test]
    fn a_refactorisation_solves_like_a_fresh_factorisation() {
        let n = 40;
        let a = random(n, 7);
        let mut lu = load(&a, n);
        lu.factor().unwrap();
        assert_eq!(lu.pivoted, 1);
        let nnz = lu.factor_nnz();
        let mut rnd = rng(11);
        for round in 0..3 {
            // perturb every stored value by up to 4%, and zero a few of those off each row's
            // dominant entry (which keeps the pivots of the first factorisation good)
            let mut a2 = a.clone();
            for (k, x) in a2.iter_mut().enumerate() {
                if *x != 0.0 {
                    *x *= 1.0 + 0.08 * rnd();
                    let (i, j) = (k / n, k % n);
                    if k % 17 == round && j != (i * 7 + 3) % n {
                        *x = 0.0;
                    }
                }
            }
            for r in 0..n {
                for c in 0..n {
                    if let Some(k) = lu.slot(r, c) {
                        lu.values_mut()[k] = a2[r * n + c];
                    }
                }
            }
            lu.factor().unwrap();
            assert_eq!(
                lu.pivoted, 1,
                "round {round}: refactored along the old pivots"
            );
            assert_eq!(lu.factor_nnz(), nnz);
            let b: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin()).collect();
            let mut x = b.clone();
            lu.solve_in_place(&mut x);
            let res = residual(&a2, n, &x, &b);
            assert!(res < 1e-12, "round {round}: residual {res:e}");
        }
    }

    /// A pivot that the new values make small fails the threshold test: the matrix is factored
    /// afresh with partial pivoting and solves to round-off.
    #[test]
    fn a_small_pivot_falls_back_to_partial_pivoting() {
        let n = 3;
        // partial pivoting takes row 1 (3.0) for column 0
        let a = [1.0, 2.0, 0.0, 3.0, 4.0, 1.0, 0.0, 1.0, 5.0];
        let mut lu = load(&a, n);
        lu.factor().unwrap();
        assert_eq!(lu.pivoted, 1);
        // now row 1's entry in column 0 is 1e-9 of row 0's: along the old pivots it would
        // be a pivot of 1e-9 against 1 below it
        let a2 = [1.0, 2.0, 0.0, 1e-9, 4.0, 1.0, 0.0, 1.0, 5.0];
        for r in 0..n {
            for c in 0..n {
                if let Some(k) = lu.slot(r, c) {
                    lu.values_mut()[k] = a2[r * n + c];
                }
            }
        }
        lu.factor().unwrap();
        assert_eq!(lu.pivoted, 2, "the refactorisation was rejected");
        let b = [1.0, -2.0, 0.5];
        let mut x = b;
        lu.solve_in_place(&mut x);
        let res = residual(&a2, n, &x, &b);
        assert!(res < 1e-14, "residual {res:e}");
        // and the next values refactor along the new pivots
        lu.values_mut()[0] *= 1.01;
        lu.factor().unwrap();
        assert_eq!(lu.pivoted, 2);
    }

    #[test]
    fn the_docs_state_the_refactorisation_threshold() {
        let doc = include_str!("../../../../docs/architecture.md");
        let stated = format!("`REFACTOR_PIVOT_RATIO = {REFACTOR_PIVOT_RATIO}`");
        assert!(
            doc.contains(&stated),
            "docs/architecture.md lacks '{stated}'"
        );
    }

    fn residual(a: &[f64], n: usize, x: &[f64], b: &[f64]) -> f64 {
        (0..n)
            .map(|i| ((0..n).map(|j| a[i * n + j] * x[j]).sum::<f64>() - b[i]).abs())
            .fold(0.0, f64::max)
    }

    /// A saddle-point matrix `[[K, G^T], [G, 0]]` with `K` tridiagonal and dominant and `G`
    /// coupling neighbours (a chain's pattern): both column orders solve it to round-off, and
    /// the symmetric AMD order, which keeps such a chain's elimination local, fills no more
    /// than a banded factorisation would (about 4 entries per unknown in each factor).
    #[test]
    fn both_column_orders_solve_a_saddle_point_chain() {
        let (nk, ng) = (60usize, 30usize);
        let n = nk + ng;
        let mut a = vec![0.0; n * n];
        for i in 0..nk {
            a[i * n + i] = 4.0 + 0.01 * i as f64;
            if i + 1 < nk {
                a[i * n + i + 1] = -1.0;
                a[(i + 1) * n + i] = -1.0;
            }
        }
        for r in 0..ng {
            for (c, g) in [(2 * r, 1.0), (2 * r + 1, -0.5 - 0.01 * r as f64)] {
                a[(nk + r) * n + c] = g;
                a[c * n + nk + r] = g;
            }
        }
        let x0: Vec<f64> = (0..n).map(|i| 1.0 + 0.1 * i as f64).collect();
        let b: Vec<f64> = (0..n)
            .map(|i| (0..n).map(|j| a[i * n + j] * x0[j]).sum())
            .collect();
        for order in [ColumnOrder::Colamd, ColumnOrder::SymmetricAmd] {
            let mut lu = load_ordered(&a, n, order);
            lu.factor().unwrap();
            let mut x = b.clone();
            lu.solve_in_place(&mut x);
            let err = x
                .iter()
                .zip(&x0)
                .map(|(u, v)| (u - v).abs())
                .fold(0.0, f64::max);
            assert!(err < 1e-12, "{order:?}: error {err:e}");
            if order == ColumnOrder::SymmetricAmd {
                assert!(
                    lu.factor_nnz() <= 8 * n,
                    "AMD factor entries {} for n = {n}",
                    lu.factor_nnz()
                );
            }
        }
    }

    #[test]
    fn solves_random_sparse_systems_repeatedly() {
        for (n, seed) in [(5usize, 1u64), (40, 2), (200, 3)] {
            let a = random(n, seed);
            let mut lu = load(&a, n);
            for round in 0..3 {
                lu.factor().unwrap();
                let x: Vec<f64> = (0..n)
                    .map(|i| (i as f64 * 0.37 + round as f64).sin())
                    .collect();
                let b: Vec<f64> = (0..n)
                    .map(|i| (0..n).map(|j| a[i * n + j] * x[j]).sum())
                    .collect();
                let mut y = b.clone();
                lu.solve_in_place(&mut y);
                let err = x
                    .iter()
                    .zip(&y)
                    .map(|(p, q)| (p - q).abs())
                    .fold(0.0, f64::max);
                assert!(err < 1e-12, "n = {n}: error {err:e}");
                assert!(residual(&a, n, &y, &b) < 1e-12);
            }
            assert!(lu.factor_nnz() >= lu.nnz());
        }
    }

    /// Rows and columns scaled by up to 1e+-12 (not powers of two): still factored, and the
    /// solution is as accurate (relative to the column scales) as unscaled.
    #[test]
    fn badly_scaled_matrices_are_solved() {
        let n = 30;
        let a = random(n, 9);
        for span in [0.0, 6.0, 12.0] {
            let dr: Vec<f64> = (0..n)
                .map(|i| 10f64.powf(span * ((i * 7 % n) as f64 / n as f64 * 2.0 - 1.0)))
                .collect();
            let dc: Vec<f64> = (0..n)
                .map(|j| 1.37 * 10f64.powf(span * ((j * 5 % n) as f64 / n as f64 * 2.0 - 1.0)))
                .collect();
            let s: Vec<f64> = (0..n * n).map(|k| a[k] * dr[k / n] * dc[k % n]).collect();
            let mut lu = load(&s, n);
            lu.factor()
                .unwrap_or_else(|e| panic!("span 1e{span}: {e:?}"));
            let y: Vec<f64> = (0..n).map(|i| 1.0 + (i as f64 * 0.37).sin()).collect();
            let x: Vec<f64> = (0..n).map(|j| y[j] / dc[j]).collect();
            let mut b: Vec<f64> = (0..n)
                .map(|i| (0..n).map(|j| s[i * n + j] * x[j]).sum())
                .collect();
            lu.solve_in_place(&mut b);
            let err = (0..n)
                .map(|j| ((b[j] - x[j]) * dc[j]).abs())
                .fold(0.0, f64::max);
            assert!(err < 1e-12, "span 1e{span}: error {err:e}");
        }
    }

    /// Singular matrices at every scaling, with the original row and column named: two equal
    /// rows (one of them is named), a zero column, and a row that depends on two others only
    /// numerically (no structural zero).
    #[test]
    fn singular_matrices_name_row_and_column() {
        let n = 12;
        let a = random(n, 4);
        for span in [0.0, 12.0] {
            let scale = |k: usize| {
                10f64.powf(span * ((k / n * 7 % n) as f64 / n as f64 - 0.5))
                    * 10f64.powf(span * ((k % n * 5 % n) as f64 / n as f64 - 0.5))
            };
            // row 9 = row 4 + row 2 (dense rows so the dependence is numerical)
            let mut dep = a.clone();
            for j in 0..n {
                dep[4 * n + j] += 0.5 + j as f64 * 0.01;
                dep[2 * n + j] -= 0.25;
                dep[9 * n + j] = dep[4 * n + j] + dep[2 * n + j];
            }
            let dep: Vec<f64> = (0..n * n).map(|k| dep[k] * scale(k)).collect();
            let mut lu = load(&dep, n);
            match lu.factor() {
                Err(LuError::Singular { row, col }) => {
                    assert!(row < n && col < n, "({row}, {col})");
                }
                other => panic!("span 1e{span}: expected singular, got {other:?}"),
            }
            // column 5 zero: every entry of the column is in the pattern but zero
            let mut zc = a.clone();
            for i in 0..n {
                zc[i * n + 5] = 0.0;
            }
            let mut lu = load(&a, n);
            for i in 0..n {
                if let Some(k) = lu.slot(i, 5) {
                    lu.values_mut()[k] = 0.0;
                }
            }
            match lu.factor() {
                Err(LuError::Singular { col, .. }) => assert_eq!(col, 5),
                other => panic!("expected singular column 5, got {other:?}"),
            }
        }
    }

    /// faer's conventions as used for the error: a 3 x 3 matrix whose second column is zero
    /// except in one entry that is exactly cancelled. The failing pivot is named in the
    /// caller's numbering, not the permuted one.
    #[test]
    fn pivot_error_is_in_original_numbering() {
        // rows 0 and 2 equal: rank 2, the third pivot fails
        let a = [1.0, 2.0, 0.0, 0.0, 1.0, 1.0, 1.0, 2.0, 0.0];
        let mut lu = load(&a, 3);
        match lu.factor() {
            Err(LuError::Singular { row, col }) => {
                // the row named is one of the two equal rows
                assert!(row == 0 || row == 2, "row {row}, col {col}");
            }
            other => panic!("{other:?}"),
        }
        // numerically dependent columns 3, 7, 10 (column 10 = column 3 + column 7, dense
        // columns so no structural zero decides): the column named is one of them, in the
        // caller's numbering (COLAMD permutes the columns); and likewise for dependent rows
        let n = 12;
        let a = random(n, 11);
        let mut dc = a.clone();
        for i in 0..n {
            dc[i * n + 3] += 0.7 + 0.01 * i as f64;
            dc[i * n + 7] -= 0.4;
            dc[i * n + 10] = dc[i * n + 3] + dc[i * n + 7];
        }
        match load(&dc, n).factor() {
            Err(LuError::Singular { col, .. }) => {
                assert!([3, 7, 10].contains(&col), "col {col}")
            }
            other => panic!("{other:?}"),
        }
        let mut dr = random(n, 4);
        for j in 0..n {
            dr[2 * n + j] += 0.5 + 0.01 * j as f64;
            dr[4 * n + j] -= 0.25;
            dr[9 * n + j] = dr[2 * n + j] + dr[4 * n + j];
        }
        match load(&dr, n).factor() {
            Err(LuError::Singular { row, .. }) => {
                assert!([2, 4, 9].contains(&row), "row {row}")
            }
            other => panic!("{other:?}"),
        }
        let mut lu = load(&[1.0, f64::NAN, 0.0, 1.0], 2);
        assert_eq!(lu.factor(), Err(LuError::NonFinite { row: 0, col: 1 }));
    }
}
