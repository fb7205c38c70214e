//! A step allocates nothing (fixed and adaptive, RK4 and DOPRI5), counted by a global allocator.

use mbd_model::models;
use mbd_solve::{run_adaptive, AdaptiveConfig, Integrator, NoObserver, State};
use mbd_tangent::{ButcherTableau, IterationMatrix, LinearSolver, TangentOptions, TangentRk};

#[global_allocator]
static GLOBAL: mbd_testkit::CountingAlloc = mbd_testkit::CountingAlloc;

#[test]
fn steps_allocate_nothing() {
    // the counter counts
    let probe = mbd_testkit::allocations();
    std::hint::black_box(vec![1u8; 16]);
    assert!(mbd_testkit::allocations() > probe);
    for sys in [
        models::manipulator().expect("model"),
        models::slider_crank().expect("model"),
    ] {
        let mut s = State::consistent(&sys, 0.0).expect("state");
        let mut rk4 = TangentRk::rk4(&sys).expect("solver");
        let mut dp = TangentRk::dopri5(&sys).expect("solver");
        let broyden = TangentOptions {
            iteration_matrix: IterationMatrix::Broyden,
            ..Default::default()
        };
        let mut br = TangentRk::new(&sys, ButcherTableau::rk4(), broyden).expect("solver");
        rk4.step(&sys, &mut s, 1e-3).expect("warm-up");
        let before = mbd_testkit::allocations();
        for _ in 0..200 {
            rk4.step(&sys, &mut s, 1e-3).expect("step");
            dp.step(&sys, &mut s, 1e-3).expect("step");
            br.step(&sys, &mut s, 1e-3).expect("step");
        }
        // steps that need halving (h = 0.1 on the manipulator) allocate nothing either
        for _ in 0..10 {
            rk4.step(&sys, &mut s, 0.1).expect("halved step");
            br.step(&sys, &mut s, 0.1).expect("halved step");
        }
        let t1 = s.t + 0.5;
        run_adaptive(
            &mut dp,
            &sys,
            &mut s,
            AdaptiveConfig::new(t1, 1e-9).without_drift_guard(),
            &mut NoObserver,
        )
        .expect("adaptive");
        let after = mbd_testkit::allocations();
        assert_eq!(after - before, 0, "allocations during steps");
    }
}

#[test]
fn sparse_steps_allocate_nothing() {
    let sparse = TangentOptions {
        linear_solver: LinearSolver::Sparse,
        ..Default::default()
    };
    // a 30-link chain (sparse by default) and the manipulator forced onto the sparse chart
    // (whose steps at h = 0.1 need halving)
    let cases = [
        (models::n_link_chain(30).expect("model"), 1e-3, false),
        (models::manipulator().expect("model"), 1e-3, true),
    ];
    for (sys, h, halve) in cases {
        let mut s = State::consistent(&sys, 0.0).expect("state");
        let mut rk4 = TangentRk::new(&sys, ButcherTableau::rk4(), sparse).expect("solver");
        let mut dp = TangentRk::new(&sys, ButcherTableau::dopri5(), sparse).expect("solver");
        assert!(rk4.is_sparse() && dp.is_sparse());
        rk4.step(&sys, &mut s, h).expect("warm-up");
        let before = mbd_testkit::allocations();
        for _ in 0..100 {
            rk4.step(&sys, &mut s, h).expect("step");
            dp.step(&sys, &mut s, h).expect("step");
        }
        if halve {
            let h0 = rk4.stats().halvings;
            for _ in 0..10 {
                rk4.step(&sys, &mut s, 0.1).expect("halved step");
            }
            assert!(rk4.stats().halvings > h0, "the large steps were halved");
        }
        let t1 = s.t + 0.1;
        run_adaptive(
            &mut dp,
            &sys,
            &mut s,
            AdaptiveConfig::new(t1, 1e-9).without_drift_guard(),
            &mut NoObserver,
        )
        .expect("adaptive");
        let after = mbd_testkit::allocations();
        assert_eq!(after - before, 0, "allocations during sparse steps");
    }
}
