//! Mechanisms with a redundant constraint equation (dependent at every configuration): the
//! double parallelogram and the pantograph (12 coordinates, 12 equations, rank 11, one degree of
//! freedom), swinging freely from rest, against their exact crank motion.

use mbd_firefly_gauss::{FaDaeError, FaDaeOptions, FireflyGauss, Partition, PartitionChoice};
use mbd_model::models::{self, ClosedLoop, CrankMotion};
use mbd_model::System;
use mbd_solve::{registry::SpecArgs, Integrator, State};

const ANGLE: f64 = -0.5;
const T_END: f64 = 0.5;

fn double_parallelogram() -> (System, ClosedLoop) {
    (
        models::double_parallelogram(0.4, 1.0, ANGLE, 0.0, false).expect("model"),
        ClosedLoop::double_parallelogram(0.4, 1.0).expect("loop"),
    )
}

fn pantograph() -> (System, ClosedLoop) {
    (
        models::pantograph(0.4, 1.0, 0.5, ANGLE, 0.0, false).expect("model"),
        ClosedLoop::pantograph(0.4, 1.0, 0.5).expect("loop"),
    )
}

/// The solver the registry builds for `spec` (e.g. `firefly-gauss:polish`).
fn registry_solver(spec: &str, sys: &System) -> Box<dyn Integrator> {
    let parsed = (mbd_firefly_gauss::SOLVERS.parse)(&SpecArgs::new(spec)).expect(spec);
    parsed
        .build(sys)
        .expect("FA-DAE accepts the redundant model")
}

fn solver(sys: &System, opts: FaDaeOptions) -> Box<dyn Integrator> {
    Box::new(FireflyGauss::new(sys, opts).expect("FA-DAE accepts the redundant model"))
}

/// One run of `T_END` at step `h`: the crank angle error at the end, the largest `|Phi|` and
/// `|Phi_q v + Phi_t|` over every equation (the redundant one too) at every grid point, each
/// relative to the solver's Newton tolerance at that state (`newton_tol` times the largest
/// translational coordinate, at least 1), and the final state's bits.
fn run(
    sys: &System,
    cl: &ClosedLoop,
    fa: &mut dyn Integrator,
    h: f64,
) -> (f64, f64, f64, Vec<u64>) {
    let body = sys
        .body_handle(&cl.tracked_body())
        .expect("tracked body")
        .index();
    let exact: CrankMotion = cl.motion(ANGLE, 0.0).expect("exact motion");
    let tol = FaDaeOptions::default().newton_tol;
    let mut s = State::consistent(sys, 0.0).expect("state");
    let m = sys.n_constraints();
    let (mut phi, mut phid) = (vec![0.0; m], vec![0.0; m]);
    let (mut worst_phi, mut worst_phid) = (0.0f64, 0.0f64);
    let steps = (T_END / h).round() as usize;
    for _ in 0..steps {
        fa.step(sys, &mut s, h).expect("step");
        let q = s.q.as_slice();
        let scale = q
            .iter()
            .enumerate()
            .filter(|(i, _)| i % 3 != 2)
            .fold(1.0f64, |a, (_, x)| a.max(x.abs()));
        sys.phi(q, s.t, &mut phi);
        sys.phi_dot(q, s.v.as_slice(), s.t, &mut phid);
        let amax = |v: &[f64]| v.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        worst_phi = worst_phi.max(amax(&phi) / (tol * scale));
        worst_phid = worst_phid.max(amax(&phid) / (tol * scale));
    }
    let err = (s.q[3 * body + 2] - exact.at(s.t)[0]).abs();
    let bits = s.q.iter().chain(s.v.iter()).map(|x| x.to_bits()).collect();
    (err, worst_phi, worst_phid, bits)
}

#[test]
fn both_variants_follow_the_exact_motion_at_order_four_and_keep_every_equation() {
    for (name, (sys, cl)) in [
        ("double parallelogram", double_parallelogram()),
        ("pantograph", pantograph()),
    ] {
        assert_eq!((sys.n_redundant(), sys.dof()), (1, 1), "{name}");
        for spec in ["firefly-gauss", "firefly-gauss:polish"] {
            let (e1, p1, v1, _) = run(&sys, &cl, &mut *registry_solver(spec, &sys), 1e-2);
            let (e2, p2, v2, _) = run(&sys, &cl, &mut *registry_solver(spec, &sys), 5e-3);
            let ratio = e1 / e2;
            eprintln!(
                "{name}, {spec}: errors {e1:.3e} {e2:.3e} (ratio {ratio:.2}, order {:.2}), \
                 max|Phi| / tol {:.2e}, max|Phidot| / tol {:.2e}",
                ratio.log2(),
                p1.max(p2),
                v1.max(v2)
            );
            // order 4: a halved step divides the error by 16. The polished variant is the
            // discretisation itself; the pure firefly adds the optimiser's error (a tenth of the
            // corrected predictor's), whose local ratios scatter around 16
            let want = if spec.contains("polish") { 12.0 } else { 5.0 };
            assert!(ratio > want, "{name}, {spec}: {e1:e} -> {e2:e}");
            assert!(e1 < 2e-7 && e2 < 2e-8, "{name}, {spec}: {e1:e} {e2:e}");
            // every equation, the redundant one too, at the Newton tolerance
            assert!(
                p1.max(p2) <= 1.0,
                "{name}, {spec}: |Phi| {p1:e} {p2:e} x tol"
            );
            // the velocities solve the rows in use to round-off; the row left out is their
            // combination only as far as the positions hold (|Phi| ~ tol), so its velocity
            // residual is a few times tol |v| (|v| about 1 m/s here)
            assert!(
                v1.max(v2) <= 10.0,
                "{name}, {spec}: |Phidot| {v1:e} {v2:e} x tol"
            );
        }
    }
}

#[test]
fn same_seed_same_bits_another_seed_another_path() {
    let (sys, cl) = pantograph();
    let o = FaDaeOptions::default().seed(11);
    let (_, _, _, a) = run(&sys, &cl, &mut *solver(&sys, o.clone()), 1e-2);
    let (_, _, _, b) = run(&sys, &cl, &mut *solver(&sys, o.clone()), 1e-2);
    assert_eq!(a, b, "same seed, same bits");
    let (_, _, _, r) = run(
        &sys,
        &cl,
        &mut *registry_solver("firefly-gauss:seed=11", &sys),
        1e-2,
    );
    assert_eq!(a, r, "the registry's solver, same bits");
    let parallel = o.clone().parallel(true);
    let (_, _, _, c) = run(&sys, &cl, &mut *solver(&sys, parallel), 1e-2);
    assert_eq!(a, c, "parallel evaluation, same bits");
    let (_, _, _, d) = run(&sys, &cl, &mut *solver(&sys, o.seed(12)), 1e-2);
    assert_ne!(a, d, "another seed takes another path");
    // the double parallelogram repartitions (a crank passes the vertical): the same bits too
    let (sys, cl) = double_parallelogram();
    let o = FaDaeOptions::polished().seed(5);
    let (_, _, _, a) = run(&sys, &cl, &mut *solver(&sys, o.clone()), 1e-2);
    let (_, _, _, b) = run(&sys, &cl, &mut *solver(&sys, o), 1e-2);
    assert_eq!(a, b, "same seed, same bits");
}

#[test]
fn auto_partition_names_the_rank_and_the_equations() {
    for (name, (sys, _)) in [
        ("double parallelogram", double_parallelogram()),
        ("pantograph", pantograph()),
    ] {
        let (q0, _) = sys.initial_guess();
        let p = Partition::auto(&sys, q0.as_slice(), 0.0).expect(name);
        let (n, m) = (sys.n_coords(), sys.n_constraints());
        let r = m - sys.n_redundant();
        assert_eq!(p.dof(), sys.dof(), "{name}");
        assert_eq!(p.dependent.len(), r, "{name}");
        assert_eq!(p.equations.len(), r, "{name}");
        assert_eq!(p.independent.len() + p.dependent.len(), n, "{name}");
        assert!(p.equations.windows(2).all(|w| w[0] < w[1]), "{name}");
        assert!(p.equations.iter().all(|&e| e < m), "{name}");
        // the solver starts from it and repartitions along the swing
        let fa = FireflyGauss::new(&sys, FaDaeOptions::default()).expect(name);
        assert_eq!(fa.partition(), &p, "{name}");
    }
}

#[test]
fn given_partition_checks_the_count_against_the_dof_and_runs() {
    let (sys, cl) = double_parallelogram();
    let (q0, _) = sys.initial_guess();
    // two indices, one degree of freedom (12 coordinates, 12 equations, one redundant)
    match Partition::given(&sys, q0.as_slice(), 0.0, &[2, 5]) {
        Err(FaDaeError::InvalidPartition { reason, .. }) => {
            assert!(reason.contains("1 degrees of freedom"), "{reason}");
            assert!(reason.contains("1 of them redundant"), "{reason}");
        }
        other => panic!("expected InvalidPartition, got {other:?}"),
    }
    // a coupler coordinate cannot be chosen: the coupler does not turn
    assert!(matches!(
        Partition::given(&sys, q0.as_slice(), 0.0, &[11]),
        Err(FaDaeError::InvalidPartition { .. })
    ));
    // the first crank's angle: eleven equations chosen for the other coordinates
    let p = Partition::given(&sys, q0.as_slice(), 0.0, &[2]).expect("crank angle");
    assert_eq!((p.dependent.len(), p.equations.len()), (11, 11));
    let opts = FaDaeOptions::polished().partition(PartitionChoice::Given(vec![2]));
    let (e, p, v, _) = run(&sys, &cl, &mut *solver(&sys, opts), 1e-2);
    assert!(e < 2e-7, "{e:e}");
    assert!(p <= 1.0 && v <= 10.0, "{p:e} {v:e}");
}

#[test]
fn a_rank_other_than_m_minus_k_is_an_error_naming_it() {
    let (sys, cl) = double_parallelogram();
    // flat (all links on the x-axis): rank 10 < 11, a singular configuration
    let (flat, _) = cl.branch_state(0.0, 0.0);
    match Partition::auto(&sys, &flat, 0.0) {
        Err(FaDaeError::Unsupported(msg)) => {
            assert!(msg.contains("rank deficient"), "{msg}");
            assert!(msg.contains("1 redundant"), "{msg}");
        }
        other => panic!("expected a rank-deficiency error, got {other:?}"),
    }
    // off the branch (the middle crank turned): the twelve rows are independent, the
    // redundancy found at build is gone
    let (mut q, _) = cl.branch_state(ANGLE, 0.0);
    q[5] += 0.3;
    match Partition::auto(&sys, &q, 0.0) {
        Err(FaDaeError::Unsupported(msg)) => {
            assert!(msg.contains("redundancy found at build is gone"), "{msg}");
            assert!(msg.contains("M.y") || msg.contains("M.x"), "{msg}");
        }
        other => panic!("expected the redundancy to be gone, got {other:?}"),
    }
}
