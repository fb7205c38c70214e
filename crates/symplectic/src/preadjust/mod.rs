//! The preadjustment potential `W_s(q)` of paper A and its gradient.
//!
//! With `g = grad V`, `G = Phi_q`, `S = G M^-1 G^T` and the symmetric `M^-1`-projector
//! `Pi = M^-1 - M^-1 G^T S^-1 G M^-1` (so `Pi = M^-1 P` with `P = I - G^T S^-1 G M^-1`):
//!
//! * tangential force `f_T = P (-g)`, its velocity-like image `u = M^-1 f_T = -Pi g`,
//! * rest multipliers `mu0 = S^-1 G M^-1 g` (so `f_T = -g + G^T mu0`),
//! * tangential stiffness `K_T = -d f_T / dq = P A + G^T S^-1 B` with the symmetric
//!   `A = Hess V - sum_k mu0_k Hess Phi_k`, so `P K_T = P A`,
//! * `W_1 = 1/2 f_T^T M^-1 f_T = 1/2 u^T M u`,
//!   `W_s = 1/2 f_T^T M^-1 (P K_T M^-1)^(s-1) f_T = 1/2 u^T A (Pi A)^(s-2) u` for `s >= 2`.
//!
//! For `s = 1, 2` this is exactly paper A's `W_s`; for `s >= 3` the projector `P`
//! between the factors keeps the modal form `W_s = 1/2 sum_i omega_i^(2s+2) eta_i^2` about an
//! equilibrium (without it the normal components of `K_T` would enter). The gradient is exact:
//! the third derivatives of `V` and `Phi` it needs for `s >= 2` come from
//! [`System::potential_third`] and [`System::constraint_third`]. The Newton Jacobian uses `A (Pi A)^s`, the exact Hessian of `W_s`
//! at an equilibrium (`f_T = 0`).

use mbd_model::System;
use mbd_solve::linalg::DenseCholesky;
use mbd_solve::sparse::ConstraintSchur;
use mbd_solve::SolveError;
use nalgebra::DMatrix;

mod e4_work;
mod modified;
mod modified2;
mod modified2_grad;
mod paper;

/// Workspace evaluating `W_s`, its gradient and an approximate Hessian (allocation-free after
/// [`Preadjustment::new`]).
#[derive(Debug)]
pub struct Preadjustment {
    s: usize,
    n: usize,
    m: usize,
    mass: Vec<f64>,
    minv: Vec<f64>,
    /// Relative step of the finite-difference checks of the derivatives (tests); the
    /// derivatives used by the integrator are exact.
    pub(crate) fd_step: f64,
    g: Vec<f64>,
    gq: DMatrix<f64>,
    chol: DenseCholesky,
    mu0: Vec<f64>,
    u: Vec<f64>,
    amat: DMatrix<f64>,
    av: Vec<Vec<f64>>,
    bv: Vec<Vec<f64>>,
    sig: Vec<Vec<f64>>,
    tn: [Vec<f64>; 4],
    tm: [Vec<f64>; 3],
    zero: Vec<f64>,
    gc: Vec<f64>,
    gc0: Vec<f64>,
    sigma: Vec<f64>,
    cm: Vec<f64>,
    /// The point of the last successful `prepare` (its results are reused when `q` repeats
    /// bit for bit: the control point `q_1` of one step is `q_0` of the next, and the Newton
    /// Jacobian is evaluated where the residual was).
    at: Vec<f64>,
    at_valid: bool,
    /// Whether `amat` holds `A` at `at`.
    a_valid: bool,
    nmu0: Vec<f64>,
    hv: Vec<f64>,
    d3: Vec<f64>,
    rheonomic: bool,
    /// The velocity of the last `modified_prepared` at `at` (valid while `mv_valid`): its
    /// results (`sigma`, `cm`, `hv`, `d3`) are reused by the Newton Jacobian, which is
    /// evaluated where the residual was.
    mv: Vec<f64>,
    mv_valid: bool,
    /// The coordinates where `A` has a nonzero column, and `k x k` blocks on them (column-major,
    /// `n x n` capacity) for the Newton Hessian of `W_s`.
    kset: Vec<usize>,
    /// Scratch `m x n` matrices: `Phi_q` (discarded) and `(Phi_q v)_q` (rows `v^T Hess Phi_k`)
    /// for the modified Jacobian.
    gscr: DMatrix<f64>,
    ct: DMatrix<f64>,
    /// Scratch: the nonzero rows of a column of `Phi_q`.
    rows: Vec<usize>,
    /// Element-local constraint rows along the velocity `rv` from one third-order pass
    /// (`System::constraint_third_local`; valid at `at` while `rv_valid`): `Phi_q`,
    /// `Hess Phi_r v`, `D^3 Phi_r(v, v, .)`; `gc` then holds `v^T Hess Phi_r v`.
    rg: Vec<[f64; 6]>,
    rhv: Vec<[f64; 6]>,
    rd3: Vec<[f64; 6]>,
    rv: Vec<f64>,
    rv_valid: bool,
    kpi: Vec<f64>,
    ka: Vec<f64>,
    kx: Vec<f64>,
    ky: Vec<f64>,
    /// The workspace of the s = 2 modified-Lagrangian term (allocated on first use).
    e4: Option<Box<e4_work::E4Work>>,
    /// The sparse layout ([`Preadjustment::new_sparse`]): `Phi_q` in element-local rows and
    /// the sparse Cholesky factorisation of `S` instead of `gq` and `chol` (which, with the
    /// other `n x n` and `m x n` matrices, are then empty).
    schur: Option<Box<ConstraintSchur>>,
}

#[cfg(test)]
pub(crate) fn matvec(a: &DMatrix<f64>, x: &[f64], out: &mut [f64]) {
    let n = a.nrows();
    out.iter_mut().for_each(|o| *o = 0.0);
    for (j, &xj) in x.iter().enumerate() {
        if xj == 0.0 {
            continue;
        }
        let col = &a.as_slice()[j * n..(j + 1) * n];
        for i in 0..n {
            out[i] += col[i] * xj;
        }
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

pub(crate) fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

impl Preadjustment {
    /// A workspace for `W_s` on `sys`.
    pub fn new(sys: &System, s: usize) -> Result<Self, SolveError> {
        Self::with_layout(sys, s, false)
    }

    /// A workspace for the modified Lagrangian alone ([`Preadjustment::modified_term`],
    /// [`Preadjustment::modified_gradients`] for `s = 1`, [`Preadjustment::modified_term_s2`],
    /// [`Preadjustment::modified_gradients_s2`] for `s = 2`) with `S = Phi_q M^-1 Phi_q^T`
    /// held sparse ([`ConstraintSchur`]): `O(N)` storage and work per evaluation on a chain of
    /// `N` bodies (the symplectic scheme's sparse stage solve). The `W_s` methods and the dense
    /// Hessians need the dense matrices and return [`SolveError::Unsupported`] on it.
    pub fn new_sparse(sys: &System) -> Result<Self, SolveError> {
        // (the degree is that of W_s, which the modified Lagrangian does not use)
        Self::with_layout(sys, 1, true)
    }

    fn with_layout(sys: &System, s: usize, sparse: bool) -> Result<Self, SolveError> {
        if s == 0 {
            return Err(SolveError::InvalidParameter {
                parameter: "s",
                value: 0.0,
                reason: "W_s needs s >= 1",
            });
        }
        let (n, m) = (sys.n_coords(), sys.n_constraints());
        let schur = if sparse {
            Some(Box::new(ConstraintSchur::new(sys)?))
        } else {
            None
        };
        // (the dense matrices: empty on the sparse layout)
        let (nd, md) = if sparse { (0, 0) } else { (n, m) };
        Ok(Preadjustment {
            s,
            n,
            m,
            mass: sys.mass_diag().as_slice().to_vec(),
            minv: sys.inv_mass_diag().as_slice().to_vec(),
            fd_step: 2e-3,
            g: vec![0.0; n],
            gq: DMatrix::zeros(md, nd),
            chol: DenseCholesky::new(md),
            mu0: vec![0.0; m],
            u: vec![0.0; n],
            amat: DMatrix::zeros(nd, nd),
            av: vec![vec![0.0; n]; s + 1],
            bv: vec![vec![0.0; n]; s + 1],
            sig: vec![vec![0.0; m]; s.max(1)],
            tn: std::array::from_fn(|_| vec![0.0; n]),
            tm: std::array::from_fn(|_| vec![0.0; m]),
            zero: vec![0.0; n],
            gc: vec![0.0; m],
            gc0: vec![0.0; m],
            sigma: vec![0.0; m],
            cm: vec![0.0; m],
            at: vec![0.0; n],
            at_valid: false,
            a_valid: false,
            nmu0: vec![0.0; m],
            hv: vec![0.0; n],
            d3: vec![0.0; n],
            rheonomic: sys.is_rheonomic(),
            mv: vec![0.0; n],
            mv_valid: false,
            kset: Vec::with_capacity(n),
            gscr: DMatrix::zeros(md, nd),
            ct: DMatrix::zeros(md, nd),
            rows: Vec::with_capacity(m),
            rg: vec![[0.0; 6]; m],
            rhv: vec![[0.0; 6]; m],
            rd3: vec![[0.0; 6]; m],
            rv: vec![0.0; n],
            rv_valid: false,
            kpi: vec![0.0; nd * nd],
            ka: vec![0.0; nd * nd],
            kx: vec![0.0; nd * nd],
            ky: vec![0.0; nd * nd.max(md)],
            e4: None,
            schur,
        })
    }

    /// [`SolveError::Unsupported`] on the sparse layout, for the methods that need the dense
    /// matrices (`what` names the method).
    pub(crate) fn require_dense(&self, what: &str) -> Result<(), SolveError> {
        if self.schur.is_some() {
            return Err(SolveError::Unsupported(format!(
                "{what} needs the dense layout (Preadjustment::new); this workspace was built by \
                 Preadjustment::new_sparse for the modified Lagrangian"
            )));
        }
        Ok(())
    }

    /// `x <- S^-1 x` with the last factorisation of `S`.
    pub(crate) fn s_solve(&mut self, x: &mut [f64]) {
        match &mut self.schur {
            Some(sc) => sc.solve_in_place(x),
            None => self.chol.solve_in_place(x),
        }
    }

    /// `out = G x` (`G = Phi_q` at the prepared point).
    pub(crate) fn g_times(&self, x: &[f64], out: &mut [f64]) {
        match &self.schur {
            Some(sc) => sc.apply(x, out),
            None => gm_times(&self.gq, x, out),
        }
    }

    /// `out += c M^-1 G^T x` (x of length m).
    pub(crate) fn add_dgt_to(&self, x: &[f64], c: f64, out: &mut [f64]) {
        match &self.schur {
            Some(sc) => sc.add_weighted_transpose(c, &self.minv, x, out),
            None => add_dgt(&self.gq, &self.minv, x, c, out),
        }
    }

    /// The degree `s`.
    pub fn s(&self) -> usize {
        self.s
    }

    /// `x -> Pi x` (`Pi = M^-1 P`); uses `tm[0]`.
    pub(crate) fn apply_pi(&mut self, x: &[f64], out: &mut [f64]) {
        let (n, m) = (self.n, self.m);
        for i in 0..n {
            out[i] = self.minv[i] * x[i];
        }
        if m == 0 {
            return;
        }
        let mut t = std::mem::take(&mut self.tm[0]);
        self.g_times(out, &mut t);
        self.s_solve(&mut t);
        self.add_dgt_to(&t, -1.0, out);
        self.tm[0] = t;
    }

    /// `out = S^-1 G M^-1 x` (length m).
    pub(crate) fn sgm(&mut self, x: &[f64], out: &mut [f64]) {
        let n = self.n;
        let mut t = std::mem::take(&mut self.tn[3]);
        for k in 0..n {
            t[k] = self.minv[k] * x[k];
        }
        self.g_times(&t, out);
        self.s_solve(out);
        self.tn[3] = t;
    }

    /// Whether the workspace holds the evaluation at exactly `q` (bit for bit).
    pub(crate) fn is_prepared_at(&self, q: &[f64]) -> bool {
        self.at_valid && self.at.as_slice() == q
    }

    /// Evaluates `g`, `G`, the Cholesky factor of `S`, `mu0` and `u` at `q` (nothing when they
    /// are held for `q`). `A` is assembled only on demand ([`Preadjustment::ensure_a`]): the
    /// gradients use Hessian-vector products instead.
    fn prepare(&mut self, sys: &System, q: &[f64]) -> Result<(), SolveError> {
        self.prepare_with(sys, q, None)
    }

    /// [`Preadjustment::prepare`]; with `Some(v)` (scleronomic models) the constraint pass is
    /// one third-order pass along `v` (`System::constraint_third_local`) that also leaves
    /// `v^T Hess Phi_k v` in `gc` and the local rows `Hess Phi_k v`, `D^3 Phi_k(v, v, .)` for
    /// `modified_prepared` (one pass instead of three).
    fn prepare_with(
        &mut self,
        sys: &System,
        q: &[f64],
        v: Option<&[f64]>,
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
        self.a_valid = false;
        self.mv_valid = false;
        self.rv_valid = false;
        sys.potential_gradient(q, &mut self.g);
        if m > 0 {
            match v {
                Some(v) if !self.rheonomic => {
                    sys.constraint_third_local(
                        q,
                        v,
                        &mut self.rg,
                        &mut self.rhv,
                        &mut self.rd3,
                        &mut self.gc,
                    );
                    match &mut self.schur {
                        Some(sc) => sc.grads_mut().copy_from_slice(&self.rg),
                        None => sys.local_rows_dense(&self.rg, &mut self.gq),
                    }
                    self.rv.copy_from_slice(v);
                    self.rv_valid = true;
                }
                _ => match &mut self.schur {
                    Some(sc) => sc.update(sys, q),
                    None => sys.phi_q(q, &mut self.gq),
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
                let rows = &mut self.rows;
                let chol = &mut self.chol;
                chol.clear();
                // S = sum_k minv_k G_:k G_:k^T over the few nonzero rows of each column
                for (k, col) in gq.as_slice().chunks_exact(m).enumerate() {
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
        } else {
            for k in 0..n {
                let acc = if m > 0 {
                    dot(&self.gq.as_slice()[k * m..(k + 1) * m], &self.mu0)
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

    /// Assembles `A = Hess V - mu0 . Hess Phi` after `prepare(q)` (once per point).
    fn ensure_a(&mut self, sys: &System, q: &[f64]) {
        if self.a_valid {
            return;
        }
        sys.potential_hessian(q, &mut self.amat);
        if self.m > 0 {
            sys.add_constraint_hessian(q, &self.mu0, -1.0, &mut self.amat);
        }
        self.a_valid = true;
    }

    /// `out = A x` without assembling `A` (one Hessian-vector pass), after `prepare(q)`.
    fn a_times(&self, sys: &System, q: &[f64], x: &[f64], out: &mut [f64]) {
        sys.lagrangian_hessian_vector(q, x, 1.0, &self.nmu0, out);
    }

    /// Krylov vectors `a_0 = u`, `a_{i+1} = Pi b_i` with `b_i = A a_i`, for `i < count`
    /// (`b_i` in `bv[i]`).
    pub(crate) fn krylov(&mut self, sys: &System, q: &[f64], count: usize) {
        self.av[0].copy_from_slice(&self.u);
        for i in 0..count {
            let mut b = std::mem::take(&mut self.bv[i]);
            self.a_times(sys, q, &self.av[i], &mut b);
            let mut next = std::mem::take(&mut self.av[i + 1]);
            self.apply_pi(&b, &mut next);
            self.av[i + 1] = next;
            self.bv[i] = b;
        }
    }

    /// The tangential force `f_T(q) = P(q) (-grad V(q))` into `out`.
    pub fn tangential_force(
        &mut self,
        sys: &System,
        q: &[f64],
        out: &mut [f64],
    ) -> Result<(), SolveError> {
        self.prepare(sys, q)?;
        for k in 0..self.n {
            out[k] = self.mass[k] * self.u[k];
        }
        Ok(())
    }
}
