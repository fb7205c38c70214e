//! The predictor and the simplified Newton iteration of the stage equations
//! (`docs/symplectic.md`, "Predictor and Newton").

use super::Galerkin;
use crate::options::ANDERSON_START_CONTRACTION;
use mbd_model::System;
use mbd_solve::linalg::max_abs as norm_inf;
use mbd_solve::{SolveError, State, StepStats};

impl Galerkin {
    /// Initial guess of the unknowns.
    pub(super) fn predict(
        &mut self,
        sys: &System,
        state: &State,
        h: f64,
    ) -> Result<(), SolveError> {
        let (n, m, s) = (self.n, self.m, self.tab.s);
        let s1 = s + 1;
        let usable = self.hist_valid
            && (self.hist_t - state.t).abs() <= 1e-9 * h
            && (self.hist_h - h).abs() <= 1e-9 * h
            && self.hist_q.as_slice() == state.q.as_slice();
        let p = self.opts.predictor_order;
        if usable && p > 0 && self.hist_len > p {
            // multistep: the degree-p polynomial through the last p + 1 solutions at t_k + h,
            // x_{k+1} = sum_i (-1)^i C(p+1, i+1) x_{k-i}
            let dim = self.dim;
            self.x.fill(0.0);
            let mut c = (p + 1) as f64;
            for i in 0..=p {
                let xi = &self.hist_multi[i * dim..(i + 1) * dim];
                for (a, b) in self.x.iter_mut().zip(xi) {
                    *a += c * b;
                }
                // next coefficient: -C(p+1, i+2) = -C(p+1, i+1) (p - i) / (i + 2)
                c = -c * (p - i) as f64 / (i + 2) as f64;
            }
        } else if usable {
            // extrapolate the previous step's polynomial: Q_nu ~ sum_mu l_mu(1 + tau_nu) Q'_mu,
            // written in displacements from q_k = Q'_s
            for nu in 1..=s {
                for i in 0..n {
                    let zs = self.hist_multi[(s - 1) * n + i];
                    let mut acc = 0.0;
                    for mu in 0..=s {
                        let zm = if mu == 0 {
                            0.0
                        } else {
                            self.hist_multi[(mu - 1) * n + i]
                        };
                        acc += self.tab.e[(nu - 1) * s1 + mu] * (zm - zs);
                    }
                    self.x[(nu - 1) * n + i] = acc;
                }
            }
            self.x[s * n..].copy_from_slice(&self.hist_multi[s * n..self.dim]);
        } else {
            let (q, v) = (state.q.as_slice(), state.v.as_slice());
            match (&mut self.acc, &mut self.sparse) {
                (Some(acc), _) => {
                    acc.solve(sys, q, v, state.t, &mut self.acc_a, &mut self.acc_l)?
                }
                (None, Some(sp)) => {
                    sp.acc
                        .solve(sys, q, v, state.t, &mut self.acc_a, &mut self.acc_l)?
                }
                (None, None) => {}
            }
            for nu in 1..=s {
                let th = self.tab.tau[nu] * h;
                for i in 0..n {
                    self.x[(nu - 1) * n + i] = th * state.v[i] + 0.5 * th * th * self.acc_a[i];
                }
            }
            for nu in 0..s {
                for r in 0..m {
                    self.x[s * n + nu * m + r] = self.tab.w[nu] * self.acc_l[r];
                }
            }
        }
        Ok(())
    }

    pub(super) fn newton(&mut self, sys: &System, t: f64, h: f64) -> Result<StepStats, SolveError> {
        let o = self.opts.newton;
        // Tolerance: relative to the positions, not the angles (which grow without bound on
        // rotating bodies), plus the round-off floor of the constraints, which is set by the
        // angles: cos and sin of theta carry an error of about eps |theta|. (NaN-safe: the
        // state was checked finite, but a NaN here would make every test below pass.)
        let pscale = 1.0 + position_scale(&self.qk);
        let qscale = 1.0 + norm_inf(&self.qk);
        let tol = o.tol * pscale + 4.0 * f64::EPSILON * qscale;
        let sn = self.tab.s * self.n;
        self.residual(sys, t, h)
            .map_err(|e| self.fault(sys, t, h, e, f64::INFINITY, 0))?;
        let mut res = norm_inf(&self.r);
        let mut evals = 1;
        if self.mlhist.lagged && res <= tol {
            // the predictor passes with extrapolated modified-Lagrangian gradients
            // (`modlag.rs`): decide on evaluated ones
            self.residual(sys, t, h)
                .map_err(|e| self.fault(sys, t, h, e, f64::INFINITY, 0))?;
            res = norm_inf(&self.r);
            evals += 1;
        }
        let mut it = 0;
        let fail = |res: f64, it: usize, s: usize, qk: &[f64], hvk: &[f64]| {
            let near = near_rank_loss(sys, t, h, qk, hvk);
            let stalled = res.is_finite() && res <= 1e3 * tol;
            let named = || {
                near.iter()
                    .map(|e| format!("{} (joints {})", e.equation, e.joints.join(", ")))
                    .collect::<Vec<_>>()
                    .join("; ")
            };
            if stalled && !near.is_empty() {
                // stalled a few digits above the tolerance where the step passes, or is a few
                // steps from, a configuration within 1e-2 of rank loss: the stage Jacobian is
                // near-singular there, and a smaller h does not change that
                SolveError::Singular {
                    t,
                    what: mbd_solve::STAGES_STALLED_NEAR_RANK_LOSS,
                    detail: format!(
                        "symplectic ({s},{s}) stage equations, h = {h}: Newton stalled near \
                         round-off, residual {res:.2e} after {it} iterations (tolerance \
                         {tol:.1e}), at a singular configuration of the mechanism, where a \
                         smaller h does not help: rank deficiency {} (equations within 1e-2 of \
                         dependence: {}) (`mbd solvers` lists the other solvers)",
                        near.len(),
                        named()
                    ),
                }
            } else if !near.is_empty() {
                // no convergence at a step that passes (or nearly reaches) rank loss: the
                // singular configuration, not the step length, is the cause
                SolveError::Singular {
                    t,
                    what: mbd_solve::STAGES_NEAR_RANK_LOSS,
                    detail: format!(
                        "symplectic ({s},{s}) stage equations, h = {h}: Newton residual {res:.2e} \
                         after {it} iterations; rank deficiency {} (equations within 1e-2 of \
                         dependence: {}) (`mbd solvers` lists the other solvers)",
                        near.len(),
                        named()
                    ),
                }
            } else if stalled {
                // stalled a few digits above the tolerance at a regular configuration: the
                // stage Jacobian is ill-conditioned at this step length
                SolveError::Newton {
                    t,
                    residual: res,
                    iterations: it,
                    context: format!(
                        "symplectic ({s},{s}) stage equations, h = {h}: stalled near round-off \
                         (tolerance {tol:.1e}) at a regular configuration, where the stage \
                         Jacobian is ill-conditioned for this step; a smaller h may converge"
                    ),
                }
            } else {
                // a step can be too long for the fastest modes of the model, e.g. of a long
                // chain under tension, with no solution near the prediction
                // (docs/symplectic.md section 2)
                SolveError::Newton {
                    t,
                    residual: res,
                    iterations: it,
                    context: format!(
                        "symplectic ({s},{s}) stage equations, h = {h}; a smaller h may \
                         converge (the step may be too long for the model's fastest motion)"
                    ),
                }
            }
        };
        if !res.is_finite() {
            return Err(fail(res, 0, self.tab.s, &self.qk, &self.hvk));
        }
        // simplified Newton: one Jacobian per step (or the last step's, if reuse is on), kept
        // while it contracts by 4x per iteration, recomputed every `jacobian_every` iterations
        let planar_modified = !self.ml.is_empty() && self.end_solve.is_none();
        let mut need_jacobian = !(self
            .opts
            .reuse_jacobian
            .keeps(self.sparse.is_some(), planar_modified)
            && self.jac_valid
            && (self.jac_h - h).abs() <= 1e-12 * h
            && self.jac_gk == self.gk);
        let mut chord = !need_jacobian;
        let mut since_jacobian = 0usize;
        let mut prev_step = f64::INFINITY;
        // Converged when the residual and the last displacement update are both below the
        // tolerance (or by the contraction estimate below), so never on the predictor alone:
        // its error is smooth in time and, accepted unchanged, accumulates coherently from step
        // to step (docs/symplectic.md, "Newton").
        let mut last_dz = f64::INFINITY;
        // Anderson mixing of the updates (`mbd_linalg::Anderson`, docs/symplectic.md), switched
        // on for the rest of this Jacobian's iterations once two plain updates contract more
        // slowly than `ANDERSON_START_CONTRACTION` (an iteration matrix that leaves out part of
        // the Jacobian, e.g. the modified Lagrangian's couplings through `S^-1` on a long
        // chain). Until then nothing is recorded (a fast iteration pays nothing); the history
        // starts from those two plain updates. `theta_chord` is their contraction, which the
        // stopping rule keeps using. With a stage Jacobian kept from a step whose iteration
        // needed the mixing, it is on from the first update and kept only if the second
        // (plain) update again contracts slowly.
        let mut aa_on = chord && self.aa_theta > 0.0;
        let mut aa_allowed = self.opts.anderson_depth > 0;
        let mut theta_chord = self.aa_theta;
        let mut lambda_prev = 1.0;
        self.aa.reset();
        while !(res <= tol && last_dz <= tol) {
            if it >= o.max_iter {
                return Err(fail(res, it, self.tab.s, &self.qk, &self.hvk));
            }
            // (while the mixed updates contract, the iteration matrix is kept)
            if need_jacobian || (since_jacobian >= o.jacobian_every && !aa_on) {
                self.jacobian(sys, t, h)
                    .map_err(|e| self.fault(sys, t, h, e, res, it))?;
                self.jac_valid = true;
                self.jac_h = h;
                self.jac_gk = self.gk;
                since_jacobian = 0;
                need_jacobian = false;
                chord = false;
                prev_step = f64::INFINITY;
                self.aa.reset();
                aa_on = false;
            }
            since_jacobian += 1;
            // the last update stays in `dx_prev` (the history mixing starts from)
            std::mem::swap(&mut self.dx, &mut self.dx_prev);
            for i in 0..self.dim {
                self.dx[i] = -self.r[i];
            }
            let mut dx = std::mem::take(&mut self.dx);
            self.solve_stage(&mut dx);
            self.dx = dx;
            if res <= tol {
                // The residual is converged, but no update has been made yet (the predictor's
                // residual was already below the tolerance) or the last one was not below the
                // tolerance: the error left is then about the size of this update, smooth in
                // time, and would accumulate from step to step. This update is applied without
                // a new residual: what it leaves is quadratic in it (or theta times it), and the
                // forces and Phi_q at the interior points that the end momentum uses are those
                // of the previous iterate, whose displacements differ by this update (of the
                // order of the tolerance): an error of that order times h in the momentum.
                for (x, d) in self.x.iter_mut().zip(&self.dx) {
                    *x += d;
                }
                self.place_control_points();
                it += 1;
                break;
            }
            // simplified-Newton stopping rule (Hairer & Wanner, IV.8): with the contraction
            // theta estimated from two updates with the same Jacobian, the error left after
            // this update is about theta / (1 - theta) |dZ|; when that is below the tolerance
            // the update is applied and only the constraints are checked at the result, with
            // the forces and, once they pass, Phi_q at the interior control points (the
            // momentum rows are not re-evaluated, nor are the preadjustment terms: the end
            // momentum takes grad W_s and the modified-Lagrangian gradients from the previous
            // iterate, an error of their Hessians times this update and times h^(2s), far below
            // the tolerance; docs/symplectic.md sections 5, 5a and "Newton")
            let dz = norm_inf(&self.dx[..sn]);
            if aa_on && self.aa.is_empty() && prev_step.is_finite() {
                // the second update of a mixing carried over from the last step, still plain:
                // the mixing goes on only if it still contracts slowly
                theta_chord = dz / prev_step;
                if theta_chord.is_nan() || theta_chord <= ANDERSON_START_CONTRACTION {
                    aa_on = false;
                    self.aa.reset();
                }
            }
            if prev_step.is_finite() && dz.is_finite() {
                // (with mixing on, the ratio of the updates understates the plain update's
                // contraction, which sets the error this branch leaves)
                let theta = if aa_on {
                    theta_chord.max(dz / prev_step)
                } else {
                    dz / prev_step
                };
                let left = theta / (1.0 - theta) * dz;
                if theta < 0.5 && left <= 0.1 * tol {
                    for (x, d) in self.x.iter_mut().zip(&self.dx) {
                        *x += d;
                    }
                    self.kinematics_with(sys, t, h, false)
                        .map_err(|e| self.fault(sys, t, h, e, res, it))?;
                    self.constraint_rows(sys, t, h);
                    evals += 1;
                    it += 1;
                    let cres = norm_inf(&self.r[sn..]);
                    if cres <= tol {
                        // the end momentum takes Phi_q at the interior control points: at the
                        // previous iterate it would be off by Hess Phi times this update, which
                        // is only bounded by tol / theta, and that error is smooth in time
                        // (an energy drift of about 1e-11 per step on the rod at 90 degrees,
                        // h = 0.025, s = 2)
                        self.refresh_interior_phiq(sys, t, h);
                        res = cres.max(left);
                        break;
                    }
                    // the constraints are not met yet: complete the residual (with the
                    // preadjustment terms here) and go on
                    self.kinematics(sys, t, h)
                        .map_err(|e| self.fault(sys, t, h, e, res, it))?;
                    self.momentum_rows(sys, t, h);
                    res = norm_inf(&self.r);
                    prev_step = dz;
                    lambda_prev = 1.0;
                    continue;
                }
            }
            // once switched on, every update is recorded and mixed
            let mut mixed = aa_on && self.aa.mix(&self.x, &mut self.dx) > 0;
            self.xt.copy_from_slice(&self.x);
            let mut lambda = 1.0;
            let mut halvings = 0;
            let res_before = res;
            loop {
                for i in 0..self.dim {
                    self.x[i] = self.xt[i] + lambda * self.dx[i];
                }
                self.residual(sys, t, h)
                    .map_err(|e| self.fault(sys, t, h, e, res, it))?;
                evals += 1;
                let rn = norm_inf(&self.r);
                if (rn.is_finite() && rn < res) || halvings >= o.max_halvings {
                    res = rn;
                    break;
                }
                if mixed {
                    // the mixed update did not lower the residual: the plain one, and no
                    // more mixing with this Jacobian
                    self.dx.copy_from_slice(self.aa.last_update());
                    self.aa.reset();
                    mixed = false;
                    aa_on = false;
                    aa_allowed = false;
                    continue;
                }
                lambda *= 0.5;
                halvings += 1;
            }
            it += 1;
            let step = lambda * norm_inf(&self.dx[..sn]);
            let poor = step > 0.25 * prev_step && step > 1e3 * f64::EPSILON * qscale;
            // (a residual that grew but is below the tolerance is round-off: the update from
            // an already converged predictor is kept)
            let worse = res > res_before && res > tol;
            if poor || !res.is_finite() || (chord && worse) {
                // the Jacobian does not contract well: recompute it here
                need_jacobian = true;
                last_dz = step;
                if !res.is_finite() || worse {
                    last_dz = f64::INFINITY;
                    self.x.copy_from_slice(&self.xt);
                    self.residual(sys, t, h)
                        .map_err(|e| self.fault(sys, t, h, e, res, it))?;
                    evals += 1;
                    res = norm_inf(&self.r);
                }
                prev_step = f64::INFINITY;
                continue;
            }
            if aa_allowed && !aa_on && !mixed && prev_step.is_finite() {
                let theta = step / prev_step;
                if theta > ANDERSON_START_CONTRACTION {
                    aa_on = true;
                    theta_chord = theta;
                    // the last two plain updates start the history
                    self.aa
                        .start(&self.xt, &self.dx_prev, lambda_prev, &self.dx);
                }
            }
            prev_step = step;
            lambda_prev = lambda;
            last_dz = step;
            if !res.is_finite() {
                return Err(fail(res, it, self.tab.s, &self.qk, &self.hvk));
            }
            if step <= o.step_tol * qscale {
                // stagnated at round-off: accept if the residual is sane
                if res <= 1e-8 * qscale {
                    break;
                }
                if chord {
                    // with a Jacobian kept from an earlier step (near a singular
                    // configuration it can stop Newton short of the solution): a new one here
                    need_jacobian = true;
                    prev_step = f64::INFINITY;
                    continue;
                }
                return Err(fail(res, it, self.tab.s, &self.qk, &self.hvk));
            }
        }
        self.aa_theta = if aa_on { theta_chord } else { 0.0 };
        Ok(StepStats {
            newton_iterations: it,
            residual: res,
            rhs_evals: evals,
            objective_evals: 0,
            ..Default::default()
        })
    }
}

/// `max |x_i|, |y_i|` over the bodies (every third coordinate is an angle); NaN if any is NaN.
fn position_scale(q: &[f64]) -> f64 {
    let mut m = 0.0f64;
    for c in q.chunks(3) {
        let a = norm_inf(&c[..2.min(c.len())]);
        if a.is_nan() {
            return f64::NAN;
        }
        m = m.max(a);
    }
    m
}

/// The equations within 1e-2 of dependence (`System::nearly_dependent_at`, weighted like
/// `M^-1`) at the configurations a step from `qk` passes or is about to pass: its start and,
/// along the start velocity `hvk` (`h v_k`), its middle, its end and the points up to three
/// steps ahead and behind ([`NEAR_STEP_FRACTIONS`]; a step that crosses a singular
/// configuration fails there, not at its start, and one a few steps short of it can fail
/// too). A point of that line that has left the constraints by more
/// than [`OFF_MANIFOLD`] of an equation's natural unit (`System::equation_scale`) is skipped:
/// the step is then too long for a straight line to say where it goes (the rank of `Phi_q`
/// there says nothing about the mechanism; unit directors of a spatial body extrapolated
/// along their velocity, for one, are neither unit nor orthogonal). Empty for a step through
/// regular configurations. An error path: allocates.
fn near_rank_loss(
    sys: &System,
    t: f64,
    h: f64,
    qk: &[f64],
    hvk: &[f64],
) -> Vec<mbd_model::RedundantEquation> {
    let scales = sys.equation_scales();
    let mut phi = vec![0.0; sys.n_constraints()];
    NEAR_STEP_FRACTIONS
        .iter()
        .filter_map(|&th| {
            let q: Vec<f64> = qk.iter().zip(hvk).map(|(q, d)| q + th * d).collect();
            let tt = t + th * h;
            // the start is on the constraints; every other point is extrapolated
            if th != 0.0 {
                sys.phi(&q, tt, &mut phi);
                let off = phi
                    .iter()
                    .zip(&scales)
                    .any(|(p, s)| p.is_nan() || p.abs() > OFF_MANIFOLD * s);
                if off {
                    return None;
                }
            }
            Some(sys.nearly_dependent_at(&q, tt, 1e-2))
        })
        .find(|near| !near.is_empty())
        .unwrap_or_default()
}

/// The points of a step's straight line `q_k + th h v_k` that [`near_rank_loss`] tests, nearest
/// first: the step itself (`th` = 0, 1/2, 1) and up to three steps on either side. The stage
/// equations lose their conditioning over a neighbourhood of a singular configuration that
/// spans a few steps (docs/symplectic.md, section 1), so a failure that close is the
/// configuration's, not the step length's.
const NEAR_STEP_FRACTIONS: [f64; 9] = [0.0, 0.5, 1.0, 2.0, -1.0, 3.0, -2.0, 4.0, -3.0];

/// How far (relative to an equation's natural unit) a point on a step's straight line may
/// have left the constraints for its rank to say something about the step ([`near_rank_loss`]).
const OFF_MANIFOLD: f64 = 0.1;

impl Galerkin {
    /// A singular matrix met at a Newton iterate (the stage Jacobian, the preadjustment's
    /// projected metric) of a step through regular configurations ([`near_rank_loss`] empty,
    /// which leaves out the redundant equations found at build time): the iterate is far from
    /// any solution, i.e. the step is too long for the motion, so the error is Newton's, with
    /// that advice. Near rank loss it stays the singular error.
    fn fault(
        &self,
        sys: &System,
        t: f64,
        h: f64,
        e: SolveError,
        res: f64,
        it: usize,
    ) -> SolveError {
        let s = self.tab.s;
        let at = if it == 0 {
            "the predictor"
        } else {
            "an iterate"
        };
        match e {
            SolveError::Singular { what, .. }
                if near_rank_loss(sys, t, h, &self.qk, &self.hvk).is_empty() =>
            {
                SolveError::Newton {
                    t,
                    residual: res,
                    iterations: it,
                    context: format!(
                        "symplectic ({s},{s}) stage equations, h = {h}: singular {what} at \
                         {at}, at a regular configuration; a smaller h may converge (the step \
                         may be too long for the model's fastest motion)"
                    ),
                }
            }
            e => e,
        }
    }
}
