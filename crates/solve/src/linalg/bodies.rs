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
use mbd_model::spatial::{RigidSolve, SpatialInertiaError};
use mbd_model::System;
use nalgebra::DMatrix;

/// The workspace of the body-eliminated solve (see the module documentation).
///
/// `Phi_q` is dense, but each of its rows acts on a few body blocks (at most two for a joint), and
/// `C` is block-diagonal: the products below visit only the blocks a row acts on, in the
/// order of their columns, so they add the same nonzero terms in the same order as the dense
/// products they replace (and give the same bits) at the cost of the blocks alone.
#[derive(Debug)]
pub(crate) struct BodySchur {
    n: usize,
    /// The whole `Phi_q` (m x n), filled by the caller.
    pub(crate) phi_q: DMatrix<f64>,
    /// The external rows (all but the spatial internal constraints).
    rows: Vec<usize>,
    /// Each external row's blocks as (first column, width, block), in column order.
    row_blocks: Vec<Vec<(usize, usize, usize)>>,
    /// Per body block, the external rows acting on it (ascending).
    block_rows: Vec<Vec<usize>>,
    /// Every body block's first column and width, by block.
    blocks: Vec<(usize, usize)>,
    /// The internal constraints' rows `r0..r0 + 6 ns`, the spatial bodies' coordinates
    /// `q0..qp` and the point masses' `qp..n`, and the first spatial body's block.
    r0: usize,
    q0: usize,
    qp: usize,
    spatial_block: usize,
    /// Each spatial body's elimination at the last factorisation.
    rigid: Vec<RigidSolve>,
    /// `Phi_e^T` and `C Phi_e^T` (`n x me`, column-major: column `e` is external row `e`
    /// contiguous, and `C` applied to it; both zero outside the row's blocks).
    pe: Vec<f64>,
    c_rows: Vec<f64>,
    /// The factorisation of `S`.
    pub(crate) chol: DenseCholesky,
    x: Vec<f64>,
    /// The external multipliers.
    le: Vec<f64>,
}

impl BodySchur {
    /// The workspace for `sys` (allocates; once).
    pub(crate) fn new(sys: &System) -> Self {
        let (m, n) = (sys.n_constraints(), sys.n_coords());
        let internal = sys.spatial_internal_rows();
        let rows: Vec<usize> = (0..m).filter(|r| !internal.contains(r)).collect();
        // each row's blocks from its element-local form; a row whose blocks could not be
        // matched to the model's (which a validated model does not have) acts on all of them
        let blocks: Vec<(usize, usize)> = (0..sys.n_body_blocks())
            .map(|b| sys.body_block(b).unwrap_or((0, 0)))
            .collect();
        let all: Vec<(usize, usize, usize)> = blocks
            .iter()
            .enumerate()
            .map(|(b, &(c, w))| (c, w, b))
            .collect();
        let mut of_row: Vec<Option<Vec<(usize, usize, usize)>>> = vec![None; m];
        let q = sys.initial_guess().0;
        sys.local_rows_gamma(q.as_slice(), None, 0.0, |r, sides, _| {
            let blocks: Option<Vec<_>> = sides
                .iter()
                .flatten()
                .map(|&(b, g)| {
                    sys.body_block(b)
                        .filter(|&(_, w)| w == g.len())
                        .map(|(c, w)| (c, w, b))
                })
                .collect();
            if let Some(slot) = of_row.get_mut(r) {
                *slot = blocks;
            }
        });
        let row_blocks: Vec<Vec<(usize, usize, usize)>> = rows
            .iter()
            .map(|&r| {
                let mut b = of_row[r].take().unwrap_or_else(|| all.clone());
                b.sort_unstable();
                b.dedup();
                b
            })
            .collect();
        let mut block_rows = vec![Vec::new(); sys.n_body_blocks()];
        for (e, blocks) in row_blocks.iter().enumerate() {
            for &(_, _, b) in blocks {
                block_rows[b].push(e);
            }
        }
        let mut chol = DenseCholesky::new(rows.len());
        chol.set_max_dependent(sys.dependency_budget());
        let q0 = sys.spatial_offset();
        BodySchur {
            n,
            phi_q: DMatrix::zeros(m, n),
            pe: vec![0.0; n * rows.len()],
            c_rows: vec![0.0; n * rows.len()],
            le: vec![0.0; rows.len()],
            rows,
            row_blocks,
            block_rows,
            blocks,
            r0: internal.start,
            q0,
            qp: sys.spatial_point_mass_offset(),
            // planar bodies' blocks (3 coordinates each) come first
            spatial_block: q0 / 3,
            rigid: Vec::with_capacity(sys.spatial_bodies().len()),
            chol,
            x: vec![0.0; n],
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
            let r = RigidSolve::new(&b.inertia, &qb).map_err(|e| match e {
                SpatialInertiaError::DependentDirectors => {
                    BodyFactorError::Directors(b.name.clone())
                }
                e => BodyFactorError::Body(b.name.clone(), e.to_string()),
            })?;
            self.rigid.push(r);
        }
        let (n, me) = (self.n, self.rows.len());
        // Phi_e^T and C Phi_e^T on each row's blocks (C is block-diagonal; the rest of each
        // column stays 0)
        for (e, blocks) in self.row_blocks.iter().enumerate() {
            let re = self.rows[e];
            let (pe, ce) = (
                &mut self.pe[e * n..(e + 1) * n],
                &mut self.c_rows[e * n..(e + 1) * n],
            );
            for &(col, width, _) in blocks {
                for k in col..col + width {
                    pe[k] = self.phi_q[(re, k)];
                }
                if (self.q0..self.qp).contains(&col) {
                    let fb: [f64; 12] = std::array::from_fn(|l| pe[col + l]);
                    let cb = self.rigid[(col - self.q0) / 12].apply_inverse_mass(&fb);
                    ce[col..col + 12].copy_from_slice(&cb);
                } else {
                    for k in col..col + width {
                        ce[k] = w[k] * pe[k];
                    }
                }
            }
        }
        // S = Phi_e C Phi_e^T: rows i and j meet only on the blocks both act on, visited in
        // column order (the order of the dense product's nonzero terms)
        let s = self.chol.values_mut();
        s[..me * me].fill(0.0);
        for (b, rows) in self.block_rows.iter().enumerate() {
            let (col, width) = self.blocks[b];
            for &j in rows {
                let cj = &self.c_rows[j * n + col..j * n + col + width];
                for &i in rows {
                    let pi = &self.pe[i * n + col..i * n + col + width];
                    let mut acc = s[i + j * me];
                    for (p, c) in pi.iter().zip(cj) {
                        acc += p * c;
                    }
                    s[i + j * me] = acc;
                }
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
        let n = self.n;
        for (e, le) in le.iter_mut().enumerate() {
            let mut acc = -r[self.rows[e]];
            let pe = &self.pe[e * n..(e + 1) * n];
            for &(col, width, _) in &self.row_blocks[e] {
                for (p, xk) in pe[col..col + width].iter().zip(&x[col..col + width]) {
                    acc += p * xk;
                }
            }
            *le = acc;
        }
        self.chol.solve_in_place(&mut le);
        lambda.fill(0.0);
        for (e, &l) in le.iter().enumerate() {
            lambda[self.rows[e]] = l;
        }
        // a = x - C Phi_e^T lambda_e: on each block, the rows acting on it
        a[..self.n].copy_from_slice(&x[..self.n]);
        for (b, rows) in self.block_rows.iter().enumerate() {
            let (col, width) = self.blocks[b];
            for (k, ak) in a.iter_mut().enumerate().skip(col).take(width) {
                let mut acc = *ak;
                for &e in rows {
                    acc -= self.c_rows[k + e * n] * le[e];
                }
                *ak = acc;
            }
        }
        // each body's internal multipliers from its own rows: G^T mu = f - Phi_e^T lambda_e - M a
        for (b, rigid) in self.rigid.iter().enumerate() {
            let o = self.q0 + 12 * b;
            let mut g: [f64; 12] = std::array::from_fn(|l| f[o + l]);
            for &e in &self.block_rows[self.spatial_block + b] {
                let (pe, l) = (&self.pe[e * n + o..e * n + o + 12], le[e]);
                for (gk, p) in g.iter_mut().zip(pe) {
                    *gk -= p * l;
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
    /// A spatial body's directors are (nearly) dependent (its name): coordinates far off the
    /// constraints.
    Directors(String),
    /// `S` is singular at this row of `Phi`.
    Row(usize),
}
