//! The sparse stage solve: the same trajectory as the dense one, constraints held on a long
//! chain, and its limits reported as errors.
mod common;
use mbd_model::models;
use mbd_solve::{Integrator, LinearSolver, SolveError, State};
use mbd_symplectic::{Galerkin, JacobianReuse, SymplecticOptions};

/// The `(s,s)` scheme on `solver` with a new stage Jacobian at every step on both paths, so
/// that the paths differ only in the rounding of their linear algebra (the default keeps the
/// sparse path's factorisation, which moves the converged steps within the Newton tolerance:
/// `the_kept_factorisation_moves_the_steps_within_the_tolerance`).
fn opts(s: usize, solver: LinearSolver) -> SymplecticOptions {
    SymplecticOptions {
        linear_solver: solver,
        ..SymplecticOptions::new(s)
    }
    .with_jacobian_reuse(JacobianReuse::Never)
}

/// `steps` steps of `h` from the consistent initial state.
fn run(sys: &mbd_model::System, o: SymplecticOptions, h: f64, steps: usize) -> (State, bool) {
    let mut g = Galerkin::new(sys, o).unwrap();
    let mut st = State::consistent(sys, 0.0).unwrap();
    for _ in 0..steps {
        g.step(sys, &mut st, h).unwrap();
    }
    (st, g.is_sparse())
}

/// 30-link chain (60 constraint equations), 200 steps of 1e-3: the sparse and the dense
/// stage solves give the same positions and velocities to 1e-10 (they differ only in the
/// rounding of the linear solves, which Newton's last update removes to the tolerance).
#[test]
fn sparse_and_dense_paths_agree_on_a_30_link_chain() {
    let sys = models::n_link_chain(30).unwrap();
    for s in [1, 2] {
        let (d, dense_sparse) = run(&sys, opts(s, LinearSolver::Dense), 1e-3, 200);
        let (sp, sparse_sparse) = run(&sys, opts(s, LinearSolver::Sparse), 1e-3, 200);
        assert!(!dense_sparse && sparse_sparse);
        let dq = (&d.q - &sp.q).amax();
        let dv = (&d.v - &sp.v).amax();
        eprintln!("({s},{s}): max |dq| = {dq:e}, max |dv| = {dv:e}");
        assert!(dq < 1e-10 && dv < 1e-10, "({s},{s}): dq {dq:e}, dv {dv:e}");
        // and the motion is not trivial: the chain fell and swung
        let d0 = State::consistent(&sys, 0.0).unwrap();
        assert!((&d.q - &d0.q).amax() > 1e-3);
    }
}

/// Andrews' squeezer (a spring-damper and a driving torque; 7 bodies), forced onto the sparse
/// path: the force Hessians come from coloured central differences instead of the exact
/// Hessian, which changes only Newton's convergence, not the solution: 2000 steps of 1e-4
/// agree with the dense path to 1e-10.
#[test]
fn sparse_and_dense_paths_agree_with_force_elements() {
    let sys = models::andrews_squeezer().unwrap();
    for s in [1, 2] {
        let (d, _) = run(&sys, opts(s, LinearSolver::Dense), 1e-4, 2000);
        let (sp, sparse) = run(&sys, opts(s, LinearSolver::Sparse), 1e-4, 2000);
        assert!(sparse);
        let dq = (&d.q - &sp.q).amax();
        let dv = (&d.v - &sp.v).amax();
        let vmax = d.v.amax();
        eprintln!("squeezer ({s},{s}): max |dq| = {dq:e}, max |dv| = {dv:e} (max |v| = {vmax:e})");
        assert!(
            dq < 1e-10 && dv < 1e-10 * (1.0 + vmax),
            "({s},{s}): dq {dq:e}, dv {dv:e}"
        );
    }
}

/// A 30-link chain with rotary and point spring-dampers (60 equations: the sparse path by
/// default), 200 steps of 1e-3: the same trajectory as the dense path to 1e-10.
#[test]
fn sparse_and_dense_paths_agree_on_a_damped_spring_chain() {
    let sys = common::damped_spring_chain(30);
    for s in [1, 2] {
        let (d, dense) = run(&sys, opts(s, LinearSolver::Dense), 1e-3, 200);
        let (sp, sparse) = run(&sys, opts(s, LinearSolver::Auto), 1e-3, 200);
        assert!(!dense && sparse);
        let dq = (&d.q - &sp.q).amax();
        let dv = (&d.v - &sp.v).amax();
        eprintln!("damped chain ({s},{s}): max |dq| = {dq:e}, max |dv| = {dv:e}");
        assert!(dq < 1e-10 && dv < 1e-10, "({s},{s}): dq {dq:e}, dv {dv:e}");
    }
}

/// 100-link chain (200 equations, the sparse path by default), 300 steps of 1e-3: the
/// position and velocity constraints hold at the Newton tolerance.
#[test]
fn constraints_hold_on_a_100_link_chain() {
    let sys = models::n_link_chain(100).unwrap();
    let m = sys.n_constraints();
    for s in [1, 2] {
        let (st, sparse) = run(&sys, SymplecticOptions::new(s), 1e-3, 300);
        assert!(sparse, "the default takes the sparse path at m = {m}");
        let mut phi = vec![0.0; m];
        sys.phi(st.q.as_slice(), st.t, &mut phi);
        let mut pd = vec![0.0; m];
        sys.phi_dot(st.q.as_slice(), st.v.as_slice(), st.t, &mut pd);
        let p = phi.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        let v = pd.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        eprintln!("({s},{s}): max |Phi| = {p:e}, max |Phi_dot| = {v:e}");
        assert!(
            p < 1e-11 && v < 1e-11,
            "({s},{s}): |Phi| {p:e}, |Phi_dot| {v:e}"
        );
    }
}

/// Paper A's `W_s` (gamma) on the sparse path: its value and gradient are the dense path's
/// (matrix-free, `S` held sparse) and its Newton Hessian a diagonal stand-in, so on the
/// 30-link chain (which `Auto` now puts on the sparse path with gamma too) 50 steps of 1e-2
/// of the (1,1), (2,2) and (3,3) schemes with gamma = 1 take the dense path's steps to 1e-10,
/// and the term is seen: the steps are further than that from the plain scheme's.
#[test]
fn the_preadjusted_scheme_takes_the_sparse_path() {
    let chain = models::n_link_chain(30).unwrap();
    for s in [1, 2, 3] {
        let (h, steps) = (1e-2, 50);
        let (d, dense_sparse) = run(
            &chain,
            opts(s, LinearSolver::Dense).with_gamma(1.0),
            h,
            steps,
        );
        let (sp, sparse_sparse) = run(
            &chain,
            opts(s, LinearSolver::Auto).with_gamma(1.0),
            h,
            steps,
        );
        let (plain, _) = run(&chain, opts(s, LinearSolver::Auto), h, steps);
        assert!(!dense_sparse && sparse_sparse, "({s},{s}): the paths");
        let dq = (&d.q - &sp.q).amax();
        let dv = (&d.v - &sp.v).amax();
        let off = (&sp.q - &plain.q).amax();
        eprintln!(
            "({s},{s}) gamma = 1: sparse - dense {dq:.2e} in q, {dv:.2e} in v; - plain {off:.2e}"
        );
        assert!(dq < 1e-10 && dv < 1e-8, "({s},{s}): dq {dq:e}, dv {dv:e}");
        assert!(off > 1e3 * dq.max(1e-14), "({s},{s}): {off:e}");
    }
    let small = models::n_link_chain(24).unwrap();
    let g = Galerkin::new(&small, opts(2, LinearSolver::Auto)).unwrap();
    assert!(!g.is_sparse(), "48 equations: dense by default");
    let big = models::n_link_chain(25).unwrap();
    assert!(Galerkin::new(&big, SymplecticOptions::new(1))
        .unwrap()
        .is_sparse());
    // a bad gamma is still an error on either path
    match Galerkin::new(&chain, opts(2, LinearSolver::Sparse).with_gamma(f64::NAN)) {
        Err(SolveError::InvalidParameter { parameter, .. }) => assert_eq!(parameter, "gamma"),
        other => panic!("{other:?}"),
    }
}

/// The default keeps the sparse path's stage factorisation from step to step
/// (`JacobianReuse::Auto`): on the 30-link chain, 200 steps of 1e-3 of (1,1) and (2,2) take
/// fewer factorisations than steps and end within the Newton tolerance of a new Jacobian at
/// every step (positions 1e-10; velocities 1e-8, the displacement tolerance divided by h).
#[test]
fn the_kept_factorisation_moves_the_steps_within_the_tolerance() {
    let sys = models::n_link_chain(30).unwrap();
    for s in [1, 2] {
        let each = opts(s, LinearSolver::Auto);
        let kept = SymplecticOptions::new(s);
        assert_eq!(kept.reuse_jacobian, JacobianReuse::Auto);
        let mut counts = Vec::new();
        let mut ends = Vec::new();
        for o in [each, kept] {
            let mut g = Galerkin::new(&sys, o).unwrap();
            assert!(g.is_sparse());
            let mut st = State::consistent(&sys, 0.0).unwrap();
            for _ in 0..200 {
                g.step(&sys, &mut st, 1e-3).unwrap();
            }
            counts.push(g.jacobian_count());
            ends.push(st);
        }
        let dq = (&ends[0].q - &ends[1].q).amax();
        let dv = (&ends[0].v - &ends[1].v).amax();
        eprintln!(
            "({s},{s}): factorisations {counts:?}; kept against new: dq {dq:.1e}, dv {dv:.1e}"
        );
        assert!(counts[0] >= 200 && counts[1] < 100, "{counts:?}");
        assert!(dq < 1e-10 && dv < 1e-8, "({s},{s}): dq {dq:e}, dv {dv:e}");
    }
}
