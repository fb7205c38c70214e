//! The semidefinite Cholesky factorisation behind [`crate::DenseCholesky::set_max_dependent`]:
//! the matrix `S = Phi_q W Phi_q^T` of a mechanism with redundant constraints is only positive
//! *semi*definite, its rank `r` below its size `m`.
//!
//! Column `j` of the textbook (left-looking) factorisation has the pivot
//! `d_j = S_jj - sum_(k<j) L_jk^2`, the squared part of row `j` (in the `W` metric) that the
//! earlier rows do not explain; `d_j / S_jj` is the squared sine of the angle between row `j`
//! and the span of the earlier ones. When that ratio is below [`DEPENDENT_PIVOT_TOL`], row `j`
//! is a combination of the earlier rows: it is *dropped*, i.e. its column of `L` is set to zero
//! and its inverse pivot to zero, so the triangular solves give `x_j = 0` and the other
//! unknowns solve the system without row and column `j`. For a right-hand side in the range of
//! `S` (the acceleration and velocity equations of a mechanism whose dependent constraints hold
//! identically) that is an exact solution, the *basic* one: every dropped equation carries a
//! zero multiplier, and `Phi_q^T x` (the generalised constraint force) is the same as for any
//! other solution. The rows are tested in their natural order, so the equation dropped is
//! always the last of a dependent set, whichever it is at the current configuration.
//!
//! At most `max_dependent` rows may be dropped: one more is an error, as a zero pivot is for
//! the ordinary factorisation (a configuration that loses rank beyond the mechanism's known
//! redundancy is singular). [`crate::DenseCholesky`] factors with
//! [`ROUNDOFF_DEPENDENT_TOL`] first and with [`DEPENDENT_PIVOT_TOL`] only where that strict
//! pass dropped fewer than `max_dependent` rows.

use crate::FactorError;

/// A pivot ratio `d_j / S_jj` below this marks row `j` as dependent on the earlier rows (a
/// semidefinite factorisation drops it). Dependent rows of a mechanism give ratios at the
/// round-off level (1e-16 to 1e-13); an independent row needs an angle of at least 1e-5 rad
/// to the span of the others.
pub const DEPENDENT_PIVOT_TOL: f64 = 1e-10;

/// The first, strict pass of [`crate::DenseCholesky`]'s semidefinite factorisation drops only
/// rows whose pivot ratio is below this (dependent to round-off). Near a singular configuration
/// of a mechanism with redundant constraints a row that is independent but nearly dependent
/// (angle `delta` to the others: ratio `delta^2`) would otherwise be taken for one of the
/// redundant rows and, with the budget spent, fail the factorisation within `1e-5` rad of the
/// singular configuration; the strict pass keeps it (a large condition estimate, which the
/// run's near-singular handling sees) and fails only within `1e-6` rad.
pub const ROUNDOFF_DEPENDENT_TOL: f64 = 1e-12;

/// Factors the column-major `m x m` matrix `a` (lower triangle read) in place, dropping at most
/// `max_dependent` rows whose pivot ratio is below `tol` (recorded in `dependent`, which must
/// have capacity `m`).
/// Writes `L` into both triangles (every solve path of [`crate::DenseCholesky`] reads one of
/// them), the inverse pivots into `inv` (zero for a dropped row) and the original diagonal into
/// `diag`; returns the condition estimate over the kept rows.
pub(crate) fn factor(
    a: &mut [f64],
    diag: &mut [f64],
    inv: &mut [f64],
    m: usize,
    max_dependent: usize,
    dependent: &mut Vec<usize>,
    tol: f64,
) -> Result<f64, FactorError> {
    dependent.clear();
    for j in 0..m {
        let d = a[j + j * m];
        if !(d >= 0.0 && d.is_finite()) {
            return Err(FactorError::NotPositiveDefinite(j));
        }
        diag[j] = d;
    }
    let mut worst = 1.0f64;
    for j in 0..m {
        let mut d = a[j + j * m];
        for k in 0..j {
            let l = a[j + k * m];
            d -= l * l;
        }
        let ratio = d / diag[j];
        if !(ratio >= tol) {
            // (a zero row gives 0 / 0: dependent too)
            if dependent.len() == max_dependent || ratio < -DEPENDENT_PIVOT_TOL.sqrt() {
                return Err(FactorError::NotPositiveDefinite(j));
            }
            dependent.push(j);
            a[j + j * m] = 1.0;
            inv[j] = 0.0;
            for i in j + 1..m {
                a[i + j * m] = 0.0;
                a[j + i * m] = 0.0;
            }
            continue;
        }
        worst = worst.max(1.0 / ratio);
        let ljj = d.sqrt();
        a[j + j * m] = ljj;
        let ij = 1.0 / ljj;
        inv[j] = ij;
        for i in j + 1..m {
            let mut y = a[i + j * m];
            for k in 0..j {
                y -= a[i + k * m] * a[j + k * m];
            }
            let l = y * ij;
            a[i + j * m] = l;
            a[j + i * m] = l;
        }
    }
    Ok(worst)
}
