//! gamma_opt by the secant method on dW(gamma) against an independent reference
//! (mbd_solve::reference_trajectory: DOPRI5 + projection at h/32).
use mbd_model::models;
use mbd_solve::{reference_trajectory, ButcherTableau, State};
use mbd_symplectic::{
    calibrate_gamma, error_measures, CalibrationSettings, SymplecticError, SymplecticOptions,
};

#[test]
fn secant_calibration_on_the_double_pendulum() {
    let sys = models::paper_a_double_pendulum().unwrap();
    let s0 = State::consistent(&sys, 0.0).unwrap();
    let (h, n) = (0.04, 100);
    let reference = reference_trajectory(&sys, &s0, h, n, 32, ButcherTableau::dopri5()).unwrap();
    for s in [1usize, 2] {
        let cal = calibrate_gamma(
            &sys,
            &s0,
            h,
            n,
            &reference,
            &SymplecticOptions::new(s),
            CalibrationSettings::default(),
        )
        .unwrap();
        let dw0 = cal.history[0].1;
        let dw_opt = cal.measures.dw();
        println!(
            "s={s}: dW1 = {dw0:.6e}, dW2 = {:.6e}, gamma_opt = {:.6}, dW(gamma_opt) = {dw_opt:.3e}, iterations {}; reference {}",
            cal.history[1].1, cal.gamma_opt, cal.iterations, cal.reference_method
        );
        assert_eq!(cal.history[0].0, 0.0);
        assert_eq!(cal.history[1].0, 1.0);
        assert!(dw_opt.abs() <= 1e-6 * dw0.abs(), "s={s}: {dw_opt} vs {dw0}");
        assert!(cal.reference_method.contains("DOPRI5"));
        let e0 = error_measures(&sys, &s0, h, n, &reference, &SymplecticOptions::new(s)).unwrap();
        println!(
            "   E|dx| {:.3e} -> {:.3e}, E|dy| {:.3e} -> {:.3e}",
            e0.mean_abs_dx, cal.measures.mean_abs_dx, e0.mean_abs_dy, cal.measures.mean_abs_dy
        );
        assert!(e0.max_phi < 1e-12 && cal.measures.max_phi < 1e-12);
    }
}

#[test]
fn mismatched_reference_is_an_error() {
    let sys = models::paper_a_double_pendulum().unwrap();
    let s0 = State::consistent(&sys, 0.0).unwrap();
    let reference = reference_trajectory(&sys, &s0, 0.02, 10, 4, ButcherTableau::dopri5()).unwrap();
    let r = error_measures(&sys, &s0, 0.01, 10, &reference, &SymplecticOptions::new(1));
    assert!(matches!(r, Err(SymplecticError::Reference { .. })), "{r:?}");
    let r = error_measures(&sys, &s0, 0.02, 20, &reference, &SymplecticOptions::new(1));
    assert!(matches!(r, Err(SymplecticError::Reference { .. })), "{r:?}");
}
