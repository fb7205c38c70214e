//! Unit tests of the stage equations (Jacobian, singular stage matrices, pivots).

use super::*;
use mbd_model::models;
use mbd_solve::LinearSolver;

/// The analytic Jacobian against central differences of the residual, at a point off the
/// solution (random-ish unknowns), for several s and models.
fn check_jacobian(sys: &System, s: usize, gamma: f64, solver: LinearSolver) {
    let st = State::consistent(sys, 0.0).unwrap();
    let mut st = st;
    for i in 0..st.v.len() {
        st.v[i] += 0.3 * ((i as f64) * 1.7).sin();
    }
    let h = 0.05;
    let opts = SymplecticOptions {
        linear_solver: solver,
        ..SymplecticOptions::new(s).with_gamma(gamma)
    };
    let mut g = Galerkin::new(sys, opts).unwrap();
    assert_eq!(g.is_sparse(), solver == LinearSolver::Sparse);
    g.qk.copy_from_slice(st.q.as_slice());
    for i in 0..g.n {
        g.hvk[i] = h * st.v[i];
    }
    g.start_phiq(sys, st.t, false);
    g.gk = gamma * g.kappa * h.powi(2 * s as i32);
    g.predict(sys, &st, h).unwrap();
    for i in 0..g.dim {
        g.x[i] += 1e-3 * ((i as f64) * 0.77).cos();
    }
    g.residual(sys, 0.0, h).unwrap();
    // analytic, unfactored: rebuild by solving with unit vectors is awkward; instead compare
    // J * e_k via the LU: J^{-1} (FD column) = e_k
    g.jacobian(sys, 0.0, h).unwrap();
    let x0 = g.x.clone();
    let dim = g.dim;
    let mut worst: f64 = 0.0;
    for k in 0..dim {
        let d = 1e-6;
        g.x.copy_from_slice(&x0);
        g.x[k] += d;
        g.residual(sys, 0.0, h).unwrap();
        let rp = g.r.clone();
        g.x[k] -= 2.0 * d;
        g.residual(sys, 0.0, h).unwrap();
        let mut col: Vec<f64> = rp
            .iter()
            .zip(&g.r)
            .map(|(a, b)| (a - b) / (2.0 * d))
            .collect();
        g.solve_stage(&mut col);
        for (i, c) in col.iter().enumerate() {
            let e = if i == k { 1.0 } else { 0.0 };
            worst = worst.max((c - e).abs());
        }
    }
    // (the chain's 5 links amplify the differences' noise: 1.3e-6 at s = 3 on both paths)
    let tolerance = if gamma != 0.0 {
        1e-2
    } else if sys.n_coords() > 9 {
        1e-5
    } else {
        1e-6
    };
    assert!(
        worst < tolerance,
        "s={s} gamma={gamma}: J^-1 J_fd - I = {worst:e}"
    );
}

include!("../../tests/common/damped.rs");

#[test]
fn jacobian_matches_finite_differences() {
    let sys = models::manipulator().unwrap();
    for s in 1..=4 {
        check_jacobian(&sys, s, 0.0, LinearSolver::Dense);
        check_jacobian(&sys, s, 0.0, LinearSolver::Sparse);
    }
    check_jacobian(&sys, 2, 1.0, LinearSolver::Dense);
    let sc = models::slider_crank().unwrap();
    check_jacobian(&sc, 2, 0.0, LinearSolver::Dense);
    check_jacobian(&sc, 3, 0.0, LinearSolver::Sparse);
    // force elements (a spring-damper and a driving torque: stiffness and damping Hessians
    // by coloured central differences on the sparse path)
    let sq = models::andrews_squeezer().unwrap();
    assert!(!sq.forces().is_empty());
    let dc = damped_spring_chain(4);
    assert!(!dc.is_conservative());
    for s in 1..=2 {
        for sys in [&sq, &dc] {
            check_jacobian(sys, s, 0.0, LinearSolver::Dense);
            check_jacobian(sys, s, 0.0, LinearSolver::Sparse);
        }
    }
    // the sparse assembly (coloured curvature seeds) on a chain with a free end
    let chain = models::n_link_chain(5).unwrap();
    for s in 1..=3 {
        check_jacobian(&chain, s, 0.0, LinearSolver::Dense);
        check_jacobian(&chain, s, 0.0, LinearSolver::Sparse);
    }
}

/// A stage matrix that is singular (a slider-crank with crank = rod at the dead point,
/// where the slider's constraint rows lose rank) is reported as singular at every h, with
/// the unknown and the equation named, on the dense and the sparse path; the same mechanism
/// off the dead point is not.
#[test]
fn singular_stage_matrix_is_reported() {
    use mbd_model::models::{slider_crank_with, SliderCrankParams};
    let r = 0.3;
    let sys = slider_crank_with(&SliderCrankParams {
        crank: r,
        rod: r,
        ..Default::default()
    })
    .unwrap();
    let half_pi = std::f64::consts::FRAC_PI_2;
    // crank up, rod down, slider on the crank pivot
    let dead = [0.0, 0.5 * r, half_pi, 0.0, 0.5 * r, -half_pi, 0.0, 0.0, 0.0];
    let st = State::consistent(&sys, 0.0).unwrap();
    let solvers = [LinearSolver::Dense, LinearSolver::Sparse];
    for (s, solver) in (1..=3).flat_map(|s| solvers.map(|v| (s, v))) {
        for h in [1e-7, 1e-3, 1e-1] {
            let opts = SymplecticOptions {
                linear_solver: solver,
                ..SymplecticOptions::new(s)
            };
            let mut g = Galerkin::new(&sys, opts).unwrap();
            assert_eq!(g.is_sparse(), solver == LinearSolver::Sparse);
            for (q, at_dead) in [(st.q.as_slice(), false), (&dead[..], true)] {
                g.qk.copy_from_slice(q);
                g.hvk.fill(0.0);
                g.start_phiq(&sys, 0.0, false);
                g.x.fill(0.0);
                g.residual(&sys, 0.0, h).unwrap();
                match (g.jacobian(&sys, 0.0, h), at_dead) {
                    (Ok(()), false) => {}
                    (Err(SolveError::Singular { detail, .. }), true) => {
                        assert!(
                            detail.contains("multiplier of") || detail.contains("constraint"),
                            "s = {s}, h = {h}: {detail}"
                        );
                    }
                    (other, _) => {
                        panic!("s = {s}, {solver:?}, h = {h}, dead point {at_dead}: {other:?}")
                    }
                }
            }
        }
    }
}

/// On the manipulator and the slider-crank the static pivots of the coordinate-blocked
/// ordering pass the pivot tests at every step, from h = 0.01 down to h = 1e-6 (the general
/// path is a guard, not the normal path), and at the usual steps without the scale factors
/// of the equilibration (`docs/symplectic.md` section 2 says from which h on they are needed).
#[test]
fn static_pivots_are_used() {
    for sys in [
        models::manipulator().unwrap(),
        models::slider_crank().unwrap(),
    ] {
        let s0 = State::consistent(&sys, 0.0).unwrap();
        for s in 1..=3 {
            for h in [1e-2, 1e-4, 1e-6] {
                let mut g = Galerkin::new(&sys, SymplecticOptions::new(s)).unwrap();
                let mut st = s0.clone();
                for _ in 0..200 {
                    g.step(&sys, &mut st, h).unwrap();
                }
                assert_eq!(g.lu.fallbacks(), 0, "s = {s}, h = {h}");
                // the scale factors are needed only for pivots near the singular test's
                // threshold: at h = 1e-6 for s >= 2, not at the usual steps
                if h >= 1e-4 {
                    assert_eq!(g.lu.equilibrations(), 0, "s = {s}, h = {h}");
                }
            }
        }
    }
}

/// The s = 2 modified Lagrangian with every kind of spatial potential (springs between two
/// bars, to ground and to a free point mass, and a constant force: `fixtures::spatial_springs`)
/// over 0.5 s: plain (2,2) order 4 and modified (2,2) order 6 (fitted slopes within 0.3 at
/// h = 1e-2, 5e-3, 2.5e-3 against (4,4) at h/16), the modified one more than 1000x closer to the
/// reference at the smallest step, and the constraints at round-off.
#[test]
fn the_s2_modified_lagrangian_takes_every_spatial_potential() {
    use mbd_solve::{run, NoObserver, RunConfig};
    let sys = mbd_model::fixtures::spatial_springs();
    let end = |opts: SymplecticOptions, h: f64| {
        let mut g = Galerkin::new(&sys, opts).unwrap();
        let mut st = State::consistent(&sys, 0.0).unwrap();
        run(
            &mut g,
            &sys,
            &mut st,
            RunConfig::new(0.5, h),
            &mut NoObserver,
        )
        .unwrap();
        let mut phi = vec![0.0; sys.n_constraints()];
        sys.phi(st.q.as_slice(), st.t, &mut phi);
        assert!(phi.iter().all(|p| p.abs() < 1e-12), "{phi:?}");
        st
    };
    let hs = [1e-2, 5e-3, 2.5e-3];
    let reference = end(SymplecticOptions::new(4), hs[0] / 16.0);
    let errors = |opts: SymplecticOptions| -> Vec<f64> {
        hs.iter()
            .map(|&h| (&end(opts, h).q - &reference.q).amax())
            .collect()
    };
    let plain = errors(SymplecticOptions::new(2));
    let modified =
        errors(SymplecticOptions::new(2).with_preadjust(PreadjustMode::ModifiedLagrangian));
    let orders = |e: &[f64]| -> Vec<f64> { e.windows(2).map(|w| (w[0] / w[1]).log2()).collect() };
    let (po, mo) = (orders(&plain), orders(&modified));
    eprintln!("plain {plain:?} {po:.2?}; modified {modified:?} {mo:.2?}");
    assert!(po.iter().all(|p| (p - 4.0).abs() < 0.3), "{po:?}");
    assert!(mo.iter().all(|p| (p - 6.0).abs() < 0.3), "{mo:?}");
    assert!(plain[2] > 1e3 * modified[2], "{plain:?} {modified:?}");
}
