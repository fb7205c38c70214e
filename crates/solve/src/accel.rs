//! The index-1 acceleration solve
//! `[[M, Phi_q^T], [Phi_q, 0]] [a; lambda] = [Q; gamma]`.
//!
//! `M` is diagonal, so the saddle-point system is solved through its Schur complement:
//! `S = Phi_q M^-1 Phi_q^T` (symmetric positive definite when `Phi_q` has full row rank),
//! `S lambda = Phi_q M^-1 Q - gamma`, `a = M^-1 (Q - Phi_q^T lambda)`. This costs
//! `O(m^2 n + m^3)` instead of `O((n+m)^3)` and uses a Cholesky factorisation (faer). A singular
//! `S` means redundant constraints or a singular configuration and is an error naming the
//! equation at the failing pivot.

use crate::error::SolveError;
use crate::linalg::DenseCholesky;
use mbd_model::System;
use nalgebra::DMatrix;

/// Workspace and driver for the index-1 solve; allocation-free after [`AccelerationSolver::new`].
#[derive(Debug)]
pub struct AccelerationSolver {
    n: usize,
    m: usize,
    /// `Phi_q` at the last solve.
    pub phi_q: DMatrix<f64>,
    /// `gamma` at the last solve.
    pub gamma: Vec<f64>,
    /// Applied forces `Q` at the last solve.
    pub forces: Vec<f64>,
    chol: DenseCholesky,
    w: Vec<f64>,
}

impl AccelerationSolver {
    /// A workspace sized for `sys`.
    pub fn new(sys: &System) -> Self {
        let (n, m) = (sys.n_coords(), sys.n_constraints());
        AccelerationSolver {
            n,
            m,
            phi_q: DMatrix::zeros(m, n),
            gamma: vec![0.0; m],
            forces: vec![0.0; n],
            chol: DenseCholesky::new(m),
            w: vec![0.0; n],
        }
    }

    /// Solves for the accelerations `a` (length n) and multipliers `lambda` (length m) at
    /// `(q, v, t)`.
    pub fn solve(
        &mut self,
        sys: &System,
        q: &[f64],
        v: &[f64],
        t: f64,
        a: &mut [f64],
        lambda: &mut [f64],
    ) -> Result<(), SolveError> {
        sys.forces_into(q, v, t, &mut self.forces);
        self.solve_with_forces(sys, q, v, t, a, lambda)
    }

    /// As [`AccelerationSolver::solve`], with the applied forces already in
    /// [`AccelerationSolver::forces`] (lets a caller add its own terms, e.g. Baumgarte).
    pub fn solve_with_forces(
        &mut self,
        sys: &System,
        q: &[f64],
        v: &[f64],
        t: f64,
        a: &mut [f64],
        lambda: &mut [f64],
    ) -> Result<(), SolveError> {
        let (n, m) = (self.n, self.m);
        if q.len() != n || v.len() != n || a.len() != n || lambda.len() != m {
            return Err(SolveError::Dimension {
                what: "acceleration solve arguments",
                expected: n,
                got: q.len(),
            });
        }
        if m == 0 {
            let minv = sys.inv_mass_diag();
            for i in 0..n {
                a[i] = minv[i] * self.forces[i];
            }
            return Ok(());
        }
        sys.phi_q_gamma(q, v, t, &mut self.phi_q, &mut self.gamma);
        self.finish(sys, t, a, lambda)
    }

    /// Completes the solve from `phi_q`, `gamma` and `forces` already set (advanced use).
    pub fn finish(
        &mut self,
        sys: &System,
        t: f64,
        a: &mut [f64],
        lambda: &mut [f64],
    ) -> Result<(), SolveError> {
        let (n, m) = (self.n, self.m);
        let minv = sys.inv_mass_diag();
        // a_free = M^-1 Q
        for i in 0..n {
            self.w[i] = minv[i] * self.forces[i];
        }
        let j = &self.phi_q;
        {
            let mut s = self.chol.matrix_mut();
            for c in 0..m {
                for r in c..m {
                    let mut acc = 0.0;
                    for k in 0..n {
                        acc += j[(r, k)] * minv[k] * j[(c, k)];
                    }
                    s[(r, c)] = acc;
                }
            }
        }
        self.chol.factor_in_place().map_err(|e| {
            let i = match e {
                crate::linalg::FactorError::Singular(i)
                | crate::linalg::FactorError::NotPositiveDefinite(i) => i,
            };
            SolveError::Singular {
                t,
                what: "constraint matrix Phi_q M^-1 Phi_q^T",
                detail: sys.equation_name(i),
            }
        })?;
        // rhs = Phi_q M^-1 Q - gamma
        for r in 0..m {
            let mut acc = 0.0;
            for k in 0..n {
                acc += j[(r, k)] * self.w[k];
            }
            lambda[r] = acc - self.gamma[r];
        }
        self.chol.solve_in_place(lambda);
        for k in 0..n {
            let mut acc = 0.0;
            for r in 0..m {
                acc += j[(r, k)] * lambda[r];
            }
            a[k] = self.w[k] - minv[k] * acc;
        }
        Ok(())
    }
}
