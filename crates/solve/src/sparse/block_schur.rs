//! `S = Phi_q W Phi_q^T` for a diagonal weight `W` over **every** row of a model with bodies of
//! any kind: [`super::ConstraintSchur`]'s operations on the block layout of
//! [`BlockRows`] (a planar row acts on 3 + 3 coordinates, a spatial one on up to 12 + 12).
//!
//! Where [`super::SparseBodySchur`] eliminates each spatial body's internal constraints first
//! (its weight is the body's constrained inverse mass), this keeps the internal rows in `S`
//! beside the joints' and weights every coordinate by a positive number. That is the form of
//! the symplectic preadjustment's projected metric, which needs `S^-1` on all rows and
//! products with `Phi_q` and `W Phi_q^T` separately. `S` couples two rows only when they share
//! a block, so for a chain it is banded and every operation is `O(N)`.

use super::{BlockRows, RowSide, SparseCholesky};
use crate::error::SolveError;
use crate::linalg::FactorError;
use mbd_model::System;

/// Two row sides on a shared block and the value slot of their entry of `S`.
pub(crate) type SharedPair = (RowSide, RowSide, usize);

/// The sparse Cholesky kernel on the pattern of `S = Phi W Phi^T` over the kept `rows` (two
/// rows couple where they share a block), allowed `max_dependent` dependent rows (a model's
/// redundant equations), and every pair of row sides on a shared block with the value slot of
/// their entry: what the block-row Schur complements ([`BlockSchur`],
/// [`super::SparseBodySchur`]) assemble from.
pub(crate) fn shared_pair_pattern(
    rows: &BlockRows,
    max_dependent: usize,
) -> Result<(SparseCholesky, Vec<SharedPair>), SolveError> {
    let mut pairs = Vec::new();
    rows.shared_pairs(|s1, s2, e1, e2| pairs.push((s1, s2, e1, e2)));
    let pattern: Vec<(usize, usize)> = pairs
        .iter()
        .filter(|p| p.2 > p.3)
        .map(|p| (p.2, p.3))
        .collect();
    let mut chol = SparseCholesky::new(rows.len(), &pattern)?;
    // a mechanism with redundant equations: each factorisation drops that many dependent rows
    // (their multipliers zero), and no more
    chol.set_max_dependent(max_dependent);
    let mut slots = Vec::with_capacity(pairs.len());
    for (s1, s2, e1, e2) in pairs {
        let slot = chol.slot(e1, e2).ok_or_else(|| {
            SolveError::Unsupported(format!("sparse Schur pattern lacks entry ({e1}, {e2})"))
        })?;
        slots.push((s1, s2, slot));
    }
    Ok((chol, slots))
}

/// One contribution to `S`: rows sharing a block (the offsets of their gradients on it, the
/// block's first coordinate and width, and the value slot of the entry).
#[derive(Clone, Copy, Debug)]
struct Contribution {
    g1: usize,
    g2: usize,
    col: usize,
    width: usize,
    slot: usize,
}

/// `Phi_q` over body blocks and the sparse Cholesky factorisation of `S = Phi_q W Phi_q^T`
/// for a positive diagonal `W` (module documentation). The pattern is analysed once in
/// [`BlockSchur::new`]; [`BlockSchur::factor`] refills and refactors it without allocating.
#[derive(Debug)]
pub struct BlockSchur {
    m: usize,
    rows: BlockRows,
    /// The rows' local gradients (the layout of `rows`).
    vals: Vec<f64>,
    contributions: Vec<Contribution>,
    chol: SparseCholesky,
}

impl BlockSchur {
    /// Analyses the pattern of `S` for `sys` (allocates; once).
    pub fn new(sys: &System) -> Result<Self, SolveError> {
        let m = sys.n_constraints();
        let rows = BlockRows::new(sys, |_| true)?;
        if rows.len() != m || (0..m).any(|r| rows.row(r) != r) {
            return Err(SolveError::Unsupported(format!(
                "the block layout of the {m} constraint rows does not keep them in order \
                 ({} laid out)",
                rows.len()
            )));
        }
        let (chol, pairs) = shared_pair_pattern(&rows, sys.dependency_budget())?;
        let contributions = pairs
            .into_iter()
            .map(|(s1, s2, slot)| Contribution {
                g1: s1.off,
                g2: s2.off,
                col: s1.col,
                width: s1.width,
                slot,
            })
            .collect();
        Ok(BlockSchur {
            m,
            vals: vec![0.0; rows.n_values()],
            rows,
            contributions,
            chol,
        })
    }

    /// Number of constraint equations `m`.
    pub fn n_constraints(&self) -> usize {
        self.m
    }

    /// Stored entries of the lower triangle of `S`.
    pub fn nnz(&self) -> usize {
        self.chol.nnz()
    }

    /// Evaluates `Phi_q(q)` at time `t` into the local rows.
    pub fn update(&mut self, sys: &System, q: &[f64], t: f64) {
        self.rows.gather(sys, q, None, t, &mut self.vals, None);
    }

    /// Assembles `S = Phi_q W Phi_q^T` (`w` the diagonal of `W`, length n) from the current
    /// rows and factors it. An error names the row (equation index) at the failing pivot.
    pub fn factor(&mut self, w: &[f64]) -> Result<(), FactorError> {
        self.chol.clear();
        let vals = self.chol.values_mut();
        for c in &self.contributions {
            let g1 = &self.vals[c.g1..c.g1 + c.width];
            let g2 = &self.vals[c.g2..c.g2 + c.width];
            let wb = &w[c.col..c.col + c.width];
            let mut acc = 0.0;
            for l in 0..c.width {
                acc += g1[l] * wb[l] * g2[l];
            }
            vals[c.slot] += acc;
        }
        self.chol.factor()
    }

    /// The rows (equations) the last factorisation dropped as dependent on earlier ones
    /// (empty for a model without redundant equations).
    pub fn dependent(&self) -> &[usize] {
        self.chol.dependent()
    }

    /// Solves `S x = b` in place with the last factorisation.
    pub fn solve_in_place(&mut self, b: &mut [f64]) {
        if self.m > 0 {
            self.chol.solve_in_place(b);
        }
    }

    /// `out[r] = (Phi_q x)_r` for every row `r`.
    pub fn apply(&self, x: &[f64], out: &mut [f64]) {
        for (e, o) in out.iter_mut().enumerate().take(self.m) {
            *o = self.rows.dot(&self.vals, e, x);
        }
    }

    /// `out += alpha W Phi_q^T y` (`w` the diagonal of `W`).
    pub fn add_weighted_transpose(&self, alpha: f64, w: &[f64], y: &[f64], out: &mut [f64]) {
        for (sides, &ye) in self.rows.sides().iter().zip(y) {
            let s = alpha * ye;
            if s == 0.0 {
                continue;
            }
            for side in sides.iter().flatten() {
                let g = &self.vals[side.off..side.off + side.width];
                let cols = side.col..side.col + side.width;
                for ((o, wk), gl) in out[cols.clone()].iter_mut().zip(&w[cols]).zip(g) {
                    *o += wk * gl * s;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{DMatrix, DVector};

    /// Every operation against the dense matrices on a chain of spatial rods (internal and
    /// joint rows): `Phi_q x`, `W Phi_q^T y` and `S^-1 b`.
    #[test]
    fn block_schur_matches_the_dense_matrices() {
        let sys = mbd_model::models::spatial_chain(4).unwrap();
        let (n, m) = (sys.n_coords(), sys.n_constraints());
        let q = sys.initial_guess().0;
        let q = q.as_slice();
        let mut bs = BlockSchur::new(&sys).unwrap();
        bs.update(&sys, q, 0.0);
        let w: Vec<f64> = (0..n).map(|k| 0.5 + 0.1 * (k % 7) as f64).collect();
        bs.factor(&w).unwrap();
        let mut g = DMatrix::zeros(m, n);
        sys.phi_q(q, 0.0, &mut g);
        let x = DVector::from_fn(n, |k, _| (k as f64 * 0.37).sin());
        let y = DVector::from_fn(m, |k, _| (k as f64 * 0.61).cos());
        let mut gx = vec![0.0; m];
        bs.apply(x.as_slice(), &mut gx);
        let gx_ref = &g * &x;
        let mut wgy = vec![1.0; n];
        bs.add_weighted_transpose(2.0, &w, y.as_slice(), &mut wgy);
        let wgy_ref = g.transpose() * &y;
        let wd = DMatrix::from_diagonal(&DVector::from_column_slice(&w));
        let s = &g * &wd * g.transpose();
        let mut sol = y.as_slice().to_vec();
        bs.solve_in_place(&mut sol);
        let sol_ref = s.lu().solve(&y).unwrap();
        let scale = gx_ref.amax().max(1.0);
        for r in 0..m {
            assert!((gx[r] - gx_ref[r]).abs() <= 1e-14 * scale, "row {r}");
            let d = (sol[r] - sol_ref[r]).abs();
            assert!(d <= 1e-9 * sol_ref.amax(), "S^-1 row {r}: {d:e}");
        }
        for k in 0..n {
            let want = 1.0 + 2.0 * w[k] * wgy_ref[k];
            assert!(
                (wgy[k] - want).abs() <= 1e-14 * want.abs().max(1.0),
                "coordinate {k}"
            );
        }
    }
}
