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
    read_diagonal(a, diag, m)?;
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

/// Copies the diagonal of the `m x m` matrix `a` into `diag`; a negative or non-finite entry
/// is an error (a semidefinite matrix has none).
#[inline]
fn read_diagonal(a: &[f64], diag: &mut [f64], m: usize) -> Result<(), FactorError> {
    for j in 0..m {
        let d = a[j + j * m];
        if !(d >= 0.0 && d.is_finite()) {
            return Err(FactorError::NotPositiveDefinite(j));
        }
        diag[j] = d;
    }
    Ok(())
}

/// A kept pivot ratio below this marks a factorisation in natural order as ill-conditioned
/// (a configuration within about `1e-4` rad of a singular one): [`crate::DenseCholesky`] then
/// factors again with diagonal pivoting (`factor_pivoted`) and keeps that result.
pub const PIVOTING_RATIO: f64 = 1e-8;

/// [`factor`] with diagonal pivoting: at each step the row with the largest pivot ratio left
/// (the part of it the rows already taken do not explain, relative to its diagonal) is taken
/// next, so the rows of the nearly singular directions come last, after every well-determined
/// one. In natural order a nearly dependent row met early divides the later rows' entries by
/// its small pivot, and the rounding that brings into the pivots of the rows after it (about
/// `eps` over the product of the small pivots' ratios' square roots: `1e-5` for two rows at
/// `4e-11`) can hide an exactly dependent row among them, so that the factorisation fails or
/// drops the wrong row. Pivoted, the rows left when the largest ratio falls below `tol` are
/// exactly the dependent ones, with ratios at round-off: all of them are dropped (an error if
/// they exceed `max_dependent`).
///
/// `piv[j]` receives the row exchanged with row `j` at step `j` (LAPACK's convention: apply
/// the exchanges in increasing `j` to a right-hand side, the factor solves the permuted
/// system, undo them in decreasing `j`); `perm` is scratch of length `m`. `dependent` gets the
/// dropped rows' original indices in increasing order. `L` is written into both triangles, as
/// by [`factor`].
#[allow(clippy::too_many_arguments)]
pub(crate) fn factor_pivoted(
    a: &mut [f64],
    diag: &mut [f64],
    inv: &mut [f64],
    piv: &mut [usize],
    perm: &mut [usize],
    m: usize,
    max_dependent: usize,
    dependent: &mut Vec<usize>,
    tol: f64,
) -> Result<f64, FactorError> {
    dependent.clear();
    read_diagonal(a, diag, m)?;
    for j in 0..m {
        perm[j] = j;
        // the full symmetric matrix: the exchanges move rows and columns
        for i in j + 1..m {
            a[j + i * m] = a[i + j * m];
        }
    }
    // the pivot ratio of a trailing row (a zero row, 0 / 0, counts as dependent)
    let ratio_of = |a: &[f64], diag: &[f64], i: usize| {
        let r = a[i + i * m] / diag[i];
        if r.is_nan() {
            f64::NEG_INFINITY
        } else {
            r
        }
    };
    let mut worst = 1.0f64;
    for j in 0..m {
        let mut p = j;
        let mut best = ratio_of(a, diag, j);
        for i in j + 1..m {
            let r = ratio_of(a, diag, i);
            if r > best {
                (p, best) = (i, r);
            }
        }
        piv[j] = p;
        if p != j {
            for c in 0..m {
                a.swap(j + c * m, p + c * m);
            }
            for r in 0..m {
                a.swap(r + j * m, r + p * m);
            }
            diag.swap(j, p);
            perm.swap(j, p);
        }
        if !(best >= tol) {
            // every row left is dependent on the rows taken (their ratios are at most `best`)
            let left = m - j;
            if left > max_dependent {
                return Err(FactorError::NotPositiveDefinite(perm[j]));
            }
            for i in j..m {
                if ratio_of(a, diag, i) < -DEPENDENT_PIVOT_TOL.sqrt() {
                    return Err(FactorError::NotPositiveDefinite(perm[i]));
                }
            }
            for i in j..m {
                // the rows after j take no exchange: the factor is the identity there
                if i > j {
                    piv[i] = i;
                }
                for c in 0..m {
                    if c != i {
                        a[i + c * m] = 0.0;
                        a[c + i * m] = 0.0;
                    }
                }
                a[i + i * m] = 1.0;
                inv[i] = 0.0;
                dependent.push(perm[i]);
            }
            dependent.sort_unstable();
            return Ok(worst);
        }
        worst = worst.max(1.0 / best);
        let ljj = a[j + j * m].sqrt();
        a[j + j * m] = ljj;
        let ij = 1.0 / ljj;
        inv[j] = ij;
        for i in j + 1..m {
            let l = a[i + j * m] * ij;
            a[i + j * m] = l;
            a[j + i * m] = l;
        }
        // the trailing Schur complement, both triangles
        for k in j + 1..m {
            let lk = a[k + j * m];
            if lk == 0.0 {
                continue;
            }
            for i in k..m {
                let v = a[i + k * m] - a[i + j * m] * lk;
                a[i + k * m] = v;
                a[k + i * m] = v;
            }
        }
    }
    Ok(worst)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::DenseCholesky;

    /// `S = Phi_q M^-1 Phi_q^T` (column-major, 12 x 12) of three cranks (0.5 m, 1 kg rods,
    /// ground pivots 1 m apart) pinned to one coupler (2 m, 4 kg) at its ends and middle, all
    /// cranks at `theta`, the equations in the order pivot 0, pin 0, pivot 1, pin 1, pivot 2,
    /// pin 2 (x then y): one redundant equation everywhere, two more dependencies at the flat
    /// position `theta = pi`.
    fn triple_parallelogram(theta: f64) -> Vec<f64> {
        let (l, n, m) = (0.5, 12, 12);
        let (s, c) = theta.sin_cos();
        let mut g = vec![0.0; m * n];
        let mut put = |r: usize, col: usize, v: f64| g[r * n + col] += v;
        for k in 0..3 {
            let (pv, pin, body) = (4 * k, 4 * k + 2, 3 * k);
            // crank point p = (-l/2, 0) at the pivot, (l/2, 0) at the pin: d(R p)/dtheta
            for (row, sign) in [(pv, -0.5), (pin, 0.5)] {
                put(row, body, 1.0);
                put(row + 1, body + 1, 1.0);
                put(row, body + 2, -sign * l * s);
                put(row + 1, body + 2, sign * l * c);
            }
            // minus the coupler's point ((k - 1) m, 0) on the pin rows (coupler angle 0)
            put(pin, 9, -1.0);
            put(pin + 1, 10, -1.0);
            put(pin + 1, 11, -(k as f64 - 1.0));
        }
        let inv_i = |mass: f64, len: f64| 12.0 / (mass * len * len);
        let minv: Vec<f64> = (0..n)
            .map(|j| match (j / 3, j % 3) {
                (3, 2) => inv_i(4.0, 2.0),
                (3, _) => 0.25,
                (_, 2) => inv_i(1.0, l),
                _ => 1.0,
            })
            .collect();
        let mut a = vec![0.0; m * m];
        for r in 0..m {
            for col in 0..m {
                a[r + col * m] = (0..n)
                    .map(|j| g[r * n + j] * minv[j] * g[col * n + j])
                    .sum();
            }
        }
        a
    }

    /// 1.5e-6 rad from the flat position (where a run's step landed): in natural order the
    /// two nearly dependent pin rows (ratios about 5e-12, kept by the strict pass) bring
    /// rounding of 1e-5 into the redundant row's pivot, and the factorisation fails; pivoted,
    /// the redundant row is found with a ratio at round-off and dropped, and the solve is
    /// backward stable. Away from the flat position both orders drop pin 2's y row.
    #[test]
    fn pivoting_finds_the_redundant_row_beside_nearly_dependent_ones() {
        let m = 12;
        let s = triple_parallelogram(std::f64::consts::PI - 1.5e-6);
        let (mut diag, mut inv, mut dep) = (vec![0.0; m], vec![0.0; m], Vec::with_capacity(m));
        let mut a = s.clone();
        let natural = factor(
            &mut a,
            &mut diag,
            &mut inv,
            m,
            1,
            &mut dep,
            ROUNDOFF_DEPENDENT_TOL,
        );
        assert!(natural.is_err(), "{natural:?} {dep:?}");
        let mut chol = DenseCholesky::new(m);
        chol.set_max_dependent(1);
        chol.values_mut().copy_from_slice(&s);
        chol.factor_in_place().expect("pivoted");
        // (a row of the dependent set, whichever the pivoting leaves last)
        assert_eq!(chol.dependent().len(), 1);
        let dropped = chol.dependent()[0];
        let cond = chol.condition_estimate();
        assert!(cond > 1e10 && cond < 1e13, "{cond:e}");
        // a right-hand side in the range of S: S x = b to rounding of the large condition
        let y: Vec<f64> = (0..m).map(|i| (i as f64 * 0.7).sin()).collect();
        let b: Vec<f64> = (0..m)
            .map(|r| (0..m).map(|col| s[r + col * m] * y[col]).sum())
            .collect();
        let mut x = b.clone();
        chol.solve_in_place(&mut x);
        assert_eq!(x[dropped], 0.0);
        let bmax = b.iter().fold(0.0f64, |w, v| w.max(v.abs()));
        for r in 0..m {
            let sx: f64 = (0..m).map(|col| s[r + col * m] * x[col]).sum();
            assert!((sx - b[r]).abs() < 1e-9 * bmax, "row {r}: {sx} vs {}", b[r]);
        }
        // forward_in_place is L^-1 P: the quadratic form b^T S^+ b from one solve
        let mut z = b.clone();
        chol.forward_in_place(&mut z);
        let q1: f64 = z.iter().map(|v| v * v).sum();
        let q2: f64 = b.iter().zip(&x).map(|(u, v)| u * v).sum();
        assert!((q1 - q2).abs() < 1e-6 * q2.abs(), "{q1} vs {q2}");
        // away from the flat position: the natural order, pin 2's y row
        let s = triple_parallelogram(1.0);
        chol.values_mut().copy_from_slice(&s);
        chol.factor_in_place().expect("natural");
        assert_eq!(chol.dependent(), &[11]);
        assert!(chol.condition_estimate() < 1.0 / PIVOTING_RATIO);
        // with always_pivot the same row space is kept, the dropped row is the pivoting's
        chol.set_always_pivot(true);
        chol.values_mut().copy_from_slice(&s);
        chol.factor_in_place().expect("pivoted");
        assert_eq!(chol.dependent().len(), 1);
    }

    /// At the flat position itself one more row is dependent to round-off: with one allowed
    /// the pivoted factorisation is an error, with two it drops two.
    #[test]
    fn pivoted_factorisation_refuses_more_dependent_rows_than_allowed() {
        let m = 12;
        let s = triple_parallelogram(std::f64::consts::PI);
        // the pivoted factorisation with a budget of `k` dependent rows
        let pivoted = |k: usize| {
            let (mut a, mut diag, mut inv) = (s.clone(), vec![0.0; m], vec![0.0; m]);
            let (mut piv, mut perm, mut dep) = (vec![0; m], vec![0; m], Vec::with_capacity(m));
            let tol = ROUNDOFF_DEPENDENT_TOL;
            let r = factor_pivoted(
                &mut a, &mut diag, &mut inv, &mut piv, &mut perm, m, k, &mut dep, tol,
            );
            (r, dep)
        };
        let (r, dep) = pivoted(1);
        assert!(r.is_err(), "{r:?} {dep:?}");
        let (r, dep) = pivoted(2);
        assert!(r.is_ok() && dep.len() == 2, "{r:?} {dep:?}");
    }
}
