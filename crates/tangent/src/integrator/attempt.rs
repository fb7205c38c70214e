//! One attempted step of [`TangentRk`]: the stage maps with their Newton starting points and
//! the end-point map, and the `eta` history the starting points are extrapolated from.

use super::*;

impl TangentRk {
    /// One attempted step of size `h` from the chart centre (at time `t`) into `xnew`; the
    /// embedded error estimate in chart coordinates (if the tableau has one) is left in
    /// `rk.err`.
    ///
    /// Newton starting points (they change only where the chord iteration starts, never its
    /// limit). After accepted fixed steps of the same size, each stage map starts from the
    /// normal coordinates of the same stage in the last steps, taken in a basis that does not
    /// depend on how the chart was factored (the dense chart's canonical `Q1`, the signs that
    /// make `R`'s diagonal positive, `TangentChart::canonical_from_zeta`; the sparse chart's
    /// `eta`, the coefficients of `Df(x_c)^T eta`), extrapolated by a polynomial in the step
    /// index (they are smooth functions of the step's start point along the trajectory), and
    /// corrected by the extrapolation error the latest earlier stage `j` of this step showed,
    /// scaled by `|Y_i|^2 / |Y_j|^2`. Without such history: for scleronomic constraints,
    /// stage `i` starts from the normal coordinates the latest earlier stage `j` with
    /// `Y_j != 0` converged to, scaled by `|Y_i|^2 / |Y_j|^2` (the manifold's normal offset
    /// above the tangent plane grows quadratically); otherwise (first such stage, rheonomic
    /// constraints) from the plain RK stage value `x_c + h sum_j a_ij F_j` (tangent part
    /// exactly `U Y_i`). Stage maps may stop on the predicted residual
    /// ([`TangentChart::map_predicted`]); the end point's residual is verified. The end point starts from the
    /// plain RK result `x_c + h sum_j b_j F_j`, whose normal part is the RK quadrature of
    /// `zeta' = Q1^T F` and so accurate to the method's order. For a FSAL tableau (last stage
    /// at `c = 1` with `a_sj = b_j`, as DOPRI5) the last stage point is the end point. With
    /// [`IterationMatrix::Interpolated`] stage `i` iterates with `Df Q1` interpolated to `c_i`.
    pub(super) fn attempt(&mut self, sys: &System, t: f64, h: f64) -> Result<AttemptWork, Attempt> {
        let n = self.n;
        let mm = 2 * self.m;
        let s = self.stages;
        let newton = self.options.newton;
        // interior stage maps: inexact after an accepted step of the same size (to rounding:
        // `mbd_solve::run` passes `t_next - t`, which differs from the nominal step in the
        // last bits)
        let (usable, recent_ok) = self.hist.usable(self.path.rcond(), RCOND_DRIFT);
        let follows = same_step(self.hist.h, h) && same_time(self.hist.t, t) && recent_ok;
        let stage_newton = if follows {
            NewtonSettings {
                tol: self.stage_tol.max(newton.tol),
                ..newton
            }
        } else {
            newton
        };
        let interpolate = self.options.iteration_matrix == IterationMatrix::Interpolated;
        // stage 0 at (t, xi = 0) is the centre itself when the centre is on the manifold
        let centre_ok = self.cur_ok && same_time(self.cur_t, t);
        let quadratic = !sys.is_rheonomic();
        // ... and its accelerations may come from the chart's QR (scleronomic constraints)
        // where the last step's stage solves were well conditioned: no index-1 matrix is
        // factored there, so the bridge could not correct that stage, and takes the condition
        // estimate it records with the step's start from stage 1
        let centre_accel = centre_ok
            && quadratic
            && s >= 2
            && same_time(self.hist.t, t)
            && (!self.options.bridge || self.bridge.leaves_alone(self.last_condition));
        if !follows {
            self.hist.clear();
        }
        self.path.set_contraction_prior(follows);
        let npts = if follows { usable } else { 0 };
        let mut ylast_sq = 0.0f64;
        let mut jlast = 0usize;
        let mut work = AttemptWork {
            end_initial_residual: f64::NAN,
            ..AttemptWork::default()
        };
        let mut failure: Option<(ChartFailure, usize)> = None;
        let mut singular_stage: Option<usize> = None;
        let mut stage = 0usize;
        self.xi.fill(0.0);
        let mut bridge = self.options.bridge.then_some(&mut self.bridge);
        // the step start's accelerations are held, their condition estimate not yet
        let mut held_without_condition = false;
        if let Some(b) = bridge.as_deref_mut() {
            b.begin(t, &self.cur[..n]);
        }
        {
            let chart = &mut self.path;
            let zlast = &mut self.zeta;
            let (zplain, x, g, fx) = (&mut self.zplain, &mut self.x, &mut self.g, &mut self.fx);
            let lambda = &mut self.lambda;
            let (a_coef, c_coef) = (&self.a_coef, &self.c_coef);
            let fsal = self.fsal;
            let (eta_now, hist, eta_pred, eta_raw) = (
                &mut self.eta_now,
                &self.hist,
                &mut self.eta_pred,
                &mut self.eta_raw,
            );
            let work = &mut work;
            let failure = &mut failure;
            let singular_stage = &mut singular_stage;
            let mut rhs = |ti: f64, y: &[f64], dy: &mut [f64]| -> Result<(), SolveError> {
                let i = stage;
                if i == 1 && interpolate {
                    // Euler prediction of the end point, x_c + h F(x_c): where the iteration
                    // matrix is interpolated to
                    x.copy_from_slice(chart.centre_point());
                    axpy(h, fx, x);
                    chart.set_secondary_point(sys, x, t + h);
                }
                chart.select_iteration_matrix(c_coef[i]);
                // stage 0 at (t, xi = 0) is the centre: no starting point, and its normal
                // coordinates (zeta = eta = 0) need no conversion
                let at_centre = i == 0 && centre_ok && ti == t;
                let ysq: f64 = y.iter().map(|v| v * v).sum();
                if at_centre {
                    eta_now[..mm].fill(0.0);
                } else if npts > 0 && i > 0 {
                    // the plain extrapolation of this stage, kept for the later stages'
                    // corrections
                    let raw = &mut eta_raw[i * mm..(i + 1) * mm];
                    hist.predict(i - 1, npts, raw);
                    eta_pred.copy_from_slice(raw);
                    if jlast > 0 {
                        // correct by the extrapolation error of the latest mapped stage j,
                        // scaled like the normal offset (|Y_i|^2 / |Y_j|^2)
                        let r = ysq / ylast_sq;
                        let raw_j = &eta_raw[jlast * mm..(jlast + 1) * mm];
                        let now = &eta_now[jlast * mm..(jlast + 1) * mm];
                        for ((p, e), x) in eta_pred.iter_mut().zip(now).zip(raw_j) {
                            *p += r * (e - x);
                        }
                    }
                    chart.zeta_from_canonical(eta_pred, zplain);
                } else if quadratic && ylast_sq > 0.0 {
                    // scleronomic: the normal offset of the manifold above Y grows like |Y|^2
                    let r = ysq / ylast_sq;
                    for (z, zl) in zplain.iter_mut().zip(zlast.iter()) {
                        *z = r * zl;
                    }
                } else {
                    // the plain RK stage value's normal part
                    zplain.fill(0.0);
                    for j in 0..i {
                        let a = a_coef[i * s + j];
                        if a != 0.0 {
                            axpy(h * a, &g[j * mm..(j + 1) * mm], zplain);
                        }
                    }
                }
                let mapped = if at_centre {
                    x.copy_from_slice(chart.centre_point());
                    Ok(MapStats::default())
                } else if fsal && i + 1 == s {
                    // FSAL: this stage point is the step's end point, whose residual is verified
                    chart.map(sys, y, ti, zplain, x, &newton, false)
                } else {
                    chart.map(sys, y, ti, zplain, x, &stage_newton, true)
                };
                if !at_centre && mapped.is_ok() {
                    if ysq > 0.0 {
                        zlast.copy_from_slice(zplain);
                        ylast_sq = ysq;
                        jlast = i;
                    }
                    chart.canonical_from_zeta(zplain, &mut eta_now[i * mm..(i + 1) * mm]);
                }
                match mapped {
                    Ok(ms) => {
                        work.exact_maps += usize::from(ms.exact);
                        work.iterations += ms.iterations;
                        work.max_map_iterations = work.max_map_iterations.max(ms.iterations);
                        work.residual = ms.residual;
                    }
                    Err(e) => {
                        *failure = Some((e, i));
                        // a cheap sentinel (no allocation); the caller reads `failure`
                        return Err(SolveError::NonFinite {
                            t: ti,
                            what: "tangent chart",
                        });
                    }
                }
                let (q, v) = x.split_at(n);
                // F = (v, a): the accelerations are solved into its second half
                let (fv, acc_a) = fx.split_at_mut(n);
                let from_chart = at_centre && centre_accel && chart.centre_accel(sys, acc_a);
                let solved = if from_chart {
                    Ok(())
                } else {
                    chart.accel(sys, q, v, ti, acc_a, lambda)
                };
                if from_chart {
                    if let Some(b) = bridge.as_deref_mut() {
                        b.hold(ti, f64::NAN, acc_a);
                        held_without_condition = true;
                    }
                } else if solved.is_ok() {
                    let c = chart.condition_estimate();
                    work.condition = work.condition.max(c);
                    if let Some(b) = bridge.as_deref_mut() {
                        // near a singular configuration: the ill-determined components from
                        // the accelerations of the last step starts
                        if b.correct(chart.rows(), sys, ti, c, acc_a, lambda) {
                            work.bridged += 1;
                        }
                        if i == 0 {
                            b.hold(ti, c, acc_a);
                        } else if held_without_condition {
                            b.hold_condition(c);
                            held_without_condition = false;
                        }
                    }
                }
                if let Err(e) = solved {
                    if matches!(e, SolveError::Singular { .. }) {
                        *singular_stage = Some(i);
                    }
                    return Err(e);
                }
                work.rhs_evals += 1;
                fv.copy_from_slice(v);
                chart.split(fx, &mut g[i * mm..(i + 1) * mm], dy);
                stage += 1;
                Ok(())
            };
            if let Err(e) = self.rk.step(&mut rhs, t, &mut self.xi, h) {
                return Err(match (failure.take(), *singular_stage) {
                    // a map at the step's end time that failed at a singular configuration
                    (Some((f, i)), _) if self.c_coef[i] == 1.0 => {
                        match self.path.singular_error_at(
                            sys,
                            &self.x[..n],
                            t + h,
                            SINGULAR_REPORT_TOL,
                        ) {
                            Some(e) => Attempt::SingularEnd(e),
                            None => Attempt::Chart(f),
                        }
                    }
                    (Some((f, _)), _) => Attempt::Chart(f),
                    // the step's start point itself: a singular configuration, reported with
                    // the numerical rank and the joints of the dependency
                    (None, Some(0)) => Attempt::Hard(
                        self.path
                            .singular_error(sys, t, SINGULAR_REPORT_TOL)
                            .unwrap_or(e),
                    ),
                    // a stage at the step's end time
                    (None, Some(i)) if self.c_coef[i] == 1.0 => Attempt::SingularEnd(
                        self.path
                            .singular_error_at(sys, &self.x[..n], t + h, SINGULAR_REPORT_TOL)
                            .unwrap_or(e),
                    ),
                    (None, Some(_)) => Attempt::Stage(e),
                    (None, None) => Attempt::Hard(e),
                });
            }
        }
        let t1 = t + h;
        if self.fsal {
            // the last stage was evaluated at xi = h sum b_j k_j, t + h: it is the end point
            self.xnew.copy_from_slice(&self.x);
        } else {
            self.path.select_iteration_matrix(1.0);
            self.zeta.fill(0.0);
            for j in 0..s {
                let b = self.b_coef[j];
                if b != 0.0 {
                    axpy(h * b, &self.g[j * mm..(j + 1) * mm], &mut self.zeta);
                }
            }
            match self.path.map(
                sys,
                &self.xi,
                t1,
                &mut self.zeta,
                &mut self.xnew,
                &newton,
                false,
            ) {
                Ok(ms) => {
                    work.exact_maps += usize::from(ms.exact);
                    work.iterations += ms.iterations;
                    work.max_map_iterations = work.max_map_iterations.max(ms.iterations);
                    work.residual = ms.residual;
                    work.end_initial_residual = ms.initial_residual;
                }
                Err(f) => {
                    return Err(
                        match self.path.singular_error_at(
                            sys,
                            &self.xnew[..n],
                            t1,
                            SINGULAR_REPORT_TOL,
                        ) {
                            Some(e) => Attempt::SingularEnd(e),
                            None => Attempt::Chart(f),
                        },
                    )
                }
            }
        }
        if self.xnew.iter().any(|x| !x.is_finite()) {
            return Err(Attempt::Hard(SolveError::NonFinite {
                t: t1,
                what: "state after tangent-space step",
            }));
        }
        Ok(work)
    }

    /// Records the accepted attempt's `eta` (a step of size `h` ending at `t_end`) and the
    /// largest condition estimate of its stage solves.
    pub(super) fn commit_history(&mut self, h: f64, t_end: f64, work: &AttemptWork) {
        let end_initial_residual = work.end_initial_residual;
        self.last_condition = work.condition;
        let (ratio, tol) = (self.options.stage_tol_ratio, self.options.newton.tol);
        self.stage_tol = if ratio > 0.0 && end_initial_residual.is_finite() {
            (ratio * end_initial_residual).max(tol)
        } else {
            tol
        };
        self.hist
            .commit(&self.eta_now[2 * self.m..], self.path.rcond());
        self.hist.h = h;
        self.hist.t = t_end;
    }
}
