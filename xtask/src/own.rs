//! The project's own experiments: convergence orders of every solver, work-precision on the
//! manipulator, long-time energy behaviour, cost of one step against the RK4 peer.

use crate::report::{fmt_e, num, Claim, Ctx, Experiment, FigureRef, Part, Section, Table};
use mbd_analysis::plot::{Figure, Series};
use mbd_analysis::{fit_order, MeasureObserver};
use mbd_model::{models, System};
use mbd_solve::{
    reference_trajectory, run, ButcherTableau, Index1Options, Index1Rk, Integrator, NoObserver,
    RunConfig, SolveError, State,
};
use serde_json::json;
use std::time::Instant;

mod work_precision;
use work_precision::work_precision;

/// A solver of the comparison: a variant of the solver registry (`mbd::registry()`), with
/// the run lengths its cost allows.
pub struct SolverSpec {
    /// Display name (the registry's label).
    pub name: &'static str,
    /// The registry's spec string.
    pub spec: &'static str,
    /// Nominal convergence order.
    pub order: f64,
    /// Builds the integrator for a system.
    pub solver: mbd::solve::registry::SolverSpec,
    /// Include in the 10^5-step long-time study (too slow for the optimisation-based solver).
    pub long_time: bool,
    /// Smallest step of the work-precision sweep (the optimisation-based solver costs about
    /// 100x a step of the others, so its sweep stops earlier).
    pub h_min: f64,
}

impl SolverSpec {
    /// Builds the integrator for `sys`.
    pub fn make(&self, sys: &System) -> Result<Box<dyn Integrator + Send>, SolveError> {
        self.solver.build(sys)
    }
}

/// Solvers whose relative cost per step (the registry's estimate) is above this skip the
/// long-time study and stop their work-precision sweep at [`WP_H_MIN_COSTLY`].
const COSTLY: f64 = 50.0;
/// Smallest work-precision step of a costly solver.
const WP_H_MIN_COSTLY: f64 = 0.02 / 128.0;

/// Every solver of the registry that the comparisons include
/// ([`mbd::solve::registry::SolverVariant::compared`]), in registry order.
pub fn solvers() -> Vec<SolverSpec> {
    mbd::registry()
        .variants()
        .filter(|(_, v)| v.compared)
        .filter_map(|(_, v)| {
            // every variant parses: the registry checks it when the family registers
            let solver = mbd::registry().parse(v.spec).ok()?;
            let cheap = v.relative_cost <= COSTLY;
            Some(SolverSpec {
                name: v.label,
                spec: v.spec,
                order: f64::from(v.order),
                solver,
                long_time: cheap,
                h_min: if cheap { WP_H_MIN } else { WP_H_MIN_COSTLY },
            })
        })
        .collect()
}

/// Smallest step of the work-precision sweep (0.02 / 2^12): below the round-off floor of every
/// fixed-step solver on the manipulator.
const WP_H_MIN: f64 = 0.02 / 4096.0;
/// The work-precision sweep of a solver stops after this many consecutive halvings of h that do
/// not improve its best error: round-off dominates there.
const ROUNDOFF_HALVINGS: usize = 2;

fn problems() -> Result<Vec<(&'static str, System)>, String> {
    let pendulum = models::pendulum(1.0, 1.0, 1.0, 9.81).map_err(|e| format!("pendulum: {e}"))?;
    let manipulator = models::manipulator().map_err(|e| format!("manipulator: {e}"))?;
    Ok(vec![
        ("single pendulum", pendulum),
        ("manipulator", manipulator),
    ])
}

use mbd_solve::linalg::max_abs_diff as max_diff;

/// Reference at `t_end` from DOPRI5 + projection with a small step (independent of every solver
/// compared).
fn reference_q(sys: &System, t_end: f64, h: f64) -> Result<Vec<f64>, String> {
    let s0 = State::consistent(sys, 0.0).map_err(|e| e.to_string())?;
    let n = (t_end / h).round() as usize;
    let r = reference_trajectory(sys, &s0, h, n, 1, ButcherTableau::dopri5())
        .map_err(|e| e.to_string())?;
    r.q.last()
        .cloned()
        .ok_or_else(|| "empty reference".to_string())
}

fn solve_to(
    sys: &System,
    spec: &SolverSpec,
    t_end: f64,
    h: f64,
) -> Result<(Vec<f64>, f64), String> {
    let mut s = State::consistent(sys, 0.0).map_err(|e| e.to_string())?;
    let mut integ = spec.make(sys).map_err(|e| e.to_string())?;
    let t = Instant::now();
    run(
        &mut integ,
        sys,
        &mut s,
        RunConfig::new(t_end, h),
        &mut NoObserver,
    )
    .map_err(|e| format!("{}: {e}", spec.name))?;
    Ok((s.q.as_slice().to_vec(), t.elapsed().as_secs_f64()))
}

/// The reason the tangent RK4 step-cost claim misses (its measurements and the cuts made are
/// in docs/report.md, "Expected misses", and docs/tangent.md).
const TANGENT_RATIO_MISS: &str = "at this claim's h = 0.01 the tangent chart's maps (three stage points and the end point, the end point to 1e-13) set the cost: 9.45 chord iterations per step in the step-weighted chart (14.6 in paper B's Euclidean one), 3.23x plain RK4 in instructions under run (34,458 against 10,666; 3.77x before the weighted chart), 3.55x by wall clock in a full run with --jobs 1 on the development machine (3.99x before); at h = 1e-3, 2.73x in instructions under run; see docs/report.md, expected misses";

/// Errors of the order study within this of zero are at the reference's / round-off floor.
const FLOOR: f64 = 1e-11;

fn orders(ctx: &Ctx) -> Result<Section, String> {
    let mut sec = Section::default();
    let t_end = 1.0;
    let hs: Vec<f64> = if ctx.quick {
        vec![0.02, 0.01, 0.005]
    } else {
        vec![0.02, 0.01, 0.005, 0.0025, 0.00125]
    };
    sec.setting(
        "error",
        "max-norm of positions at t = 1 s against DOPRI5 + projection at h = 5e-5; errors below 1e-11 are dropped as the floor",
    );
    sec.setting("step sizes", format!("{hs:?}"));
    let mut table = Table::new(
        "Measured convergence orders (least-squares slope; local orders of consecutive pairs)",
        &["solver", "problem", "nominal", "fitted", "local orders"],
    );
    let mut rows = Vec::new();
    let mut fig = Figure::new(
        "Convergence: position error at t = 1 s",
        "step size h [s]",
        "max position error [m or rad]",
    )
    .log(true, true);
    for (pname, sys) in problems()? {
        let qref = reference_q(&sys, t_end, 5e-5)?;
        for spec in solvers() {
            let mut errs = Vec::new();
            for &h in &hs {
                let (q, _) = solve_to(&sys, &spec, t_end, h)?;
                errs.push(max_diff(&q, &qref));
            }
            // points within FLOOR of zero are at the reference's / round-off floor
            let above = errs.iter().filter(|&&e| e > FLOOR).count();
            if above < 2 {
                // too accurate for a fit: the error at the finest h must still be within what
                // the nominal order predicts from the coarsest, plus the floor
                let (h0, h1) = (hs[0], hs[hs.len() - 1]);
                let bound = errs[0] * (h1 / h0).powf(spec.order) + FLOOR;
                let last = errs[errs.len() - 1];
                table.row(vec![
                    spec.name.into(),
                    pname.into(),
                    format!("{}", spec.order),
                    "at the floor".into(),
                    format!(
                        "errors {}",
                        errs.iter()
                            .map(|&e| fmt_e(e))
                            .collect::<Vec<_>>()
                            .join(", ")
                    ),
                ]);
                sec.claims.push(Claim::check(
                    format!("{} converges with at least its order {} on the {pname} (errors at the floor {FLOOR:e} at all but {above} step size(s): the error at the finest h within the coarsest error scaled by h^order, plus the floor)", spec.name, spec.order),
                    last <= bound,
                    format!("error {} at h = {h1} against the bound {}", fmt_e(last), fmt_e(bound)),
                ));
                rows.push(json!({"solver": spec.name, "problem": pname, "order": null, "errors": errs.iter().map(|&e| num(e)).collect::<Vec<_>>()}));
                fig.series.push(Series::points(
                    format!("{} ({pname})", spec.name),
                    hs.clone(),
                    errs,
                ));
                continue;
            }
            let fit = fit_order(&hs, &errs, FLOOR)
                .map_err(|e| format!("{} on {pname}: {e}", spec.name))?;
            table.row(vec![
                spec.name.into(),
                pname.into(),
                format!("{}", spec.order),
                format!("{:.2}", fit.order),
                fit.local
                    .iter()
                    .map(|o| format!("{o:.2}"))
                    .collect::<Vec<_>>()
                    .join(", "),
            ]);
            // the asymptotic order: the local order of the finest pair above the floor
            let finest = fit.local.last().copied().unwrap_or(fit.order);
            sec.claims.push(Claim::check(
                format!("{} converges with at least its order {} on the {pname} (local order of the finest resolved pair >= order - 0.3)", spec.name, spec.order),
                finest >= spec.order - 0.3,
                format!("finest local order {finest:.2}, least-squares slope {:.2}", fit.order),
            ));
            rows.push(json!({"solver": spec.name, "problem": pname, "order": num(fit.order)}));
            fig.series.push(Series::points(
                format!("{} ({pname})", spec.name),
                hs.clone(),
                errs,
            ));
        }
    }
    fig.save(&ctx.figure_path("own_orders.svg"))
        .map_err(|e| e.to_string())?;
    sec.figures.push(FigureRef { file: "own_orders.svg".into(), caption: "Position error at t = 1 s against step size, every solver, single pendulum and manipulator".into() });
    sec.tables.push(table);
    sec.summary = json!({ "orders": rows });
    Ok(sec)
}

fn long_time(ctx: &Ctx) -> Result<Section, String> {
    let mut sec = Section::default();
    let sys = models::manipulator().map_err(|e| e.to_string())?;
    let steps: usize = if ctx.quick { 10_000 } else { 100_000 };
    let h = 0.01;
    sec.setting("problem", "manipulator");
    sec.setting("h", h);
    sec.setting("steps", steps);
    let mut table = Table::new(
        "Long-time behaviour",
        &[
            "solver",
            "e(H) first tenth",
            "e(H) last tenth",
            "e(H) overall",
            "e(Phi)",
            "e(Phidot)",
        ],
    );
    let mut fig = Figure::new(
        format!("Energy error over {steps} steps (h = {h} s), manipulator"),
        "time t [s]",
        "|H - H0| / |H0|",
    )
    .log(false, true);
    let mut rows = Vec::new();
    for spec in solvers().into_iter().filter(|s| s.long_time) {
        let mut s = State::consistent(&sys, 0.0).map_err(|e| e.to_string())?;
        let mut integ = spec.make(&sys).map_err(|e| e.to_string())?;
        let mut obs = MeasureObserver::new(&sys, false).with_series();
        run(
            &mut integ,
            &sys,
            &mut s,
            // the drift of plain RK4 is what this experiment measures
            RunConfig::new(steps as f64 * h, h).without_drift_guard(),
            &mut obs,
        )
        .map_err(|e| format!("{}: {e}", spec.name))?;
        let m = obs.measures();
        let series = obs.series.take().unwrap_or_default();
        let tenth = series.len() / 10;
        let first = series[..tenth.max(1)]
            .iter()
            .fold(0.0f64, |a, r| a.max(r[1]));
        let last = series[series.len() - tenth.max(1)..]
            .iter()
            .fold(0.0f64, |a, r| a.max(r[1]));
        table.row(vec![
            spec.name.into(),
            fmt_e(first),
            fmt_e(last),
            fmt_e(m.e_h),
            fmt_e(m.e_phi),
            fmt_e(m.e_phidot),
        ]);
        rows.push(json!({"solver": spec.name, "e_H_first_tenth": num(first), "e_H_last_tenth": num(last), "e_H": num(m.e_h), "e_phi": num(m.e_phi), "e_phidot": num(m.e_phidot)}));
        // thin the series for the figure
        let stride = (series.len() / 2000).max(1);
        let (xs, ys): (Vec<f64>, Vec<f64>) =
            series.iter().step_by(stride).map(|r| (r[0], r[1])).unzip();
        fig.series.push(Series::line(spec.name, xs, ys));
    }
    fig.save(&ctx.figure_path("own_long_time_energy.svg"))
        .map_err(|e| e.to_string())?;
    sec.figures.push(FigureRef {
        file: "own_long_time_energy.svg".into(),
        caption: "Relative energy error against time over the long run".into(),
    });
    sec.tables.push(table);
    sec.summary = json!({ "own": { "long_time": rows } });
    Ok(sec)
}

/// Best time per step over `blocks` blocks of `steps` steps of the manipulator at `h = 0.01`,
/// for `integ` and for `peer`, the blocks of the two interleaved (so both see the same machine
/// load). Steps go through the public run loop (`mbd_solve::run` with its default drift guard),
/// as a user's do, in runs of at most 5 s from `s0` (plain RK4 at this step drifts past the
/// default guard at t = 7.2 s).
fn interleaved_step_cost(
    sys: &System,
    s0: &State,
    integ: &mut dyn Integrator,
    peer: &mut dyn Integrator,
    blocks: usize,
    steps: usize,
    peer_steps: usize,
) -> Result<(f64, f64), String> {
    let block = |it: &mut dyn Integrator, n: usize| -> Result<f64, String> {
        let t = Instant::now();
        let mut left = n;
        while left > 0 {
            let k = left.min(500);
            let mut st = s0.clone();
            run(
                &mut *it,
                sys,
                &mut st,
                RunConfig::new(k as f64 * 0.01, 0.01),
                &mut NoObserver,
            )
            .map_err(|e| e.to_string())?;
            left -= k;
        }
        Ok(t.elapsed().as_secs_f64() / n as f64)
    };
    let (mut best, mut best_peer) = (f64::INFINITY, f64::INFINITY);
    for _ in 0..blocks {
        best = best.min(block(&mut *integ, steps)?);
        best_peer = best_peer.min(block(&mut *peer, peer_steps)?);
    }
    Ok((best, best_peer))
}

fn step_cost(ctx: &Ctx) -> Result<Section, String> {
    let mut sec = Section::default();
    let sys = models::manipulator().map_err(|e| e.to_string())?;
    let s0 = State::consistent(&sys, 0.0).map_err(|e| e.to_string())?;
    let (blocks, steps) = if ctx.quick { (5, 2_000) } else { (30, 10_000) };
    sec.setting("problem", "manipulator, h = 0.01 s");
    sec.setting(
        "peer",
        "RK4 on the index-1 form (mbd_solve::Index1Rk, RK4 tableau), the plain RK4 step",
    );
    sec.setting(
        "method",
        format!("best of {blocks} blocks of {steps} steps through the public run loop (mbd_solve::run, default drift guard; runs of 5 s), FA-DAE and fixed-step DOPRI5: 1/100 of that; each solver's blocks interleaved with the peer's"),
    );
    sec.notes.push("Wall-clock times of one step on this machine; the ratio to the peer, measured in the same interleaved loop, is the portable number. Other experiments run at the same time on the `--jobs` threads, so for clean numbers run `cargo xtask reproduce own --only own-step-cost --jobs 1` (criterion benches: `cargo bench -p mbd-rk4`, `-p mbd-symplectic`, `-p mbd-tangent`).".into());
    let mut table = Table::new(
        "Cost of one step on the manipulator",
        &[
            "solver",
            "time per step [us]",
            "RK4 peer [us]",
            "ratio to the peer",
            "target",
        ],
    );
    // (name, target in us, target ratio)
    let targets: [(&str, Option<f64>, Option<f64>); 5] = [
        ("RK4 (index-1, plain)", Some(1.0), None),
        ("symplectic (1,1)", Some(2.0), None),
        ("symplectic (2,2)", Some(5.0), None),
        ("tangent-space RK4", None, Some(4.0)),
        ("FA-DAE + Gauss-Newton polish", None, None),
    ];
    let all = solvers();
    if let Some(t) = targets.iter().find(|t| all.iter().all(|s| s.name != t.0)) {
        return Err(format!(
            "own-step-cost: the target for '{}' names no solver of the comparison",
            t.0
        ));
    }
    let mut peer = Index1Rk::new(&sys, ButcherTableau::rk4(), Index1Options::default())
        .map_err(|e| e.to_string())?;
    let mut rows = Vec::new();
    for spec in all {
        let (abs, ratio) = targets
            .iter()
            .find(|t| t.0 == spec.name)
            .map_or((None, None), |t| (t.1, t.2));
        let mut integ = spec.make(&sys).map_err(|e| e.to_string())?;
        let n = if spec.long_time { steps } else { steps / 100 };
        let (per, per_peer) =
            interleaved_step_cost(&sys, &s0, integ.as_mut(), &mut peer, blocks, n, steps)?;
        let r = per / per_peer;
        let target = match (abs, ratio) {
            (Some(us), _) => format!("<= {us} us"),
            (None, Some(x)) => format!("<= {x}x the peer"),
            _ => "-".into(),
        };
        table.row(vec![
            spec.name.into(),
            format!("{:.3}", per * 1e6),
            format!("{:.3}", per_peer * 1e6),
            format!("{r:.2}"),
            target,
        ]);
        if let Some(us) = abs {
            sec.claims.push(Claim::timing(
                format!("one {} step on the manipulator within {us} us", spec.name),
                per * 1e6 <= us,
                format!(
                    "{:.3} us ({r:.2}x the RK4 peer's {:.3} us)",
                    per * 1e6,
                    per_peer * 1e6
                ),
            ));
        }
        if let Some(x) = ratio {
            let mut c = Claim::timing(
                format!("one {} step within {x}x a plain RK4 step", spec.name),
                r <= x,
                format!(
                    "{r:.2}x ({:.3} us against {:.3} us)",
                    per * 1e6,
                    per_peer * 1e6
                ),
            );
            if r > x && spec.spec == "tangent:rk4" {
                c = c.expected_miss(TANGENT_RATIO_MISS);
            }
            sec.claims.push(c);
        }
        rows.push(json!({"solver": spec.name, "runtime_s": num(per), "peer_runtime_s": num(per_peer), "ratio": num(r)}));
    }
    sec.tables.push(table);
    sec.timings = json!({ "step_cost": rows });
    Ok(sec)
}

/// The project's own experiments.
pub fn experiments() -> Vec<Experiment> {
    vec![
        Experiment {
            id: "own-step-cost",
            part: Part::Own,
            title: "Cost of one step against the RK4 peer",
            run: step_cost,
        },
        Experiment {
            id: "own-scaling",
            part: Part::Own,
            title: "Cost per step against system size",
            run: crate::own_scaling::scaling,
        },
        Experiment {
            id: "own-singular",
            part: Part::Own,
            title: "Singular configurations and redundant constraints, every solver",
            run: crate::own_singular::singular,
        },
        Experiment {
            id: "own-spatial",
            part: Part::Own,
            title: "Spatial bodies: heavy top, tumbling plate, torque-free body",
            run: crate::own_spatial::spatial,
        },
        Experiment {
            id: "own-orders",
            part: Part::Own,
            title: "Convergence orders of every solver",
            run: orders,
        },
        Experiment {
            id: "own-work-precision",
            part: Part::Own,
            title: "Work-precision on the manipulator",
            run: work_precision,
        },
        Experiment {
            id: "own-long-time",
            part: Part::Own,
            title: "Long-time energy behaviour",
            run: long_time,
        },
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_registered_solver_family_is_in_the_comparisons() {
        let compared: Vec<&str> = solvers().iter().map(|s| s.spec).collect();
        for f in mbd::registry().families() {
            assert!(
                f.variants.iter().any(|v| v.compared),
                "{} registers no variant the report compares",
                f.crate_name
            );
            for v in f.variants.iter().filter(|v| v.compared) {
                assert!(
                    compared.contains(&v.spec),
                    "{} missing from the report",
                    v.spec
                );
            }
        }
        // every compared solver builds for the report's problems
        for (name, sys) in problems().expect("problems") {
            for s in solvers() {
                s.make(&sys)
                    .unwrap_or_else(|e| panic!("{} on {name}: {e}", s.spec));
            }
        }
    }
}
