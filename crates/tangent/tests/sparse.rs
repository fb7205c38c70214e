//! The sparse chart (redundant tangent coordinates, sparse Cholesky of `Df Df^T`): the same
//! trajectory as the dense QR chart, constraints at the Newton tolerance on long chains, typed
//! errors at singular configurations, and the choice of path.

mod common;

use common::{residuals, state_error, ResidualWatch};
use mbd_model::{models, System};
use mbd_solve::{
    run, run_adaptive, AdaptiveConfig, ButcherTableau, Integrator, NoObserver, RunConfig,
    SolveError, State,
};
use mbd_tangent::{IterationMatrix, LinearSolver, TangentOptions, TangentRk};
use nalgebra::DVector;

fn solver(sys: &System, tableau: ButcherTableau, linear_solver: LinearSolver) -> TangentRk {
    let opts = TangentOptions {
        linear_solver,
        ..Default::default()
    };
    TangentRk::new(sys, tableau, opts).expect("solver")
}

#[test]
fn auto_picks_sparse_above_the_threshold_only() {
    let small = models::manipulator().expect("model");
    assert!(!TangentRk::rk4(&small).expect("solver").is_sparse());
    let chain = models::n_link_chain(30).expect("model");
    assert!(chain.n_constraints() > mbd_solve::SPARSE_THRESHOLD);
    let rk = TangentRk::rk4(&chain).expect("solver");
    assert!(rk.is_sparse());
    assert_eq!(
        rk.state_dim(),
        2 * (chain.n_coords() - chain.n_constraints())
    );
    let dense = solver(&chain, ButcherTableau::rk4(), LinearSolver::Dense);
    assert!(!dense.is_sparse());
    assert_eq!(dense.state_dim(), rk.state_dim());
}

#[test]
fn sparse_and_dense_rk4_agree_on_a_30_link_chain() {
    let sys = models::n_link_chain(30).expect("model");
    let s0 = State::consistent(&sys, 0.0).expect("state");
    let mut ends = vec![];
    for ls in [LinearSolver::Dense, LinearSolver::Sparse] {
        let mut rk = solver(&sys, ButcherTableau::rk4(), ls);
        let mut s = s0.clone();
        let mut watch = ResidualWatch::default();
        run(&mut rk, &sys, &mut s, RunConfig::new(0.2, 1e-3), &mut watch).expect("run");
        assert_eq!(rk.stats().steps, 200);
        assert!(
            watch.max_phi <= 1e-12 && watch.max_phidot <= 1e-11,
            "{ls:?}"
        );
        println!("{ls:?}: {:?}", rk.stats());
        ends.push(s);
    }
    let d = state_error(&ends[0], ends[1].q.as_slice(), ends[1].v.as_slice());
    let moved = state_error(&ends[0], s0.q.as_slice(), s0.v.as_slice());
    println!("max |dense - sparse| over q, v after 200 steps: {d:.2e} (moved {moved:.2e})");
    assert!(moved > 1e-2, "the chain moves");
    assert!(d <= 1e-10, "{d:e}");
}

#[test]
fn sparse_and_dense_adaptive_dopri5_agree_on_a_30_link_chain() {
    let sys = models::n_link_chain(30).expect("model");
    let s0 = State::consistent(&sys, 0.0).expect("state");
    let mut ends = vec![];
    let mut stats = vec![];
    for ls in [LinearSolver::Dense, LinearSolver::Sparse] {
        let mut dp = solver(&sys, ButcherTableau::dopri5(), ls);
        let mut s = s0.clone();
        let cfg = AdaptiveConfig::new(0.2, 1e-8).without_drift_guard();
        let st = run_adaptive(&mut dp, &sys, &mut s, cfg, &mut NoObserver).expect("adaptive");
        assert_eq!(s.t, 0.2);
        assert!(st.max_residual <= 1e-12, "{ls:?} {st:?}");
        stats.push(st);
        ends.push(s);
    }
    println!("{stats:?}");
    assert_eq!(stats[0].steps, stats[1].steps);
    assert_eq!(stats[0].rejected_steps, stats[1].rejected_steps);
    let d = state_error(&ends[0], ends[1].q.as_slice(), ends[1].v.as_slice());
    println!("max |dense - sparse| over q, v at t = 0.2: {d:.2e}");
    assert!(d <= 1e-10, "{d:e}");
}

#[test]
fn sparse_constraints_stay_at_the_newton_tolerance_on_a_100_link_chain() {
    let sys = models::n_link_chain(100).expect("model");
    let mut s = State::consistent(&sys, 0.0).expect("state");
    let mut rk = TangentRk::rk4(&sys).expect("solver");
    assert!(rk.is_sparse());
    let mut watch = ResidualWatch::default();
    run(&mut rk, &sys, &mut s, RunConfig::new(0.3, 1e-3), &mut watch).expect("run");
    let mut buf = [vec![], vec![]];
    let (p, d) = residuals(&sys, &s, &mut buf);
    println!(
        "phi {p:.2e} phidot {d:.2e}; max over the run {:.2e} {:.2e}; {:?}",
        watch.max_phi,
        watch.max_phidot,
        rk.stats()
    );
    assert_eq!(rk.stats().steps, 300);
    assert_eq!(watch.samples, 301);
    // the Newton tolerance 1e-13, or the round-off floor 8 eps (1 + |x|) of evaluating f
    let floor = 8.0 * f64::EPSILON * (1.0 + s.q.amax().max(s.v.amax()));
    let tol = 1e-13f64.max(floor);
    assert!(watch.max_phi <= tol && watch.max_phidot <= tol, "{tol:e}");
    assert!(rk.stats().max_residual <= tol);
    assert_eq!(rk.stats().halvings, 0);
}

/// The slider-crank with crank and rod of equal length folded at the pivot: `Phi_q` has rank 7
/// of 8 (see `singular.rs`).
fn folded_slider_crank() -> (System, State) {
    let l = 0.3;
    let sys = common::slider_crank(l, l, 1.0, None);
    let half = std::f64::consts::FRAC_PI_2;
    let q = DVector::from_vec(vec![0.0, 0.5 * l, half, 0.0, 0.5 * l, -half, 0.0, 0.0, 0.0]);
    let s0 = State::new(&sys, 0.0, q, DVector::zeros(9)).expect("state");
    (sys, s0)
}

#[test]
fn sparse_singular_start_is_a_typed_error() {
    let (sys, s0) = folded_slider_crank();
    let mut rk = solver(&sys, ButcherTableau::rk4(), LinearSolver::Sparse);
    let mut s = s0.clone();
    let e = rk.step(&sys, &mut s, 1e-3).unwrap_err();
    println!("{e}");
    match &e {
        SolveError::Singular { t, what, detail } => {
            assert_eq!(*t, 0.0);
            assert!(what.contains("Phi_q"), "{what}");
            assert!(detail.contains("dependent equation"), "{detail}");
        }
        other => panic!("expected a singular configuration, got {other}"),
    }
    assert_eq!(s, s0, "the state is left alone");
    let mut dp = solver(&sys, ButcherTableau::dopri5(), LinearSolver::Sparse);
    let e = run_adaptive(
        &mut dp,
        &sys,
        &mut s,
        AdaptiveConfig::new(1.0, 1e-6),
        &mut NoObserver,
    )
    .unwrap_err();
    assert!(matches!(&e, SolveError::Singular { .. }), "{e}");
    assert_eq!(s, s0);
}

#[test]
fn sparse_step_ending_on_a_flat_four_bar_configuration_is_a_typed_error() {
    // crank driven from pi/2 at pi/2 rad/s: flat (theta = pi) at t = 1 exactly, a step end
    let half = std::f64::consts::FRAC_PI_2;
    let sys = models::parallelogram_four_bar(0.4, 1.0, half, half, true).expect("model");
    let mut s = State::consistent(&sys, 0.0).expect("state");
    let mut rk = solver(&sys, ButcherTableau::rk4(), LinearSolver::Sparse);
    let e = run(
        &mut rk,
        &sys,
        &mut s,
        RunConfig::new(2.0, 1e-3),
        &mut NoObserver,
    )
    .unwrap_err();
    println!("{e}; t = {}; {:?}", s.t, rk.stats());
    let SolveError::Singular { t, .. } = e else {
        panic!("expected a singular configuration, got {e}");
    };
    // the error comes at the flat configuration, never past it with a wrong state
    assert!((0.99..=1.0 + 1e-12).contains(&t), "{t}");
    assert!(s.t <= 1.0 - 1e-3 + 1e-12 && s.t > 0.98, "{}", s.t);
    let mut buf = [vec![], vec![]];
    let (p, d) = residuals(&sys, &s, &mut buf);
    assert!(p <= 1e-12 && d <= 1e-12, "{p:e} {d:e}");
}

#[test]
fn sparse_path_rejects_the_dense_only_iteration_matrices() {
    let sys = models::n_link_chain(30).expect("model");
    for im in [IterationMatrix::Interpolated, IterationMatrix::Broyden] {
        let opts = TangentOptions {
            iteration_matrix: im,
            ..Default::default()
        };
        let e = TangentRk::new(&sys, ButcherTableau::rk4(), opts).unwrap_err();
        assert!(matches!(e, SolveError::Unsupported(_)), "{e}");
        let dense = TangentOptions {
            linear_solver: LinearSolver::Dense,
            ..opts
        };
        assert!(TangentRk::new(&sys, ButcherTableau::rk4(), dense).is_ok());
    }
}
