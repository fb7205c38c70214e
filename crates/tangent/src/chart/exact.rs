//! The exact-Newton fallback of a failed chord iteration near a singular configuration.

use super::{loop_head, ChartFailure, MapStats, NewtonSettings, TangentChart};
use crate::kernels::{gemv_cols, gemv_t_cols};
use mbd_model::System;
use mbd_solve::linalg::{max_abs, max_abs_diff};

impl TangentChart {
    /// The fallback after a failed chord iteration from `x` (its starting point): if `Df(x)`
    /// is within `fallback_change` (relative) of `Df(x_c)`, Newton's method along the normal
    /// directions with the exact matrix `J = Df(x_k) Q1` at every iterate,
    /// `x <- x - Q1 J^-1 f(x)`; otherwise `failure` as it was. Same stopping rules as the chord
    /// iteration; a numerically singular `J` is a failure. Starts from the map's predictor
    /// (`x`); the caller bounds its travel ([`TRAVEL_FACTOR`], start copied to `wx`).
    #[allow(clippy::too_many_arguments)]
    pub(super) fn exact_newton(
        &mut self,
        sys: &System,
        t: f64,
        x: &mut [f64],
        newton: &NewtonSettings,
        f: &mut [f64],
        failure: ChartFailure,
        res_start: f64,
    ) -> Result<MapStats, ChartFailure> {
        let (n, m) = (self.n, self.m);
        let (nn, mm) = (2 * n, 2 * m);
        self.form_q();
        // start from the caller's starting point (the predictor). Its projection onto the
        // tangent plane, x_c + U xi, is only used when the predictor's residual is not finite:
        // the residual is no measure of the distance to the branch near a singular
        // configuration (it grows only quadratically along the nearly singular direction), and
        // without degrees of freedom the projection is the centre itself, a whole step away
        if res_start.is_nan() {
            for ((d, xv), xc) in self.dx.iter_mut().zip(x.iter()).zip(&self.xc) {
                *d = xv - xc;
            }
            gemv_t_cols(&self.q[..mm * nn], &self.dx, &mut self.w);
            for wk in self.w.iter_mut() {
                *wk = -*wk;
            }
            self.step.copy_from_slice(x);
            gemv_cols(&self.q[..mm * nn], &self.w, &mut self.step);
            // (the residual borrows the chart mutably: the point is moved out for the call,
            // which does not allocate)
            let step = std::mem::take(&mut self.step);
            if self.residual_weighted(sys, &step, t, f).is_finite() {
                x.copy_from_slice(&step);
            }
            self.step = step;
        }
        self.wx.copy_from_slice(x);
        self.first_step = 0.0;
        self.jacobian_weighted(sys, x, t);
        let scale = max_abs(self.phi_q.as_slice()).max(max_abs(self.dphi.as_slice()));
        let change = max_abs_diff(self.pq_x.as_slice(), self.phi_q.as_slice())
            .max(max_abs_diff(self.dphi_x.as_slice(), self.dphi.as_slice()));
        if change.is_nan() || change > newton.fallback_change * scale {
            return Err(failure);
        }
        let tol = newton.tol;
        let stall_cap = self.roundoff.stall_cap(x, tol, self.vinv);
        let res0 = self.residual_weighted(sys, x, t, f);
        let mut res = res0;
        let mut it = failure.iterations;
        let max_iter = failure.iterations + newton.max_iter;
        let mut first = true;
        let done = |it: usize, res: f64| MapStats {
            iterations: it,
            residual: res,
            initial_residual: res0,
            exact: true,
        };
        loop {
            if let Some(verdict) = loop_head(t, res, res0, it, tol, max_iter) {
                if verdict.is_ok() {
                    self.exact_maps += 1;
                }
                return verdict.map(|_| done(it, res));
            }
            if !first {
                self.jacobian_weighted(sys, x, t);
            }
            first = false;
            // J = Df(x) Q1: column k = (Phi_q cq, tau X cq + Phi_q cv) for Q1_k = (cq, cv)
            // (the chart's coordinates (q, tau v), its velocity rows weighted by tau)
            if self.vs != 1.0 {
                self.dphi_x *= self.vs;
            }
            let (dp, dx) = (self.pq_x.as_slice(), self.dphi_x.as_slice());
            self.jn.fill(0.0);
            for k in 0..mm {
                let col = &self.q[k * nn..(k + 1) * nn];
                let (cq, cv) = col.split_at(n);
                let (jp, jv) = self.jn[k * mm..(k + 1) * mm].split_at_mut(m);
                gemv_cols(dp, cq, jp);
                gemv_cols(dx, cq, jv);
                gemv_cols(dp, cv, jv);
            }
            for (u, fk) in self.u.iter_mut().zip(f.iter()) {
                *u = -fk;
            }
            let solved = {
                let mut a = self.jn_lu.matrix_mut();
                for c in 0..mm {
                    for r in 0..mm {
                        a[(r, c)] = self.jn[c * mm + r];
                    }
                }
                self.jn_lu.factor_in_place().is_ok() && {
                    self.jn_lu.solve_in_place(&mut self.u);
                    self.u.iter().all(|x| x.is_finite())
                }
            };
            if !solved {
                if res <= stall_cap {
                    // J numerically singular: x is at a singular configuration, with the
                    // residual at the round-off floor (the next centre reports it)
                    self.exact_maps += 1;
                    return Ok(done(it, res));
                }
                return Err(ChartFailure {
                    t,
                    residual: res,
                    iterations: it,
                });
            }
            gemv_cols(&self.q[..mm * nn], &self.u, x);
            it += 1;
            if it == failure.iterations + 1 {
                self.first_step = max_abs_diff(x, &self.wx);
            }
            let prev = res;
            res = self.residual_weighted(sys, x, t, f);
            if res > tol && res <= stall_cap && res >= 0.9 * prev {
                self.exact_maps += 1;
                return Ok(done(it, res));
            }
            if res > newton.divergence * prev && res > tol {
                return Err(ChartFailure {
                    t,
                    residual: res,
                    iterations: it,
                });
            }
            if res <= tol {
                self.exact_maps += 1;
                return Ok(done(it, res));
            }
        }
    }

    /// `Phi_q` and `(Phi_q v)_q` at the chart point `x = (q, tau v)` into `pq_x` and `dphi_x`
    /// (unweighted).
    fn jacobian_weighted(&mut self, sys: &System, x: &[f64], t: f64) {
        let (q, v) = x.split_at(self.n);
        self.fill_velocities(v);
        self.sel.jacobian(
            sys,
            q,
            None,
            &self.vbuf,
            t,
            &mut self.pq_x,
            &mut self.dphi_x,
            false,
        );
    }
}
