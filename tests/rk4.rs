//! RK4 baseline: convergence order, drift, projection, bad inputs.

use mbd::analysis::{fit_order, MeasureObserver};
use mbd::model::{models, System};
use mbd::rk4::{Rk4, Rk4Options};
use mbd::solve::{run, Integrator, NoObserver, RunConfig, SolveError, State};

fn final_q(sys: &System, h: f64, t_end: f64, opts: Rk4Options) -> Vec<f64> {
    let mut s = State::consistent(sys, 0.0).unwrap();
    let mut rk = Rk4::new(sys, opts).unwrap();
    run(
        &mut rk,
        sys,
        &mut s,
        RunConfig::new(t_end, h),
        &mut NoObserver,
    )
    .unwrap();
    s.q.as_slice().to_vec()
}

fn measured_order(sys: &System, hs: [f64; 4]) -> f64 {
    let reference = final_q(sys, hs[3] / 64.0, 1.0, Rk4Options::plain());
    let errs: Vec<f64> = hs
        .iter()
        .map(|&h| {
            let q = final_q(sys, h, 1.0, Rk4Options::plain());
            q.iter()
                .zip(&reference)
                .fold(0.0f64, |a, (x, y)| a.max((x - y).abs()))
        })
        .collect();
    let fit = fit_order(&hs, &errs, 1e-13).unwrap();
    eprintln!(
        "errors {errs:?} local orders {:?} fitted {}",
        fit.local, fit.order
    );
    fit.order
}

#[test]
fn rk4_order_four_on_pendulum() {
    let sys = models::pendulum(1.0, 1.0, 1.0, 9.81).unwrap();
    let p = measured_order(&sys, [0.02, 0.01, 0.005, 0.0025]);
    assert!((p - 4.0).abs() <= 0.2, "order {p}");
}

#[test]
fn rk4_order_four_on_manipulator() {
    let sys = models::manipulator().unwrap();
    let p = measured_order(&sys, [0.01, 0.005, 0.0025, 0.00125]);
    assert!((p - 4.0).abs() <= 0.2, "order {p}");
}

fn manipulator_measures(opts: Rk4Options) -> mbd::analysis::RunMeasures {
    let sys = models::manipulator().unwrap();
    let mut s = State::consistent(&sys, 0.0).unwrap();
    let mut rk = Rk4::new(&sys, opts).unwrap();
    let mut obs = MeasureObserver::new(&sys, true);
    // the paper's drift measurement: the drift guard is off
    let cfg = RunConfig::new(20.0, 0.01).without_drift_guard();
    run(&mut rk, &sys, &mut s, cfg, &mut obs).unwrap();
    obs.measures()
}

#[test]
fn the_default_drift_guard_stops_plain_rk4_on_the_paper_setting_and_not_projected_rk4() {
    let sys = models::manipulator().unwrap();
    let mut s = State::consistent(&sys, 0.0).unwrap();
    let mut rk = Rk4::new(&sys, Rk4Options::plain()).unwrap();
    let err = run(
        &mut rk,
        &sys,
        &mut s,
        RunConfig::new(20.0, 0.01),
        &mut mbd::solve::NoObserver,
    )
    .expect_err("plain RK4 drifts past 1% of the links' half length within 20 s");
    match err {
        mbd::solve::SolveError::ConstraintDrift { t, joint, .. } => {
            assert!(t > 1.0 && t < 20.0, "t = {t}");
            assert!(joint.starts_with("pin"), "{joint}");
        }
        other => panic!("expected ConstraintDrift, got {other:?}"),
    }
    let mut s = State::consistent(&sys, 0.0).unwrap();
    let mut rk = Rk4::new(&sys, Rk4Options::projected()).unwrap();
    let stats = run(
        &mut rk,
        &sys,
        &mut s,
        RunConfig::new(20.0, 0.01),
        &mut mbd::solve::NoObserver,
    )
    .unwrap();
    assert_eq!(stats.steps, 2000);
    assert_eq!(stats.near_singular_steps, 0);
    assert!(stats.max_condition >= 1.0 && stats.max_condition < 100.0);
}

#[test]
fn plain_rk4_drifts_like_the_paper_and_projection_holds_constraints() {
    let m = manipulator_measures(Rk4Options::plain());
    eprintln!("plain RK4, h = 0.01, 20 s: {m:?}");
    assert!((m.h0 - 12.7436).abs() < 1e-4, "H0 = {}", m.h0);
    assert!(m.e_phi > 1e-10, "e(Phi) = {}", m.e_phi);
    // paper: e(H) = 9.08e-2, MRE(H) = 2.85e-2; same order of magnitude
    assert!(m.e_h > 9.08e-3 && m.e_h < 9.08e-1, "e(H) = {}", m.e_h);
    let p = manipulator_measures(Rk4Options::projected());
    eprintln!("projected RK4: {p:?}");
    assert!(p.e_phi <= 1e-12, "e(Phi) = {}", p.e_phi);
    assert!(p.e_phidot <= 1e-12, "e(Phidot) = {}", p.e_phidot);
    // Baumgarte reduces the drift of plain RK4
    let b = manipulator_measures(Rk4Options::baumgarte(10.0, 10.0));
    eprintln!("Baumgarte RK4: {b:?}");
    assert!(
        b.e_phi < m.e_phi,
        "Baumgarte {} vs plain {}",
        b.e_phi,
        m.e_phi
    );
}

#[test]
fn bad_run_inputs_are_errors() {
    let sys = models::pendulum(1.0, 1.0, 0.2, 9.81).unwrap();
    let s0 = State::consistent(&sys, 0.0).unwrap();
    let mut rk = Rk4::new(&sys, Rk4Options::plain()).unwrap();
    let cases = [
        (1.0, 0.0),
        (1.0, -0.01),
        (1.0, f64::NAN),
        (1.0, f64::INFINITY),
        (-1.0, 0.01),
        (0.0, 0.01),
        (f64::NAN, 0.01),
    ];
    for (t_end, h) in cases {
        let mut s = s0.clone();
        let r = run(
            &mut rk,
            &sys,
            &mut s,
            RunConfig::new(t_end, h),
            &mut NoObserver,
        );
        match r {
            Err(SolveError::InvalidStep { .. }) | Err(SolveError::InvalidInterval { .. }) => {}
            other => panic!("t_end = {t_end}, h = {h}: expected an error, got {other:?}"),
        }
        assert_eq!(s, s0, "a rejected run must not touch the state");
    }
    let mut s = s0.clone();
    assert!(matches!(
        rk.step(&sys, &mut s, -0.1),
        Err(SolveError::InvalidStep { .. })
    ));
    assert!(matches!(
        rk.step(&sys, &mut s, f64::NAN),
        Err(SolveError::InvalidStep { .. })
    ));
    let bad = State {
        t: 0.0,
        q: mbd::model::nalgebra::DVector::zeros(5),
        v: mbd::model::nalgebra::DVector::zeros(3),
    };
    let mut b2 = bad.clone();
    assert!(matches!(
        rk.step(&sys, &mut b2, 0.01),
        Err(SolveError::Dimension { .. })
    ));
    assert!(Rk4::new(&sys, Rk4Options::baumgarte(-1.0, 1.0)).is_err());
    assert!(Rk4::new(&sys, Rk4Options::baumgarte(1.0, f64::NAN)).is_err());
}

#[test]
fn run_lands_on_t_end_when_h_does_not_divide() {
    let sys = models::pendulum(1.0, 1.0, 0.2, 9.81).unwrap();
    let mut s = State::consistent(&sys, 0.0).unwrap();
    let mut rk = Rk4::new(&sys, Rk4Options::plain()).unwrap();
    let st = run(
        &mut rk,
        &sys,
        &mut s,
        RunConfig::new(1.0, 0.3),
        &mut NoObserver,
    )
    .unwrap();
    assert_eq!(st.steps, 4);
    assert_eq!(s.t, 1.0);
}

#[test]
fn sparse_and_dense_index1_solves_agree_on_a_chain() {
    use mbd::solve::LinearSolver;
    let sys = models::n_link_chain(30).unwrap();
    let mut finals = vec![];
    for linear in [LinearSolver::Dense, LinearSolver::Sparse] {
        let mut s = State::consistent(&sys, 0.0).unwrap();
        let mut rk = Rk4::new(
            &sys,
            Rk4Options {
                linear,
                ..Rk4Options::projected()
            },
        )
        .unwrap();
        run(
            &mut rk,
            &sys,
            &mut s,
            RunConfig::new(0.2, 0.002),
            &mut NoObserver,
        )
        .unwrap();
        finals.push(s.q.as_slice().to_vec());
    }
    let d = finals[0]
        .iter()
        .zip(&finals[1])
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    assert!(d < 1e-10, "dense vs sparse differ by {d}");
}

/// A run of more than `MAX_FIXED_STEPS` steps is refused as such (not as a bad step size),
/// with compact numbers; a span far below h is one short step.
#[test]
fn step_counts_out_of_range_say_so() {
    let sys = models::pendulum(1.0, 1.0, 0.2, 9.81).unwrap();
    let s0 = State::consistent(&sys, 0.0).unwrap();
    let mut rk = Rk4::new(&sys, Rk4Options::plain()).unwrap();
    let mut s = s0.clone();
    let e = run(
        &mut rk,
        &sys,
        &mut s,
        RunConfig::new(1e12, 1e-3),
        &mut NoObserver,
    )
    .unwrap_err();
    assert!(matches!(e, SolveError::TooManySteps { .. }), "{e:?}");
    let m = e.to_string();
    assert!(
        m.contains("1000000000000000 steps of h = 0.001 over 1000000000000 s")
            && m.contains("larger step"),
        "{m}"
    );
    assert_eq!(s, s0);
    let stats = run(
        &mut rk,
        &sys,
        &mut s,
        RunConfig::new(1e-300, 1e-3),
        &mut NoObserver,
    )
    .unwrap();
    assert_eq!(stats.steps, 1);
    assert_eq!(s.t, 1e-300);
    let e = SolveError::InvalidStep { h: 1e300 }.to_string();
    assert!(e.contains("h = 1e300 "), "{e}");
}
