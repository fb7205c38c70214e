//! Bad input is an error (never a panic), and a chart that cannot be followed is an error with
//! time and residual, or a counted step halving — never a silent wrong state.

mod common;

use mbd_model::{models, Body, BodyRef, Joint, SystemBuilder};
use mbd_solve::{ButcherTableau, Integrator, SolveError, State};
use mbd_tangent::{NewtonSettings, TangentOptions, TangentRk};
use nalgebra::DVector;

#[test]
fn bad_step_sizes_and_states_are_errors() {
    let sys = models::manipulator().expect("model");
    let s0 = State::consistent(&sys, 0.0).expect("state");
    let mut rk = TangentRk::rk4(&sys).expect("solver");
    for h in [0.0, -1e-3, f64::NAN, f64::INFINITY] {
        let mut s = s0.clone();
        assert!(
            matches!(
                rk.step(&sys, &mut s, h),
                Err(SolveError::InvalidStep { .. })
            ),
            "h = {h}"
        );
        assert_eq!(s, s0);
    }
    // wrong sizes
    let mut s = s0.clone();
    s.q = DVector::zeros(5);
    assert!(matches!(
        rk.step(&sys, &mut s, 1e-3),
        Err(SolveError::Dimension { .. })
    ));
    let mut s = s0.clone();
    s.v = DVector::zeros(7);
    assert!(matches!(
        rk.step(&sys, &mut s, 1e-3),
        Err(SolveError::Dimension { .. })
    ));
    // NaN in the state
    let mut s = s0.clone();
    s.q[1] = f64::NAN;
    assert!(matches!(
        rk.step(&sys, &mut s, 1e-3),
        Err(SolveError::NonFinite { .. })
    ));
    // off the manifold
    let mut s = s0.clone();
    s.q[0] += 1e-3;
    let e = rk.step(&sys, &mut s, 1e-3).unwrap_err();
    assert!(matches!(e, SolveError::InvalidParameter { .. }), "{e}");
    // another system
    let other = models::slider_crank().expect("model");
    let mut s = State::consistent(&other, 0.0).expect("state");
    assert!(matches!(
        rk.step(&other, &mut s, 1e-3),
        Err(SolveError::Dimension { .. })
    ));
    // a good step still works afterwards
    let mut s = s0.clone();
    rk.step(&sys, &mut s, 1e-3).expect("step");
    assert!((s.t - 1e-3).abs() < 1e-16);
}

#[test]
fn bad_tableaus_and_options_are_errors() {
    let sys = models::pendulum(1.0, 1.0, 0.3, 9.81).expect("model");
    let mut implicit = ButcherTableau::rk4();
    implicit.a[1] = 0.5; // a_01 != 0: not explicit
    assert!(TangentRk::new(&sys, implicit, TangentOptions::default()).is_err());
    let mut bad_c = ButcherTableau::rk4();
    bad_c.c[2] = 0.7;
    assert!(TangentRk::new(&sys, bad_c, TangentOptions::default()).is_err());
    let mut short = ButcherTableau::rk4();
    short.b.pop();
    assert!(TangentRk::new(&sys, short, TangentOptions::default()).is_err());

    let bad: Vec<TangentOptions> = vec![
        TangentOptions {
            newton: NewtonSettings {
                tol: 0.0,
                ..Default::default()
            },
            ..Default::default()
        },
        TangentOptions {
            newton: NewtonSettings {
                tol: f64::NAN,
                ..Default::default()
            },
            ..Default::default()
        },
        TangentOptions {
            newton: NewtonSettings {
                max_iter: 0,
                ..Default::default()
            },
            ..Default::default()
        },
        TangentOptions {
            newton: NewtonSettings {
                divergence: 0.5,
                ..Default::default()
            },
            ..Default::default()
        },
        TangentOptions {
            newton: NewtonSettings {
                fallback_change: -0.1,
                ..Default::default()
            },
            ..Default::default()
        },
        TangentOptions {
            newton: NewtonSettings {
                fallback_change: f64::INFINITY,
                ..Default::default()
            },
            ..Default::default()
        },
        TangentOptions {
            max_halvings: 31,
            ..Default::default()
        },
        TangentOptions {
            singular_tol: 0.0,
            ..Default::default()
        },
        TangentOptions {
            singular_tol: 1.5,
            ..Default::default()
        },
        TangentOptions {
            consistency_tol: 1e-20,
            ..Default::default()
        },
        TangentOptions {
            stage_tol_ratio: -0.1,
            ..Default::default()
        },
        TangentOptions {
            stage_tol_ratio: 1.0,
            ..Default::default()
        },
        TangentOptions {
            stage_tol_ratio: f64::NAN,
            ..Default::default()
        },
    ];
    for o in bad {
        let e = TangentRk::new(&sys, ButcherTableau::rk4(), o);
        assert!(
            matches!(e, Err(SolveError::InvalidParameter { .. })),
            "{o:?}"
        );
    }
}

#[test]
fn huge_step_without_halving_is_a_chart_error() {
    let sys = models::manipulator().expect("model");
    let s0 = State::consistent(&sys, 0.0).expect("state");
    let opts = TangentOptions {
        max_halvings: 0,
        ..Default::default()
    };
    let mut rk = TangentRk::new(&sys, ButcherTableau::rk4(), opts).expect("solver");
    // move first, so the chart is centred in fast motion
    let mut s = s0.clone();
    for _ in 0..300 {
        rk.step(&sys, &mut s, 1e-3).expect("step");
    }
    let before = s.clone();
    let e = rk.step(&sys, &mut s, 1.0).unwrap_err();
    match &e {
        SolveError::Newton {
            t,
            residual,
            context,
            ..
        } => {
            assert!((t - before.t).abs() <= 1.0 + 1e-12);
            assert!(residual.is_nan() || residual.abs() > 1e-13);
            assert!(context.contains("tangent chart"));
        }
        other => panic!("expected a chart error, got {other}"),
    }
    assert_eq!(s, before, "a failed step leaves the state as it was");
    assert_eq!(rk.stats().chart_failures, 1);
}

#[test]
fn halving_recovers_and_is_counted() {
    // h = 0.2 on the manipulator is too large for some charts (the chord iteration diverges in
    // the fast phase of the motion): those steps are redone as halves
    let sys = models::manipulator().expect("model");
    let mut s = State::consistent(&sys, 0.0).expect("state");
    let mut rk = TangentRk::rk4(&sys).expect("solver");
    let mut pd = vec![0.0; sys.n_constraints()];
    for k in 1..=10 {
        let st = rk.step(&sys, &mut s, 0.2).expect("step with halvings");
        assert!((s.t - 0.2 * k as f64).abs() < 1e-13);
        assert!(st.residual <= 1e-12, "step {k}: {st:?}");
        sys.phi_dot(s.q.as_slice(), s.v.as_slice(), s.t, &mut pd);
        assert!(pd.iter().all(|x| x.abs() <= 1e-12));
    }
    let stats = rk.stats();
    println!("{stats:?}");
    assert!(stats.halvings > 0, "{stats:?}");
    assert_eq!(stats.halvings, stats.chart_failures);
    assert!(stats.steps > 10);
}

#[test]
fn fast_motion_converges_at_the_round_off_floor() {
    // a rod spinning at 300 rad/s: Phi_q v cannot be evaluated below ~eps * 300, above the
    // default tolerance 1e-13; the chord iteration accepts the round-off floor instead of failing
    let mut b = SystemBuilder::new();
    let w = 300.0;
    let rod = b.add_body(
        Body::new("rod")
            .rod(1.0, 1.0)
            .position(0.5, 0.0, 0.0)
            .velocity(0.0, 0.5 * w, w),
    );
    b.add_joint(Joint::revolute(
        "pin",
        BodyRef::Ground,
        [0.0, 0.0],
        rod,
        [-0.5, 0.0],
    ));
    let sys = b.build().expect("model");
    let mut s = State::consistent(&sys, 0.0).expect("state");
    let mut rk = TangentRk::rk4(&sys).expect("solver");
    for _ in 0..2000 {
        let st = rk.step(&sys, &mut s, 1e-4).expect("step");
        let cap = (1e-12f64).max(mbd_tangent::ROUNDOFF_FACTOR * f64::EPSILON * (1.0 + w));
        assert!(st.residual <= cap, "{}", st.residual);
    }
    assert_eq!(rk.stats().halvings, 0);
    // the spin rate is conserved (no gravity, no damping)
    assert!((s.v[2] - w).abs() < 1e-8 * w, "{}", s.v[2]);
}
