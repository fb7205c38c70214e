//! The dense Schur complement `S = Phi_q W Phi_q^T` (diagonal `W`) from the whole dense
//! `Phi_q`: the kernel for models whose rows are not all planar element rows (spatial
//! bodies, whose elements span 24 coordinates). `O(m^2 n)` per factorisation, for the small
//! systems of the dense path.

use super::{DenseCholesky, FactorError};
use mbd_model::System;
use nalgebra::DMatrix;

/// `Phi_q` as a dense `m x n` matrix and the Cholesky factorisation of `S = Phi_q W Phi_q^T`.
#[derive(Debug)]
pub(crate) struct GlobalSchur {
    pub(crate) phi_q: DMatrix<f64>,
    pub(crate) chol: DenseCholesky,
}

impl GlobalSchur {
    /// The workspace for `sys` (allocates; once).
    pub(crate) fn new(sys: &System) -> Self {
        let (m, n) = (sys.n_constraints(), sys.n_coords());
        let mut chol = DenseCholesky::new(m);
        chol.set_max_dependent(sys.n_redundant());
        GlobalSchur {
            phi_q: DMatrix::zeros(m, n),
            chol,
        }
    }

    /// Assembles `S = Phi_q W Phi_q^T` from [`GlobalSchur::phi_q`] (`w` the diagonal of `W`)
    /// and factors it; with `rhs = (x, sub, out)` also `out = Phi_q x - sub`. An error names
    /// the row at the failing pivot.
    pub(crate) fn factor(
        &mut self,
        w: &[f64],
        mut rhs: Option<(&[f64], &[f64], &mut [f64])>,
    ) -> Result<(), FactorError> {
        let (m, n) = self.phi_q.shape();
        let jac = self.phi_q.as_slice();
        if let Some((_, sub, out)) = &mut rhs {
            for (o, s) in out.iter_mut().zip(sub.iter()) {
                *o = -s;
            }
        }
        self.chol.clear();
        for k in 0..n {
            let col = &jac[k * m..(k + 1) * m];
            if col.iter().all(|&x| x == 0.0) {
                continue;
            }
            self.chol.add_rank_one(w[k], col);
            if let Some((x, _, out)) = &mut rhs {
                let xk = x[k];
                for (o, &c) in out.iter_mut().zip(col) {
                    *o += c * xk;
                }
            }
        }
        self.chol.factor_in_place()
    }

    /// `out -= W Phi_q^T y`.
    pub(crate) fn sub_weighted_transpose(&self, w: &[f64], y: &[f64], out: &mut [f64]) {
        let (m, n) = self.phi_q.shape();
        let jac = self.phi_q.as_slice();
        for k in 0..n {
            let col = &jac[k * m..(k + 1) * m];
            let dot: f64 = col.iter().zip(y).map(|(c, l)| c * l).sum();
            out[k] -= w[k] * dot;
        }
    }
}
