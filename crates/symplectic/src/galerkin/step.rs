//! One step of the scheme through the [`Integrator`] trait: predictor, Newton iteration on the
//! stage equations, end momentum and its projection.

use super::*;

impl Integrator for Galerkin {
    fn keeps_constraints(&self) -> bool {
        true
    }
    fn name(&self) -> String {
        let s = self.tab.s;
        let mut name = format!("symplectic ({s},{s})");
        if self.opts.gamma != 0.0 {
            name += &format!(" gamma = {}", self.opts.gamma);
        }
        if !self.ml.is_empty() {
            name += " modified Lagrangian";
        }
        if self.opts.nodes == Nodes::Equispaced && s > 2 {
            name += " equispaced";
        }
        name
    }

    /// `2s` (Lobatto control points); `2s + 2` with the modified-Lagrangian preadjustment,
    /// which removes the scheme's leading `h^2s` error term (`docs/symplectic.md` section 5;
    /// the report's `own-orders` measures both).
    fn order(&self) -> Option<u32> {
        let s = self.tab.s as u32;
        let modified = self.opts.preadjust == PreadjustMode::ModifiedLagrangian;
        Some(match self.opts.nodes {
            Nodes::Lobatto if modified => 2 * s + 2,
            Nodes::Lobatto => 2 * s,
            Nodes::Equispaced => (2 * s).min(if s % 2 == 1 { s + 1 } else { s + 2 }),
        })
    }

    fn reset(&mut self) {
        self.forget();
        self.starter.reset();
    }

    /// A step of the scheme; from a singular initial configuration where its stage equations
    /// have no solution, the step is taken by projected DOPRI5 instead
    /// ([`SingularStarter`]) and the scheme takes over at its end point. The (1,1) scheme's
    /// end point `q_1` must satisfy `Phi(q_1) = 0` with constraint forces along
    /// `Phi_q(q_0)^T` alone, which at a singular `q_0` lacks one direction per dependent
    /// equation: its Newton residual stalls at `O(h^3)` (at small `h` below the Newton's
    /// acceptance, with an `O(h^3)` constraint error that the energy balance shows), so
    /// (1,1) always hands such a step to the starter. The (s,s) schemes with `s >= 2` have
    /// interior control points off the singular configuration and take the step themselves
    /// (the starter only where their Newton iteration fails there).
    fn step(&mut self, sys: &System, state: &mut State, h: f64) -> Result<StepStats, SolveError> {
        let t = state.t;
        // (bad input is reported as such, also on a singular start, not as the starter's
        // refusal)
        self.check_step(sys, state, h)?;
        if self.tab.s == 1 && self.starts_singular(sys, state)? {
            let refused = SolveError::Singular {
                t,
                what: mbd_solve::STAGES_NEAR_RANK_LOSS,
                detail: "symplectic (1,1) from a singular configuration".into(),
            };
            let stats = self.starter.step(sys, state, h, refused)?;
            self.forget();
            return Ok(stats);
        }
        match self.scheme_step(sys, state, h) {
            Err(e) if SingularStarter::takes(&e, sys, state)? => {
                let stats = self.starter.step(sys, state, h, e)?;
                // the histories (predictor, reused Jacobians) belong to the scheme's steps
                self.forget();
                Ok(stats)
            }
            r => r,
        }
    }
}

impl Galerkin {
    /// Whether `state` is a singular configuration of a model that starts on one
    /// (`System::singular_start_equations`) and does not continue this integrator's last
    /// step (a run's first step, or a state handed in): `Phi_q` there has more dependent
    /// rows than the model's redundant ones.
    fn starts_singular(&self, sys: &System, state: &State) -> Result<bool, SolveError> {
        if sys.singular_start_equations().is_empty() {
            return Ok(false);
        }
        // (the rank test only where a step may start on it)
        let continues = self.hist_valid
            && self.hist_t == state.t
            && self.hist_q.as_slice() == state.q.as_slice();
        if continues {
            return Ok(false);
        }
        SingularStarter::at_singular_start(sys, state)
    }

    /// Forgets what the steps carry over (the predictor's history, the reused end `Phi_q` and
    /// stage Jacobian, the acceleration and gradient histories).
    fn forget(&mut self) {
        self.hist_valid = false;
        self.hist_len = 0;
        self.end_phiq_valid = false;
        self.jac_valid = false;
        self.aa_theta = 0.0;
        self.w_skip_left = 0;
        self.mlhist.clear();
    }

    /// The checks of a step's input: the step size, the state's sizes and finiteness, the
    /// model the integrator was built for.
    fn check_step(&self, sys: &System, state: &State, h: f64) -> Result<(), SolveError> {
        if !(h.is_finite() && h > 0.0) {
            return Err(SolveError::InvalidStep { h });
        }
        state.check(sys)?;
        if sys.n_coords() != self.n || sys.n_constraints() != self.m {
            return Err(SolveError::Dimension {
                what: "system (the integrator was built for another model)",
                expected: self.n,
                got: sys.n_coords(),
            });
        }
        if !state.is_finite() {
            return Err(SolveError::NonFinite {
                t: state.t,
                what: "state before step",
            });
        }
        Ok(())
    }

    /// One step of the scheme itself (on input [`Galerkin::check_step`] passed).
    fn scheme_step(
        &mut self,
        sys: &System,
        state: &mut State,
        h: f64,
    ) -> Result<StepStats, SolveError> {
        let (n, m, s) = (self.n, self.m, self.tab.s);
        let t = state.t;
        self.qk.copy_from_slice(state.q.as_slice());
        for i in 0..n {
            self.hvk[i] = h * state.v[i];
        }
        // (reuse: Phi_q at the end of the previous step, which is where this one starts)
        let reuse = self.end_phiq_valid && self.hist_q == self.qk;
        self.start_phiq(sys, t, reuse);
        self.end_phiq_valid = false;
        self.gk = self.opts.gamma * self.kappa * h.powi(2 * s as i32);
        self.mlhist.first = self.hist_valid
            && (self.hist_t - t).abs() <= 1e-9 * h
            && (self.hist_h - h).abs() <= 1e-9 * h
            && self.hist_q.as_slice() == self.qk.as_slice();
        self.predict(sys, state, h)?;
        let stats = self.newton(sys, t, h)?;
        // End momentum from the discrete momentum balance, the sum of the stage equations
        // (docs/symplectic.md, "End momentum"): p- = D_s L_d equals
        //   p_k - h sum_j b_j grad U(q_j) - h sum_(nu<s) Phi_q(Q_nu)^T lt_nu
        // at the solution, but this form does not divide the Newton error of the displacements
        // by h, and the momentum identity holds to the rounding of the increment instead of to
        // that of the coefficients (whose last-bit errors would add a bias of about eps |p| per
        // step, the same sign every step). As a velocity: v- = v_k - h M^-1 (...).
        let f = &mut self.tn[0];
        f.fill(0.0);
        for (&bj, gj) in self.tab.b.iter().zip(self.gj.chunks_exact(n)) {
            for (fi, &g) in f.iter_mut().zip(gj) {
                *fi += bj * g;
            }
        }
        if !self.ml.is_empty() {
            // (D_1 + D_2) E_d = h^3 de/dq (qbar, v) = h mlq
            for (fi, &g) in f.iter_mut().zip(&self.mlq) {
                *fi -= g;
            }
        }
        if let Some(sp) = &self.sparse {
            let lts = self.x[s * n..].chunks_exact(m);
            for (grads, lt) in self.grads[..s].iter().zip(lts) {
                add_transpose(&sp.rows, grads, lt, f);
            }
        } else if m > 0 {
            let lts = self.x[s * n..].chunks_exact(m);
            for (phiq, lt) in self.phiq[..s].iter().zip(lts) {
                // (Phi_q^T lt)_i: column i of the column-major m x n Phi_q
                for (fi, col) in f.iter_mut().zip(phiq.as_slice().chunks_exact(m)) {
                    *fi += col.iter().zip(lt).map(|(a, b)| a * b).sum::<f64>();
                }
            }
        }
        for (((vm, &v), &mi), &fi) in self
            .vm
            .iter_mut()
            .zip(state.v.iter())
            .zip(&self.minv)
            .zip(f.iter())
        {
            *vm = v - h * mi * fi;
        }
        let qn1 = &self.qn[s * n..(s + 1) * n];
        let t1 = t + h;
        let planar_sparse = self.sparse.as_deref_mut().and_then(|sp| {
            let schur = sp.schur.as_mut()?;
            Some((schur, &mut sp.pv))
        });
        if let Some((schur, pv)) = planar_sparse {
            // M^-1-orthogonal projection onto Phi_q v + Phi_t = 0, O(N) (docs/symplectic.md)
            schur.update(sys, qn1);
            self.end_phiq_valid = false;
            schur.factor(&self.minv).map_err(|_| SolveError::Singular {
                t: t1,
                what: "momentum projection matrix Phi_q M^-1 Phi_q^T",
                detail: "redundant constraints or a singular configuration".into(),
            })?;
            sys.phi_t(qn1, t1, &mut self.mu);
            schur.apply(&self.vm, pv);
            for (mu, &pv) in self.mu.iter_mut().zip(pv.iter()) {
                *mu += pv;
            }
            schur.solve_in_place(&mut self.mu);
            schur.add_weighted_transpose(-1.0, &self.minv, &self.mu, &mut self.vm);
        } else if let Some(es) = self.end_solve.as_deref_mut() {
            // singular mass matrices: M v + Phi_q^T mu = M v_k - h f, Phi_q v = -Phi_t
            for (i, p) in es.p.iter_mut().enumerate() {
                *p = sys.mass_diag()[i] * state.v[i] - h * f[i];
            }
            sys.phi_t(qn1, t1, &mut es.r);
            for r in es.r.iter_mut() {
                *r = -*r;
            }
            es.solve.factor(sys, qn1, t1)?;
            es.solve.solve(&es.p, &es.r, &mut self.vm, &mut self.mu)?;
            if let Some(sp) = self.sparse.as_deref_mut() {
                sp.gather(sys, qn1, t1, &mut self.grads[s]);
            } else {
                sys.phi_q(qn1, t1, &mut self.phiq[s]);
            }
            self.end_phiq_valid = true;
        } else if m > 0 {
            sys.phi_q(qn1, t1, &mut self.phiq[s]);
            self.end_phiq_valid = true;
            let g = &self.phiq[s];
            {
                let mut sm = self.proj.matrix_mut();
                for c in 0..m {
                    for r in c..m {
                        sm[(r, c)] = (0..n).map(|k| g[(r, k)] * self.minv[k] * g[(c, k)]).sum();
                    }
                }
            }
            self.proj
                .factor_in_place()
                .map_err(|_| SolveError::Singular {
                    t: t1,
                    what: "momentum projection matrix Phi_q M^-1 Phi_q^T",
                    detail: "redundant constraints or a singular configuration".into(),
                })?;
            sys.phi_t(qn1, t1, &mut self.mu);
            for r in 0..m {
                self.mu[r] += (0..n).map(|k| g[(r, k)] * self.vm[k]).sum::<f64>();
            }
            self.proj.solve_in_place(&mut self.mu);
            for k in 0..n {
                let acc: f64 = (0..m).map(|r| g[(r, k)] * self.mu[r]).sum();
                self.vm[k] -= self.minv[k] * acc;
            }
        }
        for i in 0..n {
            state.q[i] = qn1[i];
            state.v[i] = self.vm[i];
        }
        state.t = t1;
        // history for the predictor
        let contiguous = self.hist_valid
            && (self.hist_t - t).abs() <= 1e-9 * h
            && (self.hist_h - h).abs() <= 1e-9 * h
            && self.hist_q.as_slice() == self.qk.as_slice();
        let dim = self.dim;
        let keep = if contiguous {
            self.hist_len.min(MAX_PREDICTOR_ORDER)
        } else {
            0
        };
        self.mlhist.record(contiguous, &self.mlq, &self.mlv);
        self.hist_multi.copy_within(0..keep * dim, dim);
        self.hist_multi[..dim].copy_from_slice(&self.x);
        self.hist_len = keep + 1;
        self.hist_q.copy_from_slice(state.q.as_slice());
        self.hist_t = state.t;
        self.hist_h = h;
        self.hist_valid = true;
        Ok(stats)
    }
}
