//! Rank-revealing solves by the singular value decomposition, for the small dense problems
//! where a matrix may lose rank (a configuration's dependent constraint rows, the solvability
//! conditions of a singular start): the minimum-norm least-squares solution and an orthonormal
//! basis of the null space, both with a rank cut relative to the largest singular value.
//!
//! These allocate (nalgebra's SVD); they serve set-up and rare repair paths, not steps.

use nalgebra::{DMatrix, DVector};

/// The minimum-norm least-squares solution of `a x = b`: the truncated pseudo-inverse applied
/// to `b`, singular values at most `rel_tol` times the largest treated as zero.
///
/// `None` when the SVD fails, when `a` is zero or has a non-finite entry, or when `b` does not
/// have `a`'s row count.
///
/// ```
/// use mbd_linalg::min_norm_solve;
/// use nalgebra::{DMatrix, DVector};
///
/// // rank one: x1 + x2 = 2 has the minimum-norm solution (1, 1)
/// let a = DMatrix::from_row_slice(2, 2, &[1.0, 1.0, 2.0, 2.0]);
/// let b = DVector::from_column_slice(&[2.0, 4.0]);
/// let x = min_norm_solve(a, &b, 1e-12).ok_or("no solution")?;
/// assert!((x[0] - 1.0).abs() < 1e-14 && (x[1] - 1.0).abs() < 1e-14);
/// # Ok::<(), &str>(())
/// ```
pub fn min_norm_solve(a: DMatrix<f64>, b: &DVector<f64>, rel_tol: f64) -> Option<DVector<f64>> {
    // (nalgebra's SVD panics on a NaN singular value)
    if a.nrows() != b.len() || !a.iter().all(|x| x.is_finite()) {
        return None;
    }
    let svd = a.svd(true, true);
    let smax = svd.singular_values.amax();
    if smax.is_nan() || smax <= 0.0 {
        return None;
    }
    svd.solve(b, rel_tol * smax).ok()
}

/// An orthonormal basis (columns, `b.ncols()` rows) of the null space of `b`: the right
/// singular vectors whose singular values are at most `rel_tol` times the largest. A matrix
/// with fewer rows than columns is padded with zero rows to a square first, so the directions
/// beyond its rank are among the singular vectors. A zero matrix has the whole space; an SVD
/// that fails (a non-finite entry) gives no columns.
///
/// ```
/// use mbd_linalg::null_space;
/// use nalgebra::DMatrix;
///
/// // one row in three columns: a two-dimensional null space orthogonal to (1, 2, 2)
/// let b = DMatrix::from_row_slice(1, 3, &[1.0, 2.0, 2.0]);
/// let n = null_space(&b, 1e-12);
/// assert_eq!(n.ncols(), 2);
/// assert!((&b * &n).amax() < 1e-14);
/// assert!((n.transpose() * &n - DMatrix::identity(2, 2)).amax() < 1e-14);
/// ```
pub fn null_space(b: &DMatrix<f64>, rel_tol: f64) -> DMatrix<f64> {
    let (r, c) = b.shape();
    let p = if r < c {
        let mut p = DMatrix::zeros(c, c);
        p.rows_mut(0, r).copy_from(b);
        p
    } else {
        b.clone()
    };
    // (nalgebra's SVD panics on a NaN singular value)
    if !p.iter().all(|x| x.is_finite()) {
        return DMatrix::zeros(c, 0);
    }
    let svd = p.svd(false, true);
    let Some(vt) = svd.v_t else {
        return DMatrix::zeros(c, 0);
    };
    let sv = &svd.singular_values;
    let smax = sv.amax();
    let keep: Vec<usize> = (0..sv.len())
        .filter(|&i| smax == 0.0 || sv[i] <= rel_tol * smax)
        .collect();
    let mut out = DMatrix::zeros(c, keep.len());
    for (k, &i) in keep.iter().enumerate() {
        out.set_column(k, &vt.row(i).transpose());
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_minimum_norm_solution_is_orthogonal_to_the_null_space() {
        // rank 2 in 3 columns: any solution plus a null vector solves it; the minimum-norm
        // one has no null component
        let a = DMatrix::from_row_slice(3, 3, &[1.0, 2.0, 3.0, 2.0, 4.0, 6.5, 1.0, 2.0, 3.5]);
        let x_any = DVector::from_column_slice(&[1.0, -1.0, 2.0]);
        let b = &a * &x_any;
        let x = min_norm_solve(a.clone(), &b, 1e-12).expect("a solution");
        assert!((&a * &x - &b).amax() < 1e-13);
        let n = null_space(&a, 1e-12);
        assert_eq!(n.ncols(), 1);
        assert!((n.transpose() * &x).amax() < 1e-13);
        // and it is shorter than the solution we started from
        assert!(x.norm() < x_any.norm());
    }

    #[test]
    fn a_zero_or_non_finite_or_mismatched_system_has_no_solution() {
        let b = DVector::from_column_slice(&[1.0, 2.0]);
        assert!(min_norm_solve(DMatrix::zeros(2, 2), &b, 1e-12).is_none());
        let mut a = DMatrix::identity(2, 2);
        a[(0, 1)] = f64::NAN;
        assert!(min_norm_solve(a, &b, 1e-12).is_none());
        assert!(min_norm_solve(DMatrix::identity(3, 3), &b, 1e-12).is_none());
    }

    #[test]
    fn the_rank_cut_decides_which_directions_are_null() {
        // singular values 1 and 1e-9: null below a cut of 1e-8, not below 1e-10
        let b = DMatrix::from_row_slice(2, 2, &[1.0, 0.0, 0.0, 1e-9]);
        assert_eq!(null_space(&b, 1e-8).ncols(), 1);
        assert_eq!(null_space(&b, 1e-10).ncols(), 0);
        assert_eq!(null_space(&DMatrix::zeros(2, 3), 1e-12).ncols(), 3);
        let mut bad = DMatrix::identity(2, 2);
        bad[(1, 1)] = f64::INFINITY;
        assert_eq!(null_space(&bad, 1e-12).ncols(), 0);
    }

    /// The null space of a rank-deficient wide matrix: orthonormal, annihilated, of the right
    /// dimension.
    #[test]
    fn null_space_of_a_wide_rank_deficient_matrix() {
        let b = DMatrix::from_row_slice(2, 4, &[1.0, 2.0, 0.0, -1.0, 2.0, 4.0, 0.0, -2.0]);
        let nb = null_space(&b, 1e-9);
        assert_eq!(nb.ncols(), 3);
        assert!((&b * &nb).amax() < 1e-14);
        let g = nb.tr_mul(&nb) - DMatrix::identity(3, 3);
        assert!(g.amax() < 1e-14);
        let nt = null_space(&b.transpose(), 1e-9);
        assert_eq!(nt.ncols(), 1);
        assert!((b.transpose() * &nt).amax() < 1e-14);
    }
}
