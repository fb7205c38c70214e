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
