//! Sparse Cholesky factorisation on a fixed pattern (faer, simplicial), with diagonal
//! equilibration and the scale-invariant pivot test of the dense path.

use crate::{FactorError, LinalgError, Scratch, CHOLESKY_PIVOT_TOL};
use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::cholesky::llt::factor::LltRegularization;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, CholeskySymbolicParams, LltRef, SymbolicCholesky,
    SymbolicCholeskyRaw,
};
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat, SymbolicSparseColMatRef};
use faer::{Conj, MatMut, Par, Side};

/// A symmetric positive definite `m x m` matrix on a fixed sparsity pattern, and its Cholesky
/// factorisation.
///
/// The pattern (lower triangle; the diagonal is always included) is given once to
/// [`SparseCholesky::new`], which computes the fill-reducing ordering and the symbolic
/// factorisation and allocates every buffer. A caller then writes values through
/// [`SparseCholesky::slot`] / [`SparseCholesky::values_mut`], calls
/// [`SparseCholesky::factor`] and [`SparseCholesky::solve_in_place`]; none of these allocate.
///
/// The factorisation is of the diagonally equilibrated matrix `D^-1/2 A D^-1/2`
/// (`D = diag(A)`), so the pivot test `L_jj^2 >= CHOLESKY_PIVOT_TOL` there is the dense path's
/// scale-invariant test `L_jj^2 >= CHOLESKY_PIVOT_TOL A_jj`, and
/// [`SparseCholesky::condition_estimate`] is the same `max_j A_jj / L_jj^2`. (The pivot order
/// is the fill-reducing one, not the natural one, so the estimate can differ from the dense
/// one; both grow like the inverse square distance to a singular configuration.)
///
/// ```
/// use mbd_linalg::SparseCholesky;
/// // the 1D Laplacian [[2, -1, 0], [-1, 2, -1], [0, -1, 2]]
/// let mut chol = SparseCholesky::new(3, &[(1, 0), (2, 1)])?;
/// for (r, c, v) in [(0, 0, 2.0), (1, 1, 2.0), (2, 2, 2.0), (1, 0, -1.0), (2, 1, -1.0)] {
///     let k = chol.slot(r, c).expect("in the pattern");
///     chol.values_mut()[k] = v;
/// }
/// chol.factor()?;
/// let mut b = [1.0, 0.0, 1.0];
/// chol.solve_in_place(&mut b);
/// assert!(b.iter().all(|x| (x - 1.0).abs() < 1e-14));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug)]
pub struct SparseCholesky {
    m: usize,
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    values: Vec<f64>,
    scaled: Vec<f64>,
    scale: Vec<f64>,
    diag_slot: Vec<usize>,
    symbolic: SymbolicCholesky<usize>,
    /// position of each column's diagonal entry in `l_values` (simplicial storage)
    l_diag: Vec<usize>,
    /// fill-reducing permutation: pivot `j` is original index `perm[j]`
    perm: Vec<usize>,
    l_values: Vec<f64>,
    mem: Scratch,
    factored: bool,
    condition: f64,
    /// How many dependent rows a factorisation may drop (0: the matrix must be definite).
    max_dependent: usize,
    /// The rows (original indices) dropped by the last factorisation.
    dependent: Vec<usize>,
}

/// The pivot a semidefinite factorisation puts in place of a dependent row's (in the
/// equilibrated matrix, whose genuine pivots are at most 1 plus rounding): `L_jj = 2` exactly
/// marks the row as dropped.
const DROPPED_PIVOT: f64 = 4.0;

impl SparseCholesky {
    /// Analyses the pattern: `m` unknowns, off-diagonal entries `(row, col)` of the lower
    /// triangle (`row > col`; an entry given as `row < col` is mirrored, repeats are merged, the
    /// diagonal is added). Allocates; done once per pattern.
    pub fn new(m: usize, lower: &[(usize, usize)]) -> Result<Self, LinalgError> {
        let mut entries: Vec<(usize, usize)> = (0..m).map(|r| (r, r)).collect();
        for &(r, c) in lower {
            if r >= m || c >= m {
                return Err(LinalgError::PatternEntry {
                    what: "sparse Cholesky pattern entry",
                    dim: m,
                    index: r.max(c),
                });
            }
            let (r, c) = if r >= c { (r, c) } else { (c, r) };
            entries.push((c, r));
        }
        entries.sort_unstable();
        entries.dedup();
        let mut col_ptr = vec![0usize; m + 1];
        let mut row_idx = Vec::with_capacity(entries.len());
        for &(c, r) in &entries {
            col_ptr[c + 1] += 1;
            row_idx.push(r);
        }
        for c in 0..m {
            col_ptr[c + 1] += col_ptr[c];
        }
        // the diagonal is each column's first entry (rows sorted, r >= c)
        let diag_slot: Vec<usize> = (0..m).map(|c| col_ptr[c]).collect();
        let sym = SymbolicSparseColMat::<usize>::new_checked(
            m,
            m,
            col_ptr.clone(),
            None,
            row_idx.clone(),
        );
        let params = CholeskySymbolicParams {
            supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SIMPLICIAL,
            ..Default::default()
        };
        let symbolic =
            factorize_symbolic_cholesky(sym.as_ref(), Side::Lower, Default::default(), params)
                .map_err(|e| {
                    LinalgError::Analysis(format!("sparse symbolic analysis failed: {e:?}"))
                })?;
        let l_diag = match symbolic.raw() {
            SymbolicCholeskyRaw::Simplicial(s) => {
                let (cp, ri) = (s.col_ptr(), s.row_idx());
                let mut d = Vec::with_capacity(m);
                for j in 0..m {
                    let col = &ri[cp[j]..cp[j + 1]];
                    match col.iter().position(|&r| r == j) {
                        Some(p) => d.push(cp[j] + p),
                        None => {
                            return Err(LinalgError::Analysis(format!(
                                "sparse Cholesky: column {j} of L has no diagonal entry"
                            )))
                        }
                    }
                }
                d
            }
            SymbolicCholeskyRaw::Supernodal(_) => {
                return Err(LinalgError::Analysis(
                    "sparse Cholesky: expected a simplicial factorisation".into(),
                ))
            }
        };
        let perm = match symbolic.perm() {
            Some(p) => p.arrays().0.to_vec(),
            None => (0..m).collect(),
        };
        let req = StackReq::any_of(&[
            symbolic.factorize_numeric_llt_scratch::<f64>(Par::Seq, Default::default()),
            symbolic.solve_in_place_scratch::<f64>(1, Par::Seq),
        ]);
        let nnz = row_idx.len();
        let l_values = vec![0.0; symbolic.len_val()];
        Ok(SparseCholesky {
            m,
            col_ptr,
            row_idx,
            values: vec![0.0; nnz],
            scaled: vec![0.0; nnz],
            scale: vec![0.0; m],
            diag_slot,
            symbolic,
            l_diag,
            perm,
            l_values,
            mem: Scratch(MemBuffer::new(req)),
            factored: false,
            condition: 0.0,
            max_dependent: 0,
            dependent: Vec::new(),
        })
    }

    /// Lets each factorisation drop up to `k` rows that depend on the earlier ones in the
    /// elimination order (a positive *semi*definite matrix, as `Phi_q M^-1 Phi_q^T` is for a
    /// mechanism with `k` redundant constraint equations), as
    /// [`crate::DenseCholesky::set_max_dependent`] does: a pivot of the equilibrated matrix at
    /// most [`crate::DEPENDENT_PIVOT_TOL`] is replaced by a positive one (faer's dynamic
    /// regularisation) and the row's unknown is then set to zero in every solve. `k = 0` (the
    /// default) is the definite factorisation, unchanged. Allocates the list of dropped rows
    /// (once).
    pub fn set_max_dependent(&mut self, k: usize) {
        self.max_dependent = k.min(self.m);
        self.dependent = Vec::with_capacity(self.m);
        self.factored = false;
    }

    /// The rows (original indices) dropped as dependent by the last factorisation, in the
    /// elimination order (empty unless [`SparseCholesky::set_max_dependent`] allowed some).
    pub fn dependent(&self) -> &[usize] {
        &self.dependent
    }

    /// Dimension `m`.
    pub fn dim(&self) -> usize {
        self.m
    }

    /// Stored entries of the lower triangle (the matrix, not its factor).
    pub fn nnz(&self) -> usize {
        self.values.len()
    }

    /// Entries of the factor `L` (fill included).
    pub fn factor_nnz(&self) -> usize {
        self.l_values.len()
    }

    /// The value slot of entry `(row, col)` (either triangle), `None` outside the pattern.
    pub fn slot(&self, row: usize, col: usize) -> Option<usize> {
        let (r, c) = if row >= col { (row, col) } else { (col, row) };
        if c >= self.m {
            return None;
        }
        let s = &self.row_idx[self.col_ptr[c]..self.col_ptr[c + 1]];
        s.binary_search(&r).ok().map(|k| self.col_ptr[c] + k)
    }

    /// The values of the lower triangle, in the order of [`SparseCholesky::slot`].
    pub fn values_mut(&mut self) -> &mut [f64] {
        self.factored = false;
        &mut self.values
    }

    /// Sets every value to zero.
    pub fn clear(&mut self) {
        self.factored = false;
        self.values.fill(0.0);
    }

    /// Factors the matrix. A non-positive or non-finite diagonal entry, or a pivot of the
    /// equilibrated matrix below [`CHOLESKY_PIVOT_TOL`], is an error naming the (original)
    /// index of the row at fault. Sets [`SparseCholesky::condition_estimate`].
    pub fn factor(&mut self) -> Result<(), FactorError> {
        self.factored = false;
        self.condition = f64::INFINITY;
        let m = self.m;
        if m == 0 {
            self.factored = true;
            self.condition = 1.0;
            return Ok(());
        }
        for j in 0..m {
            let d = self.values[self.diag_slot[j]];
            if !(d > 0.0 && d.is_finite()) {
                return Err(FactorError::NotPositiveDefinite(j));
            }
            self.scale[j] = 1.0 / d.sqrt();
        }
        for c in 0..m {
            let sc = self.scale[c];
            for k in self.col_ptr[c]..self.col_ptr[c + 1] {
                self.scaled[k] = self.values[k] * sc * self.scale[self.row_idx[k]];
            }
        }
        let sym = SymbolicSparseColMatRef::new_checked(m, m, &self.col_ptr, None, &self.row_idx);
        let mat = SparseColMatRef::new(sym, &self.scaled);
        let stack = MemStack::new(&mut self.mem.0);
        let regularization = if self.max_dependent > 0 {
            LltRegularization {
                dynamic_regularization_delta: DROPPED_PIVOT,
                dynamic_regularization_epsilon: crate::DEPENDENT_PIVOT_TOL,
            }
        } else {
            LltRegularization::default()
        };
        self.dependent.clear();
        let res = self.symbolic.factorize_numeric_llt(
            &mut self.l_values,
            mat,
            Side::Lower,
            regularization,
            Par::Seq,
            stack,
            Default::default(),
        );
        if let Err(e) = res {
            // faer reports the failing pivot 1-based, in the permuted order
            let faer::linalg::cholesky::llt::factor::LltError::NonPositivePivot { index } = e;
            let j = index.saturating_sub(1);
            return Err(FactorError::NotPositiveDefinite(
                self.perm.get(j).copied().unwrap_or(j),
            ));
        }
        let mut worst = 1.0f64;
        for (j, &p) in self.l_diag.iter().enumerate() {
            let l = self.l_values[p];
            if self.max_dependent > 0 && l == DROPPED_PIVOT.sqrt() {
                if self.dependent.len() == self.max_dependent {
                    return Err(FactorError::NotPositiveDefinite(self.perm[j]));
                }
                self.dependent.push(self.perm[j]);
                // the solves divide by L_jj: an infinite one gives the dropped row's unknown
                // zero and leaves the others alone (its column below the diagonal is rounding
                // noise, multiplied by that zero)
                self.l_values[p] = f64::INFINITY;
                continue;
            }
            let piv = l * l;
            if !(piv >= CHOLESKY_PIVOT_TOL) {
                return Err(FactorError::NotPositiveDefinite(self.perm[j]));
            }
            worst = worst.max(1.0 / piv);
        }
        self.condition = worst;
        self.factored = true;
        Ok(())
    }

    /// `max_j A_jj / L_jj^2` of the last factorisation (>= 1; see the type's documentation):
    /// 0 before the first factorisation, infinite after a failed one.
    pub fn condition_estimate(&self) -> f64 {
        self.condition
    }

    /// Whether the last [`SparseCholesky::factor`] succeeded and no value changed since.
    pub fn is_factored(&self) -> bool {
        self.factored
    }

    /// Solves `A x = b` in place with the last factorisation (call
    /// [`SparseCholesky::factor`] first; an unfactored matrix leaves `b` unchanged).
    pub fn solve_in_place(&mut self, b: &mut [f64]) {
        let m = self.m;
        if !self.factored || b.len() != m || m == 0 {
            return;
        }
        for (x, s) in b.iter_mut().zip(&self.scale) {
            *x *= s;
        }
        let llt = LltRef::<'_, usize, f64>::new(&self.symbolic, &self.l_values);
        let stack = MemStack::new(&mut self.mem.0);
        llt.solve_in_place_with_conj(
            Conj::No,
            MatMut::from_column_major_slice_mut(b, m, 1),
            Par::Seq,
            stack,
        );
        for (x, s) in b.iter_mut().zip(&self.scale) {
            *x *= s;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::DenseCholesky;

    /// A random symmetric positive definite banded matrix (bandwidth 2) with a wide diagonal
    /// scale spread.
    fn banded(m: usize, seed: u64) -> Vec<(usize, usize, f64)> {
        let mut s = seed;
        let mut rnd = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((s >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        };
        let d: Vec<f64> = (0..m).map(|i| 10f64.powi((i % 7) as i32 - 3)).collect();
        let mut e = Vec::new();
        for i in 0..m {
            e.push((i, i, 4.0 * d[i] * d[i]));
            for k in 1..=2 {
                if i >= k {
                    e.push((i, i - k, rnd() * d[i] * d[i - k]));
                }
            }
        }
        e
    }

    #[test]
    fn matches_the_dense_factorisation_and_condition_estimate_is_scale_free() {
        let m = 40;
        let e = banded(m, 7);
        let pattern: Vec<(usize, usize)> = e.iter().map(|&(r, c, _)| (r, c)).collect();
        let mut sp = SparseCholesky::new(m, &pattern).unwrap();
        let mut de = DenseCholesky::new(m);
        for &(r, c, v) in &e {
            let k = sp.slot(r, c).unwrap();
            sp.values_mut()[k] = v;
            de.matrix_mut()[(r, c)] = v;
        }
        sp.factor().unwrap();
        de.factor_in_place().unwrap();
        let b: Vec<f64> = (0..m).map(|i| (i as f64).sin()).collect();
        let (mut x1, mut x2) = (b.clone(), b.clone());
        sp.solve_in_place(&mut x1);
        de.solve_in_place(&mut x2);
        let scale = x2.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        for (a, b) in x1.iter().zip(&x2) {
            assert!((a - b).abs() <= 1e-12 * scale, "{a} vs {b}");
        }
        let k = sp.condition_estimate();
        assert!((1.0..10.0).contains(&k), "{k}");
    }

    #[test]
    fn singular_rows_are_named_by_their_original_index() {
        // rows 3 and 5 identical: [x3, x5] block [[1, 1], [1, 1]] (plus identity elsewhere)
        let m = 8;
        let mut sp = SparseCholesky::new(m, &[(5, 3)]).unwrap();
        for i in 0..m {
            let k = sp.slot(i, i).unwrap();
            sp.values_mut()[k] = 1.0;
        }
        let k = sp.slot(3, 5).unwrap();
        sp.values_mut()[k] = 1.0;
        match sp.factor() {
            Err(FactorError::NotPositiveDefinite(i)) => assert!(i == 3 || i == 5, "{i}"),
            other => panic!("expected a singular pivot, got {other:?}"),
        }
        assert!(sp.condition_estimate().is_infinite());
        // a zero diagonal entry is named directly
        let k = sp.slot(6, 6).unwrap();
        sp.values_mut()[k] = 0.0;
        assert!(matches!(
            sp.factor(),
            Err(FactorError::NotPositiveDefinite(6))
        ));
    }

    /// `G G^T` for a 40 x 60 banded `G` whose rows 17 and 33 are combinations of others (a
    /// positive semidefinite matrix of rank 38), in the sparse and the dense semidefinite
    /// factorisations: both drop two rows, one more dependent row is an error, and for a
    /// right-hand side in the range the solutions agree and solve the system.
    #[test]
    fn semidefinite_factorisations_drop_dependent_rows_and_agree() {
        let (m, n) = (40, 60);
        let mut g = vec![vec![0.0; n]; m];
        for (i, row) in g.iter_mut().enumerate() {
            for k in 0..3 {
                row[(i + k) % n] = 1.0 + ((i * 7 + k * 3) % 5) as f64;
            }
        }
        g[17] = g[16]
            .iter()
            .zip(&g[18])
            .map(|(a, b)| 2.0 * a - 0.5 * b)
            .collect();
        g[33] = g[32].iter().zip(&g[31]).map(|(a, b)| a + b).collect();
        let s = |r: usize, c: usize| -> f64 { g[r].iter().zip(&g[c]).map(|(a, b)| a * b).sum() };
        let mut pattern = Vec::new();
        for r in 0..m {
            for c in 0..r {
                if s(r, c) != 0.0 {
                    pattern.push((r, c));
                }
            }
        }
        let fill = |sp: &mut SparseCholesky, de: &mut DenseCholesky| {
            for r in 0..m {
                for c in 0..=r {
                    let v = s(r, c);
                    if v != 0.0 {
                        let k = sp.slot(r, c).unwrap();
                        sp.values_mut()[k] = v;
                    }
                    de.matrix_mut()[(r, c)] = v;
                }
            }
        };
        let mut sp = SparseCholesky::new(m, &pattern).unwrap();
        let mut de = DenseCholesky::new(m);
        // definite factorisations refuse it
        fill(&mut sp, &mut de);
        assert!(sp.factor().is_err());
        assert!(de.factor_in_place().is_err());
        // one dropped row allowed: not enough
        sp.set_max_dependent(1);
        de.set_max_dependent(1);
        fill(&mut sp, &mut de);
        assert!(sp.factor().is_err());
        assert!(de.factor_in_place().is_err());
        sp.set_max_dependent(2);
        de.set_max_dependent(3);
        fill(&mut sp, &mut de);
        sp.factor().unwrap();
        de.factor_in_place().unwrap();
        // in the natural order the last row of each dependent set goes: 18 (= (2 g16 - g17) / 0.5)
        // and 33
        assert_eq!(de.dependent(), &[18, 33]);
        assert_eq!(sp.dependent().len(), 2);
        // b = S x0 is in the range; both solutions solve S x = b
        let x0: Vec<f64> = (0..m).map(|i| (i as f64 * 0.37).cos()).collect();
        let b: Vec<f64> = (0..m)
            .map(|r| (0..m).map(|c| s(r, c) * x0[c]).sum())
            .collect();
        let bmax = b.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        for x in [
            {
                let mut x = b.clone();
                sp.solve_in_place(&mut x);
                x
            },
            {
                let mut x = b.clone();
                de.solve_in_place(&mut x);
                x
            },
        ] {
            for r in 0..m {
                let sx: f64 = (0..m).map(|c| s(r, c) * x[c]).sum();
                assert!(
                    (sx - b[r]).abs() <= 1e-10 * bmax,
                    "row {r}: {sx} vs {}",
                    b[r]
                );
            }
        }
        let mut x = b.clone();
        de.solve_in_place(&mut x);
        assert_eq!((x[18], x[33]), (0.0, 0.0));
        let mut y = b.clone();
        sp.solve_in_place(&mut y);
        for &d in sp.dependent() {
            assert_eq!(y[d], 0.0, "dropped row {d}");
        }
    }

    #[test]
    fn pattern_errors_and_slots() {
        assert!(SparseCholesky::new(3, &[(3, 0)]).is_err());
        let sp = SparseCholesky::new(3, &[(0, 2)]).unwrap();
        assert_eq!(sp.slot(2, 0), sp.slot(0, 2));
        assert!(sp.slot(1, 0).is_none());
        assert_eq!(sp.nnz(), 4);
    }
}
