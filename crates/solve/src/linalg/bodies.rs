//! The constrained solve of a model with spatial bodies, their internal constraints eliminated
//! body by body (`mbd_model::spatial::RigidSolve`, docs/spatial.md): the index-1 solve and the
//! projections for any mass matrix that is definite on the constraints' tangent space (thin
//! discs and plates included), from the whole dense `Phi_q`.
//!
//! With `C` the block-diagonal constrained inverse mass (a planar body's or a spatial point
//! mass's block its diagonal `M^-1`, `I/m` for a point mass, or the projection's weights; a
//! spatial body's block `RigidSolve`'s) and `Phi_e` the
//! rows other than the internal constraints, the solution of
//! `M a + Phi^T lambda = f`, `Phi a = r` is
//!
//! ```text
//! x = C f + d(r_int),                 d: the particular accelerations of each spatial body
//! S lambda_e = Phi_e x - r_e,         S = Phi_e C Phi_e^T
//! a = x - C Phi_e^T lambda_e
//! ```
//!
//! and each body's internal multipliers follow from its own rows,
//! `mu = (G G^T)^-1 G (f - Phi_e^T lambda_e - M a)`.

use super::{DenseCholesky, FactorError};
use mbd_model::spatial::RigidSolve;
use mbd_model::System;
use nalgebra::DMatrix;

/// The workspace of the body-eliminated solve (see the module documentation).
#[derive(Debug)]
pub(crate) struct BodySchur {
    n: usize,
    /// The whole `Phi_q` (m x n), filled by the caller.
    pub(crate) phi_q: DMatrix<f64>,
    /// The external rows (all but the spatial internal constraints).
    rows: Vec<usize>,
    /// The internal constraints' rows `r0..r0 + 6 ns`, the spatial bodies' coordinates
    /// `q0..qp` and the point masses' `qp..n`.
    r0: usize,
    q0: usize,
    qp: usize,
    /// Each spatial body's elimination at the last factorisation.
    rigid: Vec<RigidSolve>,
    /// `C Phi_e^T` (column `e`: `C` applied to external row `e`).
    c_rows: DMatrix<f64>,
    /// The factorisation of `S`.
    pub(crate) chol: DenseCholesky,
    x: Vec<f64>,
    y: Vec<f64>,
    /// The external multipliers.
    le: Vec<f64>,
}

impl BodySchur {
    /// The workspace for `sys` (allocates; once).
    pub(crate) fn new(sys: &System) -> Self {
        let (m, n) = (sys.n_constraints(), sys.n_coords());
        let internal = sys.spatial_internal_rows();
        let rows: Vec<usize> = (0..m).filter(|r| !internal.contains(r)).collect();
        let mut chol = DenseCholesky::new(rows.len());
        chol.set_max_dependent(sys.n_redundant());
        BodySchur {
            n,
            phi_q: DMatrix::zeros(m, n),
            c_rows: DMatrix::zeros(n, rows.len()),
            le: vec![0.0; rows.len()],
            rows,
            r0: internal.start,
            q0: sys.spatial_offset(),
            qp: sys.spatial_point_mass_offset(),
            rigid: Vec::with_capacity(sys.spatial_bodies().len()),
            chol,
            x: vec![0.0; n],
            y: vec![0.0; n],
        }
    }

    /// `out = C f` (`w` the planar and point-mass coordinates' weights, e.g. `M^-1`).
    fn apply_c(&self, w: &[f64], f: &[f64], out: &mut [f64]) {
        let q0 = self.q0;
        for k in (0..q0).chain(self.qp..self.n) {
            out[k] = w[k] * f[k];
        }
        for (b, rigid) in self.rigid.iter().enumerate() {
            let o = q0 + 12 * b;
            let fb: [f64; 12] = std::array::from_fn(|l| f[o + l]);
            out[o..o + 12].copy_from_slice(&rigid.apply_inverse_mass(&fb));
        }
    }

    /// Builds each spatial body's elimination at `q`, `C Phi_e^T` from [`BodySchur::phi_q`]
    /// and factors `S = Phi_e C Phi_e^T`. Errors: a degenerate spatial body (named), or the
    /// row of the failing pivot of `S`.
    pub(crate) fn factor(
        &mut self,
        sys: &System,
        q: &[f64],
        w: &[f64],
    ) -> Result<(), BodyFactorError> {
        self.rigid.clear();
        for (k, b) in sys.spatial_bodies().iter().enumerate() {
            let o = self.q0 + 12 * k;
            let qb: [f64; 12] = std::array::from_fn(|l| q[o + l]);
            let r = RigidSolve::new(&b.inertia, &qb)
                .map_err(|e| BodyFactorError::Body(b.name.clone(), e.to_string()))?;
            self.rigid.push(r);
        }
        let me = self.rows.len();
        let mut row = std::mem::take(&mut self.x);
        let mut crow = std::mem::take(&mut self.y);
        for e in 0..me {
            for (k, x) in row.iter_mut().enumerate() {
                *x = self.phi_q[(self.rows[e], k)];
            }
            self.apply_c(w, &row, &mut crow);
            self.c_rows.column_mut(e).copy_from_slice(&crow);
        }
        (self.x, self.y) = (row, crow);
        let s = self.chol.values_mut();
        for j in 0..me {
            for i in 0..me {
                let ri = self.rows[i];
                let mut acc = 0.0;
                for k in 0..self.n {
                    acc += self.phi_q[(ri, k)] * self.c_rows[(k, j)];
                }
                s[i + j * me] = acc;
            }
        }
        self.chol.factor_in_place().map_err(|e| {
            let i = match e {
                FactorError::Singular(i) | FactorError::NotPositiveDefinite(i) => i,
            };
            BodyFactorError::Row(self.rows.get(i).copied().unwrap_or(i))
        })
    }

    /// The model rows (equations) the last factorisation dropped as dependent on earlier
    /// ones, appended to `out` (none for a model without redundant equations).
    pub(crate) fn dependent_rows(&self, out: &mut Vec<usize>) {
        out.extend(self.chol.dependent().iter().map(|&e| self.rows[e]));
    }

    /// The solution `a` of `M a + Phi^T lambda = f`, `Phi a = r` at the last factorisation
    /// (see the module documentation), with its multipliers `lambda` (length m).
    pub(crate) fn solve(
        &mut self,
        w: &[f64],
        f: &[f64],
        r: &[f64],
        a: &mut [f64],
        lambda: &mut [f64],
    ) {
        let mut x = std::mem::take(&mut self.x);
        self.apply_c(w, f, &mut x);
        for (b, rigid) in self.rigid.iter().enumerate() {
            let o = self.q0 + 12 * b;
            let ri: [f64; 6] = std::array::from_fn(|l| r[self.r0 + 6 * b + l]);
            let d = rigid.solve(&[0.0; 12], &ri);
            for l in 0..12 {
                x[o + l] += d[l];
            }
        }
        // S lambda_e = Phi_e x - r_e
        let mut le = std::mem::take(&mut self.le);
        for (e, le) in le.iter_mut().enumerate() {
            let re = self.rows[e];
            let mut acc = -r[re];
            for k in 0..self.n {
                acc += self.phi_q[(re, k)] * x[k];
            }
            *le = acc;
        }
        self.chol.solve_in_place(&mut le);
        lambda.fill(0.0);
        for (e, &l) in le.iter().enumerate() {
            lambda[self.rows[e]] = l;
        }
        for k in 0..self.n {
            let mut acc = x[k];
            for (e, &l) in le.iter().enumerate() {
                acc -= self.c_rows[(k, e)] * l;
            }
            a[k] = acc;
        }
        // each body's internal multipliers from its own rows: G^T mu = f - Phi_e^T lambda_e - M a
        for (b, rigid) in self.rigid.iter().enumerate() {
            let o = self.q0 + 12 * b;
            let mut g: [f64; 12] = std::array::from_fn(|l| f[o + l]);
            for (e, &l) in le.iter().enumerate() {
                let re = self.rows[e];
                for (k, gk) in g.iter_mut().enumerate() {
                    *gk -= self.phi_q[(re, o + k)] * l;
                }
            }
            let ab: [f64; 12] = std::array::from_fn(|l| a[o + l]);
            let mu = rigid.multipliers(&g, &ab);
            lambda[self.r0 + 6 * b..self.r0 + 6 * b + 6].copy_from_slice(&mu);
        }
        self.x = x;
        self.le = le;
    }
}

/// Why [`BodySchur::factor`] failed.
#[derive(Debug)]
pub(crate) enum BodyFactorError {
    /// A spatial body's elimination (its name, the reason).
    Body(String, String),
    /// `S` is singular at this row of `Phi`.
    Row(usize),
}
