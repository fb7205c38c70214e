//! The tangent-space Runge-Kutta integrator: fixed steps ([`Integrator`]) and adaptive steps
//! ([`TangentRk::integrate_adaptive`]).

use crate::chart::{ChartFailure, MapStats, NewtonSettings, TangentChart};
use crate::error::TangentError;
use crate::kernels::axpy;
use mbd_model::System;
use mbd_solve::{
    AccelerationSolver, ButcherTableau, ExplicitRk, Flow, Integrator, Observer, SolveError, State,
    StepController, StepStats,
};

/// The matrix of the chord Newton iteration of the chart maps (the limit, the point of the
/// chart, is the same for both; only the speed differs).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum IterationMatrix {
    /// `Df(x_c) Q1 = R^T`, factored once per chart: the paper's chord iteration (the
    /// default). Contraction factor `O(h)` per iteration; each iteration costs one residual
    /// evaluation and one `2n x 2m` product.
    #[default]
    Centre,
    /// `Df Q1` interpolated linearly between the centre and the Euler prediction of the end
    /// point, `x_c + h F(x_c)`: one more evaluation of `Df` per step, and each iteration applies
    /// a `2m x 2m` correction on top. Contraction factor `O(h^2)`: about half the iterations of
    /// [`IterationMatrix::Centre`], and a larger domain of convergence for large steps; per
    /// step it is slower on the small mechanisms of the papers (see `docs/tangent.md`).
    Interpolated,
    /// Starts each chart from the centre's `R^-T` and improves the iteration's inverse matrix
    /// by good Broyden rank-one updates after every correction, carried from one map of the
    /// step to the next ([`TangentChart::set_broyden`]): superlinear convergence for `O(n m)`
    /// more work per iteration, no extra `Df`. On the manipulator it saves a third of the
    /// iterations at `h = 0.01` but costs more per step than the centre chord (the residual is
    /// cheap there; `docs/tangent.md`), so it is not the default.
    Broyden,
}

/// Settings of [`TangentRk`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TangentOptions {
    /// The chord Newton iteration of the chart map (tolerance 1e-13 on `||(Phi, Phidot)||_inf`
    /// by default).
    pub newton: NewtonSettings,
    /// The chord iteration's matrix (default [`IterationMatrix::Centre`]).
    pub iteration_matrix: IterationMatrix,
    /// Automatic step halving on chart failure in fixed-step mode: a step whose chart map fails
    /// is redone as two half steps (each re-centring the chart), recursively up to this depth
    /// (so at most `2^max_halvings` sub-steps). Every halving is counted in
    /// [`TangentStats::halvings`]. 0 turns it off: a chart failure is then an error at once.
    /// Default 4. At most 30.
    pub max_halvings: u32,
    /// Relative threshold on the diagonal of `R` (QR of `Df^T`) below which the configuration
    /// counts as singular (an error). Default 1e-8.
    pub singular_tol: f64,
    /// Largest `||(Phi, Phidot)||_inf` accepted for the state handed to a step (it is projected
    /// onto the manifold by the first chart map). Larger is an error: project the state first
    /// (`System::project`). Default 1e-8.
    pub consistency_tol: f64,
    /// Inexact stage maps: after an accepted step of the same size, the chart maps of the
    /// interior Runge-Kutta stages stop at `max(newton.tol, stage_tol_ratio * E)`, where `E` is
    /// the constraint residual `||f||_inf` of the previous step's plain RK end point
    /// `x_c + h sum_j b_j F_j` (the end map's starting point: the method's local error in the
    /// normal directions, `O(h^(p+1))`). A stage point off the manifold by `delta` changes the
    /// step by about `h L delta`, so the ratio keeps that a small fraction of the local error
    /// the method makes anyway; the step's end point is always mapped to `newton.tol`. 0 maps
    /// every stage to `newton.tol`. Not used for FSAL tableaus (their last stage is the end
    /// point). Default 1e-2; must lie in [0, 1).
    pub stage_tol_ratio: f64,
}

impl Default for TangentOptions {
    fn default() -> Self {
        TangentOptions {
            newton: NewtonSettings::default(),
            iteration_matrix: IterationMatrix::default(),
            max_halvings: 4,
            singular_tol: 1e-8,
            consistency_tol: 1e-8,
            stage_tol_ratio: 1e-2,
        }
    }
}

impl TangentOptions {
    /// Checks every setting.
    pub fn validate(&self) -> Result<(), SolveError> {
        self.newton.validate()?;
        if self.max_halvings > 30 {
            return Err(SolveError::InvalidParameter {
                parameter: "max_halvings",
                value: self.max_halvings as f64,
                reason: "must be at most 30",
            });
        }
        if !(self.singular_tol.is_finite() && self.singular_tol > 0.0 && self.singular_tol < 1.0) {
            return Err(SolveError::InvalidParameter {
                parameter: "singular_tol",
                value: self.singular_tol,
                reason: "must lie in (0, 1)",
            });
        }
        if !(self.consistency_tol.is_finite() && self.consistency_tol >= self.newton.tol) {
            return Err(SolveError::InvalidParameter {
                parameter: "consistency_tol",
                value: self.consistency_tol,
                reason: "must be finite and at least newton.tol",
            });
        }
        if !(self.stage_tol_ratio >= 0.0 && self.stage_tol_ratio < 1.0) {
            return Err(SolveError::InvalidParameter {
                parameter: "stage_tol_ratio",
                value: self.stage_tol_ratio,
                reason: "must lie in [0, 1)",
            });
        }
        Ok(())
    }
}

/// Work counters of a [`TangentRk`], cumulative since construction or the last
/// [`Integrator::reset`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TangentStats {
    /// Accepted steps (sub-steps of halved steps count one each).
    pub steps: usize,
    /// Chart centrings (QR factorisations of `Df^T`).
    pub charts: usize,
    /// Fixed-step mode: steps redone as two halves after a chart failure.
    pub halvings: usize,
    /// Chart failures met (recovered by halving or rejection, or returned as errors).
    pub chart_failures: usize,
    /// Chord Newton iterations of the accepted steps (all their maps).
    pub newton_iterations: usize,
    /// Most chord Newton iterations of one map of an accepted step.
    pub max_map_iterations: usize,
    /// Acceleration solves (right-hand-side evaluations) of the accepted steps.
    pub rhs_evals: usize,
    /// Largest `||(Phi, Phidot)||_inf` of an accepted step's end point.
    pub max_residual: f64,
    /// Chart maps of the accepted steps completed by the exact Newton fallback after the chord
    /// iteration failed ([`NewtonSettings::fallback_change`]: near-singular charts).
    pub exact_maps: usize,
}

/// Settings of [`TangentRk::integrate_adaptive`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AdaptiveSettings {
    /// Tolerances, safety factor, shrink/growth limits and the smallest step. The scaled error
    /// is `sqrt(sum_i (e_i / (atol + rtol max(|x_c,i|, |x_new,i|)))^2 / d)` with `e = U err_xi`
    /// the embedded estimate mapped to `x = (q, v)` and `d = 2 (n - m)` the dimension of the
    /// state equation.
    pub controller: StepController,
    /// First step size; `None` picks Hairer, Norsett and Wanner's estimate from `F(x0)` and
    /// one explicit Euler trial step (two acceleration solves).
    pub h0: Option<f64>,
    /// Largest step size.
    pub h_max: f64,
    /// Limit on accepted plus rejected steps.
    pub max_steps: usize,
    /// `beta` of the PI step-size controller (Hairer-Wanner form, `q` the embedded order):
    /// after an accepted step with error norm `err` (previous accepted step: `err_prev`),
    /// `h <- h safety err^-(1/(q+1) - 0.75 beta) err_prev^beta`. `None` (default) is
    /// Gustafsson's PI.3.4, `beta = 0.4 / (q+1)` (0.08 for DOPRI5: exponents 0.14 and 0.08);
    /// `Some(0.0)` the classical I controller; Hairer and Wanner's DOPRI5 code uses 0.04. Must
    /// lie in `[0, 1 / (1.75 (q+1)))`: at larger values a steady error never lets the step grow.
    pub pi_beta: Option<f64>,
    /// Factor applied to the step after a chart failure (the chart map did not converge) or a
    /// singular index-1 solve at a stage point; the error controller's memory is left alone.
    /// Default 0.25; must lie in (0, 1).
    pub chart_shrink: f64,
    /// Most chart failures in a row at one point before [`TangentError::Chart`]. Default 8
    /// (the step shrinks by `chart_shrink^8`, 1.5e-5 by default).
    pub max_chart_failures: usize,
}

impl Default for AdaptiveSettings {
    fn default() -> Self {
        AdaptiveSettings {
            controller: StepController::default(),
            h0: None,
            h_max: f64::INFINITY,
            max_steps: 10_000_000,
            pi_beta: None,
            chart_shrink: 0.25,
            max_chart_failures: 8,
        }
    }
}

impl AdaptiveSettings {
    /// Default settings with `atol = rtol = tol`.
    pub fn with_tolerance(tol: f64) -> Self {
        let mut s = Self::default();
        s.controller.atol = tol;
        s.controller.rtol = tol;
        s
    }

    /// Checks every setting.
    pub fn validate(&self) -> Result<(), SolveError> {
        let c = &self.controller;
        let bad = |parameter, value, reason| {
            Err(SolveError::InvalidParameter {
                parameter,
                value,
                reason,
            })
        };
        if !(c.atol.is_finite() && c.atol >= 0.0) {
            return bad("controller.atol", c.atol, "must be non-negative and finite");
        }
        if !(c.rtol.is_finite() && c.rtol >= 0.0) {
            return bad("controller.rtol", c.rtol, "must be non-negative and finite");
        }
        if !(c.atol > 0.0 || c.rtol > 0.0) {
            return bad(
                "controller.atol",
                c.atol,
                "atol and rtol cannot both be zero",
            );
        }
        if !(c.safety > 0.0 && c.safety <= 1.0) {
            return bad("controller.safety", c.safety, "must lie in (0, 1]");
        }
        if !(c.fac_min > 0.0 && c.fac_min < 1.0) {
            return bad("controller.fac_min", c.fac_min, "must lie in (0, 1)");
        }
        if !(c.fac_max > 1.0 && c.fac_max.is_finite()) {
            return bad(
                "controller.fac_max",
                c.fac_max,
                "must be finite and above 1",
            );
        }
        if !(c.h_min.is_finite() && c.h_min > 0.0) {
            return bad("controller.h_min", c.h_min, "must be positive and finite");
        }
        if let Some(h0) = self.h0 {
            if !(h0.is_finite() && h0 > 0.0) {
                return bad("h0", h0, "must be positive and finite");
            }
        }
        if self.h_max.is_nan() || self.h_max <= 0.0 {
            return bad("h_max", self.h_max, "must be positive");
        }
        if self.max_steps == 0 {
            return bad("max_steps", 0.0, "must be at least 1");
        }
        if let Some(b) = self.pi_beta {
            // the bound for the tableau's embedded order is checked when it is known
            if !(0.0..0.5).contains(&b) {
                return bad("pi_beta", b, "must lie in [0, 1 / (1.75 (q+1)))");
            }
        }
        if !(self.chart_shrink > 0.0 && self.chart_shrink < 1.0) {
            return bad("chart_shrink", self.chart_shrink, "must lie in (0, 1)");
        }
        if self.max_chart_failures == 0 {
            return bad("max_chart_failures", 0.0, "must be at least 1");
        }
        Ok(())
    }
}

/// Summary of [`TangentRk::integrate_adaptive`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct AdaptiveStats {
    /// Accepted steps.
    pub accepted: usize,
    /// Steps rejected by the error test.
    pub rejected: usize,
    /// Steps rejected because the chart map failed, or the index-1 solve at a stage point was
    /// singular (retried with [`AdaptiveSettings::chart_shrink`] times the step).
    pub chart_rejections: usize,
    /// Chart maps completed by the exact Newton fallback ([`NewtonSettings::fallback_change`]).
    pub exact_maps: usize,
    /// The first step chosen by the initial-step estimate (0 if [`AdaptiveSettings::h0`] was
    /// given).
    pub h_initial_estimate: f64,
    /// Acceleration solves.
    pub rhs_evals: usize,
    /// Chord Newton iterations.
    pub newton_iterations: usize,
    /// Smallest accepted step.
    pub h_min: f64,
    /// Largest accepted step.
    pub h_max: f64,
    /// Largest `||(Phi, Phidot)||_inf` at an accepted point.
    pub max_residual: f64,
    /// Whether the observer stopped the run early.
    pub stopped_early: bool,
}

/// Why an attempted step failed.
enum Attempt {
    /// The chart map failed (recoverable with a smaller step).
    Chart(ChartFailure),
    /// The index-1 solve at a stage point after the first was singular: the stage point landed
    /// (numerically) on a singular configuration the step passes; another step size moves it.
    Stage(SolveError),
    /// A stage at the step's end time, or the end point, is (numerically) a singular
    /// configuration ([`SolveError::Singular`] with rank and joints): halving keeps the end
    /// time, and with it the configuration, so fixed steps stop at once; an adaptive step
    /// changes its end time and retries.
    SingularEnd(SolveError),
    /// Anything else (singular configuration, bad model): returned as is.
    Hard(SolveError),
}

/// Paper B's method: explicit Runge-Kutta on the state equation `xi' = U^T F(x(xi), t)` of a
/// local chart of the constraint manifold, re-centred after every accepted step.
///
/// One step from `(t, x_c)`: centre the chart at `x_c` (QR of `Df(x_c)^T`), integrate `xi` from 0
/// over `[t, t + h]` with the tableau, evaluating every stage at a point of the manifold found by
/// chord Newton, and map the result back. Position and velocity constraints hold at every step
/// to the Newton tolerance. Allocation-free per step after [`TangentRk::new`].
#[derive(Debug)]
pub struct TangentRk {
    chart: TangentChart,
    rk: ExplicitRk,
    acc: AccelerationSolver,
    options: TangentOptions,
    stats: TangentStats,
    n: usize,
    m: usize,
    stages: usize,
    a_coef: Vec<f64>,
    b_coef: Vec<f64>,
    c_coef: Vec<f64>,
    /// Whether the last stage is the end point (`c_s = 1`, `a_sj = b_j`).
    fsal: bool,
    /// Current accepted point `(q, v)`.
    cur: Vec<f64>,
    /// Its time.
    cur_t: f64,
    /// Whether `cur` is on the manifold at `cur_t` to the Newton tolerance.
    cur_ok: bool,
    /// End point of the last attempt.
    xnew: Vec<f64>,
    /// Stage point.
    x: Vec<f64>,
    /// Chart coordinates.
    xi: Vec<f64>,
    /// Normal coordinates (chord Newton unknowns).
    zeta: Vec<f64>,
    /// Normal part of the plain RK stage value.
    zplain: Vec<f64>,
    /// Normal components `Q1^T F` of each stage's derivative (`stages x 2m`).
    g: Vec<f64>,
    /// `F = (v, a)`.
    fx: Vec<f64>,
    /// `Q^T F`.
    proj: Vec<f64>,
    /// Residual buffer.
    res: Vec<f64>,
    acc_a: Vec<f64>,
    lambda: Vec<f64>,
    /// Error estimate mapped to `x`, and the error scale.
    ex: Vec<f64>,
    scale: Vec<f64>,
    /// The paper's normal coefficients `eta` of every map of the attempt in progress (stage `i`
    /// at `i * 2m`, the end point at `s * 2m`; stage 0 is the centre, `eta = 0`).
    eta_now: Vec<f64>,
    /// `eta_now` of the last `hist_len` (at most [`HISTORY`]) accepted steps, most recent
    /// first, all of size `hist_h`, consecutive, the latest ending at `hist_t`.
    eta_hist: Vec<f64>,
    hist_len: usize,
    /// [`TangentChart::rcond`] of the charts of the steps in `eta_hist`.
    hist_rcond: [f64; HISTORY],
    hist_h: f64,
    hist_t: f64,
    /// Extrapolated `eta` of the map in progress, and of an earlier stage.
    eta_pred: Vec<f64>,
    eta_tmp: Vec<f64>,
    /// Tolerance of the interior stage maps of a step that follows the last accepted one
    /// (`TangentOptions::stage_tol_ratio`).
    stage_tol: f64,
}

/// Steps of `eta` history kept for the Newton starting points.
const HISTORY: usize = 3;

/// Largest factor by which [`TangentChart::rcond`] may differ between the current chart and
/// the charts of the history steps for the history to be used (predictors, inexact stage
/// maps). Near a singular configuration `R` changes fast from chart to chart
/// (`min |R_ii|` is about the distance to the singularity); the paper's `eta = R^-1 zeta` then
/// varies too fast for polynomial extrapolation, and a stage point off the manifold changes the
/// index-1 acceleration by about `1 / min |R_ii|` times its residual.
const RCOND_DRIFT: f64 = 2.0;

/// Per-attempt work counts.
#[derive(Clone, Copy, Debug, Default)]
struct AttemptWork {
    iterations: usize,
    max_map_iterations: usize,
    rhs_evals: usize,
    residual: f64,
    /// `||f||_inf` at the plain RK end point (NaN for FSAL tableaus).
    end_initial_residual: f64,
    /// Maps completed by the exact Newton fallback.
    exact_maps: usize,
    /// Largest index-1 condition estimate of the attempt's stage solves.
    condition: f64,
}

impl TangentRk {
    /// A solver for `sys` with `tableau` (any explicit tableau; validated) and `options`.
    pub fn new(
        sys: &System,
        tableau: ButcherTableau,
        options: TangentOptions,
    ) -> Result<Self, SolveError> {
        options.validate()?;
        let (n, m) = (sys.n_coords(), sys.n_constraints());
        let mut chart = TangentChart::new(sys);
        chart.singular_tol = options.singular_tol;
        chart.set_broyden(options.iteration_matrix == IterationMatrix::Broyden);
        let dim = chart.dim();
        let s = tableau.stages;
        let a_coef = tableau.a.clone();
        let b_coef = tableau.b.clone();
        let c_coef = tableau.c.clone();
        let fsal = s > 0
            && tableau.c[s - 1] == 1.0
            && (0..s).all(|j| tableau.a[(s - 1) * s + j] == tableau.b[j]);
        let rk = ExplicitRk::new(tableau, dim)?;
        Ok(TangentRk {
            chart,
            rk,
            acc: AccelerationSolver::new(sys),
            options,
            stats: TangentStats::default(),
            n,
            m,
            stages: s,
            a_coef,
            b_coef,
            c_coef,
            fsal,
            cur: vec![0.0; 2 * n],
            cur_t: f64::NAN,
            cur_ok: false,
            xnew: vec![0.0; 2 * n],
            x: vec![0.0; 2 * n],
            xi: vec![0.0; dim],
            zeta: vec![0.0; 2 * m],
            zplain: vec![0.0; 2 * m],
            g: vec![0.0; s * 2 * m],
            fx: vec![0.0; 2 * n],
            proj: vec![0.0; 2 * n],
            res: vec![0.0; 2 * m],
            acc_a: vec![0.0; n],
            lambda: vec![0.0; m],
            ex: vec![0.0; 2 * n],
            scale: vec![0.0; 2 * n],
            eta_now: vec![0.0; (s + 1) * 2 * m],
            eta_hist: vec![0.0; HISTORY * (s + 1) * 2 * m],
            hist_len: 0,
            hist_rcond: [1.0; HISTORY],
            hist_h: f64::NAN,
            hist_t: f64::NAN,
            eta_pred: vec![0.0; 2 * m],
            eta_tmp: vec![0.0; 2 * m],
            stage_tol: options.newton.tol,
        })
    }

    /// Tangent-space RK4 with default options (the paper's method).
    pub fn rk4(sys: &System) -> Result<Self, SolveError> {
        Self::new(sys, ButcherTableau::rk4(), TangentOptions::default())
    }

    /// Tangent-space DOPRI5 (order 5, embedded order-4 estimate for
    /// [`TangentRk::integrate_adaptive`]) with default options.
    pub fn dopri5(sys: &System) -> Result<Self, SolveError> {
        Self::new(sys, ButcherTableau::dopri5(), TangentOptions::default())
    }

    /// The tableau.
    pub fn tableau(&self) -> &ButcherTableau {
        &self.rk.tableau
    }

    /// The options.
    pub fn options(&self) -> &TangentOptions {
        &self.options
    }

    /// Work counters since construction or the last reset.
    pub fn stats(&self) -> &TangentStats {
        &self.stats
    }

    /// The chart of the last step (centred at that step's start point).
    pub fn chart(&self) -> &TangentChart {
        &self.chart
    }

    /// Dimension of the state equation, `2 (n - m)`.
    pub fn state_dim(&self) -> usize {
        self.chart.dim()
    }

    fn check_sizes(&self, sys: &System, state: &State) -> Result<(), SolveError> {
        if sys.n_coords() != self.n || sys.n_constraints() != self.m {
            return Err(SolveError::Dimension {
                what: "system (not the one the solver was built for: coordinates)",
                expected: self.n,
                got: sys.n_coords(),
            });
        }
        state.check(sys)?;
        if !state.is_finite() {
            return Err(SolveError::NonFinite {
                t: state.t,
                what: "state handed to the tangent-space step",
            });
        }
        Ok(())
    }

    /// Loads `state` into `cur` and checks it lies on the manifold to `consistency_tol`.
    fn load(&mut self, sys: &System, state: &State) -> Result<(), SolveError> {
        let n = self.n;
        if self.cur_ok
            && same_time(state.t, self.cur_t)
            && state.q.as_slice() == &self.cur[..n]
            && state.v.as_slice() == &self.cur[n..]
        {
            // the state is the end point of our last step: on the manifold to newton.tol
            return Ok(());
        }
        self.hist_len = 0;
        self.cur[..n].copy_from_slice(state.q.as_slice());
        self.cur[n..].copy_from_slice(state.v.as_slice());
        self.cur_t = state.t;
        self.cur_ok = self.m == 0;
        if self.m == 0 {
            return Ok(());
        }
        let r = self.chart.residual(sys, &self.cur, state.t, &mut self.res);
        self.cur_ok = r <= self.options.newton.tol;
        if r.is_nan() || r > self.options.consistency_tol {
            return Err(SolveError::InvalidParameter {
                parameter: "state: ||(Phi, Phidot)||_inf",
                value: r,
                reason: "the state is not on the constraint manifold (above consistency_tol); \
                         project it first (System::project)",
            });
        }
        Ok(())
    }

    fn store(&self, state: &mut State) {
        let n = self.n;
        state.q.as_mut_slice().copy_from_slice(&self.cur[..n]);
        state.v.as_mut_slice().copy_from_slice(&self.cur[n..]);
    }

    fn centre(&mut self, sys: &System, t: f64) -> Result<(), SolveError> {
        let n = self.n;
        let (q, v) = self.cur.split_at(n);
        self.chart.centre(sys, q, v, t)?;
        self.stats.charts += 1;
        Ok(())
    }

    /// One attempted step of size `h` from the chart centre (at time `t`) into `xnew`; the
    /// embedded error estimate in chart coordinates (if the tableau has one) is left in
    /// `rk.err`.
    ///
    /// Newton starting points (they change only where the chord iteration starts, never its
    /// limit). After accepted fixed steps of the same size, each stage map starts from the
    /// paper's normal coefficients `eta` (`Df(x_c)^T eta`, independent of the basis `Q1`) of
    /// the same stage in the last up to three steps, extrapolated by a polynomial in the step
    /// index (`eta` is a smooth function of the step's start point along the trajectory), and
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
    fn attempt(&mut self, sys: &System, t: f64, h: f64) -> Result<AttemptWork, Attempt> {
        let n = self.n;
        let mm = 2 * self.m;
        let s = self.stages;
        let newton = self.options.newton;
        // interior stage maps: inexact after an accepted step of the same size (to rounding:
        // `mbd_solve::run` passes `t_next - t`, which differs from the nominal step in the
        // last bits)
        let rcond = self.chart.rcond();
        let follows = same_step(self.hist_h, h)
            && same_time(self.hist_t, t)
            && self.hist_rcond[..self.hist_len]
                .iter()
                .all(|&r| r <= RCOND_DRIFT * rcond && rcond <= RCOND_DRIFT * r);
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
        let scleronomic = quadratic && self.m > 0;
        if !follows {
            self.hist_len = 0;
        }
        let npts = self.hist_len;
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
        {
            let chart = &mut self.chart;
            let acc = &mut self.acc;
            let zlast = &mut self.zeta;
            let (zplain, x, g, fx, proj) = (
                &mut self.zplain,
                &mut self.x,
                &mut self.g,
                &mut self.fx,
                &mut self.proj,
            );
            let (acc_a, lambda) = (&mut self.acc_a, &mut self.lambda);
            let (a_coef, c_coef) = (&self.a_coef, &self.c_coef);
            let fsal = self.fsal;
            let (eta_now, eta_hist, eta_pred, eta_tmp) = (
                &mut self.eta_now,
                &self.eta_hist,
                &mut self.eta_pred,
                &mut self.eta_tmp,
            );
            let work = &mut work;
            let failure = &mut failure;
            let singular_stage = &mut singular_stage;
            let mut rhs = |ti: f64, y: &[f64], dy: &mut [f64]| -> Result<(), SolveError> {
                let i = stage;
                // plain RK stage value's normal part
                zplain.fill(0.0);
                for j in 0..i {
                    let a = a_coef[i * s + j];
                    if a != 0.0 {
                        axpy(h * a, &g[j * mm..(j + 1) * mm], zplain);
                    }
                }
                if i == 1 && interpolate {
                    // Euler prediction of the end point, x_c + h F(x_c): where the iteration
                    // matrix is interpolated to
                    x.copy_from_slice(chart.centre_point());
                    axpy(h, fx, x);
                    chart.set_secondary_point(sys, x);
                }
                chart.select_iteration_matrix(c_coef[i]);
                let ysq: f64 = y.iter().map(|v| v * v).sum();
                if npts > 0 {
                    extrapolate(eta_hist, npts, (s + 1) * mm, i * mm, eta_pred);
                    if jlast > 0 {
                        // correct by the extrapolation error of the latest mapped stage j,
                        // scaled like the normal offset (|Y_i|^2 / |Y_j|^2)
                        let r = ysq / ylast_sq;
                        extrapolate(eta_hist, npts, (s + 1) * mm, jlast * mm, eta_tmp);
                        let now = &eta_now[jlast * mm..(jlast + 1) * mm];
                        for ((p, e), x) in eta_pred.iter_mut().zip(now).zip(eta_tmp.iter()) {
                            *p += r * (e - x);
                        }
                    }
                    chart.zeta_from_eta(eta_pred, zplain);
                } else if quadratic && ylast_sq > 0.0 {
                    // scleronomic: the normal offset of the manifold above Y grows like |Y|^2
                    let r = ysq / ylast_sq;
                    for (z, zl) in zplain.iter_mut().zip(zlast.iter()) {
                        *z = r * zl;
                    }
                }
                let mapped = if i == 0 && centre_ok && ti == t {
                    x.copy_from_slice(chart.centre_point());
                    Ok(MapStats::default())
                } else if fsal && i + 1 == s {
                    // FSAL: this stage point is the step's end point, whose residual is verified
                    chart.map(sys, y, ti, zplain, x, &newton)
                } else {
                    chart.map_predicted(sys, y, ti, zplain, x, &stage_newton)
                };
                if ysq > 0.0 && mapped.is_ok() {
                    zlast.copy_from_slice(zplain);
                    ylast_sq = ysq;
                    jlast = i;
                }
                if mapped.is_ok() {
                    chart.eta_from_zeta(zplain, &mut eta_now[i * mm..(i + 1) * mm]);
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
                let solved = if i == 0 && centre_ok && ti == t && scleronomic {
                    // at the centre: Phi_q and (Phi_q v)_q are the chart's, so
                    // gamma = -(Phi_q v)_q v needs no model evaluation
                    sys.forces_into(q, v, ti, &mut acc.forces);
                    acc.phi_q.copy_from(chart.centre_phi_q());
                    let dphi = chart.centre_phi_q_dot_jacobian().as_slice();
                    let m = acc.gamma.len();
                    acc.gamma.fill(0.0);
                    for (col, &vk) in dphi.chunks_exact(m.max(1)).zip(v) {
                        for (gr, &d) in acc.gamma.iter_mut().zip(col) {
                            *gr -= d * vk;
                        }
                    }
                    acc.finish(sys, ti, acc_a, lambda)
                } else {
                    acc.solve(sys, q, v, ti, acc_a, lambda)
                };
                if solved.is_ok() {
                    work.condition = work.condition.max(acc.condition_estimate());
                }
                if let Err(e) = solved {
                    if matches!(e, SolveError::Singular { .. }) {
                        *singular_stage = Some(i);
                    }
                    return Err(e);
                }
                work.rhs_evals += 1;
                fx[..n].copy_from_slice(v);
                fx[n..].copy_from_slice(acc_a);
                chart.coordinates(fx, proj);
                g[i * mm..(i + 1) * mm].copy_from_slice(&proj[..mm]);
                dy.copy_from_slice(&proj[mm..]);
                stage += 1;
                Ok(())
            };
            if let Err(e) = self.rk.step(&mut rhs, t, &mut self.xi, h) {
                return Err(match (failure.take(), *singular_stage) {
                    // a map at the step's end time that failed at a singular configuration
                    (Some((f, i)), _) if self.c_coef[i] == 1.0 => {
                        match self.chart.singular_error_at(
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
                        self.chart
                            .singular_error(sys, t, SINGULAR_REPORT_TOL)
                            .unwrap_or(e),
                    ),
                    // a stage at the step's end time
                    (None, Some(i)) if self.c_coef[i] == 1.0 => Attempt::SingularEnd(
                        self.chart
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
            self.chart.select_iteration_matrix(1.0);
            self.zeta.fill(0.0);
            for j in 0..s {
                let b = self.b_coef[j];
                if b != 0.0 {
                    axpy(h * b, &self.g[j * mm..(j + 1) * mm], &mut self.zeta);
                }
            }
            match self
                .chart
                .map(sys, &self.xi, t1, &mut self.zeta, &mut self.xnew, &newton)
            {
                Ok(ms) => {
                    work.exact_maps += usize::from(ms.exact);
                    work.iterations += ms.iterations;
                    work.max_map_iterations = work.max_map_iterations.max(ms.iterations);
                    work.residual = ms.residual;
                    work.end_initial_residual = ms.initial_residual;
                }
                Err(f) => {
                    return Err(
                        match self.chart.singular_error_at(
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
            self.chart
                .eta_from_zeta(&self.zeta, &mut self.eta_now[s * mm..(s + 1) * mm]);
        }
        if self.xnew.iter().any(|x| !x.is_finite()) {
            return Err(Attempt::Hard(SolveError::NonFinite {
                t: t1,
                what: "state after tangent-space step",
            }));
        }
        Ok(work)
    }

    /// Records the accepted attempt's `eta` (a step of size `h` ending at `t_end`).
    fn commit_history(&mut self, h: f64, t_end: f64, end_initial_residual: f64) {
        let (ratio, tol) = (self.options.stage_tol_ratio, self.options.newton.tol);
        self.stage_tol = if ratio > 0.0 && end_initial_residual.is_finite() {
            (ratio * end_initial_residual).max(tol)
        } else {
            tol
        };
        let len = self.eta_now.len();
        self.eta_hist.copy_within(0..(HISTORY - 1) * len, len);
        self.eta_hist[..len].copy_from_slice(&self.eta_now);
        self.hist_rcond.copy_within(0..HISTORY - 1, 1);
        self.hist_rcond[0] = self.chart.rcond();
        self.hist_len = (self.hist_len + 1).min(HISTORY);
        self.hist_h = h;
        self.hist_t = t_end;
    }

    fn account(&mut self, w: &AttemptWork) {
        self.stats.newton_iterations += w.iterations;
        self.stats.max_map_iterations = self.stats.max_map_iterations.max(w.max_map_iterations);
        self.stats.rhs_evals += w.rhs_evals;
        self.stats.exact_maps += w.exact_maps;
    }

    /// Advances `cur` from `t` by `h`, halving on chart failure up to `max_halvings` levels.
    fn advance(
        &mut self,
        sys: &System,
        t: f64,
        h: f64,
        depth: u32,
        out: &mut StepStats,
    ) -> Result<(), SolveError> {
        self.centre(sys, t)?;
        match self.attempt(sys, t, h) {
            Ok(w) => {
                self.account(&w);
                self.commit_history(h, t + h, w.end_initial_residual);
                std::mem::swap(&mut self.cur, &mut self.xnew);
                self.cur_t = t + h;
                self.cur_ok = true;
                self.stats.steps += 1;
                self.stats.max_residual = self.stats.max_residual.max(w.residual);
                out.newton_iterations += w.iterations;
                out.rhs_evals += w.rhs_evals;
                out.residual = out.residual.max(w.residual);
                out.condition = out.condition.max(w.condition);
                Ok(())
            }
            Err(fail @ (Attempt::Chart(_) | Attempt::Stage(_))) => {
                self.stats.chart_failures += 1;
                if depth < self.options.max_halvings {
                    self.stats.halvings += 1;
                    let h2 = 0.5 * h;
                    self.advance(sys, t, h2, depth + 1, out)?;
                    self.advance(sys, t + h2, h2, depth + 1, out)
                } else {
                    Err(match fail {
                        Attempt::Chart(f) => f.into_error(),
                        Attempt::Stage(e) | Attempt::SingularEnd(e) | Attempt::Hard(e) => e,
                    })
                }
            }
            Err(Attempt::Hard(e) | Attempt::SingularEnd(e)) => Err(e),
        }
    }

    /// Integrates from `state.t` to `t_end` with adaptive steps controlled by the tableau's
    /// embedded error estimate (e.g. DOPRI5 5(4), Bogacki-Shampine 3(2)), calling `observer`
    /// with the initial state (step 0) and after every accepted step.
    ///
    /// Step control (`docs/tangent.md` section 6): the first step from Hairer, Norsett and
    /// Wanner's estimate (`f(x0)` and one explicit Euler trial step) unless
    /// [`AdaptiveSettings::h0`] is given; after an accepted step a PI controller
    /// (`h <- h safety err^-(1/(q+1) - 0.75 beta) err_prev^beta`, clamped to
    /// `[fac_min, fac_max]`, no growth right after a rejection), after a rejected one
    /// `h <- h max(fac_min, safety err^-(1/(q+1) - 0.75 beta))`. A chart failure (the chart map
    /// did not converge) or a singular index-1 solve at a stage point multiplies the step by
    /// [`AdaptiveSettings::chart_shrink`] without touching the controller's memory; more than
    /// [`AdaptiveSettings::max_chart_failures`] of them in a row, or a step below
    /// `controller.h_min`, is an error ([`TangentError::Chart`],
    /// [`TangentError::StepSizeTooSmall`]). A singular configuration at an accepted point is
    /// [`SolveError::Singular`] at once (no retry with smaller steps).
    pub fn integrate_adaptive<O: Observer + ?Sized>(
        &mut self,
        sys: &System,
        state: &mut State,
        t_end: f64,
        settings: &AdaptiveSettings,
        observer: &mut O,
    ) -> Result<AdaptiveStats, TangentError> {
        settings.validate()?;
        self.check_sizes(sys, state)?;
        let t0 = state.t;
        if !(t_end.is_finite() && t_end > t0) {
            return Err(SolveError::InvalidInterval {
                t0,
                t_end,
                reason: "end time must be finite and after the start time",
            }
            .into());
        }
        let q_order = match (&self.rk.tableau.b_hat, self.rk.tableau.embedded_order) {
            (Some(_), q) if q > 0 => q,
            _ => {
                return Err(SolveError::Unsupported(format!(
                "adaptive stepping needs a tableau with an embedded error estimate; '{}' has none \
                     (use DOPRI5 or Bogacki-Shampine)",
                self.rk.tableau.name
            ))
                .into())
            }
        };
        self.load(sys, state)?;
        self.adaptive_loop(sys, state, t_end, settings, observer, q_order)
    }

    /// The step loop of [`TangentRk::integrate_adaptive`] (`state` loaded, settings checked).
    fn adaptive_loop<O: Observer + ?Sized>(
        &mut self,
        sys: &System,
        state: &mut State,
        t_end: f64,
        settings: &AdaptiveSettings,
        observer: &mut O,
        q_order: u32,
    ) -> Result<AdaptiveStats, TangentError> {
        let t0 = state.t;
        let ctrl = settings.controller;
        let mut st = AdaptiveStats {
            h_min: f64::INFINITY,
            ..Default::default()
        };
        if observer.observe(sys, state, 0)? == Flow::Stop {
            st.stopped_early = true;
            st.h_min = 0.0;
            return Ok(st);
        }
        let mut h = match settings.h0 {
            Some(h0) => h0,
            None => {
                let h0 = self.initial_step(sys, t0, t_end - t0, settings)?;
                st.h_initial_estimate = h0;
                st.rhs_evals += 2;
                h0
            }
        };
        h = h.min(settings.h_max);
        // the PI controller: exponents and memory (the error norm of the last accepted step)
        let k = q_order as f64 + 1.0;
        let beta = settings.pi_beta.unwrap_or(0.4 / k);
        if beta >= 1.0 / (1.75 * k) {
            return Err(SolveError::InvalidParameter {
                parameter: "pi_beta",
                value: beta,
                reason: "must lie in [0, 1 / (1.75 (q+1))) for the tableau's embedded order q",
            }
            .into());
        }
        let expo = 1.0 / k - 0.75 * beta;
        let mut err_prev = 1e-4f64;
        let mut t = t0;
        let mut last_rejected = false;
        let mut chart_failures_here = 0usize;
        let mut centred_at = f64::NAN;
        let mut attempts = 0usize;
        while t < t_end {
            attempts += 1;
            if attempts > settings.max_steps {
                return Err(TangentError::TooManySteps {
                    t,
                    max_steps: settings.max_steps,
                });
            }
            let remaining = t_end - t;
            let last = h >= remaining * (1.0 - 1e-12);
            let hs = if last { remaining } else { h };
            if hs < ctrl.h_min && !last {
                return Err(TangentError::StepSizeTooSmall {
                    t,
                    h: hs,
                    h_min: ctrl.h_min,
                });
            }
            if centred_at != t {
                self.centre(sys, t)?;
                centred_at = t;
            }
            match self.attempt(sys, t, hs) {
                Ok(w) => {
                    self.account(&w);
                    st.rhs_evals += w.rhs_evals;
                    st.newton_iterations += w.iterations;
                    st.exact_maps += w.exact_maps;
                    // error estimate mapped to x: e = U err_xi
                    self.ex.fill(0.0);
                    for (k, &e) in self.rk.err.iter().enumerate() {
                        let col = self.chart.tangent(k);
                        for (exi, c) in self.ex.iter_mut().zip(col) {
                            *exi += e * c;
                        }
                    }
                    for ((s, a), b) in self.scale.iter_mut().zip(&self.cur).zip(&self.xnew) {
                        *s = a.abs().max(b.abs());
                    }
                    let en = self.error_norm(&ctrl);
                    if !en.is_finite() {
                        return Err(SolveError::NonFinite {
                            t,
                            what: "embedded error estimate",
                        }
                        .into());
                    }
                    chart_failures_here = 0;
                    let grow = ctrl.safety * en.powf(-expo);
                    if en <= 1.0 {
                        std::mem::swap(&mut self.cur, &mut self.xnew);
                        t = if last { t_end } else { t + hs };
                        self.commit_history(hs, t, w.end_initial_residual);
                        self.cur_t = t;
                        self.cur_ok = true;
                        st.accepted += 1;
                        st.h_min = st.h_min.min(hs);
                        st.h_max = st.h_max.max(hs);
                        st.max_residual = st.max_residual.max(w.residual);
                        self.stats.steps += 1;
                        self.stats.max_residual = self.stats.max_residual.max(w.residual);
                        state.t = t;
                        self.store(state);
                        // PI control (Gustafsson; Hairer-Wanner's DOPRI5 form)
                        let mut fac = if en == 0.0 {
                            ctrl.fac_max
                        } else {
                            (grow * err_prev.powf(beta)).clamp(ctrl.fac_min, ctrl.fac_max)
                        };
                        err_prev = en.max(1e-4);
                        if last_rejected {
                            fac = fac.min(1.0);
                        }
                        last_rejected = false;
                        h = (hs * fac).min(settings.h_max);
                        if observer.observe(sys, state, st.accepted)? == Flow::Stop {
                            st.stopped_early = true;
                            break;
                        }
                    } else {
                        st.rejected += 1;
                        last_rejected = true;
                        h = hs * grow.clamp(ctrl.fac_min, 1.0);
                    }
                }
                Err(fail @ (Attempt::Chart(_) | Attempt::Stage(_) | Attempt::SingularEnd(_))) => {
                    self.stats.chart_failures += 1;
                    st.chart_rejections += 1;
                    chart_failures_here += 1;
                    last_rejected = true;
                    h = settings.chart_shrink * hs;
                    if h < ctrl.h_min || chart_failures_here > settings.max_chart_failures {
                        return Err(TangentError::Chart {
                            source: match fail {
                                Attempt::Chart(f) => f.into_error(),
                                Attempt::Stage(e) | Attempt::SingularEnd(e) | Attempt::Hard(e) => e,
                            },
                            h: hs,
                            failures: chart_failures_here,
                        });
                    }
                }
                Err(Attempt::Hard(e)) => return Err(e.into()),
            }
        }
        if st.accepted == 0 {
            st.h_min = 0.0;
        }
        Ok(st)
    }

    /// The scaled error norm of the estimate `ex` (mapped to `x`) with the scale in `scale`
    /// (`max(|x_c,i|, |x_1,i|)`): `sqrt(sum_i (e_i / (atol + rtol scale_i))^2 / d)` with
    /// `d = 2 (n - m)` the dimension of the state equation. `e = U err_xi` has the Euclidean
    /// length of the estimate in chart coordinates, spread over the `2n` ambient components;
    /// dividing by `2n` instead of `d` would shrink the RMS of a `d`-dimensional error by
    /// `sqrt(d / 2n)` (1/sqrt(3) on the manipulator) and loosen every tolerance by that much.
    fn error_norm(&self, ctrl: &StepController) -> f64 {
        let d = self.chart.dim().max(1) as f64;
        let sum: f64 = self
            .ex
            .iter()
            .zip(&self.scale)
            .map(|(e, y)| (e / (ctrl.atol + ctrl.rtol * y.abs())).powi(2))
            .sum();
        (sum / d).sqrt()
    }

    /// Hairer, Norsett and Wanner's initial step (`HINIT` of DOPRI5, "Solving ODEs I",
    /// section II.4) in the controller's scaled RMS norm (`sk = atol + rtol |x0|`, normalised
    /// like [`TangentRk::error_norm`]): `d0 = ||x0||`, `d1 = ||F(x0)||`,
    /// `h_a = 0.01 d0 / d1` (1e-6 if either is below 1e-5), one explicit Euler trial step
    /// `x1 = x0 + h_a F(x0)` (off the manifold by `O(h_a^2)`; the index-1 solve does not need
    /// it on), `d2 = ||F(x1) - F(x0)|| / h_a`, `h_b = (0.01 / max(d1, d2))^(1/p)` with `p` the
    /// method's order (`max(1e-6, 1e-3 h_a)` if `max(d1, d2) <= 1e-15`), and
    /// `h0 = min(100 h_a, h_b, h_max, span)`, at least `h_min`. Two acceleration solves.
    fn initial_step(
        &mut self,
        sys: &System,
        t: f64,
        span: f64,
        settings: &AdaptiveSettings,
    ) -> Result<f64, SolveError> {
        let ctrl = &settings.controller;
        let n = self.n;
        let d = self.chart.dim().max(1) as f64;
        let norm = |x: &[f64], y: &[f64]| -> f64 {
            let sum: f64 = x
                .iter()
                .zip(y)
                .map(|(e, y)| (e / (ctrl.atol + ctrl.rtol * y.abs())).powi(2))
                .sum();
            (sum / d).sqrt()
        };
        {
            let (q, v) = self.cur.split_at(n);
            if let Err(e) = self
                .acc
                .solve(sys, q, v, t, &mut self.acc_a, &mut self.lambda)
            {
                return Err(match e {
                    SolveError::Singular { .. } => self
                        .chart
                        .singular_error_at(sys, q, t, SINGULAR_REPORT_TOL)
                        .unwrap_or(e),
                    e => e,
                });
            }
        }
        self.stats.rhs_evals += 1;
        self.fx[..n].copy_from_slice(&self.cur[n..]);
        self.fx[n..].copy_from_slice(&self.acc_a);
        let d0 = norm(&self.cur, &self.cur);
        let d1 = norm(&self.fx, &self.cur);
        let ha = if d0 < 1e-5 || d1 < 1e-5 {
            1e-6
        } else {
            0.01 * d0 / d1
        }
        .min(settings.h_max)
        .min(span);
        // explicit Euler trial step x1 = x0 + ha F(x0), F(x1) into proj
        for ((x1, x0), f) in self.x.iter_mut().zip(&self.cur).zip(&self.fx) {
            *x1 = x0 + ha * f;
        }
        {
            let (q, v) = self.x.split_at(n);
            self.acc
                .solve(sys, q, v, t + ha, &mut self.acc_a, &mut self.lambda)?;
        }
        self.stats.rhs_evals += 1;
        self.proj[..n].copy_from_slice(&self.x[n..]);
        self.proj[n..].copy_from_slice(&self.acc_a);
        for (df, f0) in self.ex.iter_mut().zip(self.proj.iter().zip(&self.fx)) {
            *df = (f0.0 - f0.1) / ha;
        }
        let d2 = norm(&self.ex, &self.cur);
        let d12 = d1.max(d2);
        let p = self.rk.tableau.order.max(1) as f64;
        let hb = if d12 <= 1e-15 {
            (1e-3 * ha).max(1e-6)
        } else {
            (0.01 / d12).powf(1.0 / p)
        };
        let h0 = (100.0 * ha).min(hb).min(settings.h_max).min(span);
        if !h0.is_finite() {
            return Err(SolveError::NonFinite {
                t,
                what: "initial step estimate",
            });
        }
        Ok(h0.max(ctrl.h_min))
    }
}

/// Relative tolerance to which two step sizes, or two times, count as the same
/// ([`same_step`], [`same_time`]).
const STEP_RTOL: f64 = 1e-12;

/// Relative threshold of the rank report when the index-1 solve at a step's start point is
/// singular (the dense Cholesky of `Phi_q M^-1 Phi_q^T` gives up at pivots below `1e-7` of the
/// largest, i.e. `Phi_q` singular values about that far apart).
const SINGULAR_REPORT_TOL: f64 = 1e-6;

/// Whether two step sizes agree to [`STEP_RTOL`] relative. `mbd_solve::run` passes each step
/// `t_next - t` with `t_next = t0 + k h`, which differs from the nominal `h` in the last bits on
/// most steps; the fast paths that need "a step of the same size as the last" must not depend
/// on those bits.
#[inline]
fn same_step(a: f64, b: f64) -> bool {
    (a - b).abs() <= STEP_RTOL * a.abs().max(b.abs())
}

/// Whether two times agree to [`STEP_RTOL`] relative (the same instant up to rounding).
#[inline]
fn same_time(a: f64, b: f64) -> bool {
    a == b || (a - b).abs() <= STEP_RTOL * a.abs().max(b.abs())
}

/// Polynomial extrapolation to the next step of the `eta` of one map (offset `off` within a
/// step's record of length `len`) from the last `npts` (1 to 3) steps, most recent first.
fn extrapolate(hist: &[f64], npts: usize, len: usize, off: usize, out: &mut [f64]) {
    let w: &[f64] = match npts {
        1 => &[1.0],
        2 => &[2.0, -1.0],
        _ => &[3.0, -3.0, 1.0],
    };
    out.fill(0.0);
    for (k, &wk) in w.iter().enumerate() {
        axpy(wk, &hist[k * len + off..k * len + off + out.len()], out);
    }
}

impl Integrator for TangentRk {
    fn name(&self) -> String {
        format!("tangent-space {}", self.rk.tableau.name)
    }

    fn order(&self) -> Option<u32> {
        Some(self.rk.tableau.order)
    }

    fn reset(&mut self) {
        self.stats = TangentStats::default();
        self.cur_ok = false;
        self.hist_len = 0;
    }

    fn step(&mut self, sys: &System, state: &mut State, h: f64) -> Result<StepStats, SolveError> {
        self.check_sizes(sys, state)?;
        if !(h.is_finite() && h > 0.0) {
            return Err(SolveError::InvalidStep { h });
        }
        self.load(sys, state)?;
        let mut out = StepStats::default();
        let t = state.t;
        self.advance(sys, t, h, 0, &mut out)?;
        self.store(state);
        state.t = t + h;
        Ok(out)
    }
}
