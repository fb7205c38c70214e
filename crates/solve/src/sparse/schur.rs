//! The constraint Jacobian in element-local form and the weighted Schur complement
//! `S = Phi_q W Phi_q^T` on its sparse pattern.

use super::SparseCholesky;
use crate::error::SolveError;
use crate::linalg::FactorError;
use mbd_model::System;

/// One contribution to an entry of `S`: rows `r1 >= r2` both act on `body`; `o1`, `o2` are the
/// offsets (0 or 3) of that body in the rows' local gradients; `idx` is the value slot.
#[derive(Clone, Copy, Debug)]
struct Contribution {
    r1: usize,
    r2: usize,
    o1: usize,
    o2: usize,
    body: usize,
    idx: usize,
}

/// Which bodies each constraint equation acts on: the incidence every sparse pattern of the
/// workspace is built from (`S`, the tangent chart's `Df Df^T`, the symplectic stage system).
#[derive(Clone, Debug)]
pub struct RowIncidence {
    /// Per equation: its joint's `(first, second)` body (coordinate block), `None` = ground.
    pub row_bodies: Vec<(Option<usize>, Option<usize>)>,
    /// Per body: the equations acting on it, with the body's offset (0 or 3) in the equation's
    /// element-local gradient ([`mbd_model::System::phi_q_local`]).
    pub by_body: Vec<Vec<(usize, usize)>>,
}

impl RowIncidence {
    /// The incidence of `sys` (allocates; once per pattern).
    pub fn new(sys: &System) -> Self {
        let mut row_bodies = vec![(None, None); sys.n_constraints()];
        for j in sys.joint_handles() {
            let jb = sys.joint_bodies(j);
            for r in sys.joint_rows(j) {
                row_bodies[r] = jb;
            }
        }
        let mut by_body: Vec<Vec<(usize, usize)>> = vec![Vec::new(); sys.n_coords() / 3];
        for (r, &(a, b)) in row_bodies.iter().enumerate() {
            if let Some(a) = a {
                by_body[a].push((r, 0));
            }
            if let Some(b) = b {
                by_body[b].push((r, 3));
            }
        }
        RowIncidence {
            row_bodies,
            by_body,
        }
    }
}

/// `Phi_q` stored row by row in element-local form (each equation acts on at most two bodies:
/// six numbers per row) and the sparse Cholesky factorisation of `S = Phi_q W Phi_q^T` for a
/// positive diagonal weight `W` (`M^-1` for the index-1 solve and the projections).
///
/// `S` couples two equations only when they act on a common body, so for a chain it is block
/// tridiagonal; its pattern is analysed once in [`ConstraintSchur::new`], and
/// [`ConstraintSchur::factor`] refills and refactors it without allocating. Every product with
/// `Phi_q` or `Phi_q^T` costs `O(m)`.
#[derive(Debug)]
pub struct ConstraintSchur {
    n: usize,
    m: usize,
    row_bodies: Vec<(Option<usize>, Option<usize>)>,
    grads: Vec<[f64; 6]>,
    contributions: Vec<Contribution>,
    chol: SparseCholesky,
}

impl ConstraintSchur {
    /// Analyses the pattern of `S` for `sys` (allocates; done once).
    pub fn new(sys: &System) -> Result<Self, SolveError> {
        let (n, m) = (sys.n_coords(), sys.n_constraints());
        let RowIncidence {
            row_bodies,
            by_body,
        } = RowIncidence::new(sys);
        let mut pattern = Vec::new();
        for rows in &by_body {
            for &(r1, _) in rows {
                for &(r2, _) in rows {
                    if r1 > r2 {
                        pattern.push((r1, r2));
                    }
                }
            }
        }
        let mut chol = SparseCholesky::new(m, &pattern)?;
        // a mechanism with redundant equations: each factorisation drops that many dependent
        // rows (their multipliers zero), and no more
        chol.set_max_dependent(sys.dependency_budget());
        let mut contributions = Vec::new();
        for (body, rows) in by_body.iter().enumerate() {
            for &(r1, o1) in rows {
                for &(r2, o2) in rows {
                    if r1 >= r2 {
                        let idx = chol.slot(r1, r2).ok_or_else(|| {
                            SolveError::Unsupported(format!(
                                "sparse Schur pattern lacks entry ({r1}, {r2})"
                            ))
                        })?;
                        contributions.push(Contribution {
                            r1,
                            r2,
                            o1,
                            o2,
                            body,
                            idx,
                        });
                    }
                }
            }
        }
        Ok(ConstraintSchur {
            n,
            m,
            row_bodies,
            grads: vec![[0.0; 6]; m],
            contributions,
            chol,
        })
    }

    /// Number of coordinates `n`.
    pub fn n_coords(&self) -> usize {
        self.n
    }

    /// Number of constraint equations `m`.
    pub fn n_constraints(&self) -> usize {
        self.m
    }

    /// Stored entries of the lower triangle of `S`.
    pub fn nnz(&self) -> usize {
        self.chol.nnz()
    }

    /// The element-local rows of `Phi_q` (see [`System::phi_q_local`]).
    pub fn grads(&self) -> &[[f64; 6]] {
        &self.grads
    }

    /// Mutable element-local rows of `Phi_q`, to be filled by [`System::phi_q_local`] or
    /// [`System::phi_q_local_gamma`].
    pub fn grads_mut(&mut self) -> &mut [[f64; 6]] {
        &mut self.grads
    }

    /// Evaluates `Phi_q(q)` into the local rows.
    pub fn update(&mut self, sys: &System, q: &[f64]) {
        sys.phi_q_local(q, &mut self.grads);
    }

    /// The bodies (coordinate blocks) of each row: `(first, second)`, `None` = ground.
    pub fn row_bodies(&self) -> &[(Option<usize>, Option<usize>)] {
        &self.row_bodies
    }

    /// Assembles `S = Phi_q W Phi_q^T` (`w` the diagonal of `W`, length n) from the current
    /// rows and factors it. An error names the row (equation index) at the failing pivot.
    pub fn factor(&mut self, w: &[f64]) -> Result<(), FactorError> {
        self.chol.clear();
        let vals = self.chol.values_mut();
        for c in &self.contributions {
            let (g1, g2) = (&self.grads[c.r1], &self.grads[c.r2]);
            let wb = &w[3 * c.body..3 * c.body + 3];
            let mut acc = 0.0;
            for l in 0..3 {
                acc += g1[c.o1 + l] * wb[l] * g2[c.o2 + l];
            }
            vals[c.idx] += acc;
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
        self.chol.solve_in_place(b);
    }

    /// Condition estimate of the last factored `S` (see [`SparseCholesky::condition_estimate`]).
    pub fn condition_estimate(&self) -> f64 {
        if self.m == 0 {
            1.0
        } else {
            self.chol.condition_estimate()
        }
    }

    /// `out[r] = (Phi_q x)_r` for every row `r`.
    pub fn apply(&self, x: &[f64], out: &mut [f64]) {
        for ((o, g), &(ba, bb)) in out.iter_mut().zip(&self.grads).zip(&self.row_bodies) {
            let mut acc = 0.0;
            if let Some(b) = ba {
                for l in 0..3 {
                    acc += g[l] * x[3 * b + l];
                }
            }
            if let Some(b) = bb {
                for l in 0..3 {
                    acc += g[3 + l] * x[3 * b + l];
                }
            }
            *o = acc;
        }
    }

    /// `out += alpha W Phi_q^T y` (`w` the diagonal of `W`).
    pub fn add_weighted_transpose(&self, alpha: f64, w: &[f64], y: &[f64], out: &mut [f64]) {
        for ((g, &(ba, bb)), &yr) in self.grads.iter().zip(&self.row_bodies).zip(y) {
            let s = alpha * yr;
            if let Some(b) = ba {
                for l in 0..3 {
                    out[3 * b + l] += w[3 * b + l] * g[l] * s;
                }
            }
            if let Some(b) = bb {
                for l in 0..3 {
                    out[3 * b + l] += w[3 * b + l] * g[3 + l] * s;
                }
            }
        }
    }
}
