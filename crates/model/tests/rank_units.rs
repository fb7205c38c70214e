//! The near-dependence report (`System::nearly_dependent_at`) weighs the columns of `Phi_q` by
//! `System::rank_weights`, so it does not depend on the unit of length: a mechanism and its
//! copy scaled by 1e-3 (lengths 1e-3, inertias 1e-6) report the same equations at every
//! tolerance.

use mbd_model::{models, System};

fn near(sys: &System, tol: f64) -> Vec<String> {
    let (q, _) = sys.initial_guess();
    sys.nearly_dependent_at(q.as_slice(), 0.0, tol)
        .into_iter()
        .map(|e| e.equation)
        .collect()
}

#[test]
fn the_report_does_not_depend_on_the_unit_of_length() {
    let mut found_some = false;
    for angle in [0.5, 0.05, 0.005, 5e-4] {
        for tol in [1e-3, 1e-2, 1e-1] {
            let metres = models::parallelogram_four_bar(0.5, 1.0, angle, 0.0, false).unwrap();
            let millis = models::parallelogram_four_bar(0.5e-3, 1.0e-3, angle, 0.0, false).unwrap();
            let (a, b) = (near(&metres, tol), near(&millis, tol));
            assert_eq!(a, b, "angle {angle}, tolerance {tol}");
            found_some |= !a.is_empty();
        }
    }
    // near the flat configuration the report does name the closing loop's equations
    assert!(found_some, "no near-dependence found at any angle");
}
