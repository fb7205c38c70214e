//! Dense output and event location: the pendulum's period from zero crossings against the
//! exact elliptic-integral period, the interpolation order at mid-step times, `at_times`
//! samples, terminal events and the error cases.

use mbd_model::models;
use mbd_solve::{
    run, run_adaptive, AdaptiveConfig, ButcherTableau, DenseOutput, Event, Index1Options, Index1Rk,
    NoObserver, Observer, RunConfig, SolveError, State,
};
use std::f64::consts::{FRAC_PI_2, PI};

const G: f64 = 9.81;

/// The exact period of a uniform rod of length `l` pivoted at one end, released at rest at
/// `angle0` from the downward vertical: `T = 4 K(sin(angle0/2)) / omega0` with
/// `omega0^2 = 3 g / (2 l)` and `K(k) = pi / (2 AGM(1, sqrt(1 - k^2)))`.
fn exact_period(l: f64, angle0: f64) -> f64 {
    let k = (0.5 * angle0).sin();
    let (mut a, mut b) = (1.0f64, (1.0 - k * k).sqrt());
    // quadratic convergence: 8 iterations reach round-off for any k < 1 used here
    for _ in 0..8 {
        let an = 0.5 * (a + b);
        b = (a * b).sqrt();
        a = an;
    }
    let kk = PI / (2.0 * a);
    4.0 * kk / (1.5 * G / l).sqrt()
}

fn dopri5(sys: &mbd_model::System) -> Index1Rk {
    Index1Rk::new(sys, ButcherTableau::dopri5(), Index1Options::default()).unwrap()
}

/// The angle from the downward vertical is `q[2] + pi/2`; its falling zero crossings are one
/// period apart, as are the falling crossings of the angular velocity (at the left extreme).
#[test]
fn pendulum_period_from_zero_crossings_matches_elliptic_integral() {
    for (l, angle0) in [(1.0, 1.0), (0.7, 2.5)] {
        let sys = models::pendulum(1.0, l, angle0, G).unwrap();
        let exact = exact_period(l, angle0);
        let mut state = State::consistent(&sys, 0.0).unwrap();
        let mut rk = dopri5(&sys);
        let mut dense = DenseOutput::new(&sys, NoObserver)
            .with_event(Event::new("through bottom", |_t, q, _v| q[2] + FRAC_PI_2).falling())
            .with_event(Event::new("angular velocity", |_t, _q, v| v[2]).falling());
        let t_end = 3.2 * exact;
        let cfg = AdaptiveConfig::new(t_end, 1e-12).without_drift_guard();
        let stats = run_adaptive(&mut rk, &sys, &mut state, cfg, &mut dense).unwrap();
        let hits = dense.events();
        for ev in 0..2 {
            let t: Vec<f64> = hits.iter().filter(|h| h.event == ev).map(|h| h.t).collect();
            assert_eq!(t.len(), 3, "event {ev}: {t:?}");
            for w in t.windows(2) {
                let rel = ((w[1] - w[0]) - exact).abs() / exact;
                println!(
                    "l {l}, angle0 {angle0}: event {ev} period {:.15} exact {exact:.15} rel {rel:.2e} \
                     ({} steps)",
                    w[1] - w[0],
                    stats.steps
                );
                assert!(rel < 1e-10, "event {ev}: relative period error {rel:e}");
            }
            // the first angle crossing is a quarter period after the release
            if ev == 0 {
                let rel = (t[0] - 0.25 * exact).abs() / exact;
                assert!(rel < 1e-10, "quarter period: {rel:e}");
            }
        }
        // the interpolated state at a hit satisfies the event to round-off
        for h in hits.iter().filter(|h| h.event == 0) {
            assert!((h.q[2] + FRAC_PI_2).abs() < 1e-9, "{h:?}");
            assert!(!h.rising && h.v[2] < 0.0);
        }
    }
}

/// One DOPRI5 step of size `h` from the release; returns the interpolation errors of `q` and
/// `v` at mid-step against a fine reference integration.
fn midstep_error(h: f64) -> (f64, f64) {
    let sys = models::pendulum(1.0, 1.0, 1.2, G).unwrap();
    let s0 = State::consistent(&sys, 0.0).unwrap();
    let mut rk = dopri5(&sys);
    let mut s = s0.clone();
    let mut dense = DenseOutput::new(&sys, NoObserver)
        .at_times([0.5 * h])
        .unwrap();
    run(
        &mut rk,
        &sys,
        &mut s,
        RunConfig::new(h, h).without_drift_guard(),
        &mut dense,
    )
    .unwrap();
    let mut reference = s0;
    run(
        &mut rk,
        &sys,
        &mut reference,
        RunConfig::new(0.5 * h, h / 2000.0).without_drift_guard(),
        &mut NoObserver,
    )
    .unwrap();
    let samples = dense.samples();
    assert_eq!(samples.len(), 1);
    let maxdiff = |a: &[f64], b: &[f64]| {
        a.iter()
            .zip(b)
            .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
    };
    let eq = maxdiff(&samples.q[0], reference.q.as_slice());
    let ev = maxdiff(&samples.v[0], reference.v.as_slice());
    (eq, ev)
}

fn slope(x: &[f64], y: &[f64]) -> f64 {
    let lx: Vec<f64> = x.iter().map(|v| v.ln()).collect();
    let ly: Vec<f64> = y.iter().map(|v| v.ln()).collect();
    let n = lx.len() as f64;
    let (mx, my) = (lx.iter().sum::<f64>() / n, ly.iter().sum::<f64>() / n);
    let num: f64 = lx.iter().zip(&ly).map(|(a, b)| (a - mx) * (b - my)).sum();
    let den: f64 = lx.iter().map(|a| (a - mx).powi(2)).sum();
    num / den
}

/// The quintic Hermite interpolant with the index-1 accelerations: `q` to `O(h^6)`, `v` to
/// `O(h^5)` at mid-step.
#[test]
fn interpolation_error_at_mid_step_has_the_expected_order() {
    let hs = [0.4, 0.2, 0.1, 0.05];
    let (mut eq, mut ev) = (vec![], vec![]);
    for &h in &hs {
        let (a, b) = midstep_error(h);
        println!("h {h}: q error {a:.3e}, v error {b:.3e}");
        eq.push(a);
        ev.push(b);
    }
    let (sq, sv) = (slope(&hs, &eq), slope(&hs, &ev));
    println!("slopes: q {sq:.2}, v {sv:.2}");
    assert!((5.5..6.8).contains(&sq), "q slope {sq}");
    assert!((4.5..5.8).contains(&sv), "v slope {sv}");
}

/// `at_times` samples agree with fixed-step states at the same times, including the ends.
#[test]
fn at_times_samples_match_step_states() {
    let sys = models::pendulum(1.0, 1.0, 0.8, G).unwrap();
    let s0 = State::consistent(&sys, 0.0).unwrap();
    let times = [0.0, 0.123, 0.5, 0.5, 0.77, 1.0, 1.5];
    let mut rk = dopri5(&sys);
    let mut s = s0.clone();
    let mut dense = DenseOutput::new(&sys, NoObserver).at_times(times).unwrap();
    let cfg = AdaptiveConfig::new(1.0, 1e-11).without_drift_guard();
    run_adaptive(&mut rk, &sys, &mut s, cfg, &mut dense).unwrap();
    let smp = dense.samples();
    // 1.5 lies after the end of the run
    assert_eq!(smp.t, times[..6].to_vec());
    for (k, &t) in smp.t.iter().enumerate() {
        let mut r = s0.clone();
        if t > 0.0 {
            let h = t / (t / 1e-3).ceil();
            run(
                &mut rk,
                &sys,
                &mut r,
                RunConfig::new(t, h).without_drift_guard(),
                &mut NoObserver,
            )
            .unwrap();
        }
        let e = smp.q[k]
            .iter()
            .zip(r.q.iter())
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        assert!(e < 1e-9, "t {t}: {e:e}");
    }
    // the last step's interpolant reproduces the end state
    let (mut q, mut v) = (vec![0.0; 3], vec![0.0; 3]);
    dense.interpolate(1.0, &mut q, &mut v).unwrap();
    assert_eq!(q, s.q.as_slice());
    assert_eq!(v, s.v.as_slice());
}

/// A terminal event stops the run after the step in which it occurred.
#[test]
fn terminal_event_stops_the_run() {
    let sys = models::pendulum(1.0, 1.0, 0.5, G).unwrap();
    let mut s = State::consistent(&sys, 0.0).unwrap();
    let mut rk = dopri5(&sys);
    let mut dense = DenseOutput::new(&sys, NoObserver)
        .at_times([0.1, 0.2, 5.0])
        .unwrap()
        .with_event(Event::new("bottom", |_t, q, _v| q[2] + FRAC_PI_2).terminal());
    let cfg = AdaptiveConfig::new(10.0, 1e-10);
    let st = run_adaptive(&mut rk, &sys, &mut s, cfg, &mut dense).unwrap();
    assert!(st.stopped_early);
    let hits = dense.events();
    assert_eq!(hits.len(), 1);
    let quarter = 0.25 * exact_period(1.0, 0.5);
    assert!(
        (hits[0].t - quarter).abs() < 1e-9,
        "{} vs {quarter}",
        hits[0].t
    );
    assert!(s.t >= hits[0].t && s.t < 1.0, "stopped at {}", s.t);
    // samples after the event are not recorded
    assert_eq!(dense.samples().t, vec![0.1, 0.2]);
}

#[test]
fn bad_inputs_are_errors() {
    let sys = models::pendulum(1.0, 1.0, 0.5, G).unwrap();
    for tol in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        let d = DenseOutput::new(&sys, NoObserver).with_time_tol(tol);
        assert!(
            matches!(
                d,
                Err(SolveError::InvalidParameter {
                    parameter: "time_tol",
                    ..
                })
            ),
            "{tol}"
        );
    }
    let d = DenseOutput::new(&sys, NoObserver).at_times([0.3, f64::INFINITY]);
    assert!(matches!(d, Err(SolveError::InvalidParameter { .. })));
    let d = DenseOutput::new(&sys, NoObserver).at_times([0.3, 0.2]);
    assert!(matches!(d, Err(SolveError::InvalidParameter { value, .. }) if value == 0.2));

    // interpolation before any step, outside the last step, with wrong lengths
    let mut dense = DenseOutput::new(&sys, NoObserver);
    let (mut q, mut v) = (vec![0.0; 3], vec![0.0; 3]);
    assert!(matches!(
        dense.interpolate(0.0, &mut q, &mut v),
        Err(SolveError::InvalidInterval { .. })
    ));
    let mut s = State::consistent(&sys, 0.0).unwrap();
    let mut rk = dopri5(&sys);
    run(&mut rk, &sys, &mut s, RunConfig::new(0.1, 0.05), &mut dense).unwrap();
    assert!(matches!(
        dense.interpolate(0.01, &mut q, &mut v),
        Err(SolveError::InvalidInterval { .. })
    ));
    let mut short = vec![0.0; 2];
    assert!(matches!(
        dense.interpolate(0.07, &mut short, &mut v),
        Err(SolveError::Dimension { .. })
    ));
    assert!(dense.interpolate(0.07, &mut q, &mut v).is_ok());

    // a state of another system
    let other = models::manipulator().unwrap();
    let so = State::consistent(&other, 0.0).unwrap();
    assert!(matches!(
        dense.observe(&other, &so, 3),
        Err(SolveError::Dimension { .. })
    ));

    // an event function returning NaN
    let mut dense =
        DenseOutput::new(&sys, NoObserver).with_event(Event::new("nan", |t, _q, _v| {
            if t > 0.05 {
                f64::NAN
            } else {
                1.0
            }
        }));
    let mut s = State::consistent(&sys, 0.0).unwrap();
    let e = run(&mut rk, &sys, &mut s, RunConfig::new(0.2, 0.05), &mut dense);
    assert!(matches!(e, Err(SolveError::NonFinite { .. })), "{e:?}");
}

/// Above the sparse threshold the acceleration solve takes the sparse path (as the solvers
/// do), and its interpolant agrees with the dense path's.
#[test]
fn sparse_and_dense_interpolation_agree_on_a_long_chain() {
    let sys = models::n_link_chain(60).unwrap();
    assert!(sys.n_constraints() > mbd_solve::SPARSE_THRESHOLD);
    let times: Vec<f64> = (1..=7).map(|k| 0.0137 * k as f64).collect();
    let mut results = vec![];
    for linear in [
        mbd_solve::LinearSolver::Auto,
        mbd_solve::LinearSolver::Dense,
    ] {
        let mut s = State::consistent(&sys, 0.0).unwrap();
        let mut rk =
            Index1Rk::new(&sys, ButcherTableau::dopri5(), Index1Options::default()).unwrap();
        let mut dense = DenseOutput::new(&sys, NoObserver)
            .with_linear(&sys, linear)
            .unwrap()
            .at_times(times.clone())
            .unwrap();
        assert_eq!(dense.is_sparse(), linear == mbd_solve::LinearSolver::Auto);
        run(
            &mut rk,
            &sys,
            &mut s,
            RunConfig::new(0.1, 0.025).without_drift_guard(),
            &mut dense,
        )
        .unwrap();
        assert_eq!(dense.samples().len(), times.len());
        results.push(dense.samples().clone());
    }
    let mut worst = 0.0f64;
    for k in 0..times.len() {
        for (a, b) in results[0].q[k].iter().zip(&results[1].q[k]) {
            worst = worst.max((a - b).abs());
        }
        for (a, b) in results[0].v[k].iter().zip(&results[1].v[k]) {
            worst = worst.max((a - b).abs());
        }
    }
    println!("sparse vs dense interpolation: max difference {worst:.2e}");
    assert!(worst < 1e-10, "{worst:e}");
    // a system with other coordinates is refused
    let small = models::pendulum(1.0, 1.0, 0.5, G).unwrap();
    assert!(matches!(
        DenseOutput::new(&sys, NoObserver).with_linear(&small, mbd_solve::LinearSolver::Dense),
        Err(SolveError::Dimension { .. })
    ));
}
