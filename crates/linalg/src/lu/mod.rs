//! The project's dense LU: `n x n` storage (row-major, preallocated), with a static
//! elimination order, pattern tracking and a scale-invariant pivot test. It is the dense path
//! of the symplectic stage equations (10-100 unknowns, mostly zeros), the Newton solver's and
//! the tangent chart's LU, and the small LUs of firefly-gauss (with `pivot_tol = 0`).
//! A general dense matrix is handled the same way: its pattern is simply full.
//!
//! The Jacobian of the stage equations is mostly zeros (for the (2,2) scheme on a double
//! pendulum, 90 of 400 entries are nonzero: identity blocks, the sparse `Phi_q` and the
//! constraint curvature), and its nonzero pattern is fixed by the model's structure. So:
//! - a fixed symmetric ordering chosen by the caller ([`DenseLu::with_ordering`]): the
//!   Galerkin scheme puts the `s` displacement unknowns of each coordinate together (their
//!   block of the Jacobian is `s x s` when the Hessians are sparse) and the multipliers last, so
//!   the elimination of the displacements fills in little and leaves a small Schur complement
//!   on the multipliers;
//! - the pattern of the entries that have ever been nonzero is tracked as the matrix is written
//!   ([`DenseLu::add`], [`DenseLu::set`]); when it grows (in the first steps, and whenever an
//!   entry becomes nonzero for the first time), a symbolic factorisation with the diagonal
//!   pivots of the ordering is recomputed; each numeric factorisation runs over its index lists
//!   only (no searching or scanning of zeros). A diagonal
//!   pivot is accepted if it is at least `PIVOT_THRESHOLD` times the largest entry of its
//!   column (threshold pivoting, the usual compromise of sparse LU codes between sparsity and
//!   the growth of the factors); if one is not, that factorisation is redone by
//! - the general path: threshold partial pivoting (the diagonal pivot unless another entry of
//!   its column is more than `1 / PIVOT_THRESHOLD` times larger), which updates a row only in
//!   the columns where the pivot row is nonzero and records the nonzero pattern of `L` and `U`
//!   as it goes.
//!
//! **Singularity test.** A pivot is negligible, and the matrix singular, when it is at most
//! `PIVOT_TOL n` in the *equilibrated* matrix `D_r A D_c`: every row, then every column,
//! scaled by a power of two that brings its largest entry into `[1, 2)`, so the test does not
//! depend on the units of the equations and unknowns (the stage equations of a mechanism with
//! centimetre links and 1e-7 kg m^2 inertias at h = 1e-7 have multiplier columns 1e-14 times
//! smaller than the others, which a test relative to `max |A|` took for singular). The scaling
//! is not applied to the stored matrix: powers of two scale without rounding, so the pivots of
//! `D_r A D_c` are exactly `r_k u_kk c_k` and only the test needs the scale factors. They cost
//! two passes over the pattern, so the static path computes them only when a pivot is below
//! `4 PIVOT_TOL n max |A|` (above that the scaled test cannot fail); the general path computes
//! them always and chooses its pivots by their magnitude in the row-scaled matrix (scaled
//! partial pivoting). The static path's threshold test compares unscaled entries of one column,
//! which is invariant under column scaling.
//!
//! The solves ([`DenseLu::solve_in_place`], [`DenseLu::solve_with`],
//! [`DenseLu::solve_transpose_in_place`]) touch only the recorded nonzeros of `L` and `U`.
//!
//! Files: the matrix storage and its entry methods here, the symbolic factorisation in
//! `symbolic.rs`, the numeric factorisation (both paths and the equilibration) in `factor.rs`,
//! the triangular solves in `solve.rs`, the tests in `tests.rs`.

/// A diagonal pivot is kept if it is at least this fraction of the largest entry of its column.
pub const PIVOT_THRESHOLD: f64 = 0.1;

/// A pivot of the equilibrated matrix below `PIVOT_TOL n` is negligible (the matrix singular):
/// a few hundred rounding errors of its O(1) entries. The default of [`DenseLu::pivot_tol`].
pub const PIVOT_TOL: f64 = 1e-14;

mod factor;
mod solve;
mod symbolic;

use crate::{FactorError, LuError};
use faer::MatMut;
use nalgebra::DMatrix;
use symbolic::Pattern;

/// LU of an `n x n` matrix with a fixed row and column ordering (see the module documentation).
///
/// The caller writes the matrix in its own numbering through [`DenseLu::add`] /
/// [`DenseLu::set`] (after [`DenseLu::clear`]), which track its nonzero pattern, or writes every
/// entry through [`DenseLu::matrix_mut`] / [`DenseLu::rows_mut`] (the storage, in the ordered
/// numbering: the natural one for [`DenseLu::new`]), or copies a matrix in
/// ([`DenseLu::factor`]). It is stored in the ordered numbering, row-major. Row interchanges
/// are kept in a permutation vector (rows never move in memory), so the nonzero lists recorded
/// during the elimination stay valid for [`DenseLu::solve_in_place`]. Factorisations and
/// solves allocate nothing.
#[derive(Clone, Debug)]
pub struct DenseLu {
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
    /// Positions (ordered numbering) of the `n_nz` entries of `mask` (row by row: those of
    /// row `i` are `nz[nz_start[i]..nz_start[i + 1]]`), and their columns.
    nz: Vec<usize>,
    nz_start: Vec<usize>,
    nz_col: Vec<usize>,
    n_nz: usize,
    /// Copy of the matrix at `nz`, for the general path when the static pivots fail.
    backup: Vec<f64>,
    /// `rp[k]`: the physical row of the `k`-th pivot.
    rp: Vec<usize>,
    /// The general path's pivot row per column while it eliminates (`usize::MAX`: dropped).
    prow: Vec<usize>,
    /// Nonzeros of the last factorisation of the general path.
    dynamic: Pattern,
    /// Entries (ordered numbering) that have been nonzero in some matrix so far.
    mask: Vec<bool>,
    /// `mask` with the fill-in of the elimination (scratch of the symbolic factorisation).
    fill: Vec<bool>,
    /// Whether `mask` grew since the last symbolic factorisation.
    dirty: bool,
    /// The symbolic factorisation of `mask` with static diagonal pivots.
    symbolic: Pattern,
    /// Whether the last factorisation used `symbolic`.
    static_used: bool,
    /// Number of factorisations that fell back to the general path.
    fallbacks: usize,
    /// Number of symbolic factorisations.
    analyses: usize,
    /// Values of the active pattern's nonzeros: multipliers of `L` (aligned with `l_idx`),
    /// entries of `U` right of the diagonal (aligned with `u_idx`), inverse pivots.
    l_val: Vec<f64>,
    u_val: Vec<f64>,
    dinv: Vec<f64>,
    /// Scratch vectors of the solve.
    y: Vec<f64>,
    x: Vec<f64>,
    /// Row and column scale factors (powers of two) of the equilibration, ordered numbering
    /// (used by the pivot tests only).
    rscale: Vec<f64>,
    cscale: Vec<f64>,
    /// Largest entry of each column of the row-scaled matrix (scratch of the equilibration).
    cmax: Vec<f64>,
    /// Whether `rscale` and `cscale` belong to the matrix being factored.
    scaled: bool,
    /// Number of factorisations that needed the scale factors.
    equilibrations: usize,
    /// Whether the storage was written directly since the last factorisation (the pattern is
    /// then rescanned).
    raw: bool,
    /// Whether the last factorisation succeeded (and nothing was written since).
    factored: bool,
    /// A pivot of the equilibrated matrix at most `pivot_tol n` counts as zero (default
    /// [`PIVOT_TOL`]; 0: only exact zeros).
    pub pivot_tol: f64,
    /// Ordered positions from which a negligible pivot may be dropped, and how many.
    drop_from: usize,
    drop_max: usize,
    /// The ordered positions dropped by the last factorisation (capacity `drop_max`).
    dropped: Vec<usize>,
}

impl DenseLu {
    /// An LU of `n x n` matrices in the natural ordering.
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
        DenseLu {
            n,
            rows,
            cols,
            rpos,
            cpos,
            f: vec![0.0; n * n],
            nz: vec![0; n * n],
            nz_start: vec![0; n + 1],
            nz_col: vec![0; n * n],
            n_nz: 0,
            backup: vec![0.0; n * n],
            rp: (0..n).collect(),
            prow: vec![0; n],
            dynamic: Pattern::new(n),
            mask: (0..n * n).map(|k| k % (n + 1) == 0).collect(),
            fill: vec![false; n * n],
            dirty: true,
            symbolic: Pattern::new(n),
            static_used: false,
            fallbacks: 0,
            analyses: 0,
            l_val: vec![0.0; n * n],
            u_val: vec![0.0; n * n],
            dinv: vec![0.0; n],
            y: vec![0.0; n],
            x: vec![0.0; n],
            rscale: vec![1.0; n],
            cscale: vec![1.0; n],
            cmax: vec![0.0; n],
            scaled: false,
            equilibrations: 0,
            raw: false,
            factored: false,
            pivot_tol: PIVOT_TOL,
            drop_from: n,
            drop_max: 0,
            dropped: Vec::new(),
        }
    }

    /// Lets each factorisation drop up to `max` pivots at ordered positions `from..n` whose
    /// equilibrated value is at most [`crate::DEPENDENT_PIVOT_TOL`] `n`: the unknown of a
    /// dropped pivot is zero in every solve and its equation is left out. For a saddle-point
    /// matrix whose multipliers are ordered last (`from` = the first multiplier) and whose
    /// constraint rows are dependent (redundant constraints), that is the basic solution: the
    /// dependent equations carry zero multipliers, as with
    /// [`crate::DenseCholesky::set_max_dependent`]. The static elimination order drops
    /// such pivots; the general path (partial pivoting) drops a column without a usable pivot, and
    /// the row left over for it is the dependent equation. Allocates once.
    pub fn set_droppable(&mut self, from: usize, max: usize) {
        self.drop_from = from.min(self.n);
        self.drop_max = max.min(self.n - self.drop_from);
        self.dropped = Vec::with_capacity(self.drop_max);
        self.factored = false;
    }

    /// The caller's unknowns (columns) whose pivots the last factorisation dropped (see
    /// [`DenseLu::set_droppable`]).
    pub fn dropped(&self) -> impl Iterator<Item = usize> + '_ {
        self.dropped.iter().map(|&k| self.cols[k])
    }

    /// Dimension.
    pub fn dim(&self) -> usize {
        self.n
    }

    /// The storage (ordered numbering, the natural one for [`DenseLu::new`]) as a matrix, to be
    /// overwritten entirely (after a factorisation it holds the factors), then factored by
    /// [`DenseLu::factor_in_place`] or [`DenseLu::factor_lu`].
    pub fn matrix_mut(&mut self) -> MatMut<'_, f64> {
        self.raw = true;
        self.factored = false;
        MatMut::from_row_major_slice_mut(&mut self.f, self.n, self.n)
    }

    /// The storage as a row-major slice (`a[r * n + c]`, ordered numbering), to be overwritten
    /// entirely, like [`DenseLu::matrix_mut`].
    pub fn rows_mut(&mut self) -> &mut [f64] {
        self.raw = true;
        self.factored = false;
        &mut self.f
    }

    /// Copies `a` (natural numbering of [`DenseLu::new`]) in and factors it; the error gives
    /// the unknown (column) without a usable pivot.
    pub fn factor(&mut self, a: &DMatrix<f64>) -> Result<(), FactorError> {
        let n = self.n;
        for r in 0..n {
            for c in 0..n {
                self.f[r * n + c] = a[(r, c)];
            }
        }
        self.raw = true;
        self.factor_in_place()
    }

    /// Factors the matrix written through [`DenseLu::matrix_mut`] (or the entry methods); the
    /// error gives the unknown (column) without a usable pivot.
    pub fn factor_in_place(&mut self) -> Result<(), FactorError> {
        self.factor_lu().map_err(|e| match e {
            LuError::Singular { col, .. } | LuError::NonFinite { col, .. } => {
                FactorError::Singular(col)
            }
        })
    }

    /// Smallest and largest pivot magnitude of the last successful factorisation (unscaled).
    pub fn pivot_range(&self) -> (f64, f64) {
        self.dinv[..self.n]
            .iter()
            .fold((f64::INFINITY, 0.0f64), |(lo, hi), &d| {
                let p = 1.0 / d.abs();
                (lo.min(p), hi.max(p))
            })
    }

    /// `ln |det A|` of the last successful factorisation: the sum of the logarithms of the
    /// pivot magnitudes (no overflow or underflow for any size).
    pub fn log_abs_det(&self) -> f64 {
        -self.dinv[..self.n]
            .iter()
            .map(|d| d.abs().ln())
            .sum::<f64>()
    }

    /// Number of factorisations in which a static pivot failed the threshold test, so the
    /// general path was taken.
    pub fn fallbacks(&self) -> usize {
        self.fallbacks
    }

    /// Number of factorisations that needed the equilibration's scale factors.
    pub fn equilibrations(&self) -> usize {
        self.equilibrations
    }

    /// Number of symbolic factorisations (one per growth of the pattern).
    pub fn analyses(&self) -> usize {
        self.analyses
    }

    /// Sets the matrix to zero (before it is written by [`DenseLu::add`] / [`DenseLu::set`]).
    pub fn clear(&mut self) {
        self.factored = false;
        self.f.fill(0.0);
    }

    /// Adds `v` to the entry `(r, c)` (the caller's numbering).
    #[inline]
    pub fn add(&mut self, r: usize, c: usize, v: f64) {
        let k = self.rpos[r] * self.n + self.cpos[c];
        self.f[k] += v;
        self.track(k, v);
    }

    /// Sets the entry `(r, c)` (the caller's numbering) to `v`.
    #[inline]
    pub fn set(&mut self, r: usize, c: usize, v: f64) {
        let k = self.rpos[r] * self.n + self.cpos[c];
        self.f[k] = v;
        self.track(k, v);
    }

    #[inline]
    fn track(&mut self, k: usize, v: f64) {
        if v != 0.0 && !self.mask[k] {
            self.mask[k] = true;
            self.dirty = true;
        }
    }
}

#[cfg(test)]
mod tests;
