//! The projected metric at one configuration, shared by every preadjustment term.
//!
//! With `g = grad V`, `G = Phi_q`, `S = G M^-1 G^T` and the symmetric `M^-1`-projector
//! `Pi = M^-1 - M^-1 G^T S^-1 G M^-1`:
//!
//! * the rest multipliers `mu0 = S^-1 G M^-1 g` (so the tangential force is
//!   `f_T = -g + G^T mu0`),
//! * its velocity-like image `u = M^-1 f_T = -Pi g`,
//! * the operators `x -> Pi x`, `x -> S^-1 x`, `x -> G x`, `x -> M^-1 G^T x`,
//!   `x -> S^-1 G M^-1 x` and the matrix-free `x -> A x` with the tangential stiffness
//!   `A = Hess V - mu0 . Hess Phi`.
//!
//! `S` is factored densely ([`DenseCholesky`], `G` an `m x n` matrix) or, on the sparse layout,
//! held in element-local rows and factored sparsely ([`ConstraintSchur`] for planar models,
//! [`BlockSchur`] over body blocks with spatial bodies, whose `M^-1` is then the regularised
//! diagonal of [`super::augmented::regularised_inverse`]). The evaluation is kept
//! while the point does not change bit for bit: the control point `q_1` of one step is `q_0` of
//! the next, and the Newton Jacobian is evaluated where the residual was. Every evaluation at a
//! new point gets a new [`Stamp`], by which the terms tell whether what they keep is still of
//! this point.

use super::augmented::Augmented;
use super::{dot, LocalRow, ZERO_ROW};
use crate::passes;
use mbd_model::System;
use mbd_solve::linalg::{DenseCholesky, FactorError};
use mbd_solve::sparse::{BlockSchur, ConstraintSchur};
use mbd_solve::SolveError;
use nalgebra::DMatrix;

/// Which evaluation of the metric a term's kept results belong to (0: none).
pub(super) type Stamp = u64;

/// The shared quantities of the preadjustment terms at one point `q` (module doc); allocated
/// once, evaluated in place.
#[derive(Debug)]
pub(crate) struct ProjectedMetric {
    n: usize,
    m: usize,
    mass: Vec<f64>,
    /// The diagonal of `M^-1` (with spatial bodies: that of the augmented `M_W^-1`, a finite
    /// stand-in on massless coordinates, for bounds and the sparse layout only).
    minv: Vec<f64>,
    /// With spatial bodies (dense layout): the augmented `M_W^-1`, used wherever `M^-1` acts
    /// (module `augmented`).
    aug: Option<Box<Augmented>>,
    rheonomic: bool,
    /// Whether `Phi_q` depends on time (a spatial angle driver), and the time the evaluations
    /// take (0 on every other model, whose `Phi_q`, constraint Hessians and `gamma_c` do not
    /// depend on it).
    time_jacobian: bool,
    t: f64,
    /// Whether the element-local rows along a velocity come from one fused pass with `Phi_q`
    /// (planar scleronomic models; the pass takes planar joints only).
    fused: bool,
    /// `grad V`.
    g: Vec<f64>,
    /// Dense layout: `Phi_q` (`m x n`) and the Cholesky factor of `S` (empty on the sparse
    /// layout).
    gq: DMatrix<f64>,
    chol: DenseCholesky,
    /// Sparse layout: `Phi_q` in element-local rows and the sparse factor of `S`.
    schur: Option<Box<SparseS>>,
    mu0: Vec<f64>,
    /// `-mu0`: the constraint weights of `A`.
    nmu0: Vec<f64>,
    u: Vec<f64>,
    /// The point of the last successful evaluation, and its stamp.
    at: Vec<f64>,
    at_valid: bool,
    stamp: Stamp,
    /// Scratch: the nonzero rows of a column of `Phi_q`; `Phi_q` in element-local rows from a
    /// fused pass; an m-vector for `Pi`; an n-vector for `S^-1 G M^-1`.
    nz_rows: Vec<usize>,
    local_grads: Vec<LocalRow>,
    tmp_m: Vec<f64>,
    tmp_n: Vec<f64>,
}

/// The constraint rows along a velocity `v` from the fused pass of
/// [`ProjectedMetric::prepare_along`] (one third-order pass over the joints instead of three):
/// per row `Hess Phi_r v` and `D^3 Phi_r(v, v, .)` in element-local form and
/// `v^T Hess Phi_r v`. Owned by the term that asks for them.
#[derive(Debug)]
pub(super) struct RowsAlong {
    /// The velocity and the metric's stamp they were computed at (0: not valid).
    pub(super) v: Vec<f64>,
    pub(super) stamp: Stamp,
    pub(super) hess_v: Vec<LocalRow>,
    pub(super) third_vv: Vec<LocalRow>,
    pub(super) vhv: Vec<f64>,
}

impl RowsAlong {
    pub(super) fn new(n: usize, m: usize) -> Self {
        RowsAlong {
            v: vec![0.0; n],
            stamp: 0,
            hess_v: vec![ZERO_ROW; m],
            third_vv: vec![ZERO_ROW; m],
            vhv: vec![0.0; m],
        }
    }
}

impl ProjectedMetric {
    /// The workspace for `sys`; `sparse` holds `S` sparse ([`ConstraintSchur`]), without any
    /// `n x n` or `m x n` matrix.
    pub(super) fn new(sys: &System, sparse: bool) -> Result<Self, SolveError> {
        let (n, m) = (sys.n_coords(), sys.n_constraints());
        let schur = match (sparse, sys.has_spatial()) {
            (false, _) => None,
            (true, false) => Some(Box::new(SparseS::Planar(ConstraintSchur::new(sys)?))),
            (true, true) => Some(Box::new(SparseS::Blocks(BlockSchur::new(sys)?))),
        };
        let mut minv = sys.inv_mass_diag().as_slice().to_vec();
        if sparse {
            // (the augmented M_W^-1 has 9 x 9 blocks; the sparse layout weights S by a
            // diagonal, the regularised M^-1 that the s = 2 term takes on either layout)
            super::augmented::regularised_inverse(sys, &mut minv);
        }
        let (nd, md) = if sparse { (0, 0) } else { (n, m) };
        let mut chol = DenseCholesky::new(md);
        chol.set_max_dependent(sys.dependency_budget());
        Ok(ProjectedMetric {
            n,
            m,
            mass: sys.mass_diag().as_slice().to_vec(),
            minv,
            aug: if sparse {
                None
            } else {
                Augmented::new(sys).map(Box::new)
            },
            rheonomic: sys.is_rheonomic(),
            time_jacobian: sys.jacobian_depends_on_time(),
            t: 0.0,
            fused: !sys.is_rheonomic() && !sys.has_spatial(),
            g: vec![0.0; n],
            gq: DMatrix::zeros(md, nd),
            chol,
            schur,
            mu0: vec![0.0; m],
            nmu0: vec![0.0; m],
            u: vec![0.0; n],
            at: vec![0.0; n],
            at_valid: false,
            stamp: 0,
            nz_rows: Vec::with_capacity(m),
            local_grads: vec![ZERO_ROW; m],
            tmp_m: vec![0.0; m],
            tmp_n: vec![0.0; n],
        })
    }

    /// The number of coordinates `n`.
    pub(super) fn n(&self) -> usize {
        self.n
    }

    /// The number of constraints `m`.
    pub(super) fn m(&self) -> usize {
        self.m
    }

    /// The diagonal of `M`.
    pub(super) fn mass(&self) -> &[f64] {
        &self.mass
    }

    /// The diagonal of `M^-1`.
    pub(super) fn minv(&self) -> &[f64] {
        &self.minv
    }

    /// Whether the constraints depend on time.
    pub(super) fn rheonomic(&self) -> bool {
        self.rheonomic
    }

    /// Whether `Phi_q` depends on time (a spatial angle driver): the evaluations then take the
    /// time of [`ProjectedMetric::set_time`].
    pub(super) fn time_jacobian(&self) -> bool {
        self.time_jacobian
    }

    /// The time the evaluations take: the last [`ProjectedMetric::set_time`] on a model whose
    /// `Phi_q` depends on time, 0 on every other.
    pub(super) fn t(&self) -> f64 {
        self.t
    }

    /// Sets the time of the next evaluations on a model whose `Phi_q` depends on time (a new
    /// time makes the prepared point stale); nothing on every other model, whose evaluations do
    /// not depend on it (they keep t = 0, bit for bit as before).
    pub(super) fn set_time(&mut self, t: f64) {
        if self.time_jacobian && t.to_bits() != self.t.to_bits() {
            self.t = t;
            self.at_valid = false;
        }
    }

    /// `grad V` at the prepared point.
    pub(super) fn grad_v(&self) -> &[f64] {
        &self.g
    }

    /// `Phi_q` at the prepared point (dense layout only).
    pub(super) fn gq(&self) -> &DMatrix<f64> {
        &self.gq
    }

    /// The Cholesky factor of `S` at the prepared point (dense layout only).
    pub(super) fn chol(&self) -> &DenseCholesky {
        &self.chol
    }

    /// `mu0 = S^-1 G M^-1 grad V`.
    pub(super) fn mu0(&self) -> &[f64] {
        &self.mu0
    }

    /// `-mu0`.
    pub(super) fn neg_mu0(&self) -> &[f64] {
        &self.nmu0
    }

    /// `u = M^-1 f_T = -Pi grad V`.
    pub(super) fn u(&self) -> &[f64] {
        &self.u
    }

    /// The stamp of the current evaluation (changes with every evaluation at a new point).
    pub(super) fn stamp(&self) -> Stamp {
        self.stamp
    }

    /// Whether `S` is held sparse.
    pub(super) fn is_sparse(&self) -> bool {
        self.schur.is_some()
    }

    /// [`SolveError::Unsupported`] on the sparse layout, for the methods that need the dense
    /// matrices (`what` names the method).
    pub(super) fn require_dense(&self, what: &str) -> Result<(), SolveError> {
        if self.schur.is_some() {
            return Err(SolveError::Unsupported(format!(
                "{what} needs the dense layout (Preadjustment::new); this workspace holds S \
                 sparse (Preadjustment::new_sparse, or with_layout with sparse = true)"
            )));
        }
        Ok(())
    }

    /// [`SolveError::Dimension`] unless `v` has length `n`.
    pub(super) fn check_v(&self, v: &[f64]) -> Result<(), SolveError> {
        if v.len() != self.n {
            return Err(SolveError::Dimension {
                what: "v for the modified-Lagrangian term",
                expected: self.n,
                got: v.len(),
            });
        }
        Ok(())
    }

    /// `(G^T x)_k`, the dot product of column `k` of `G` with `x` (dense layout).
    pub(super) fn g_col_dot(&self, k: usize, x: &[f64]) -> f64 {
        let m = self.m;
        dot(&self.gq.as_slice()[k * m..(k + 1) * m], x)
    }

    /// `x <- S^-1 x` with the last factorisation of `S`.
    pub(super) fn s_solve(&mut self, x: &mut [f64]) {
        match &mut self.schur {
            Some(sc) => sc.solve_in_place(x),
            None => self.chol.solve_in_place(x),
        }
    }

    /// `out = S^-1 x`.
    pub(super) fn s_inv_into(&mut self, x: &[f64], out: &mut [f64]) {
        out.copy_from_slice(x);
        self.s_solve(out);
    }

    /// `out = G x`.
    pub(super) fn g_times(&self, x: &[f64], out: &mut [f64]) {
        match &self.schur {
            Some(sc) => sc.apply(x, out),
            None => gm_times(&self.gq, x, out),
        }
    }

    /// `out += c M^-1 G^T x` (x of length m).
    #[inline]
    pub(super) fn add_dgt_to(&self, x: &[f64], c: f64, out: &mut [f64]) {
        match (&self.schur, &self.aug) {
            (Some(sc), _) => sc.add_weighted_transpose(c, &self.minv, x, out),
            (None, Some(aug)) => {
                if self.m > 0 {
                    aug.add_apply(c, |k| self.g_col_dot(k, x), out);
                }
            }
            (None, None) => add_dgt(&self.gq, &self.minv, x, c, out),
        }
    }

    /// `out = M^-1 x` (`M_W^-1 x` with spatial bodies).
    pub(super) fn minv_mul(&self, x: &[f64], out: &mut [f64]) {
        match &self.aug {
            Some(aug) => aug.apply(x, out),
            None => {
                for ((o, xi), mi) in out.iter_mut().zip(x).zip(&self.minv) {
                    *o = mi * xi;
                }
            }
        }
    }

    /// Takes a constant diagonal inverse mass instead of the augmented `M_W^-1` (the s = 2
    /// term's reverse pass is derived with one): `M^-1`, regularised on massless directors
    /// ([`super::augmented::regularised_inverse`]). Nothing on a model without spatial bodies.
    pub(super) fn use_plain_inverse(&mut self, sys: &System) {
        if self.aug.is_some() {
            self.aug = None;
            super::augmented::regularised_inverse(sys, &mut self.minv);
            self.at_valid = false;
        }
    }

    /// Whether `M^-1` is the augmented `M_W^-1` (spatial bodies, dense layout).
    pub(super) fn is_augmented(&self) -> bool {
        self.aug.is_some()
    }

    /// The entry `(i, j)` of `M^-1` (of `M_W^-1` with spatial bodies).
    pub(super) fn minv_entry(&self, i: usize, j: usize) -> f64 {
        match &self.aug {
            Some(aug) => aug.entry(i, j),
            None if i == j => self.minv[i],
            None => 0.0,
        }
    }

    /// The coordinates `j` with `M^-1_kj` possibly nonzero (a spatial body's directors share
    /// a block of `M_W^-1`).
    pub(super) fn minv_partners(&self, k: usize) -> std::ops::Range<usize> {
        match &self.aug {
            Some(aug) => aug.partners(k),
            None => k..k + 1,
        }
    }

    /// The multipliers of `M` from `S^-1 c` of a solve whose constraint part is `c` (the
    /// augmented metric's correction; nothing without spatial bodies), in place.
    pub(super) fn correct_multipliers(&self, c: &[f64], mult: &mut [f64]) {
        if let Some(aug) = &self.aug {
            aug.correct(c, mult);
        }
    }

    /// What `c^T S^-1 c` computed with the augmented metric exceeds that of `M` by (0 without
    /// spatial bodies).
    pub(super) fn penalty(&self, c: &[f64]) -> f64 {
        self.aug.as_ref().map_or(0.0, |aug| aug.penalty(c))
    }

    /// `f(row, w)` for the rows and weights of [`ProjectedMetric::penalty`] (nothing without
    /// spatial bodies): `penalty(c) = sum w c_row^2`.
    pub(super) fn for_each_penalty_row(&self, f: impl FnMut(usize, f64)) {
        if let Some(aug) = &self.aug {
            aug.for_each_penalty_row(f);
        }
    }

    /// `out = M^-1 G^T x` (x of length m).
    pub(super) fn dgt_into(&self, x: &[f64], out: &mut [f64]) {
        out.fill(0.0);
        self.add_dgt_to(x, 1.0, out);
    }

    /// `out = -M^-1 G^T S^-1 x`; `s` receives `S^-1 x`.
    pub(super) fn neg_e_into(&mut self, x: &[f64], s: &mut [f64], out: &mut [f64]) {
        s.copy_from_slice(x);
        self.s_solve(s);
        self.dgt_into(s, out);
        out.iter_mut().for_each(|o| *o = -*o);
    }

    /// `out = Pi x`.
    pub(super) fn apply_pi(&mut self, x: &[f64], out: &mut [f64]) {
        let (n, m) = (self.n, self.m);
        if self.aug.is_some() {
            self.minv_mul(x, out);
        } else {
            for i in 0..n {
                out[i] = self.minv[i] * x[i];
            }
        }
        if m == 0 {
            return;
        }
        let mut t = std::mem::take(&mut self.tmp_m);
        self.g_times(out, &mut t);
        self.s_solve(&mut t);
        self.add_dgt_to(&t, -1.0, out);
        self.tmp_m = t;
    }

    /// `out = S^-1 G M^-1 x` (length m).
    pub(super) fn sgm(&mut self, x: &[f64], out: &mut [f64]) {
        let n = self.n;
        let mut t = std::mem::take(&mut self.tmp_n);
        if self.aug.is_some() {
            self.minv_mul(x, &mut t);
        } else {
            for k in 0..n {
                t[k] = self.minv[k] * x[k];
            }
        }
        self.g_times(&t, out);
        self.s_solve(out);
        self.tmp_n = t;
    }

    /// `pi = Pi x` (bit for bit [`ProjectedMetric::apply_pi`]) and `sg = S^-1 G M^-1 x`
    /// ([`ProjectedMetric::sgm`], the solve inside `Pi x`), by one solve.
    pub(super) fn pi_sgm(&mut self, x: &[f64], pi: &mut [f64], sg: &mut [f64]) {
        if self.aug.is_some() {
            self.minv_mul(x, pi);
        } else {
            for ((p, xi), mi) in pi.iter_mut().zip(x).zip(&self.minv) {
                *p = mi * xi;
            }
        }
        if self.m == 0 {
            return;
        }
        self.sgm(x, sg);
        self.add_dgt_to(sg, -1.0, pi);
    }

    /// `out = A x` without assembling `A` (one Hessian-vector pass), after `prepare(q)`.
    pub(super) fn a_times(&self, sys: &System, q: &[f64], x: &[f64], out: &mut [f64]) {
        passes::lagrangian_hessian_vector(sys, q, self.t, x, 1.0, &self.nmu0, out);
    }

    /// Whether the workspace holds the evaluation at exactly `q` (bit for bit).
    fn is_prepared_at(&self, q: &[f64]) -> bool {
        self.at_valid && self.at.as_slice() == q
    }

    /// Evaluates `grad V`, `G`, the factor of `S`, `mu0` and `u` at `q` (nothing when they are
    /// held for `q`).
    pub(super) fn prepare(&mut self, sys: &System, q: &[f64]) -> Result<(), SolveError> {
        self.prepare_with(sys, q, None)
    }

    /// [`ProjectedMetric::prepare`]; on a scleronomic model, when `q` is new, the constraint
    /// pass is one third-order pass along `v` that also fills `rows` (and stamps them).
    pub(super) fn prepare_along(
        &mut self,
        sys: &System,
        q: &[f64],
        v: &[f64],
        rows: &mut RowsAlong,
    ) -> Result<(), SolveError> {
        self.prepare_with(sys, q, Some((v, rows)))
    }

    fn prepare_with(
        &mut self,
        sys: &System,
        q: &[f64],
        along: Option<(&[f64], &mut RowsAlong)>,
    ) -> Result<(), SolveError> {
        let (n, m) = (self.n, self.m);
        if q.len() != n {
            return Err(SolveError::Dimension {
                what: "q for W_s",
                expected: n,
                got: q.len(),
            });
        }
        if self.is_prepared_at(q) {
            return Ok(());
        }
        self.at_valid = false;
        self.stamp += 1;
        if let Some(aug) = &mut self.aug {
            aug.update(q)?;
            aug.diagonal(&mut self.minv);
        }
        sys.potential_gradient(q, &mut self.g);
        if m > 0 {
            match along {
                Some((v, rows)) if self.fused => {
                    passes::constraint_third_local(
                        sys,
                        q,
                        v,
                        &mut self.local_grads,
                        &mut rows.hess_v,
                        &mut rows.third_vv,
                        &mut rows.vhv,
                    );
                    match self.schur.as_deref_mut() {
                        Some(SparseS::Planar(sc)) => {
                            sc.grads_mut().copy_from_slice(&self.local_grads)
                        }
                        // (the fused pass takes planar models only)
                        Some(sc @ SparseS::Blocks(_)) => sc.update(sys, q, self.t),
                        None => sys.local_rows_dense(&self.local_grads, &mut self.gq),
                    }
                    rows.v.copy_from_slice(v);
                    rows.stamp = self.stamp;
                }
                _ => match &mut self.schur {
                    Some(sc) => sc.update(sys, q, self.t),
                    None => sys.phi_q(q, self.t, &mut self.gq),
                },
            }
            let singular = || SolveError::Singular {
                t: f64::NAN,
                what: "Phi_q M^-1 Phi_q^T in W_s",
                detail: "redundant constraints or a singular configuration".into(),
            };
            if let Some(sc) = &mut self.schur {
                sc.factor(&self.minv).map_err(|_| singular())?;
            } else {
                let gq = &self.gq;
                let minv = &self.minv;
                let rows = &mut self.nz_rows;
                let chol = &mut self.chol;
                chol.clear();
                // S = sum_k minv_k G_:k G_:k^T over the few nonzero rows of each column (with
                // spatial bodies: their directors' columns by blocks of M_W^-1, below)
                let aug = self.aug.as_deref();
                for (k, col) in gq.as_slice().chunks_exact(m).enumerate() {
                    if aug.is_some_and(|a| a.in_block(k)) {
                        continue;
                    }
                    rows.clear();
                    rows.extend((0..m).filter(|&r| col[r] != 0.0));
                    for (i, &c) in rows.iter().enumerate() {
                        let gc = minv[k] * col[c];
                        for &r in &rows[i..] {
                            // rows ascending: r >= c, the lower triangle
                            chol.add(r, c, col[r] * gc);
                        }
                    }
                }
                if let Some(aug) = aug {
                    aug.add_to_schur(gq, rows, chol);
                }
                self.chol.factor_in_place().map_err(|_| singular())?;
            }
            let g = std::mem::take(&mut self.g);
            let mut mu0 = std::mem::take(&mut self.mu0);
            self.sgm(&g, &mut mu0);
            self.g = g;
            self.mu0 = mu0;
        }
        if self.schur.is_some() {
            // u = M^-1 (G^T mu0 - g)
            for k in 0..n {
                self.u[k] = -self.minv[k] * self.g[k];
            }
            let mut u = std::mem::take(&mut self.u);
            self.add_dgt_to(&self.mu0, 1.0, &mut u);
            self.u = u;
        } else if let Some(aug) = &self.aug {
            // u = M_W^-1 (G^T mu0 - g)
            let mut t = std::mem::take(&mut self.tmp_n);
            for (k, tk) in t.iter_mut().enumerate() {
                let acc = if m > 0 {
                    self.g_col_dot(k, &self.mu0)
                } else {
                    0.0
                };
                *tk = acc - self.g[k];
            }
            aug.apply(&t, &mut self.u);
            self.tmp_n = t;
        } else {
            for k in 0..n {
                let acc = if m > 0 {
                    self.g_col_dot(k, &self.mu0)
                } else {
                    0.0
                };
                self.u[k] = self.minv[k] * (acc - self.g[k]);
            }
        }
        for r in 0..m {
            self.nmu0[r] = -self.mu0[r];
        }
        self.at.copy_from_slice(q);
        self.at_valid = true;
        Ok(())
    }
}

/// `out = G x` for the column-major `m x n` matrix `G`, by columns (zero entries of `x`
/// skipped).
fn gm_times(g: &DMatrix<f64>, x: &[f64], out: &mut [f64]) {
    let m = g.nrows();
    out.fill(0.0);
    if m == 0 {
        return;
    }
    for (col, &xk) in g.as_slice().chunks_exact(m).zip(x) {
        if xk != 0.0 {
            for (o, &gr) in out.iter_mut().zip(col) {
                *o += gr * xk;
            }
        }
    }
}

/// `out += c M^-1 G^T x` for the column-major `m x n` matrix `G` (x of length m).
fn add_dgt(g: &DMatrix<f64>, minv: &[f64], x: &[f64], c: f64, out: &mut [f64]) {
    let m = g.nrows();
    if m == 0 {
        return;
    }
    for ((o, col), mi) in out.iter_mut().zip(g.as_slice().chunks_exact(m)).zip(minv) {
        *o += c * mi * dot(col, x);
    }
}

/// `S` held sparse (the sparse layout): planar models in the six-number rows that the fused
/// pass fills, models with spatial bodies over body blocks.
#[derive(Debug)]
enum SparseS {
    Planar(ConstraintSchur),
    Blocks(BlockSchur),
}

impl SparseS {
    /// Evaluates `Phi_q(q, t)` (a planar `Phi_q` does not depend on `t`).
    fn update(&mut self, sys: &System, q: &[f64], t: f64) {
        match self {
            SparseS::Planar(s) => s.update(sys, q),
            SparseS::Blocks(s) => s.update(sys, q, t),
        }
    }

    /// Assembles and factors `S = Phi_q W Phi_q^T` for the diagonal `w`.
    fn factor(&mut self, w: &[f64]) -> Result<(), FactorError> {
        match self {
            SparseS::Planar(s) => s.factor(w),
            SparseS::Blocks(s) => s.factor(w),
        }
    }

    /// `b <- S^-1 b`.
    fn solve_in_place(&mut self, b: &mut [f64]) {
        match self {
            SparseS::Planar(s) => s.solve_in_place(b),
            SparseS::Blocks(s) => s.solve_in_place(b),
        }
    }

    /// `out = Phi_q x`.
    fn apply(&self, x: &[f64], out: &mut [f64]) {
        match self {
            SparseS::Planar(s) => s.apply(x, out),
            SparseS::Blocks(s) => s.apply(x, out),
        }
    }

    /// `out += alpha W Phi_q^T y`.
    fn add_weighted_transpose(&self, alpha: f64, w: &[f64], y: &[f64], out: &mut [f64]) {
        match self {
            SparseS::Planar(s) => s.add_weighted_transpose(alpha, w, y, out),
            SparseS::Blocks(s) => s.add_weighted_transpose(alpha, w, y, out),
        }
    }
}
