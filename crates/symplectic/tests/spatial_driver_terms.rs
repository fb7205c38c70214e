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

/// The largest difference between `grad` and fourth-order central differences of `f` in
/// `q` (`wrt_q`) or `v`, relative to the largest gradient entry.
fn fd_error(
    f: &mut dyn FnMut(&[f64], &[f64]) -> f64,
    q: &[f64],
    v: &[f64],
    gq: &[f64],
    gv: &[f64],
) -> f64 {
    let d = 1e-4;
    let n = q.len();
    let scale = gq.iter().chain(gv).fold(1e-30f64, |a, x| a.max(x.abs()));
    let mut worst = 0.0f64;
    for wrt_q in [true, false] {
        for l in 0..n {
            let mut acc = 0.0;
            for (cf, k) in [(8.0, 1.0), (-8.0, -1.0), (-1.0, 2.0), (1.0, -2.0)] {
                let (mut y, mut w) = (q.to_vec(), v.to_vec());
                if wrt_q {
                    y[l] += k * d;
                } else {
                    w[l] += k * d;
                }
                acc += cf * f(&y, &w);
            }
            let fd = acc / (12.0 * d);
            let g = if wrt_q { gq[l] } else { gv[l] };
            worst = worst.max((fd - g).abs());
        }
    }
    worst / scale
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
            let mut f = |y: &[f64], w: &[f64]| {
                if s == 1 {
                    p.modified_term(&sys, y, w).unwrap()
                } else {
                    p.modified_term_s2(&sys, y, w).unwrap()
                }
            };
            let err = fd_error(&mut f, &q, &v, &gq, &gv);
            eprintln!("s = {s}, t = {t}: {err:e}");
            assert!(
                err < 1e-6,
                "s = {s}, t = {t}: gradients off by {err:e} (relative)"
            );
        }
    }
}
