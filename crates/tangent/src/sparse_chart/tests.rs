//! The sparse chart against the dense one.

use super::SparseChart;
use crate::chart::TangentChart;
use mbd_model::models;
use mbd_solve::State;

#[test]
fn sparse_projector_is_the_dense_u_u_transpose() {
    // off the manifold in v on purpose: only Df(x_c) matters
    let sys = models::n_link_chain(6).expect("model");
    let s = State::consistent(&sys, 0.0).expect("state");
    let n = sys.n_coords();
    let v: Vec<f64> = (0..n).map(|i| 0.3 * (i as f64 + 1.0).sin()).collect();
    let mut dense = TangentChart::new(&sys);
    dense
        .centre(&sys, s.q.as_slice(), &v, 0.0)
        .expect("dense centre");
    let mut sparse = SparseChart::new(&sys).expect("sparse chart");
    sparse
        .centre(&sys, s.q.as_slice(), &v, 0.0)
        .expect("sparse centre");
    assert_eq!(sparse.dim(), dense.dim());
    let (nn, mm) = (sparse.ambient_dim(), sparse.codim());
    let fx: Vec<f64> = (0..nn).map(|i| (0.7 * i as f64).cos()).collect();
    let (mut g, mut py) = (vec![0.0; mm], vec![0.0; nn]);
    sparse.split(&fx, &mut g, &mut py);
    // U U^T F with the dense chart's orthonormal basis
    dense.form_q();
    let mut uu = vec![0.0; nn];
    for k in 0..dense.dim() {
        let u = dense.tangent(k);
        let c: f64 = u.iter().zip(&fx).map(|(a, b)| a * b).sum();
        for (o, a) in uu.iter_mut().zip(u) {
            *o += c * a;
        }
    }
    let d = py
        .iter()
        .zip(&uu)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    // P F lies in ker Df, and F = P F + Df^T g
    let mut dfp = vec![0.0; mm];
    sparse.apply_df(&py, &mut dfp);
    let mut back = py.clone();
    sparse.add_df_t(1.0, &g, &mut back);
    let r = back
        .iter()
        .zip(&fx)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    let k = dfp.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    println!("|P F - U U^T F| {d:.1e}, |Df P F| {k:.1e}, |P F + Df^T g - F| {r:.1e}");
    assert!(d < 1e-12 && k < 1e-12 && r < 1e-12, "{d:e} {k:e} {r:e}");
    // the rcond estimates are of the same size (QR diagonal against Cholesky of G)
    let ratio = sparse.rcond() / dense.rcond();
    assert!((0.01..100.0).contains(&ratio), "{ratio}");
}
