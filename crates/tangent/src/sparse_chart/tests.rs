//! The sparse chart against the dense one.

use super::SparseChart;
use crate::chart::TangentChart;
use mbd_model::models;
use mbd_solve::State;

/// On a planar chain, a spatial chain (12-coordinate blocks with their internal constraints)
/// and the Bricard linkage (a redundant equation, which both charts leave out).
#[test]
fn sparse_projector_is_the_dense_u_u_transpose() {
    for (sys, tangent_v) in [
        (models::n_link_chain(6).expect("planar chain"), false),
        (models::spatial_chain(4).expect("spatial chain"), false),
        (models::bricard().expect("Bricard"), true),
    ] {
        projector_matches(&sys, tangent_v);
    }
}

/// The projectors agree at a consistent `q` with a velocity off the manifold (only `Df(x_c)`
/// matters), or, with `tangent_v`, projected onto `ker Phi_q`: the Bricard linkage's
/// redundancy holds on its constraint manifold only, so an off-manifold velocity gives its
/// velocity rows one more rank, which the sparse chart sees and the dense chart (choosing
/// its rows from `Phi_q`) does not.
fn projector_matches(sys: &mbd_model::System, tangent_v: bool) {
    let s = State::consistent(sys, 0.0).expect("state");
    let n = sys.n_coords();
    let mut v: Vec<f64> = (0..n).map(|i| 0.3 * (i as f64 + 1.0).sin()).collect();
    if tangent_v {
        let mut pq = nalgebra::DMatrix::zeros(sys.n_constraints(), n);
        sys.phi_q(s.q.as_slice(), 0.0, &mut pq);
        let svd = pq.svd(false, true);
        let vt = svd.v_t.expect("V^T");
        let v0 = nalgebra::DVector::from_column_slice(&v);
        let mut p = v0.clone();
        for (k, &sv) in svd.singular_values.iter().enumerate() {
            if sv > 1e-10 * svd.singular_values[0] {
                let row = vt.row(k).transpose();
                p -= &row * row.dot(&v0);
            }
        }
        v.copy_from_slice(p.as_slice());
    }
    let mut dense = TangentChart::new(sys);
    dense
        .centre(sys, s.q.as_slice(), &v, 0.0)
        .expect("dense centre");
    let mut sparse = SparseChart::new(sys).expect("sparse chart");
    sparse
        .centre(sys, s.q.as_slice(), &v, 0.0)
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
