//! Cross-solver agreement on the manipulator at t = 2 s: every solver converges to the same
//! trajectory as an independent reference (DOPRI5 on the index-1 form with projection at a tiny
//! step), with the error falling at its order; and, without the reference, the solvers'
//! Richardson-extrapolated end points agree with each other far more closely than their own
//! errors (they converge to one limit), and each solver's Richardson error estimate matches its
//! error against the reference.

use mbd::model::{models, System};
use mbd::rk4::{Rk4, Rk4Options};
use mbd::solve::{
    reference_trajectory, run, ButcherTableau, Integrator, NoObserver, RunConfig, State,
};
use mbd::symplectic::{Galerkin, SymplecticOptions};
use mbd::tangent::TangentRk;

type Make = fn(&System) -> Box<dyn Integrator>;

/// Each solver with its order and the step of its first run (the second halves it): in the
/// asymptotic range of its error. (Tangent RK4's leading error term is small in the
/// step-weighted chart, so the next one still shows at h = 0.0025: it takes h = 0.001;
/// docs/tangent.md, "The chart's metric".)
fn solvers() -> Vec<(&'static str, u32, f64, Make)> {
    vec![
        ("RK4", 4, 0.0025, |s| {
            Box::new(Rk4::new(s, Rk4Options::plain()).unwrap())
        }),
        ("RK4+projection", 4, 0.0025, |s| {
            Box::new(Rk4::new(s, Rk4Options::projected()).unwrap())
        }),
        ("symplectic (1,1)", 2, 0.00125, |s| {
            Box::new(Galerkin::new(s, SymplecticOptions::new(1)).unwrap())
        }),
        ("symplectic (2,2)", 4, 0.0025, |s| {
            Box::new(Galerkin::new(s, SymplecticOptions::new(2)).unwrap())
        }),
        ("tangent RK4", 4, 0.001, |s| {
            Box::new(TangentRk::rk4(s).unwrap())
        }),
    ]
}

fn final_q(sys: &System, integ: &mut dyn Integrator, h: f64) -> Vec<f64> {
    let mut s = State::consistent(sys, 0.0).unwrap();
    run(integ, sys, &mut s, RunConfig::new(2.0, h), &mut NoObserver).unwrap();
    s.q.as_slice().to_vec()
}

fn dist(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
}

#[test]
fn solvers_agree_on_the_manipulator_at_two_seconds() {
    let sys = models::manipulator().unwrap();
    let s0 = State::consistent(&sys, 0.0).unwrap();
    let reference =
        reference_trajectory(&sys, &s0, 1e-4, 20_000, 1, ButcherTableau::dopri5()).unwrap();
    let qref = reference.q.last().unwrap().clone();
    let mut finals = Vec::new();
    for (name, p, h, make) in solvers() {
        let e1 = dist(&final_q(&sys, make(&sys).as_mut(), h), &qref);
        let q2 = final_q(&sys, make(&sys).as_mut(), h / 2.0);
        let e2 = dist(&q2, &qref);
        let ratio = e1 / e2;
        eprintln!(
            "{name}: error {e1:.3e} (h = {h}), {e2:.3e} (h/2), ratio {ratio:.2} (2^p = {})",
            1 << p
        );
        // the error falls as the order predicts (to within 30 % of 2^p)
        assert!(
            ratio > 0.7 * f64::from(1u32 << p) && ratio < 1.3 * f64::from(1u32 << p),
            "{name}: ratio {ratio}"
        );
        assert!(e2 < 1e-3, "{name}: error {e2}");
        // Richardson: q2 + (q2 - q1) / (2^p - 1) removes the leading error term
        let q1 = final_q(&sys, make(&sys).as_mut(), h);
        let c = 1.0 / (f64::from(1u32 << p) - 1.0);
        let est = dist(&q2, &q1) * c;
        assert!(
            est > 0.7 * e2 && est < 1.3 * e2,
            "{name}: Richardson estimate {est:e} against the true error {e2:e}"
        );
        let qr: Vec<f64> = q2.iter().zip(&q1).map(|(a, b)| a + (a - b) * c).collect();
        finals.push((name, qr, e2));
    }
    // two solvers' extrapolated end points agree to a small fraction of their errors (measured:
    // at most 0.15 x, RK4 + projection against (2,2)): they
    // converge to the same limit (a solver converging to another trajectory, or not at its
    // order, fails this whatever the reference says)
    for i in 0..finals.len() {
        for j in i + 1..finals.len() {
            let d = dist(&finals[i].1, &finals[j].1);
            let scale = finals[i].2 + finals[j].2;
            eprintln!(
                "{} vs {}: extrapolated end points differ by {d:.3e} = {:.3} x (e_i + e_j)",
                finals[i].0,
                finals[j].0,
                d / scale
            );
            assert!(
                d <= 0.25 * scale,
                "{} vs {}: {d:e} against errors {scale:e}",
                finals[i].0,
                finals[j].0
            );
        }
    }
}
