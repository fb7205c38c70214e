//! The command line, declared with clap's derive API.

use clap::{Args, Parser, Subcommand};
use mbd::solve::registry::SolverSpec;
use std::path::PathBuf;

const MAIN_EXAMPLE: &str = "\
Examples:
  mbd check examples/models/slider_crank_spring.toml
  mbd run examples/models/slider_crank_spring.toml --solver symplectic:2 --t-end 5 --h 1e-3 --out slider.csv
  mbd plot slider.csv --y slider.x --y crank.theta -o slider.svg
  mbd animate slider.csv --model examples/models/slider_crank_spring.toml -o slider.html

`mbd solvers` lists the solvers (spec strings for --solver). See docs/cli.md.";

const RUN_EXAMPLE: &str = "\
Examples:
  mbd run examples/models/pendulum.toml --solver rk4 --t-end 2 --h 1e-3 --out pendulum.csv
  mbd run examples/models/four_bar.toml --solver symplectic:2:gamma=1 --t-end 5 --h 1e-3 --out fb.json --every 10
  mbd run examples/models/manipulator.json --solver tangent:dopri5 --t-end 3 --tol 1e-8 --out arm.csv
  mbd run examples/models/pendulum.toml --solver index1:dopri5 --t-end 1 --tol 1e-9 --out p.csv

Columns: t, every coordinate (body.x, body.y, body.theta), every velocity (d_body.x, ...),
the energy H, and the constraint residuals max_abs_phi = max|Phi| and
max_abs_phidot = max|Phi_q v + Phi_t|; with --reactions, JOINT.fx, JOINT.fy and JOINT.mz per
joint. Without --out the CSV goes to standard output.";

const CHECK_EXAMPLE: &str = "\
Example:
  mbd check examples/models/slider_crank_spring.toml";

const PLOT_EXAMPLE: &str = "\
Example:
  mbd plot slider.csv --y slider.x --y crank.x -o slider.svg
  mbd plot slider.csv --x crank.theta --y d_crank.theta";

const SOLVERS_EXAMPLE: &str = "\
Example:
  mbd solvers
  mbd solvers --markdown
  mbd run examples/models/pendulum.toml --solver symplectic:2:gamma=1 --t-end 2 --h 1e-3";

const ANIMATE_EXAMPLE: &str = "\
Examples:
  mbd animate slider.csv --model examples/models/slider_crank_spring.toml -o slider.html
  mbd run examples/models/heavy_top.toml --solver rk4-projected --t-end 2 --h 1e-3 --out top.csv
  mbd animate top.csv --model examples/models/heavy_top.toml --trace top:0,0,0.5 -o top.html

A planar model gives a 2D page; a model with spatial bodies a 3D page (each spatial body as its
equivalent inertia box, joints, links from centres of mass to joints, the path of the --trace
point; drag to orbit, wheel to zoom, double-click to reset the view). Open the page in a
browser; append #t=1.25 to its address to open it paused at t = 1.25 s, and on the 3D page
&az=30&el=20&zoom=1.5 to set the camera (degrees).";

/// `mbd`: simulate planar and spatial rigid multibody systems from model files.
#[derive(Debug, Parser)]
#[command(name = "mbd", version, about, after_help = MAIN_EXAMPLE)]
pub struct Cli {
    /// The command.
    #[command(subcommand)]
    pub command: Command,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Simulate a model with one of the solvers and write the trajectory (CSV or JSON).
    #[command(after_help = RUN_EXAMPLE)]
    Run(RunArgs),
    /// Validate a model file; print its bodies, joints, degrees of freedom and consistent
    /// initial state.
    #[command(after_help = CHECK_EXAMPLE)]
    Check(CheckArgs),
    /// Plot columns of a result CSV as an SVG figure.
    #[command(after_help = PLOT_EXAMPLE)]
    Plot(PlotArgs),
    /// Write a self-contained HTML page animating a result CSV with the model's geometry.
    #[command(after_help = ANIMATE_EXAMPLE)]
    Animate(AnimateArgs),
    /// List the registered solvers: spec string, order, adaptive, cost scaling, what each
    /// refuses.
    #[command(after_help = SOLVERS_EXAMPLE)]
    Solvers(SolversArgs),
}

/// Arguments of `mbd solvers`.
#[derive(Debug, Args)]
pub struct SolversArgs {
    /// Print the table as Markdown (the table README.md and docs/cli.md carry).
    #[arg(long)]
    pub markdown: bool,
}

/// Arguments of `mbd run`.
#[derive(Debug, Args)]
#[command(group(clap::ArgGroup::new("step").required(true).args(["h", "tol"])))]
pub struct RunArgs {
    /// Model file (.toml or .json).
    pub model: PathBuf,
    /// Solver spec string, e.g. rk4, symplectic:2, tangent:dopri5 (`mbd solvers` lists them).
    #[arg(long, short, value_parser = parse_solver)]
    pub solver: SolverSpec,
    /// End time in s (the run starts at t0 = 0).
    #[arg(long, allow_hyphen_values = true, value_parser = parse_t_end)]
    pub t_end: f64,
    /// Fixed step size in s.
    #[arg(long, allow_hyphen_values = true, value_parser = parse_h, conflicts_with = "tol")]
    pub h: Option<f64>,
    /// Error tolerance for adaptive steps (solvers with an embedded error estimate: `mbd
    /// solvers` marks them adaptive), from 1e-14 to below 1.
    #[arg(long, allow_hyphen_values = true, value_parser = parse_tol)]
    pub tol: Option<f64>,
    /// Absolute part of the adaptive error tolerance, in the model's units (default: --tol).
    /// The error of coordinate `y` may be `atol + tol |y|`: for a mechanism much smaller than
    /// its unit of length (millimetre parts in metres) give an atol scaled to it, e.g.
    /// --tol 1e-10 --atol 1e-13.
    #[arg(long, allow_hyphen_values = true, value_parser = parse_atol, requires = "tol")]
    pub atol: Option<f64>,
    /// Output file: .csv or .json, or - (or none) for CSV on standard output; a device such as
    /// /dev/null takes CSV.
    #[arg(long, short)]
    pub out: Option<PathBuf>,
    /// Write every K-th step (and always the first and the last state).
    #[arg(long, default_value = "1", value_parser = parse_count)]
    pub every: u64,
    /// Stop when a constraint residual exceeds this fraction of its equation's scale (the
    /// mechanism's size, or 1 rad): the drift guard's tolerance (default 0.01).
    #[arg(long, value_parser = parse_drift_tol, conflicts_with = "no_drift_guard")]
    pub drift_tol: Option<f64>,
    /// Run without the drift guard (to measure drift itself).
    #[arg(long)]
    pub no_drift_guard: bool,
    /// Save the final state as JSON (coordinate names, t, q, v), for --initial-state.
    #[arg(long)]
    pub save_state: Option<PathBuf>,
    /// Start from a state saved with --save-state (at its time; --t-end is the end time) instead
    /// of the model's initial state.
    #[arg(long)]
    pub initial_state: Option<PathBuf>,
    /// Refuse a run of more steps than this (fixed steps: t-end / h; adaptive: the budget of
    /// step attempts).
    #[arg(long, default_value = "1e9", value_parser = parse_count)]
    pub max_steps: u64,
    /// Add each joint's reaction: JOINT.fx, JOINT.fy (force on the joint's second body,
    /// global axes, N) and JOINT.mz (moment about the joint's point on that body, N m).
    #[arg(long)]
    pub reactions: bool,
}

/// Arguments of `mbd check`.
#[derive(Debug, Args)]
pub struct CheckArgs {
    /// Model file (.toml or .json).
    pub model: PathBuf,
}

/// Arguments of `mbd plot`.
#[derive(Debug, Args)]
pub struct PlotArgs {
    /// A result file written by `mbd run`: CSV, or JSON (`.json`).
    pub csv: PathBuf,
    /// Column(s) to plot against x (repeat --y for several curves).
    #[arg(long, required = true)]
    pub y: Vec<String>,
    /// Column on the horizontal axis.
    #[arg(long, default_value = "t")]
    pub x: String,
    /// Output SVG (default: the CSV's name with extension .svg).
    #[arg(long, short)]
    pub out: Option<PathBuf>,
}

/// Arguments of `mbd animate`.
#[derive(Debug, Args)]
pub struct AnimateArgs {
    /// A CSV written by `mbd run` for this model.
    pub csv: PathBuf,
    /// The model file the CSV was computed from.
    #[arg(long, short)]
    pub model: PathBuf,
    /// Output HTML page.
    #[arg(long, short)]
    pub out: PathBuf,
    /// The point whose path the 3D page draws (models with spatial bodies): BODY (its centre
    /// of mass) or BODY:x,y,z (a point in the body's frame, metres from its centre of mass, as
    /// in model files). Default: the last spatial body's centre of mass.
    #[arg(long, value_name = "BODY[:x,y,z]", value_parser = parse_trace, allow_hyphen_values = true)]
    pub trace: Option<TraceSpec>,
}

/// The `--trace` option of `mbd animate`: a spatial body's name and a point in its body frame.
#[derive(Clone, Debug, PartialEq)]
pub struct TraceSpec {
    /// The body's name (checked against the model by `mbd animate`).
    pub body: String,
    /// The point in the body frame (m, from the centre of mass); `None`: the centre of mass.
    pub point: Option<[f64; 3]>,
}

/// `BODY` or `BODY:x,y,z` (the last `:` followed by a comma-separated triple separates the
/// point; a body name may itself contain `:`).
fn parse_trace(s: &str) -> Result<TraceSpec, String> {
    let s = s.trim();
    if let Some((body, point)) = s.rsplit_once(':').filter(|(_, p)| p.contains(',')) {
        let xs: Vec<&str> = point.split(',').collect();
        let nums: Vec<f64> = xs
            .iter()
            .filter_map(|x| x.trim().parse::<f64>().ok())
            .filter(|x| x.is_finite())
            .collect();
        if xs.len() != 3 || nums.len() != 3 {
            return Err(format!(
                "'{point}' is not a point x,y,z of three finite numbers (metres in the body's \
                 frame), e.g. --trace {body}:0,0,0.5"
            ));
        }
        if body.is_empty() {
            return Err(format!(
                "no body name before ':{point}', e.g. --trace rod:{point}"
            ));
        }
        return Ok(TraceSpec {
            body: body.to_string(),
            point: Some([nums[0], nums[1], nums[2]]),
        });
    }
    if s.is_empty() {
        return Err("give a spatial body's name, e.g. --trace top or --trace top:0,0,0.5".into());
    }
    Ok(TraceSpec {
        body: s.to_string(),
        point: None,
    })
}

fn parse_solver(s: &str) -> Result<SolverSpec, String> {
    mbd::registry()
        .parse(s)
        .map_err(|e| format!("{e} (`mbd solvers` lists them)"))
}

fn parse_number(s: &str) -> Result<f64, String> {
    s.trim()
        .parse::<f64>()
        .map_err(|_| format!("'{s}' is not a number"))
}

/// `s` as a positive finite number, else the error `what` followed by ` (got {s})`.
fn parse_positive(s: &str, what: &str) -> Result<f64, String> {
    let x = parse_number(s)?;
    if x.is_finite() && x > 0.0 {
        Ok(x)
    } else {
        Err(format!("{what} (got {s})"))
    }
}

fn parse_h(s: &str) -> Result<f64, String> {
    parse_positive(
        s,
        "the step size must be a positive number of seconds, e.g. --h 1e-3",
    )
}

fn parse_atol(s: &str) -> Result<f64, String> {
    parse_positive(
        s,
        "the absolute tolerance must be positive and finite, e.g. --atol 1e-13",
    )
}

/// The smallest relative tolerance `--tol` takes: about 45 units of round-off, below which
/// the error test of an adaptive step can fail on rounding alone.
const MIN_TOL: f64 = 1e-14;

fn parse_tol(s: &str) -> Result<f64, String> {
    let t = parse_number(s)?;
    if t.is_finite() && (MIN_TOL..1.0).contains(&t) {
        Ok(t)
    } else if t > 0.0 && t < MIN_TOL {
        Err(format!(
            "the tolerance {s} is below what double precision can deliver (the error test \
             would fail on rounding alone); use --tol {MIN_TOL:e} or more, and --atol for a \
             small absolute error"
        ))
    } else {
        Err(format!(
            "the tolerance must lie in (0, 1), e.g. --tol 1e-8 (got {s})"
        ))
    }
}

/// A count of steps: a whole number at least 1, written as an integer or in exponent form
/// (`1e9`).
fn parse_count(s: &str) -> Result<u64, String> {
    let bad = || format!("expected a whole number of steps, at least 1 (got {s})");
    if let Ok(n) = s.trim().parse::<u64>() {
        return if n >= 1 { Ok(n) } else { Err(bad()) };
    }
    let x: f64 = s.trim().parse().map_err(|_| bad())?;
    if x.fract() == 0.0 && (1.0..=u64::MAX as f64).contains(&x) {
        Ok(x as u64)
    } else if x > u64::MAX as f64 {
        Err(format!("{s} is more than the largest count, {}", u64::MAX))
    } else {
        Err(bad())
    }
}

fn parse_drift_tol(s: &str) -> Result<f64, String> {
    parse_positive(
        s,
        "the drift tolerance must be a positive fraction of the equations' scale, e.g. \
         --drift-tol 0.05",
    )
}

fn parse_t_end(s: &str) -> Result<f64, String> {
    parse_positive(
        s,
        "the end time must be after the start time t0 = 0, e.g. --t-end 5",
    )
}
