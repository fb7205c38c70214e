//! `own-spatial`: spatial bodies (natural coordinates, docs/spatial.md) with every solver of the
//! registry that takes them. The heavy top (a solid body and a disc on a massless axle, whose
//! mass matrix is singular): convergence orders. A flat plate tumbling about its intermediate
//! axis: the flip times located by events against the exact Jacobi-elliptic solution. A
//! torque-free body with symplectic (2,2), plain and with the s = 2 modified Lagrangian, over a
//! long time: energy and angular momentum. The s = 2 modified Lagrangian with a spatial spring:
//! its order and gain on a rod on a spring. The preadjusted symplectic schemes on spatial angle
//! drivers (`examples/models/driven_arm.toml`): orders and gains. A
//! chain of rods on ball joints: the cost of a step against its length on the sparse path, and
//! (`own_spatial_mixing.rs`) the Newton iterations of the (1,1) modified scheme there with and
//! without the mixing of its updates.

use crate::own_scaling::MAX_EXPONENT;
use crate::report::{fmt_e, num, Claim, Ctx, Section, Table};
use mbd::model::models::{free_body, heavy_top, sprung_rod, TorqueFreeBody};
use mbd::prelude::*;
use mbd::solve::{DenseOutput, Event, NoObserver};
use mbd::Simulation;
use mbd_analysis::fit_order;
use mbd_solve::nalgebra::{Matrix3, Vector3};
use serde_json::json;

/// Tolerance on a fitted order (the issue's).
const ORDER_TOL: f64 = 0.3;
/// Errors below this are at the floor of the reference.
const FLOOR: f64 = 1e-11;
/// The tumbling body's floor: its reference (symplectic (4,4) at h = 0.0125) is good to about
/// 1e-15, and the order-8 errors need the decade below the heavy top's floor.
const TUMBLING_FLOOR: f64 = 1e-13;
/// The documented miss of the long-time energy claim.
const ENERGY_MISS: &str =
    "the (2,2) scheme's energy error at h = T/50 is 7.8e-8 plain and 5.4e-10 with the s = 2 \
    modified Lagrangian (order 6 in the energy, which removes the h^4 term): the 1e-10 target \
    would need the next, h^6 term or a step of about T/66";
/// The smallest factor by which the s = 2 modified Lagrangian must lower plain (2,2)'s energy
/// error on the torque-free body at T/50 (order 6 against 4: about `(h omega)^-2`).
const MODIFIED_ENERGY_GAIN: f64 = 100.0;

fn run(sys: &System, spec: &str, t_end: f64, h: f64) -> Result<State, String> {
    let mut sim = Simulation::new(sys.clone(), spec).map_err(|e| e.to_string())?;
    sim.run(RunConfig::new(t_end, h))
        .map_err(|e| format!("{spec}: {e}"))?;
    Ok(sim.state().clone())
}

/// One solver's errors in `q` at `t_end` against `reference` for each step of `hs`, and their
/// fitted order (errors below `floor` left out of the fit).
fn order_study(
    sys: &System,
    spec: &str,
    t_end: f64,
    hs: &[f64],
    reference: &State,
    floor: f64,
) -> Result<(Vec<f64>, f64), String> {
    let mut errs = Vec::new();
    for &h in hs {
        let s = run(sys, spec, t_end, h)?;
        errs.push(mbd_solve::linalg::max_abs_diff(
            s.q.as_slice(),
            reference.q.as_slice(),
        ));
    }
    let fit = fit_order(hs, &errs, floor).map_err(|e| format!("{spec}: {e} ({errs:?})"))?;
    Ok((errs, fit.order))
}

/// The claim that `spec` reaches its order `order` on `model` within [`ORDER_TOL`].
fn order_claim(spec: &str, order: u32, model: &str, fitted: f64, errs: &[f64]) -> Claim {
    Claim::check(
        format!("{spec} reaches its order {order} on {model} within {ORDER_TOL}"),
        (fitted - f64::from(order)).abs() <= ORDER_TOL,
        format!("fitted {fitted:.3} from errors {errs:?}"),
    )
}

/// Errors for a table cell.
fn fmt_errors(errs: &[f64]) -> String {
    errs.iter()
        .map(|e| fmt_e(*e))
        .collect::<Vec<_>>()
        .join(", ")
}

/// Angular momentum about the origin of the spatial bodies.
fn angular_momentum(sys: &System, s: &State) -> Vector3<f64> {
    Vector3::from(sys.spatial_angular_momentum(s.q.as_slice(), s.v.as_slice()))
}

pub fn spatial(ctx: &Ctx) -> Result<Section, String> {
    let mut sec = Section::default();
    orders(ctx, &mut sec)?;
    tumbling_orders(ctx, &mut sec)?;
    flips(&mut sec)?;
    long_time(ctx, &mut sec)?;
    spring_s2(&mut sec)?;
    driven_arm(&mut sec)?;
    director_drift(ctx, &mut sec)?;
    scaling(ctx, &mut sec)?;
    crate::own_spatial_mixing::mixing(ctx, &mut sec)?;
    Ok(sec)
}

/// Convergence orders of every solver that takes the heavy top.
fn orders(ctx: &Ctx, sec: &mut Section) -> Result<(), String> {
    let t_end = 0.5;
    // orders up to 4 at h = 2e-3 .. 5e-4 (tangent RK4's leading error term is small in the
    // step-weighted chart: at h = 4e-3 the next one still shows, docs/tangent.md, "The chart's
    // metric"), higher orders at h = 4e-3 .. 1e-3 (smaller steps reach the round-off floor)
    let hs_for = |order: u32| -> Vec<f64> {
        match (order >= 5, ctx.quick) {
            (true, _) => vec![4e-3, 2e-3, 1e-3],
            (false, true) => vec![1e-3, 5e-4],
            (false, false) => vec![2e-3, 1e-3, 5e-4],
        }
    };
    sec.setting(
        "heavy top",
        "1 kg, centre of mass 0.5 m from the tip, tilted 0.3 rad, spinning at 20 rad/s; t = 0.5 s; error: max-norm of q against index-1 DOPRI5 at h = 6.25e-5",
    );
    sec.setting(
        "step sizes",
        format!("{:?} (orders 5 and 6: {:?})", hs_for(4), hs_for(5)),
    );
    let mut table = Table::new(
        "Heavy top: convergence orders (least-squares slope) of every solver that takes spatial bodies",
        &["solver", "body", "nominal", "fitted", "errors"],
    );
    let mut rows = Vec::new();
    let mut refused = Vec::new();
    for (body, moments) in [
        ("solid", [0.3, 0.3, 0.1]),
        ("disc, E_3 = 0", [0.25, 0.25, 0.5]),
    ] {
        let sys = heavy_top(moments, 0.3, 20.0).map_err(|e| e.to_string())?;
        let reference = run(&sys, "index1:dopri5", t_end, 6.25e-5)?;
        let mut smallest_h_errors: Vec<(&str, f64)> = Vec::new();
        for (_, v) in mbd::registry().variants().filter(|(_, v)| v.compared) {
            if Simulation::new(sys.clone(), v.spec).is_err() {
                refused.push(format!("{} ({body})", v.spec));
                continue;
            }
            // the swarm-based solver costs about 100 plain steps a step: two step sizes
            let hs = hs_for(v.order);
            let hs_v: Vec<f64> = if v.relative_cost > 20.0 {
                hs[..2].to_vec()
            } else {
                hs
            };
            let (errs, fitted) = order_study(&sys, v.spec, t_end, &hs_v, &reference, FLOOR)?;
            if let Some(&e) = errs.last() {
                smallest_h_errors.push((v.spec, e));
            }
            table.row(vec![
                v.spec.to_string(),
                body.to_string(),
                format!("{}", v.order),
                format!("{fitted:.2}"),
                fmt_errors(&errs),
            ]);
            sec.claims.push(order_claim(
                v.spec,
                v.order,
                &format!("the heavy top ({body})"),
                fitted,
                &errs,
            ));
            rows.push(json!({"solver": v.spec, "body": body, "order": num(fitted), "errors": errs.iter().map(|e| num(*e)).collect::<Vec<_>>()}));
        }
        modified_gain(
            sec,
            &format!("the heavy top ({body})"),
            hs_for(4)[hs_for(4).len() - 1],
            &smallest_h_errors,
        );
    }
    sec.tables.push(table);
    if !refused.is_empty() {
        sec.notes
            .push(format!("Refused by name: {}.", refused.join(", ")));
    }
    sec.summary = json!({ "spatial_orders": rows });
    Ok(())
}

/// Orders on a body tumbling about its intermediate axis: every compared solver that takes it,
/// and the plain symplectic (s,s) scheme for s = 1..4 (order 2s), at step sizes where even the
/// order-8 errors stay above round-off.
fn tumbling_orders(ctx: &Ctx, sec: &mut Section) -> Result<(), String> {
    let sys = free_body([1.0, 2.0, 2.5], [0.05, 2.0, 0.05]).map_err(|e| e.to_string())?;
    let t_end = 4.0;
    // orders 6 and 8 reach round-off sooner: they take steps sixteen times as large
    // (orders up to 4 take steps half as large: tangent RK4's leading error term is small in
    // the step-weighted chart, and at h = 0.025 the next one still shows)
    let hs_for = |order: u32| -> Vec<f64> {
        let base = match order {
            6.. => 0.4,
            5 => 0.025,
            _ => 0.0125,
        };
        let n = if ctx.quick { 2 } else { 3 };
        (0..n).map(|k| base / f64::from(1 << k)).collect()
    };
    sec.setting(
        "tumbling body",
        format!("J = (1, 2, 2.5), omega0 = (0.05, 2, 0.05) rad/s (about the intermediate axis), t = {t_end} s, h = {:?} (order 5: {:?}, orders 6 and 8: {:?}); error: max-norm of q against symplectic:4 at h = 0.0125, errors below {TUMBLING_FLOOR:e} left out of the fits", hs_for(4), hs_for(5), hs_for(8)),
    );
    let reference = run(&sys, "symplectic:4", t_end, 0.0125)?;
    let mut table = Table::new(
        "Tumbling body: convergence orders (least-squares slope)",
        &["solver", "nominal", "fitted", "errors"],
    );
    let mut specs: Vec<(String, u32)> = mbd::registry()
        .variants()
        .filter(|(_, v)| v.compared && v.relative_cost <= 20.0)
        .map(|(_, v)| (v.spec.to_string(), v.order))
        .collect();
    for s in 3..=4 {
        specs.push((format!("symplectic:{s}"), 2 * s));
    }
    let mut rows = Vec::new();
    let mut smallest_h_errors: Vec<(String, f64)> = Vec::new();
    for (spec, order) in specs {
        if Simulation::new(sys.clone(), &spec).is_err() {
            continue;
        }
        let hs = hs_for(order);
        let (errs, fitted) = order_study(&sys, &spec, t_end, &hs, &reference, TUMBLING_FLOOR)?;
        if let Some(&e) = errs.last() {
            smallest_h_errors.push((spec.clone(), e));
        }
        table.row(vec![
            spec.clone(),
            format!("{order}"),
            format!("{fitted:.2}"),
            fmt_errors(&errs),
        ]);
        sec.claims.push(order_claim(
            &spec,
            order,
            "a body tumbling about its intermediate axis",
            fitted,
            &errs,
        ));
        rows.push(json!({"solver": spec, "order": num(fitted), "errors": errs.iter().map(|e| num(*e)).collect::<Vec<_>>()}));
    }
    sec.tables.push(table);
    sec.summary["spatial_tumbling_orders"] = json!(rows);
    let errs: Vec<(&str, f64)> = smallest_h_errors
        .iter()
        .map(|(s, e)| (s.as_str(), *e))
        .collect();
    let h4 = hs_for(4);
    modified_gain(sec, "the tumbling body", h4[h4.len() - 1], &errs);
    Ok(())
}

/// The smallest factor by which the s = 1 modified Lagrangian must lower plain (1,1)'s error
/// at the smallest step of an order study (order 4 against 2: about `(h omega)^-2`).
const MODIFIED_GAIN: f64 = 100.0;

/// The claim that the s = 1 modified Lagrangian's error at the smallest step `h` of an order
/// study on `model` is at least [`MODIFIED_GAIN`] below plain (1,1)'s (`errs`: each solver's
/// error at that step); nothing if either did not run.
fn modified_gain(sec: &mut Section, model: &str, h: f64, errs: &[(&str, f64)]) {
    let find = |spec: &str| errs.iter().find(|e| e.0 == spec).map(|e| e.1);
    let (Some(plain), Some(modified)) = (find("symplectic:1"), find("symplectic:1:modified"))
    else {
        return;
    };
    let gain = plain / modified;
    sec.claims.push(Claim::check(
        format!(
            "the s = 1 modified Lagrangian lowers plain (1,1)'s error on {model} at least \
             {MODIFIED_GAIN}x at h = {h:e}"
        ),
        gain >= MODIFIED_GAIN,
        format!("{gain:.0}x ({} -> {})", fmt_e(plain), fmt_e(modified)),
    ));
}

/// The tumbling flat plate's flips against the exact solution.
fn flips(sec: &mut Section) -> Result<(), String> {
    let (j, w0) = ([1.0, 2.0, 3.0], [0.05, 2.0, 0.05]);
    let sys = free_body(j, w0).map_err(|e| e.to_string())?;
    let exact = TorqueFreeBody::new(j, Vector3::from(w0), Matrix3::identity())
        .map_err(|e| e.to_string())?;
    let t_end = exact.period().ok_or("the plate does not tumble")? * 0.8;
    let want = exact.flip_times(t_end);
    let probe = sys.clone();
    let mut dense =
        DenseOutput::new(&sys, NoObserver).with_event(Event::new("omega_2 = 0", move |_, q, v| {
            probe
                .spatial_body_angular_velocity(0, q, v)
                .map_or(0.0, |w| w[1])
        }));
    let mut sim = Simulation::new(sys.clone(), "index1:dopri5").map_err(|e| e.to_string())?;
    sim.run_observed(AdaptiveConfig::new(t_end, 1e-12), &mut dense)
        .map_err(|e| e.to_string())?;
    let found: Vec<f64> = dense.events().iter().map(|e| e.t).collect();
    let mut table = Table::new(
        "Flat plate J = (1, 2, 3) (E_3 = 0) tumbling about its intermediate axis, omega0 = (0.05, 2, 0.05): flips (zeros of the intermediate angular velocity) located by events with index1:dopri5 at tol 1e-12, against the exact Jacobi-elliptic solution",
        &["flip", "located (s)", "exact (s)", "relative error"],
    );
    let mut worst = 0.0f64;
    for (k, (f, e)) in found.iter().zip(&want).enumerate() {
        let rel = (f - e).abs() / e;
        worst = worst.max(rel);
        table.row(vec![
            format!("{}", k + 1),
            format!("{f:.12}"),
            format!("{e:.12}"),
            fmt_e(rel),
        ]);
    }
    sec.tables.push(table);
    sec.claims.push(Claim::check(
        "flip times of a tumbling body within 1e-8 relative of the exact solution at tol 1e-12 (event location)",
        found.len() == want.len() && worst < 1e-8,
        format!("{} flips located, {} exact; largest relative error {}", found.len(), want.len(), fmt_e(worst)),
    ));
    Ok(())
}

/// The smallest factor by which the s = 2 modified Lagrangian must lower plain (2,2)'s error on
/// the rod on a spring at the smallest step (order 6 against 4: about `(h omega)^-2`).
const SPRING_S2_GAIN: f64 = 100.0;

/// Symplectic (2,2), plain and with the s = 2 modified Lagrangian, on a rod on an undamped
/// spatial spring (a non-linear spatial potential in the term's passes): fitted orders and the
/// gain at the smallest step, errors against symplectic (4,4) at h/16.
fn spring_s2(sec: &mut Section) -> Result<(), String> {
    let sys = sprung_rod([0.05, 0.05, 0.002]).map_err(|e| e.to_string())?;
    let (t_end, hs) = (1.0, [2e-2, 1e-2, 5e-3]);
    let reference = run(&sys, "symplectic:4", t_end, hs[0] / 16.0)?;
    let mut table = Table::new(
        "Rod on an undamped spatial spring (models::sprung_rod, t = 1 s): symplectic (2,2), plain and with the s = 2 modified Lagrangian; error: max-norm of q against symplectic:4 at h = 1.25e-3",
        &["solver", "nominal", "fitted", "errors"],
    );
    let mut last = Vec::new();
    for (spec, order) in [("symplectic:2", 4u32), ("symplectic:2:modified", 6)] {
        let (errs, fitted) = order_study(&sys, spec, t_end, &hs, &reference, FLOOR)?;
        table.row(vec![
            spec.to_string(),
            format!("{order}"),
            format!("{fitted:.2}"),
            fmt_errors(&errs),
        ]);
        sec.claims.push(order_claim(
            spec,
            order,
            "a rod on a spatial spring",
            fitted,
            &errs,
        ));
        last.push(errs[errs.len() - 1]);
    }
    sec.tables.push(table);
    if let [plain, modified] = last[..] {
        sec.claims.push(Claim::check(
            format!("the s = 2 modified Lagrangian lowers plain (2,2)'s error on a rod on a spatial spring at least {SPRING_S2_GAIN}x at h = 5e-3"),
            plain >= SPRING_S2_GAIN * modified,
            format!("{:.0}x ({} -> {})", plain / modified, fmt_e(plain), fmt_e(modified)),
        ));
    }
    Ok(())
}

/// The s = 1 modified Lagrangian's least gain over plain (1,1) on the driven arm.
const DRIVEN_S1_GAIN: f64 = 100.0;

/// The preadjusted symplectic schemes on spatial angle drivers (`examples/models/
/// driven_arm.toml`: a motor turning an arm from the ground and one turning a forearm against
/// the arm, whose `Phi_q` and constraint Hessians turn with time): plain, modified-Lagrangian
/// and `W_s` (gamma = 1) (s,s) schemes, s = 1, 2, errors in `q` at t = 0.5 s against
/// symplectic (4,4) at h = 1.25e-3. Claimed: every preadjusted variant keeps at least the
/// plain order 2s (the terms are derived for constraints that do not depend on time), the
/// s = 1 modified Lagrangian lowers plain (1,1)'s error at least [`DRIVEN_S1_GAIN`]x at the
/// smallest step, and the s = 2 one lowers plain (2,2)'s at every step.
fn driven_arm(sec: &mut Section) -> Result<(), String> {
    let sys = System::from_toml(include_str!("../../examples/models/driven_arm.toml"))
        .map_err(|e| format!("examples/models/driven_arm.toml: {e}"))?;
    let (t_end, hs) = (0.5, [1e-2, 5e-3, 2.5e-3]);
    let reference = run(&sys, "symplectic:4", t_end, 1.25e-3)?;
    let mut table = Table::new(
        "Spatial angle drivers (examples/models/driven_arm.toml, t = 0.5 s): the symplectic schemes, plain and preadjusted, h = 1e-2, 5e-3, 2.5e-3; error: max-norm of q against symplectic:4 at h = 1.25e-3",
        &["solver", "plain order", "fitted", "errors"],
    );
    let mut errors = Vec::new();
    for (spec, plain_order, preadjusted) in [
        ("symplectic:1", 2u32, false),
        ("symplectic:1:modified", 2, true),
        ("symplectic:1:gamma=1", 2, true),
        ("symplectic:2", 4, false),
        ("symplectic:2:modified", 4, true),
        ("symplectic:2:gamma=1", 4, true),
    ] {
        let (errs, fitted) = order_study(&sys, spec, t_end, &hs, &reference, 1e-13)?;
        table.row(vec![
            spec.to_string(),
            format!("{plain_order}"),
            format!("{fitted:.2}"),
            fmt_errors(&errs),
        ]);
        if preadjusted {
            sec.claims.push(Claim::check(
                format!("{spec} keeps at least the plain order {plain_order} (within {ORDER_TOL}) on spatial angle drivers"),
                fitted >= f64::from(plain_order) - ORDER_TOL,
                format!("fitted {fitted:.3} from errors {errs:?}"),
            ));
        }
        errors.push((spec, errs));
    }
    sec.tables.push(table);
    let find = |spec: &str| errors.iter().find(|e| e.0 == spec).map(|e| e.1.clone());
    if let (Some(plain), Some(modified)) = (find("symplectic:1"), find("symplectic:1:modified")) {
        let (p, m) = (plain[2], modified[2]);
        sec.claims.push(Claim::check(
            format!("the s = 1 modified Lagrangian lowers plain (1,1)'s error on spatial angle drivers at least {DRIVEN_S1_GAIN}x at h = 2.5e-3"),
            p >= DRIVEN_S1_GAIN * m,
            format!("{:.0}x ({} -> {})", p / m, fmt_e(p), fmt_e(m)),
        ));
    }
    if let (Some(plain), Some(modified)) = (find("symplectic:2"), find("symplectic:2:modified")) {
        let gains: Vec<String> = plain
            .iter()
            .zip(&modified)
            .map(|(p, m)| format!("{:.1}x", p / m))
            .collect();
        sec.claims.push(Claim::check(
            "the s = 2 modified Lagrangian lowers plain (2,2)'s error on spatial angle drivers at every step",
            plain.iter().zip(&modified).all(|(p, m)| m < p),
            format!("gains {}", gains.join(", ")),
        ));
    }
    Ok(())
}

/// Symplectic (2,2), plain and with the s = 2 modified Lagrangian, on a torque-free body over
/// a long time: the largest relative deviations of the energy and of the angular momentum.
fn long_time(ctx: &Ctx, sec: &mut Section) -> Result<(), String> {
    let sys = free_body([1.0, 2.0, 2.5], [0.05, 2.0, 0.05]).map_err(|e| e.to_string())?;
    let t_end = if ctx.quick { 100.0 } else { 1000.0 };
    let h = std::f64::consts::PI / 50.0;
    sec.setting(
        "torque-free body",
        format!("J = (1, 2, 2.5), omega0 = (0.05, 2, 0.05) rad/s, symplectic:2 and symplectic:2:modified at h = pi/50 (1/50 of the spin period), {t_end} s"),
    );
    let mut table = Table::new(
        "Torque-free body over a long time: largest relative deviations",
        &["solver", "energy", "angular momentum"],
    );
    let mut energy = Vec::new();
    for spec in ["symplectic:2", "symplectic:2:modified"] {
        let mut sim = Simulation::new(sys.clone(), spec).map_err(|e| e.to_string())?;
        let s0 = sim.state().clone();
        let (h0, l0) = (
            sys.energy(s0.q.as_slice(), s0.v.as_slice()),
            angular_momentum(&sys, &s0),
        );
        let mut worst = (0.0f64, 0.0f64);
        let mut watch = |_: &System, s: &State, _: usize| -> Result<Flow, SolveError> {
            let e = (sys.energy(s.q.as_slice(), s.v.as_slice()) - h0).abs() / h0;
            let l = (angular_momentum(&sys, s) - l0).amax() / l0.norm();
            worst = (worst.0.max(e), worst.1.max(l));
            Ok(Flow::Continue)
        };
        sim.run_observed(RunConfig::new(t_end, h), &mut watch)
            .map_err(|e| format!("{spec}: {e}"))?;
        table.row(vec![spec.to_string(), fmt_e(worst.0), fmt_e(worst.1)]);
        sec.claims.push(Claim::check(
            format!("{spec} keeps all three components of a torque-free body's angular momentum to 1e-10 relative at 1/50 of the spin period"),
            worst.1 < 1e-10,
            format!("max relative deviation {} over {t_end} s", fmt_e(worst.1)),
        ));
        energy.push(worst.0);
    }
    sec.tables.push(table);
    let (plain, modified) = (energy[0], energy[1]);
    sec.claims.push(
        Claim::check(
            "symplectic (2,2) (with the s = 2 modified Lagrangian) keeps a torque-free body's energy to 1e-10 relative at 1/50 of the spin period",
            modified < 1e-10,
            format!(
                "max relative deviation over {t_end} s: {} (plain (2,2): {})",
                fmt_e(modified),
                fmt_e(plain)
            ),
        )
        .expected_miss(ENERGY_MISS),
    );
    sec.claims.push(Claim::check(
        format!("the s = 2 modified Lagrangian lowers plain (2,2)'s energy error on the torque-free body at least {MODIFIED_ENERGY_GAIN}x at 1/50 of the spin period"),
        plain >= MODIFIED_ENERGY_GAIN * modified,
        format!("{:.0}x ({} -> {})", plain / modified, fmt_e(plain), fmt_e(modified)),
    ));
    Ok(())
}

/// The director constraints over a million steps of the torque-free body (a hundred thousand
/// in quick mode): symplectic (2,2) and projected RK4 at 1/50 of the spin period.
fn director_drift(ctx: &Ctx, sec: &mut Section) -> Result<(), String> {
    let sys = free_body([1.0, 2.0, 2.5], [0.05, 2.0, 0.05]).map_err(|e| e.to_string())?;
    let steps: usize = if ctx.quick { 100_000 } else { 1_000_000 };
    let h = std::f64::consts::PI / 50.0;
    let mut phi = vec![0.0; sys.n_constraints()];
    for spec in ["symplectic:2", "rk4-projected"] {
        let mut sim = Simulation::new(sys.clone(), spec).map_err(|e| e.to_string())?;
        let mut worst = 0.0f64;
        let mut watch = |sys: &System, s: &State, _: usize| -> Result<Flow, SolveError> {
            sys.phi(s.q.as_slice(), s.t, &mut phi);
            worst = phi.iter().fold(worst, |m, x| m.max(x.abs()));
            Ok(Flow::Continue)
        };
        sim.run_observed(RunConfig::new(steps as f64 * h, h), &mut watch)
            .map_err(|e| format!("{spec}: {e}"))?;
        sec.claims.push(Claim::check(
            format!("{spec} keeps a torque-free body's director constraints at round-off (1e-13) over {steps} steps"),
            worst <= 1e-13,
            format!("max abs(Phi) {} over {steps} steps of h = pi/50", fmt_e(worst)),
        ));
    }
    Ok(())
}

/// The solvers timed on the spatial chain, and whether each is expected to run there.
const SCALING_SOLVERS: [(&str, bool); 9] = [
    ("rk4-projected", true),
    ("index1:dopri5", true),
    ("tangent:rk4", true),
    ("symplectic:2", true),
    ("symplectic:1", true),
    ("symplectic:1:gamma=1", true),
    ("symplectic:2:gamma=1", true),
    ("symplectic:1:modified", true),
    ("symplectic:2:modified", true),
];
/// The solvers of the [`MAX_RATIO`] claim that every solver must meet.
const INDEX1_AND_TANGENT: [&str; 3] = ["rk4-projected", "index1:dopri5", "tangent:rk4"];
/// The spatial chain's bound on a solver's cost per step relative to plain RK4 at the largest N.
const MAX_RATIO: f64 = 10.0;
/// The solvers whose misses of the scaling claims are documented, with the reason for each.
const DOCUMENTED_MISSES: [(&str, &str); 2] = [
    ("symplectic:1:modified", "the (1,1) modified scheme's instructions per step grow 12.5x from N = 100 to 1000 (23.8M to 296M, callgrind, 2026-11-28: exponent 1.10) through the augmented LU of its projected position block, which N = 100 does not need (its bound |c| rho^2 is below the threshold there); its wall-clock exponent measured 1.15 to 1.30 in five runs"),
    ("symplectic:2:modified", "the (2,2) modified scheme's instructions per step grow 13.5x from N = 100 to 1000 (59.0M to 799M, callgrind, 2026-11-28, steps 8 to 16 at N = 1000: exponent 1.13); its wall-clock exponent measured 1.14 to 1.22"),
];

/// Cost of a step on a chain of spatial rods against its length, as ratios to plain RK4.
fn scaling(ctx: &Ctx, sec: &mut Section) -> Result<(), String> {
    let ns: [usize; 2] = if ctx.quick { [30, 100] } else { [100, 1000] };
    let (blocks, block_s) = if ctx.quick { (2, 0.03) } else { (5, 0.3) };
    sec.setting(
        "spatial chain",
        format!("models::spatial_chain: rods of 0.5 m on ball joints, 12 coordinates and 9 equations per rod, h = 1e-3; best of {blocks} blocks of about {block_s} s, each block the second half of a run of twice its steps (at least {} each) through the public run loop (symplectic (s,s), plain and modified, keeps its sparse stage factorisation across steps; the first half carries the run's start-up), interleaved with plain RK4's; N = {ns:?}", crate::own_scaling::CONTINUING_MIN_STEPS),
    );
    let mut table = Table::new(
        "Spatial chain: cost of one step (microseconds, and ratio to plain RK4 in the same loop)",
        &[
            "solver",
            &format!("N = {}", ns[0]),
            &format!("N = {}", ns[1]),
            "exponent",
        ],
    );
    let mut peer_cost = [0.0; 2];
    let mut worst_ratio = 0.0f64;
    let mut worst_all = 0.0f64;
    let mut worst_exp = 0.0f64;
    // the solvers above the claims' bounds: the exponent, the 10x ratio
    let (mut over_exp, mut over_ratio): (Vec<&str>, Vec<&str>) = (Vec::new(), Vec::new());
    let mut refused = Vec::new();
    for (spec, runs) in SCALING_SOLVERS {
        let mut row = vec![spec.to_string()];
        let mut per = [f64::NAN; 2];
        for (k, &n) in ns.iter().enumerate() {
            let sys = mbd::model::models::spatial_chain(n).map_err(|e| e.to_string())?;
            let s0 = State::consistent(&sys, 0.0).map_err(|e| e.to_string())?;
            let mut peer = mbd::registry()
                .parse("rk4")
                .and_then(|p| p.build(&sys))
                .map_err(|e| e.to_string())?;
            let made = mbd::registry().parse(spec).and_then(|p| p.build(&sys));
            let mut integ = match made {
                Ok(i) => i,
                Err(e) if !runs => {
                    refused.push(format!("{spec} at N = {n}: {e}"));
                    row.push("refused".into());
                    continue;
                }
                Err(e) => return Err(format!("{spec}, N = {n}: {e}")),
            };
            let (t, tp) = crate::own_scaling::measure(
                &sys,
                &s0,
                integ.as_mut(),
                peer.as_mut(),
                blocks,
                block_s,
                true,
            )?;
            per[k] = t;
            peer_cost[k] = tp;
            row.push(format!("{:.0} ({:.2}x)", t * 1e6, t / tp));
            if k == 1 {
                if INDEX1_AND_TANGENT.contains(&spec) {
                    worst_ratio = worst_ratio.max(t / tp);
                }
                worst_all = worst_all.max(t / tp);
                if t / tp > MAX_RATIO {
                    over_ratio.push(spec);
                }
            }
        }
        let exp = (per[1] / per[0]).ln() / (ns[1] as f64 / ns[0] as f64).ln();
        if exp.is_finite() {
            worst_exp = worst_exp.max(exp);
            if exp > MAX_EXPONENT {
                over_exp.push(spec);
            }
        }
        row.push(if exp.is_finite() {
            format!("{exp:.2}")
        } else {
            "-".into()
        });
        table.row(row);
    }
    let peer_exp = (peer_cost[1] / peer_cost[0]).ln() / (ns[1] as f64 / ns[0] as f64).ln();
    table.row(vec![
        "rk4 (peer)".into(),
        format!("{:.0}", peer_cost[0] * 1e6),
        format!("{:.0}", peer_cost[1] * 1e6),
        format!("{peer_exp:.2}"),
    ]);
    sec.tables.push(table);
    for r in &refused {
        sec.notes.push(r.clone());
    }
    let largest = ns[1];
    let mut refused_solvers: Vec<&str> = SCALING_SOLVERS
        .iter()
        .map(|s| s.0)
        .filter(|s| refused.iter().any(|r| r.starts_with(&format!("{s} at"))))
        .collect();
    refused_solvers.dedup();
    // a miss by documented solvers alone is expected, with their reasons
    let reason = |spec: &str| DOCUMENTED_MISSES.iter().find(|d| d.0 == spec).map(|d| d.1);
    let expected = |c: Claim, over: &[&str]| {
        let reasons: Option<Vec<String>> = over
            .iter()
            .map(|s| reason(s).map(|r| format!("{s}: {r}")))
            .collect();
        match reasons {
            Some(r) if !r.is_empty() => {
                c.expected_miss(format!("{}; see docs/report.md, own-spatial", r.join("; ")))
            }
            _ => c,
        }
    };
    sec.claims.push(expected(
        Claim::timing(
            format!("on a spatial chain, every timed solver's cost per step grows at most like N^{MAX_EXPONENT} (sparse paths)"),
            worst_exp.max(peer_exp) <= MAX_EXPONENT,
            format!(
                "largest fitted exponent {:.2} (plain RK4 {peer_exp:.2}); above {MAX_EXPONENT}: {}",
                worst_exp.max(peer_exp),
                if over_exp.is_empty() { "none".to_string() } else { over_exp.join(", ") }
            ),
        ),
        &over_exp,
    ));
    sec.claims.push(Claim::timing(
        format!("on a {largest}-rod spatial chain, projected RK4, index-1 DOPRI5 and tangent RK4 cost within {MAX_RATIO}x plain RK4 per step"),
        worst_ratio <= MAX_RATIO,
        format!("largest ratio {worst_ratio:.2}"),
    ));
    let every = Claim::timing(
        format!("every solver but FA-DAE runs a {largest}-rod spatial chain within {MAX_RATIO}x plain RK4 per step"),
        refused_solvers.is_empty() && worst_all <= MAX_RATIO,
        format!(
            "{} refused it ({}); largest ratio of those that ran {worst_all:.2}; above {MAX_RATIO}x: {}",
            refused_solvers.len(),
            refused_solvers.join(", "),
            if over_ratio.is_empty() { "none".to_string() } else { over_ratio.join(", ") }
        ),
    );
    sec.claims.push(if refused_solvers.is_empty() {
        expected(every, &over_ratio)
    } else {
        every
    });
    sec.timings = json!({ "spatial_scaling": {
        "n": ns,
        "peer_s_per_step": peer_cost,
        "worst_ratio": num(worst_ratio),
        "worst_exponent": num(worst_exp),
    }});
    Ok(())
}
