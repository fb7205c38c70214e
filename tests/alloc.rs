//! Hot loops allocate nothing: counts heap allocations during steps with a counting allocator.

use mbd::model::models;
use mbd::rk4::{Rk4, Rk4Options};
use mbd::solve::{Integrator, State};
use mbd_testkit::allocations;

#[global_allocator]
static GLOBAL: mbd_testkit::CountingAlloc = mbd_testkit::CountingAlloc;

fn count_step_allocations<I: Integrator>(mut integ: I, sys: &mbd::model::System) -> usize {
    let mut s = State::consistent(sys, 0.0).unwrap();
    integ.step(sys, &mut s, 0.01).unwrap(); // warm-up
    let before = allocations();
    for _ in 0..100 {
        integ.step(sys, &mut s, 0.01).unwrap();
    }
    allocations() - before
}

// One test function: the allocation counter is global, so concurrent tests would pollute it.
#[test]
fn steps_allocate_nothing() {
    // the counter counts
    let before = allocations();
    std::hint::black_box(vec![1u8; 16]);
    assert!(allocations() > before);
    rk4_steps_allocate_nothing();
    sparse_rk4_steps_allocate_nothing();
    spatial_steps_allocate_nothing();
}

/// Spatial bodies: RK4 on the dense (disc top) and the sparse path (a 6-rod chain, forced
/// sparse), projected RK4, symplectic (2,2) on the disc top (its singular mass matrix taking
/// the constrained end-velocity solve), and the spatial joints' reactions of an output row.
fn spatial_steps_allocate_nothing() {
    use mbd::solve::LinearSolver;
    use mbd::symplectic::{Galerkin, SymplecticOptions};
    let disc = models::heavy_top([0.25, 0.25, 0.5], 0.3, 20.0).unwrap();
    let chain = models::spatial_chain(6).unwrap();
    let sparse = Rk4Options {
        linear: LinearSolver::Sparse,
        ..Rk4Options::plain()
    };
    let sparse_projected = Rk4Options {
        linear: LinearSolver::Sparse,
        ..Rk4Options::projected()
    };
    for (name, n) in [
        (
            "disc rk4",
            count_step_allocations(Rk4::new(&disc, Rk4Options::plain()).unwrap(), &disc),
        ),
        (
            "disc rk4-projected",
            count_step_allocations(Rk4::new(&disc, Rk4Options::projected()).unwrap(), &disc),
        ),
        (
            "chain sparse rk4",
            count_step_allocations(Rk4::new(&chain, sparse).unwrap(), &chain),
        ),
        (
            "chain sparse rk4-projected",
            count_step_allocations(Rk4::new(&chain, sparse_projected).unwrap(), &chain),
        ),
        (
            "disc symplectic:2",
            count_step_allocations(
                Galerkin::new(&disc, SymplecticOptions::new(2)).unwrap(),
                &disc,
            ),
        ),
    ] {
        assert_eq!(n, 0, "{name}");
    }
    let s = State::consistent(&chain, 0.0).unwrap();
    let lambda = vec![0.5; chain.n_constraints()];
    let mut out = vec![Default::default(); chain.spatial_joints().len()];
    chain
        .spatial_joint_reactions_into(s.q.as_slice(), s.t, &lambda, &mut out)
        .unwrap();
    let before = allocations();
    chain
        .spatial_joint_reactions_into(s.q.as_slice(), s.t, &lambda, &mut out)
        .unwrap();
    assert_eq!(allocations() - before, 0, "spatial reactions");
    assert!(chain
        .spatial_joint_reactions_into(s.q.as_slice(), s.t, &lambda, &mut out[..2])
        .is_err());
}

fn rk4_steps_allocate_nothing() {
    let sys = models::manipulator().unwrap();
    assert_eq!(
        count_step_allocations(Rk4::new(&sys, Rk4Options::plain()).unwrap(), &sys),
        0
    );
    assert_eq!(
        count_step_allocations(Rk4::new(&sys, Rk4Options::projected()).unwrap(), &sys),
        0
    );
    assert_eq!(
        count_step_allocations(
            Rk4::new(&sys, Rk4Options::baumgarte(5.0, 5.0)).unwrap(),
            &sys
        ),
        0
    );
}

fn sparse_rk4_steps_allocate_nothing() {
    use mbd::solve::LinearSolver;
    let sys = models::n_link_chain(60).unwrap();
    let opts = Rk4Options {
        linear: LinearSolver::Sparse,
        ..Rk4Options::plain()
    };
    assert_eq!(
        count_step_allocations(Rk4::new(&sys, opts).unwrap(), &sys),
        0
    );
    // the sparse projection (sparse Cholesky of Phi_q M^-1 Phi_q^T) too
    let projected = Rk4Options {
        linear: LinearSolver::Sparse,
        ..Rk4Options::projected()
    };
    assert_eq!(
        count_step_allocations(Rk4::new(&sys, projected).unwrap(), &sys),
        0
    );
}
