//! The modified-Lagrangian preadjustment of the (2,2) scheme (`h^5 e4` at the chord midpoint,
//! `docs/symplectic.md` section 5b): the rod pendulum's period error falls with order 6 at
//! 45 degrees, where the plain (2,2) scheme's falls with order 4.
mod common;
use mbd_symplectic::{PreadjustMode, SymplecticOptions};

/// Relative period error of the (2,2) scheme on the rod (the quintic through six samples
/// locates each crossing).
fn period_error(theta0: f64, h: f64, modified: bool, periods: f64) -> f64 {
    let mut o = SymplecticOptions::new(2);
    if modified {
        o = o.with_preadjust(PreadjustMode::ModifiedLagrangian);
    }
    common::rod_period_error(theta0, h, o, periods, 6)
}

#[test]
fn pendulum_period_order_six_without_parameter() {
    let th = 45f64.to_radians();
    let (p1, p2) = (
        period_error(th, 0.1, false, 20.0),
        period_error(th, 0.05, false, 20.0),
    );
    let (m1, m2) = (
        period_error(th, 0.1, true, 20.0),
        period_error(th, 0.05, true, 20.0),
    );
    let (op, om) = ((p1 / p2).abs().log2(), (m1 / m2).abs().log2());
    eprintln!(
        "45 deg, (2,2): plain {p1:.3e} / {p2:.3e} (order {op:.2}); modified Lagrangian \
         {m1:.3e} / {m2:.3e} (order {om:.2})"
    );
    assert!((3.7..4.3).contains(&op), "plain order {op}");
    assert!(om >= 5.5, "modified-Lagrangian order {om}");
    assert!(m2.abs() < 0.05 * p2.abs(), "{m2} vs {p2}");
}

/// The first residual of a continuing step takes the `e4` gradients extrapolated from the last
/// four steps (`galerkin/modlag.rs`); every later residual evaluates them, so the accepted
/// steps are the same, to Newton's tolerance, as those of an integrator reset before every
/// step (no history: no extrapolation and the Taylor predictor).
#[test]
fn extrapolated_first_residual_does_not_change_the_steps() {
    use mbd_model::models;
    use mbd_solve::{Integrator, State};
    use mbd_symplectic::Galerkin;
    let sys = models::paper_a_double_pendulum().unwrap();
    let o = SymplecticOptions::new(2).with_preadjust(PreadjustMode::ModifiedLagrangian);
    let (mut a, mut b) = (
        Galerkin::new(&sys, o).unwrap(),
        Galerkin::new(&sys, o).unwrap(),
    );
    let mut sa = State::consistent(&sys, 0.0).unwrap();
    let mut sb = sa.clone();
    let mut worst = 0.0f64;
    for _ in 0..200 {
        a.step(&sys, &mut sa, 0.04).unwrap();
        b.reset();
        b.step(&sys, &mut sb, 0.04).unwrap();
        worst = worst.max(common::max_abs_diff(sa.q.as_slice(), sb.q.as_slice()));
    }
    eprintln!("200 steps: max |q_a - q_b| {worst:.2e}");
    assert!(worst < 1e-11, "{worst}");
}

/// Bad inputs of the (2,2) mode are typed errors: `gamma != 0`, a model with a damper, and
/// gradient buffers of the wrong length.
#[test]
fn typed_errors_s2() {
    use mbd_model::models;
    use mbd_solve::SolveError;
    use mbd_symplectic::{Galerkin, Preadjustment};
    let sys = models::paper_a_double_pendulum().unwrap();
    let o = SymplecticOptions::new(2).with_preadjust(PreadjustMode::ModifiedLagrangian);
    match Galerkin::new(&sys, o.with_gamma(0.5)) {
        Err(SolveError::InvalidParameter { parameter, .. }) => assert_eq!(parameter, "gamma"),
        other => panic!("expected InvalidParameter(gamma), got {other:?}"),
    }
    let damped = common::damped_spring_chain(3);
    match Galerkin::new(&damped, o) {
        Err(SolveError::Unsupported(msg)) => assert!(msg.contains("conservative"), "{msg}"),
        other => panic!("expected Unsupported, got {other:?}"),
    }
    let n = sys.n_coords();
    let (q, v) = (vec![0.1; n], vec![0.2; n]);
    let mut p = Preadjustment::new(&sys, 2).unwrap();
    let (mut gq, mut short) = (vec![0.0; n], vec![0.0; n - 1]);
    match p.modified_gradients_s2(&sys, &q, &v, &mut gq, &mut short) {
        Err(SolveError::Dimension {
            what,
            expected,
            got,
        }) => {
            assert_eq!((what, expected, got), ("de4/dv", n, n - 1))
        }
        other => panic!("expected Dimension, got {other:?}"),
    }
    assert!(matches!(
        p.modified_gradients_s2(&sys, &q, &v[..n - 1], &mut gq, &mut short),
        Err(SolveError::Dimension { .. })
    ));
}

/// `Preadjustment::new_sparse` (`S` held sparse) gives the dense workspace's `e4`, `e` (s = 1)
/// and their gradients at a generic state, to round-off, on a 30-link chain, a chain of
/// spatial rods and the spatial spring fixture (`S` over body blocks), and `W_s`'s value and
/// gradient for s = 1, 2, 3 (`Preadjustment::with_layout`); its dense Hessians are typed errors
/// (the measured differences are in `docs/symplectic.md` section 5b).
#[test]
fn sparse_workspace_matches_the_dense_one() {
    use mbd_model::{fixtures, models};
    use mbd_solve::SolveError;
    use mbd_symplectic::Preadjustment;
    for (name, sys) in [
        ("30-link chain", models::n_link_chain(30).unwrap()),
        ("spatial chain", models::spatial_chain(4).unwrap()),
        ("spatial springs", fixtures::spatial_springs()),
    ] {
        let (q, v) = generic_state(&sys);
        let [de, dg, de1, dg1] = sparse_minus_dense(&sys, &q, &v);
        eprintln!(
            "{name}: sparse - dense, relative: e4 {de:.1e}, its gradients {dg:.1e}; e (s = 1) \
             {de1:.1e}, its gradients {dg1:.1e}"
        );
        assert!(de < 1e-12 && dg < 1e-12, "{name}: e4 {de}, gradients {dg}");
        assert!(
            de1 < 1e-12 && dg1 < 1e-12,
            "{name}: e {de1}, gradients {dg1}"
        );
        // W_s on the sparse layout: its value and gradient are the dense workspace's
        for s in [1, 2, 3] {
            let mut sparse = Preadjustment::with_layout(&sys, s, true).unwrap();
            let mut dense = Preadjustment::new(&sys, s).unwrap();
            let (mut gs, mut gd) = (vec![0.0; q.len()], vec![0.0; q.len()]);
            let ws = sparse.gradient(&sys, &q, &mut gs).unwrap();
            let wd = dense.gradient(&sys, &q, &mut gd).unwrap();
            let scale = gd.iter().fold(wd.abs(), |a, x| a.max(x.abs()));
            let dw = (ws - wd).abs() / scale;
            let dgr = gs
                .iter()
                .zip(&gd)
                .fold(0.0f64, |a, (x, y)| a.max((x - y).abs()))
                / scale;
            eprintln!("{name}: W_{s} sparse - dense, relative: value {dw:.1e}, gradient {dgr:.1e}");
            assert!(dw < 1e-10 && dgr < 1e-10, "{name}, s = {s}: {dw}, {dgr}");
            // (the dense Hessians stay dense-only)
            let mut h = nalgebra::DMatrix::zeros(q.len(), q.len());
            match sparse.approximate_hessian(&sys, &q, &mut h) {
                Err(SolveError::Unsupported(msg)) => assert!(msg.contains("dense layout"), "{msg}"),
                other => panic!("expected Unsupported, got {other:?}"),
            }
        }
    }
}

/// A spatial body with a zero second moment (the disc top, `E_3 = 0`): the sparse layout
/// weights `S` by the regularised diagonal inverse mass (docs/spatial.md), the dense one by the
/// augmented `M_W^-1` (s = 1) or the same regularised diagonal (s = 2). Both agree to the
/// regularisation's level (about `eps / MASSLESS_REGULARISATION`, 2e-8, from the cancellation
/// in `Pi`; measured: `e4` 7.2e-13, its gradients 7.8e-10, `e` 8.4e-13, its gradients
/// 1.7e-10); a layout that dropped the massless director's weight would be off by order one.
#[test]
fn sparse_workspace_takes_a_massless_director() {
    let sys = mbd_model::models::heavy_top([0.25, 0.25, 0.5], 0.3, 20.0).unwrap();
    let (q, v) = generic_state(&sys);
    let [de, dg, de1, dg1] = sparse_minus_dense(&sys, &q, &v);
    eprintln!(
        "disc top: sparse - dense, relative: e4 {de:.1e}, its gradients {dg:.1e}; e (s = 1) \
         {de1:.1e}, its gradients {dg1:.1e}"
    );
    assert!(de < 1e-8 && dg < 1e-8, "e4 {de}, gradients {dg}");
    assert!(de1 < 1e-8 && dg1 < 1e-8, "e {de1}, gradients {dg1}");
}

/// A configuration on the constraint manifold after 0.3 s of the plain (2,2) scheme, with a
/// velocity that is not tangent (the terms are evaluated at chords).
fn generic_state(sys: &mbd_model::System) -> (Vec<f64>, Vec<f64>) {
    let s0 = mbd_solve::State::consistent(sys, 0.0).unwrap();
    let (st, _) = common::run(sys, &s0, SymplecticOptions::new(2), 0.01, 30);
    let v = (0..sys.n_coords())
        .map(|i| st.v[i] + 0.05 * ((i as f64) * 0.7).sin())
        .collect();
    (st.q.as_slice().to_vec(), v)
}

/// The relative differences between the sparse and the dense workspace at `(q, v)`: `e4`, its
/// gradients (of their largest entry), `e` (s = 1) and its gradients.
fn sparse_minus_dense(sys: &mbd_model::System, q: &[f64], v: &[f64]) -> [f64; 4] {
    use mbd_symplectic::Preadjustment;
    let n = q.len();
    let (mut dense, mut sparse) = (
        Preadjustment::new(sys, 1).unwrap(),
        Preadjustment::new_sparse(sys).unwrap(),
    );
    let (mut gqd, mut gvd, mut gqs, mut gvs) =
        (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let rel = |ed: f64, es: f64, gd: (&[f64], &[f64]), gs: (&[f64], &[f64])| {
        let scale = gd.0.iter().chain(gd.1).fold(0.0f64, |a, x| a.max(x.abs()));
        assert!(ed.abs() > 0.0 && scale > 0.0);
        let dg = common::max_abs_diff(gd.0, gs.0).max(common::max_abs_diff(gd.1, gs.1));
        [(ed - es).abs() / ed.abs(), dg / scale]
    };
    let ed = dense
        .modified_gradients_s2(sys, q, v, &mut gqd, &mut gvd)
        .unwrap();
    let es = sparse
        .modified_gradients_s2(sys, q, v, &mut gqs, &mut gvs)
        .unwrap();
    let [de, dg] = rel(ed, es, (&gqd, &gvd), (&gqs, &gvs));
    let e1d = dense
        .modified_gradients(sys, q, v, &mut gqd, &mut gvd)
        .unwrap();
    let e1s = sparse
        .modified_gradients(sys, q, v, &mut gqs, &mut gvs)
        .unwrap();
    let [de1, dg1] = rel(e1d, e1s, (&gqd, &gvd), (&gqs, &gvs));
    [de, dg, de1, dg1]
}
