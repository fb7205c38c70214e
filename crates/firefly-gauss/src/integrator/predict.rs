//! The partition check, the predictor of the free end state and the search box around it.

use super::*;

impl FireflyGauss {
    /// Auto partitioning: re-choose the dependent coordinates and the equations when the
    /// dependent block at the step's start has become much worse than the best available one
    /// (see [`FaDaeOptions::repartition_threshold`]). Given partitioning: error when it is
    /// singular; with redundant equations the equations are re-chosen for the given
    /// coordinates first, in the same way. Returns whether the partition changed and the
    /// quality of the dependent block before any change (`|det Phi_d| / |det Phi_best|`; NaN
    /// for a given partition).
    pub(super) fn check_partition(
        &mut self,
        sys: &System,
        state: &State,
    ) -> Result<(bool, f64), FaDaeError> {
        let q = state.q.as_slice();
        sys.phi_q(q, state.t, &mut self.ws.jac);
        self.partition
            .fill_dependent_block(&self.ws.jac, self.ws.lu.rows_mut());
        let factored = self.ws.lu.factor_lu().map(|()| self.ws.lu.pivot_range());
        if let PartitionChoice::Given(_) = self.opts.partition {
            if self.prob.r < self.m {
                return self.check_given_rows(state, factored.is_ok());
            }
            let ratio = match factored {
                Ok((pmin, pmax)) => pmin / pmax,
                Err(_) => 0.0,
            };
            if ratio.is_nan() || ratio <= 1e-12 {
                return Err(SolveError::Singular {
                    t: state.t,
                    what: "dependent block of Phi_q (user-given partition)",
                    detail: format!("independent coordinates {:?}", self.partition.independent),
                }
                .into());
            }
            return Ok((false, f64::NAN));
        }
        let current = match factored {
            Ok(_) => self.ws.lu.log_abs_det(),
            Err(_) => f64::NEG_INFINITY,
        };
        // Phi_q rank deficient (a singular configuration) or, with redundant equations, of
        // higher rank than at build: no block is better, keep this one (the step fails in
        // `prepare` if it is exactly singular)
        let Ok(best) = self.pivoting.eliminate(&self.ws.jac) else {
            return Ok((false, 1.0));
        };
        let quality = (current - best).exp().min(1.0);
        if quality >= self.opts.repartition_threshold {
            return Ok((false, quality));
        }
        let p = self.pivoting.partition();
        let changed = p != self.partition;
        if changed {
            self.partition = p;
            self.prob.set_partition(&self.partition);
            self.n_corr = 0;
        }
        Ok((changed, quality))
    }

    /// A given partition of a mechanism with redundant equations: the coordinates are the
    /// user's, the equations are not. When the block of the equations in use is worse than
    /// `repartition_threshold` times the best block for these coordinates (complete pivoting
    /// restricted to the dependent columns), the equations are re-chosen; a block that stays
    /// singular is an error as without redundant equations. `factored`: the LU of the block in
    /// use (in `self.ws.lu`) succeeded.
    fn check_given_rows(
        &mut self,
        state: &State,
        factored: bool,
    ) -> Result<(bool, f64), FaDaeError> {
        let current = if factored {
            self.ws.lu.log_abs_det()
        } else {
            f64::NEG_INFINITY
        };
        let mut changed = false;
        if let Ok(best) = self
            .pivoting
            .eliminate_with_dependent(&self.ws.jac, &self.partition.dependent)
        {
            if (current - best).exp() < self.opts.repartition_threshold.max(1e-12) {
                let p = self.pivoting.partition();
                changed = p.equations != self.partition.equations;
                if changed {
                    self.partition.equations.clone_from(&p.equations);
                    self.prob.set_partition(&self.partition);
                    self.n_corr = 0;
                }
            }
        }
        self.partition
            .fill_dependent_block(&self.ws.jac, self.ws.lu.rows_mut());
        let ratio = match self.ws.lu.factor_lu().map(|()| self.ws.lu.pivot_range()) {
            Ok((pmin, pmax)) => pmin / pmax,
            Err(_) => 0.0,
        };
        if ratio.is_nan() || ratio <= 1e-12 {
            return Err(SolveError::Singular {
                t: state.t,
                what: "dependent block of Phi_q (user-given partition)",
                detail: format!(
                    "independent coordinates {:?}, equations {:?}",
                    self.partition.independent, self.partition.equations
                ),
            }
            .into());
        }
        Ok((changed, f64::NAN))
    }

    /// RK4 on the index-1 form from the state (the predictor) and, without a correction
    /// history (first step, after a repartition), two RK4 half steps: the Richardson estimate
    /// of the predictor's error that sizes the first box.
    pub(super) fn predict(
        &mut self,
        sys: &System,
        state: &State,
        h: f64,
    ) -> Result<(), FaDaeError> {
        let t0 = state.t;
        let (mut qo, mut vo) = (
            std::mem::take(&mut self.qhat),
            std::mem::take(&mut self.vhat),
        );
        let r = self.rk4(
            sys,
            state.q.as_slice(),
            state.v.as_slice(),
            t0,
            h,
            &mut qo,
            &mut vo,
        );
        self.qhat = qo;
        self.vhat = vo;
        r?;
        let dof = self.partition.dof();
        for (k, &i) in self.partition.independent.iter().enumerate() {
            self.xhat[k] = self.qhat[i];
            self.xhat[dof + k] = self.vhat[i];
        }
        if self.n_corr == 0 {
            // no correction history yet: estimate the predictor's error by Richardson
            // extrapolation, two RK4 half steps against the full step
            let (mut qm, mut vm) = (std::mem::take(&mut self.qs), std::mem::take(&mut self.vs));
            let (mut q2, mut v2) = (vec![0.0; self.n], vec![0.0; self.n]);
            let mut r = self.rk4(
                sys,
                state.q.as_slice(),
                state.v.as_slice(),
                t0,
                0.5 * h,
                &mut qm,
                &mut vm,
            );
            if r.is_ok() {
                r = self.rk4(sys, &qm, &vm, t0 + 0.5 * h, 0.5 * h, &mut q2, &mut v2);
            }
            self.qs = qm;
            self.vs = vm;
            r?;
            for (k, &i) in self.partition.independent.iter().enumerate() {
                self.xtay[k] = self.xhat[k] + (q2[i] - self.xhat[k]) * (16.0 / 15.0);
                self.xtay[dof + k] =
                    self.xhat[dof + k] + (v2[i] - self.xhat[dof + k]) * (16.0 / 15.0);
            }
        }
        if self.qhat.iter().chain(&self.vhat).any(|x| !x.is_finite()) {
            return Err(SolveError::NonFinite {
                t: t0,
                what: "FA-DAE predictor",
            }
            .into());
        }
        Ok(())
    }

    /// One classic RK4 step on the index-1 form from `(q0, v0, t0)` into `(qo, vo)`.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn rk4(
        &mut self,
        sys: &System,
        q0: &[f64],
        v0: &[f64],
        t0: f64,
        h: f64,
        qo: &mut [f64],
        vo: &mut [f64],
    ) -> Result<(), FaDaeError> {
        let n = self.n;
        let c = [0.0, 0.5, 0.5, 1.0];
        let (mut qs, mut vs) = (std::mem::take(&mut self.rq), std::mem::take(&mut self.rv));
        let mut res = Ok(());
        for (s, &cs) in c.iter().enumerate() {
            if s == 0 {
                qs.copy_from_slice(q0);
                vs.copy_from_slice(v0);
            } else {
                let (kv, ka) = (&self.kv[s - 1], &self.ka[s - 1]);
                for i in 0..n {
                    qs[i] = q0[i] + cs * h * kv[i];
                    vs[i] = v0[i] + cs * h * ka[i];
                }
            }
            self.kv[s].copy_from_slice(&vs);
            let ka = &mut self.ka[s];
            res = self
                .acc
                .solve(sys, &qs, &vs, t0 + cs * h, ka, &mut self.lambda);
            if res.is_err() {
                break;
            }
        }
        self.rq = qs;
        self.rv = vs;
        res?;
        for i in 0..n {
            qo[i] = q0[i]
                + h / 6.0
                    * (self.kv[0][i] + 2.0 * self.kv[1][i] + 2.0 * self.kv[2][i] + self.kv[3][i]);
            vo[i] = v0[i]
                + h / 6.0
                    * (self.ka[0][i] + 2.0 * self.ka[1][i] + 2.0 * self.ka[2][i] + self.ka[3][i]);
        }
        Ok(())
    }

    /// The predictor (into `centre`) and the box half-widths and floors.
    pub(super) fn predictor_and_box(&mut self, dof: usize, h: f64) {
        let nd = 2 * dof;
        let b = &self.opts.bounds;
        let corrected = self.opts.predictor == Predictor::CorrectedRk4;
        let (group_max, diff_max) = (max_abs, max_abs_diff);
        // estimated error of the predictor, per group (positions, velocities)
        let (ez, ev) = match (self.n_corr, corrected) {
            (0, _) => (
                diff_max(&self.xhat[..dof], &self.xtay[..dof]),
                diff_max(&self.xhat[dof..], &self.xtay[dof..]),
            ),
            (1, _) | (_, false) => (group_max(&self.corr[..dof]), group_max(&self.corr[dof..])),
            _ => (
                diff_max(&self.corr[..dof], &self.corr_prev[..dof]),
                diff_max(&self.corr[dof..], &self.corr_prev[dof..]),
            ),
        };
        for k in 0..nd {
            self.centre[k] = self.xhat[k]
                + if corrected && self.n_corr > 0 {
                    self.corr[k]
                } else {
                    0.0
                };
        }
        // balanced box: a full half-width in z or in zdot moves the interpolant's second
        // derivative at the Gauss nodes by comparable amounts (6 dz / h^2 vs 4 dzdot / h)
        let fz = b.min_relative * (1.0 + group_max(&self.centre[..dof]));
        let fv = b.min_relative * (1.0 + group_max(&self.centre[dof..]));
        let wz = (b.safety * ez.max(h * ev)).max(fz);
        let wv = (wz / h).max(fv);
        for k in 0..dof {
            self.half[k] = wz;
            self.half[dof + k] = wv;
            self.floor[k] = fz;
            self.floor[dof + k] = fv;
        }
        for k in 0..nd {
            let sign = if k % 2 == 0 { 1.0 } else { -1.0 };
            self.centre[k] += sign * self.opts.predictor_offset * self.half[k];
        }
    }
}
