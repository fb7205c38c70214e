//! The preadjustments' terms on a model with spatial angle drivers (whose `Phi_q` and
//! constraint Hessians turn with time): at a fixed time `t`, the exact gradients against
//! central differences of the terms.

use mbd_model::System;
use mbd_solve::State;
use mbd_symplectic::Preadjustment;

/// `examples/models/driven_arm.toml`: two spatial angle drivers, one between two moving bodies.
fn model() -> System {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples/models/driven_arm.toml");
    System::from_path(path).expect("the driven-arm example loads")
}

#[test]
fn modified_term_gradients_match_differences_at_a_time() {
    let sys = model();
    let st = State::consistent(&sys, 0.0).unwrap();
    let (q, v) = (st.q.as_slice().to_vec(), st.v.as_slice().to_vec());
    let n = q.len();
    for t in [0.0, 0.35] {
        for s in [1usize, 2] {
            let mut p = Preadjustment::new(&sys, s).unwrap();
            p.set_time(t);
            let (mut gq, mut gv) = (vec![0.0; n], vec![0.0; n]);
            if s == 1 {
                p.modified_gradients(&sys, &q, &v, &mut gq, &mut gv)
                    .unwrap();
            } else {
                p.modified_gradients_s2(&sys, &q, &v, &mut gq, &mut gv)
                    .unwrap();
            }
            let f = |y: &[f64], w: &[f64]| {
                if s == 1 {
                    p.modified_term(&sys, y, w).unwrap()
                } else {
                    p.modified_term_s2(&sys, y, w).unwrap()
                }
            };
            let err = mbd_testkit::gradient_error(f, &q, &v, &gq, &gv, 1e-4);
            eprintln!("s = {s}, t = {t}: {err:e}");
            assert!(
                err < 1e-6,
                "s = {s}, t = {t}: gradients off by {err:e} (relative)"
            );
        }
    }
}

/// The driven arm with both drivers frozen at their angles at time `t` (constant motions).
fn frozen(t: f64) -> System {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples/models/driven_arm.toml");
    let text = std::fs::read_to_string(path).unwrap();
    let motor = format!(
        "motion = {{ kind = \"polynomial\", coeffs = [{:e}] }}",
        3.0 * t
    );
    let elbow = format!(
        "motion = {{ kind = \"polynomial\", coeffs = [{:e}] }}",
        0.5 * (2.0 * t).sin()
    );
    let text = text
        .replace(
            "motion = { kind = \"polynomial\", coeffs = [0.0, 3.0] }",
            &motor,
        )
        .replace(
            "motion = { kind = \"harmonic\", amplitude = 0.5, omega = 2.0 }",
            &elbow,
        );
    assert!(!text.contains("harmonic") && !text.contains("[0.0, 3.0]"));
    System::from_toml(&text).unwrap()
}

/// Every term at time `t` on the driven arm is the term of the model frozen at `t` (its
/// drivers held at their angles then), as the scheme takes it: paper A's `W_s` (s = 1, 2), the
/// s = 1 term `e` and the s = 2 term `e4`, equal to rounding at a generic `(q, v)` (`e4` moves
/// with `t` here; `W_s` does not: each driver's hinge leaves it the same rotation to fix,
/// whatever `theta`), and `grad W_s` against central differences of `W_s`.
#[test]
fn the_terms_at_a_time_are_those_of_the_frozen_model() {
    let sys = model();
    let st = State::consistent(&sys, 0.0).unwrap();
    let q = st.q.as_slice().to_vec();
    let v: Vec<f64> =
        st.v.iter()
            .enumerate()
            .map(|(i, x)| x + 0.1 * (i as f64).cos())
            .collect();
    let n = q.len();
    for t in [0.0, 0.35] {
        let fz = frozen(t);
        let close = |a: f64, b: f64, what: &str| {
            assert!(
                (a - b).abs() <= 1e-10 * a.abs().max(b.abs()),
                "{what} at t = {t}: {a} against the frozen model's {b}"
            );
        };
        for s in [1usize, 2] {
            let mut p = Preadjustment::new(&sys, s).unwrap();
            p.set_time(t);
            let mut pf = Preadjustment::new(&fz, s).unwrap();
            close(
                p.value(&sys, &q).unwrap(),
                pf.value(&fz, &q).unwrap(),
                &format!("W_{s}"),
            );
            let mut g = vec![0.0; n];
            p.gradient(&sys, &q, &mut g).unwrap();
            let f = |y: &[f64], _: &[f64]| p.value(&sys, y).unwrap();
            let err = mbd_testkit::gradient_error(f, &q, &[], &g, &[], 1e-4);
            assert!(
                err < 1e-6,
                "s = {s}, t = {t}: grad W_s off by {err:e} (relative)"
            );
        }
        let mut p = Preadjustment::new(&sys, 2).unwrap();
        p.set_time(t);
        let mut pf = Preadjustment::new(&fz, 2).unwrap();
        close(
            p.modified_term(&sys, &q, &v).unwrap(),
            pf.modified_term(&fz, &q, &v).unwrap(),
            "e",
        );
        close(
            p.modified_term_s2(&sys, &q, &v).unwrap(),
            pf.modified_term_s2(&fz, &q, &v).unwrap(),
            "e4",
        );
    }
}
