//! Damped Newton's method with an analytic Jacobian on preallocated buffers.

use crate::error::SolveError;
use crate::linalg::{max_abs as norm_inf, DenseLu};
use nalgebra::DMatrix;

/// A square nonlinear system `r(x) = 0`.
pub trait NewtonProblem {
    /// Number of unknowns (= equations).
    fn dim(&self) -> usize;
    /// Residual `r(x)` into `r`.
    fn residual(&mut self, x: &[f64], r: &mut [f64]);
    /// Jacobian `dr/dx` into `jac` (dim x dim, overwritten).
    fn jacobian(&mut self, x: &[f64], jac: &mut DMatrix<f64>);
}

/// Settings of [`Newton`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NewtonOptions {
    /// Converged when `||r||_inf <= tol` (or the last update is below `step_tol` relative).
    pub tol: f64,
    /// Converged when `||dx||_inf <= step_tol (1 + ||x||_inf)` and the residual fell.
    pub step_tol: f64,
    /// Iteration limit.
    pub max_iter: usize,
    /// Backtracking halvings allowed per iteration (0 = plain Newton).
    pub max_halvings: usize,
    /// Recompute the Jacobian every `k` iterations (1 = full Newton).
    pub jacobian_every: usize,
}

impl Default for NewtonOptions {
    fn default() -> Self {
        NewtonOptions {
            tol: 1e-12,
            step_tol: 1e-15,
            max_iter: 30,
            max_halvings: 8,
            jacobian_every: 1,
        }
    }
}

impl NewtonOptions {
    /// Checks the settings.
    pub fn validate(&self) -> Result<(), SolveError> {
        if !(self.tol > 0.0 && self.tol.is_finite()) {
            return Err(SolveError::InvalidParameter {
                parameter: "newton.tol",
                value: self.tol,
                reason: "must be positive and finite",
            });
        }
        if !(self.step_tol >= 0.0 && self.step_tol.is_finite()) {
            return Err(SolveError::InvalidParameter {
                parameter: "newton.step_tol",
                value: self.step_tol,
                reason: "must be non-negative and finite",
            });
        }
        if self.max_iter == 0 {
            return Err(SolveError::InvalidParameter {
                parameter: "newton.max_iter",
                value: 0.0,
                reason: "must be at least 1",
            });
        }
        if self.jacobian_every == 0 {
            return Err(SolveError::InvalidParameter {
                parameter: "newton.jacobian_every",
                value: 0.0,
                reason: "must be at least 1",
            });
        }
        Ok(())
    }
}

/// What a Newton solve did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct NewtonStats {
    /// Iterations (Jacobian solves).
    pub iterations: usize,
    /// Final `||r||_inf`.
    pub residual: f64,
    /// Jacobian evaluations.
    pub jacobians: usize,
}

/// Damped Newton solver with its workspace (allocation-free per solve).
#[derive(Debug)]
pub struct Newton {
    /// Settings.
    pub options: NewtonOptions,
    lu: DenseLu,
    jac: DMatrix<f64>,
    r: Vec<f64>,
    dx: Vec<f64>,
    xt: Vec<f64>,
    rt: Vec<f64>,
}

impl Newton {
    /// A solver for problems of dimension `n`.
    pub fn new(n: usize, options: NewtonOptions) -> Self {
        Newton {
            options,
            lu: DenseLu::new(n),
            jac: DMatrix::zeros(n, n),
            r: vec![0.0; n],
            dx: vec![0.0; n],
            xt: vec![0.0; n],
            rt: vec![0.0; n],
        }
    }

    /// The Jacobian at the last evaluation.
    pub fn last_jacobian(&self) -> &DMatrix<f64> {
        &self.jac
    }

    /// Solves `r(x) = 0` starting from `x` (overwritten with the solution). `t` and `context` go
    /// into the error if it fails.
    pub fn solve<P: NewtonProblem + ?Sized>(
        &mut self,
        p: &mut P,
        x: &mut [f64],
        t: f64,
        context: &str,
    ) -> Result<NewtonStats, SolveError> {
        let n = self.r.len();
        if p.dim() != n || x.len() != n {
            return Err(SolveError::Dimension {
                what: "Newton unknowns",
                expected: n,
                got: x.len(),
            });
        }
        let o = self.options;
        let fail = |res: f64, it: usize| SolveError::Newton {
            t,
            residual: res,
            iterations: it,
            context: context.to_string(),
        };
        p.residual(x, &mut self.r);
        let mut res = norm_inf(&self.r);
        let mut stats = NewtonStats {
            iterations: 0,
            residual: res,
            jacobians: 0,
        };
        if !res.is_finite() {
            return Err(fail(res, 0));
        }
        if res <= o.tol {
            return Ok(stats);
        }
        for it in 0..o.max_iter {
            if it % o.jacobian_every == 0 {
                p.jacobian(x, &mut self.jac);
                stats.jacobians += 1;
                self.lu
                    .factor(&self.jac)
                    .map_err(|_| SolveError::Singular {
                        t,
                        what: "Newton Jacobian",
                        detail: context.to_string(),
                    })?;
            }
            for i in 0..n {
                self.dx[i] = -self.r[i];
            }
            self.lu.solve_in_place(&mut self.dx);
            let mut lambda = 1.0;
            let mut accepted = false;
            for _ in 0..=o.max_halvings {
                for i in 0..n {
                    self.xt[i] = x[i] + lambda * self.dx[i];
                }
                p.residual(&self.xt, &mut self.rt);
                let rn = norm_inf(&self.rt);
                if rn.is_finite() && (rn < res || o.max_halvings == 0) {
                    accepted = true;
                    res = rn;
                    break;
                }
                lambda *= 0.5;
            }
            stats.iterations = it + 1;
            if !accepted {
                // no decrease: accept whether the full step is at round-off level
                let step = norm_inf(&self.dx);
                let xs = norm_inf(x);
                if step <= 1e3 * f64::EPSILON * (1.0 + xs) {
                    stats.residual = res;
                    return Ok(stats);
                }
                return Err(fail(res, it + 1));
            }
            x.copy_from_slice(&self.xt);
            std::mem::swap(&mut self.r, &mut self.rt);
            stats.residual = res;
            let step = lambda * norm_inf(&self.dx);
            if res <= o.tol || step <= o.step_tol * (1.0 + norm_inf(x)) {
                return Ok(stats);
            }
        }
        Err(fail(res, o.max_iter))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    struct Circle;
    impl NewtonProblem for Circle {
        fn dim(&self) -> usize {
            2
        }
        fn residual(&mut self, x: &[f64], r: &mut [f64]) {
            r[0] = x[0] * x[0] + x[1] * x[1] - 4.0;
            r[1] = x[0] - x[1];
        }
        fn jacobian(&mut self, x: &[f64], j: &mut DMatrix<f64>) {
            j[(0, 0)] = 2.0 * x[0];
            j[(0, 1)] = 2.0 * x[1];
            j[(1, 0)] = 1.0;
            j[(1, 1)] = -1.0;
        }
    }
    #[test]
    fn converges_quadratically() {
        let mut nw = Newton::new(2, NewtonOptions::default());
        let mut x = [3.0, 1.0];
        let s = nw.solve(&mut Circle, &mut x, 0.0, "circle").unwrap();
        assert!((x[0] - 2f64.sqrt()).abs() < 1e-14 && (x[1] - 2f64.sqrt()).abs() < 1e-14);
        assert!(s.iterations <= 7, "{s:?}");
    }
    #[test]
    fn reports_failure_with_time_and_residual() {
        struct NoRoot;
        impl NewtonProblem for NoRoot {
            fn dim(&self) -> usize {
                1
            }
            fn residual(&mut self, x: &[f64], r: &mut [f64]) {
                r[0] = x[0] * x[0] + 1.0;
            }
            fn jacobian(&mut self, x: &[f64], j: &mut DMatrix<f64>) {
                j[(0, 0)] = 2.0 * x[0];
            }
        }
        let mut nw = Newton::new(1, NewtonOptions::default());
        let mut x = [0.5];
        match nw.solve(&mut NoRoot, &mut x, 1.25, "no root") {
            Err(SolveError::Newton { t, residual, .. }) => {
                assert_eq!(t, 1.25);
                assert!(residual >= 1.0);
            }
            Err(SolveError::Singular { t, .. }) => assert_eq!(t, 1.25),
            other => panic!("expected failure, got {other:?}"),
        }
    }
}
