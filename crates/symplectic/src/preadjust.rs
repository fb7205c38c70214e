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
//! For `s = 1, 2` this is exactly the `W_s` of methods.md 2.2; for `s >= 3` the projector `P`
//! between the factors keeps the modal form `W_s = 1/2 sum_i omega_i^(2s+2) eta_i^2` about an
//! equilibrium (without it the normal components of `K_T` would enter). The gradient is exact
//! except for the third derivatives of `V` and `Phi` (needed for `s >= 2`), which are central
//! differences of the exact Hessians along a few directions, Richardson-extrapolated
//! (error `O(fd_step^4)`). The Newton Jacobian uses `A (Pi A)^s`, the exact Hessian of `W_s`
//! at an equilibrium (`f_T = 0`).

use mbd_model::System;
use mbd_solve::linalg::DenseCholesky;
use mbd_solve::SolveError;
use nalgebra::DMatrix;

/// Workspace evaluating `W_s`, its gradient and an approximate Hessian (allocation-free after
/// [`Preadjustment::new`]).
#[derive(Debug)]
pub struct Preadjustment {
    s: usize,
    n: usize,
    m: usize,
    mass: Vec<f64>,
    minv: Vec<f64>,
    /// Relative central-difference step for the third derivatives.
    pub fd_step: f64,
    g: Vec<f64>,
    gq: DMatrix<f64>,
    chol: DenseCholesky,
    mu0: Vec<f64>,
    u: Vec<f64>,
    amat: DMatrix<f64>,
    hs: DMatrix<f64>,
    av: Vec<Vec<f64>>,
    bv: Vec<Vec<f64>>,
    sig: Vec<Vec<f64>>,
    tn: [Vec<f64>; 4],
    tm: [Vec<f64>; 3],
    qp: Vec<f64>,
    zero: Vec<f64>,
    gc: Vec<f64>,
    gc0: Vec<f64>,
    sigma: Vec<f64>,
    cm: Vec<f64>,
}

fn matvec(a: &DMatrix<f64>, x: &[f64], out: &mut [f64]) {
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

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

impl Preadjustment {
    /// A workspace for `W_s` on `sys`.
    pub fn new(sys: &System, s: usize) -> Result<Self, SolveError> {
        if s == 0 {
            return Err(SolveError::InvalidParameter {
                parameter: "s",
                value: 0.0,
                reason: "W_s needs s >= 1",
            });
        }
        let (n, m) = (sys.n_coords(), sys.n_constraints());
        Ok(Preadjustment {
            s,
            n,
            m,
            mass: sys.mass_diag().as_slice().to_vec(),
            minv: sys.inv_mass_diag().as_slice().to_vec(),
            fd_step: 2e-3,
            g: vec![0.0; n],
            gq: DMatrix::zeros(m, n),
            chol: DenseCholesky::new(m),
            mu0: vec![0.0; m],
            u: vec![0.0; n],
            amat: DMatrix::zeros(n, n),
            hs: DMatrix::zeros(n, n),
            av: vec![vec![0.0; n]; s + 1],
            bv: vec![vec![0.0; n]; s.max(1)],
            sig: vec![vec![0.0; m]; s.max(1)],
            tn: std::array::from_fn(|_| vec![0.0; n]),
            tm: std::array::from_fn(|_| vec![0.0; m]),
            qp: vec![0.0; n],
            zero: vec![0.0; n],
            gc: vec![0.0; m],
            gc0: vec![0.0; m],
            sigma: vec![0.0; m],
            cm: vec![0.0; m],
        })
    }

    /// The degree `s`.
    pub fn s(&self) -> usize {
        self.s
    }

    /// `x -> Pi x` (`Pi = M^-1 P`); uses `tm[0]`.
    fn apply_pi(&mut self, x: &[f64], out: &mut [f64]) {
        let (n, m) = (self.n, self.m);
        for i in 0..n {
            out[i] = self.minv[i] * x[i];
        }
        if m == 0 {
            return;
        }
        let t = &mut self.tm[0];
        for r in 0..m {
            t[r] = (0..n).map(|k| self.gq[(r, k)] * out[k]).sum();
        }
        self.chol.solve_in_place(t);
        for k in 0..n {
            let acc: f64 = (0..m).map(|r| self.gq[(r, k)] * t[r]).sum();
            out[k] -= self.minv[k] * acc;
        }
    }

    /// `out = S^-1 G M^-1 x` (length m).
    fn sgm(&mut self, x: &[f64], out: &mut [f64]) {
        let (n, m) = (self.n, self.m);
        for r in 0..m {
            out[r] = (0..n).map(|k| self.gq[(r, k)] * self.minv[k] * x[k]).sum();
        }
        self.chol.solve_in_place(out);
    }

    /// Evaluates `g`, `G`, `S`, `mu0`, `u` and `A` at `q`.
    fn prepare(&mut self, sys: &System, q: &[f64]) -> Result<(), SolveError> {
        let (n, m) = (self.n, self.m);
        if q.len() != n {
            return Err(SolveError::Dimension {
                what: "q for W_s",
                expected: n,
                got: q.len(),
            });
        }
        sys.potential_gradient(q, &mut self.g);
        if m > 0 {
            sys.phi_q(q, &mut self.gq);
            {
                let gq = &self.gq;
                let minv = &self.minv;
                let mut sm = self.chol.matrix_mut();
                for c in 0..m {
                    for r in c..m {
                        sm[(r, c)] = (0..n).map(|k| gq[(r, k)] * minv[k] * gq[(c, k)]).sum();
                    }
                }
            }
            self.chol
                .factor_in_place()
                .map_err(|_| SolveError::Singular {
                    t: f64::NAN,
                    what: "Phi_q M^-1 Phi_q^T in W_s",
                    detail: "redundant constraints or a singular configuration".into(),
                })?;
            let g = std::mem::take(&mut self.g);
            let mut mu0 = std::mem::take(&mut self.mu0);
            self.sgm(&g, &mut mu0);
            self.g = g;
            self.mu0 = mu0;
        }
        for k in 0..n {
            let acc: f64 = (0..m).map(|r| self.gq[(r, k)] * self.mu0[r]).sum();
            self.u[k] = self.minv[k] * (acc - self.g[k]);
        }
        sys.potential_hessian(q, &mut self.amat);
        if m > 0 {
            sys.add_constraint_hessian(q, &self.mu0, -1.0, &mut self.amat);
        }
        Ok(())
    }

    /// Krylov vectors `a_0 = u`, `a_{i+1} = Pi A a_i` for `i < count`.
    fn krylov(&mut self, count: usize) {
        self.av[0].copy_from_slice(&self.u);
        for i in 0..count {
            let mut t = std::mem::take(&mut self.tn[0]);
            matvec(&self.amat, &self.av[i], &mut t);
            let mut next = std::mem::take(&mut self.av[i + 1]);
            self.apply_pi(&t, &mut next);
            self.av[i + 1] = next;
            self.tn[0] = t;
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

    /// `W_s(q)`.
    pub fn value(&mut self, sys: &System, q: &[f64]) -> Result<f64, SolveError> {
        self.prepare(sys, q)?;
        Ok(self.value_prepared())
    }

    fn value_prepared(&mut self) -> f64 {
        let s = self.s;
        if s == 1 {
            return 0.5
                * (0..self.n)
                    .map(|k| self.mass[k] * self.u[k] * self.u[k])
                    .sum::<f64>();
        }
        self.krylov(s - 2);
        let mut t = std::mem::take(&mut self.tn[0]);
        matvec(&self.amat, &self.av[s - 2], &mut t);
        let w = 0.5 * dot(&self.u, &t);
        self.tn[0] = t;
        w
    }

    /// `grad W_s(q)` into `out`; returns `W_s(q)`.
    pub fn gradient(
        &mut self,
        sys: &System,
        q: &[f64],
        out: &mut [f64],
    ) -> Result<f64, SolveError> {
        self.prepare(sys, q)?;
        let (n, m, s) = (self.n, self.m, self.s);
        if s == 1 {
            // grad W_1 = -A u (exact: only second derivatives enter)
            matvec(&self.amat, &self.u, out);
            out.iter_mut().for_each(|x| *x = -*x);
            return Ok(self.value_prepared());
        }
        let l = s - 2;
        self.krylov(l + 1);
        // b_k = A a_k, sigma_k = S^-1 G M^-1 b_k (k = 0..=l)
        for k in 0..=l {
            let mut b = std::mem::take(&mut self.bv[k]);
            matvec(&self.amat, &self.av[k], &mut b);
            let mut sg = std::mem::take(&mut self.sig[k]);
            if m > 0 {
                self.sgm(&b, &mut sg);
            }
            self.bv[k] = b;
            self.sig[k] = sg;
        }
        let w = 0.5 * dot(&self.u, &self.bv[l]);
        // (1)+(3): -A a_{l+1} - sum_j (sigma_{l-j} . H) a_j
        matvec(&self.amat, &self.av[l + 1], out);
        out.iter_mut().for_each(|x| *x = -*x);
        if m > 0 {
            for j in 0..=l {
                sys.constraint_hessian(q, &self.sig[l - j], &mut self.hs);
                let mut t = std::mem::take(&mut self.tn[0]);
                matvec(&self.hs, &self.av[j], &mut t);
                for i in 0..n {
                    out[i] -= t[i];
                }
                self.tn[0] = t;
            }
            // (2b): h_k = 1/2 sum_i a_i^T H_k a_{l-i}; rho = S^-1 h;
            //        + (rho . H) a_0 - A M^-1 G^T rho
            let mut h = std::mem::take(&mut self.tm[1]);
            let mut g1 = std::mem::take(&mut self.tm[2]);
            h.iter_mut().for_each(|x| *x = 0.0);
            for i in 0..=l {
                let (ai, ac) = (&self.av[i], &self.av[l - i]);
                let vp = &mut self.tn[1];
                for k in 0..n {
                    vp[k] = ai[k] + ac[k];
                }
                sys.gamma(q, vp, 0.0, &mut g1);
                for r in 0..m {
                    h[r] -= 0.125 * g1[r];
                }
                for k in 0..n {
                    vp[k] = ai[k] - ac[k];
                }
                sys.gamma(q, vp, 0.0, &mut g1);
                for r in 0..m {
                    h[r] += 0.125 * g1[r];
                }
            }
            self.chol.solve_in_place(&mut h); // rho
            sys.constraint_hessian(q, &h, &mut self.hs);
            let mut t = std::mem::take(&mut self.tn[0]);
            matvec(&self.hs, &self.av[0], &mut t);
            for i in 0..n {
                out[i] += t[i];
            }
            let t2 = &mut self.tn[2];
            for k in 0..n {
                let acc: f64 = (0..m).map(|r| self.gq[(r, k)] * h[r]).sum();
                t2[k] = self.minv[k] * acc;
            }
            matvec(&self.amat, t2, &mut t);
            for i in 0..n {
                out[i] -= t[i];
            }
            self.tn[0] = t;
            self.tm[1] = h;
            self.tm[2] = g1;
        }
        // (2a): 1/2 sum_i (D_{a_i} A~) a_{l-i}, A~ = Hess V - mu0 . Hess Phi with mu0 frozen
        for i in 0..=l {
            let j = l - i;
            if i > j {
                break;
            }
            let factor = if i == j { 0.5 } else { 1.0 };
            self.third_derivative(sys, q, i, j, factor, out);
        }
        Ok(w)
    }

    /// `out += factor * (D_{a_i} A~) a_j` by Richardson-extrapolated central differences.
    fn third_derivative(
        &mut self,
        sys: &System,
        q: &[f64],
        i: usize,
        j: usize,
        factor: f64,
        out: &mut [f64],
    ) {
        let n = self.n;
        let norm = self.av[i].iter().fold(0.0f64, |a, &b| a.max(b.abs()));
        if norm == 0.0 {
            return;
        }
        let eps = self.fd_step;
        for (coef, shift) in [(8.0, 0.5), (-8.0, -0.5), (-1.0, 1.0), (1.0, -1.0)] {
            let qp = &mut self.tn[1];
            for k in 0..n {
                qp[k] = q[k] + shift * eps * self.av[i][k] / norm;
            }
            sys.potential_hessian(qp, &mut self.hs);
            if self.m > 0 {
                sys.add_constraint_hessian(qp, &self.mu0, -1.0, &mut self.hs);
            }
            let mut t = std::mem::take(&mut self.tn[0]);
            matvec(&self.hs, &self.av[j], &mut t);
            let c = factor * norm * coef / (6.0 * eps);
            for k in 0..n {
                out[k] += c * t[k];
            }
            self.tn[0] = t;
        }
    }

    /// An approximate Hessian of `W_s` for Newton: `A (Pi A)^s` (exact at an equilibrium),
    /// symmetrised, into `out` (overwritten).
    pub fn approximate_hessian(
        &mut self,
        sys: &System,
        q: &[f64],
        out: &mut DMatrix<f64>,
    ) -> Result<(), SolveError> {
        self.prepare(sys, q)?;
        let n = self.n;
        for c in 0..n {
            let mut x = std::mem::take(&mut self.tn[2]);
            for r in 0..n {
                x[r] = self.amat[(r, c)];
            }
            let mut y = std::mem::take(&mut self.tn[3]);
            for _ in 0..self.s {
                self.apply_pi(&x, &mut y);
                matvec(&self.amat, &y, &mut x);
            }
            for r in 0..n {
                out[(r, c)] = x[r];
            }
            self.tn[2] = x;
            self.tn[3] = y;
        }
        for c in 0..n {
            for r in c + 1..n {
                let v = 0.5 * (out[(r, c)] + out[(c, r)]);
                out[(r, c)] = v;
                out[(c, r)] = v;
            }
        }
        Ok(())
    }

    /// The velocity-dependent modified-Lagrangian term of the (1,1) scheme (without its `h^2`):
    /// `e(q, v) = -1/24 f_T^T M^-1 f_T + 1/12 v^T A v + 1/24 gamma_c^T S^-1 gamma_c` with
    /// `gamma_c,k = v^T Hess Phi_k v` (see `docs/symplectic.md`, "Modified-Lagrangian
    /// preadjustment"). Independent of the `s` of the workspace.
    pub fn modified_term(&mut self, sys: &System, q: &[f64], v: &[f64]) -> Result<f64, SolveError> {
        self.check_v(v)?;
        self.prepare(sys, q)?;
        Ok(self.modified_prepared(sys, q, v))
    }

    fn check_v(&self, v: &[f64]) -> Result<(), SolveError> {
        if v.len() != self.n {
            return Err(SolveError::Dimension {
                what: "v for the modified-Lagrangian term",
                expected: self.n,
                got: v.len(),
            });
        }
        Ok(())
    }

    /// `e(q, v)` after `prepare(q)`; leaves `gamma_c` in `gc` and `S^-1 gamma_c` in `sigma`.
    fn modified_prepared(&mut self, sys: &System, q: &[f64], v: &[f64]) -> f64 {
        let (n, m) = (self.n, self.m);
        let uu: f64 = (0..n).map(|k| self.mass[k] * self.u[k] * self.u[k]).sum();
        let mut t = std::mem::take(&mut self.tn[0]);
        matvec(&self.amat, v, &mut t);
        let vav = dot(v, &t);
        self.tn[0] = t;
        let mut gg = 0.0;
        if m > 0 {
            // gamma(q, v, t) = -(v^T Hess Phi_k v) + time part: the time part cancels
            sys.gamma(q, v, 0.0, &mut self.gc);
            sys.gamma(q, &self.zero, 0.0, &mut self.gc0);
            for r in 0..m {
                self.gc[r] = self.gc0[r] - self.gc[r];
            }
            self.sigma.copy_from_slice(&self.gc);
            self.chol.solve_in_place(&mut self.sigma);
            gg = dot(&self.gc, &self.sigma);
        }
        -uu / 24.0 + vav / 12.0 + gg / 24.0
    }

    /// Check of [`Preadjustment::modified_gradients`]: `d e / d q` by Richardson-extrapolated
    /// central differences of `e` in each coordinate, `d e / d v` as there.
    #[cfg(test)]
    pub(crate) fn modified_gradients_fd(
        &mut self,
        sys: &System,
        q: &[f64],
        v: &[f64],
        dq: &mut [f64],
        dv: &mut [f64],
    ) -> Result<f64, SolveError> {
        self.check_v(v)?;
        let n = self.n;
        if dq.len() != n || dv.len() != n {
            return Err(SolveError::Dimension {
                what: "gradient buffers of the modified-Lagrangian term",
                expected: n,
                got: dq.len().min(dv.len()),
            });
        }
        let mut qp = std::mem::take(&mut self.qp);
        qp.copy_from_slice(q);
        for l in 0..n {
            let d = self.fd_step * (1.0 + q[l].abs());
            let mut acc = 0.0;
            for (coef, shift) in [(8.0, 0.5), (-8.0, -0.5), (-1.0, 1.0), (1.0, -1.0)] {
                qp[l] = q[l] + shift * d;
                let r = self.prepare(sys, &qp);
                if let Err(e) = r {
                    self.qp = qp;
                    return Err(e);
                }
                acc += coef * self.modified_prepared(sys, &qp, v);
            }
            qp[l] = q[l];
            dq[l] = acc / (6.0 * d);
        }
        self.qp = qp;
        self.prepare(sys, q)?;
        let e = self.modified_prepared(sys, q, v);
        matvec(&self.amat, v, dv);
        if self.m > 0 {
            sys.constraint_hessian(q, &self.sigma, &mut self.hs);
            let mut t = std::mem::take(&mut self.tn[0]);
            matvec(&self.hs, v, &mut t);
            for k in 0..n {
                dv[k] += t[k];
            }
            self.tn[0] = t;
        }
        dv.iter_mut().for_each(|x| *x /= 6.0);
        Ok(e)
    }

    /// `A + H_sigma` at `q` (`H_sigma = sum_k sigma_k Hess Phi_k`, `sigma = S^-1 gamma_c(q, v)`)
    /// into `out` (overwritten): `6 d^2 e / dv^2`, used for the Newton Jacobian.
    pub fn modified_velocity_hessian(
        &mut self,
        sys: &System,
        q: &[f64],
        v: &[f64],
        out: &mut DMatrix<f64>,
    ) -> Result<(), SolveError> {
        self.check_v(v)?;
        self.prepare(sys, q)?;
        self.modified_prepared(sys, q, v);
        if self.m > 0 {
            sys.constraint_hessian(q, &self.sigma, out);
        } else {
            out.fill(0.0);
        }
        for (a, b) in out.iter_mut().zip(self.amat.iter()) {
            *a += b;
        }
        Ok(())
    }

    /// Gradients of [`Preadjustment::modified_term`], into `dq` and `dv`; returns `e(q, v)`.
    /// With `sigma = S^-1 gamma_c`, `H_sigma = sum_k sigma_k Hess Phi_k`, `u = M^-1 f_T` and
    /// `w = M^-1 Phi_q^T sigma` (derivation in `docs/symplectic.md`):
    ///
    /// * `d e / d v = 1/6 (A v + H_sigma v)` (exact),
    /// * `d e / d q = 1/12 [(A + H_sigma)(u - w) + D^3(V + (sigma - mu0) . Phi)(v, v)]`, where
    ///   the third-derivative term is the derivative along `v` of `Hess(V + (sigma - mu0) . Phi) v`
    ///   (`sigma`, `mu0` frozen), by Richardson-extrapolated central differences of the exact
    ///   Hessians with step `fd_step (1 + |q|_inf)` along `v / |v|_inf` (error `O(fd_step^4)`).
    pub fn modified_gradients(
        &mut self,
        sys: &System,
        q: &[f64],
        v: &[f64],
        dq: &mut [f64],
        dv: &mut [f64],
    ) -> Result<f64, SolveError> {
        self.check_v(v)?;
        let (n, m) = (self.n, self.m);
        if dq.len() != n || dv.len() != n {
            return Err(SolveError::Dimension {
                what: "gradient buffers of the modified-Lagrangian term",
                expected: n,
                got: dq.len().min(dv.len()),
            });
        }
        self.prepare(sys, q)?;
        let e = self.modified_prepared(sys, q, v);
        // (A + H_sigma) applied to v and to u - w
        if m > 0 {
            sys.constraint_hessian(q, &self.sigma, &mut self.hs);
        } else {
            self.hs.fill(0.0);
        }
        {
            let amat = self.amat.as_slice();
            let hs = self.hs.as_mut_slice();
            for (a, b) in hs.iter_mut().zip(amat) {
                *a += b;
            }
        }
        matvec(&self.hs, v, dv);
        dv.iter_mut().for_each(|x| *x /= 6.0);
        let uw = &mut self.tn[1];
        for k in 0..n {
            let acc: f64 = (0..m).map(|r| self.gq[(r, k)] * self.sigma[r]).sum();
            uw[k] = self.u[k] - self.minv[k] * acc;
        }
        matvec(&self.hs, &self.tn[1], dq);
        // third derivatives along v
        let vn = v.iter().fold(0.0f64, |a, &b| a.max(b.abs()));
        if vn > 0.0 {
            for r in 0..m {
                self.cm[r] = self.sigma[r] - self.mu0[r];
            }
            let d = self.fd_step * (1.0 + q.iter().fold(0.0f64, |a, &b| a.max(b.abs())));
            for (coef, shift) in [(8.0, 0.5), (-8.0, -0.5), (-1.0, 1.0), (1.0, -1.0)] {
                let qp = &mut self.qp;
                for k in 0..n {
                    qp[k] = q[k] + shift * d * v[k] / vn;
                }
                sys.potential_hessian(qp, &mut self.hs);
                if m > 0 {
                    sys.add_constraint_hessian(qp, &self.cm, 1.0, &mut self.hs);
                }
                let t = &mut self.tn[2];
                matvec(&self.hs, v, t);
                let c = coef * vn / (6.0 * d);
                for k in 0..n {
                    dq[k] += c * t[k];
                }
            }
        }
        dq.iter_mut().for_each(|x| *x /= 12.0);
        Ok(e)
    }
}

#[cfg(test)]
mod modlag_tests {
    use super::*;
    use mbd_model::models;

    /// The analytic position gradient of the modified-Lagrangian term against central
    /// differences of the term itself, away from equilibrium and with a generic velocity.
    #[test]
    fn modified_gradient_matches_differences() {
        let sys = models::paper_a_double_pendulum().unwrap();
        let st = mbd_solve::State::consistent(&sys, 0.0).unwrap();
        let n = sys.n_coords();
        let q: Vec<f64> = st.q.iter().copied().collect();
        let v: Vec<f64> = (0..n)
            .map(|i| 0.7 * ((i as f64) * 1.3 + 0.4).sin())
            .collect();
        let mut p = Preadjustment::new(&sys, 1).unwrap();
        let (mut a, mut av, mut b, mut bv) =
            (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]);
        let ea = p.modified_gradients(&sys, &q, &v, &mut a, &mut av).unwrap();
        let eb = p
            .modified_gradients_fd(&sys, &q, &v, &mut b, &mut bv)
            .unwrap();
        assert_eq!(ea, eb);
        let scale = b.iter().fold(0.0f64, |x, &y| x.max(y.abs()));
        for i in 0..n {
            assert!(
                (a[i] - b[i]).abs() < 1e-7 * scale,
                "dq[{i}]: {} vs {}",
                a[i],
                b[i]
            );
            assert!((av[i] - bv[i]).abs() < 1e-12 * (1.0 + bv[i].abs()));
        }
    }
}
