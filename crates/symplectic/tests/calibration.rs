//! gamma_opt by the secant method on dW(gamma) against an independent reference
//! (mbd_solve::reference_trajectory: DOPRI5 + projection at h/32), with paper A's measures from
//! mbd-analysis (trajectory_errors) on runs through the public run loop.
use mbd_analysis::{trajectory_errors, Trajectory, TrajectoryErrors};
use mbd_model::{models, System};
use mbd_solve::{reference_trajectory, run, ButcherTableau, Recorder, RunConfig, State};
use mbd_symplectic::{
    calibrate_gamma, CalibrationSettings, Galerkin, SymplecticError, SymplecticOptions,
};

/// Paper A's measures of one run of the scheme against the reference.
fn measure(
    sys: &System,
    s0: &State,
    h: f64,
    n: usize,
    reference: &Trajectory,
    opts: SymplecticOptions,
) -> Result<TrajectoryErrors, SymplecticError> {
    let mut scheme = Galerkin::new(sys, opts)?;
    let mut st = s0.clone();
    let mut rec = Recorder::new();
    let cfg = RunConfig::new(s0.t + n as f64 * h, h).without_drift_guard();
    run(&mut scheme, sys, &mut st, cfg, &mut rec)?;
    trajectory_errors(sys, &Trajectory::from(rec), reference)
        .map_err(|e| SymplecticError::Solve(mbd_solve::SolveError::Unsupported(e.to_string())))
}

#[test]
fn secant_calibration_on_the_double_pendulum() {
    let sys = models::paper_a_double_pendulum().unwrap();
    let s0 = State::consistent(&sys, 0.0).unwrap();
    let (h, n) = (0.04, 100);
    let reference: Trajectory = reference_trajectory(&sys, &s0, h, n, 32, ButcherTableau::dopri5())
        .unwrap()
        .into();
    for s in [1usize, 2] {
        let cal = calibrate_gamma(CalibrationSettings::default(), |g| {
            let e = measure(
                &sys,
                &s0,
                h,
                n,
                &reference,
                SymplecticOptions::new(s).with_gamma(g),
            )?;
            Ok((e.d_w, e))
        })
        .unwrap();
        let dw0 = cal.history[0].1;
        let dw_opt = cal.measures.d_w;
        assert_eq!(cal.history[0].0, 0.0);
        assert_eq!(cal.history[1].0, 1.0);
        assert!(dw_opt.abs() <= 1e-6 * dw0.abs(), "s={s}: {dw_opt} vs {dw0}");
        let e0 = measure(&sys, &s0, h, n, &reference, SymplecticOptions::new(s)).unwrap();
        assert_eq!(e0.d_w, dw0, "the first secant point is the plain scheme");
        assert_eq!(e0.samples, n + 1);
        // the calibrated scheme is more accurate than the plain one on the calibration run
        assert!(
            cal.measures.e_abs_dx < e0.e_abs_dx,
            "s={s}: E|dx| {} -> {}",
            e0.e_abs_dx,
            cal.measures.e_abs_dx
        );
    }
}

#[test]
fn secant_failures_are_reported_with_their_history() {
    // a flat measure: the secant cannot move
    let r = calibrate_gamma(CalibrationSettings::default(), |_| Ok((1.0, ())));
    match r {
        Err(SymplecticError::Calibration { history, .. }) => assert_eq!(history.len(), 2),
        other => panic!("expected a calibration error, got {other:?}"),
    }
    // equal starting points are a bad parameter
    let settings = CalibrationSettings {
        start: (1.0, 1.0),
        ..Default::default()
    };
    assert!(calibrate_gamma(settings, |g| Ok((g, ()))).is_err());
    // the measure's own errors pass through
    let r: Result<_, SymplecticError> = calibrate_gamma(CalibrationSettings::default(), |_| {
        Err::<(f64, ()), _>(mbd_solve::SolveError::InvalidStep { h: -1.0 }.into())
    });
    assert!(matches!(r, Err(SymplecticError::Solve(_))), "{r:?}");
}
