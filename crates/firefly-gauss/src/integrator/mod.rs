//! The FA-DAE integrator: predictor, box, firefly run, optional Gauss-Newton polish,
//! completion of the accepted state.

use crate::accel::RefinedAcceleration;
use crate::error::FaDaeError;
use crate::objective::{StepProblem, Workspace};
use crate::options::{FaDaeOptions, MissPolicy, PartitionChoice, Predictor};
use crate::partition::{Partition, Pivoting};
use mbd_firefly::{Bounds, Firefly, Objective, SyncObjective};
use mbd_model::System;
use mbd_solve::linalg::DenseLu;
use mbd_solve::linalg::{max_abs, max_abs_diff};
use mbd_solve::{
    AccelerationSolver, ButcherTableau, Integrator, SingularStarter, SolveError, State, StepStats,
};
use std::sync::Mutex;

mod predict;
mod search;
mod stats;

pub use stats::{FaDaeStats, StepInfo};

/// Serial objective adaptor.
struct SerialObjective<'a> {
    prob: &'a StepProblem,
    sys: &'a System,
    ws: &'a mut Workspace,
}

impl Objective for SerialObjective<'_> {
    fn eval(&mut self, x: &[f64]) -> f64 {
        self.prob.objective(self.sys, self.ws, x)
    }
    fn dim(&self) -> Option<usize> {
        Some(self.prob.dim())
    }
}

/// Parallel objective adaptor: a pool of workspaces, any free one is used (the value does not
/// depend on which: every evaluation starts from the same data).
struct ParallelObjective<'a> {
    prob: &'a StepProblem,
    sys: &'a System,
    pool: &'a [Mutex<Workspace>],
}

impl SyncObjective for ParallelObjective<'_> {
    fn eval(&self, x: &[f64]) -> f64 {
        let k = self.pool.len();
        let start = rayon::current_thread_index().unwrap_or(0);
        loop {
            for i in 0..k {
                if let Ok(mut ws) = self.pool[(start + i) % k].try_lock() {
                    return self.prob.objective(self.sys, &mut ws, x);
                }
            }
            std::thread::yield_now();
        }
    }
    fn dim(&self) -> Option<usize> {
        Some(self.prob.dim())
    }
}

/// SplitMix64 finaliser: a well-mixed 64-bit hash of `x`.
fn splitmix64(mut x: u64) -> u64 {
    x = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
    x = (x ^ (x >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    x = (x ^ (x >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    x ^ (x >> 31)
}

/// The seed of attempt `attempt` of step `step` for the run seed `seed`.
pub fn step_seed(seed: u64, step: u64, attempt: u32) -> u64 {
    splitmix64(seed ^ splitmix64(step ^ splitmix64(u64::from(attempt) ^ 0xFA_DAE)))
}

/// The FA-DAE solver of paper C: an [`Integrator`] whose every step is a firefly minimisation
/// of the two-point Gauss residual of the equations of motion. See the crate documentation and
/// `docs/firefly-gauss.md`.
#[derive(Debug)]
pub struct FireflyGauss {
    opts: FaDaeOptions,
    n: usize,
    m: usize,
    partition: Partition,
    pivoting: Pivoting,
    prob: StepProblem,
    ws: Workspace,
    pool: Vec<Mutex<Workspace>>,
    acc: AccelerationSolver,
    lambda: Vec<f64>,
    end_acc: RefinedAcceleration,
    // RK4 predictor
    ka: [Vec<f64>; 4],
    kv: [Vec<f64>; 4],
    qs: Vec<f64>,
    vs: Vec<f64>,
    rq: Vec<f64>,
    rv: Vec<f64>,
    qhat: Vec<f64>,
    vhat: Vec<f64>,
    // decision space
    xhat: Vec<f64>,
    xtay: Vec<f64>,
    centre: Vec<f64>,
    half: Vec<f64>,
    best: Vec<f64>,
    corr: Vec<f64>,
    corr_prev: Vec<f64>,
    floor: Vec<f64>,
    /// Corrections available (0, 1, 2 = two or more).
    n_corr: u8,
    // polish
    gn_lu: DenseLu,
    gn_r: Vec<f64>,
    gn_rt: Vec<f64>,
    gn_dx: Vec<f64>,
    gn_xt: Vec<f64>,
    step_index: u64,
    last: StepInfo,
    stats: FaDaeStats,
    /// The first step from a singular configuration, where the dependent block of every
    /// partition is singular.
    starter: SingularStarter,
}

impl FireflyGauss {
    /// A solver for `sys`. The partition is chosen (or checked) at the system's consistent
    /// initial configuration (`State::consistent` at `t = 0`; the initial guess where it has
    /// none).
    ///
    /// # Errors
    /// Invalid options ([`FaDaeError::InvalidOption`], [`FaDaeError::Firefly`]), invalid
    /// independent coordinates ([`FaDaeError::InvalidPartition`]), a system without degrees of
    /// freedom or whose `Phi_q` at that configuration does not have the rank `m - k` the build
    /// found (`k` redundant equations; [`FaDaeError::Unsupported`]), unless the model starts
    /// on a singular configuration (`System::singular_start_equations`) and the partition is
    /// automatic: then it is provisional and the first step is the singular starter's
    /// ([`Integrator::step`]).
    pub fn new(sys: &System, options: FaDaeOptions) -> Result<Self, FaDaeError> {
        options.validate()?;
        // its acceleration solves are dense
        mbd_solve::refuse_large_spatial(sys, "the FA-DAE solver", mbd_solve::LinearSolver::Auto)
            .map_err(FaDaeError::Solve)?;
        let (n, m) = (sys.n_coords(), sys.n_constraints());
        // the start's configuration: the guess projected onto the constraints (a guess off
        // them, on a singular configuration, may have a rank the start does not), the guess
        // itself where it has no consistent state (the run reports that)
        let q0 = match State::consistent(sys, 0.0) {
            Ok(s) => s.q,
            Err(_) => sys.initial_guess().0,
        };
        let partition = match &options.partition {
            PartitionChoice::Auto => match Partition::auto(sys, q0.as_slice(), 0.0) {
                Ok(p) => p,
                // a model that starts on a singular configuration: the first step is the
                // starter's, and the partition is checked at its end
                Err(e) => Partition::at_singular_start(sys, q0.as_slice(), 0.0).ok_or(e)?,
            },
            PartitionChoice::Given(ind) => Partition::given(sys, q0.as_slice(), 0.0, ind)?,
        };
        let dof = partition.dof();
        let mut prob = StepProblem::new(sys, &partition);
        prob.newton_max_iter = options.newton_max_iter;
        let threads = rayon::current_num_threads().max(1) + 1;
        let pool = if options.parallel {
            (0..threads)
                .map(|_| Mutex::new(Workspace::new(sys)))
                .collect()
        } else {
            Vec::new()
        };
        let z = || vec![0.0; n];
        let d = || vec![0.0; 2 * dof];
        Ok(FireflyGauss {
            n,
            m,
            partition,
            pivoting: Pivoting::new(m, n, sys.n_redundant()),
            prob,
            ws: Workspace::new(sys),
            pool,
            acc: AccelerationSolver::new(sys),
            lambda: vec![0.0; m],
            end_acc: RefinedAcceleration::new(sys),
            ka: [z(), z(), z(), z()],
            kv: [z(), z(), z(), z()],
            qs: z(),
            vs: z(),
            rq: z(),
            rv: z(),
            qhat: z(),
            vhat: z(),
            xhat: d(),
            xtay: d(),
            centre: d(),
            half: d(),
            best: d(),
            corr: d(),
            corr_prev: d(),
            floor: d(),
            n_corr: 0,
            gn_lu: crate::objective::small_lu(2 * dof),
            gn_r: d(),
            gn_rt: d(),
            gn_dx: d(),
            gn_xt: d(),
            step_index: 0,
            last: StepInfo::default(),
            stats: FaDaeStats::new(),
            // (DOPRI5: one step's local error O(h^6), below the method's order 4)
            starter: SingularStarter::new(ButcherTableau::dopri5()),
            opts: options,
        })
    }

    /// The options in use.
    pub fn options(&self) -> &FaDaeOptions {
        &self.opts
    }

    /// The current coordinate partition.
    pub fn partition(&self) -> &Partition {
        &self.partition
    }

    /// Accelerations at the end of the last step (index-1 solve with one refinement step), with
    /// `||Phi_q a - gamma||_inf` as [`RefinedAcceleration::residual`].
    pub fn end_acceleration(&self) -> &RefinedAcceleration {
        &self.end_acc
    }

    /// The accepted decision vector `(z, zdot)` of the last step.
    pub fn last_solution(&self) -> &[f64] {
        &self.best
    }

    /// The objective of the last step's problem at the decision vector `x` (length
    /// `2 dof`; NaN if `x` cannot be completed or has the wrong length). For diagnostics and
    /// benchmarks: one call is one objective evaluation as the optimiser sees it.
    pub fn objective_at(&mut self, sys: &System, x: &[f64]) -> f64 {
        if x.len() != self.prob.dim() || sys.n_coords() != self.n {
            return f64::NAN;
        }
        self.prob.objective(sys, &mut self.ws, x)
    }

    /// What the last step did.
    pub fn last_step(&self) -> &StepInfo {
        &self.last
    }

    /// Totals since the last reset.
    pub fn stats(&self) -> &FaDaeStats {
        &self.stats
    }

    /// One step of size `h` from `state` (advancing `state.t` by `h`), with the crate's own
    /// error type. [`Integrator::step`] calls this.
    ///
    /// # Errors
    /// Wrong-size state or system, `h <= 0` or not finite, a singular dependent block, a
    /// failed completion of the accepted state, no feasible candidate, or a missed target under
    /// [`MissPolicy::Error`]. On error `state` is unchanged.
    pub fn try_step(
        &mut self,
        sys: &System,
        state: &mut State,
        h: f64,
    ) -> Result<StepStats, FaDaeError> {
        if !(h.is_finite() && h > 0.0) {
            return Err(SolveError::InvalidStep { h }.into());
        }
        if sys.n_coords() != self.n || sys.n_constraints() != self.m {
            return Err(SolveError::Dimension {
                what: "system (not the one the FA-DAE solver was built for)",
                expected: self.n,
                got: sys.n_coords(),
            }
            .into());
        }
        state.check(sys)?;
        if !state.is_finite() {
            return Err(SolveError::NonFinite {
                t: state.t,
                what: "state at the step's start",
            }
            .into());
        }
        let t0 = state.t;
        let mut info = StepInfo {
            t: t0,
            h,
            ..StepInfo::default()
        };
        (info.repartitioned, info.partition_quality) = self.check_partition(sys, state)?;
        self.predict(sys, state, h)?;
        let dof = self.partition.dof();
        let nd = 2 * dof;

        // the step problem (chord Jacobian at the predictor, metric at q0)
        self.prob.q_start.copy_from_slice(&self.qhat);
        // Phi's round-off scales with the translational coordinates (every third coordinate is
        // an angle, which enters only through sin and cos)
        let xy_max = state
            .q
            .iter()
            .enumerate()
            .filter(|(i, _)| i % 3 != 2)
            .fold(1.0f64, |a, (_, x)| a.max(x.abs())); // finite: checked above
        self.prob.newton_tol = self.opts.newton_tol * xy_max;
        self.prob
            .prepare(
                sys,
                &mut self.ws,
                t0,
                h,
                state.q.as_slice(),
                state.v.as_slice(),
            )
            .map_err(|what| SolveError::Singular {
                t: t0,
                what: "FA-DAE step matrix",
                detail: what.to_string(),
            })?;
        self.predictor_and_box(dof, h);
        let f_pred = {
            let centre = std::mem::take(&mut self.centre);
            let f = self.prob.objective(sys, &mut self.ws, &centre);
            self.centre = centre;
            f
        };
        // round-off floor of the objective: each of the 2 dof residual components carries
        // a few ulps of the independent coordinates
        let floor = {
            let zmax = max_abs(&self.xhat[..dof]);
            let s = f64::EPSILON * (1.0 + zmax);
            128.0 * dof as f64 * s * s
        };
        let target = if f_pred.is_finite() {
            (self.opts.tolerance * f_pred).max(floor)
        } else {
            floor
        };
        info.objective_predictor = f_pred;
        info.target = target;

        // firefly stages: each run is seeded with the best point so far and searches a box
        // centred on it; the box shrinks when the run ends inside it and widens when the best
        // point sits at a face.
        let b = self.opts.bounds.clone();
        let mut f_best = if self.opts.seed_predictor {
            f_pred
        } else {
            f64::INFINITY
        };
        self.best.copy_from_slice(&self.centre);
        let mut f_centre = f_pred;
        let mut stage = 0u32;
        loop {
            let remaining = self.opts.max_generations.saturating_sub(info.generations);
            let seed_centre = self.opts.seed_predictor || stage > 0;
            let result = self.run_firefly(sys, target, stage, remaining, seed_centre)?;
            info.generations += result.generations;
            info.evaluations += result.evaluations;
            info.stop_reason = result.stop_reason;
            info.stages = stage + 1;
            if result.best_f < f_best || (!f_best.is_finite() && result.best_f.is_finite()) {
                f_best = result.best_f;
                self.best.copy_from_slice(&result.best_x);
            }
            if f_best <= target || info.generations >= self.opts.max_generations {
                break;
            }
            if !f_best.is_finite() {
                // nothing feasible in the box: widen it
                if info.expansions >= b.max_expansions {
                    return Err(FaDaeError::NoFeasibleCandidate { t: t0 });
                }
                for w in self.half.iter_mut() {
                    *w *= b.expansion;
                }
                info.expansions += 1;
                stage += 1;
                continue;
            }
            let at_face = (0..nd).any(|k| {
                let w = self.half[k];
                w > 0.0
                    && (self.best[k] - self.centre[k]).abs() >= w * (1.0 - 2.0 * b.edge_fraction)
            });
            let mut changed = false;
            if at_face && info.expansions < b.max_expansions {
                for w in self.half.iter_mut() {
                    *w *= b.expansion;
                }
                info.expansions += 1;
                changed = true;
            } else {
                // shrink around the best point, by the distance reduction the stage achieved
                let reduction = if f_centre.is_finite() && f_centre > 0.0 {
                    (f_best / f_centre).sqrt()
                } else {
                    b.max_shrink
                };
                let factor = (b.safety * reduction).clamp(b.min_shrink, b.max_shrink);
                for k in 0..nd {
                    let w = (self.half[k] * factor).max(self.floor[k]);
                    changed |= w < self.half[k];
                    self.half[k] = w;
                }
            }
            if !changed && f_best >= f_centre {
                // at the floor and no progress: nothing more to gain
                break;
            }
            self.centre.copy_from_slice(&self.best);
            f_centre = f_best;
            stage += 1;
        }
        info.objective_firefly = f_best;
        info.reached_target = info.objective_firefly <= target;
        if !info.reached_target && self.opts.on_miss == MissPolicy::Error {
            return Err(FaDaeError::TargetMissed {
                t: t0,
                best: info.objective_firefly,
                target,
                generations: info.generations,
                reason: format!("{:?}", info.stop_reason),
            });
        }
        info.objective_final = info.objective_firefly;
        if self.opts.polish {
            let (it, evals, f) = self.polish(sys, info.objective_firefly);
            info.polish_iterations = it;
            info.polish_evaluations = evals;
            info.objective_final = f;
        }

        // accepted state
        let best = std::mem::take(&mut self.best);
        let done = self.prob.complete(sys, &mut self.ws, &best);
        self.best = best;
        if done.is_none() {
            return Err(SolveError::Newton {
                t: t0,
                residual: f64::NAN,
                iterations: self.opts.newton_max_iter,
                context: "FA-DAE completion of the accepted state".into(),
            }
            .into());
        }
        // accelerations of the accepted state (index-1 solve, refined): the third constraint
        // level at the grid point
        self.end_acc.solve(sys, &self.ws.q1, &self.ws.v1, t0 + h)?;
        state.q.as_mut_slice().copy_from_slice(&self.ws.q1);
        state.v.as_mut_slice().copy_from_slice(&self.ws.v1);
        state.t = t0 + h;
        std::mem::swap(&mut self.corr, &mut self.corr_prev);
        for k in 0..nd {
            self.corr[k] = self.best[k] - self.xhat[k];
        }
        self.n_corr = (self.n_corr + 1).min(2);
        self.step_index += 1;

        // bookkeeping
        let s = &mut self.stats;
        s.steps += 1;
        s.generations += info.generations;
        let evals = info.evaluations + info.polish_evaluations as u64 + 1;
        s.evaluations += evals;
        s.expansions += u64::from(info.expansions);
        s.target_misses += u64::from(!info.reached_target);
        s.repartitions += u64::from(info.repartitioned);
        s.polish_iterations += info.polish_iterations as u64;
        s.max_objective = s.max_objective.max(info.objective_final);
        if f_pred.is_finite() && f_pred > 100.0 * floor {
            let ratio = f_pred / info.objective_firefly.max(floor);
            s.min_ratio = s.min_ratio.min(ratio);
            s.log_ratio_sum += ratio.ln();
            s.ratio_count += 1;
        } else {
            s.roundoff_steps += 1;
        }
        self.last = info;
        Ok(StepStats {
            newton_iterations: info.polish_iterations,
            residual: info.objective_final.sqrt(),
            rhs_evals: 5,
            objective_evals: evals as usize,
            condition: self.end_acc.condition_estimate(),
            bridged_stages: 0,
        })
    }
}

impl Integrator for FireflyGauss {
    fn name(&self) -> String {
        let mut s = String::from("FA-DAE (firefly");
        if self.opts.polish {
            s += " + Gauss-Newton polish";
        }
        s += ")";
        s
    }

    /// [`FireflyGauss::try_step`]; from a singular configuration of a model that starts on
    /// one (every dependent block singular there), the step is taken by projected DOPRI5
    /// ([`SingularStarter`]; one step's local error `O(h^6)`, below the method's order 4) and
    /// the solver takes over at its end point, where its partition is checked as at every step.
    fn step(&mut self, sys: &System, state: &mut State, h: f64) -> Result<StepStats, SolveError> {
        match self.try_step(sys, state, h).map_err(SolveError::from) {
            Err(e) if SingularStarter::takes(&e, sys, state)? => {
                self.starter.step(sys, state, h, e)
            }
            r => r,
        }
    }

    fn keeps_constraints(&self) -> bool {
        true
    }
    fn reset(&mut self) {
        self.step_index = 0;
        self.n_corr = 0;
        self.stats = FaDaeStats::new();
        self.last = StepInfo::default();
        self.starter.reset();
    }

    fn order(&self) -> Option<u32> {
        Some(4)
    }
}
