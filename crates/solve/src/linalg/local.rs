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

/// One term `g_r1[o1..o1 + 3] . (W g_r2)[o2..o2 + 3]` of `S_(r1, r2)` (`r1` implied by the
/// term's place in the plan).
#[derive(Clone, Copy, Debug)]
struct Term {
    /// Index of `S_(r1, r2)` in the column-major storage.
    idx: usize,
    r2: usize,
    /// The body's columns in the two rows: `false` for `0..3`, `true` for `3..6`.
    second1: bool,
    second2: bool,
}

/// The body's three columns of a local row.
#[inline(always)]
fn half(g: &[f64; 6], second: bool) -> &[f64] {
    if second {
        &g[3..]
    } else {
        &g[..3]
    }
}

/// `Phi_q` in element-local rows and the Cholesky factorisation of `S = Phi_q W Phi_q^T`.
#[derive(Debug)]
pub(crate) struct DenseSchur {
    m: usize,
    /// Per row: the first coordinate (`3 i`) of the body in its local columns `0..3` and
    /// `3..6`, [`GROUND`] for ground.
    cols: Vec<[usize; 2]>,
    /// One term of `S` per pair of rows `r1 >= r2` acting on a common body, grouped by `r1`
    /// (row `r1`'s terms at `starts[r1]..starts[r1 + 1]`): see [`Term`].
    plan: Vec<Term>,
    starts: Vec<usize>,
    /// The element-local rows of `Phi_q` (see [`System::phi_q_local`]).
    pub(crate) grads: Vec<[f64; 6]>,
    /// `W`-weighted rows of the last [`DenseSchur::factor`].
    weighted: Vec<[f64; 6]>,
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
                        plan.push((
                            r1,
                            Term {
                                idx: r1 + r2 * m,
                                r2,
                                second1: o1 == 3,
                                second2: o2 == 3,
                            },
                        ));
                    }
                }
            }
        }
        // by rows, and within a row by entry (the terms of one entry stay in body order)
        plan.sort_by_key(|&(r1, t)| (r1, t.r2));
        let mut starts = vec![0; m + 1];
        for &(r1, _) in &plan {
            starts[r1 + 1] += 1;
        }
        for r in 0..m {
            starts[r + 1] += starts[r];
        }
        DenseSchur {
            m,
            cols,
            plan: plan.into_iter().map(|(_, t)| t).collect(),
            starts,
            grads: vec![[0.0; 6]; m],
            weighted: vec![[0.0; 6]; m],
            chol: DenseCholesky::new(m),
        }
    }

    /// Assembles `S = Phi_q W Phi_q^T` (`w` the diagonal of `W`, length n) from
    /// [`DenseSchur::grads`] and factors it; an error names the row at the failing pivot.
    pub(crate) fn factor(&mut self, w: &[f64]) -> Result<(), FactorError> {
        self.factor_impl(w, None)
    }

    /// [`DenseSchur::factor`], and `out_r = (Phi_q x)_r - sub_r` for every row `r` (`x` of
    /// length n, `sub` of length m) from the same pass over the rows.
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
        for (r, ((wr, g), c)) in self
            .weighted
            .iter_mut()
            .zip(&self.grads)
            .zip(&self.cols)
            .enumerate()
        {
            *wr = [0.0; 6];
            let mut acc = 0.0;
            for (s, &col) in c.iter().enumerate() {
                if col != GROUND {
                    let wb = &w[col..col + 3];
                    for l in 0..3 {
                        wr[3 * s + l] = wb[l] * g[3 * s + l];
                    }
                    if let Some((x, _, _)) = &rhs {
                        let xb = &x[col..col + 3];
                        for l in 0..3 {
                            acc += g[3 * s + l] * xb[l];
                        }
                    }
                }
            }
            if let Some((_, sub, out)) = &mut rhs {
                out[r] = acc - sub[r];
            }
        }
        let s = self.chol.values_mut();
        s.fill(0.0);
        for (g, span) in self.grads.iter().zip(self.starts.windows(2)) {
            for t in &self.plan[span[0]..span[1]] {
                let (a, b) = (half(g, t.second1), half(&self.weighted[t.r2], t.second2));
                s[t.idx] += a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
            }
        }
        self.chol.factor_in_place()
    }

    /// `out -= W Phi_q^T y` with the `W` of the last [`DenseSchur::factor`].
    pub(crate) fn sub_weighted_transpose(&self, y: &[f64], out: &mut [f64]) {
        for ((wr, c), &yr) in self.weighted.iter().zip(&self.cols).zip(y) {
            for (s, &col) in c.iter().enumerate() {
                if col != GROUND {
                    let ob = &mut out[col..col + 3];
                    for l in 0..3 {
                        ob[l] -= yr * wr[3 * s + l];
                    }
                }
            }
        }
    }

    /// The rows into the dense `m x n` matrix `out` (overwritten).
    pub(crate) fn scatter(&self, out: &mut DMatrix<f64>) {
        out.as_mut_slice().fill(0.0);
        for (r, (g, c)) in self.grads.iter().zip(&self.cols).enumerate() {
            for (s, &col) in c.iter().enumerate() {
                if col != GROUND {
                    for l in 0..3 {
                        out[(r, col + l)] = g[3 * s + l];
                    }
                }
            }
        }
    }

    /// The rows from the dense `m x n` matrix `jac`, if it has the structure of `Phi_q` (every
    /// entry outside a row's bodies' columns zero); `false` (rows unchanged) otherwise.
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
