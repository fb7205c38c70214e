//! The rank report of a singular configuration: numerical rank of `Phi_q`, dependent
//! equations and the joints of the dependency (an error path; allocates).

use super::TangentChart;
use crate::kernels::dot;
use mbd_model::System;
use mbd_solve::linalg::{axpy, max_abs};
use mbd_solve::SolveError;

impl TangentChart {
    /// A singular configuration at the last centre: the numerical rank of `Phi_q(q_c)` (`m x n`)
    /// from a column-pivoted Householder QR of `(D Phi_q W^(1/2))^T`, `W` the model's
    /// [`System::rank_weights`] and `D` scaling each row to unit norm (so the threshold depends
    /// neither on the units of lengths nor on those of the equations; rank `r`: the pivots
    /// `|R_kk| > rel_tol |R_00|`), the dependent equations (the pivots after `r`) and the
    /// joints involved in the dependency (the rows with a weight above `1e-6` of the largest in
    /// a left null vector `z`, `Phi_q^T z ~ 0`, of each dependent equation:
    /// `z = P [R11^-1 R12 e_j; -e_j]`), as [`SolveError::Singular`]
    /// (`what` = `"configuration (rank-deficient constraint Jacobian Phi_q)"`, `detail` =
    /// `"rank r of m; dependent equations ...; joints ..."`). `None` if `Phi_q` has full
    /// rank at that threshold or was not evaluated. Allocates (an error path).
    pub fn singular_error(&mut self, sys: &System, t: f64, rel_tol: f64) -> Option<SolveError> {
        let (n, m) = (self.n, self.m);
        if m == 0 || m > n {
            return None;
        }
        self.pq_x.copy_from(&self.phi_q);
        self.rank_report(sys, t, rel_tol)
    }

    /// [`TangentChart::singular_error`] for `Phi_q` at the configuration `q` (length `n`; e.g.
    /// a stage point whose index-1 solve was singular). `None` if `Phi_q(q)` has full rank at
    /// `rel_tol` or `q` has the wrong length.
    pub fn singular_error_at(
        &mut self,
        sys: &System,
        q: &[f64],
        t: f64,
        rel_tol: f64,
    ) -> Option<SolveError> {
        let (n, m) = (self.n, self.m);
        if m == 0 || m > n || q.len() != n {
            return None;
        }
        self.sel.phi_q(sys, q, t, &mut self.pq_x);
        self.rank_report(sys, t, rel_tol)
    }

    /// The rank report of `Phi_q` held in `pq_x`.
    pub(super) fn rank_report(&mut self, sys: &System, t: f64, rel_tol: f64) -> Option<SolveError> {
        let (n, m) = (self.n, self.m);
        // Phi_q^T (n x m), column j = row j of Phi_q
        // (allocation-free unless rank deficient: the report's strings)
        let pq = self.pq_x.as_slice();
        let a = &mut self.rr;
        for j in 0..m {
            for (c, w) in self.rank_w.iter().enumerate() {
                a[j * n + c] = pq[c * m + j] * w;
            }
            // each equation in its own unit: the pivots measure angles between the gradients
            let col = &mut a[j * n..(j + 1) * n];
            let norm = dot(col, col).sqrt();
            if norm > 0.0 {
                col.iter_mut().for_each(|x| *x /= norm);
            }
        }
        let perm = &mut self.perm;
        for (j, p) in perm.iter_mut().enumerate() {
            *p = j;
        }
        let norms = &mut self.norms;
        let v = &mut self.hv;
        let mut r00 = 0.0f64;
        let mut rank = m;
        for k in 0..m {
            // pivot: the remaining column of largest norm (recomputed: tiny matrices)
            for (j, nj) in norms.iter_mut().enumerate().skip(k) {
                *nj = dot(&a[j * n + k..(j + 1) * n], &a[j * n + k..(j + 1) * n]);
            }
            let p = (k..m).fold(k, |p, j| if norms[j] > norms[p] { j } else { p });
            if p != k {
                for c in 0..n {
                    a.swap(k * n + c, p * n + c);
                }
                perm.swap(k, p);
                norms.swap(k, p);
            }
            let col_norm = norms[k].sqrt();
            if k == 0 {
                r00 = col_norm;
            }
            if col_norm.is_nan() || col_norm <= rel_tol * r00 || k >= n {
                rank = k;
                break;
            }
            // Householder reflector on rows k..n of column k, applied to the columns after it
            let x0 = a[k * n + k];
            let beta = if x0 >= 0.0 { -col_norm } else { col_norm };
            let v = &mut v[..n - k];
            v.copy_from_slice(&a[k * n + k..(k + 1) * n]);
            v[0] -= beta;
            let vv = dot(v, v);
            if vv > 0.0 {
                for j in k + 1..m {
                    let cj = &mut a[j * n + k..(j + 1) * n];
                    let s = 2.0 * dot(v, cj) / vv;
                    axpy(-s, v, cj);
                }
            }
            a[k * n + k] = beta;
            for x in a[k * n + k + 1..(k + 1) * n].iter_mut() {
                *x = 0.0;
            }
        }
        if rank == m {
            return None;
        }
        let mut dependent = Vec::new();
        let mut joints: Vec<String> = Vec::new();
        for j in rank..m {
            // y = R11^-1 R12 e_j by back substitution (R11 = rank x rank upper triangle)
            let mut y: Vec<f64> = (0..rank).map(|i| a[j * n + i]).collect();
            for i in (0..rank).rev() {
                let mut acc = y[i];
                for k in i + 1..rank {
                    acc -= a[k * n + i] * y[k];
                }
                y[i] = acc / a[i * n + i];
            }
            let wmax = max_abs(&y).max(1.0);
            dependent.push(sys.equation_name(self.sel.full_row(perm[j])));
            let mut rows: Vec<usize> = vec![self.sel.full_row(perm[j])];
            rows.extend(
                (0..rank)
                    .filter(|&i| y[i].abs() > 1e-6 * wmax)
                    .map(|i| self.sel.full_row(perm[i])),
            );
            rows.sort_unstable();
            for r in rows {
                if let Some(h) = sys.equation_joint(r) {
                    let name = sys.joints()[h.index()].name.clone();
                    if !joints.contains(&name) {
                        joints.push(name);
                    }
                }
            }
        }
        Some(SolveError::Singular {
            t,
            what: "configuration (rank-deficient constraint Jacobian Phi_q)",
            detail: format!(
                "rank {rank} of {m}; dependent equations {}; joints {}",
                dependent.join(", "),
                joints.join(", ")
            ),
        })
    }
}
