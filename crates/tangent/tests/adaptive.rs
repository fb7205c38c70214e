//! Adaptive stepping with the embedded estimate (DOPRI5 5(4), Bogacki-Shampine 3(2)) in chart
//! coordinates: the error against a reference follows the requested tolerance, constraints stay
//! at the Newton tolerance at every accepted step, and chart failures are rejections.

mod common;

use common::{state_error, ResidualWatch};
use mbd_model::models;
use mbd_model::System;
use mbd_solve::{
    reference_trajectory, run_adaptive, AdaptiveConfig, AdaptiveIntegrator, ButcherTableau,
    NoObserver, Observer, RunStats, SolveError, State,
};
use mbd_tangent::{TangentOptions, TangentRk};

/// An adaptive run through the one run loop without the drift guard, with the solver's own
/// counters after it.
fn adaptive<O: Observer>(
    rk: &mut TangentRk,
    sys: &System,
    s: &mut State,
    cfg: AdaptiveConfig,
    obs: &mut O,
) -> Result<(RunStats, usize), SolveError> {
    let st = run_adaptive(rk, sys, s, cfg.without_drift_guard(), obs)?;
    Ok((st, rk.stats().chart_failures))
}

#[test]
fn dopri5_error_follows_tolerance_on_manipulator() {
    let sys = models::manipulator().expect("model");
    let s0 = State::consistent(&sys, 0.0).expect("state");
    let r = reference_trajectory(&sys, &s0, 1.0, 1, 8000, ButcherTableau::dopri5()).expect("ref");
    let mut errs = vec![];
    let mut steps = vec![];
    for tol in [1e-5, 1e-7, 1e-9, 1e-11] {
        let mut s = s0.clone();
        let mut dp = TangentRk::dopri5(&sys).expect("solver");
        let mut watch = ResidualWatch::default();
        let (st, chart) = adaptive(
            &mut dp,
            &sys,
            &mut s,
            AdaptiveConfig::new(1.0, tol),
            &mut watch,
        )
        .expect("adaptive run");
        assert_eq!(s.t, 1.0);
        assert_eq!(watch.samples, st.steps + 1);
        assert!(watch.max_phi <= 1e-12 && watch.max_phidot <= 1e-12);
        assert!(st.max_residual <= 1e-12);
        assert!(st.min_step > 0.0 && st.min_step <= st.max_step);
        let e = state_error(&s, &r.q[1], &r.v[1]);
        println!(
            "tol {tol:e}: error {e:e}, accepted {}, rejected {} (chart {chart}), h in [{:e}, {:e}]",
            st.steps, st.rejected_steps, st.min_step, st.max_step
        );
        errs.push(e);
        steps.push(st.steps);
    }
    for w in errs.windows(2) {
        // 100x tighter tolerance: at least 10x smaller error
        assert!(w[1] < 0.1 * w[0], "{errs:?}");
    }
    for (e, tol) in errs.iter().zip([1e-5, 1e-7, 1e-9, 1e-11]) {
        assert!(*e < 1e3 * tol, "error {e} for tolerance {tol}");
    }
    assert!(steps.windows(2).all(|w| w[1] > w[0]), "{steps:?}");
}

#[test]
fn dopri5_error_and_rejections_stay_in_bounds_from_loose_to_tight_tolerances() {
    // manipulator to t = 2 s against a DOPRI5 reference (32000 steps, projection): the error at
    // the end stays within 100 tol and fewer than 20% of the attempts are rejected (error test
    // or chart failure), at loose tolerances too; the first step follows the tolerance
    let sys = models::manipulator().expect("model");
    let s0 = State::consistent(&sys, 0.0).expect("state");
    let r = reference_trajectory(&sys, &s0, 2.0, 1, 32_000, ButcherTableau::dopri5()).expect("ref");
    let mut h0 = vec![];
    for tol in [1e-3, 1e-6, 1e-9, 1e-12] {
        let mut s = s0.clone();
        let mut dp = TangentRk::dopri5(&sys).expect("solver");
        let cfg = AdaptiveConfig::new(2.0, tol);
        let (first, work) = dp
            .initial_step(&sys, &s, 2.0, &cfg)
            .expect("estimate")
            .expect("the tangent solver estimates its first step");
        assert_eq!(work.rhs_evals, 2);
        let (st, chart) =
            adaptive(&mut dp, &sys, &mut s, cfg, &mut NoObserver).expect("adaptive run");
        let e = state_error(&s, &r.q[1], &r.v[1]);
        let attempts = st.steps + st.rejected_steps;
        let rate = st.rejected_steps as f64 / attempts as f64;
        println!(
            "tol {tol:.0e}: error {e:.2e} ({:.1} tol), {} accepted, {} rejected ({chart} by the \
             chart) ({:.1}%), first step {first:.2e}",
            e / tol,
            st.steps,
            st.rejected_steps,
            100.0 * rate,
        );
        assert!(e / tol <= 100.0, "tol {tol}: error {e}");
        assert!(rate < 0.2, "tol {tol}: {st:?}");
        assert!(st.max_residual <= 1e-12);
        h0.push(first);
    }
    // the first step follows the tolerance (about tol^(1/5))
    assert!(h0.windows(2).all(|w| w[1] < 0.5 * w[0]), "{h0:?}");
}

#[test]
fn bogacki_shampine_adaptive_and_tableau_without_estimate_is_an_error() {
    let sys = models::slider_crank().expect("model");
    let s0 = State::consistent(&sys, 0.0).expect("state");
    let r = reference_trajectory(&sys, &s0, 0.5, 1, 4000, ButcherTableau::dopri5()).expect("ref");
    let mut s = s0.clone();
    let mut bs = TangentRk::new(
        &sys,
        ButcherTableau::bogacki_shampine(),
        TangentOptions::default(),
    )
    .expect("solver");
    let (st, _) = adaptive(
        &mut bs,
        &sys,
        &mut s,
        AdaptiveConfig::new(0.5, 1e-8),
        &mut NoObserver,
    )
    .expect("run");
    let e = state_error(&s, &r.q[1], &r.v[1]);
    assert!(e < 1e-5, "error {e}");
    assert!(st.steps > 10);

    let mut rk4 = TangentRk::rk4(&sys).expect("solver");
    assert!(mbd_solve::Integrator::as_adaptive(&mut rk4).is_none());
    let mut s = s0.clone();
    let err = adaptive(
        &mut rk4,
        &sys,
        &mut s,
        AdaptiveConfig::new(0.5, 1e-6),
        &mut NoObserver,
    )
    .unwrap_err();
    assert!(matches!(err, SolveError::Unsupported(_)), "{err}");
    assert_eq!(s, s0, "the state is untouched on error");
}

#[test]
fn too_large_first_step_is_rejected_not_fatal() {
    let sys = models::manipulator().expect("model");
    let mut s = State::consistent(&sys, 0.0).expect("state");
    let mut dp = TangentRk::dopri5(&sys).expect("solver");
    let cfg = AdaptiveConfig::new(2.0, 1e-8).with_h0(2.0);
    let (st, chart) = adaptive(&mut dp, &sys, &mut s, cfg, &mut NoObserver).expect("run");
    println!("{st:?}");
    assert!(chart > 0);
    // chart failures shrink the step by 4: from 2 s to a step the chart can take in a few
    assert!(chart <= 4, "{st:?}");
    assert_eq!(s.t, 2.0);
    // with one chart failure allowed in a row, the second is an error naming the count
    let mut s = State::consistent(&sys, 0.0).expect("state");
    let options = TangentOptions {
        max_chart_failures: 1,
        chart_shrink: 0.9,
        ..Default::default()
    };
    let mut dp = TangentRk::new(&sys, ButcherTableau::dopri5(), options).expect("solver");
    let e = adaptive(&mut dp, &sys, &mut s, cfg, &mut NoObserver).unwrap_err();
    assert!(
        matches!(e, SolveError::RepeatedFailure { failures: 2, .. }),
        "{e}"
    );
}

#[test]
fn bad_adaptive_settings_are_errors() {
    let sys = models::pendulum(1.0, 1.0, 0.5, 9.81).expect("model");
    let s0 = State::consistent(&sys, 0.0).expect("state");
    let mut dp = TangentRk::dopri5(&sys).expect("solver");
    let ctrl = |f: &dyn Fn(&mut mbd_solve::StepController)| {
        let mut a = AdaptiveConfig::new(1.0, 1e-6);
        f(&mut a.controller);
        a
    };
    let base = AdaptiveConfig::new(1.0, 1e-6);
    let bad = [
        ctrl(&|c| c.atol = -1.0),
        ctrl(&|c| c.rtol = f64::NAN),
        ctrl(&|c| {
            c.atol = 0.0;
            c.rtol = 0.0
        }),
        ctrl(&|c| c.h_min = 0.0),
        ctrl(&|c| c.fac_max = 0.5),
        AdaptiveConfig {
            h0: Some(-1.0),
            ..base
        },
        AdaptiveConfig { h_max: 0.0, ..base },
        AdaptiveConfig {
            max_steps: 0,
            ..base
        },
        AdaptiveConfig {
            pi_beta: Some(-0.01),
            ..base
        },
        // above 1 / (1.75 (q+1)) = 0.114 for DOPRI5's embedded order 4
        AdaptiveConfig {
            pi_beta: Some(0.12),
            ..base
        },
        AdaptiveConfig {
            pi_beta: Some(f64::NAN),
            ..base
        },
    ];
    for a in &bad {
        let mut s = s0.clone();
        let e = adaptive(&mut dp, &sys, &mut s, *a, &mut NoObserver);
        assert!(
            matches!(e, Err(SolveError::InvalidParameter { .. })),
            "{a:?}: {e:?}"
        );
    }
    // the chart-failure rule's settings are the solver's options
    for o in [
        TangentOptions {
            chart_shrink: 1.0,
            ..Default::default()
        },
        TangentOptions {
            chart_shrink: 0.0,
            ..Default::default()
        },
        TangentOptions {
            max_chart_failures: 0,
            ..Default::default()
        },
    ] {
        let e = TangentRk::new(&sys, ButcherTableau::dopri5(), o);
        assert!(
            matches!(e, Err(SolveError::InvalidParameter { .. })),
            "{o:?}: {e:?}"
        );
    }
    // end time before the start, or not finite
    for t_end in [-1.0, 0.0, f64::NAN, f64::INFINITY] {
        let mut s = s0.clone();
        let e = adaptive(
            &mut dp,
            &sys,
            &mut s,
            AdaptiveConfig::new(t_end, 1e-6),
            &mut NoObserver,
        );
        assert!(
            matches!(e, Err(SolveError::InvalidInterval { .. })),
            "{e:?}"
        );
    }
    // step-count limit and h_min
    let mut a = AdaptiveConfig::new(1.0, 1e-12);
    a.max_steps = 5;
    let mut s = s0.clone();
    let e = adaptive(&mut dp, &sys, &mut s, a, &mut NoObserver);
    assert!(
        matches!(e, Err(SolveError::TooManyAttempts { attempts: 5, .. })),
        "{e:?}"
    );
    let mut a = AdaptiveConfig::new(1.0, 1e-14).with_h0(0.5);
    a.controller.h_min = 1e-2;
    let mut s = s0.clone();
    let e = adaptive(&mut dp, &sys, &mut s, a, &mut NoObserver);
    assert!(
        matches!(
            e,
            Err(SolveError::StepSizeTooSmall { h_min, .. }) if h_min == 1e-2
        ),
        "{e:?}"
    );
}
