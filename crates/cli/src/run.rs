//! `mbd run`: integrate a model and write the trajectory.

use crate::args::RunArgs;
use crate::error::CliError;
use indicatif::{ProgressBar, ProgressStyle};
use mbd::output::{not_conserved, output_columns, Collector};
use mbd::solve::registry::SolverSpec;
use mbd::Simulation;
use mbd_analysis::{CsvObserver, MeasureObserver};
use mbd_model::System;
use mbd_solve::{
    AdaptiveConfig, DriftGuard, Flow, Observer, RunConfig, RunStats, SolveError, State,
};
use std::io::{IsTerminal, Write};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// What a run did, for the summary line.
#[derive(Clone, Debug)]
pub struct RunSummary {
    /// The run loop's statistics.
    pub stats: RunStats,
    /// Energy and constraint errors over the samples (every step).
    pub measures: mbd_analysis::RunMeasures,
    /// Wall-clock time of the integration, s.
    pub wall_time: f64,
    /// Rows written.
    pub rows: usize,
    /// Why `H` is not conserved (dampers, time-dependent loads, drivers), if it is not: then
    /// `e(H)` is the energy exchanged, not an error, and the line says so instead.
    pub not_conserved: Option<String>,
    /// Where `H` is not conserved: the energy balance's largest residual relative to the
    /// largest `|H|` (`mbd_analysis::EnergyBalance`).
    pub balance: Option<f64>,
}

impl RunSummary {
    /// The one-line summary printed on standard error.
    pub fn line(&self, solver: &SolverSpec) -> String {
        let energy = match &self.not_conserved {
            None => format!("e(H) = {:.3e}", self.measures.e_h_scaled()),
            Some(why) => format!(
                "H not conserved ({why}): max |H - H0| / |H0| = {:.3e}, energy balance \
                 residual {:.3e} of max |H|",
                self.measures.e_h,
                self.balance.unwrap_or(f64::NAN)
            ),
        };
        format!(
            "mbd run: {} steps ({} rejected) with {solver}, {} rows; {energy}, \
             e(Phi) = {:.3e}, e(Phidot) = {:.3e}; wall time {:.3} s",
            self.stats.steps,
            self.stats.rejected_steps,
            self.rows,
            self.measures.e_phi,
            self.measures.e_phidot,
            self.wall_time
        )
    }
}

/// Where the rows go: streamed as CSV, or kept for one JSON document.
enum Sink {
    Csv(CsvObserver<Box<dyn Write>>),
    Json {
        rows: Collector,
        file: std::fs::File,
    },
}

impl Observer for Sink {
    fn observe(&mut self, sys: &System, s: &State, step: usize) -> Result<Flow, SolveError> {
        match self {
            Sink::Csv(c) => c.observe(sys, s, step),
            Sink::Json { rows, .. } => rows.observe(sys, s, step),
        }
    }
}

/// Counts the rows a sink writes (mirrors the sinks' sampling rule).
struct RowCount {
    every: usize,
    rows: usize,
    last_t: Option<f64>,
}

impl Observer for RowCount {
    fn observe(&mut self, _: &System, s: &State, step: usize) -> Result<Flow, SolveError> {
        if step % self.every == 0 {
            self.rows += 1;
            self.last_t = Some(s.t);
        }
        Ok(Flow::Continue)
    }
}

/// A progress bar over simulated time, drawn only when standard error is a terminal.
struct Progress {
    bar: Option<ProgressBar>,
    t_end: f64,
}

impl Progress {
    const TICKS: u64 = 1000;

    fn new(t_end: f64) -> Self {
        let bar = std::io::stderr().is_terminal().then(|| {
            let bar = ProgressBar::new(Self::TICKS);
            if let Ok(style) =
                ProgressStyle::with_template("{bar:40} {percent:>3}% t = {msg} s  [{elapsed}]")
            {
                bar.set_style(style);
            }
            bar
        });
        Progress { bar, t_end }
    }
}

impl Observer for Progress {
    fn observe(&mut self, _: &System, s: &State, _: usize) -> Result<Flow, SolveError> {
        if let Some(bar) = &self.bar {
            let frac = (s.t / self.t_end).clamp(0.0, 1.0);
            let pos = (frac * Self::TICKS as f64) as u64;
            if pos != bar.position() {
                bar.set_position(pos);
                bar.set_message(format!("{:.4}", s.t));
            }
        }
        Ok(Flow::Continue)
    }
}

fn open_sink(args: &RunArgs, sys: &System, every: usize) -> Result<Sink, CliError> {
    let csv = |w: Box<dyn Write>| {
        Sink::Csv(output_columns(CsvObserver::new(w), sys, args.reactions).with_every(every))
    };
    let stdout = || csv(Box::new(std::io::BufWriter::new(std::io::stdout())));
    let Some(out) = &args.out else {
        return Ok(stdout());
    };
    if out.as_os_str() == "-" {
        return Ok(stdout());
    }
    let ext = out
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    // a device or pipe (`/dev/null`, a named pipe) takes CSV whatever its name
    let device = std::fs::metadata(out).is_ok_and(|m| !m.is_file() && !m.is_dir());
    let json = match ext.as_deref() {
        Some("csv") => false,
        Some("json") => true,
        _ if device => false,
        _ => {
            return Err(CliError::Usage(format!(
                "--out '{}': the output file must end in .csv or .json (or be - for standard \
                 output)",
                out.display()
            )))
        }
    };
    // created (with its folder) before the run, so an unwritable path fails at once
    if let Some(dir) = out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|e| CliError::write(out, e))?;
    }
    let file = std::fs::File::create(out).map_err(|e| CliError::write(out, e))?;
    Ok(if json {
        Sink::Json {
            rows: Collector::new(sys, args.reactions, every),
            file,
        }
    } else {
        csv(Box::new(std::io::BufWriter::new(file)))
    })
}

/// The solvers that pass singular configurations on their branch (the report's
/// `own-singular` experiment): the advice after a singular stop.
const PASSES_SINGULAR: [&str; 3] = ["rk4-projected", "symplectic:1", "symplectic:2"];

fn solve_error(solver: &SolverSpec, source: SolveError) -> CliError {
    let hint = match &source {
        SolveError::ConstraintDrift {
            residual,
            tolerance,
            ..
        } if *residual > mbd_solve::BLOWUP_RATIO * *tolerance => {
            " (--h, or --tol with index1:dopri5 or tangent:dopri5; symplectic:S is implicit)"
        }
        SolveError::ConstraintDrift { .. } => {
            " (solvers that hold them: rk4-projected, symplectic:S, tangent:rk4; --drift-tol \
             loosens the guard, default 0.01, and --no-drift-guard turns it off)"
        }
        SolveError::TooManySteps { .. } => "",
        SolveError::Observer { .. } => "; check the output path and the free disk space",
        // a singular configuration: a smaller step does not help a solver that cannot pass
        SolveError::Singular { .. } => {
            let this = solver.spec();
            let hint = if PASSES_SINGULAR.contains(&this) {
                let others: Vec<&str> = PASSES_SINGULAR
                    .iter()
                    .copied()
                    .filter(|s| *s != this)
                    .collect();
                format!(
                    "; the mechanism is at or near a singular configuration: this solver \
                     usually passes such configurations on its branch (the report's \
                     own-singular experiment) and steps over a step that lands on one, but \
                     it stops where it cannot: a run that ends or starts on the configuration \
                     (a --t-end or initial state a little off it passes), or one it cannot \
                     pass at this step: another --h may pass, or {}",
                    others.join(" or ")
                )
            } else {
                format!(
                    "; the mechanism is at or near a singular configuration: the solvers that \
                     keep the constraints pass such configurations on their branch ({}; see \
                     the report's own-singular experiment), the others stop there",
                    PASSES_SINGULAR.join(", ")
                )
            };
            return CliError::Solve {
                solver: solver.to_string(),
                source: Box::new(source),
                hint,
            };
        }
        // a refusal of the model or the setting: no step size helps
        SolveError::Unsupported(_)
        | SolveError::InvalidParameter { .. }
        | SolveError::Dimension { .. }
        | SolveError::SolverSpec { .. }
        | SolveError::UnknownSolver { .. }
        | SolveError::Model(_) => "; `mbd solvers` lists what each solver refuses",
        _ => "; try a smaller --h (or --tol), or another --solver",
    };
    CliError::Solve {
        solver: solver.to_string(),
        source: Box::new(source),
        hint: hint.into(),
    }
}

/// The saved state at `path` (`--initial-state`), as saved: not projected again, so a restart
/// continues the run it was saved from (the run loop's drift guard checks it like every state).
fn restart_state(sys: &System, path: &Path) -> Result<State, CliError> {
    mbd_analysis::load_state(sys, path).map_err(|e| CliError::Usage(e.to_string()))
}

/// Warns about given initial values that the consistent initial state changed (at most five
/// named), with how to keep them.
fn warn_initial_changes(sys: &System, state: &State) {
    let changes = mbd_solve::initial_changes(sys, state.q.as_slice(), state.v.as_slice());
    if changes.is_empty() {
        return;
    }
    let shown: Vec<String> = changes
        .iter()
        .take(5)
        .map(|c| {
            format!(
                "{} given {} used {}",
                c.name,
                mbd_model::format_number(c.given),
                mbd_model::format_number(c.used)
            )
        })
        .collect();
    let more = if changes.len() > 5 {
        format!(" and {} more", changes.len() - 5)
    } else {
        String::new()
    };
    // `inputs` exist for planar bodies only: a change on a spatial body gets other advice
    let planar = changes.iter().any(|c| {
        let name = c.name.strip_prefix("d_").unwrap_or(&c.name);
        name.rsplit_once('.')
            .is_some_and(|(body, _)| sys.body_handle(body).is_some())
    });
    let advice = if planar {
        "to keep a value, mark it an input of its body (inputs = [\"d_theta\"] in the model \
         file, Body::input_velocity in code) and the others are solved for"
    } else {
        "spatial bodies have no inputs: to keep the values, give positions, orientations and \
         velocities that satisfy the joints"
    };
    note!(
        "warning: the initial state was made consistent with the constraints, which changed \
         given values: {}{more}; {advice}",
        shown.join("; ")
    );
}

/// Runs the simulation, writes the output and returns the summary.
pub fn run(args: &RunArgs) -> Result<RunSummary, CliError> {
    if args.tol.is_some() && !args.solver.adaptive() {
        let adaptive: Vec<&str> = mbd::registry()
            .variants()
            .filter(|(_, v)| v.adaptive)
            .map(|(_, v)| v.spec)
            .collect();
        return Err(CliError::Usage(format!(
            "--tol needs a solver with an embedded error estimate, and '{}' has none: give a \
             fixed step with --h, or use --tol with one of: {}",
            args.solver,
            adaptive.join(", ")
        )));
    }
    let sys = crate::model::load(&args.model)?;
    if sys.n_redundant() > 0 {
        let names: Vec<&str> = sys
            .redundant_equations()
            .iter()
            .map(|e| e.equation.as_str())
            .collect();
        note!(
            "warning: {} redundant constraint equation(s) ({}): combinations of the others, \
             carrying no multiplier (`mbd check` lists them; redundant_constraints = \"reject\" \
             in the model file refuses them)",
            names.len(),
            names.join(", ")
        );
    }
    if let Some(note) = sys.singular_start_note() {
        note!("warning: {note}");
    }
    let state = match &args.initial_state {
        None => {
            let state = State::consistent(&sys, 0.0).map_err(|source| CliError::Initial {
                path: args.model.display().to_string(),
                source: Box::new(source),
            })?;
            warn_initial_changes(&sys, &state);
            state
        }
        Some(path) => restart_state(&sys, path)?,
    };
    if args.t_end <= state.t {
        return Err(CliError::Usage(format!(
            "--t-end {} is not after the initial state's time {} (a saved state's time is kept; \
             --t-end is the end time, not a duration)",
            mbd_model::format_number(args.t_end),
            mbd_model::format_number(state.t)
        )));
    }
    let guard = if args.no_drift_guard {
        None
    } else {
        Some(DriftGuard {
            position_tol: args.drift_tol.unwrap_or(DriftGuard::DEFAULT_POSITION_TOL),
            ..DriftGuard::default()
        })
    };
    let max_steps = usize::try_from(args.max_steps).unwrap_or(usize::MAX);
    let plan: mbd::Plan = match (args.h, args.tol) {
        (_, Some(tol)) => {
            let mut cfg = AdaptiveConfig::new(args.t_end, tol);
            if let Some(atol) = args.atol {
                cfg.controller.atol = atol;
            }
            cfg.drift_guard = guard;
            cfg.max_steps = max_steps;
            cfg.into()
        }
        (Some(h), None) => {
            let steps = mbd_solve::step_count(state.t, args.t_end, h)
                .map_err(|e| CliError::Usage(e.to_string()))?;
            if steps > max_steps {
                return Err(CliError::Usage(format!(
                    "the run needs {steps} steps (--t-end {} / --h {}), more than --max-steps {}: \
                     raise --max-steps to run it, or take a larger --h",
                    mbd_model::format_number(args.t_end),
                    mbd_model::format_number(h),
                    args.max_steps
                )));
            }
            let span = args.t_end - state.t;
            if h > span {
                note!(
                    "warning: --h {} is longer than the run ({} s): it is one step of {} s; \
                     give a smaller --h for a trajectory",
                    mbd_model::format_number(h),
                    mbd_model::format_number(span),
                    mbd_model::format_number(span)
                );
            }
            let mut cfg = RunConfig::new(args.t_end, h);
            cfg.drift_guard = guard;
            cfg.into()
        }
        (None, None) => {
            return Err(CliError::Usage(
                "give a step size with --h (or a tolerance with --tol)".into(),
            ))
        }
    };
    let integrator = args
        .solver
        .build(&sys)
        .map_err(|e| solve_error(&args.solver, mbd::registry().with_advice(&sys, e)))?;
    if let Some(c) = args.solver.caveat(&sys) {
        note!("warning: {c}");
    }
    let every = usize::try_from(args.every).unwrap_or(usize::MAX);
    let why_not_conserved = not_conserved(&sys);
    let sink = open_sink(args, &sys, every)?;
    let measures = MeasureObserver::new(&sys, false);
    let count = RowCount {
        every,
        rows: 0,
        last_t: None,
    };
    let progress = Progress::new(args.t_end);
    let bar = progress.bar.clone();
    let mut obs = (measures, (count, (sink, progress)));
    let mut sim = Simulation::from_parts(sys, args.solver.spec(), integrator, state)
        .map_err(|e| solve_error(&args.solver, solve_part(e)))?;
    let started = Instant::now();
    let result = sim.run_observed(plan, &mut obs);
    let wall_time = started.elapsed().as_secs_f64();
    if let Some(bar) = bar {
        bar.finish_and_clear();
    }
    let stats = result.map_err(|e| solve_error(&args.solver, solve_part(e)))?;
    let (measures, (count, (sink, _))) = obs;
    let balance = match &sink {
        Sink::Csv(c) => c.energy_balance(),
        Sink::Json { rows, .. } => rows.energy_balance(),
    }
    .map(|b| b.max_residual() / b.max_energy().max(f64::MIN_POSITIVE));
    let final_written = count.last_t == Some(sim.state().t);
    let rows = count.rows + usize::from(!final_written);
    finish(
        args,
        sim.system(),
        sim.state(),
        sink,
        stats,
        &measures,
        wall_time,
    )?;
    Ok(RunSummary {
        stats,
        measures: measures.measures(),
        wall_time,
        rows,
        not_conserved: why_not_conserved,
        balance,
    })
}

/// The solver-side error of a run (the run loop returns nothing else).
fn solve_part(e: mbd::Error) -> SolveError {
    match e {
        mbd::Error::Solve(e) => e,
        other => SolveError::Unsupported(other.to_string()),
    }
}

fn out_path(args: &RunArgs) -> PathBuf {
    args.out.clone().unwrap_or_else(|| PathBuf::from("-"))
}

fn finish(
    args: &RunArgs,
    sys: &System,
    state: &State,
    sink: Sink,
    stats: RunStats,
    measures: &MeasureObserver,
    wall_time: f64,
) -> Result<(), CliError> {
    if let Some(path) = &args.save_state {
        mbd_analysis::save_state(sys, state, path).map_err(|e| CliError::write(path, e))?;
    }
    let out = out_path(args);
    match sink {
        Sink::Csv(mut c) => c.finish(sys, state).map_err(|e| CliError::write(&out, e)),
        Sink::Json { mut rows, file } => {
            rows.finish(sys, state)
                .map_err(|e| solve_error(&args.solver, e))?;
            let columns = rows.columns(sys);
            let data: Vec<&[f64]> = rows.data().chunks(columns.len().max(1)).collect();
            let m = measures.measures();
            let doc = serde_json::json!({
                "model": args.model.display().to_string(),
                "solver": args.solver.to_string(),
                "h": args.h,
                "tol": args.tol,
                "atol": args.atol,
                "t_end": args.t_end,
                "every": args.every,
                "columns": columns,
                "rows": data,
                "summary": {
                    "steps": stats.steps,
                    "rejected_steps": stats.rejected_steps,
                    "e_h": m.e_h_scaled(),
                    "energy_scale": m.energy_scale(),
                    "e_phi": m.e_phi,
                    "e_phidot": m.e_phidot,
                    "wall_time_s": wall_time,
                },
            });
            write_json(&out, file, &doc)
        }
    }
}

fn write_json(path: &Path, file: std::fs::File, doc: &serde_json::Value) -> Result<(), CliError> {
    let mut w = std::io::BufWriter::new(file);
    serde_json::to_writer(&mut w, doc).map_err(|e| CliError::write(path, e))?;
    writeln!(w)
        .and_then(|()| w.flush())
        .map_err(|e| CliError::write(path, e))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A singular configuration names the solvers that pass it, never "a smaller --h".
    #[test]
    fn a_singular_stop_names_the_solvers_that_pass() {
        let spec = mbd::registry().parse("rk4").expect("spec");
        let e = solve_error(
            &spec,
            SolveError::Singular {
                t: 0.357,
                what: "configuration (Phi_q near rank loss)",
                detail: "condition estimate 2e7".into(),
            },
        )
        .to_string();
        assert!(
            e.contains("rk4-projected") && e.contains("symplectic:2"),
            "{e}"
        );
        assert!(!e.contains("smaller --h"), "{e}");
    }
}
