//! The spatial rows' Hessians at a time `t`, an angle driver's included (its equation turns
//! with `theta(t)`): against central differences of `Phi_q`, and the Hessian-vector products
//! against the assembled weighted Hessian.

use mbd_model::System;
use nalgebra::DMatrix;

/// `examples/models/driven_arm.toml`: an arm turned by a spatial angle driver from the
/// ground (`theta = 3 t`), a pendulum on a ball joint at its tip and a forearm on a hinge there,
/// driven against the arm (`theta = 0.5 sin 2t`): a driver between two moving bodies, whose
/// equation is bilinear in their directors.
fn driven_arm() -> System {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples/models/driven_arm.toml");
    System::from_path(path).expect("the driven-arm example loads")
}

/// A configuration near the initial one (the Hessians are constant in `q`, so any point
/// checks them; off the manifold on purpose).
fn perturbed(sys: &System) -> Vec<f64> {
    let (q, _) = sys.initial_guess();
    q.iter()
        .enumerate()
        .map(|(i, x)| x + 0.03 * ((i as f64) * 0.37).sin())
        .collect()
}

#[test]
fn row_hessians_at_t_match_differences_of_phi_q() {
    let sys = driven_arm();
    assert!(sys.jacobian_depends_on_time());
    let q = perturbed(&sys);
    let (n, m) = (sys.n_coords(), sys.n_constraints());
    for t in [0.0, 0.4, 1.3] {
        // column c of every row's Hessian: (Phi_q(q + d e_c) - Phi_q(q - d e_c)) / 2d (exact
        // up to rounding: Phi_q is affine in q)
        let d = 1e-4;
        let mut fd = vec![DMatrix::<f64>::zeros(n, n); m];
        let (mut gp, mut gm) = (DMatrix::zeros(m, n), DMatrix::zeros(m, n));
        for c in 0..n {
            let (mut qp, mut qm) = (q.clone(), q.clone());
            qp[c] += d;
            qm[c] -= d;
            sys.phi_q(&qp, t, &mut gp);
            sys.phi_q(&qm, t, &mut gm);
            for (r, h) in fd.iter_mut().enumerate() {
                for i in 0..n {
                    h[(i, c)] = (gp[(r, i)] - gm[(r, i)]) / (2.0 * d);
                }
            }
        }
        let mut checked_driver = false;
        for (r, want) in fd.iter().enumerate() {
            let mut got = DMatrix::<f64>::zeros(n, n);
            sys.spatial_row_hessian_at(&q, t, r, |i, j, h| got[(i, j)] += h);
            let err = (&got - want).amax();
            assert!(
                err < 1e-9 * (1.0 + want.amax()),
                "row {r} ({}) at t = {t}: Hessian off by {err:e}",
                sys.equation_name(r)
            );
            if sys.spatial_row_hessian(&q, r).is_none() && want.amax() > 0.1 {
                checked_driver = true;
            }
        }
        assert!(checked_driver, "the angle driver's row was checked");
    }
}

#[test]
fn hessian_vector_products_at_t_match_the_assembled_hessian() {
    let sys = driven_arm();
    let q = perturbed(&sys);
    let (n, m) = (sys.n_coords(), sys.n_constraints());
    let w: Vec<f64> = (0..m).map(|r| 1.0 + 0.1 * r as f64).collect();
    let x: Vec<f64> = (0..n).map(|i| ((i as f64) * 0.71).cos()).collect();
    for t in [0.0, 0.9] {
        let mut h = DMatrix::zeros(n, n);
        sys.add_spatial_constraint_hessian(&q, t, &w, 1.0, &mut h);
        let want = &h * nalgebra::DVector::from_column_slice(&x);
        let mut got = vec![0.0; n];
        sys.add_spatial_hessian_vector(&q, t, &x, &w, 1.0, &mut got);
        let err = want
            .iter()
            .zip(&got)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(err < 1e-12 * (1.0 + want.amax()), "t = {t}: off by {err:e}");
    }
}
