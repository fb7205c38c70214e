//! The tangent-space Runge-Kutta integrator: fixed steps ([`Integrator`]) and adaptive steps
//! ([`AdaptiveIntegrator`], driven by [`mbd_solve::run_adaptive`]).

use crate::chart::{ChartFailure, MapStats, NewtonSettings, TangentChart};
use crate::sparse_chart::SparseChart;
use mbd_model::System;
use mbd_solve::linalg::axpy;
use mbd_solve::{
    AccelerationSolver, AdaptiveIntegrator, ButcherTableau, ExplicitRk, Integrator, SingularBridge,
    SolveError, SparseAccelerationSolver, State, StepAttempt, StepController, StepStats,
};
mod adaptive;
mod attempt;
mod history;
mod options;
mod path;
mod starter;

use history::EtaHistory;
use path::{Path, SparseParts};

pub use options::{ChartMetric, IterationMatrix, TangentOptions, TangentStats};

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
///
/// Above [`mbd_solve::SPARSE_THRESHOLD`] constraint equations (or as chosen by
/// [`TangentOptions::linear_solver`]) the chart is a sparse one: the state equation is
/// integrated in redundant coordinates `y = U xi` in `ker Df(x_c)` (`y' = P F`), which gives
/// the same steps up to rounding at `O(N)` cost for chains.
#[derive(Debug)]
pub struct TangentRk {
    /// The chart and the index-1 solver (dense or sparse).
    path: Path,
    rk: ExplicitRk,
    options: TangentOptions,
    stats: TangentStats,
    n: usize,
    m: usize,
    /// The model's constraint equations (`m` plus its redundant ones).
    m_full: usize,
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
    /// Chart coordinates (dense: `xi`, `2 (n - m)`; sparse: `y`, `2n`).
    xi: Vec<f64>,
    /// Normal coordinates (chord Newton unknowns).
    zeta: Vec<f64>,
    /// Normal part of the plain RK stage value.
    zplain: Vec<f64>,
    /// Normal components `Q1^T F` of each stage's derivative (`stages x 2m`).
    g: Vec<f64>,
    /// `F = (v, a)`.
    fx: Vec<f64>,
    /// Work space (`2n`).
    proj: Vec<f64>,
    /// Residual buffer.
    res: Vec<f64>,
    acc_a: Vec<f64>,
    lambda: Vec<f64>,
    /// Error estimate mapped to `x`, and the error scale.
    ex: Vec<f64>,
    scale: Vec<f64>,
    /// The paper's normal coefficients `eta` of every stage map of the attempt in progress
    /// (stage `i` at `i * 2m`; stage 0 is the centre, `eta = 0`). The end point's are not kept:
    /// it starts from the RK quadrature, not from the history.
    eta_now: Vec<f64>,
    /// The interior stages' `eta` (stages `1..s`) of the last accepted steps of one size.
    hist: EtaHistory,
    /// Extrapolated and corrected `eta` of the map in progress; the plain extrapolations of
    /// the attempt's stages (stage `i` at `i * 2m`).
    eta_pred: Vec<f64>,
    eta_raw: Vec<f64>,
    /// Tolerance of the interior stage maps of a step that follows the last accepted one
    /// (`TangentOptions::stage_tol_ratio`).
    stage_tol: f64,
    /// The time the chart was centred at for adaptive attempts from the current point (NaN once
    /// the point changed): a rejected attempt retries from the same chart.
    centred_at: f64,
    /// Adaptive attempts in a row from the current point that failed for another reason than
    /// the error test.
    failures_here: usize,
    /// The accelerations of the last step starts, for stages near a singular configuration.
    bridge: SingularBridge,
    /// The largest condition estimate of the stage solves of the last accepted step (infinite
    /// before one): whether the next step's start may take its accelerations from the chart.
    last_condition: f64,
    /// Projected RK of the same tableau for a step from a singular configuration (its
    /// integrator built on first use; `starter.rs`).
    starter: mbd_solve::SingularStarter,
}

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
    /// Stages bridged through a singular configuration.
    bridged: usize,
}

impl TangentRk {
    /// A solver for `sys` with `tableau` (any explicit tableau; validated) and `options`.
    pub fn new(
        sys: &System,
        tableau: ButcherTableau,
        options: TangentOptions,
    ) -> Result<Self, SolveError> {
        options.validate()?;
        let (n, m_full) = (sys.n_coords(), sys.n_constraints());
        let sparse = options.linear_solver.use_sparse(m_full);
        // the dense chart works with the m - k independent rows (chosen at each centre); the
        // sparse chart with all m, its factorisations dropping the dependent ones
        let m = if sparse {
            m_full
        } else {
            m_full - sys.n_redundant()
        };
        let path = if sparse {
            if options.iteration_matrix != IterationMatrix::Centre {
                return Err(SolveError::Unsupported(format!(
                    "the sparse tangent chart iterates with the centre's matrix only \
                     (iteration matrix {:?}; choose LinearSolver::Dense for it)",
                    options.iteration_matrix
                )));
            }
            let mut chart = SparseChart::new(sys)?;
            chart.singular_tol = options.singular_tol;
            Path::Sparse(Box::new(SparseParts {
                chart,
                acc: SparseAccelerationSolver::new(sys)?,
            }))
        } else {
            let mut chart = TangentChart::new(sys);
            chart.singular_tol = options.singular_tol;
            chart.set_broyden(options.iteration_matrix == IterationMatrix::Broyden);
            Path::Dense {
                chart,
                acc: AccelerationSolver::new(sys),
            }
        };
        let dim = path.coord_dim();
        let s = tableau.stages;
        let a_coef = tableau.a.clone();
        let b_coef = tableau.b.clone();
        let c_coef = tableau.c.clone();
        let fsal = s > 0
            && tableau.c[s - 1] == 1.0
            && (0..s).all(|j| tableau.a[(s - 1) * s + j] == tableau.b[j]);
        let starter = mbd_solve::SingularStarter::new(tableau.clone());
        let rk = ExplicitRk::new(tableau, dim)?;
        Ok(TangentRk {
            path,
            rk,
            options,
            stats: TangentStats::default(),
            n,
            m,
            m_full,
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
            lambda: vec![0.0; m_full],
            ex: vec![0.0; 2 * n],
            scale: vec![0.0; 2 * n],
            eta_now: vec![0.0; s * 2 * m],
            hist: EtaHistory::new(s.saturating_sub(1), 2 * m, !sparse),
            eta_pred: vec![0.0; 2 * m],
            eta_raw: vec![0.0; s * 2 * m],
            stage_tol: options.newton.tol,
            centred_at: f64::NAN,
            failures_here: 0,
            bridge: SingularBridge::new(sys),
            last_condition: f64::INFINITY,
            starter,
        })
    }

    /// Tangent-space RK4 with default options (the paper's method).
    pub fn rk4(sys: &System) -> Result<Self, SolveError> {
        Self::new(sys, ButcherTableau::rk4(), TangentOptions::default())
    }

    /// Tangent-space DOPRI5 (order 5, embedded order-4 estimate for adaptive steps through
    /// [`mbd_solve::run_adaptive`]) with default options.
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

    /// The reciprocal condition estimate of the last step's chart (the smallest over the
    /// largest diagonal of the factor of `Df^T`, dense or sparse): about the distance to the
    /// nearest singular configuration, relative to the mechanism's scale.
    pub fn rcond(&self) -> f64 {
        self.path.rcond()
    }

    /// [`IterationMatrix::Broyden`] on the dense path: the rank-one updates made and the resets
    /// to the centre's matrix since construction; `(0, 0)` otherwise.
    pub fn broyden_counts(&self) -> (usize, usize) {
        match &self.path {
            Path::Dense { chart, .. } => chart.broyden_counts(),
            Path::Sparse(_) => (0, 0),
        }
    }

    /// Whether the solver runs on the sparse chart ([`TangentOptions::linear_solver`]).
    pub fn is_sparse(&self) -> bool {
        matches!(self.path, Path::Sparse(_))
    }

    /// Dimension of the state equation, `2 (n - m)` (the sparse path integrates it in `2n`
    /// redundant coordinates).
    pub fn state_dim(&self) -> usize {
        self.path.dim()
    }

    fn check_sizes(&self, sys: &System, state: &State) -> Result<(), SolveError> {
        if sys.n_coords() != self.n || sys.n_constraints() != self.m_full {
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
        self.hist.clear();
        self.centred_at = f64::NAN;
        self.failures_here = 0;
        self.cur[..n].copy_from_slice(state.q.as_slice());
        self.cur[n..].copy_from_slice(state.v.as_slice());
        self.cur_t = state.t;
        self.cur_ok = self.m == 0;
        if self.m == 0 {
            return Ok(());
        }
        let r = self.path.residual(sys, &self.cur, state.t, &mut self.res);
        self.cur_ok = r <= self.options.newton.tol;
        if r.is_nan() || r > self.options.consistency_tol {
            return Err(SolveError::InvalidParameter {
                parameter: "state: ||(Phi, Phidot)||_inf",
                value: r,
                reason: "the state is not on the constraint manifold (above consistency_tol); \
                         project it first (mbd_solve::project_state)",
            });
        }
        Ok(())
    }

    fn store(&self, state: &mut State) {
        let n = self.n;
        state.q.as_mut_slice().copy_from_slice(&self.cur[..n]);
        state.v.as_mut_slice().copy_from_slice(&self.cur[n..]);
    }

    /// Centres the chart at the current state for a step of size `h` (which sets the
    /// chart's metric, [`ChartMetric::velocity_weight`]).
    fn centre(&mut self, sys: &System, t: f64, h: f64) -> Result<(), SolveError> {
        let n = self.n;
        let (q, v) = self.cur.split_at(n);
        self.path
            .set_velocity_weight(self.options.metric.velocity_weight(h));
        self.path.centre(sys, q, v, t)?;
        self.stats.charts += 1;
        Ok(())
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
        self.centre(sys, t, h)?;
        match self.attempt(sys, t, h) {
            Ok(w) => {
                self.account(&w);
                self.commit_history(h, t + h, &w);
                std::mem::swap(&mut self.cur, &mut self.xnew);
                self.bridge.accept(t + h, &self.cur[..self.n]);
                self.cur_t = t + h;
                self.cur_ok = true;
                self.stats.steps += 1;
                self.stats.max_residual = self.stats.max_residual.max(w.residual);
                out.newton_iterations += w.iterations;
                out.rhs_evals += w.rhs_evals;
                out.residual = out.residual.max(w.residual);
                out.condition = out.condition.max(w.condition);
                out.bridged_stages += w.bridged;
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
                        Attempt::Chart(f) => self.near_singular(sys, t, f.into_error()),
                        Attempt::Stage(e) | Attempt::SingularEnd(e) | Attempt::Hard(e) => e,
                    })
                }
            }
            Err(Attempt::Hard(e) | Attempt::SingularEnd(e)) => Err(e),
        }
    }
}

impl TangentRk {
    /// A chart map that failed at every halving, at a centre `t` within
    /// [`NEAR_SINGULAR_TOL`] of rank loss, is reported as the singular configuration it is
    /// (with the numerical rank at that tolerance, the dependent equations and their joints)
    /// rather than as a Newton failure; elsewhere `e` is returned.
    pub(super) fn near_singular(&mut self, sys: &System, t: f64, e: SolveError) -> SolveError {
        match self.path.singular_error(sys, t, NEAR_SINGULAR_TOL) {
            Some(SolveError::Singular { detail, .. }) => SolveError::Singular {
                t,
                what: mbd_solve::CHART_NEAR_RANK_LOSS,
                detail: format!("{detail} (pivots below {NEAR_SINGULAR_TOL:.0e}); {e}"),
            },
            _ => e,
        }
    }
}

/// A centre where a column-pivoted QR of `Phi_q^T` has a pivot below this fraction of the
/// largest (constraint gradients within about 0.6 degrees of dependence) is near a singular
/// configuration, for the report of a chart map that failed there.
const NEAR_SINGULAR_TOL: f64 = 1e-2;

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
impl Integrator for TangentRk {
    fn name(&self) -> String {
        format!("tangent-space {}", self.rk.tableau.name)
    }

    fn order(&self) -> Option<u32> {
        Some(self.rk.tableau.order)
    }

    fn keeps_constraints(&self) -> bool {
        true
    }
    fn reset(&mut self) {
        self.stats = TangentStats::default();
        self.cur_ok = false;
        self.hist.clear();
        self.centred_at = f64::NAN;
        self.failures_here = 0;
        self.bridge.clear();
        self.starter.reset();
    }

    fn as_adaptive(&mut self) -> Option<&mut dyn AdaptiveIntegrator> {
        if self.embedded_order().is_some() {
            Some(self)
        } else {
            None
        }
    }

    fn step(&mut self, sys: &System, state: &mut State, h: f64) -> Result<StepStats, SolveError> {
        self.check_sizes(sys, state)?;
        if !(h.is_finite() && h > 0.0) {
            return Err(SolveError::InvalidStep { h });
        }
        self.load(sys, state)?;
        self.centred_at = f64::NAN;
        let mut out = StepStats::default();
        let t = state.t;
        match self.advance(sys, t, h, 0, &mut out) {
            Ok(()) => {}
            Err(e) if mbd_solve::SingularStarter::refused_at_start(&e, t) => {
                let stats = self.starter.step(sys, state, h, e)?;
                self.after_starter();
                return Ok(stats);
            }
            Err(e) => return Err(e),
        }
        self.store(state);
        state.t = t + h;
        Ok(out)
    }
}
