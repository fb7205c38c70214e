//! The body-eliminated constrained solve of [`crate::linalg::BodySchur`] on the sparse path:
//! bodies of any kind (planar, 3 coordinates; spatial, 12 with six internal constraints;
//! spatial point masses, 3) as blocks, constraint rows in element-local form (each acts on at most two blocks), and
//! `S = Phi_e C Phi_e^T` over the external rows (all but the spatial internal constraints)
//! assembled on its sparse pattern and factored by the sparse Cholesky kernel.
//!
//! `C` is block diagonal: a planar or point-mass block is its diagonal weight (`M^-1`, `I/m`
//! for a point mass), a spatial block the
//! body's constrained inverse mass (`mbd_model::spatial::RigidSolve`), applied to each row's
//! gradient on the block once per factorisation (`C_b g`, kept for the products with `S` and
//! the solve). `S` couples two rows only when they share a block, so for
//! a chain it is block tridiagonal and every operation is `O(N)`. The solve is that of the
//! dense module: `x = C f + d(r_int)`, `S lambda_e = Phi_e x - r_e`, `a = x - C Phi_e^T
//! lambda_e`, and each spatial body's internal multipliers from its own rows.

use super::{BlockRows, SparseCholesky};
use crate::error::SolveError;
use crate::linalg::{BodyFactorError, FactorError};
use mbd_model::spatial::{RigidSolve, SpatialInertiaError};
use mbd_model::System;

/// One contribution to `S`: a side of external row `e1` and one of `e2` share a block
/// (offsets of the first's gradient and the second's `C_b g`).
#[derive(Clone, Copy, Debug)]
struct Contribution {
    g1: usize,
    c2: usize,
    width: usize,
    slot: usize,
}

/// The sparse body-eliminated solve (see the module documentation).
#[derive(Debug)]
pub(crate) struct SparseBodySchur {
    n: usize,
    m: usize,
    /// The external rows (every row but the spatial internal constraints) over body blocks.
    rows: BlockRows,
    /// The external rows' local gradients (the layout of `rows`).
    grads: Vec<f64>,
    /// `C_b g` for each side's gradient, in the same layout.
    cg: Vec<f64>,
    contributions: Vec<Contribution>,
    /// The planar blocks and the first spatial coordinate and internal row.
    planar: usize,
    q0: usize,
    r0: usize,
    /// The first block and the first coordinate of the spatial point masses (diagonal weights,
    /// like the planar blocks).
    point_block: usize,
    qp: usize,
    /// The spatial coordinates at the last [`SparseBodySchur::update`].
    qs: Vec<f64>,
    /// Each spatial body's elimination at the last factorisation.
    rigid: Vec<RigidSolve>,
    chol: SparseCholesky,
    x: Vec<f64>,
    le: Vec<f64>,
}

impl SparseBodySchur {
    /// Analyses the pattern of `S` for `sys` (allocates; once).
    pub(crate) fn new(sys: &System) -> Result<Self, SolveError> {
        let (n, m) = (sys.n_coords(), sys.n_constraints());
        let internal = sys.spatial_internal_rows();
        let nblocks = sys.n_body_blocks();
        let rows = BlockRows::new(sys, |r| !internal.contains(&r))?;
        let me = rows.len();
        let (chol, pairs) =
            super::block_schur::shared_pair_pattern(&rows, sys.dependency_budget())?;
        let contributions = pairs
            .into_iter()
            .map(|(s1, s2, slot)| Contribution {
                g1: s1.off,
                c2: s2.off,
                width: s1.width,
                slot,
            })
            .collect();
        let ns = sys.spatial_bodies().len();
        Ok(SparseBodySchur {
            n,
            m,
            grads: vec![0.0; rows.n_values()],
            cg: vec![0.0; rows.n_values()],
            rows,
            contributions,
            planar: nblocks - ns - sys.spatial_point_masses().len(),
            point_block: nblocks - sys.spatial_point_masses().len(),
            qp: sys.spatial_point_mass_offset(),
            q0: sys.spatial_offset(),
            r0: internal.start,
            qs: vec![0.0; 12 * ns],
            rigid: Vec::with_capacity(ns),
            chol,
            x: vec![0.0; n],
            le: vec![0.0; me],
        })
    }

    /// Evaluates the rows at `(q, v, t)` (`v = None`: zero velocities): the local gradients, and
    /// `gamma` (length m) for every row.
    pub(crate) fn update(
        &mut self,
        sys: &System,
        q: &[f64],
        v: Option<&[f64]>,
        t: f64,
        gamma: &mut [f64],
    ) {
        self.qs.copy_from_slice(&q[self.q0..self.qp]);
        self.rows.gather(sys, q, v, t, &mut self.grads, Some(gamma));
    }

    /// `out = C_b f` on block `b` (`w` the planar and point-mass weights).
    fn apply_block(&self, b: usize, col: usize, w: &[f64], f: &[f64], out: &mut [f64]) {
        if b < self.planar || b >= self.point_block {
            for l in 0..3 {
                out[l] = w[col + l] * f[l];
            }
        } else {
            let fb: [f64; 12] = std::array::from_fn(|l| f[l]);
            out[..12].copy_from_slice(&self.rigid[b - self.planar].apply_inverse_mass(&fb));
        }
    }

    /// Each spatial body's elimination at the last [`SparseBodySchur::update`], `C_b` times
    /// each row's gradient, and the factorisation of `S`. Errors: a degenerate spatial body
    /// (named) or the row of the failing pivot.
    pub(crate) fn factor(&mut self, sys: &System, w: &[f64]) -> Result<(), BodyFactorError> {
        self.rigid.clear();
        for (k, b) in sys.spatial_bodies().iter().enumerate() {
            let qb: [f64; 12] = std::array::from_fn(|l| self.qs[12 * k + l]);
            let r = RigidSolve::new(&b.inertia, &qb).map_err(|e| match e {
                SpatialInertiaError::DependentDirectors => {
                    BodyFactorError::Directors(b.name.clone())
                }
                e => BodyFactorError::Body(b.name.clone(), e.to_string()),
            })?;
            self.rigid.push(r);
        }
        let mut cg = std::mem::take(&mut self.cg);
        for s in self.rows.sides().iter().flatten().flatten() {
            let range = s.off..s.off + s.width;
            self.apply_block(
                s.block,
                s.col,
                w,
                &self.grads[range.clone()],
                &mut cg[range],
            );
        }
        self.cg = cg;
        self.chol.clear();
        let vals = self.chol.values_mut();
        for c in &self.contributions {
            let g = &self.grads[c.g1..c.g1 + c.width];
            let cg = &self.cg[c.c2..c.c2 + c.width];
            vals[c.slot] += g.iter().zip(cg).map(|(a, b)| a * b).sum::<f64>();
        }
        self.chol.factor().map_err(|e| {
            let i = match e {
                FactorError::Singular(i) | FactorError::NotPositiveDefinite(i) => i,
            };
            BodyFactorError::Row(if i < self.rows.len() {
                self.rows.row(i)
            } else {
                i
            })
        })
    }

    /// Non-zeros stored for the lower triangle of `S`.
    pub(crate) fn nnz(&self) -> usize {
        self.chol.nnz()
    }

    /// The condition estimate of the last factored `S` (1 without external rows).
    pub(crate) fn condition_estimate(&self) -> f64 {
        if self.rows.is_empty() {
            1.0
        } else {
            self.chol.condition_estimate()
        }
    }

    /// How many rows the last factorisation dropped as dependent on earlier ones.
    pub(crate) fn dropped(&self) -> usize {
        self.chol.dependent().len()
    }

    /// The model rows (equations) the last factorisation dropped as dependent on earlier
    /// ones, appended to `out` (none for a model without redundant equations).
    pub(crate) fn dependent_rows(&self, out: &mut Vec<usize>) {
        out.extend(self.chol.dependent().iter().map(|&e| self.rows.row(e)));
    }

    /// The solution `a` of `M a + Phi^T lambda = f`, `Phi a = r` at the last factorisation,
    /// with its multipliers `lambda` (length m).
    pub(crate) fn solve(
        &mut self,
        w: &[f64],
        f: &[f64],
        r: &[f64],
        a: &mut [f64],
        lambda: &mut [f64],
    ) {
        debug_assert!(a.len() == self.n && lambda.len() == self.m);
        let mut x = std::mem::take(&mut self.x);
        for k in (0..self.q0).chain(self.qp..self.n) {
            x[k] = w[k] * f[k];
        }
        for (b, rigid) in self.rigid.iter().enumerate() {
            let o = self.q0 + 12 * b;
            let fb: [f64; 12] = std::array::from_fn(|l| f[o + l]);
            let ri: [f64; 6] = std::array::from_fn(|l| r[self.r0 + 6 * b + l]);
            x[o..o + 12].copy_from_slice(&rigid.solve(&fb, &ri));
        }
        // S lambda_e = Phi_e x - r_e
        let mut le = std::mem::take(&mut self.le);
        for (e, l) in le.iter_mut().enumerate() {
            *l = self.rows.dot(&self.grads, e, &x) - r[self.rows.row(e)];
        }
        if !le.is_empty() {
            self.chol.solve_in_place(&mut le);
        }
        a.copy_from_slice(&x);
        lambda.fill(0.0);
        for (e, &l) in le.iter().enumerate() {
            lambda[self.rows.row(e)] = l;
            self.rows.add_scaled(&self.cg, e, -l, a);
        }
        // each spatial body's internal multipliers: G^T mu = f - Phi_e^T lambda_e - M a
        for (k, rigid) in self.rigid.iter().enumerate() {
            let o = self.q0 + 12 * k;
            let mut g: [f64; 12] = std::array::from_fn(|l| f[o + l]);
            for &(e, side) in &self.rows.by_block()[self.planar + k] {
                if let Some(s) = self.rows.sides()[e][side] {
                    for (gl, d) in g.iter_mut().zip(&self.grads[s.off..s.off + 12]) {
                        *gl -= d * le[e];
                    }
                }
            }
            let ab: [f64; 12] = std::array::from_fn(|l| a[o + l]);
            let mu = rigid.multipliers(&g, &ab);
            lambda[self.r0 + 6 * k..self.r0 + 6 * k + 6].copy_from_slice(&mu);
        }
        self.x = x;
        self.le = le;
    }
}
