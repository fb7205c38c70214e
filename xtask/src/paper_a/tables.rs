//! Paper A, Tables 1-3: errors of the (s,s) schemes and the gain of the preadjustment.

use super::*;

pub(super) fn table1(ctx: &Ctx) -> Result<Section, String> {
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
            let m = measure_run(
                &p,
                h,
                n,
                &r,
                SymplecticOptions::new(s)
                    .with_gamma(gamma)
                    .with_nodes(Nodes::Equispaced),
            )?;
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

pub(super) fn table2(ctx: &Ctx) -> Result<Section, String> {
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

pub(super) fn table3(ctx: &Ctx) -> Result<Section, String> {
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
