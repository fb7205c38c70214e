//! `run_adaptive` with the index-1 DOPRI5: the error follows the tolerance, the run lands on
//! `t_end`, and tableaus without an embedded pair are refused.

use mbd_model::models;
use mbd_solve::{
    run, run_adaptive, AdaptiveConfig, ButcherTableau, Index1Options, Index1Rk, NoObserver,
    Recorder, RunConfig, SolveError, State,
};

#[test]
fn adaptive_dopri5_error_follows_tolerance() {
    let sys = models::manipulator().unwrap();
    let s0 = State::consistent(&sys, 0.0).unwrap();
    // reference: fixed-step DOPRI5 at a small step
    let mut reference = s0.clone();
    let mut rk = Index1Rk::new(&sys, ButcherTableau::dopri5(), Index1Options::default()).unwrap();
    run(
        &mut rk,
        &sys,
        &mut reference,
        RunConfig::new(2.0, 2e-4),
        &mut NoObserver,
    )
    .unwrap();
    let mut errs = vec![];
    for tol in [1e-6, 1e-9] {
        let mut s = s0.clone();
        let mut rec = Recorder::new();
        let st = run_adaptive(
            &mut rk,
            &sys,
            &mut s,
            AdaptiveConfig::new(2.0, tol),
            &mut rec,
        )
        .unwrap();
        let err = (s.q.clone() - reference.q.clone()).amax();
        println!(
            "tol {tol:e}: error {err:.2e}, {} steps, {} rejected",
            st.steps, st.rejected_steps
        );
        assert_eq!(s.t, 2.0);
        assert_eq!(rec.len(), st.steps + 1);
        assert!(err < 1e3 * tol, "tol {tol:e}: error {err:e}");
        errs.push((err, st.steps));
    }
    assert!(errs[1].0 < errs[0].0 && errs[1].1 > errs[0].1);
}

#[test]
fn adaptive_needs_an_embedded_pair() {
    let sys = models::pendulum(1.0, 1.0, 0.3, 9.81).unwrap();
    let mut s = State::consistent(&sys, 0.0).unwrap();
    let mut rk = Index1Rk::new(&sys, ButcherTableau::rk4(), Index1Options::default()).unwrap();
    let e = run_adaptive(
        &mut rk,
        &sys,
        &mut s,
        AdaptiveConfig::new(1.0, 1e-8),
        &mut NoObserver,
    )
    .unwrap_err();
    assert!(matches!(e, SolveError::Unsupported(_)), "{e}");
    let mut rk = Index1Rk::new(&sys, ButcherTableau::dopri5(), Index1Options::default()).unwrap();
    let e = run_adaptive(
        &mut rk,
        &sys,
        &mut s,
        AdaptiveConfig::new(-1.0, 1e-8),
        &mut NoObserver,
    )
    .unwrap_err();
    assert!(matches!(e, SolveError::InvalidInterval { .. }), "{e}");
}

/// A step the controller shrinks below `h_min` is `StepSizeTooSmall` naming the time and the
/// step; running out of attempts is `TooManyAttempts`.
#[test]
fn adaptive_failures_have_their_own_errors() {
    let sys = models::pendulum(1.0, 1.0, 0.5, 9.81).unwrap();
    let s0 = State::consistent(&sys, 0.0).unwrap();
    let mut rk = Index1Rk::new(&sys, ButcherTableau::dopri5(), Index1Options::default()).unwrap();
    let mut cfg = AdaptiveConfig::new(1.0, 1e-14).with_h0(0.5);
    cfg.controller.h_min = 1e-2;
    let mut s = s0.clone();
    let e = run_adaptive(&mut rk, &sys, &mut s, cfg, &mut NoObserver).unwrap_err();
    match &e {
        SolveError::StepSizeTooSmall { t, h, h_min } => {
            assert_eq!(*t, 0.0);
            assert!(*h < 1e-2 && *h_min == 1e-2, "{e}");
        }
        other => panic!("expected StepSizeTooSmall, got {other:?}"),
    }
    assert!(e.to_string().contains("t = 0") && e.to_string().contains("h_min"));

    let mut cfg = AdaptiveConfig::new(1.0, 1e-12);
    cfg.max_steps = 5;
    let mut s = s0.clone();
    let e = run_adaptive(&mut rk, &sys, &mut s, cfg, &mut NoObserver).unwrap_err();
    assert!(
        matches!(e, SolveError::TooManyAttempts { attempts: 5, t } if t > 0.0 && t < 1.0),
        "{e:?}"
    );
    assert!(e.to_string().contains("max_steps"));
}
