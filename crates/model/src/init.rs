//! Rank checks and consistent initial conditions.

use crate::error::ModelError;
use crate::system::System;
use faer::linalg::solvers::Solve;
use faer::{Mat, Side};
use nalgebra::{DMatrix, DVector};

/// Settings of [`System::project`].
#[derive(Clone, Copy, Debug)]
pub struct ProjectionOptions {
    /// Target max-norm of `Phi`. It is floored at the round-off level of the coordinates,
    /// `8 eps max(1, |q_guess|_inf)`, which no iteration can beat (so a model placed far from
    /// the origin still projects).
    pub tol: f64,
    /// Newton iteration limit.
    pub max_iter: usize,
}

impl Default for ProjectionOptions {
    fn default() -> Self {
        ProjectionOptions {
            tol: 1e-13,
            max_iter: 50,
        }
    }
}

/// A state on the constraint manifold, with how far the guess was moved.
#[derive(Clone, Debug)]
pub struct ConsistentState {
    /// Positions with `Phi(q, t) = 0`.
    pub q: DVector<f64>,
    /// Velocities with `Phi_q v + Phi_t = 0`.
    pub v: DVector<f64>,
    /// Max-norm of the position correction `q - q_guess`.
    pub position_correction: f64,
    /// Max-norm of the velocity correction `v - v_guess`.
    pub velocity_correction: f64,
    /// Newton iterations of the position projection.
    pub iterations: usize,
    /// Final `||Phi||_inf`.
    pub residual: f64,
    /// Final `||Phi_q v + Phi_t||_inf`.
    pub velocity_residual: f64,
}

use crate::numeric::max_abs;

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

    /// Projects the bodies' stored initial state onto the constraints at time `t`.
    pub fn consistent_state(&self, t: f64) -> Result<ConsistentState, ModelError> {
        let (q, v) = self.initial_guess();
        self.project(q.as_slice(), v.as_slice(), t, ProjectionOptions::default())
    }

    /// Projects a guess `(q, v)` onto the constraint manifold at time `t`: positions by Newton
    /// with the minimum `M`-norm correction `dq = -M^-1 Phi_q^T (Phi_q M^-1 Phi_q^T)^-1 Phi`,
    /// then velocities by the `M`-orthogonal projection onto `Phi_q v + Phi_t = 0`.
    pub fn project(
        &self,
        q_guess: &[f64],
        v_guess: &[f64],
        t: f64,
        opts: ProjectionOptions,
    ) -> Result<ConsistentState, ModelError> {
        self.check_len("q_guess", q_guess, self.n)?;
        self.check_len("v_guess", v_guess, self.n)?;
        if let Some(i) = q_guess.iter().chain(v_guess).position(|x| !x.is_finite()) {
            return Err(ModelError::InvalidParameter {
                element: "initial state".into(),
                parameter: if i < self.n { "q_guess" } else { "v_guess" },
                value: f64::NAN,
                reason: "must be finite",
            });
        }
        let (n, m) = (self.n, self.m);
        let mut q = DVector::from_column_slice(q_guess);
        let mut v = DVector::from_column_slice(v_guess);
        if m == 0 {
            return Ok(ConsistentState {
                q,
                v,
                position_correction: 0.0,
                velocity_correction: 0.0,
                iterations: 0,
                residual: 0.0,
                velocity_residual: 0.0,
            });
        }
        let mut phi = vec![0.0; m];
        let mut jac = DMatrix::zeros(m, n);
        let mut iterations = 0;
        let worst = |phi: &[f64]| -> (f64, usize) {
            phi.iter().enumerate().fold(
                (0.0, 0),
                |(a, ia), (i, &b)| if b.abs() > a { (b.abs(), i) } else { (a, ia) },
            )
        };
        let tol = opts.tol.max(8.0 * f64::EPSILON * max_abs(q_guess).max(1.0));
        loop {
            self.phi(q.as_slice(), t, &mut phi);
            let (res, iw) = worst(&phi);
            if !res.is_finite() || (iterations >= opts.max_iter && res > tol) {
                return Err(ModelError::Projection {
                    residual: res,
                    iterations,
                    equation: self.equation_name(iw),
                });
            }
            if res <= tol {
                break;
            }
            self.phi_q(q.as_slice(), &mut jac);
            let y = self
                .schur_solve(&jac, &phi)
                .map_err(|_| ModelError::Projection {
                    residual: res,
                    iterations,
                    equation: self.equation_name(iw),
                })?;
            // dq = -M^-1 Phi_q^T y
            let dq = jac.tr_mul(&y).component_mul(&self.inv_mass);
            q -= dq;
            iterations += 1;
        }
        self.check_rank(q.as_slice(), t)?;
        self.phi_q(q.as_slice(), &mut jac);
        let mut pd = vec![0.0; m];
        self.phi_dot(q.as_slice(), v.as_slice(), t, &mut pd);
        for _ in 0..2 {
            let y = self
                .schur_solve(&jac, &pd)
                .map_err(|_| ModelError::Singular {
                    joints: self.joints.iter().map(|j| j.name.clone()).collect(),
                })?;
            v -= jac.tr_mul(&y).component_mul(&self.inv_mass);
            self.phi_dot(q.as_slice(), v.as_slice(), t, &mut pd);
        }
        self.phi(q.as_slice(), t, &mut phi);
        let position_correction = max_abs((&q - DVector::from_column_slice(q_guess)).as_slice());
        let velocity_correction = max_abs((&v - DVector::from_column_slice(v_guess)).as_slice());
        Ok(ConsistentState {
            q,
            v,
            position_correction,
            velocity_correction,
            iterations,
            residual: max_abs(&phi),
            velocity_residual: max_abs(&pd),
        })
    }

    /// Solves `(Phi_q M^-1 Phi_q^T) y = rhs` (Cholesky); an error if not positive definite.
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

    /// Solves `(Phi_q M^-1 Phi_q^T) y = rhs` (Cholesky); an error if not positive definite.
    fn schur_solve(&self, jac: &DMatrix<f64>, rhs: &[f64]) -> Result<DVector<f64>, ()> {
        let m = self.m;
        let llt = self.schur_matrix(jac).llt(Side::Lower).map_err(|_| ())?;
        let mut b = Mat::<f64>::zeros(m, 1);
        for i in 0..m {
            b[(i, 0)] = rhs[i];
        }
        llt.solve_in_place(b.as_mut());
        Ok(DVector::from_iterator(m, (0..m).map(|i| b[(i, 0)])))
    }
}
