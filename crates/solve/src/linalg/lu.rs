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
//! [`DenseLu::solve`] touches only the recorded nonzeros of `L` and `U`.

/// A diagonal pivot is kept if it is at least this fraction of the largest entry of its column.
pub const PIVOT_THRESHOLD: f64 = 0.1;

/// A pivot of the equilibrated matrix below `PIVOT_TOL n` is negligible (the matrix singular):
/// a few hundred rounding errors of its O(1) entries. The default of [`DenseLu::pivot_tol`].
pub const PIVOT_TOL: f64 = 1e-14;

use super::{pow2_inverse, FactorError, LuError};
use faer::MatMut;
use nalgebra::DMatrix;

/// Nonzero lists of `L` (by columns) and `U` (by rows) of one factorisation.
#[derive(Clone, Debug, Default)]
struct Pattern {
    /// Rows of the multipliers of column `k`: `l_idx[l_start[k]..l_start[k + 1]]`.
    l_idx: Vec<usize>,
    l_start: Vec<usize>,
    /// Columns right of the diagonal in the `k`-th pivot row: `u_idx[u_start[k]..u_start[k + 1]]`.
    u_idx: Vec<usize>,
    u_start: Vec<usize>,
}

impl Pattern {
    fn new(n: usize) -> Self {
        Pattern {
            l_idx: vec![0; n * n],
            l_start: vec![0; n + 1],
            u_idx: vec![0; n * n],
            u_start: vec![0; n + 1],
        }
    }
}

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
        }
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

    /// Symbolic factorisation of `mask` with the diagonal pivots of the ordering.
    fn analyse(&mut self) {
        let n = self.n;
        self.n_nz = 0;
        for (k, &m) in self.mask.iter().enumerate() {
            if k % n == 0 {
                self.nz_start[k / n] = self.n_nz;
            }
            if m {
                self.nz[self.n_nz] = k;
                self.nz_col[self.n_nz] = k % n;
                self.n_nz += 1;
            }
        }
        self.nz_start[n] = self.n_nz;
        let mask = &mut self.fill;
        mask.copy_from_slice(&self.mask);
        let p = &mut self.symbolic;
        let (mut nl, mut nu) = (0, 0);
        for k in 0..n {
            p.u_start[k] = nu;
            for j in k + 1..n {
                if mask[k * n + j] {
                    p.u_idx[nu] = j;
                    nu += 1;
                }
            }
            p.l_start[k] = nl;
            for i in k + 1..n {
                if mask[i * n + k] {
                    p.l_idx[nl] = i;
                    nl += 1;
                    for &j in &p.u_idx[p.u_start[k]..nu] {
                        mask[i * n + j] = true;
                    }
                }
            }
        }
        p.l_start[n] = nl;
        p.u_start[n] = nu;
        self.dirty = false;
        self.analyses += 1;
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

    /// Factors the matrix in place (singularity tests on the equilibrated matrix, see the
    /// module docs). Errors name the entry, row or unknown at fault in the caller's numbering.
    pub fn factor_lu(&mut self) -> Result<(), LuError> {
        let n = self.n;
        self.factored = false;
        if self.raw {
            // written directly: every nonzero joins the pattern
            for (k, &v) in self.f.iter().enumerate() {
                if v != 0.0 && !self.mask[k] {
                    self.mask[k] = true;
                    self.dirty = true;
                }
            }
            self.raw = false;
        }
        if self.dirty {
            self.analyse();
        }
        // the entries outside the pattern are zero: the largest entry and the copy for the
        // fallback need only the pattern's
        let mut gmax = 0.0f64;
        // (a NaN or infinite entry makes the sum non-finite; so can an overflow, which the
        // search below then does not confirm)
        let mut sum = 0.0f64;
        for (b, &k) in self.backup.iter_mut().zip(&self.nz[..self.n_nz]) {
            let v = self.f[k];
            *b = v;
            let a = v.abs();
            sum += a;
            if a > gmax {
                gmax = a;
            }
        }
        if !sum.is_finite() {
            let bad = self.nz[..self.n_nz]
                .iter()
                .find(|&&k| !self.f[k].is_finite());
            if let Some(&k) = bad {
                return Err(LuError::NonFinite {
                    row: self.rows[k / n],
                    col: self.cols[k % n],
                });
            }
        }
        self.scaled = false;
        let tol = self.pivot_tol * n as f64;
        for (k, r) in self.rp.iter_mut().enumerate() {
            *r = k;
        }
        if self.factor_static(tol, gmax)? {
            self.static_used = true;
            self.factored = true;
            return Ok(());
        }
        self.fallbacks += 1;
        self.f.fill(0.0);
        for (&b, &k) in self.backup.iter().zip(&self.nz[..self.n_nz]) {
            self.f[k] = b;
        }
        self.static_used = false;
        self.equilibrate()?;
        self.factor_dynamic(tol)
            .map_err(|(i, k)| LuError::Singular {
                row: self.rows[i],
                col: self.cols[k],
            })?;
        self.factored = true;
        Ok(())
    }

    /// The scale factors of the equilibration (from `backup`, the matrix before elimination),
    /// once per factorisation: row by row, the row's largest entry and its scale factor, then
    /// the column maxima of the row-scaled matrix. An all-zero row or column is an error.
    fn equilibrate(&mut self) -> Result<(), LuError> {
        if self.scaled {
            return Ok(());
        }
        let (nz_col, backup) = (&self.nz_col, &self.backup);
        let cmax = &mut self.cmax;
        cmax.fill(0.0);
        for (i, (w, r)) in self
            .nz_start
            .windows(2)
            .zip(self.rscale.iter_mut())
            .enumerate()
        {
            let row = &backup[w[0]..w[1]];
            let mx = row.iter().fold(0.0f64, |m, b| m.max(b.abs()));
            if mx == 0.0 {
                return Err(LuError::Singular {
                    row: self.rows[i],
                    col: self.cols[i],
                });
            }
            let sc = pow2_inverse(mx);
            *r = sc;
            for (&b, &j) in row.iter().zip(&nz_col[w[0]..w[1]]) {
                let c = &mut cmax[j];
                *c = c.max(b.abs() * sc);
            }
        }
        for (j, (sc, &mx)) in self.cscale.iter_mut().zip(cmax.iter()).enumerate() {
            if mx == 0.0 {
                return Err(LuError::Singular {
                    row: self.rows[j],
                    col: self.cols[j],
                });
            }
            *sc = pow2_inverse(mx);
        }
        self.scaled = true;
        self.equilibrations += 1;
        Ok(())
    }

    /// Elimination with the static diagonal pivots over the symbolic pattern; `Ok(false)`
    /// (with the matrix partly eliminated) if a pivot fails the threshold test (at least
    /// `PIVOT_THRESHOLD` times the largest entry below it) or the singularity test.
    ///
    /// The singularity test is `|u_kk| r_k c_k > tol` in the equilibrated matrix. Since every
    /// entry of the row-scaled matrix is below 1, `c_k >= 1/2`, and `r_k > 1 / (2 max |A|)`,
    /// so `|u_kk| > 4 tol max |A|` passes it without the scale factors, which are computed
    /// only when a pivot is smaller than that (on the papers' models: at h below about 1e-4).
    fn factor_static(&mut self, tol: f64, gmax: f64) -> Result<bool, LuError> {
        let n = self.n;
        let sure = 4.0 * tol * gmax;
        for k in 0..n {
            let piv = self.f[k * n + k];
            let pa = piv.abs();
            if pa.is_nan() {
                return Ok(false);
            }
            if pa <= sure {
                self.equilibrate()?;
                if pa * self.rscale[k] * self.cscale[k] <= tol {
                    return Ok(false);
                }
            }
            let (a, p) = (&mut self.f, &self.symbolic);
            let (l_val, u_val, dinv) = (&mut self.l_val, &mut self.u_val, &mut self.dinv);
            let (ls, le) = (p.l_start[k], p.l_start[k + 1]);
            let lrows = &p.l_idx[ls..le];
            // (the entries were checked finite; a NaN from an overflow in the elimination,
            // which `max` would skip here, reaches a later pivot through the multipliers and
            // fails its test)
            let colmax = lrows.iter().fold(0.0f64, |m, &i| m.max(a[i * n + k].abs()));
            if pa < PIVOT_THRESHOLD * colmax {
                return Ok(false);
            }
            let (us, ue) = (p.u_start[k], p.u_start[k + 1]);
            let ucols = &p.u_idx[us..ue];
            for (v, &j) in u_val[us..ue].iter_mut().zip(ucols) {
                *v = a[k * n + j];
            }
            let uv = &u_val[us..ue];
            let inv = 1.0 / piv;
            dinv[k] = inv;
            for (lv, &i) in l_val[ls..le].iter_mut().zip(lrows) {
                let row = &mut a[i * n..(i + 1) * n];
                let f = row[k] * inv;
                *lv = f;
                if f != 0.0 {
                    for (&j, &v) in ucols.iter().zip(uv) {
                        row[j] -= f * v;
                    }
                }
            }
        }
        Ok(true)
    }

    /// Threshold partial pivoting, recording the nonzeros of `L` and `U`; `Err((i, k))` if
    /// column `k` has no usable pivot (`i`: the physical row at position `k`).
    fn factor_dynamic(&mut self, tol: f64) -> Result<(), (usize, usize)> {
        let n = self.n;
        let a = &mut self.f;
        let p = &mut self.dynamic;
        for (k, r) in self.rp.iter_mut().enumerate() {
            *r = k;
        }
        let (mut nl, mut nu) = (0, 0);
        let (rs, cs) = (&self.rscale, &self.cscale);
        for k in 0..n {
            // scaled partial pivoting: magnitudes in the equilibrated matrix
            let diag = a[self.rp[k] * n + k].abs() * rs[self.rp[k]];
            let mut piv = k;
            let mut best = diag;
            for i in k + 1..n {
                let v = a[self.rp[i] * n + k].abs() * rs[self.rp[i]];
                // (a NaN is taken, and fails the test below)
                if v > best || v.is_nan() {
                    best = v;
                    piv = i;
                }
            }
            if best.is_nan() || best * cs[k] <= tol {
                return Err((self.rp[piv], k));
            }
            if diag < PIVOT_THRESHOLD * best {
                self.rp.swap(k, piv);
            }
            let pk = self.rp[k];
            // the nonzeros of the pivot row right of the diagonal: the row of U
            p.u_start[k] = nu;
            for (j, &v) in a[pk * n..(pk + 1) * n].iter().enumerate().skip(k + 1) {
                if v != 0.0 {
                    p.u_idx[nu] = j;
                    self.u_val[nu] = v;
                    nu += 1;
                }
            }
            let uc = &p.u_idx[p.u_start[k]..nu];
            let uv = &self.u_val[p.u_start[k]..nu];
            let inv = 1.0 / a[pk * n + k];
            self.dinv[k] = inv;
            p.l_start[k] = nl;
            for &ph in &self.rp[k + 1..] {
                let row = &mut a[ph * n..(ph + 1) * n];
                let f = row[k];
                if f != 0.0 {
                    let f = f * inv;
                    for (&j, &v) in uc.iter().zip(uv) {
                        row[j] -= f * v;
                    }
                    p.l_idx[nl] = ph;
                    self.l_val[nl] = f;
                    nl += 1;
                }
            }
        }
        p.l_start[n] = nl;
        p.u_start[n] = nu;
        Ok(())
    }

    /// Solves `A x = b` in place after a successful factorisation (`b` and `x` in the
    /// caller's numbering; without one, `b` is left unchanged).
    pub fn solve_in_place(&mut self, b: &mut [f64]) {
        let (mut y, mut x) = (std::mem::take(&mut self.y), std::mem::take(&mut self.x));
        self.solve_with(b, &mut y, &mut x);
        (self.y, self.x) = (y, x);
    }

    /// [`DenseLu::solve_in_place`] through a shared reference, with the caller's workspace
    /// (`y` and `x` of length at least `n`).
    pub fn solve_with(&self, b: &mut [f64], y: &mut [f64], x: &mut [f64]) {
        let n = self.n;
        if !self.factored || b.len() != n || y.len() < n || x.len() < n {
            return;
        }
        let rp = &self.rp;
        let p = if self.static_used {
            &self.symbolic
        } else {
            &self.dynamic
        };
        for (yi, &r) in y.iter_mut().zip(&self.rows) {
            *yi = b[r];
        }
        // forward: L z = P y, column by column (z_k ends in y[rp[k]])
        for k in 0..n {
            let yk = y[rp[k]];
            if yk != 0.0 {
                let (ls, le) = (p.l_start[k], p.l_start[k + 1]);
                for (&ph, &l) in p.l_idx[ls..le].iter().zip(&self.l_val[ls..le]) {
                    y[ph] -= l * yk;
                }
            }
        }
        // backward: U x = z, row by row
        for k in (0..n).rev() {
            let (us, ue) = (p.u_start[k], p.u_start[k + 1]);
            let mut s = 0.0;
            for (&j, &u) in p.u_idx[us..ue].iter().zip(&self.u_val[us..ue]) {
                s += u * x[j];
            }
            x[k] = (y[rp[k]] - s) * self.dinv[k];
        }
        for (&xj, &c) in x.iter().zip(&self.cols) {
            b[c] = xj;
        }
    }

    /// Solves `A^T x = b` in place after a successful factorisation (`b` and `x` in the
    /// caller's numbering; without one, `b` is left unchanged).
    pub fn solve_transpose_in_place(&mut self, b: &mut [f64]) {
        let n = self.n;
        if !self.factored || b.len() != n {
            return;
        }
        let (y, x, rp) = (&mut self.y, &mut self.x, &self.rp);
        let p = if self.static_used {
            &self.symbolic
        } else {
            &self.dynamic
        };
        // the ordered matrix is B = P^T L U (P: pivot k is physical row rp[k]), so
        // B^T = U^T L^T P: U^T w = d, then L^T v = w, then y = P^T v
        for (xj, &c) in x.iter_mut().zip(&self.cols) {
            *xj = b[c];
        }
        for k in 0..n {
            let wk = x[k] * self.dinv[k];
            x[k] = wk;
            if wk != 0.0 {
                let (us, ue) = (p.u_start[k], p.u_start[k + 1]);
                for (&j, &u) in p.u_idx[us..ue].iter().zip(&self.u_val[us..ue]) {
                    x[j] -= u * wk;
                }
            }
        }
        // L^T v = w backwards, v kept by physical row (L's rows are physical)
        for k in (0..n).rev() {
            let (ls, le) = (p.l_start[k], p.l_start[k + 1]);
            let mut v = x[k];
            for (&ph, &l) in p.l_idx[ls..le].iter().zip(&self.l_val[ls..le]) {
                v -= l * y[ph];
            }
            y[rp[k]] = v;
        }
        for (&yi, &r) in y.iter().zip(&self.rows) {
            b[r] = yi;
        }
    }
}

#[cfg(test)]
mod tests;
