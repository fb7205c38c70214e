//! One run the way `mbd run` does it: the consistent initial state, the same plan (fixed steps
//! or adaptive ones, drift guard, step budget), the registry's solver, and the rows of the
//! CLI's output ([`mbd::output::Collector`]), so a result equals the CLI's output bit for bit.
//! Plain Rust: no Python object is touched, so it runs with the GIL released.

use crate::errors::Failure;
use mbd::model::System;
use mbd::output::{not_conserved, Collector};
use mbd::solve::{AdaptiveConfig, DriftGuard, RunConfig, RunStats, State, StopReason};
use mbd::Simulation;
use mbd_analysis::MeasureObserver;
use std::time::Instant;

/// A run's options (the `mbd run` flags of the same names).
#[derive(Clone, Debug)]
pub struct RunOptions {
    /// The solver's spec string (`"symplectic:2"`).
    pub solver: String,
    /// The end time, s.
    pub t_end: f64,
    /// The fixed step, s.
    pub h: Option<f64>,
    /// The tolerance of adaptive steps.
    pub tol: Option<f64>,
    /// The absolute part of the adaptive tolerance (`None`: `tol`).
    pub atol: Option<f64>,
    /// Keep every k-th step (and always the first and the last state).
    pub every: usize,
    /// Add the joint reactions.
    pub reactions: bool,
    /// The drift guard's tolerance (`None`: its default, 0.01).
    pub drift_tol: Option<f64>,
    /// Whether the drift guard is on.
    pub drift_guard: bool,
    /// The step budget.
    pub max_steps: usize,
}

/// What a run kept: the CLI's columns and rows, and its statistics.
#[derive(Clone, Debug)]
pub struct RunData {
    /// The column names.
    pub columns: Vec<String>,
    /// The rows, row-major.
    pub data: Vec<f64>,
    /// The number of rows.
    pub rows: usize,
    /// The number of coordinates.
    pub n_coordinates: usize,
    /// The run loop's statistics.
    pub stats: RunStats,
    /// The energy and constraint errors over every step.
    pub measures: mbd_analysis::RunMeasures,
    /// Wall-clock time of the integration, s.
    pub wall_time: f64,
    /// Why `H` is not conserved, where it is not.
    pub not_conserved: Option<String>,
    /// Where `H` is not conserved: the energy balance's largest residual relative to `max |H|`.
    pub balance: Option<f64>,
    /// Warnings `mbd run` prints (initial values the consistent state changed, redundant
    /// equations, a singular initial configuration, the solver's caveat for this model, the
    /// run's passages near or over singular configurations).
    pub warnings: Vec<String>,
}

impl RunData {
    /// The stop reason as text: `"end"`, `"observer"` or `"event"`.
    pub fn stop(&self) -> &'static str {
        match self.stats.stop {
            StopReason::ReachedEnd => "end",
            StopReason::Observer => "observer",
            _ => "event",
        }
    }
}

fn warnings(sys: &System, state: &State) -> Vec<String> {
    let mut out = Vec::new();
    if sys.n_redundant() > 0 {
        let names: Vec<&str> = sys
            .redundant_equations()
            .iter()
            .map(|e| e.equation.as_str())
            .collect();
        out.push(format!(
            "{} redundant constraint equation(s) ({}): combinations of the others, carrying no \
             multiplier",
            names.len(),
            names.join(", ")
        ));
    }
    out.extend(sys.singular_start_note());
    let changes = mbd::solve::initial_changes(sys, state.q.as_slice(), state.v.as_slice());
    if !changes.is_empty() {
        let shown: Vec<String> = changes
            .iter()
            .map(|c| {
                format!(
                    "{} given {} used {}",
                    c.name,
                    mbd::model::format_number(c.given),
                    mbd::model::format_number(c.used)
                )
            })
            .collect();
        out.push(format!(
            "the initial state was made consistent with the constraints, which changed given \
             values: {} (mark a value an input of its body to keep it)",
            shown.join("; ")
        ));
    }
    out
}

/// Runs `sys` as `mbd run` would with the same options.
pub fn run_model(sys: &System, opts: &RunOptions) -> Result<RunData, Failure> {
    let spec = mbd::registry().parse(&opts.solver)?;
    if opts.tol.is_some() && !spec.adaptive() {
        let adaptive: Vec<&str> = mbd::registry()
            .variants()
            .filter(|(_, v)| v.adaptive)
            .map(|(_, v)| v.spec)
            .collect();
        return Err(Failure::argument(format!(
            "tol needs a solver with an embedded error estimate, and '{}' has none: give a fixed \
             step h, or use tol with one of: {}",
            opts.solver,
            adaptive.join(", ")
        )));
    }
    let state = State::consistent(sys, 0.0)?;
    let mut warnings = warnings(sys, &state);
    // what the solver does not deliver on this model (e.g. the modified schemes with drivers)
    warnings.extend(spec.caveat(sys));
    if opts.t_end.is_nan() || opts.t_end <= state.t {
        return Err(Failure::argument(format!(
            "t_end {} is not after the initial state's time {}",
            mbd::model::format_number(opts.t_end),
            mbd::model::format_number(state.t)
        )));
    }
    let guard = opts.drift_guard.then(|| DriftGuard {
        position_tol: opts.drift_tol.unwrap_or(DriftGuard::DEFAULT_POSITION_TOL),
        ..DriftGuard::default()
    });
    let plan: mbd::Plan = match (opts.h, opts.tol) {
        (Some(_), Some(_)) => return Err(Failure::argument("give h or tol, not both")),
        (_, None) if opts.atol.is_some() => {
            return Err(Failure::argument("atol needs tol (adaptive steps)"))
        }
        (None, Some(tol)) => {
            let mut cfg = AdaptiveConfig::new(opts.t_end, tol);
            if let Some(atol) = opts.atol {
                if !(atol.is_finite() && atol > 0.0) {
                    return Err(Failure::argument(format!(
                        "atol must be positive and finite, got {atol}"
                    )));
                }
                cfg.controller.atol = atol;
            }
            cfg.drift_guard = guard;
            cfg.max_steps = opts.max_steps;
            cfg.into()
        }
        (Some(h), None) => {
            let steps = mbd::solve::step_count(state.t, opts.t_end, h)?;
            if steps > opts.max_steps {
                return Err(Failure::argument(format!(
                    "the run needs {steps} steps (t_end {} / h {}), more than max_steps {}",
                    mbd::model::format_number(opts.t_end),
                    mbd::model::format_number(h),
                    opts.max_steps
                )));
            }
            let mut cfg = RunConfig::new(opts.t_end, h);
            cfg.drift_guard = guard;
            cfg.into()
        }
        (None, None) => {
            return Err(Failure::argument(
                "give a step size h (or a tolerance tol for an adaptive solver)",
            ))
        }
    };
    let integrator = spec
        .build(sys)
        .map_err(|e| mbd::registry().with_advice(sys, e))?;
    let mut obs = (
        MeasureObserver::new(sys, false),
        Collector::new(sys, opts.reactions, opts.every),
    );
    let mut sim = Simulation::from_parts(sys.clone(), spec.spec(), integrator, state)?;
    let started = Instant::now();
    let result = sim.run_observed(plan, &mut obs);
    let wall_time = started.elapsed().as_secs_f64();
    let stats = result?;
    // the run's own warning, as `mbd run` prints it (passages near or over singular
    // configurations)
    warnings.extend(stats.warning());
    let (measures, mut rows) = obs;
    rows.finish(sim.system(), sim.state())?;
    let balance = rows
        .energy_balance()
        .map(|b| b.max_residual() / b.max_energy().max(f64::MIN_POSITIVE));
    let columns = rows.columns(sim.system());
    Ok(RunData {
        columns,
        rows: rows.rows(),
        data: rows.into_data(),
        n_coordinates: sys.n_coords(),
        stats,
        measures: measures.measures(),
        wall_time,
        not_conserved: not_conserved(sys),
        balance,
        warnings,
    })
}
