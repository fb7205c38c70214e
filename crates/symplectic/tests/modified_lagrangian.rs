//! The parameter-free modified-Lagrangian preadjustment of the (1,1) scheme:
//! pendulum period error of order 4 at 45 and 90 degrees (plain: order 2), paper A's double
//! pendulum against a DOPRI5 reference, constraints over a long run, typed errors.
mod common;
use mbd_model::{models, System};
use mbd_solve::{reference_trajectory, ButcherTableau, Integrator, SolveError, State};
use mbd_symplectic::{Galerkin, PreadjustMode, SymplecticOptions};

fn opts(modlag: bool) -> SymplecticOptions {
    let o = SymplecticOptions::new(1);
    if modlag {
        o.with_preadjust(PreadjustMode::ModifiedLagrangian)
    } else {
        o
    }
}

/// Relative period error of the (1,1) scheme on the rod (the cubic through four samples locates
/// each crossing).
fn period_error(theta0: f64, h: f64, modlag: bool, periods: f64) -> f64 {
    common::rod_period_error(theta0, h, opts(modlag), periods, 4)
}

#[test]
fn pendulum_period_order_four_without_parameter() {
    for deg in [45.0f64, 90.0] {
        let th = deg.to_radians();
        let (p1, p2) = (
            period_error(th, 0.1, false, 20.0),
            period_error(th, 0.05, false, 20.0),
        );
        let (m1, m2) = (
            period_error(th, 0.1, true, 40.0),
            period_error(th, 0.05, true, 40.0),
        );
        let (op, om) = ((p1 / p2).abs().log2(), (m1 / m2).abs().log2());
        eprintln!(
            "{deg} deg: plain {p1:.3e} / {p2:.3e} (order {op:.2}); modified Lagrangian \
             {m1:.3e} / {m2:.3e} (order {om:.2})"
        );
        assert!((1.8..2.3).contains(&op), "plain order {op} at {deg} deg");
        assert!(om >= 3.5, "modified-Lagrangian order {om} at {deg} deg");
        assert!(m1.abs() < 0.05 * p1.abs(), "{m1} vs {p1} at {deg} deg");
    }
}

fn mean_abs_errors(
    sys: &System,
    modlag: bool,
    h: f64,
    n: usize,
    reference: &[Vec<f64>],
) -> (f64, f64) {
    let mut st = State::consistent(sys, 0.0).unwrap();
    let mut sch = Galerkin::new(sys, opts(modlag)).unwrap();
    let nb = sys.n_coords() / 3;
    let (mut ex, mut ey) = (0.0, 0.0);
    for r in reference.iter().skip(1).take(n) {
        sch.step(sys, &mut st, h).unwrap();
        for b in 0..nb {
            ex += (st.q[3 * b] - r[3 * b]).abs();
            ey += (st.q[3 * b + 1] - r[3 * b + 1]).abs();
        }
    }
    let c = (n * nb) as f64;
    (ex / c, ey / c)
}

#[test]
fn double_pendulum_errors_fall_fifty_fold() {
    let sys = models::paper_a_double_pendulum().unwrap();
    let s0 = State::consistent(&sys, 0.0).unwrap();
    let (h, n) = (0.04, 500); // 20 s
    let reference = reference_trajectory(&sys, &s0, h, n, 64, ButcherTableau::dopri5()).unwrap();
    assert_eq!(reference.q.len(), n + 1);
    let (px, py) = mean_abs_errors(&sys, false, h, n, &reference.q);
    let (mx, my) = mean_abs_errors(&sys, true, h, n, &reference.q);
    eprintln!(
        "double pendulum, h = 0.04, 20 s: E|dx| {px:.4e} -> {mx:.4e} ({:.0}x), E|dy| {py:.4e} -> \
         {my:.4e} ({:.0}x)",
        px / mx,
        py / my
    );
    assert!(mx * 50.0 < px, "E|dx| {mx} vs plain {px}");
    assert!(my * 50.0 < py, "E|dy| {my} vs plain {py}");
}

#[test]
fn constraints_stay_at_tolerance() {
    let sys = models::paper_a_double_pendulum().unwrap();
    let mut st = State::consistent(&sys, 0.0).unwrap();
    let mut sch = Galerkin::new(&sys, opts(true)).unwrap();
    let h0 = sys.energy(st.q.as_slice(), st.v.as_slice());
    let m = sys.n_constraints();
    let (mut phi, mut worst, mut dh) = (vec![0.0; m], 0.0f64, 0.0f64);
    let mut gq = nalgebra::DMatrix::zeros(m, sys.n_coords());
    let mut worst_v = 0.0f64;
    for _ in 0..3000 {
        sch.step(&sys, &mut st, 0.04).unwrap();
        sys.phi(st.q.as_slice(), st.t, &mut phi);
        worst = phi.iter().fold(worst, |a, &b| a.max(b.abs()));
        sys.phi_q(st.q.as_slice(), 0.0, &mut gq);
        let gv = &gq * &st.v;
        worst_v = gv.iter().fold(worst_v, |a, &b| a.max(b.abs()));
        dh = dh.max((sys.energy(st.q.as_slice(), st.v.as_slice()) - h0).abs());
    }
    eprintln!("3000 steps: max |Phi| {worst:.2e}, max |Phi_q v| {worst_v:.2e}, max |dH| {dh:.2e}");
    assert!(worst < 1e-12, "max |Phi| = {worst}");
    assert!(worst_v < 1e-11, "max |Phi_q v| = {worst_v}");
    // no drift: the energy error stays bounded (of the order of the scheme's h^2 oscillation)
    assert!(dh < 1e-2, "max |dH| = {dh}");
}

#[test]
fn typed_errors() {
    let sys = models::paper_a_double_pendulum().unwrap();
    let bad_s = SymplecticOptions::new(3).with_preadjust(PreadjustMode::ModifiedLagrangian);
    match Galerkin::new(&sys, bad_s) {
        Err(SolveError::InvalidParameter { parameter, .. }) => assert_eq!(parameter, "preadjust"),
        other => panic!("expected InvalidParameter(preadjust), got {other:?}"),
    }
    let bad_gamma = opts(true).with_gamma(1.0);
    match Galerkin::new(&sys, bad_gamma) {
        Err(SolveError::InvalidParameter { parameter, .. }) => assert_eq!(parameter, "gamma"),
        other => panic!("expected InvalidParameter(gamma), got {other:?}"),
    }
    // the sparse stage solve takes the modified Lagrangian and the paper's W_s
    let sparse = |o: SymplecticOptions| SymplecticOptions {
        linear_solver: mbd_solve::LinearSolver::Sparse,
        ..o
    };
    assert!(Galerkin::new(&sys, sparse(opts(true))).is_ok_and(|g| g.is_sparse()));
    assert!(
        Galerkin::new(&sys, sparse(SymplecticOptions::new(1).with_gamma(1.0)))
            .is_ok_and(|g| g.is_sparse())
    );
}

/// Work of a step, printed for the docs (no wall-clock assertion): Newton iterations and
/// residual evaluations per step, plain vs modified Lagrangian, and the elapsed-time ratio.
#[test]
fn step_cost_report() {
    let sys = models::paper_a_double_pendulum().unwrap();
    let mut out = Vec::new();
    for modlag in [false, true] {
        let mut st = State::consistent(&sys, 0.0).unwrap();
        let mut sch = Galerkin::new(&sys, opts(modlag)).unwrap();
        let (mut it, mut ev) = (0usize, 0usize);
        let t0 = std::time::Instant::now();
        for _ in 0..2000 {
            let s = sch.step(&sys, &mut st, 0.04).unwrap();
            it += s.newton_iterations;
            ev += s.rhs_evals;
        }
        let dt = t0.elapsed().as_secs_f64();
        eprintln!(
            "modified Lagrangian {modlag}: {:.2} Newton iterations, {:.2} residuals, {:.2} \
             Jacobians per step, {:.2} us per step",
            it as f64 / 2000.0,
            ev as f64 / 2000.0,
            sch.jacobian_count() as f64 / 2000.0,
            dt / 2000.0 * 1e6
        );
        out.push((it, dt));
    }
    eprintln!("cost ratio (time): {:.2}", out[1].1 / out[0].1);
    // the omitted Jacobian terms are O(h^2) smaller: Newton converges in a few iterations
    // (measured 3.79 against 2.86 per step)
    assert!(
        out[1].0 <= 2 * out[0].0,
        "iterations {} vs {}",
        out[1].0,
        out[0].0
    );
}
