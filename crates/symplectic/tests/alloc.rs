//! `Integrator::step` allocates nothing (counting global allocator), for s = 1, 2 and with the
//! preadjustment on, on the dense and on the sparse path.
use mbd_model::models;
use mbd_solve::{Integrator, LinearSolver, State};
use mbd_symplectic::{Galerkin, JacobianReuse, PreadjustMode, SymplecticOptions};

#[global_allocator]
static GLOBAL: mbd_testkit::CountingAlloc = mbd_testkit::CountingAlloc;

#[test]
fn steps_allocate_nothing() {
    let sys = models::manipulator().unwrap();
    let s0 = State::consistent(&sys, 0.0).unwrap();
    for (s, gamma) in [(1, 0.0), (2, 0.0), (3, 0.0), (2, 1.0)] {
        let mut g = Galerkin::new(&sys, SymplecticOptions::new(s).with_gamma(gamma)).unwrap();
        let mut st = s0.clone();
        g.step(&sys, &mut st, 0.01).unwrap();
        let before = mbd_testkit::allocations();
        for _ in 0..100 {
            g.step(&sys, &mut st, 0.01).unwrap();
        }
        let n = mbd_testkit::allocations() - before;
        assert_eq!(n, 0, "s={s} gamma={gamma}: {n} allocations in 100 steps");
    }
    // the modified-Lagrangian preadjustment (s = 1, and s = 2, whose e4 workspace is allocated
    // by the first step)
    for s in [1, 2] {
        let opts = SymplecticOptions::new(s).with_preadjust(PreadjustMode::ModifiedLagrangian);
        let mut g = Galerkin::new(&sys, opts).unwrap();
        let mut st = s0.clone();
        g.step(&sys, &mut st, 0.01).unwrap();
        let before = mbd_testkit::allocations();
        for _ in 0..100 {
            g.step(&sys, &mut st, 0.01).unwrap();
        }
        let n = mbd_testkit::allocations() - before;
        assert_eq!(
            n, 0,
            "modified Lagrangian, s = {s}: {n} allocations in 100 steps"
        );
    }
}

/// The sparse path (a 30-link chain, sparse stage LU, sparse projection): after the first
/// steps (which size the LU's factor storage), no step allocates, with one Jacobian per step,
/// with the Jacobian reused, and with the modified Lagrangian (s = 1, 2; s = 1 also at a step
/// where its exact position block is taken, through the augmented LU).
#[test]
fn sparse_steps_allocate_nothing() {
    let sys = models::n_link_chain(30).unwrap();
    let s0 = State::consistent(&sys, 0.0).unwrap();
    // (the last three: the modified Lagrangian, its workspace with S held sparse)
    for (s, reuse, modified, h) in [
        (1, false, false, 1e-3),
        (2, false, false, 1e-3),
        (3, false, false, 1e-3),
        (2, true, false, 1e-3),
        (1, false, true, 1e-3),
        (2, false, true, 1e-3),
        (1, false, true, 3e-2),
    ] {
        let mut opts = SymplecticOptions {
            linear_solver: LinearSolver::Sparse,
            reuse_jacobian: if reuse {
                JacobianReuse::Always
            } else {
                JacobianReuse::Never
            },
            ..SymplecticOptions::new(s)
        };
        if modified {
            opts = opts.with_preadjust(PreadjustMode::ModifiedLagrangian);
        }
        let mut g = Galerkin::new(&sys, opts).unwrap();
        assert!(g.is_sparse());
        let mut st = s0.clone();
        for _ in 0..3 {
            g.step(&sys, &mut st, h).unwrap();
        }
        let before = mbd_testkit::allocations();
        for _ in 0..100 {
            g.step(&sys, &mut st, h).unwrap();
        }
        let n = mbd_testkit::allocations() - before;
        assert_eq!(
            n, 0,
            "s={s} reuse={reuse} modified={modified} h={h}: {n} allocations in 100 steps"
        );
    }
    // force elements with damping: the coloured force differences allocate nothing either
    let sys = damped_spring_chain(30);
    let s0 = State::consistent(&sys, 0.0).unwrap();
    for s in [1, 2] {
        let mut g = Galerkin::new(&sys, SymplecticOptions::new(s)).unwrap();
        assert!(g.is_sparse());
        let mut st = s0.clone();
        for _ in 0..3 {
            g.step(&sys, &mut st, 1e-3).unwrap();
        }
        let before = mbd_testkit::allocations();
        for _ in 0..100 {
            g.step(&sys, &mut st, 1e-3).unwrap();
        }
        let n = mbd_testkit::allocations() - before;
        assert_eq!(n, 0, "damped chain, s={s}: {n} allocations in 100 steps");
    }
}

include!("common/damped.rs");
