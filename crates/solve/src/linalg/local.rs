//! The dense Schur complement `S = Phi_q W Phi_q^T` (diagonal `W`, e.g. `M^-1`) assembled from
//! the element-local rows of `Phi_q` (each equation acts on at most two bodies: six numbers per
//! row), for the small systems of the dense path: the index-1 solve and the projection. Which
//! pairs of rows share a body is worked out once, so an assembly is one three-term product per
//! pair and shared body, with no loop over zero columns.

use super::{DenseCholesky, FactorError};
use crate::sparse::RowIncidence;
use mbd_model::System;
use nalgebra::DMatrix;

/// A side of a row that acts on no body (ground).
const GROUND: usize = usize::MAX;

/// `Phi_q` in element-local rows and the Cholesky factorisation of `S = Phi_q W Phi_q^T`.
///
/// Each row has two halves, the three columns of its first and of its second body (half
/// `2 r + s`); `S_(r1, r2)` is the sum over the bodies the two rows share of
/// `u_h1 . (W u_h2)` for the halves `h1`, `h2` on that body.
#[derive(Debug)]
pub(crate) struct DenseSchur {
    m: usize,
    /// Per row: the first coordinate (`3 i`) of the body in its local columns `0..3` and
    /// `3..6`, [`GROUND`] for ground.
    cols: Vec<[usize; 2]>,
    /// One term `(index of S_(r1, r2) in the column-major storage, h1, h2)` per pair of rows
    /// `r1 >= r2` acting on a common body, in storage order (the terms of one entry in body
    /// order).
    plan: Vec<[usize; 3]>,
    /// The element-local rows of `Phi_q` (see [`System::phi_q_local`]).
    pub(crate) grads: Vec<[f64; 6]>,
    /// The halves of the rows and their `W`-weighted values at the last
    /// [`DenseSchur::factor`] (ground halves unused).
    u: Vec<[f64; 3]>,
    wu: Vec<[f64; 3]>,
    /// The factorisation of `S`.
    pub(crate) chol: DenseCholesky,
}

impl DenseSchur {
    /// The workspace and assembly plan for `sys` (allocates; once).
    pub(crate) fn new(sys: &System) -> Self {
        let m = sys.n_constraints();
        let inc = RowIncidence::new(sys);
        let side = |b: Option<usize>| b.map_or(GROUND, |i| 3 * i);
        let cols = inc
            .row_bodies
            .iter()
            .map(|&(a, b)| [side(a), side(b)])
            .collect();
        let mut plan = Vec::new();
        for rows in &inc.by_body {
            for &(r1, o1) in rows {
                for &(r2, o2) in rows {
                    if r1 >= r2 {
                        plan.push([r1 + r2 * m, 2 * r1 + o1 / 3, 2 * r2 + o2 / 3]);
                    }
                }
            }
        }
        // in storage order (a stable sort: the terms of one entry stay in body order)
        plan.sort_by_key(|t| t[0]);
        let mut chol = DenseCholesky::new(m);
        // a mechanism with redundant equations: each factorisation drops that many dependent
        // rows (their multipliers zero), and no more
        chol.set_max_dependent(sys.dependency_budget());
        DenseSchur {
            m,
            cols,
            plan,
            grads: vec![[0.0; 6]; m],
            u: vec![[0.0; 3]; 2 * m],
            wu: vec![[0.0; 3]; 2 * m],
            chol,
        }
    }

    /// Assembles `S = Phi_q W Phi_q^T` (`w` the diagonal of `W`, length n) from
    /// [`DenseSchur::grads`] and factors it; an error names the row at the failing pivot.
    #[inline]
    pub(crate) fn factor(&mut self, w: &[f64]) -> Result<(), FactorError> {
        self.factor_impl(w, None)
    }

    /// [`DenseSchur::factor`], and `out_r = (Phi_q x)_r - sub_r` for every row `r` (`x` of
    /// length n, `sub` of length m) from the same pass over the rows.
    #[inline(always)]
    pub(crate) fn factor_rhs(
        &mut self,
        w: &[f64],
        x: &[f64],
        sub: &[f64],
        out: &mut [f64],
    ) -> Result<(), FactorError> {
        self.factor_impl(w, Some((x, sub, out)))
    }

    #[inline(always)]
    fn factor_impl(
        &mut self,
        w: &[f64],
        mut rhs: Option<(&[f64], &[f64], &mut [f64])>,
    ) -> Result<(), FactorError> {
        let m = self.grads.len();
        let (grads, cols) = (&self.grads[..], &self.cols[..m]);
        let (u, wu) = (&mut self.u[..2 * m], &mut self.wu[..2 * m]);
        for r in 0..m {
            let (g, c) = (&grads[r], cols[r]);
            let mut acc = 0.0;
            for s in 0..2 {
                let col = c[s];
                if col == GROUND {
                    continue;
                }
                let h = [g[3 * s], g[3 * s + 1], g[3 * s + 2]];
                let wb = &w[col..col + 3];
                u[2 * r + s] = h;
                wu[2 * r + s] = [wb[0] * h[0], wb[1] * h[1], wb[2] * h[2]];
                if let Some((x, _, _)) = &rhs {
                    let xb = &x[col..col + 3];
                    acc += h[0] * xb[0];
                    acc += h[1] * xb[1];
                    acc += h[2] * xb[2];
                }
            }
            if let Some((_, sub, out)) = &mut rhs {
                out[r] = acc - sub[r];
            }
        }
        let (u, wu, plan) = (&self.u[..], &self.wu[..], &self.plan[..]);
        let s = self.chol.values_mut();
        s.fill(0.0);
        for &[idx, h1, h2] in plan {
            let (a, b) = (&u[h1], &wu[h2]);
            s[idx] += a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        }
        self.chol.factor_in_place()
    }

    /// `out = Phi_q x` from the rows (`x`: n, `out`: m).
    pub(crate) fn times(&self, x: &[f64], out: &mut [f64]) {
        for ((o, g), c) in out.iter_mut().zip(&self.grads).zip(&self.cols) {
            let mut acc = 0.0;
            for (s, &col) in c.iter().enumerate() {
                if col != GROUND {
                    for l in 0..3 {
                        acc += g[3 * s + l] * x[col + l];
                    }
                }
            }
            *o = acc;
        }
    }

    /// `out -= W Phi_q^T y` with the `W` of the last [`DenseSchur::factor`].
    #[inline(always)]
    pub(crate) fn sub_weighted_transpose(&self, y: &[f64], out: &mut [f64]) {
        let m = self.cols.len();
        let (cols, wu, y) = (&self.cols[..], &self.wu[..2 * m], &y[..m]);
        for r in 0..m {
            let (c, yr) = (cols[r], y[r]);
            for s in 0..2 {
                let col = c[s];
                if col == GROUND {
                    continue;
                }
                let (ob, wr) = (&mut out[col..col + 3], &wu[2 * r + s]);
                ob[0] -= yr * wr[0];
                ob[1] -= yr * wr[1];
                ob[2] -= yr * wr[2];
            }
        }
    }

    /// The rows into the dense `m x n` matrix `out` (overwritten).
    pub(crate) fn scatter(&self, out: &mut DMatrix<f64>) {
        let m = self.m;
        let data = out.as_mut_slice();
        data.fill(0.0);
        for (r, (g, c)) in self.grads.iter().zip(&self.cols).enumerate() {
            for (s, &col) in c.iter().enumerate() {
                if col != GROUND {
                    // column-major: entry (r, k) at r + k m
                    for l in 0..3 {
                        data[r + (col + l) * m] = g[3 * s + l];
                    }
                }
            }
        }
    }

    /// The rows from the dense `m x n` matrix `jac`, if it has the structure of `Phi_q` (every
    /// entry outside a row's bodies' columns zero); `false` otherwise (the rows are then
    /// partly overwritten: the caller solves from `jac` itself).
    pub(crate) fn gather(&mut self, jac: &DMatrix<f64>) -> bool {
        let (m, n) = jac.shape();
        if m != self.m {
            return false;
        }
        let data = jac.as_slice();
        for (r, (g, c)) in self.grads.iter_mut().zip(&self.cols).enumerate() {
            let mut nonzeros = 0usize;
            for k in 0..n {
                nonzeros += (data[r + k * m] != 0.0) as usize;
            }
            let mut inside = 0usize;
            for (s, &col) in c.iter().enumerate() {
                for l in 0..3 {
                    let x = if col == GROUND {
                        0.0
                    } else {
                        data[r + (col + l) * m]
                    };
                    g[3 * s + l] = x;
                    inside += (x != 0.0) as usize;
                }
            }
            if inside != nonzeros {
                return false;
            }
        }
        true
    }
}
