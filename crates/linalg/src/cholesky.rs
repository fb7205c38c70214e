//! The dense Cholesky factorisation [`DenseCholesky`] on a preallocated workspace: kernels of
//! fixed dimension up to [`FIXED_CHOLESKY`], plain loops up to [`SMALL_CHOLESKY`], faer's
//! blocked factorisation above; a scale-invariant pivot test and a condition estimate.

use crate::{semidefinite, FactorError, LinalgError, Scratch};
use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::cholesky::llt;
use faer::{MatMut, Par};

/// Below this dimension [`DenseCholesky`] uses a plain unblocked factorisation: for the
/// handful of constraints of a small mechanism, faer's blocked, SIMD-dispatched routine spends
/// more in set-up than in arithmetic (measured with callgrind on the manipulator, m = 4: the
/// faer factorisation and solve took about 5,000 instructions per RK4 stage, the unblocked loops
/// a few hundred). Larger systems go to faer.
pub const SMALL_CHOLESKY: usize = 16;

/// Up to this dimension [`DenseCholesky::solve_in_place`] solves with plain loops over the
/// factor whichever path factored it: one right-hand side is `O(m^2)` either way, and faer's
/// set-up dominated up to here (callgrind, a 10-link chain, m = 20: about 5,600 instructions
/// per faer solve against about 1,000 for the loops).
pub const SMALL_CHOLESKY_SOLVE: usize = 64;

/// Up to this dimension [`DenseCholesky`] factors and solves with one kernel per dimension
/// (loops of known length, which the compiler unrolls): at these sizes the loops of run-time
/// length spent more on loop control than on arithmetic (callgrind, the manipulator's m = 4:
/// about 650 instructions per factorisation and 430 per solve with run-time lengths).
pub const FIXED_CHOLESKY: usize = 8;

/// Calls `$f::<m>(args)` for `m = $m` up to [`FIXED_CHOLESKY`], else evaluates `$other`.
macro_rules! by_dimension {
    ($m:expr, $f:ident($($arg:expr),*), $other:expr) => {
        match $m {
            1 => $f::<1>($($arg),*),
            2 => $f::<2>($($arg),*),
            3 => $f::<3>($($arg),*),
            4 => $f::<4>($($arg),*),
            5 => $f::<5>($($arg),*),
            6 => $f::<6>($($arg),*),
            7 => $f::<7>($($arg),*),
            8 => $f::<8>($($arg),*),
            _ => $other,
        }
    };
}

/// `d > 0` and finite, in two floating-point comparisons (`d - d` is zero exactly for finite
/// `d`), where `d.is_finite()` or `d < inf` compiled to an integer classification of the bits.
#[inline(always)]
#[allow(clippy::eq_op)]
fn positive_finite(d: f64) -> bool {
    d > 0.0 && d - d == 0.0
}

/// [`DenseCholesky::factor_in_place`] for a fixed dimension `M`: the same checks and
/// operations in the same order as the run-time-length loops; returns the condition estimate.
#[inline]
fn factor_fixed<const M: usize>(
    a: &mut [f64],
    diag: &mut [f64],
    inv: &mut [f64],
) -> Result<f64, FactorError> {
    let (a, diag, inv) = (&mut a[..M * M], &mut diag[..M], &mut inv[..M]);
    for j in 0..M {
        let d = a[j + j * M];
        if !positive_finite(d) {
            return Err(FactorError::NotPositiveDefinite(j));
        }
        diag[j] = d;
    }
    // (the indices are constants once unrolled: L is read from the lower triangle alone)
    for j in 0..M {
        let mut d = a[j + j * M];
        for k in 0..j {
            let l = a[j + k * M];
            d -= l * l;
        }
        if !(d > 0.0) {
            return Err(FactorError::NotPositiveDefinite(j));
        }
        let ljj = d.sqrt();
        a[j + j * M] = ljj;
        let ij = 1.0 / ljj;
        inv[j] = ij;
        for i in j + 1..M {
            let mut y = a[i + j * M];
            for k in 0..j {
                y -= a[i + k * M] * a[j + k * M];
            }
            a[i + j * M] = y * ij;
        }
    }
    let mut worst = 0.0f64;
    for i in 0..M {
        let l = a[i + i * M];
        let ratio = diag[i] / (l * l);
        if !(ratio * CHOLESKY_PIVOT_TOL <= 1.0) {
            return Err(FactorError::NotPositiveDefinite(i));
        }
        worst = worst.max(ratio);
    }
    Ok(worst)
}

/// `b <- L^-1 b` for a fixed dimension `M`, by rows.
#[inline]
fn forward_fixed<const M: usize>(a: &[f64], inv: &[f64], b: &mut [f64]) {
    let (a, inv, b) = (&a[..M * M], &inv[..M], &mut b[..M]);
    for i in 0..M {
        let mut x = b[i];
        for k in 0..i {
            x -= a[i + k * M] * b[k];
        }
        b[i] = x * inv[i];
    }
}

/// `b <- L^-T b` for a fixed dimension `M` (column i of L below the diagonal is row i of L^T).
#[inline]
fn backward_fixed<const M: usize>(a: &[f64], inv: &[f64], b: &mut [f64]) {
    let (a, inv, b) = (&a[..M * M], &inv[..M], &mut b[..M]);
    for i in (0..M).rev() {
        let mut acc = 0.0;
        for k in i + 1..M {
            acc += a[k + i * M] * b[k];
        }
        b[i] = (b[i] - acc) * inv[i];
    }
}

/// Cholesky `L L^T` of a symmetric positive definite `m x m` matrix, reusing its storage.
/// Only the lower triangle of the matrix is read (above [`FIXED_CHOLESKY`] and up to
/// [`SMALL_CHOLESKY`] the factorisation also writes `L^T` into the upper triangle, for its
/// triangular solves: fill the matrix again, after [`DenseCholesky::clear`] for
/// [`DenseCholesky::add_rank_one`], before the next factorisation).
#[derive(Debug)]
pub struct DenseCholesky {
    m: usize,
    /// Column-major `m x m` storage: the matrix, then its factor.
    a: Vec<f64>,
    /// The matrix's diagonal before the last factorisation.
    diag: Vec<f64>,
    /// `1 / L_jj` of the last factorisation (the small solves multiply: a division's latency
    /// is several multiplications').
    inv: Vec<f64>,
    /// `max_j A_jj / L_jj^2` of the last factorisation.
    condition: f64,
    mem: Scratch,
    factored: bool,
    /// How many dependent rows a factorisation may drop (0: the matrix must be definite).
    max_dependent: usize,
    /// The rows dropped by the last factorisation (capacity `m`).
    dependent: Vec<usize>,
    /// The matrix before a semidefinite factorisation's strict pass (allocated by
    /// [`DenseCholesky::set_max_dependent`] for `k > 0`).
    backup: Vec<f64>,
    /// Whether the last factorisation was pivoted (`semidefinite::factor_pivoted`), and its
    /// row exchanges and scratch (allocated with `backup`).
    pivoted: bool,
    piv: Vec<usize>,
    perm: Vec<usize>,
    /// Pivot every semidefinite factorisation (a rank-revealing row selection), not only
    /// ill-conditioned ones.
    always_pivot: bool,
}

/// Smallest accepted pivot of [`DenseCholesky`], relative to the matrix's own diagonal entry:
/// `L_jj^2 >= CHOLESKY_PIVOT_TOL * A_jj`. The ratio `L_jj^2 / A_jj` is the part of row `j`
/// that the earlier rows do not explain (for `S = Phi_q M^-1 Phi_q^T`: the squared sine of the
/// angle, in the `M^-1` metric, between constraint gradient `j` and the span of the earlier
/// ones). It does not change when rows and columns are scaled (`D A D`), so badly scaled but
/// well-posed mechanisms (millimetre parts beside tonne masses) pass, while dependent
/// constraints or a singular configuration (the ratio at round-off level) fail.
pub const CHOLESKY_PIVOT_TOL: f64 = 1e-14;

impl DenseCholesky {
    /// Workspace for `m x m` matrices (aborts, like `Vec`, if the storage cannot be allocated:
    /// [`DenseCholesky::try_new`] reports that instead).
    pub fn new(m: usize) -> Self {
        let req = StackReq::any_of(&[
            llt::factor::cholesky_in_place_scratch::<f64>(m, Par::Seq, Default::default()),
            llt::solve::solve_in_place_scratch::<f64>(m, 1, Par::Seq),
        ]);
        DenseCholesky {
            m,
            a: vec![0.0; m * m],
            diag: vec![0.0; m],
            inv: vec![0.0; m],
            condition: 0.0,
            mem: Scratch(MemBuffer::new(req)),
            factored: false,
            max_dependent: 0,
            dependent: Vec::new(),
            backup: Vec::new(),
            pivoted: false,
            piv: Vec::new(),
            perm: Vec::new(),
            always_pivot: false,
        }
    }

    /// Workspace for `m x m` matrices, or [`LinalgError::Allocation`] when the storage (`m^2`
    /// numbers and faer's scratch memory) cannot be allocated.
    ///
    /// ```
    /// use mbd_linalg::{DenseCholesky, LinalgError};
    /// assert_eq!(DenseCholesky::try_new(3)?.dim(), 3);
    /// let huge = 1usize << 40;
    /// assert_eq!(
    ///     DenseCholesky::try_new(huge).unwrap_err(),
    ///     LinalgError::Allocation { rows: huge, cols: huge }
    /// );
    /// # Ok::<(), LinalgError>(())
    /// ```
    pub fn try_new(m: usize) -> Result<Self, LinalgError> {
        let too_big = LinalgError::Allocation { rows: m, cols: m };
        let mm = m.checked_mul(m).ok_or(too_big.clone())?;
        let zeros = |len: usize| -> Result<Vec<f64>, LinalgError> {
            let mut v = Vec::new();
            v.try_reserve_exact(len).map_err(|_| too_big.clone())?;
            v.resize(len, 0.0);
            Ok(v)
        };
        let a = zeros(mm)?;
        let diag = zeros(m)?;
        let inv = zeros(m)?;
        let req = StackReq::any_of(&[
            llt::factor::cholesky_in_place_scratch::<f64>(m, Par::Seq, Default::default()),
            llt::solve::solve_in_place_scratch::<f64>(m, 1, Par::Seq),
        ]);
        let mem = MemBuffer::try_new(req).map_err(|_| too_big)?;
        Ok(DenseCholesky {
            m,
            a,
            diag,
            inv,
            condition: 0.0,
            mem: Scratch(mem),
            factored: false,
            max_dependent: 0,
            dependent: Vec::new(),
            backup: Vec::new(),
            pivoted: false,
            piv: Vec::new(),
            perm: Vec::new(),
            always_pivot: false,
        })
    }

    /// Lets each factorisation drop up to `k` rows that depend on the earlier ones (a
    /// positive *semi*definite matrix of rank `m - k`, as `Phi_q M^-1 Phi_q^T` is for a
    /// mechanism with `k` redundant constraint equations): a dropped row's unknown is zero in
    /// every solve (see the module `semidefinite`: the basic solution). `k = 0` (the default)
    /// is the definite factorisation, unchanged. With `k > 0` every factorisation and solve
    /// runs the plain loops. Allocates the list of dropped rows (once).
    ///
    /// ```
    /// use mbd_linalg::DenseCholesky;
    /// // rows 0 and 2 equal: rank 2
    /// let a = [[1.0, 0.5, 1.0], [0.5, 2.0, 0.5], [1.0, 0.5, 1.0]];
    /// let mut c = DenseCholesky::new(3);
    /// c.set_max_dependent(1);
    /// for (r, row) in a.iter().enumerate() {
    ///     for (k, v) in row.iter().enumerate() {
    ///         c.matrix_mut()[(r, k)] = *v;
    ///     }
    /// }
    /// c.factor_in_place()?;
    /// assert_eq!(c.dependent(), &[2]);
    /// // a right-hand side in the range of the matrix: A x = b with x_2 = 0
    /// let mut x = [1.5, 2.5, 1.5];
    /// c.solve_in_place(&mut x);
    /// assert!((x[0] - 1.0).abs() < 1e-15 && (x[1] - 1.0).abs() < 1e-15 && x[2] == 0.0);
    /// # Ok::<(), mbd_linalg::FactorError>(())
    /// ```
    pub fn set_max_dependent(&mut self, k: usize) {
        self.max_dependent = k.min(self.m);
        self.dependent = Vec::with_capacity(self.m);
        (self.backup, self.piv, self.perm) = if k > 0 {
            (vec![0.0; self.m * self.m], vec![0; self.m], vec![0; self.m])
        } else {
            (Vec::new(), Vec::new(), Vec::new())
        };
        self.pivoted = false;
        self.factored = false;
    }

    /// Makes every semidefinite factorisation pivoted (`true`), not only those whose natural
    /// order meets a pivot ratio below [`crate::PIVOTING_RATIO`] (the default, `false`): the
    /// rows kept are then the best-conditioned set the diagonal pivoting finds, and the rows
    /// dropped ([`DenseCholesky::dependent`]) the ones the others explain best, wherever they
    /// stand in the matrix. For choosing which equations of a redundant mechanism to keep
    /// near a singular configuration.
    pub fn set_always_pivot(&mut self, on: bool) {
        self.always_pivot = on;
        self.factored = false;
    }

    /// The rows dropped as dependent by the last factorisation, in increasing order (empty
    /// unless [`DenseCholesky::set_max_dependent`] allowed some).
    pub fn dependent(&self) -> &[usize] {
        &self.dependent
    }

    /// A cheap condition estimate of the last factored matrix after symmetric diagonal
    /// equilibration: `max_j A_jj / L_jj^2` (>= 1; a lower bound of the condition number of
    /// `D^-1/2 A D^-1/2`, `D = diag(A)`, that grows like the inverse square distance to a
    /// singular configuration). 0 before the first factorisation, infinite after a failed one.
    pub fn condition_estimate(&self) -> f64 {
        self.condition
    }

    /// Dimension.
    pub fn dim(&self) -> usize {
        self.m
    }

    /// Sets the matrix to zero (before [`DenseCholesky::add_rank_one`]).
    pub fn clear(&mut self) {
        self.factored = false;
        self.a.fill(0.0);
    }

    /// Adds `w x x^T` to the lower triangle.
    #[inline]
    pub fn add_rank_one(&mut self, w: f64, x: &[f64]) {
        let m = self.m;
        self.factored = false;
        for c in 0..m {
            let wc = w * x[c];
            if wc == 0.0 {
                continue;
            }
            let col = &mut self.a[c * m..(c + 1) * m];
            for r in c..m {
                col[r] += wc * x[r];
            }
        }
    }

    /// The column-major `m x m` storage of the matrix to be factored (the lower triangle is
    /// read), for assembly in place.
    #[inline]
    pub fn values_mut(&mut self) -> &mut [f64] {
        self.factored = false;
        &mut self.a
    }

    /// `A_rc += v` for `r >= c` (the lower triangle; entry by entry, e.g. summing a sparse
    /// product into it after [`DenseCholesky::clear`]).
    #[inline]
    pub fn add(&mut self, r: usize, c: usize, v: f64) {
        debug_assert!(r >= c && r < self.m);
        self.factored = false;
        self.a[r + c * self.m] += v;
    }

    /// `b <- L^-1 b` with the factor `A = L L^T` (so `x^T A^-1 y = (L^-1 x) . (L^-1 y)`: a
    /// quadratic form in `A^-1` from one triangular solve per vector). After a pivoted
    /// semidefinite factorisation `P A P^T = L L^T` it is `b <- L^-1 P b`, for which the same
    /// holds. Leaves `b` unchanged when nothing is factored.
    pub fn forward_in_place(&self, b: &mut [f64]) {
        let m = self.m;
        if m == 0 || !self.factored {
            return;
        }
        self.exchange(b, true);
        self.forward_unpivoted(b);
    }

    /// `b <- L^-1 b` (the row exchanges of a pivoted factorisation already applied).
    fn forward_unpivoted(&self, b: &mut [f64]) {
        let m = self.m;
        let a = &self.a;
        by_dimension!(m, forward_fixed(a, &self.inv, b), ());
        if m <= FIXED_CHOLESKY {
            return;
        }
        if m <= SMALL_CHOLESKY {
            // by rows, from the copy of L's rows in the upper triangle (the small
            // factorisation's): the same operations in the same order as by columns
            for i in 0..m {
                let row = &a[i * m..i * m + i];
                let mut x = b[i];
                for (&l, &y) in row.iter().zip(&b[..i]) {
                    x -= l * y;
                }
                b[i] = x * self.inv[i];
            }
            return;
        }
        // both factorisation paths leave L in the lower triangle of `a`; by columns (contiguous)
        for k in 0..m {
            let col = &a[k * m..(k + 1) * m];
            let x = b[k] * self.inv[k];
            b[k] = x;
            if x != 0.0 {
                for (bi, &l) in b[k + 1..m].iter_mut().zip(&col[k + 1..]) {
                    *bi -= l * x;
                }
            }
        }
    }

    /// The matrix to be factored (lower triangle is read): fill it, then call
    /// [`DenseCholesky::factor_in_place`].
    pub fn matrix_mut(&mut self) -> MatMut<'_, f64> {
        self.factored = false;
        MatMut::from_column_major_slice_mut(&mut self.a, self.m, self.m)
    }

    /// Factors the matrix written through [`DenseCholesky::matrix_mut`] or
    /// [`DenseCholesky::add_rank_one`]. A pivot below [`CHOLESKY_PIVOT_TOL`] times its own
    /// diagonal entry (a scale-invariant test) counts as not positive definite: for the
    /// constraint matrix `Phi_q M^-1 Phi_q^T` that means redundant constraints or a singular
    /// configuration. Also sets [`DenseCholesky::condition_estimate`].
    pub fn factor_in_place(&mut self) -> Result<(), FactorError> {
        self.factored = false;
        let m = self.m;
        if m == 0 {
            self.factored = true;
            self.condition = 1.0;
            return Ok(());
        }
        self.condition = f64::INFINITY;
        if self.max_dependent > 0 {
            // a strict pass first (only round-off-dependent rows dropped: a nearly dependent
            // row near a singular configuration is kept), the tolerant one where it finds
            // fewer dependent rows than allowed (semidefinite::ROUNDOFF_DEPENDENT_TOL)
            self.pivoted = false;
            self.backup.copy_from_slice(&self.a);
            let natural = self.factor_semidefinite(false);
            // near a singular configuration (a small kept pivot, or no factorisation at all)
            // the natural order can mistake or lose the dependent rows: pivoted, the nearly
            // singular directions come last (semidefinite::factor_pivoted)
            if !self.always_pivot && natural.is_ok_and(|c| c <= 1.0 / semidefinite::PIVOTING_RATIO)
            {
                self.condition = natural?;
                self.factored = true;
                return Ok(());
            }
            self.a.copy_from_slice(&self.backup);
            match self.factor_semidefinite(true) {
                Ok(c) => {
                    self.pivoted = true;
                    self.condition = c;
                }
                Err(e) => {
                    // the natural order's result where it had one (its error otherwise)
                    self.a.copy_from_slice(&self.backup);
                    self.condition = self.factor_semidefinite(false).map_err(|_| e)?;
                }
            }
            self.factored = true;
            return Ok(());
        }
        if m <= FIXED_CHOLESKY {
            let (a, diag, inv) = (&mut self.a, &mut self.diag, &mut self.inv);
            self.condition = by_dimension!(m, factor_fixed(a, diag, inv), unreachable!())?;
            self.factored = true;
            return Ok(());
        }
        for (j, dj) in self.diag.iter_mut().enumerate() {
            let d = self.a[j + j * m];
            if !positive_finite(d) {
                return Err(FactorError::NotPositiveDefinite(j));
            }
            *dj = d;
        }
        if m <= SMALL_CHOLESKY {
            // The textbook dot-product form, `L_ij = (A_ij - sum_k<j L_ik L_jk) / L_jj`, with
            // every row of L also kept in the (otherwise unused) upper triangle: row i of L
            // before column j is then the contiguous `a[i m..i m + j]`, so each sum is a short
            // scalar loop over two contiguous slices.
            let a = &mut self.a[..m * m];
            for j in 0..m {
                let (_, from_j) = a.split_at_mut(j * m);
                let (colj, after) = from_j.split_at_mut(m);
                // row j of L (columns k < j), then A_jj and the column below it
                let (lj, low) = colj.split_at_mut(j);
                let mut d = low[0];
                for &l in lj.iter() {
                    d -= l * l;
                }
                if !(d > 0.0) {
                    return Err(FactorError::NotPositiveDefinite(j));
                }
                let ljj = d.sqrt();
                low[0] = ljj;
                let inv = 1.0 / ljj;
                for (r, x) in low[1..].iter_mut().enumerate() {
                    // row i = j + 1 + r: its L_ik, k < j, at the top of column i
                    let coli = &mut after[r * m..r * m + j + 1];
                    let mut y = *x;
                    for (&lik, &ljk) in coli.iter().zip(lj.iter()) {
                        y -= lik * ljk;
                    }
                    let lij = y * inv;
                    *x = lij;
                    coli[j] = lij;
                }
            }
        } else {
            let stack = MemStack::new(&mut self.mem.0);
            let mat = MatMut::from_column_major_slice_mut(&mut self.a, m, m);
            if let Err(llt::factor::LltError::NonPositivePivot { index }) =
                llt::factor::cholesky_in_place(
                    mat,
                    Default::default(),
                    Par::Seq,
                    stack,
                    Default::default(),
                )
            {
                return Err(FactorError::NotPositiveDefinite(index));
            }
        }
        let mut worst = 0.0f64;
        for i in 0..m {
            let l = self.a[i + i * m];
            let ratio = self.diag[i] / (l * l);
            if !(ratio * CHOLESKY_PIVOT_TOL <= 1.0) {
                return Err(FactorError::NotPositiveDefinite(i));
            }
            worst = worst.max(ratio);
            self.inv[i] = 1.0 / l;
        }
        self.condition = worst;
        self.factored = true;
        Ok(())
    }

    /// The semidefinite factorisation of the matrix in `a` (`max_dependent > 0`), natural
    /// or pivoted: a strict pass that drops only rows dependent to round-off
    /// ([`semidefinite::ROUNDOFF_DEPENDENT_TOL`]), then, where it dropped fewer than
    /// `max_dependent`, a tolerant one ([`semidefinite::DEPENDENT_PIVOT_TOL`]) from the
    /// matrix in `backup`. Returns the condition estimate.
    fn factor_semidefinite(&mut self, pivoted: bool) -> Result<f64, FactorError> {
        let (m, k) = (self.m, self.max_dependent);
        let mut strict = true;
        loop {
            let tol = if strict {
                semidefinite::ROUNDOFF_DEPENDENT_TOL
            } else {
                semidefinite::DEPENDENT_PIVOT_TOL
            };
            let (a, diag, inv, dep) = (
                &mut self.a,
                &mut self.diag,
                &mut self.inv,
                &mut self.dependent,
            );
            let c = if pivoted {
                let (piv, perm) = (&mut self.piv, &mut self.perm);
                semidefinite::factor_pivoted(a, diag, inv, piv, perm, m, k, dep, tol)?
            } else {
                semidefinite::factor(a, diag, inv, m, k, dep, tol)?
            };
            if !strict || self.dependent.len() == k {
                return Ok(c);
            }
            strict = false;
            self.a.copy_from_slice(&self.backup);
        }
    }

    /// Applies the row exchanges of a pivoted factorisation to `b` (`forward`), or undoes
    /// them (nothing after an unpivoted factorisation).
    #[inline]
    fn exchange(&self, b: &mut [f64], forward: bool) {
        if !self.pivoted {
            return;
        }
        if forward {
            for (j, &p) in self.piv.iter().enumerate() {
                b.swap(j, p);
            }
        } else {
            for (j, &p) in self.piv.iter().enumerate().rev() {
                b.swap(j, p);
            }
        }
    }

    /// Solves `A x = b` in place.
    pub fn solve_in_place(&mut self, b: &mut [f64]) {
        let m = self.m;
        if m == 0 || !self.factored {
            return;
        }
        // a pivoted factor solves the exchanged system (its L is stored as the others')
        self.exchange(b, true);
        self.solve_unpivoted(b);
        self.exchange(b, false);
    }

    /// [`DenseCholesky::solve_in_place`] with the row exchanges already applied.
    fn solve_unpivoted(&mut self, b: &mut [f64]) {
        let m = self.m;
        if m <= FIXED_CHOLESKY {
            let (a, inv) = (&self.a, &self.inv);
            by_dimension!(m, forward_fixed(a, inv, b), ());
            by_dimension!(m, backward_fixed(a, inv, b), ());
            return;
        }
        if m <= SMALL_CHOLESKY_SOLVE || self.max_dependent > 0 {
            // L y = b, then L^T x = y (row i of L^T is column i of L: contiguous)
            self.forward_unpivoted(b);
            let a = &self.a;
            for i in (0..m).rev() {
                let (head, tail) = b.split_at_mut(i + 1);
                let mut acc = 0.0;
                for (&l, &x) in a[i * m + i + 1..(i + 1) * m].iter().zip(tail.iter()) {
                    acc += l * x;
                }
                head[i] = (head[i] - acc) * self.inv[i];
            }
            return;
        }
        let rhs = MatMut::from_column_major_slice_mut(b, m, 1);
        let stack = MemStack::new(&mut self.mem.0);
        let l = faer::MatRef::from_column_major_slice(&self.a, m, m);
        llt::solve::solve_in_place(l, rhs, Par::Seq, stack);
    }
}

#[cfg(test)]
#[path = "cholesky_tests.rs"]
mod tests;
