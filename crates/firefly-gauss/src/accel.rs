//! Accelerations at a grid point from the index-1 solve, refined once.

use mbd_model::System;
use mbd_solve::{AccelerationSolver, SolveError};

/// The index-1 solve `[[M, Phi_q^T], [Phi_q, 0]] [a; lambda] = [Q; gamma]` followed by one step
/// of iterative refinement of the constraint row (`[[M, Phi_q^T], [Phi_q, 0]] [da; dl] =
/// [0; gamma - Phi_q a]`), so that the acceleration constraint `Phi_q a = gamma` holds to
/// round-off even where `Phi_q M^-1 Phi_q^T` is moderately conditioned and `gamma` large
/// (fast motion). The solver core's plain Schur-complement solve leaves residuals of a few
/// `1e-13` on the manipulator at high angular velocity; after refinement they are
/// `~1e-14`. Allocation-free after [`RefinedAcceleration::new`].
///
/// ```
/// use mbd_firefly_gauss::RefinedAcceleration;
/// use mbd_model::models;
/// use mbd_solve::State;
/// let sys = models::manipulator()?;
/// let s = State::consistent(&sys, 0.0)?;
/// let mut acc = RefinedAcceleration::new(&sys);
/// acc.solve(&sys, s.q.as_slice(), s.v.as_slice(), 0.0)?;
/// assert!(acc.residual() < 1e-14);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug)]
pub struct RefinedAcceleration {
    acc: AccelerationSolver,
    a: Vec<f64>,
    lambda: Vec<f64>,
    da: Vec<f64>,
    dl: Vec<f64>,
    gamma: Vec<f64>,
    r: Vec<f64>,
    residual: f64,
}

impl RefinedAcceleration {
    /// Workspace for `sys`.
    pub fn new(sys: &System) -> Self {
        let (n, m) = (sys.n_coords(), sys.n_constraints());
        RefinedAcceleration {
            acc: AccelerationSolver::new(sys),
            a: vec![0.0; n],
            lambda: vec![0.0; m],
            da: vec![0.0; n],
            dl: vec![0.0; m],
            gamma: vec![0.0; m],
            r: vec![0.0; m],
            residual: 0.0,
        }
    }

    /// `gamma - Phi_q a` into `self.r`; returns its max norm.
    fn constraint_residual(&mut self) -> f64 {
        let mut worst = 0.0f64;
        for k in 0..self.r.len() {
            let mut x = self.gamma[k];
            for (i, ai) in self.a.iter().enumerate() {
                x -= self.acc.phi_q[(k, i)] * ai;
            }
            self.r[k] = x;
            worst = worst.max(x.abs());
        }
        worst
    }

    /// The condition estimate of the last index-1 matrix (see
    /// [`AccelerationSolver::condition_estimate`]).
    pub fn condition_estimate(&self) -> f64 {
        self.acc.condition_estimate()
    }

    /// Solves at `(q, v, t)`.
    ///
    /// # Errors
    /// As [`AccelerationSolver::solve`] (singular constraint matrix, wrong sizes).
    pub fn solve(&mut self, sys: &System, q: &[f64], v: &[f64], t: f64) -> Result<(), SolveError> {
        self.acc
            .solve(sys, q, v, t, &mut self.a, &mut self.lambda)?;
        self.gamma.copy_from_slice(&self.acc.gamma);
        let before = self.constraint_residual();
        // refinement: right-hand side [0; r] (zero forces, gamma replaced by the residual)
        self.acc.forces.iter_mut().for_each(|f| *f = 0.0);
        self.acc.gamma.copy_from_slice(&self.r);
        self.acc.finish(sys, t, &mut self.da, &mut self.dl)?;
        self.acc.gamma.copy_from_slice(&self.gamma);
        for (a, d) in self.a.iter_mut().zip(&self.da) {
            *a += d;
        }
        let after = self.constraint_residual();
        if after <= before {
            for (l, d) in self.lambda.iter_mut().zip(&self.dl) {
                *l += d;
            }
            self.residual = after;
        } else {
            for (a, d) in self.a.iter_mut().zip(&self.da) {
                *a -= d;
            }
            self.residual = before;
        }
        Ok(())
    }

    /// Accelerations of the last solve.
    pub fn a(&self) -> &[f64] {
        &self.a
    }

    /// Multipliers of the last solve.
    pub fn lambda(&self) -> &[f64] {
        &self.lambda
    }

    /// `||Phi_q a - gamma||_inf` of the last solve (after refinement).
    pub fn residual(&self) -> f64 {
        self.residual
    }
}
