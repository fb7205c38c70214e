//! The modified-Lagrangian (1,1) step is a symplectic map of the constrained phase space
//! (its long run is in `long_run.rs`).
//!
//! The Jacobian of one step is taken by central differences in the reduced coordinates of the
//! double pendulum (joint angles and their conjugate momenta `p_theta = T^T M v`, a chart of the
//! constrained phase space: every perturbed state is consistent by construction, and the result
//! is read back in the same chart), with the machinery of `symplecticity.rs` (`common::reduced`).
//! The same check is shown to fail for non-symplectic maps: the projected index-1 RK4 step and
//! the scheme with its end momentum scaled by `1 + 1e-6`.
mod common;
use common::reduced::{jacobian, jacobian_of, reduced_map, reduced_step, symplecticity_defect};
use mbd_model::models;
use mbd_solve::{ButcherTableau, Index1Options, Index1Rk, Integrator, State};
use mbd_symplectic::{Galerkin, PreadjustMode, SymplecticOptions};
use std::f64::consts::FRAC_PI_2;

/// What central differences of step 1e-5 resolve here: the plain and modified schemes measure
/// 1e-11..5e-11 (truncation `~d^2 |f'''|` and round-off `~eps / d`); a map that scales the
/// momentum by `1 + 1e-6` measures 1e-6.
const TOL: f64 = 1e-9;

fn modified() -> SymplecticOptions {
    common::tight(1).with_preadjust(PreadjustMode::ModifiedLagrangian)
}

/// Two generic states of the double pendulum (angles from the downward vertical 0.5/0.9 and
/// -1.1/0.4 rad, non-zero momenta), as `(theta_1, theta_2, p_1, p_2)`.
const STATES: [[f64; 4]; 2] = [
    [-FRAC_PI_2 + 0.5, -FRAC_PI_2 + 0.9, 0.3, -0.2],
    [-FRAC_PI_2 - 1.1, -FRAC_PI_2 + 0.4, -0.8, 0.5],
];

#[test]
fn modified_lagrangian_step_is_symplectic() {
    let sys = models::paper_a_double_pendulum().unwrap();
    for z in STATES {
        for h in [0.04, 0.1] {
            let plain = symplecticity_defect(&jacobian(&sys, common::tight(1), h, &z, 1e-5));
            let j = jacobian(&sys, modified(), h, &z, 1e-5);
            let defect = symplecticity_defect(&j);
            // the map is not the identity: the check has something to test
            let moved = (&j - nalgebra::DMatrix::identity(4, 4)).abs().max();
            println!(
                "z = {z:?}, h = {h}: |J^T Omega J - Omega| modified {defect:.3e} (plain \
                 {plain:.3e}), |J - I| = {moved:.3e}"
            );
            assert!(moved > 1e-2, "{moved}");
            assert!(defect < TOL, "z = {z:?}, h = {h}: defect {defect}");
        }
    }
}

#[test]
fn the_check_fails_for_non_symplectic_maps() {
    let sys = models::paper_a_double_pendulum().unwrap();
    let z = STATES[0];
    let h = 0.04;
    // (1) RK4 on the index-1 form with projection: accurate (O(h^4)) but not symplectic
    let mut rk4 = Index1Rk::new(&sys, ButcherTableau::rk4(), Index1Options::default()).unwrap();
    let j = jacobian_of(&z, 1e-5, &mut |z| {
        reduced_map(&sys, z, &mut |sys, st: &mut State| {
            rk4.step(sys, st, h).unwrap();
        })
    });
    let d_rk4 = symplecticity_defect(&j);
    // (2) the modified-Lagrangian step with its end momentum scaled by 1 + 1e-6 (still on the
    // velocity constraint, which is linear in v): J^T Omega J = (1 + 1e-6) Omega
    let j = jacobian_of(&z, 1e-5, &mut |z| {
        let mut g = Galerkin::new(&sys, modified()).unwrap();
        reduced_map(&sys, z, &mut |sys, st: &mut State| {
            g.step(sys, st, h).unwrap();
            st.v *= 1.0 + 1e-6;
        })
    });
    let d_scaled = symplecticity_defect(&j);
    let d_ok = symplecticity_defect(&jacobian(&sys, modified(), h, &z, 1e-5));
    println!(
        "h = {h}: defect RK4 {d_rk4:.3e}, modified with p * (1 + 1e-6) {d_scaled:.3e}, \
         modified {d_ok:.3e}"
    );
    assert!(
        d_rk4 > 10.0 * TOL,
        "RK4 passed the symplecticity check: {d_rk4}"
    );
    assert!(
        d_scaled > 10.0 * TOL,
        "the perturbed map passed: {d_scaled}"
    );
    assert!(d_ok < TOL);
    // the reduced step itself (no perturbation) agrees with the closure form
    let a = reduced_step(&sys, modified(), h, &z);
    let mut g = Galerkin::new(&sys, modified()).unwrap();
    let b = reduced_map(&sys, &z, &mut |sys, st: &mut State| {
        g.step(sys, st, h).unwrap();
    });
    assert_eq!(a, b);
}

/// The (2,2) step with the `h^5 e4` term (`docs/symplectic.md` section 5b; exact gradients of
/// `e4` by a reverse pass) is symplectic to what the differences resolve, like the plain step.
#[test]
fn modified_lagrangian_s2_step_is_symplectic() {
    let sys = models::paper_a_double_pendulum().unwrap();
    let opts = common::tight(2).with_preadjust(PreadjustMode::ModifiedLagrangian);
    for z in STATES {
        for h in [0.04, 0.1] {
            let plain = symplecticity_defect(&jacobian(&sys, common::tight(2), h, &z, 1e-5));
            let j = jacobian(&sys, opts, h, &z, 1e-5);
            let defect = symplecticity_defect(&j);
            let moved = (&j - nalgebra::DMatrix::identity(4, 4)).abs().max();
            println!(
                "(2,2) z = {z:?}, h = {h}: |J^T Omega J - Omega| modified {defect:.3e} (plain \
                 {plain:.3e}), |J - I| = {moved:.3e}"
            );
            assert!(moved > 1e-2, "{moved}");
            assert!(defect < TOL, "z = {z:?}, h = {h}: defect {defect}");
        }
    }
}
