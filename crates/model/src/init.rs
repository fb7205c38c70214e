//! The rank check of the constraint Jacobian (consistent initial states are
//! `mbd_solve::consistent_state`, on the solver core's projection).

use crate::error::ModelError;
use crate::system::System;
use faer::{Mat, Side};
use mbd_linalg::{max_abs, SparseCholesky};
use nalgebra::{DMatrix, DVector};

/// Above this many constraint equations [`System::check_rank`] factors the Schur complement
/// `Phi_q M^-1 Phi_q^T` as a sparse matrix (memory and time linear in the size of a chain)
/// instead of forming `Phi_q` densely.
pub const SPARSE_RANK_THRESHOLD: usize = 200;

impl System {
    /// Checks that `Phi_q(q)` has full row rank. On failure returns
    /// [`ModelError::Redundant`] naming the first dependent equation and the joints whose
    /// equations it combines.
    ///
    /// Above [`SPARSE_RANK_THRESHOLD`] equations the test is a sparse Cholesky factorisation of
    /// `Phi_q M^-1 Phi_q^T` (equilibrated pivots above `mbd_linalg::CHOLESKY_PIVOT_TOL`); a
    /// failure names the equation whose pivot vanished and the joints that share a body with
    /// it.
    pub fn check_rank(&self, q: &[f64], _t: f64) -> Result<(), ModelError> {
        self.check_len("q", q, self.n)?;
        let (n, m) = (self.n, self.m);
        if m == 0 {
            return Ok(());
        }
        if m > SPARSE_RANK_THRESHOLD {
            return self.check_rank_sparse(q);
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

    /// The sparse rank test of [`System::check_rank`]: `S = Phi_q M^-1 Phi_q^T` from the
    /// element-local rows, its pattern from the bodies the rows share (O(m) entries for a
    /// chain), factored by [`SparseCholesky`].
    fn check_rank_sparse(&self, q: &[f64]) -> Result<(), ModelError> {
        let m = self.m;
        let mut grads = vec![[0.0; 6]; m];
        self.phi_q_local(q, &mut grads);
        // per body, the rows that touch it and the slot of the body in each row
        let mut touching: Vec<Vec<(usize, usize)>> = vec![Vec::new(); self.bodies.len()];
        for (ji, at) in self.joint_attach.iter().enumerate() {
            let o = self.row_offset[ji];
            for r in o..o + self.joints[ji].n_equations() {
                for (slot, body) in [(0, at.a), (3, at.b)] {
                    if let Some(i) = body {
                        touching[i].push((r, slot));
                    }
                }
            }
        }
        let mut pattern = Vec::new();
        for rows in &touching {
            for (a, &(r, _)) in rows.iter().enumerate() {
                for &(s, _) in &rows[..a] {
                    if r != s {
                        pattern.push((r.max(s), r.min(s)));
                    }
                }
            }
        }
        let mut chol =
            SparseCholesky::new(m, &pattern).map_err(|e| ModelError::InvalidElement {
                element: "constraint Jacobian".into(),
                message: format!("the sparse rank check could not analyse its pattern: {e}"),
            })?;
        for (i, rows) in touching.iter().enumerate() {
            let w = [
                self.inv_mass[3 * i],
                self.inv_mass[3 * i + 1],
                self.inv_mass[3 * i + 2],
            ];
            for (a, &(r, sr)) in rows.iter().enumerate() {
                for &(s, ss) in &rows[..=a] {
                    let v: f64 = (0..3)
                        .map(|l| w[l] * grads[r][sr + l] * grads[s][ss + l])
                        .sum();
                    let (hi, lo) = (r.max(s), r.min(s));
                    if let Some(k) = chol.slot(hi, lo) {
                        chol.values_mut()[k] += v;
                    }
                }
            }
        }
        let Err(e) = chol.factor() else {
            return Ok(());
        };
        let r = match e {
            mbd_linalg::FactorError::NotPositiveDefinite(r)
            | mbd_linalg::FactorError::Singular(r) => r,
        };
        let mut joints: Vec<String> = Vec::new();
        let ji = self.eq_joint[r];
        let at = self.joint_attach[ji];
        for body in [at.a, at.b].into_iter().flatten() {
            for &(s, _) in &touching[body] {
                let name = &self.joints[self.eq_joint[s]].name;
                if !joints.contains(name) {
                    joints.push(name.clone());
                }
            }
        }
        Err(ModelError::Redundant {
            equation: self.equation_name(r),
            joints,
        })
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
