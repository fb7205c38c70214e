//! Paper A's experiments: the parameter-preadjusted symplectic algorithm (`mbd-symplectic`).
//!
//! System (project choice, experiments.md): two uniform rods, 1 kg, 1 m, pinned chain,
//! g = 9.81, both released at rest 30 degrees from the downward vertical
//! (`models::paper_a_double_pendulum`). `N_t` is read as seconds of simulated time (the scan
//! does not say; see the note in Table 1). Reference: `mbd_solve::reference_trajectory`
//! (DOPRI5 on the index-1 form with projection after every step, at `h / substeps`), an
//! independent solver.

use crate::plot::{Figure, Series};
use crate::report::{
    fmt_e, num, Claim, Ctx, Experiment, FigureRef, PaperValue, Part, Section, Table,
};
use mbd_model::{models, System};
use mbd_solve::{reference_trajectory, ButcherTableau, Integrator, ReferenceTrajectory, State};
use mbd_symplectic::{
    calibrate_gamma, error_measures, kappa, CalibrationSettings, ErrorMeasures, Galerkin, Nodes,
    SymplecticOptions,
};
use serde_json::{json, Value};

/// Paper A's experiments.
pub fn experiments() -> Vec<Experiment> {
    vec![
        Experiment {
            id: "paper-a-table1",
            part: Part::PaperA,
            title: "Table 1: errors of the (s,s) schemes with gamma = 0 and gamma_T",
            run: table1,
        },
        Experiment {
            id: "paper-a-table2",
            part: Part::PaperA,
            title: "Table 2: secant calibration of gamma_opt",
            run: table2,
        },
        Experiment {
            id: "paper-a-table3",
            part: Part::PaperA,
            title: "Table 3: gamma = 0 against gamma_opt",
            run: table3,
        },
        Experiment {
            id: "paper-a-fig3",
            part: Part::PaperA,
            title: "Fig. 3: energy error against step size (orders)",
            run: fig3,
        },
        Experiment {
            id: "paper-a-fig4",
            part: Part::PaperA,
            title: "Fig. 4: long-run errors against gamma",
            run: fig4,
        },
        Experiment {
            id: "paper-a-fig5-6",
            part: Part::PaperA,
            title: "Figs. 5-6: absolute and signed averaged errors against gamma",
            run: fig5_6,
        },
        Experiment {
            id: "paper-a-fig7",
            part: Part::PaperA,
            title: "Fig. 7: x of body 2 over time (reference, gamma = 0, gamma_opt)",
            run: fig7,
        },
    ]
}

const NT_NOTE: &str = "Reading of N_t: the scan gives `h = 0.04, N_t = 100` (Table 1), `h = 0.01, N_t = 1000` (Fig. 4) and `h = 0.01, N_t = 10` (Figs. 5-6, Table 2) without units. We read N_t as **seconds of simulated time** (100 s = 2500 steps of 0.04 s), not as periods or steps. The paper's system is not legible either: ours is the project's choice (two uniform 1 kg, 1 m rods released at rest at 30 degrees; regular motion, normal-mode periods 2.2 s and 0.82 s at small amplitude). Its E|dx| cannot exceed about 1 m, so the paper's (1,1) errors of 2.4 show that its system or span differs: compare trends and claims, not digits.";

struct Problem {
    sys: System,
    s0: State,
}

fn problem() -> Result<Problem, String> {
    let sys = models::paper_a_double_pendulum().map_err(|e| e.to_string())?;
    let s0 = State::consistent(&sys, 0.0).map_err(|e| e.to_string())?;
    Ok(Problem { sys, s0 })
}

fn steps(span: f64, h: f64) -> usize {
    (span / h).round() as usize
}

fn reference(
    p: &Problem,
    h: f64,
    n: usize,
    substeps: usize,
) -> Result<ReferenceTrajectory, String> {
    reference_trajectory(&p.sys, &p.s0, h, n, substeps, ButcherTableau::dopri5())
        .map_err(|e| format!("reference: {e}"))
}

fn measures(
    p: &Problem,
    h: f64,
    n: usize,
    r: &ReferenceTrajectory,
    s: usize,
    gamma: f64,
) -> Result<ErrorMeasures, String> {
    error_measures(
        &p.sys,
        &p.s0,
        h,
        n,
        r,
        &SymplecticOptions::new(s).with_gamma(gamma),
    )
    .map_err(|e| format!("(s = {s}, gamma = {gamma}, h = {h}): {e}"))
}

fn calibrate(
    p: &Problem,
    h: f64,
    n: usize,
    r: &ReferenceTrajectory,
    s: usize,
) -> Result<mbd_symplectic::Calibration, String> {
    calibrate_gamma(
        &p.sys,
        &p.s0,
        h,
        n,
        r,
        &SymplecticOptions::new(s),
        CalibrationSettings::default(),
    )
    .map_err(|e| format!("calibration s = {s}: {e}"))
}

fn ref_check(
    p: &Problem,
    h: f64,
    n: usize,
    sub: usize,
    r: &ReferenceTrajectory,
) -> Result<f64, String> {
    // the reference's own error, estimated against one with half the step
    let r2 = reference(p, h, n, 2 * sub)?;
    Ok(r.q
        .iter()
        .zip(&r2.q)
        .flat_map(|(a, b)| a.iter().zip(b).map(|(x, y)| (x - y).abs()))
        .fold(0.0, f64::max))
}

fn table1(ctx: &Ctx) -> Result<Section, String> {
    let p = problem()?;
    let h = 0.04;
    let span = if ctx.quick { 10.0 } else { 100.0 };
    let n = steps(span, h);
    let sub = if ctx.quick { 16 } else { 64 };
    let r = reference(&p, h, n, sub)?;
    let ref_err = ref_check(&p, h, n, sub, &r)?;
    let mut sec = Section::default();
    sec.setting(
        "system",
        "paper_a_double_pendulum (2 rods, 1 kg, 1 m, 30 deg, at rest)",
    );
    sec.setting("h", h);
    sec.setting("N_t (s)", span);
    sec.setting("steps", n);
    sec.setting(
        "reference",
        format!(
            "{} (max change when halving its step: {})",
            r.method,
            fmt_e(ref_err)
        ),
    );
    sec.setting(
        "control points",
        "Gauss-Lobatto (= the paper's equispaced points for s <= 2)",
    );
    sec.setting("gamma_T", 1);
    sec.notes.push(NT_NOTE.to_string());
    let mut t = Table::new(
        "Table 1: E|dx|, E|dy|, E|dH| (means over both bodies and all steps)",
        &[
            "(s,s)",
            "gamma",
            "E|dx| ours",
            "paper",
            "ratio",
            "E|dy| ours",
            "paper",
            "ratio",
            "E|dH| ours",
            "paper",
            "ratio",
            "max |Phi|",
        ],
    );
    let mut rows = Vec::new();
    let mut summary = Vec::new();
    for &(s, gt, paper) in &crate::paper_values::get()?.paper_a.table1.rows {
        let gamma = if gt { 1.0 } else { 0.0 };
        let m = measures(&p, h, n, &r, s, gamma)?;
        let ours = [m.mean_abs_dx, m.mean_abs_dy, m.mean_abs_dh];
        let mut cells = vec![
            format!("({s},{s})"),
            if gt { "gamma_T".into() } else { "0".into() },
        ];
        for k in 0..3 {
            let pv = PaperValue::Value(paper[k]);
            cells.push(fmt_e(ours[k]));
            cells.push(pv.cell());
            cells.push(pv.ratio(ours[k]));
        }
        cells.push(fmt_e(m.max_phi));
        t.row(cells);
        summary.push(json!({"s": s, "gamma": gamma, "E_dx": num(ours[0]), "E_dy": num(ours[1]), "E_dH": num(ours[2]),
            "paper": {"E_dx": num(paper[0]), "E_dy": num(paper[1]), "E_dH": num(paper[2])}}));
        rows.push((s, gt, ours));
    }
    sec.tables.push(t);
    // the claim: gamma_T lowers every error of every row
    let mut held = true;
    let mut ev = Vec::new();
    for s in 1..=4 {
        let a = rows.iter().find(|r| r.0 == s && !r.1).map(|r| r.2);
        let b = rows.iter().find(|r| r.0 == s && r.1).map(|r| r.2);
        if let (Some(a), Some(b)) = (a, b) {
            let ok = (0..3).all(|k| b[k] < a[k]);
            held &= ok;
            ev.push(format!(
                "s={s}: {:.2}x/{:.2}x/{:.2}x{}",
                a[0] / b[0],
                a[1] / b[1],
                a[2] / b[2],
                if ok { "" } else { " (NOT lower)" }
            ));
        }
    }
    sec.claims.push(
        Claim::check(
            "gamma_T lowers every error (E|dx|, E|dy|, E|dH|) of every row of Table 1",
            held,
            format!(
                "reduction factors gamma=0 / gamma_T (dx/dy/dH): {}",
                ev.join("; ")
            ),
        )
        .expected_miss(
            "the preadjustment corrects the phase, not the energy: at s = 1 gamma_T raises E|dH| by 4/3 \
             (derived in docs/symplectic.md section 7), and at s = 3, 4 E|dH| is at its round-off floor",
        ),
    );
    // the literal reading: equispaced control points for s = 3, 4
    let mut te = Table::new(
        "Table 1 with equally spaced control points (the literal reading) for s = 3, 4: the constraint forces are then lumped by Newton-Cotes weights and the order drops to 4 and 6",
        &["(s,s)", "gamma", "E|dx|", "E|dy|", "E|dH|"],
    );
    for s in [3usize, 4] {
        for gamma in [0.0, 1.0] {
            let m = error_measures(
                &p.sys,
                &p.s0,
                h,
                n,
                &r,
                &SymplecticOptions::new(s)
                    .with_gamma(gamma)
                    .with_nodes(Nodes::Equispaced),
            )
            .map_err(|e| e.to_string())?;
            te.row(vec![
                format!("({s},{s})"),
                format!("{gamma}"),
                fmt_e(m.mean_abs_dx),
                fmt_e(m.mean_abs_dy),
                fmt_e(m.mean_abs_dh),
            ]);
        }
    }
    sec.tables.push(te);
    sec.notes.push(format!(
        "kappa_s (gamma = 1 cancels the leading phase error, docs/symplectic.md): {}",
        (1..=4)
            .map(|s| format!("kappa_{s} = {:.6e}", kappa(s)))
            .collect::<Vec<_>>()
            .join(", ")
    ));
    sec.summary = json!({"paper_a": {"table1": summary}});
    Ok(sec)
}

fn table2(ctx: &Ctx) -> Result<Section, String> {
    let p = problem()?;
    let h = 0.01;
    let span = if ctx.quick { 2.0 } else { 10.0 };
    let n = steps(span, h);
    let r = reference(&p, h, n, 32)?;
    let mut sec = Section::default();
    sec.setting("h", h);
    sec.setting("N_t (s)", span);
    sec.setting("reference", &r.method);
    sec.setting(
        "secant start",
        "gamma_1 = 0, gamma_2 = gamma_T = 1; stop when |d gamma| <= 1e-9 (1 + |gamma|)",
    );
    sec.notes.push("dW(gamma) = E[dx] + E[dy] (signed means over both bodies and all steps, paper eqs. 38-39).".into());
    let mut t = Table::new(
        "Table 2: secant calibration of gamma_opt",
        &[
            "(s,s)",
            "dW_1 ours",
            "paper",
            "dW_2 ours",
            "paper",
            "gamma_opt ours",
            "paper",
            "dW(gamma_opt)",
            "secant iterations",
        ],
    );
    let mut summary = Vec::new();
    for &(s, paper) in &crate::paper_values::get()?.paper_a.table2.rows {
        let c = calibrate(&p, h, n, &r, s)?;
        let (dw1, dw2) = (c.history[0].1, c.history[1].1);
        t.row(vec![
            format!("({s},{s})"),
            fmt_e(dw1),
            PaperValue::Value(paper[0]).cell(),
            fmt_e(dw2),
            PaperValue::Value(paper[1]).cell(),
            format!("{:.6}", c.gamma_opt),
            format!("{:.6}", paper[2]),
            fmt_e(c.measures.dw()),
            c.iterations.to_string(),
        ]);
        sec.notes.push(format!(
            "s = {s}: secant history (gamma, dW): {}",
            c.history
                .iter()
                .map(|(g, d)| format!("({g:.6}, {})", fmt_e(*d)))
                .collect::<Vec<_>>()
                .join(", ")
        ));
        summary.push(
            json!({"s": s, "dW1": num(dw1), "dW2": num(dw2), "gamma_opt": num(c.gamma_opt),
            "paper": {"dW1": num(paper[0]), "dW2": num(paper[1]), "gamma_opt": num(paper[2])}}),
        );
        sec.claims.push(Claim::check(
            format!("the secant iteration from gamma = 0, gamma_T finds a root of dW (s = {s})"),
            c.measures.dw().abs() <= (1e-4 * dw1.abs()).max(1e-14),
            format!(
                "gamma_opt = {:.6}, dW: {} -> {}",
                c.gamma_opt,
                fmt_e(dw1),
                fmt_e(c.measures.dw())
            ),
        ));
    }
    sec.tables.push(t);
    sec.summary = json!({"paper_a": {"table2": summary}});
    Ok(sec)
}

fn table3(ctx: &Ctx) -> Result<Section, String> {
    let p = problem()?;
    let (hc, span_c) = (0.01, if ctx.quick { 2.0 } else { 10.0 });
    let nc = steps(span_c, hc);
    let rc = reference(&p, hc, nc, 32)?;
    let h = 0.04;
    let span = if ctx.quick { 10.0 } else { 100.0 };
    let n = steps(span, h);
    let sub = if ctx.quick { 16 } else { 64 };
    let r = reference(&p, h, n, sub)?;
    let mut sec = Section::default();
    sec.setting(
        "calibration",
        format!("h = {hc}, N_t = {span_c} s (Table 2)"),
    );
    sec.setting("evaluation", format!("h = {h}, N_t = {span} s (Table 1)"));
    sec.setting("reference", &r.method);
    sec.notes.push("gamma_opt is calibrated at h = 0.01 over N_t = 10 (Table 2) and then used at h = 0.04 over N_t = 100, as we read the paper (the correction scales with kappa_s h^(2s), so gamma is step-independent to leading order). The rows 'gamma_opt (direct)' calibrate at the evaluation setting itself (h = 0.04, N_t = 100), the best one parameter can do there.".into());
    sec.notes.push(NT_NOTE.to_string());
    sec.notes.push("Why the gain is smaller at s = 2 (docs/symplectic.md): at small amplitude both normal modes of the double pendulum share the phase constant c_s = -kappa_s/2 and gamma = 1 cancels it (tested); at 30 degrees the phase error has an amplitude-dependent part that the linear-mode shape of W_s cannot represent. On the single pendulum (s = 2, h = 0.1, 20 s) gamma_opt grows from 1.01 at 2 degrees to 3.0 at 30 degrees and 91 at 45 degrees; with two modes of different amplitude, one gamma zeroes the signed mean dW but cannot cancel both drifts.".into());
    let mut t = Table::new(
        "Table 3: gamma = 0 against gamma_opt (E[dH] signed, as the paper prints it)",
        &[
            "(s,s)",
            "gamma",
            "value",
            "E|dx| ours",
            "paper",
            "E|dy| ours",
            "paper",
            "E[dH] ours",
            "paper",
            "E|dH| ours",
        ],
    );
    let mut summary = Vec::new();
    for &(s, p0, popt) in &crate::paper_values::get()?.paper_a.table3.rows {
        let cal = calibrate(&p, hc, nc, &rc, s)?;
        let direct = calibrate(&p, h, n, &r, s)?;
        let m0 = measures(&p, h, n, &r, s, 0.0)?;
        let mo = measures(&p, h, n, &r, s, cal.gamma_opt)?;
        let md = direct.measures;
        for (label, g, m, pv) in [
            ("0", 0.0, m0, Some(p0)),
            ("gamma_opt", cal.gamma_opt, mo, Some(popt)),
            ("gamma_opt (direct)", direct.gamma_opt, md, None),
        ] {
            let pc = |k: usize| pv.map_or("-".to_string(), |v| PaperValue::Value(v[k]).cell());
            t.row(vec![
                format!("({s},{s})"),
                label.into(),
                format!("{g:.6}"),
                fmt_e(m.mean_abs_dx),
                pc(0),
                fmt_e(m.mean_abs_dy),
                pc(1),
                fmt_e(m.mean_dh),
                pc(2),
                fmt_e(m.mean_abs_dh),
            ]);
            summary.push(json!({"s": s, "gamma": label, "gamma_value": num(g), "E_dx": num(m.mean_abs_dx),
                "E_dy": num(m.mean_abs_dy), "E_dH_signed": num(m.mean_dh), "E_dH": num(m.mean_abs_dh)}));
        }
        let (fx, fy) = (
            m0.mean_abs_dx / mo.mean_abs_dx,
            m0.mean_abs_dy / mo.mean_abs_dy,
        );
        let (dx, dy) = (
            m0.mean_abs_dx / md.mean_abs_dx,
            m0.mean_abs_dy / md.mean_abs_dy,
        );
        sec.claims.push(Claim::check(
            format!("gamma_opt (calibrated at h = 0.01, N_t = 10, used at h = 0.04, N_t = 100) lowers E|dx| and E|dy| at least 10x against gamma = 0 (s = {s})"),
            fx >= 10.0 && fy >= 10.0,
            format!(
                "gamma_opt = {:.4}: E|dx| {} -> {} ({fx:.2}x), E|dy| {} -> {} ({fy:.2}x)",
                cal.gamma_opt,
                fmt_e(m0.mean_abs_dx),
                fmt_e(mo.mean_abs_dx),
                fmt_e(m0.mean_abs_dy),
                fmt_e(mo.mean_abs_dy),
            ),
        ).expected_miss(
            "gamma_opt depends on h and the span (the needed gamma grows with amplitude and differs per mode, \
             docs/symplectic.md section 7), so calibrating on a short fine run and applying it to a long coarse \
             one loses most of the gain",
        ));
        let direct_claim = Claim::check(
            format!("gamma_opt calibrated at the evaluation setting (h = 0.04, N_t = 100) lowers E|dx| and E|dy| at least 10x against gamma = 0 (s = {s})"),
            dx >= 10.0 && dy >= 10.0,
            format!(
                "gamma_opt = {:.4}: E|dx| {} -> {} ({dx:.2}x), E|dy| {} -> {} ({dy:.2}x)",
                direct.gamma_opt,
                fmt_e(m0.mean_abs_dx),
                fmt_e(md.mean_abs_dx),
                fmt_e(m0.mean_abs_dy),
                fmt_e(md.mean_abs_dy),
            ),
        );
        // s = 2: one gamma cannot cancel the amplitude-dependent phase error of both modes
        // (docs/symplectic.md section 7); s = 1 holds at the paper's span (60x) but not over
        // the quick run's shortened span
        let direct_claim = if s >= 2 {
            direct_claim.expected_miss(
                "at s = 2 the needed gamma differs per mode and grows with amplitude; one gamma zeroes the \
                 signed mean but leaves both modes' drifts partly uncorrected (docs/symplectic.md section 7)",
            )
        } else if ctx.quick {
            direct_claim
                .expected_miss("quick mode shortens the span; the claim is about the paper's 100 s")
        } else {
            direct_claim
        };
        sec.claims.push(direct_claim);
    }
    sec.tables.push(t);
    sec.summary = json!({"paper_a": {"table3": summary}});
    Ok(sec)
}

/// Least-squares log-log slope of the errors above 1e-12 (`mbd_analysis::fit_order`); NaN when
/// fewer than two points are above that floor.
fn slope(h: &[f64], e: &[f64]) -> f64 {
    mbd_analysis::fit_order(h, e, 1e-12).map_or(f64::NAN, |f| f.order)
}

fn fig3(ctx: &Ctx) -> Result<Section, String> {
    let p = problem()?;
    let span = if ctx.quick { 2.0 } else { 10.0 };
    let h0 = p.sys.energy(p.s0.q.as_slice(), p.s0.v.as_slice());
    let mut sec = Section::default();
    sec.setting("span (s)", span);
    sec.setting("energy error", "E|dH| = mean over the steps of |H_k - H_0|");
    let mut fig = Figure::new(
        "Paper A Fig. 3: energy error against step size",
        "h (s)",
        "E|dH| (J)",
    )
    .log(true, true);
    let mut t = Table::new(
        "Fig. 3: measured orders of the energy error (least-squares slope, points above 1e-12)",
        &["(s,s)", "h", "E|dH|", "order", "paper"],
    );
    let mut double = Vec::new();
    for s in 1..=4usize {
        let hs: Vec<f64> = match s {
            1 | 2 => vec![0.08, 0.04, 0.02, 0.01],
            // the asymptotic range of the double pendulum (fast mode omega ~ 7.6 rad/s) above
            // the round-off floor
            3 => vec![0.1, 0.07, 0.05, 0.035, 0.025],
            _ => vec![0.08, 0.07, 0.06, 0.05, 0.04],
        };
        let mut es = Vec::new();
        for &h in &hs {
            let n = steps(span, h);
            let mut g =
                Galerkin::new(&p.sys, SymplecticOptions::new(s)).map_err(|e| e.to_string())?;
            let mut st = p.s0.clone();
            let mut acc = 0.0;
            for k in 1..=n {
                g.step(&p.sys, &mut st, h).map_err(|e| e.to_string())?;
                st.t = k as f64 * h;
                acc += (p.sys.energy(st.q.as_slice(), st.v.as_slice()) - h0).abs();
            }
            es.push(acc / (n + 1) as f64);
        }
        let order = slope(&hs, &es);
        t.row(vec![
            format!("({s},{s})"),
            hs.iter()
                .map(|h| format!("{h}"))
                .collect::<Vec<_>>()
                .join(", "),
            es.iter().map(|e| fmt_e(*e)).collect::<Vec<_>>().join(", "),
            format!("{order:.2}"),
            match s {
                1 => "2".into(),
                2 => "4".into(),
                _ => "-".into(),
            },
        ]);
        if s <= 2 {
            sec.claims.push(Claim::check(
                format!(
                    "Fig. 3: energy error of order {} on the double pendulum (s = {s})",
                    2 * s
                ),
                (order - 2.0 * s as f64).abs() <= 0.3,
                format!("slope {order:.2}"),
            ));
        }
        double.push(json!({"s": s, "order_energy_double_pendulum": num(order)}));
        fig = fig.with(Series::points(format!("(s,s) = ({s},{s})"), hs, es));
    }
    fig.save(&ctx.figure_path("paper_a_fig3.svg"))?;
    sec.figures.push(FigureRef {
        file: "paper_a_fig3.svg".into(),
        caption: "Energy error E|dH| against h for s = 1..4 (log-log); slopes 2s".into(),
    });
    sec.tables.push(t);
    sec.notes.push("On the double pendulum the s = 3, 4 energy errors reach their asymptotic range only near the round-off floor (the fast mode has omega h = 0.3-0.8 at these steps), so their slopes above are pre-asymptotic; the orders are measured below on the single pendulum and the manipulator.".into());
    // measured orders 2s: positions at the end and max energy error, against DOPRI5
    let mut to = Table::new(
        "Measured orders (least-squares slopes; error at t_end against DOPRI5 + projection with 4e4 steps over the span)",
        &["problem", "(s,s)", "t_end (s): steps", "position error at t_end", "order", "max |dH|", "order"],
    );
    let mut orders = Vec::new();
    let pend = models::pendulum(1.0, 1.0, 1.0, 9.81).map_err(|e| e.to_string())?;
    let man = models::manipulator().map_err(|e| e.to_string())?;
    // (s, t_end, steps): the manipulator over 0.5 s (0.6 s for s = 4: its s = 4 errors settle
    // into the asymptotic slope only there, above the round-off floor)
    type Runs = [(f64, &'static [usize]); 4];
    let pend_runs: Runs = [
        (1.0, &[10, 20, 40]),
        (1.0, &[10, 20, 40]),
        (1.0, &[8, 12, 16, 24]),
        (1.0, &[7, 10, 14]),
    ];
    let man_runs: Runs = [
        (0.5, &[10, 14, 20]),
        (0.5, &[10, 14, 20]),
        (0.5, &[10, 14, 20]),
        (0.6, &[18, 24, 32]),
    ];
    let table: [(&str, &System, Runs); 2] = [
        ("single pendulum (1 rad)", &pend, pend_runs),
        ("manipulator", &man, man_runs),
    ];
    for (name, sys, runs) in table {
        let s0 = State::consistent(sys, 0.0).map_err(|e| e.to_string())?;
        let e0 = sys.energy(s0.q.as_slice(), s0.v.as_slice());
        for s in 1..=4usize {
            let (t_end, ns_s) = runs[s - 1];
            let r = reference_trajectory(sys, &s0, t_end, 1, 40000, ButcherTableau::dopri5())
                .map_err(|e| e.to_string())?;
            let (mut hs, mut eq, mut eh) = (Vec::new(), Vec::new(), Vec::new());
            for &n in ns_s {
                let h = t_end / n as f64;
                let mut o = SymplecticOptions::new(s);
                o.newton.tol = 1e-17;
                let mut g = Galerkin::new(sys, o).map_err(|e| e.to_string())?;
                let mut st = s0.clone();
                let mut emax = 0.0f64;
                for k in 1..=n {
                    g.step(sys, &mut st, h).map_err(|e| e.to_string())?;
                    st.t = k as f64 * h;
                    emax = emax.max((sys.energy(st.q.as_slice(), st.v.as_slice()) - e0).abs());
                }
                hs.push(h);
                eq.push(
                    st.q.iter()
                        .zip(&r.q[1])
                        .map(|(a, b)| (a - b).abs())
                        .fold(0.0, f64::max),
                );
                eh.push(emax);
            }
            let (pq, ph) = (slope(&hs, &eq), slope(&hs, &eh));
            to.row(vec![
                name.into(),
                format!("({s},{s})"),
                format!(
                    "{t_end}: {}",
                    ns_s.iter()
                        .map(|n| n.to_string())
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
                eq.iter().map(|e| fmt_e(*e)).collect::<Vec<_>>().join(", "),
                format!("{pq:.2}"),
                eh.iter().map(|e| fmt_e(*e)).collect::<Vec<_>>().join(", "),
                format!("{ph:.2}"),
            ]);
            sec.claims.push(Claim::check(
                format!(
                    "order 2s = {} for positions and energy, {name} (s = {s})",
                    2 * s
                ),
                (pq - 2.0 * s as f64).abs() <= 0.3 && (ph - 2.0 * s as f64).abs() <= 0.3,
                format!("slopes {pq:.2} (positions), {ph:.2} (energy)"),
            ));
            orders
                .push(json!({"s": s, "problem": name, "order": num(pq), "order_energy": num(ph)}));
        }
    }
    sec.tables.push(to);
    sec.summary = json!({"paper_a": {"orders": orders, "fig3": double}});
    Ok(sec)
}

fn gamma_sweep(
    p: &Problem,
    h: f64,
    n: usize,
    r: &ReferenceTrajectory,
    s: usize,
    gammas: &[f64],
) -> Result<Vec<ErrorMeasures>, String> {
    gammas.iter().map(|&g| measures(p, h, n, r, s, g)).collect()
}

fn fig4(ctx: &Ctx) -> Result<Section, String> {
    let p = problem()?;
    let h = 0.01;
    let span = if ctx.quick { 5.0 } else { 1000.0 };
    let n = steps(span, h);
    let r = reference(&p, h, n, if ctx.quick { 8 } else { 16 })?;
    let gammas: Vec<f64> = if ctx.quick {
        vec![0.0, 1.0, 2.0, 3.0]
    } else {
        (0..=10).map(|k| 0.5 * k as f64).collect()
    };
    let m = gamma_sweep(&p, h, n, &r, 1, &gammas)?;
    let mut sec = Section::default();
    sec.setting("(s,s)", "(1,1)");
    sec.setting("h", h);
    sec.setting("N_t (s)", span);
    sec.setting("reference", &r.method);
    let fig = Figure::new(
        "Paper A Fig. 4: errors against gamma, (1,1), h = 0.01",
        "gamma",
        "error",
    )
    .log(false, true)
    .with(Series::line(
        "E|dx| (m)",
        gammas.clone(),
        m.iter().map(|e| e.mean_abs_dx).collect(),
    ))
    .with(Series::line(
        "E|dy| (m)",
        gammas.clone(),
        m.iter().map(|e| e.mean_abs_dy).collect(),
    ))
    .with(Series::line(
        "E|dH| (J)",
        gammas.clone(),
        m.iter().map(|e| e.mean_abs_dh).collect(),
    ));
    fig.save(&ctx.figure_path("paper_a_fig4.svg"))?;
    sec.figures.push(FigureRef {
        file: "paper_a_fig4.svg".into(),
        caption: format!(
            "E|dx|, E|dy|, E|dH| of the (1,1) scheme against gamma, h = 0.01 over {span} s"
        ),
    });
    let best = gammas
        .iter()
        .zip(&m)
        .min_by(|a, b| {
            (a.1.mean_abs_dx + a.1.mean_abs_dy).total_cmp(&(b.1.mean_abs_dx + b.1.mean_abs_dy))
        })
        .map(|(g, _)| *g)
        .unwrap_or(f64::NAN);
    sec.notes.push(format!(
        "Smallest E|dx| + E|dy| on the grid at gamma = {best}."
    ));
    sec.summary = json!({"paper_a": {"fig4": {"gamma": gammas, "E_dx": m.iter().map(|e| num(e.mean_abs_dx)).collect::<Vec<_>>(),
        "E_dy": m.iter().map(|e| num(e.mean_abs_dy)).collect::<Vec<_>>(), "E_dH": m.iter().map(|e| num(e.mean_abs_dh)).collect::<Vec<_>>()}}});
    Ok(sec)
}

fn fig5_6(ctx: &Ctx) -> Result<Section, String> {
    let p = problem()?;
    let h = 0.01;
    let span = if ctx.quick { 2.0 } else { 10.0 };
    let n = steps(span, h);
    let r = reference(&p, h, n, 32)?;
    let gammas: Vec<f64> = if ctx.quick {
        vec![0.0, 1.0, 2.0, 3.0, 4.0, 5.0]
    } else {
        (0..=20).map(|k| 0.25 * k as f64).collect()
    };
    let mut sec = Section::default();
    sec.setting("h", h);
    sec.setting("N_t (s)", span);
    sec.setting("reference", &r.method);
    let mut f5 = Figure::new(
        "Paper A Fig. 5: E|dx| + E|dy| against gamma",
        "gamma",
        "E|dx| + E|dy| (m)",
    )
    .log(false, true);
    let mut f6 = Figure::new(
        "Paper A Fig. 6: averaged signed error dW against gamma",
        "gamma",
        "dW = E[dx] + E[dy] (m)",
    );
    let mut summary = serde_json::Map::new();
    for s in [1usize, 2] {
        let m = gamma_sweep(&p, h, n, &r, s, &gammas)?;
        let cal = calibrate(&p, h, n, &r, s)?;
        let abs: Vec<f64> = m.iter().map(|e| e.mean_abs_dx + e.mean_abs_dy).collect();
        let dw: Vec<f64> = m.iter().map(|e| e.dw()).collect();
        // normalise by the gamma = 0 value so both s share an axis
        let a0 = abs[0];
        let d0 = dw[0].abs();
        f5 = f5.with(Series::line(
            format!("({s},{s}) / its gamma=0 value"),
            gammas.clone(),
            abs.iter().map(|v| v / a0).collect(),
        ));
        f6 = f6.with(Series::line(
            format!("({s},{s}) / |dW(0)|"),
            gammas.clone(),
            dw.iter().map(|v| v / d0).collect(),
        ));
        f6 = f6.with(Series::points(
            format!("gamma_opt ({s},{s}) = {:.3}", cal.gamma_opt),
            vec![cal.gamma_opt],
            vec![0.0],
        ));
        let (gmin, vmin) = gammas
            .iter()
            .zip(&abs)
            .min_by(|a, b| a.1.total_cmp(b.1))
            .map(|(g, v)| (*g, *v))
            .unwrap_or((f64::NAN, f64::NAN));
        sec.notes.push(format!(
            "s = {s}: E|dx| + E|dy| is smallest on the grid at gamma = {gmin} ({} vs {} at gamma = 0); dW crosses zero at gamma_opt = {:.4}.",
            fmt_e(vmin),
            fmt_e(a0),
            cal.gamma_opt
        ));
        sec.claims.push(Claim::check(
            format!("the absolute error against gamma has its minimum near gamma_opt (s = {s})"),
            (gmin - cal.gamma_opt).abs() <= 0.75,
            format!(
                "grid minimum at gamma = {gmin}, gamma_opt = {:.3}",
                cal.gamma_opt
            ),
        ));
        summary.insert(
            format!("s{s}"),
            json!({"gamma": gammas, "abs": abs.iter().map(|v| num(*v)).collect::<Vec<_>>(), "dW": dw.iter().map(|v| num(*v)).collect::<Vec<_>>(), "gamma_opt": num(cal.gamma_opt)}),
        );
    }
    f5.save(&ctx.figure_path("paper_a_fig5.svg"))?;
    f6.save(&ctx.figure_path("paper_a_fig6.svg"))?;
    sec.figures.push(FigureRef {
        file: "paper_a_fig5.svg".into(),
        caption: "E|dx| + E|dy| against gamma, normalised by the gamma = 0 value (a V with its minimum near gamma_opt)".into(),
    });
    sec.figures.push(FigureRef {
        file: "paper_a_fig6.svg".into(),
        caption: "dW(gamma), normalised by |dW(0)|: it crosses zero at gamma_opt".into(),
    });
    sec.summary = json!({"paper_a": {"fig5_6": Value::Object(summary)}});
    Ok(sec)
}

fn fig7(ctx: &Ctx) -> Result<Section, String> {
    let p = problem()?;
    let (hc, span_c) = (0.01, if ctx.quick { 2.0 } else { 10.0 });
    let nc = steps(span_c, hc);
    let rc = reference(&p, hc, nc, 32)?;
    let cal = calibrate(&p, hc, nc, &rc, 1)?;
    let h = 0.04;
    let span = if ctx.quick { 10.0 } else { 100.0 };
    let n = steps(span, h);
    let r = reference(&p, h, n, if ctx.quick { 16 } else { 64 })?;
    let t: Vec<f64> = (0..=n).map(|k| k as f64 * h).collect();
    let x_ref: Vec<f64> = r.q.iter().map(|q| q[3]).collect();
    let mut curves = Vec::new();
    for g in [0.0, cal.gamma_opt] {
        let mut integ = Galerkin::new(&p.sys, SymplecticOptions::new(1).with_gamma(g))
            .map_err(|e| e.to_string())?;
        let mut st = p.s0.clone();
        let mut x = vec![st.q[3]];
        for k in 1..=n {
            integ.step(&p.sys, &mut st, h).map_err(|e| e.to_string())?;
            st.t = k as f64 * h;
            x.push(st.q[3]);
        }
        curves.push(x);
    }
    // the last 10 s, where the phase drift shows
    let k0 = n.saturating_sub(steps(10.0, h));
    let win = |v: &[f64]| v[k0..].to_vec();
    let fig = Figure::new(
        format!("Paper A Fig. 7: x of body 2, (1,1), h = 0.04, last 10 s of {span} s"),
        "t (s)",
        "x_2 (m)",
    )
    .with(Series::line("reference", win(&t), win(&x_ref)))
    .with(Series::line("gamma = 0", win(&t), win(&curves[0])))
    .with(Series::line(
        format!("gamma_opt = {:.3}", cal.gamma_opt),
        win(&t),
        win(&curves[1]),
    ));
    fig.save(&ctx.figure_path("paper_a_fig7.svg"))?;
    let err = |c: &[f64]| {
        c.iter()
            .zip(&x_ref)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max)
    };
    let mut sec = Section::default();
    sec.setting("h", h);
    sec.setting("N_t (s)", span);
    sec.setting(
        "gamma_opt",
        format!(
            "{:.6} (calibrated at h = 0.01 over {span_c} s)",
            cal.gamma_opt
        ),
    );
    sec.notes.push(format!(
        "max |x_2 - x_2,ref| over the run: {} (gamma = 0), {} (gamma_opt).",
        fmt_e(err(&curves[0])),
        fmt_e(err(&curves[1]))
    ));
    sec.figures.push(FigureRef {
        file: "paper_a_fig7.svg".into(),
        caption: "x-component of body 2's centre of mass: reference, gamma = 0 and gamma_opt over the last 10 s of the run".into(),
    });
    sec.summary = json!({"paper_a": {"fig7": {"max_abs_dx2_gamma0": num(err(&curves[0])), "max_abs_dx2_gamma_opt": num(err(&curves[1])), "gamma_opt": num(cal.gamma_opt)}}});
    Ok(sec)
}
