//! Bad input gets an error naming the problem, never a panic.
use mbd_model::models;
use mbd_solve::{Integrator, SolveError, State};
use mbd_symplectic::{Galerkin, SymplecticOptions};
use nalgebra::DVector;

#[test]
fn invalid_options_are_rejected() {
    let sys = models::pendulum(1.0, 1.0, 0.5, 9.81).unwrap();
    let bad = [
        SymplecticOptions::new(0),
        SymplecticOptions::new(2).with_gamma(f64::NAN),
        SymplecticOptions::new(2).with_gamma(f64::INFINITY),
        SymplecticOptions {
            fd_step: 0.0,
            ..SymplecticOptions::new(2)
        },
        SymplecticOptions {
            predictor_order: 7,
            ..SymplecticOptions::new(2)
        },
        SymplecticOptions {
            anderson_depth: mbd_symplectic::MAX_ANDERSON_DEPTH + 1,
            ..SymplecticOptions::new(2)
        },
    ];
    for o in bad {
        match Galerkin::new(&sys, o) {
            Err(SolveError::InvalidParameter { parameter, .. }) => {
                assert!(
                    ["s", "gamma", "fd_step", "predictor_order", "anderson_depth"]
                        .contains(&parameter)
                )
            }
            other => panic!("expected InvalidParameter, got {other:?}"),
        }
    }
    let mut o = SymplecticOptions::new(1);
    o.newton.max_iter = 0;
    assert!(Galerkin::new(&sys, o).is_err());
}

#[test]
fn bad_steps_and_states_are_rejected() {
    let sys = models::pendulum(1.0, 1.0, 0.5, 9.81).unwrap();
    let mut g = Galerkin::new(&sys, SymplecticOptions::new(2)).unwrap();
    let mut st = State::consistent(&sys, 0.0).unwrap();
    for h in [0.0, -0.1, f64::NAN, f64::INFINITY] {
        assert!(matches!(
            g.step(&sys, &mut st, h),
            Err(SolveError::InvalidStep { .. })
        ));
    }
    let mut wrong = st.clone();
    wrong.q = DVector::zeros(4);
    assert!(matches!(
        g.step(&sys, &mut wrong, 0.01),
        Err(SolveError::Dimension { .. })
    ));
    let mut nan = st.clone();
    nan.v[0] = f64::NAN;
    assert!(g.step(&sys, &mut nan, 0.01).is_err());
    // integrator built for another model
    let other = models::manipulator().unwrap();
    let mut st2 = State::consistent(&other, 0.0).unwrap();
    assert!(g.step(&other, &mut st2, 0.01).is_err());
}

#[test]
fn newton_failure_reports_time_and_residual() {
    let sys = models::manipulator().unwrap();
    let mut st = State::consistent(&sys, 0.0).unwrap();
    let mut g = Galerkin::new(&sys, SymplecticOptions::new(2)).unwrap();
    let mut failure = None;
    for _ in 0..20 {
        match g.step(&sys, &mut st, 5.0) {
            Ok(_) => continue,
            Err(e) => {
                failure = Some(e);
                break;
            }
        }
    }
    match failure {
        Some(SolveError::Newton {
            t,
            residual,
            iterations,
            context,
        }) => {
            println!("t = {t}, residual {residual:e}, {iterations} iterations: {context}");
            assert!(t.is_finite() && residual > 0.0 && context.contains("h = 5"));
        }
        Some(SolveError::Singular { t, .. }) => assert!(t.is_finite()),
        other => panic!("expected a Newton failure, got {other:?}"),
    }
}
