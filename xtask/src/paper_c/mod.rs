//! Paper C's experiments: the firefly-algorithm DAE solver (FA-DAE, `mbd-firefly-gauss`) on
//! the two-link manipulator. Table 1 (step sizes), Table 2 (against RK4), Figs. 2-5, the
//! measured orders, and the determinism checks.

mod table1;
use table1::{table1_polished, table1_pure};
mod checks;
use checks::{determinism, orders, table2};

use crate::report::{
    fmt_e, num, Claim, Ctx, Experiment, FigureRef, PaperValue, Part, Section, Table,
};
use mbd_analysis::plot::{Figure, Series};
use mbd_analysis::{fit_order, MeasureObserver, RunMeasures};
use mbd_firefly_gauss::{FaDaeOptions, FaDaeStats, FireflyGauss, RefinedAcceleration};
use mbd_model::{models, System};
use mbd_rk4::{Rk4, Rk4Options};
use mbd_solve::linalg::{max_abs, max_abs_diff};
use mbd_solve::{
    reference_trajectory, run, ButcherTableau, Flow, Integrator, Observer, RunConfig, SolveError,
    State,
};
use serde_json::{json, Value};
use std::time::Instant;

/// The run seed of every FA-DAE run of the report.
const SEED: u64 = 2021;

const PAPER_TIME: f64 = 20.0;
const QUICK_TIME: f64 = 1.0;

/// One row of the paper's Table 1: h, e(H), MRE(H), e(Phi), e(Phidot), e(Phiddot), runtime.
struct PaperRow {
    h: f64,
    e_h: PaperValue,
    mre_h: PaperValue,
    e_phi: PaperValue,
    e_phidot: PaperValue,
    e_phiddot: PaperValue,
    runtime: f64,
}

fn paper_row(r: &'static crate::paper_values::PaperCRow) -> PaperRow {
    PaperRow {
        h: r.h,
        e_h: r.e_h.value(),
        mre_h: r.mre_h.value(),
        e_phi: r.e_phi.value(),
        e_phidot: r.e_phidot.value(),
        e_phiddot: r.e_phiddot.value(),
        runtime: r.runtime,
    }
}

/// Paper C's Table 1 rows (from `xtask/data/paper_values.json`).
fn paper_table1() -> Result<Vec<PaperRow>, String> {
    let v = crate::paper_values::get()?;
    Ok(v.paper_c.table1.rows.iter().map(paper_row).collect())
}

/// Paper C's RK4 row of Table 2.
fn paper_rk4() -> Result<PaperRow, String> {
    Ok(paper_row(&crate::paper_values::get()?.paper_c.rk4))
}

/// Paper C's measures plus the acceleration residual from the refined index-1 solve and,
/// optionally, sampled series for the figures.
struct PcObserver {
    meas: MeasureObserver,
    acc: RefinedAcceleration,
    e_phiddot: f64,
    stride: usize,
    /// t, tip x, tip y, H, T, V, |Phi|, |Phidot|, |Phiddot|
    series: Vec<[f64; 9]>,
    phi: Vec<f64>,
}

impl PcObserver {
    fn new(sys: &System, stride: usize) -> Self {
        PcObserver {
            meas: MeasureObserver::new(sys, false),
            acc: RefinedAcceleration::new(sys),
            e_phiddot: 0.0,
            stride,
            series: Vec::new(),
            phi: vec![0.0; sys.n_constraints()],
        }
    }

    fn measures(&self) -> RunMeasures {
        let mut m = self.meas.measures();
        m.e_phiddot = self.e_phiddot;
        m
    }
}

impl Observer for PcObserver {
    fn observe(&mut self, sys: &System, s: &State, step: usize) -> Result<Flow, SolveError> {
        self.meas.add(sys, s)?;
        let (q, v) = (s.q.as_slice(), s.v.as_slice());
        self.acc.solve(sys, q, v, s.t)?;
        let r = self.acc.residual();
        self.e_phiddot = self.e_phiddot.max(r);
        if self.stride > 0 && step.is_multiple_of(self.stride) {
            let tip = sys.point_position(
                sys.body_handles().nth(1).expect("the model has two bodies"),
                [0.5, 0.0],
                q,
            );
            sys.phi(q, s.t, &mut self.phi);
            let ep = max_abs(&self.phi);
            sys.phi_dot(q, v, s.t, &mut self.phi);
            let ev = max_abs(&self.phi);
            let (kin, pot) = (sys.kinetic(v), sys.potential(q));
            self.series
                .push([s.t, tip.x, tip.y, kin + pot, kin, pot, ep, ev, r]);
        }
        Ok(Flow::Continue)
    }
}

/// CPU time of the calling thread in seconds (Linux: `/proc/thread-self/schedstat`, whose first
/// field is the time spent on a CPU in nanoseconds), `None` elsewhere.
fn thread_cpu_seconds() -> Option<f64> {
    let s = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    let ns: f64 = s.split_whitespace().next()?.parse().ok()?;
    Some(ns * 1e-9)
}

/// The clock `simulate` reports as runtime: the thread's CPU time where available.
fn runtime_clock() -> &'static str {
    if thread_cpu_seconds().is_some() {
        "CPU"
    } else {
        "wall-clock"
    }
}

/// The outcome of one simulation.
struct RunOut {
    m: RunMeasures,
    /// CPU seconds of the (single) thread that ran the solver; wall seconds where the CPU time
    /// is not available.
    runtime: f64,
    wall: f64,
    state: State,
    series: Vec<[f64; 9]>,
}

fn simulate(
    sys: &System,
    integ: &mut dyn Integrator,
    t_end: f64,
    h: f64,
    stride: usize,
) -> Result<RunOut, String> {
    let mut s = State::consistent(sys, 0.0).map_err(|e| e.to_string())?;
    let mut obs = PcObserver::new(sys, stride);
    let cpu0 = thread_cpu_seconds();
    let t = Instant::now();
    // paper C's RK4 row measures the drift of unstabilised RK4: no drift guard
    let cfg = RunConfig::new(t_end, h).without_drift_guard();
    run(integ, sys, &mut s, cfg, &mut obs)
        .map_err(|e| format!("{} at h = {h}: {e}", integ.name()))?;
    let wall = t.elapsed().as_secs_f64();
    let runtime = match (cpu0, thread_cpu_seconds()) {
        (Some(a), Some(b)) if b > a => b - a,
        _ => wall,
    };
    Ok(RunOut {
        m: obs.measures(),
        runtime,
        wall,
        state: s,
        series: obs.series,
    })
}

fn fadae(
    sys: &System,
    opts: FaDaeOptions,
    t_end: f64,
    h: f64,
    stride: usize,
) -> Result<(RunOut, FaDaeStats), String> {
    let mut fa = FireflyGauss::new(sys, opts).map_err(|e| e.to_string())?;
    let out = simulate(sys, &mut fa, t_end, h, stride)?;
    Ok((out, *fa.stats()))
}

fn options(polish: bool) -> FaDaeOptions {
    FaDaeOptions::default().seed(SEED).polish(polish)
}

/// The report's name of a variant. The pure firefly is the paper's algorithm, but its stopping
/// rule is the project's default (the paper states epsilon = 1e-7: `FaDaeOptions::paper`,
/// Table 2).
fn variant_name(polish: bool) -> String {
    let tol = FaDaeOptions::default().tolerance;
    if polish {
        format!("FA-DAE + Gauss-Newton polish (project defaults, tolerance {tol:e})")
    } else {
        format!("FA-DAE (pure firefly, project defaults: tolerance {tol:e})")
    }
}

fn bits(s: &State) -> Vec<u64> {
    s.q.iter().chain(s.v.iter()).map(|x| x.to_bits()).collect()
}

fn settings(sec: &mut Section, ctx: &Ctx, t_end: f64) {
    let o = FaDaeOptions::default();
    sec.setting("system", "two-link manipulator (models::manipulator: 1 kg, 1 m rods, g = 9.81, theta = (pi/3, 0), at rest; H0 = 12.7436 J)");
    sec.setting(
        "simulated time",
        format!(
            "{t_end} s{}",
            if ctx.quick {
                " (quick mode; paper: 20 s)"
            } else {
                ""
            }
        ),
    );
    sec.setting("seed", SEED);
    sec.setting(
        "firefly",
        format!(
            "population {}, beta0 {}, gamma {}, alpha {}, alpha decay {} per generation, snapshot variant, at most {} generations per step",
            o.firefly.population, o.firefly.beta0, o.firefly.gamma, o.firefly.alpha, o.firefly.alpha_decay, o.max_generations
        ),
    );
    sec.setting(
        "stopping rule",
        format!(
            "project default: objective <= {:e} x objective(predictor) (or its round-off floor); stages of at most {} generations, a stage ends after {} generations without improvement. The paper states epsilon = {:e} (FaDaeOptions::paper, read as the relative target: Table 2)",
            o.tolerance,
            o.stage_generations,
            o.stagnation_generations.unwrap_or(0),
            FaDaeOptions::paper().tolerance
        ),
    );
    sec.setting(
        "box",
        format!(
            "centred on RK4 + last correction; half-width {} x the change of the correction (positions), velocities balanced (x 1/h); shrunk between stages, widened x{} at a face",
            o.bounds.safety, o.bounds.expansion
        ),
    );
    sec.setting("e(Phiddot)", "||Phi_q a - gamma||_inf with a from the index-1 solve refined by one step of iterative refinement (mbd_firefly_gauss::RefinedAcceleration), same for every solver");
    sec.setting(
        "runtime",
        format!(
            "{} seconds of the thread that ran the whole run (serial objective, one core), measures included",
            runtime_clock()
        ),
    );
}

/// Paper C's experiments.
pub fn experiments() -> Vec<Experiment> {
    vec![
        Experiment {
            id: "paper-c-table1",
            part: Part::PaperC,
            title: "Table 1 and Figs. 2-5: FA-DAE (pure firefly) against step size",
            run: table1_pure,
        },
        Experiment {
            id: "paper-c-table1-polished",
            part: Part::PaperC,
            title: "Table 1, FA-DAE with the Gauss-Newton polish",
            run: table1_polished,
        },
        Experiment {
            id: "paper-c-table2",
            part: Part::PaperC,
            title: "Table 2: FA-DAE against RK4 at h = 0.01",
            run: table2,
        },
        Experiment {
            id: "paper-c-orders",
            part: Part::PaperC,
            title: "Measured order of FA-DAE (polished and pure)",
            run: orders,
        },
        Experiment {
            id: "paper-c-determinism",
            part: Part::PaperC,
            title: "Determinism: same seed, parallel evaluation",
            run: determinism,
        },
    ]
}
