//! Work-precision on the manipulator: each solver's error at t = 2 s against its cost, with the
//! round-off floor located by halving the step until the error stops falling.

use super::*;

/// The largest rise of the error above its best value so far as `h` falls (`errs` ordered by
/// decreasing `h`): `max_i err_i / max(min_{j <= i} err_j, resolution)` (1 when the error never
/// rises). Errors below `resolution`, the distance between two reference solutions, are not
/// measured: a best value below it counts as `resolution`.
fn worst_rise(errs: &[f64], resolution: f64) -> f64 {
    let mut best = f64::INFINITY;
    let mut rise = 1.0f64;
    for &e in errs {
        if e.is_nan() {
            return f64::NAN;
        }
        best = best.min(e);
        rise = rise.max(e / best.max(resolution));
    }
    rise
}

pub(super) fn work_precision(ctx: &Ctx) -> Result<Section, String> {
    let mut sec = Section::default();
    let sys = models::manipulator().map_err(|e| e.to_string())?;
    let t_end = 2.0;
    // halving from 0.02 s down to each solver's h_min (quick: three steps)
    let sweep = |h_min: f64| -> Vec<f64> {
        let n = if ctx.quick { 3 } else { 13 };
        (0..n)
            .map(|k| 0.02 / f64::powi(2.0, k))
            .filter(|&h| ctx.quick || h >= h_min * (1.0 - 1e-12))
            .collect()
    };
    let qref = reference_q(&sys, t_end, 5e-5)?;
    let qref2 = reference_q(&sys, t_end, 1e-4)?;
    let ref_err = max_diff(&qref, &qref2);
    sec.setting(
        "problem",
        "paper-C manipulator, error = max-norm of positions at t = 2 s",
    );
    sec.setting(
        "reference",
        format!("DOPRI5 on the index-1 form + projection, h = 5e-5 s (differs from h = 1e-4 by {}: the floor this experiment can resolve)", fmt_e(ref_err)),
    );
    sec.setting(
        "step sizes",
        if ctx.quick {
            "0.02, 0.01, 0.005 (quick: the floor is not reached)".to_string()
        } else {
            format!("0.02 / 2^k, halving until {ROUNDOFF_HALVINGS} consecutive halvings no longer improve the best error (round-off dominates) or down to 0.02 / 4096 = 4.9e-6 s (FA-DAE: 0.02 / 128)")
        },
    );
    let mut table = Table::new(
        "Work-precision on the manipulator",
        &["solver", "h [s]", "error at t = 2 s", "wall time [s]"],
    );
    let mut floors = Table::new(
        "Round-off floor of every solver: the best error of the sweep, and the largest rise of the error above its best value so far as h keeps falling (the claim: at most 10x; a best value below the reference's resolution counts as that resolution)",
        &["solver", "best error", "at h [s]", "smallest h [s]", "error there", "largest rise"],
    );
    let mut rows = Vec::new();
    let mut floor_rows = Vec::new();
    let mut fig = Figure::new(
        "Work-precision, manipulator, t = 2 s",
        "wall time [s]",
        "max position error",
    )
    .log(true, true);
    let mut fig_h = Figure::new(
        "Error against step size down to round-off, manipulator, t = 2 s",
        "step size h [s]",
        "max position error",
    )
    .log(true, true);
    for spec in solvers() {
        let mut hs = sweep(spec.h_min);
        let (mut xs, mut ys) = (vec![], vec![]);
        let mut since_best = 0;
        for k in 0..hs.len() {
            let h = hs[k];
            // round-off dominates once two consecutive halvings no longer improve the best
            // error: the sweep stops there (at most at h_min)
            if since_best >= ROUNDOFF_HALVINGS {
                hs.truncate(k);
                break;
            }
            // repeat short runs so timings are above timer resolution
            let (q, mut wall) = solve_to(&sys, &spec, t_end, h)?;
            if wall < 0.05 {
                let reps = (0.05 / wall.max(1e-6)).ceil().min(200.0) as usize;
                let t = Instant::now();
                for _ in 0..reps {
                    solve_to(&sys, &spec, t_end, h)?;
                }
                wall = t.elapsed().as_secs_f64() / reps as f64;
            }
            let err = max_diff(&q, &qref);
            if ys.iter().all(|&e| err < e) {
                since_best = 0;
            } else {
                since_best += 1;
            }
            table.row(vec![
                spec.name.into(),
                format!("{h:.4e}"),
                fmt_e(err),
                format!("{wall:.3e}"),
            ]);
            rows.push(json!({"solver": spec.name, "h": num(h), "error": num(err), "runtime_s": num(wall)}));
            xs.push(wall);
            ys.push(err);
        }
        let (ib, best) = ys
            .iter()
            .copied()
            .enumerate()
            .fold(
                (0, f64::INFINITY),
                |a, (i, e)| if e < a.1 { (i, e) } else { a },
            );
        let rise = worst_rise(&ys, ref_err);
        let last = ys.len() - 1;
        floors.row(vec![
            spec.name.into(),
            fmt_e(best),
            format!("{:.4e}", hs[ib]),
            format!("{:.4e}", hs[last]),
            fmt_e(ys[last]),
            format!("{rise:.2}"),
        ]);
        floor_rows.push(json!({"solver": spec.name, "best_error": num(best), "best_h": num(hs[ib]), "h_min": num(hs[last]), "error_at_h_min": num(ys[last]), "max_rise": num(rise)}));
        sec.claims.push(Claim::check(
            format!("{}: the error never rises more than 10x above its best value as h falls (manipulator, t = 2 s)", spec.name),
            rise <= 10.0,
            format!("largest rise {rise:.2}x; best {} at h = {:.3e}, {} at the smallest h = {:.3e}", fmt_e(best), hs[ib], fmt_e(ys[last]), hs[last]),
        ));
        fig_h
            .series
            .push(Series::points(spec.name, hs.clone(), ys.clone()));
        fig.series.push(Series::points(spec.name, xs, ys));
    }
    // the accuracy targets for the symplectic scheme
    for (name, target) in [("symplectic (1,1)", 2e-8), ("symplectic (2,2)", 1e-11)] {
        let best = floor_rows
            .iter()
            .find(|r| r["solver"] == name)
            .and_then(|r| r["best_error"].as_f64())
            .ok_or_else(|| format!("work-precision: no row for {name}"))?;
        let text = format!(
            "{name} reaches {} on the manipulator at t = 2 s",
            fmt_e(target)
        );
        sec.claims.push(if ctx.quick {
            Claim::not_checked(text, "quick mode stops the sweep at h = 0.005 s")
        } else {
            Claim::check(text, best <= target, format!("best error {}", fmt_e(best)))
        });
    }
    fig.save(&ctx.figure_path("own_work_precision.svg"))
        .map_err(|e| e.to_string())?;
    fig_h
        .save(&ctx.figure_path("own_error_vs_h.svg"))
        .map_err(|e| e.to_string())?;
    sec.figures.push(FigureRef {
        file: "own_work_precision.svg".into(),
        caption: "Error at t = 2 s against wall time, every solver, manipulator".into(),
    });
    sec.figures.push(FigureRef {
        file: "own_error_vs_h.svg".into(),
        caption: "Error at t = 2 s against the step size, down to each solver's round-off floor"
            .into(),
    });
    sec.tables.push(floors);
    sec.tables.push(table);
    sec.summary = json!({ "work_precision": rows, "work_precision_floor": floor_rows, "work_precision_reference_resolution": num(ref_err) });
    Ok(sec)
}

#[cfg(test)]
mod tests {
    use super::worst_rise;

    #[test]
    fn worst_rise_measures_the_rise_above_the_best_so_far() {
        assert_eq!(worst_rise(&[1.0, 0.1, 0.01, 0.001], 0.0), 1.0);
        assert!((worst_rise(&[1.0, 0.1, 0.01, 0.05, 0.02], 0.0) - 5.0).abs() < 1e-12);
        // a best value below the reference's resolution counts as the resolution
        assert!((worst_rise(&[1.0, 1e-14, 2e-13], 1e-13) - 2.0).abs() < 1e-12);
        assert!(worst_rise(&[1.0, f64::NAN, 0.5], 0.0).is_nan());
    }
}
