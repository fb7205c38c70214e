//! Dense output and event location through the shared run loop: the period of a single
//! pendulum from the zero crossings of its horizontal position, against the exact
//! elliptic-integral period, with adaptive DOPRI5 (tangent-space and index-1) at tol 1e-12.

use mbd::model::{models, System};
use mbd::solve::{
    run, run_adaptive, AdaptiveConfig, ButcherTableau, DenseOutput, Event, Index1Options, Index1Rk,
    NoObserver, ProjectionSettings, RunConfig, State,
};
use mbd::tangent::{TangentOptions, TangentRk};
use std::f64::consts::PI;

const THETA0: f64 = 1.2;

fn agm(mut a: f64, mut b: f64) -> f64 {
    for _ in 0..60 {
        let (an, bn) = (0.5 * (a + b), (a * b).sqrt());
        a = an;
        b = bn;
        if (a - b).abs() <= 1e-17 * a {
            break;
        }
    }
    0.5 * (a + b)
}

/// The pendulum and its exact period `2 pi sqrt(I_pivot / (m g d)) / AGM(1, cos(theta0/2))`,
/// with `m`, the centroidal inertia and the pivot distance `d` read from the model.
fn pendulum() -> (System, State, f64) {
    let g = 9.81;
    let sys = models::pendulum(1.3, 0.8, THETA0, g).unwrap();
    let s = State::consistent(&sys, 0.0).unwrap();
    let body = &sys.bodies()[0];
    let d = (s.q[0] * s.q[0] + s.q[1] * s.q[1]).sqrt();
    assert!((d - 0.4).abs() < 1e-12, "pivot distance {d}");
    // the initial angle from the downward vertical is THETA0
    assert!((s.q[2] + PI / 2.0 - THETA0).abs() < 1e-12);
    let ip = body.inertia + body.mass * d * d;
    let t = 2.0 * PI * (ip / (body.mass * g * d)).sqrt() / agm(1.0, (THETA0 / 2.0).cos());
    (sys, s, t)
}

/// The period from the first and last rising crossings of `x` (the centre's horizontal
/// position) recorded by `dense`.
fn period_from<O>(dense: &DenseOutput<O>) -> (f64, usize) {
    let hits = dense.events();
    assert!(hits.len() >= 3, "{} crossings", hits.len());
    assert!(hits.iter().all(|h| h.rising && h.q[0].abs() < 1e-9));
    let n = hits.len() - 1;
    ((hits[n].t - hits[0].t) / n as f64, hits.len())
}

#[test]
fn pendulum_period_from_events_adaptive_tangent_dopri5() {
    let (sys, mut s, exact) = pendulum();
    let mut integ =
        TangentRk::new(&sys, ButcherTableau::dopri5(), TangentOptions::default()).unwrap();
    let mut dense =
        DenseOutput::new(&sys, NoObserver).with_event(Event::new("x = 0", |_, q, _| q[0]).rising());
    let cfg = AdaptiveConfig::new(4.5 * exact, 1e-12);
    let stats = run_adaptive(&mut integ, &sys, &mut s, cfg, &mut dense).unwrap();
    let (period, n) = period_from(&dense);
    let rel = (period - exact).abs() / exact;
    println!(
        "tangent DOPRI5 tol 1e-12 via run_adaptive: T = {period:.15} exact {exact:.15} rel {rel:.2e} \
         ({n} crossings, {} steps, {} rejected)",
        stats.steps, stats.rejected_steps
    );
    assert!(stats.steps > 10 && (s.t - 4.5 * exact).abs() < 1e-12);
    assert!(rel < 1e-10, "relative period error {rel:e}");
}

#[test]
fn pendulum_period_from_events_adaptive_index1_dopri5() {
    let (sys, mut s, exact) = pendulum();
    let opts = Index1Options {
        projection: Some(ProjectionSettings::default()),
        ..Default::default()
    };
    let mut integ = Index1Rk::new(&sys, ButcherTableau::dopri5(), opts).unwrap();
    let mut dense =
        DenseOutput::new(&sys, NoObserver).with_event(Event::new("x = 0", |_, q, _| q[0]).rising());
    let stats = run_adaptive(
        &mut integ,
        &sys,
        &mut s,
        AdaptiveConfig::new(4.5 * exact, 1e-12),
        &mut dense,
    )
    .unwrap();
    let (period, n) = period_from(&dense);
    let rel = (period - exact).abs() / exact;
    println!(
        "index-1 DOPRI5 + projection tol 1e-12: rel {rel:.2e} ({n} crossings, {} steps, {} rejected)",
        stats.steps, stats.rejected_steps
    );
    assert!(rel < 1e-10, "relative period error {rel:e}");
}

/// A terminal event stops the run in the step of the crossing, and interpolated output times
/// agree with a run that lands on them.
#[test]
fn terminal_event_and_output_times() {
    let (sys, s0, exact) = pendulum();
    let opts = Index1Options {
        projection: Some(ProjectionSettings::default()),
        ..Default::default()
    };
    let mut integ = Index1Rk::new(&sys, ButcherTableau::dopri5(), opts.clone()).unwrap();
    let h = 1e-3;
    let mut s = s0.clone();
    let mut dense = DenseOutput::new(&sys, NoObserver)
        .at_times([0.1234, 0.5, 0.6])
        .unwrap()
        .with_event(Event::new("x = 0", |_, q, _| q[0]).terminal());
    let stats = run(
        &mut integ,
        &sys,
        &mut s,
        RunConfig::new(10.0, h),
        &mut dense,
    )
    .unwrap();
    // the first crossing is a quarter period after release
    let hit = &dense.events()[0];
    let quarter = (hit.t - exact / 4.0).abs();
    println!(
        "terminal event: t = {} (T/4 = {}), error {quarter:.2e}",
        hit.t,
        exact / 4.0
    );
    assert!(stats.stopped_early && dense.events().len() == 1 && !hit.rising);
    assert!(quarter < 1e-10, "quarter period off by {quarter:e}");
    assert!(s.t >= hit.t && s.t - hit.t <= h * (1.0 + 1e-9));
    // output times before the event only (0.5 and 0.6 lie after T/4 = 0.47...)
    assert!(exact / 4.0 < 0.5);
    assert_eq!(dense.samples().t, vec![0.1234]);
    // compare with a run that lands on 0.1234
    let mut s2 = s0.clone();
    let mut integ2 = Index1Rk::new(&sys, ButcherTableau::dopri5(), opts).unwrap();
    run(
        &mut integ2,
        &sys,
        &mut s2,
        RunConfig::new(0.1234, 1e-4),
        &mut NoObserver,
    )
    .unwrap();
    let dq = (0..3)
        .map(|i| (dense.samples().q[0][i] - s2.q[i]).abs())
        .fold(0.0, f64::max);
    let dv = (0..3)
        .map(|i| (dense.samples().v[0][i] - s2.v[i]).abs())
        .fold(0.0, f64::max);
    println!("output time 0.1234: |dq| {dq:.2e} |dv| {dv:.2e}");
    assert!(dq < 1e-12 && dv < 1e-10, "dq {dq:e} dv {dv:e}");
}
