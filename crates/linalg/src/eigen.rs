//! The symmetric eigenvalue problem by the cyclic Jacobi method, in place: for the small
//! dense matrices whose near-null space a caller needs (the Schur complement of the
//! constraints near a singular configuration), where accuracy in the small eigenvalues
//! matters more than speed (Jacobi computes them to high relative accuracy for a scaled
//! positive definite matrix; Demmel & Veselic 1992).

/// Sweeps after which [`symmetric_eigen`] stops even if the off-diagonal part has not fallen
/// to rounding (a sweep squares the off-diagonal norm once the iteration is quadratic; 8 to 12
/// sweeps are typical at double precision).
pub const JACOBI_MAX_SWEEPS: usize = 60;

/// Eigenvalues and eigenvectors of the symmetric `m x m` matrix `a` (column-major, both
/// triangles; overwritten) by cyclic Jacobi rotations: on return the diagonal of `a` holds the
/// eigenvalues (unsorted) and column `j` of `v` (`m x m`, overwritten) the unit eigenvector of
/// the `j`-th. Stops when every off-diagonal entry is below `1e-17 sqrt(|a_pp a_qq|)` (or below
/// the underflow threshold), or after [`JACOBI_MAX_SWEEPS`] sweeps; returns the sweeps done.
/// Allocation-free; `O(m^3)` per sweep.
///
/// ```
/// use mbd_linalg::symmetric_eigen;
/// // [[2, 1], [1, 2]]: eigenvalues 1 and 3, eigenvectors (1, -1) / sqrt 2 and (1, 1) / sqrt 2
/// let mut a = [2.0, 1.0, 1.0, 2.0];
/// let mut v = [0.0; 4];
/// symmetric_eigen(&mut a, &mut v, 2);
/// let (l0, l1) = (a[0], a[3]);
/// assert!((l0.min(l1) - 1.0).abs() < 1e-15 && (l0.max(l1) - 3.0).abs() < 1e-15);
/// let j = if l0 < l1 { 0 } else { 1 };
/// assert!((v[2 * j].abs() - 0.5f64.sqrt()).abs() < 1e-15 && v[2 * j] * v[2 * j + 1] < 0.0);
/// ```
pub fn symmetric_eigen(a: &mut [f64], v: &mut [f64], m: usize) -> usize {
    let (a, v) = (&mut a[..m * m], &mut v[..m * m]);
    v.fill(0.0);
    for i in 0..m {
        v[i + i * m] = 1.0;
    }
    for sweep in 0..JACOBI_MAX_SWEEPS {
        let mut rotated = false;
        for p in 0..m {
            for q in p + 1..m {
                let apq = a[p + q * m];
                let (app, aqq) = (a[p + p * m], a[q + q * m]);
                if apq.abs() <= 1e-17 * (app * aqq).abs().sqrt() || apq.abs() < f64::MIN_POSITIVE {
                    continue;
                }
                rotated = true;
                // the rotation that zeroes a_pq (Golub & Van Loan, Algorithm 8.5.1), with the
                // smaller of the two angles
                let theta = (aqq - app) / (2.0 * apq);
                let t = if theta.abs() > 1e150 {
                    0.5 / theta
                } else {
                    theta.signum() / (theta.abs() + theta.mul_add(theta, 1.0).sqrt())
                };
                let c = 1.0 / t.mul_add(t, 1.0).sqrt();
                let s = t * c;
                for k in 0..m {
                    let (akp, akq) = (a[k + p * m], a[k + q * m]);
                    a[k + p * m] = c * akp - s * akq;
                    a[k + q * m] = s * akp + c * akq;
                }
                for k in 0..m {
                    let (apk, aqk) = (a[p + k * m], a[q + k * m]);
                    a[p + k * m] = c * apk - s * aqk;
                    a[q + k * m] = s * apk + c * aqk;
                }
                for k in 0..m {
                    let (vkp, vkq) = (v[k + p * m], v[k + q * m]);
                    v[k + p * m] = c * vkp - s * vkq;
                    v[k + q * m] = s * vkp + c * vkq;
                }
            }
        }
        if !rotated {
            return sweep;
        }
    }
    JACOBI_MAX_SWEEPS
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `A = Q diag(d) Q^T` with `Q` a product of rotations.
    fn spd(d: &[f64]) -> Vec<f64> {
        let m = d.len();
        let mut q = vec![0.0; m * m];
        for i in 0..m {
            q[i + i * m] = 1.0;
        }
        for (k, (i, j)) in [(0, 1), (1, 2), (0, 3), (2, 4), (1, 4), (3, 4)]
            .into_iter()
            .enumerate()
        {
            let (c, s) = (0.3 + 0.1 * k as f64).sin_cos();
            for r in 0..m {
                let (x, y) = (q[r + i * m], q[r + j * m]);
                q[r + i * m] = c * x - s * y;
                q[r + j * m] = s * x + c * y;
            }
        }
        let mut a = vec![0.0; m * m];
        for r in 0..m {
            for c in 0..m {
                a[r + c * m] = (0..m).map(|k| q[r + k * m] * d[k] * q[c + k * m]).sum();
            }
        }
        a
    }

    #[test]
    fn eigenpairs_of_a_badly_conditioned_matrix_hold_to_relative_accuracy() {
        let d = [3.0, 1e-12, 0.5, 2.0, 7e-9];
        let m = d.len();
        let a0 = spd(&d);
        let mut a = a0.clone();
        let mut v = vec![0.0; m * m];
        let sweeps = symmetric_eigen(&mut a, &mut v, m);
        assert!(sweeps < 15, "{sweeps} sweeps");
        let mut got: Vec<f64> = (0..m).map(|j| a[j + j * m]).collect();
        got.sort_by(f64::total_cmp);
        let mut want = d.to_vec();
        want.sort_by(f64::total_cmp);
        for (g, w) in got.iter().zip(&want) {
            // the tiny eigenvalues to the accuracy the entries of A (size 1) carry
            assert!((g - w).abs() <= 1e-14 * 7.0, "eigenvalue {g} against {w}");
        }
        for j in 0..m {
            let lam = a[j + j * m];
            let col = &v[j * m..(j + 1) * m];
            let norm: f64 = col.iter().map(|x| x * x).sum::<f64>().sqrt();
            assert!((norm - 1.0).abs() < 1e-14);
            for r in 0..m {
                let av: f64 = (0..m).map(|c| a0[r + c * m] * col[c]).sum();
                assert!((av - lam * col[r]).abs() < 1e-14, "A v = lambda v, row {r}");
            }
        }
    }

    #[test]
    fn a_diagonal_matrix_takes_no_rotation() {
        let mut a = [2.0, 0.0, 0.0, 5.0];
        let mut v = [9.0; 4];
        assert_eq!(symmetric_eigen(&mut a, &mut v, 2), 0);
        assert_eq!((a, v), ([2.0, 0.0, 0.0, 5.0], [1.0, 0.0, 0.0, 1.0]));
    }
}
