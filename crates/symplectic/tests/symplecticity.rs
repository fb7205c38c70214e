//! Symplecticity of the one-step map on the reduced phase space (finite differences through the
//! constrained step), the phase error of the linearised pendulum (orders 2s with gamma = 0 and
//! 2s + 2 with gamma = 1) and the measured phase constants behind kappa_s.
mod common;
use common::reduced::{chain_q, jacobian, symplecticity_defect};
use mbd_model::models;
use mbd_symplectic::{kappa, phase_constant};
use nalgebra::DMatrix;
use std::f64::consts::FRAC_PI_2;

#[test]
fn pendulum_map_preserves_area() {
    let sys = models::pendulum(1.0, 1.0, 1.0, 9.81).unwrap();
    for s in 1..=4 {
        let z = [-FRAC_PI_2 + 1.0, 0.7];
        let j = jacobian(&sys, common::tight(s), 0.1, &z, 1e-5);
        let det = j.determinant();
        println!("pendulum s={s}: det J - 1 = {:.3e}", det - 1.0);
        assert!((det - 1.0).abs() < 1e-9, "s={s}: det = {det}");
    }
}

#[test]
fn double_pendulum_map_is_symplectic() {
    let sys = models::paper_a_double_pendulum().unwrap();
    for (s, gamma) in [(1, 0.0), (2, 0.0), (3, 0.0), (2, 1.0)] {
        let z = [-FRAC_PI_2 + 0.5, -FRAC_PI_2 + 0.9, 0.3, -0.2];
        let opts = common::tight(s).with_gamma(gamma);
        let j = jacobian(&sys, opts, 0.04, &z, 1e-5);
        let defect = symplecticity_defect(&j);
        println!("double pendulum s={s} gamma={gamma}: |J^T Omega J - Omega| = {defect:.3e}");
        assert!(defect < 1e-8, "s={s} gamma={gamma}: {defect}");
    }
}

/// Relative frequency error of the linearised rod pendulum: the eigenvalue angle of the
/// one-step map's Jacobian at the hanging equilibrium (central differences of amplitude 1e-5).
fn frequency_error(s: usize, gamma: f64, omega_h: f64) -> f64 {
    let sys = models::pendulum(1.0, 1.0, 0.0, 9.81).unwrap();
    let omega = (1.5f64 * 9.81).sqrt();
    let h = omega_h / omega;
    let j = jacobian(
        &sys,
        common::tight(s).with_gamma(gamma),
        h,
        &[-FRAC_PI_2, 0.0],
        1e-5,
    );
    let angle = (0.5 * j.trace()).acos();
    angle / omega_h - 1.0
}

#[test]
fn phase_error_orders_and_constants() {
    let xs = [0.8, 0.8 / 2f64.sqrt(), 0.4];
    for (s, gamma, order) in [(1, 0.0, 2.0), (2, 0.0, 4.0), (1, 1.0, 4.0), (2, 1.0, 6.0)] {
        let es: Vec<f64> = xs.iter().map(|&x| frequency_error(s, gamma, x)).collect();
        let p = common::slope(&xs, &es.iter().map(|e| e.abs()).collect::<Vec<_>>());
        println!("s={s} gamma={gamma}: relative frequency errors {es:?}, order {p:.3}");
        assert!(
            (p - order).abs() < 0.3,
            "s={s} gamma={gamma}: phase order {p}"
        );
    }
    // the measured constants behind kappa_s: c_s = -kappa_s / 2 (numerical motion runs fast)
    for (s, x) in [(1, 0.1), (2, 0.2), (3, 0.5)] {
        let e = frequency_error(s, 0.0, x);
        let c = e / f64::powi(x, 2 * s as i32);
        println!(
            "s={s}: measured c_s = {c:.6e}, predicted {:.6e} (kappa_s = {:.6e})",
            phase_constant(s),
            kappa(s)
        );
        assert!((c / phase_constant(s) - 1.0).abs() < 0.03, "s={s}: c = {c}");
    }
}

/// Both normal modes of the double pendulum (small amplitude) have the same phase constant
/// c_s = -kappa_s / 2: all their stiffness comes from the constraint curvature, which the scheme
/// integrates with the Lobatto weights. So one gamma cancels the leading phase error of both.
#[test]
fn double_pendulum_modes_share_the_phase_constant() {
    let sys = models::paper_a_double_pendulum().unwrap();
    let g = 9.81;
    let eq = [-FRAC_PI_2, -FRAC_PI_2];
    let (_, t) = chain_q(&eq);
    let m = DMatrix::from_diagonal(sys.mass_diag());
    let mr = t.transpose() * &m * &t;
    let kr = DMatrix::from_row_slice(2, 2, &[1.5 * g, 0.0, 0.0, 0.5 * g]);
    // omega^2: eigenvalues of M_r^-1 K_r (symmetric form L^-1 K L^-T)
    let l = mr.clone().cholesky().unwrap().l();
    let li = l.clone().try_inverse().unwrap();
    let sym = &li * &kr * li.transpose();
    let mut w2: Vec<f64> = sym.symmetric_eigenvalues().iter().copied().collect();
    w2.sort_by(f64::total_cmp);
    let omega: Vec<f64> = w2.iter().map(|x| x.sqrt()).collect();
    for (s, gamma, h) in [
        (1, 0.0, 0.02),
        (2, 0.0, 0.05),
        (1, 1.0, 0.02),
        (2, 1.0, 0.05),
    ] {
        let z = [eq[0], eq[1], 0.0, 0.0];
        let j = jacobian(&sys, common::tight(s).with_gamma(gamma), h, &z, 1e-6);
        let mut ang: Vec<f64> = j
            .complex_eigenvalues()
            .iter()
            .map(|c| c.im.atan2(c.re).abs())
            .collect();
        ang.sort_by(f64::total_cmp);
        ang.dedup_by(|a, b| (*a - *b).abs() < 1e-9);
        let mut line = format!("s={s} gamma={gamma} h={h}:");
        for (k, w) in omega.iter().enumerate() {
            let e = ang[k] / (w * h) - 1.0;
            let c = e / (w * h).powi(2 * s as i32);
            line += &format!(
                " mode {k} (omega = {w:.4}): rel. freq. error {e:.3e}, /(omega h)^2s = {c:.4e};"
            );
            if gamma == 0.0 {
                assert!((c / phase_constant(s) - 1.0).abs() < 0.05, "{line}");
            } else {
                assert!(c.abs() < 0.1 * phase_constant(s), "{line}");
            }
        }
        println!("{line}");
    }
}
