//! The rank check of the constraint Jacobian (consistent initial states are
//! `mbd_solve::consistent_state`, on the solver core's projection).

use crate::error::ModelError;
use crate::system::System;
use faer::{Mat, Side};
use mbd_linalg::max_abs;
use nalgebra::{DMatrix, DVector};

impl System {
    /// Checks that `Phi_q(q)` has full row rank. On failure returns
    /// [`ModelError::Redundant`] naming the first dependent equation and the joints whose
    /// equations it combines.
    pub fn check_rank(&self, q: &[f64], _t: f64) -> Result<(), ModelError> {
        self.check_len("q", q, self.n)?;
        let (n, m) = (self.n, self.m);
        if m == 0 {
            return Ok(());
        }
        let mut jac = DMatrix::zeros(m, n);
        self.phi_q(q, &mut jac);
        // Fast path: a well-conditioned Cholesky factor of Phi_q M^-1 Phi_q^T proves full rank.
        if self.schur_well_conditioned(&jac) {
            return Ok(());
        }
        // Gram-Schmidt on the rows (twice for stability), tracking each basis vector as a
        // combination of the original rows so a dependency can be traced to its joints.
        let scale = (0..m)
            .map(|r| jac.row(r).norm())
            .fold(0.0, f64::max)
            .max(1e-300);
        let tol = 1e-9 * scale;
        let mut basis: Vec<DVector<f64>> = Vec::new();
        let mut combo: Vec<DVector<f64>> = Vec::new();
        for r in 0..m {
            let row: DVector<f64> = jac.row(r).transpose();
            let mut w = row.clone();
            let mut c = DVector::zeros(m);
            c[r] = 1.0;
            let mut proj = vec![0.0; basis.len()];
            for _ in 0..2 {
                for (k, b) in basis.iter().enumerate() {
                    let p = b.dot(&w);
                    proj[k] += p;
                    w -= b * p;
                    c -= &combo[k] * p;
                }
            }
            let norm = w.norm();
            if norm <= tol {
                // row r = sum_k proj_k basis_k = sum_k proj_k sum_j combo_k[j] row_j
                let mut coef = DVector::zeros(m);
                for (k, p) in proj.iter().enumerate() {
                    coef += &combo[k] * *p;
                }
                let cmax = max_abs(coef.as_slice()).max(1e-300);
                let mut joints: Vec<String> = Vec::new();
                let mut push = |ji: usize| {
                    let name = self.joints[ji].name.clone();
                    if !joints.contains(&name) {
                        joints.push(name);
                    }
                };
                for j in 0..m {
                    if coef[j].abs() > 1e-8 * cmax {
                        push(self.eq_joint[j]);
                    }
                }
                push(self.eq_joint[r]);
                return Err(ModelError::Redundant {
                    equation: self.equation_name(r),
                    joints,
                });
            }
            basis.push(w / norm);
            combo.push(c / norm);
        }
        Ok(())
    }

    /// `S = Phi_q M^-1 Phi_q^T` (dense), accumulated column by column over the few non-zeros of
    /// each column of `Phi_q`, so building it costs `O(n k^2)` for `k` non-zeros per column.
    fn schur_matrix(&self, jac: &DMatrix<f64>) -> Mat<f64> {
        let m = self.m;
        let mut s = Mat::<f64>::zeros(m, m);
        let mut nz: Vec<(usize, f64)> = Vec::with_capacity(8);
        for k in 0..self.n {
            nz.clear();
            let col = jac.column(k);
            for (r, &x) in col.iter().enumerate() {
                if x != 0.0 {
                    nz.push((r, x));
                }
            }
            let w = self.inv_mass[k];
            for &(i, xi) in &nz {
                for &(j, xj) in &nz {
                    s[(i, j)] += w * xi * xj;
                }
            }
        }
        s
    }

    /// Whether `S` has a Cholesky factor with pivots above `1e-7` of the largest (`S` condition
    /// below ~1e14): the fast full-rank test of [`System::check_rank`].
    fn schur_well_conditioned(&self, jac: &DMatrix<f64>) -> bool {
        let Ok(llt) = self.schur_matrix(jac).llt(Side::Lower) else {
            return false;
        };
        let l = llt.L();
        let d: Vec<f64> = (0..self.m).map(|i| l[(i, i)].abs()).collect();
        let dmax = d.iter().cloned().fold(0.0, f64::max);
        d.iter().all(|&x| x > 1e-7 * dmax)
    }
}
