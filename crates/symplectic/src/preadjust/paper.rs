//! Paper A's `W_s`: value, gradient (exact third derivatives) and the Newton Hessian.

use super::{dot, Preadjustment};
use mbd_model::System;
use mbd_solve::SolveError;
use nalgebra::DMatrix;

impl Preadjustment {
    /// `W_s(q)`.
    pub fn value(&mut self, sys: &System, q: &[f64]) -> Result<f64, SolveError> {
        self.require_dense("Preadjustment::value")?;
        self.prepare(sys, q)?;
        Ok(self.value_prepared(sys, q))
    }

    fn value_prepared(&mut self, sys: &System, q: &[f64]) -> f64 {
        let s = self.s;
        if s == 1 {
            return 0.5
                * (0..self.n)
                    .map(|k| self.mass[k] * self.u[k] * self.u[k])
                    .sum::<f64>();
        }
        // W_s = 1/2 u^T b_{s-2}, b_i = A a_i
        self.krylov(sys, q, s - 1);
        0.5 * dot(&self.u, &self.bv[s - 2])
    }

    /// `grad W_s(q)` into `out`; returns `W_s(q)`. Matrix-free: every product with `A` or
    /// with a weighted constraint Hessian is one Hessian-vector pass over the elements
    /// ([`System::lagrangian_hessian_vector`]), the third derivatives are exact.
    pub fn gradient(
        &mut self,
        sys: &System,
        q: &[f64],
        out: &mut [f64],
    ) -> Result<f64, SolveError> {
        self.require_dense("Preadjustment::gradient")?;
        self.prepare(sys, q)?;
        let (n, m, s) = (self.n, self.m, self.s);
        if s == 1 {
            // grad W_1 = -A u (exact: only second derivatives enter)
            self.a_times(sys, q, &self.u, out);
            out.iter_mut().for_each(|x| *x = -*x);
            return Ok(self.value_prepared(sys, q));
        }
        let l = s - 2;
        // a_0..a_{l+1}, b_k = A a_k (k = 0..=l); sigma_k = S^-1 G M^-1 b_k
        if l == 0 {
            // s = 2: b_0 = A u and the third-derivative term D^3 (V - mu0 . Phi)(u, u, .) from
            // one third-order pass (System::lagrangian_third) instead of a Hessian-vector pass
            // and two third-order passes
            self.av[0].copy_from_slice(&self.u);
            let mut b = std::mem::take(&mut self.bv[0]);
            sys.lagrangian_third(q, &self.u, 1.0, &self.nmu0, &mut b, &mut self.d3);
            let mut next = std::mem::take(&mut self.av[1]);
            self.apply_pi(&b, &mut next);
            self.av[1] = next;
            self.bv[0] = b;
        } else {
            self.krylov(sys, q, l + 1);
        }
        if m > 0 {
            for k in 0..=l {
                let mut sg = std::mem::take(&mut self.sig[k]);
                let b = std::mem::take(&mut self.bv[k]);
                self.sgm(&b, &mut sg);
                self.bv[k] = b;
                self.sig[k] = sg;
            }
        }
        let w = 0.5 * dot(&self.u, &self.bv[l]);
        // (2b): h_k = 1/2 sum_i a_i^T H_k a_{l-i} (polarised gamma); rho = S^-1 h
        let mut h = std::mem::take(&mut self.tm[1]);
        h.iter_mut().for_each(|x| *x = 0.0);
        if m > 0 {
            let mut g1 = std::mem::take(&mut self.tm[2]);
            for i in 0..=l {
                if 2 * i == l && !self.rheonomic {
                    // a^T H_k a = -gamma_k(q, a) (no time part): one pass, not two (the
                    // polarisation's a - a = 0 gives nothing; gamma(2a) = 4 gamma(a) exactly)
                    sys.gamma(q, &self.av[i], 0.0, &mut g1);
                    for r in 0..m {
                        h[r] -= 0.5 * g1[r];
                    }
                    continue;
                }
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
            self.tm[2] = g1;
            self.chol.solve_in_place(&mut h); // rho
        }
        // (1)+(2b'): -A (a_{l+1} + M^-1 G^T rho)
        {
            let t2 = &mut self.tn[2];
            for k in 0..n {
                let acc: f64 = (0..m).map(|r| self.gq[(r, k)] * h[r]).sum();
                t2[k] = self.av[l + 1][k] + self.minv[k] * acc;
            }
        }
        self.a_times(sys, q, &self.tn[2], out);
        out.iter_mut().for_each(|x| *x = -*x);
        // (3)+(2b''): -sum_j (sigma_{l-j} . H) a_j + (rho . H) a_0
        if m > 0 {
            let mut t = std::mem::take(&mut self.tn[0]);
            let mut wts = std::mem::take(&mut self.cm);
            self.mv_valid = false;
            for j in 0..=l {
                for r in 0..m {
                    wts[r] = self.sig[l - j][r] - if j == 0 { h[r] } else { 0.0 };
                }
                sys.lagrangian_hessian_vector(q, &self.av[j], 0.0, &wts, &mut t);
                for i in 0..n {
                    out[i] -= t[i];
                }
            }
            self.cm = wts;
            self.tn[0] = t;
        }
        self.tm[1] = h;
        // (2a): 1/2 sum_i (D_{a_i} A~) a_{l-i}, A~ = Hess V - mu0 . Hess Phi with mu0 frozen
        // (exact third derivatives)
        if l == 0 {
            for (o, &d) in out.iter_mut().zip(&self.d3) {
                *o += 0.5 * d;
            }
            return Ok(w);
        }
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

    /// `out += factor * (D_{a_i} A~) a_j = factor * D^3 (V - mu0 . Phi)(a_i, a_j, .)` (`mu0`
    /// frozen), exact: [`System::potential_third`] and [`System::constraint_third`] along
    /// `a_i` when `i = j`, by polarisation along `a_i +- a_j` otherwise.
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
        let mut dir = std::mem::take(&mut self.tn[1]);
        let signs: &[f64] = if i == j { &[1.0] } else { &[1.0, -1.0] };
        for &sg in signs {
            for k in 0..n {
                dir[k] = self.av[i][k] + if i == j { 0.0 } else { sg * self.av[j][k] };
            }
            let c = if i == j { factor } else { 0.25 * sg * factor };
            sys.add_potential_third(q, &dir, c, out);
            if self.m > 0 {
                sys.add_constraint_third(q, &dir, &self.mu0, -c, out);
            }
        }
        self.tn[1] = dir;
    }

    /// A bound on the spectral radius of `M^-1 A` (Gershgorin: `max_i minv_i sum_l |A_il|`; the
    /// eigenvalues are those of the symmetric `M^-1/2 A M^-1/2`), so the Newton Hessian
    /// [`Preadjustment::approximate_hessian`] is at most `bound^(s+1)` in the mass metric.
    pub fn hessian_bound(&mut self, sys: &System, q: &[f64]) -> Result<f64, SolveError> {
        self.require_dense("Preadjustment::hessian_bound")?;
        self.prepare(sys, q)?;
        self.ensure_a(sys, q);
        let n = self.n;
        let mut rho = 0.0f64;
        for i in 0..n {
            let row: f64 = (0..n).map(|l| self.amat[(i, l)].abs()).sum();
            rho = rho.max(self.minv[i] * row);
        }
        Ok(rho)
    }

    /// The block `K` of the coordinates where `A` is not zero (into `kset`; returns `|K|`),
    /// `Y = L^-1 (G M^-1)_K` (`S = L L^T`; one triangular solve per column, packed into `ky`,
    /// m x |K|) and `A_KK` (column-major into `ka`), after `prepare` and `ensure_a`.
    fn k_block(&mut self) -> usize {
        let (n, m) = (self.n, self.m);
        self.kset.clear();
        for (c, col) in self.amat.as_slice().chunks_exact(n).enumerate() {
            if col.iter().any(|&a| a != 0.0) {
                self.kset.push(c);
            }
        }
        let k = self.kset.len();
        for (cj, &c) in self.kset.iter().enumerate() {
            let y = &mut self.ky[cj * m..(cj + 1) * m];
            for r in 0..m {
                y[r] = self.gq[(r, c)] * self.minv[c];
            }
            self.chol.forward_in_place(y);
            for (ri, &r) in self.kset.iter().enumerate() {
                self.ka[cj * k + ri] = self.amat[(r, c)];
            }
        }
        k
    }

    /// An approximate Hessian of `W_s` for Newton: `A (Pi A)^s` (exact at an equilibrium),
    /// symmetrised, into `out` (overwritten).
    ///
    /// `A` is symmetric, so its zero columns (coordinates that enter `V` and the constraints
    /// linearly, e.g. the positions of bodies with revolute joints under gravity) are zero rows
    /// too, and `A (Pi A)^s` lives on the block `K x K` of the other coordinates:
    /// `A_KK (Pi_KK A_KK)^s`, with `Pi_KK = M^-1_KK - (G M^-1)_K^T S^-1 (G M^-1)_K` from `|K|`
    /// Cholesky solves. Dense products of size `|K|` only.
    pub fn approximate_hessian(
        &mut self,
        sys: &System,
        q: &[f64],
        out: &mut DMatrix<f64>,
    ) -> Result<(), SolveError> {
        self.require_dense("Preadjustment::approximate_hessian")?;
        self.prepare(sys, q)?;
        self.ensure_a(sys, q);
        let (n, m) = (self.n, self.m);
        let k = self.k_block();
        // Pi_KK = M^-1_KK - Y^T Y (ky is free after this, until the products below)
        for cj in 0..k {
            for ri in 0..k {
                let yy = dot(
                    &self.ky[ri * m..(ri + 1) * m],
                    &self.ky[cj * m..(cj + 1) * m],
                );
                let d = if ri == cj {
                    self.minv[self.kset[cj]]
                } else {
                    0.0
                };
                self.kpi[cj * k + ri] = d - yy;
            }
        }
        // X = A_KK, then X <- A_KK (Pi_KK X), s times
        self.kx[..k * k].copy_from_slice(&self.ka[..k * k]);
        let mul = |a: &[f64], b: &[f64], o: &mut [f64]| {
            // o = a b, k x k column-major
            for cj in 0..k {
                for ri in 0..k {
                    o[cj * k + ri] = (0..k).map(|l| a[l * k + ri] * b[cj * k + l]).sum();
                }
            }
        };
        for _ in 0..self.s {
            mul(&self.kpi, &self.kx, &mut self.ky);
            mul(&self.ka, &self.ky, &mut self.kx);
        }
        out.fill(0.0);
        let o = out.as_mut_slice();
        for (cj, &c) in self.kset.iter().enumerate() {
            for (ri, &r) in self.kset.iter().enumerate() {
                o[c * n + r] = 0.5 * (self.kx[cj * k + ri] + self.kx[ri * k + cj]);
            }
        }
        Ok(())
    }

    /// `A Pi A` into `out` (overwritten): [`Preadjustment::approximate_hessian`] with `s = 1`
    /// whatever the workspace's `s`, in fewer operations (the modified Lagrangian's Newton
    /// matrix, `galerkin/dense.rs`). The same matrix up to rounding, symmetric by construction:
    /// with `Pi_KK = M^-1_KK - Y^T Y`, `Y = L^-1 (G M^-1)_K` as there,
    /// `A_KK Pi_KK A_KK = A_KK M^-1_KK A_KK - Z^T Z`, `Z = Y A_KK` (`m x |K|`, zeros of `A_KK`
    /// skipped), so each entry of the upper triangle is one `|K|`-term and one `m`-term dot
    /// product (no `|K|^3` products).
    pub(crate) fn approximate_hessian_1(
        &mut self,
        sys: &System,
        q: &[f64],
        out: &mut DMatrix<f64>,
    ) -> Result<(), SolveError> {
        self.require_dense("Preadjustment::approximate_hessian_1")?;
        if out.shape() != (self.n, self.n) {
            return Err(SolveError::Dimension {
                what: "the approximate Hessian",
                expected: self.n,
                got: out.nrows(),
            });
        }
        self.prepare(sys, q)?;
        self.ensure_a(sys, q);
        let (n, m) = (self.n, self.m);
        let k = self.k_block();
        // Z = Y A_KK (m x k, columns packed into gscr: free outside
        // add_modified_velocity_hessian)
        let z = self.gscr.as_mut_slice();
        for cj in 0..k {
            let zc = &mut z[cj * m..(cj + 1) * m];
            zc.fill(0.0);
            for (l, &a) in self.ka[cj * k..(cj + 1) * k].iter().enumerate() {
                if a != 0.0 {
                    for (zr, &yr) in zc.iter_mut().zip(&self.ky[l * m..(l + 1) * m]) {
                        *zr += yr * a;
                    }
                }
            }
        }
        let o = out.as_mut_slice();
        o.fill(0.0);
        for (cj, &c) in self.kset.iter().enumerate() {
            let ac = &self.ka[cj * k..(cj + 1) * k];
            let zc = &z[cj * m..(cj + 1) * m];
            for (ri, &r) in self.kset.iter().enumerate().take(cj + 1) {
                // (A symmetric: row ri of A_KK is its column ri)
                let ar = &self.ka[ri * k..(ri + 1) * k];
                let am: f64 = ar
                    .iter()
                    .zip(ac)
                    .zip(&self.kset)
                    .map(|((&x, &y), &l)| x * self.minv[l] * y)
                    .sum();
                let x = am - dot(&z[ri * m..(ri + 1) * m], zc);
                o[c * n + r] = x;
                o[r * n + c] = x;
            }
        }
        Ok(())
    }
}
