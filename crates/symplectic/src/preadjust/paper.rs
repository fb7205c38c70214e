//! Paper A's preadjustment potential `W_s(q)`: its value, its exact gradient and its Newton
//! Hessian (`docs/symplectic.md` section 5).
//!
//! With the metric's `u = M^-1 f_T`, `Pi` and `A` ([`ProjectedMetric`]) and the normal
//! projector `P = I - G^T S^-1 G M^-1` (`Pi = M^-1 P`):
//!
//! * `W_1 = 1/2 f_T^T M^-1 f_T = 1/2 u^T M u`,
//! * `W_s = 1/2 f_T^T M^-1 (P K_T M^-1)^(s-1) f_T = 1/2 u^T A (Pi A)^(s-2) u` for `s >= 2`, with
//!   the tangential stiffness `K_T = -d f_T / dq = P A + G^T S^-1 B` (so `P K_T = P A`).
//!
//! For `s = 1, 2` this is exactly paper A's `W_s`; for `s >= 3` the projector `P` between the
//! factors keeps the modal form `W_s = 1/2 sum_i omega_i^(2s+2) eta_i^2` about an equilibrium
//! (without it the normal components of `K_T` would enter). The gradient is exact: the third
//! derivatives of `V` and `Phi` it needs for `s >= 2` come from [`passes::potential_third`](crate::passes::potential_third) and
//! [`passes::constraint_third`](crate::passes::constraint_third). The Newton Hessian is `A (Pi A)^s`, the exact Hessian of `W_s`
//! at an equilibrium (`f_T = 0`; [`TangentStiffness::a_pi_a_power`]).

use super::dot;
use super::metric::ProjectedMetric;
use super::stiffness::TangentStiffness;
use crate::passes;
use mbd_model::System;
use nalgebra::DMatrix;

/// The workspace of `W_s` for one degree `s`: the Krylov vectors and the gradient's scratch.
#[derive(Debug)]
pub(crate) struct PaperTerm {
    s: usize,
    /// Krylov vectors `a_i` (`av`), `b_i = A a_i` (`bv`) and `sigma_i = S^-1 G M^-1 b_i`.
    av: Vec<Vec<f64>>,
    bv: Vec<Vec<f64>>,
    sig: Vec<Vec<f64>>,
    /// `h_k = 1/2 sum_i a_i^T Hess Phi_k a_{s-2-i}`, then `rho = S^-1 h` (length m).
    h: Vec<f64>,
    /// `gamma` of a polarisation direction (length m).
    gam: Vec<f64>,
    /// A polarisation direction; the `A`-product's argument; a Hessian-vector product
    /// (length n).
    dir: Vec<f64>,
    arg: Vec<f64>,
    hvp: Vec<f64>,
    /// The constraint weights of a Hessian-vector product (length m).
    wts: Vec<f64>,
    /// `D^3 (V - mu0 . Phi)(u, u, .)` (s = 2).
    d3: Vec<f64>,
}

impl PaperTerm {
    /// The workspace of `W_s` (`s >= 1`) for `n` coordinates and `m` constraints.
    pub(super) fn new(n: usize, m: usize, s: usize) -> Self {
        PaperTerm {
            s,
            av: vec![vec![0.0; n]; s + 1],
            bv: vec![vec![0.0; n]; s + 1],
            sig: vec![vec![0.0; m]; s.max(1)],
            h: vec![0.0; m],
            gam: vec![0.0; m],
            dir: vec![0.0; n],
            arg: vec![0.0; n],
            hvp: vec![0.0; n],
            wts: vec![0.0; m],
            d3: vec![0.0; n],
        }
    }

    /// The degree `s`.
    pub(super) fn s(&self) -> usize {
        self.s
    }

    /// Krylov vectors `a_0 = u`, `a_{i+1} = Pi b_i` with `b_i = A a_i`, for `i < count`.
    fn krylov(&mut self, metric: &mut ProjectedMetric, sys: &System, q: &[f64], count: usize) {
        self.av[0].copy_from_slice(metric.u());
        for i in 0..count {
            metric.a_times(sys, q, &self.av[i], &mut self.bv[i]);
            let (a, b) = (&mut self.av[i + 1], &self.bv[i]);
            metric.apply_pi(b, a);
        }
    }

    /// `W_s(q)` at the metric's prepared point `q`.
    pub(super) fn value(&mut self, metric: &mut ProjectedMetric, sys: &System, q: &[f64]) -> f64 {
        let s = self.s;
        if s == 1 {
            let (mass, u) = (metric.mass(), metric.u());
            return 0.5 * (0..metric.n()).map(|k| mass[k] * u[k] * u[k]).sum::<f64>();
        }
        // W_s = 1/2 u^T b_{s-2}, b_i = A a_i
        self.krylov(metric, sys, q, s - 1);
        0.5 * dot(metric.u(), &self.bv[s - 2])
    }

    /// `grad W_s(q)` into `out` at the metric's prepared point `q` (dense layout); returns
    /// `W_s(q)`. Matrix-free: every product with `A` or with a weighted constraint Hessian is
    /// one Hessian-vector pass over the elements ([`passes::lagrangian_hessian_vector`](crate::passes::lagrangian_hessian_vector)).
    pub(super) fn gradient(
        &mut self,
        metric: &mut ProjectedMetric,
        sys: &System,
        q: &[f64],
        out: &mut [f64],
    ) -> f64 {
        let (n, m, s) = (metric.n(), metric.m(), self.s);
        if s == 1 {
            // grad W_1 = -A u (exact: only second derivatives enter)
            metric.a_times(sys, q, metric.u(), out);
            out.iter_mut().for_each(|x| *x = -*x);
            return self.value(metric, sys, q);
        }
        let l = s - 2;
        // a_0..a_{l+1}, b_k = A a_k (k = 0..=l); sigma_k = S^-1 G M^-1 b_k
        if l == 0 {
            // s = 2: b_0 = A u and the third-derivative term D^3 (V - mu0 . Phi)(u, u, .) from
            // one third-order pass (passes::lagrangian_third) instead of a Hessian-vector pass
            // and two third-order passes
            self.av[0].copy_from_slice(metric.u());
            let (u, nmu0) = (metric.u(), metric.neg_mu0());
            passes::lagrangian_third(
                sys,
                q,
                metric.t(),
                u,
                1.0,
                nmu0,
                &mut self.bv[0],
                &mut self.d3,
            );
            let (a, b) = (&mut self.av[1], &self.bv[0]);
            metric.apply_pi(b, a);
        } else {
            self.krylov(metric, sys, q, l + 1);
        }
        if m > 0 {
            for k in 0..=l {
                metric.sgm(&self.bv[k], &mut self.sig[k]);
            }
        }
        let w = 0.5 * dot(metric.u(), &self.bv[l]);
        // (2b): h_k = 1/2 sum_i a_i^T H_k a_{l-i} (polarised gamma); rho = S^-1 h
        let h = &mut self.h;
        h.fill(0.0);
        if m > 0 {
            let g1 = &mut self.gam;
            let t = metric.t();
            // with a Jacobian that depends on time (a spatial angle driver) gamma also holds
            // the odd -2 Phi_tq x: each polarisation pair is taken at +x and -x as well
            let signs: &[f64] = if metric.time_jacobian() {
                &[1.0, -1.0]
            } else {
                &[1.0]
            };
            let wgt = 0.125 / signs.len() as f64;
            for i in 0..=l {
                if 2 * i == l && !metric.rheonomic() {
                    // a^T H_k a = -gamma_k(q, a) (no time part): one pass, not two (the
                    // polarisation's a - a = 0 gives nothing; gamma(2a) = 4 gamma(a) exactly)
                    sys.gamma(q, &self.av[i], t, g1);
                    for r in 0..m {
                        h[r] -= 0.5 * g1[r];
                    }
                    continue;
                }
                let (ai, ac) = (&self.av[i], &self.av[l - i]);
                let vp = &mut self.dir;
                for &sg in signs {
                    for k in 0..n {
                        vp[k] = sg * (ai[k] + ac[k]);
                    }
                    sys.gamma(q, vp, t, g1);
                    for r in 0..m {
                        h[r] -= wgt * g1[r];
                    }
                    for k in 0..n {
                        vp[k] = sg * (ai[k] - ac[k]);
                    }
                    sys.gamma(q, vp, t, g1);
                    for r in 0..m {
                        h[r] += wgt * g1[r];
                    }
                }
            }
            // rho; with spatial bodies on the dense layout the augmented metric's, and h kept
            // for its correction below
            if metric.is_augmented() {
                self.gam.copy_from_slice(h);
            }
            metric.s_solve(h);
        }
        // (1)+(2b'): -A (a_{l+1} + M^-1 G^T rho)
        if metric.is_augmented() {
            // M_W^-1 G^T S_W^-1 h: the minimum-norm solution of G x = h (that of M)
            self.arg.copy_from_slice(&self.av[l + 1]);
            if m > 0 {
                metric.add_dgt_to(h, 1.0, &mut self.arg);
                // rho of M from the augmented metric's
                metric.correct_multipliers(&self.gam, h);
            }
        } else {
            self.arg.copy_from_slice(&self.av[l + 1]);
            if m > 0 {
                metric.add_dgt_to(h, 1.0, &mut self.arg);
            }
        }
        metric.a_times(sys, q, &self.arg, out);
        out.iter_mut().for_each(|x| *x = -*x);
        // (3)+(2b''): -sum_j (sigma_{l-j} . H) a_j + (rho . H) a_0
        if m > 0 {
            let (t, wts) = (&mut self.hvp, &mut self.wts);
            for j in 0..=l {
                for r in 0..m {
                    wts[r] = self.sig[l - j][r] - if j == 0 { h[r] } else { 0.0 };
                }
                passes::lagrangian_hessian_vector(sys, q, metric.t(), &self.av[j], 0.0, wts, t);
                for i in 0..n {
                    out[i] -= t[i];
                }
            }
        }
        // (2a): 1/2 sum_i (D_{a_i} A~) a_{l-i}, A~ = Hess V - mu0 . Hess Phi with mu0 frozen
        // (exact third derivatives)
        if l == 0 {
            for (o, &d) in out.iter_mut().zip(&self.d3) {
                *o += 0.5 * d;
            }
            return w;
        }
        for i in 0..=l {
            let j = l - i;
            if i > j {
                break;
            }
            let factor = if i == j { 0.5 } else { 1.0 };
            self.third_derivative(metric, sys, q, i, j, factor, out);
        }
        w
    }

    /// `out += factor * (D_{a_i} A~) a_j = factor * D^3 (V - mu0 . Phi)(a_i, a_j, .)` (`mu0`
    /// frozen), exact: [`passes::potential_third`](crate::passes::potential_third) and [`passes::constraint_third`](crate::passes::constraint_third) along
    /// `a_i` when `i = j`, by polarisation along `a_i +- a_j` otherwise.
    #[allow(clippy::too_many_arguments)]
    fn third_derivative(
        &mut self,
        metric: &ProjectedMetric,
        sys: &System,
        q: &[f64],
        i: usize,
        j: usize,
        factor: f64,
        out: &mut [f64],
    ) {
        let n = metric.n();
        let dir = &mut self.dir;
        let signs: &[f64] = if i == j { &[1.0] } else { &[1.0, -1.0] };
        for &sg in signs {
            for k in 0..n {
                dir[k] = self.av[i][k] + if i == j { 0.0 } else { sg * self.av[j][k] };
            }
            let c = if i == j { factor } else { 0.25 * sg * factor };
            passes::add_potential_third(sys, q, dir, c, out);
            if metric.m() > 0 {
                passes::add_constraint_third(sys, q, dir, metric.mu0(), -c, out);
            }
        }
    }

    /// The diagonal stand-in for the Newton Hessian on the sparse stage solve, at the metric's
    /// prepared point `q`: `out_i = A_ii (w_i A_ii)^s` (the diagonal of `A (W A)^s` with the
    /// off-diagonal entries of `A = Hess V - mu0 . Hess Phi` left out and `Pi` replaced by
    /// the diagonal `W`: `M^-1`, or a finite stand-in on a massless coordinate), from one
    /// diagonal pass in `O(N)`; returns `max_i w_i |A_ii|`, a lower bound of the spectral
    /// radius of `W A` (Rayleigh quotients).
    pub(super) fn newton_diagonal(
        &self,
        metric: &ProjectedMetric,
        sys: &System,
        q: &[f64],
        w: &[f64],
        out: &mut [f64],
    ) -> f64 {
        out.fill(0.0);
        passes::add_lagrangian_hessian_diagonals(
            sys,
            q,
            metric.t(),
            [(
                passes::LagrangianWeights {
                    potential: 1.0,
                    constraints: metric.neg_mu0(),
                },
                &mut *out,
            )],
        );
        let mut rho = 0.0f64;
        for (o, &wi) in out.iter_mut().zip(w) {
            let r = wi * *o;
            rho = rho.max(r.abs());
            *o *= r.powi(self.s as i32);
        }
        rho
    }

    /// The Newton Hessian `A (Pi A)^s` at the metric's prepared point `q` into `out`
    /// (overwritten; dense layout).
    pub(super) fn newton_hessian(
        &self,
        metric: &ProjectedMetric,
        stiffness: &mut TangentStiffness,
        sys: &System,
        q: &[f64],
        out: &mut DMatrix<f64>,
    ) {
        stiffness.ensure(metric, sys, q);
        stiffness.a_pi_a_power(metric, self.s, out);
    }
}
