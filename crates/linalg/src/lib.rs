//! # mbd-linalg
//!
//! The numerical linear algebra of the mbd workspace, on preallocated workspaces that do not
//! allocate once set up:
//!
//! * [`DenseCholesky`]: Cholesky `L L^T` of a symmetric positive definite matrix, with kernels
//!   of fixed dimension for the smallest systems, a scale-invariant pivot test
//!   ([`CHOLESKY_PIVOT_TOL`]) and a condition estimate;
//! * [`DenseLu`]: the dense LU with a caller-chosen elimination order, nonzero-pattern tracking,
//!   threshold pivoting and a pivot test on the equilibrated matrix;
//! * [`SparseCholesky`] and [`SparseLu`]: the same factorisations on a fixed sparsity pattern
//!   (faer's simplicial factorisations), analysed once and refactored in place;
//! * [`symmetric_eigen`]: the cyclic Jacobi eigen-decomposition of a small symmetric matrix
//!   (its near-null space, accurately);
//! * [`min_norm_solve`] and [`null_space`]: the minimum-norm least-squares solution and the
//!   null space of a small dense matrix that may lose rank, by the SVD with a relative rank cut;
//! * [`Anderson`]: Anderson acceleration of a linearly converging fixed-point iteration (the
//!   simplified Newton iterations whose iteration matrix leaves out part of the Jacobian);
//! * small kernels: [`max_abs`] and [`max_abs_diff`] (max-norms that never lose a NaN),
//!   [`axpy`], [`dot`], [`pow2_inverse`].
//!
//! Failures are [`FactorError`] and [`LuError`] (what one factorisation reports) and
//! [`LinalgError`] (every failure of the crate, set-up included). The crate knows nothing about
//! multibody systems: `mbd-model` and `mbd-solve` build on it.
//!
//! ```
//! use mbd_linalg::{max_abs, DenseCholesky, DenseLu};
//!
//! // A = [[4, 1], [1, 3]] by Cholesky (the lower triangle is read) ...
//! let mut chol = DenseCholesky::new(2);
//! chol.add(0, 0, 4.0);
//! chol.add(1, 0, 1.0);
//! chol.add(1, 1, 3.0);
//! chol.factor_in_place()?;
//! let mut x = [1.0, 2.0];
//! chol.solve_in_place(&mut x);
//! let r = [4.0 * x[0] + x[1] - 1.0, x[0] + 3.0 * x[1] - 2.0];
//! assert!(max_abs(&r) < 1e-15);
//!
//! // ... and by LU (every entry is written)
//! let mut lu = DenseLu::new(2);
//! for (i, j, v) in [(0, 0, 4.0), (0, 1, 1.0), (1, 0, 1.0), (1, 1, 3.0)] {
//!     lu.set(i, j, v);
//! }
//! lu.factor_in_place()?;
//! let mut y = [1.0, 2.0];
//! lu.solve_in_place(&mut y);
//! assert!((x[0] - y[0]).abs() < 1e-15 && (x[1] - y[1]).abs() < 1e-15);
//! # Ok::<(), mbd_linalg::FactorError>(())
//! ```
#![warn(missing_docs)]
// `!(d > 0.0)` rejects NaN with the non-positive pivots in one comparison; index loops over
// the factors read like the textbook algorithms.
#![allow(clippy::needless_range_loop, clippy::neg_cmp_op_on_partial_ord)]

mod anderson;
mod cholesky;
mod eigen;
mod error;
mod householder;
mod lu;
mod semidefinite;
mod sparse;
mod svd;

pub use anderson::Anderson;
pub use cholesky::{
    DenseCholesky, CHOLESKY_PIVOT_TOL, FIXED_CHOLESKY, SMALL_CHOLESKY, SMALL_CHOLESKY_SOLVE,
};
pub use eigen::{symmetric_eigen, JACOBI_MAX_SWEEPS};
pub use error::{FactorError, LinalgError, LuError};
pub use householder::{form_q_padded, qr_padded, reflect, solve_rt};
pub use lu::{DenseLu, PIVOT_THRESHOLD, PIVOT_TOL};
pub use semidefinite::{DEPENDENT_PIVOT_TOL, PIVOTING_RATIO, ROUNDOFF_DEPENDENT_TOL};
pub use sparse::{ColumnOrder, SparseCholesky, SparseLu, REFACTOR_PIVOT_RATIO, SPARSE_PIVOT_TOL};
pub use svd::{min_norm_solve, null_space};

use faer::dyn_stack::MemBuffer;

/// faer's scratch memory (wrapped for `Debug`).
pub(crate) struct Scratch(pub(crate) MemBuffer);

impl std::fmt::Debug for Scratch {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("Scratch")
    }
}

/// The power of two `2^-e` with `v 2^-e` in `[1, 2)`, for finite `v > 0` (clamped to the
/// normal range, so it is never zero or infinite): the exact scale factor of the
/// equilibrations.
///
/// ```
/// use mbd_linalg::pow2_inverse;
/// assert_eq!(pow2_inverse(1.0), 1.0);
/// assert_eq!(pow2_inverse(5.0), 0.25);
/// assert_eq!(pow2_inverse(0.3), 4.0);
/// ```
#[inline]
pub fn pow2_inverse(v: f64) -> f64 {
    let e = ((v.to_bits() >> 52) & 0x7ff) as i64; // biased exponent of v
                                                  // 2^-(e - 1023) has biased exponent 2046 - e
    let b = (2046 - e).clamp(1, 2046) as u64;
    f64::from_bits(b << 52)
}

/// `max_i |x_i|`, or NaN when any entry is NaN (0 for an empty slice): the one max-norm of the
/// workspace, so a NaN anywhere in a residual is seen everywhere.
///
/// `f64::max` ignores a NaN operand, so a plain fold loses a NaN that is followed by a finite
/// entry (`[NaN, 1e-20]` would give `1e-20`) and a Newton iteration could report convergence
/// on a NaN residual. This helper returns NaN as soon as it sees one.
///
/// ```
/// use mbd_linalg::max_abs;
/// assert_eq!(max_abs(&[1.0, -3.0, 2.0]), 3.0);
/// assert!(max_abs(&[f64::NAN, 1e-20]).is_nan());
/// assert!(max_abs(&[1e-20, f64::NAN]).is_nan());
/// assert_eq!(max_abs(&[]), 0.0);
/// ```
#[inline]
pub fn max_abs(x: &[f64]) -> f64 {
    let mut m = 0.0f64;
    for &v in x {
        let a = v.abs();
        if a > m {
            m = a;
        } else if a.is_nan() {
            return f64::NAN;
        }
    }
    m
}

/// `max_i |a_i - b_i|` over the common length, NaN when any difference is NaN.
///
/// ```
/// use mbd_linalg::max_abs_diff;
/// assert_eq!(max_abs_diff(&[1.0, 2.0], &[1.5, 0.0]), 2.0);
/// assert!(max_abs_diff(&[f64::NAN, 0.0], &[0.0, 1.0]).is_nan());
/// ```
#[inline]
pub fn max_abs_diff(a: &[f64], b: &[f64]) -> f64 {
    let mut m = 0.0f64;
    for (x, y) in a.iter().zip(b) {
        let d = (x - y).abs();
        if d > m {
            m = d;
        } else if d.is_nan() {
            return f64::NAN;
        }
    }
    m
}

/// `y <- y + a x` over the common length (entry by entry, `y_i += a * x_i`).
///
/// ```
/// use mbd_linalg::axpy;
/// let mut y = [1.0, 2.0, 3.0];
/// axpy(2.0, &[1.0, 0.5, -1.0], &mut y);
/// assert_eq!(y, [3.0, 3.0, 1.0]);
/// ```
#[inline]
pub fn axpy(a: f64, x: &[f64], y: &mut [f64]) {
    for (yi, xi) in y.iter_mut().zip(x) {
        *yi += a * xi;
    }
}

/// `a . b` over the common length, summed left to right.
///
/// ```
/// use mbd_linalg::dot;
/// assert_eq!(dot(&[1.0, 2.0, 3.0], &[4.0, -1.0, 0.5]), 3.5);
/// ```
#[inline]
pub fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nan_is_never_lost_wherever_it_sits() {
        for pos in 0..4 {
            let mut x = [1e-20, 5.0, -7.0, 1e-30];
            x[pos] = f64::NAN;
            assert!(max_abs(&x).is_nan(), "NaN at {pos} lost");
            let y = [0.0; 4];
            assert!(max_abs_diff(&x, &y).is_nan(), "NaN diff at {pos} lost");
        }
    }

    #[test]
    fn infinities_and_signs() {
        assert_eq!(max_abs(&[-f64::INFINITY, 1.0]), f64::INFINITY);
        assert_eq!(max_abs(&[-2.0, 1.0]), 2.0);
        assert_eq!(max_abs(&[0.0, -0.0]), 0.0);
    }
}

/// The README's example, compiled and run as a doctest.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctest;
