//! `own-scaling`: cost of one step against the number of bodies, for every solver that is meant
//! to scale (RK4 plain and projected, symplectic (1,1) and (2,2), tangent-space RK4), on the
//! N-link chain, through the public run loop, as ratios to plain RK4 timed in the same loop.

use crate::own::solvers;
use crate::report::{num, Claim, Ctx, FigureRef, Section, Table};
use mbd_analysis::plot::{Figure, Series};
use mbd_model::{models, System};
use mbd_solve::{
    run, ButcherTableau, Index1Options, Index1Rk, Integrator, NoObserver, RunConfig, State,
};
use serde_json::json;
use std::time::Instant;

/// The report's targets for the cost of a step relative to plain RK4 at N = 100 and
/// N = 1000, by registry spec. Every compared solver of the registry is measured; those the
/// registry marks as scaling (`SolverVariant::scales`) are held to [`MAX_EXPONENT`], the rest
/// (FA-DAE, which optimises `2 (n - m)` variables per step with a swarm) are measured as far as
/// the time budget allows, to document their limit.
const TARGETS: [(&str, f64); 4] = [
    ("rk4-projected", 2.0),
    ("symplectic:1", 3.0),
    ("symplectic:2", 8.0),
    ("tangent:rk4", 8.0),
];

/// The fewest steps in each half of a continuing block ([`measure`]): long against the
/// interval at which symplectic (s,s) refreshes the stage Jacobian it keeps across steps
/// (about every 12 to 15 steps on the 1000-rod spatial chain at h = 1e-3, every 40 or so on the
/// 100-rod one), so that a block times the refreshes at their rate in a long run.
pub(crate) const CONTINUING_MIN_STEPS: usize = 32;

/// Largest allowed cost exponent between N = 100 and N = 1000.
pub(crate) const MAX_EXPONENT: f64 = 1.2;
/// Step size of every run.
const H: f64 = 1e-3;
/// A solver whose step is predicted to take longer than this at the next N (extrapolated from
/// its two largest measured sizes, at least linearly) is not run there (reported as not run).
const SKIP_ABOVE_S: f64 = 1.0;

/// Seconds per step of `integ`, from a run of `steps` steps through [`run`] starting at `s0`.
fn timed_run(
    integ: &mut dyn Integrator,
    sys: &System,
    st: &mut State,
    steps: usize,
) -> Result<f64, String> {
    let t_end = st.t + steps as f64 * H;
    let t = Instant::now();
    run(
        &mut *integ,
        sys,
        st,
        RunConfig::new(t_end, H),
        &mut NoObserver,
    )
    .map_err(|e| e.to_string())?;
    Ok(t.elapsed().as_secs_f64() / steps as f64)
}

/// One measured cell of the table.
struct Cell {
    solver: &'static str,
    n_bodies: usize,
    per_step: f64,
    peer: f64,
}

/// Best-of-blocks time per step of `integ` and of the plain RK4 peer, blocks of about
/// `block_s` seconds interleaved. With `continuing`, a block is the second half of a run of
/// twice its steps (what a long run costs per step, for a solver that keeps a factorisation
/// across steps); otherwise each block is a run from `s0`.
pub(crate) fn measure(
    sys: &System,
    s0: &State,
    integ: &mut dyn Integrator,
    peer: &mut dyn Integrator,
    blocks: usize,
    block_s: f64,
    continuing: bool,
) -> Result<(f64, f64), String> {
    // warm-up and a first estimate of the step cost (one step each)
    let (mut st, mut st_peer) = (s0.clone(), s0.clone());
    // (a run's first steps cost more: the first step's Taylor predictor and, for a solver
    // that keeps its factorisation, the first factorisation; `continuing` times a stretch of
    // a run after them)
    let one = timed_run(integ, sys, &mut st, 1)?;
    let one_peer = timed_run(peer, sys, &mut st_peer, 1)?;
    // (a continuing block is at least CONTINUING_MIN_STEPS steps: the first step's time,
    // from which the count is estimated, carries the start-up, and a scheme that extrapolates
    // from its last steps, like the s = 2 modified Lagrangian's gradients from four, reaches
    // its steady cost only after them)
    let least = if continuing { CONTINUING_MIN_STEPS } else { 2 };
    let steps = ((block_s / one.max(1e-9)) as usize).clamp(least, 2000);
    let peer_steps = ((block_s / one_peer.max(1e-9)) as usize).clamp(least, 2000);
    let (mut best, mut best_peer) = (f64::INFINITY, f64::INFINITY);
    for _ in 0..blocks {
        if continuing {
            best = best.min(second_stretch(integ, sys, s0, steps)?);
            best_peer = best_peer.min(second_stretch(peer, sys, s0, peer_steps)?);
        } else {
            st.clone_from(s0);
            st_peer.clone_from(s0);
            best = best.min(timed_run(integ, sys, &mut st, steps)?);
            best_peer = best_peer.min(timed_run(peer, sys, &mut st_peer, peer_steps)?);
        }
    }
    Ok((best, best_peer))
}

/// The time per step of the second of two stretches of `steps` steps of one run from `s0`
/// through the public run loop (an observer notes the time where the second begins and ends):
/// the first stretch carries the run's start-up.
fn second_stretch(
    integ: &mut dyn Integrator,
    sys: &System,
    s0: &State,
    steps: usize,
) -> Result<f64, String> {
    let mut st = s0.clone();
    let mut marks = Vec::with_capacity(3);
    let mut mark = |_: &System, _: &State, k: usize| {
        if k == marks.len() * steps {
            marks.push(Instant::now());
        }
        Ok(mbd::solve::Flow::Continue)
    };
    run(
        &mut *integ,
        sys,
        &mut st,
        RunConfig::new((2 * steps) as f64 * H, H),
        &mut mark,
    )
    .map_err(|e| e.to_string())?;
    match marks.as_slice() {
        [_, a, b] => Ok((*b - *a).as_secs_f64() / steps as f64),
        _ => Err(format!("timed run: {} marks, 3 expected", marks.len())),
    }
}

/// The experiment.
pub fn scaling(ctx: &Ctx) -> Result<Section, String> {
    let mut sec = Section::default();
    let ns: [usize; 5] = [10, 30, 100, 300, 1000];
    let (blocks, block_s) = if ctx.quick { (2, 0.03) } else { (5, 0.2) };
    sec.setting(
        "problem",
        "N-link pendulum chain (models::n_link_chain: 1 kg, 1 m rods released at 30 degrees), h = 1e-3 s",
    );
    sec.setting(
        "method",
        format!("best of {blocks} blocks of about {block_s} s each through the public run loop (mbd_solve::run, default drift guard), each solver's blocks interleaved with plain RK4's (mbd_solve::Index1Rk, RK4 tableau); for every solver meant to scale a block is the second half of a run of twice its steps (at least {CONTINUING_MIN_STEPS} each: the first half carries the run's start-up, such as the first stage factorisation and the first step's predictor), for FA-DAE a run from the start; construction (symbolic analysis) not timed; dense kernels up to {} constraints, sparse above", mbd_solve::SPARSE_THRESHOLD),
    );
    sec.notes.push(format!("Times are wall-clock on this machine; the ratio to plain RK4 measured in the same loop is the portable number. A solver whose step is predicted (from its two largest measured sizes) to take more than {SKIP_ABOVE_S} s at the next N is not run there or beyond."));
    let all = solvers();
    let scales = |spec: &str| mbd::registry().variant(spec).is_some_and(|v| v.scales);
    let target_of = |spec: &str| TARGETS.iter().find(|t| t.0 == spec).map(|t| t.1);
    if let Some(t) = TARGETS.iter().find(|t| all.iter().all(|s| s.spec != t.0)) {
        return Err(format!(
            "own-scaling: the target for '{}' names no compared solver",
            t.0
        ));
    }
    let mut cells: Vec<Cell> = Vec::new();
    let mut skipped: Vec<(&str, usize)> = Vec::new();
    for &n in &ns {
        let sys = models::n_link_chain(n).map_err(|e| e.to_string())?;
        let s0 = State::consistent(&sys, 0.0).map_err(|e| e.to_string())?;
        let mut peer = Index1Rk::new(&sys, ButcherTableau::rk4(), Index1Options::default())
            .map_err(|e| e.to_string())?;
        for spec in &all {
            let name = spec.name;
            let mine: Vec<&Cell> = cells.iter().filter(|c| c.solver == name).collect();
            let predicted = match mine.as_slice() {
                [.., a, b] => {
                    let e = ((b.per_step / a.per_step).ln()
                        / (b.n_bodies as f64 / a.n_bodies as f64).ln())
                    .max(1.0);
                    b.per_step * (n as f64 / b.n_bodies as f64).powf(e)
                }
                [b] => b.per_step * n as f64 / b.n_bodies as f64,
                [] => 0.0,
            };
            let too_slow = predicted > SKIP_ABOVE_S;
            if too_slow || skipped.iter().any(|s| s.0 == name) {
                skipped.push((name, n));
                continue;
            }
            let measured = spec
                .make(&sys)
                .map_err(|e| e.to_string())
                .and_then(|mut integ| {
                    // a scaling solver's blocks time a stretch of a long run (the claims are
                    // about its steady cost per step: a run restarted at every block would
                    // time the start-up, which weighs more where a block has fewer steps);
                    // FA-DAE, measured only to document its limit, restarts
                    let continuing = scales(spec.spec);
                    measure(
                        &sys,
                        &s0,
                        integ.as_mut(),
                        &mut peer,
                        blocks,
                        block_s,
                        continuing,
                    )
                });
            let (per, peer_per) = match measured {
                Ok(x) => x,
                // a solver not meant to scale is measured to document its limit: a failure
                // there is a finding
                Err(e) if !scales(spec.spec) => {
                    sec.notes
                        .push(format!("{name} failed on the {n}-link chain: {e}"));
                    skipped.push((name, n));
                    continue;
                }
                Err(e) => return Err(format!("{name}, N = {n}: {e}")),
            };
            cells.push(Cell {
                solver: name,
                n_bodies: n,
                per_step: per,
                peer: peer_per,
            });
        }
    }
    let mut table = Table::new(
        "Cost of one step against chain length (microseconds, and ratio to plain RK4 in the same loop)",
        &["solver", "N = 10", "N = 30", "N = 100", "N = 300", "N = 1000", "exponent 100 -> 1000"],
    );
    let mut rows = Vec::new();
    let mut fig = Figure::new(
        "Cost per step, N-link chain",
        "chain length N (bodies)",
        "time per step [s]",
    )
    .log(true, true);
    for spec in &all {
        let (name, target) = (spec.name, target_of(spec.spec));
        let mine: Vec<&Cell> = cells.iter().filter(|c| c.solver == name).collect();
        let mut row = vec![name.to_string()];
        for &n in &ns {
            row.push(match mine.iter().find(|c| c.n_bodies == n) {
                Some(c) => format!("{:.1} ({:.2}x)", c.per_step * 1e6, c.per_step / c.peer),
                None => "not run (too slow)".into(),
            });
        }
        let at = |n: usize| mine.iter().find(|c| c.n_bodies == n);
        let exponent = match (at(100), at(1000)) {
            (Some(a), Some(b)) => Some((b.per_step / a.per_step).ln() / 10f64.ln()),
            _ => None,
        };
        row.push(exponent.map_or("-".into(), |e| format!("{e:.2}")));
        table.row(row);
        for c in &mine {
            rows.push(json!({
                "solver": name,
                "n_bodies": c.n_bodies,
                "us_per_step": num(c.per_step * 1e6),
                "ratio_to_rk4": num(c.per_step / c.peer),
            }));
        }
        fig = fig.with(Series::line(
            name,
            mine.iter().map(|c| c.n_bodies as f64).collect(),
            mine.iter().map(|c| c.per_step).collect(),
        ));
        if !scales(spec.spec) {
            continue;
        }
        if let Some(target) = target {
            for n in [100, 1000] {
                sec.claims.push(match at(n) {
                    Some(c) => {
                        let r = c.per_step / c.peer;
                        Claim::timing(
                            format!("one {name} step on the {n}-link chain within {target}x a plain RK4 step"),
                            r <= target,
                            format!("{r:.2}x ({:.1} us against {:.1} us)", c.per_step * 1e6, c.peer * 1e6),
                        )
                    }
                    None => Claim::timing(
                        format!("one {name} step on the {n}-link chain within {target}x a plain RK4 step"),
                        false,
                        format!("not run: its step was predicted to take more than {SKIP_ABOVE_S} s"),
                    ),
                });
            }
        }
        sec.claims.push(match exponent {
            Some(e) => Claim::timing(
                format!(
                    "{name}: cost exponent between N = 100 and N = 1000 at most {MAX_EXPONENT}"
                ),
                e <= MAX_EXPONENT,
                format!("{e:.2}"),
            ),
            None => Claim::timing(
                format!(
                    "{name}: cost exponent between N = 100 and N = 1000 at most {MAX_EXPONENT}"
                ),
                false,
                "not measured at both sizes".to_string(),
            ),
        });
    }
    fig.save(&ctx.figure_path("own_scaling.svg"))
        .map_err(|e| e.to_string())?;
    sec.figures.push(FigureRef {
        file: "own_scaling.svg".into(),
        caption: "Cost per step against chain length, every solver meant to scale (log-log)".into(),
    });
    sec.tables.push(table);
    // wall-clock numbers: summary.json's top-level `scaling` list
    sec.wall_clock = json!({ "scaling": rows });
    Ok(sec)
}
