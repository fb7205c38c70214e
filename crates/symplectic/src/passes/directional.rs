//! Directional derivatives of orders 2 to 4 of the constraints and of the potential,
//! `D^k f(q)(w, ..., w)`, from one truncated-Taylor pass per element ([`Taylor4`]): what
//! higher-order modified-Lagrangian terms need (mixed contractions by polarisation, e.g.
//! `D^2 f(a, b) = [D^2 f(a + b)^2 - D^2 f(a - b)^2] / 4` and
//! `D^3 f(a, a, b) = [D^3 f(a + b)^3 - D^3 f(a - b)^3 - 2 D^3 f(b)^3] / 6`).

use mbd_model::jet::{Frame, Scalar, Taylor4};
use mbd_model::{BodyAngles, JointElement, System};

#[inline(always)]
fn loc_taylor(q: &[f64], ang: Option<&BodyAngles>, w: &[f64], i: Option<usize>) -> Frame<Taylor4> {
    match i {
        Some(i) => BodyAngles::frame(
            ang,
            i,
            std::array::from_fn(|k| Taylor4::var(q[3 * i + k], w[3 * i + k])),
        ),
        None => Frame::fixed(),
    }
}

/// `out[r] = [D^2 Phi_r(w, w), D^3 Phi_r(w, w, w), D^4 Phi_r(w, w, w, w)]` at `q` for every
/// constraint row `r` (the configuration part: time enters the joint equations only
/// additively).
pub(crate) fn constraint_directional(sys: &System, q: &[f64], w: &[f64], out: &mut [[f64; 3]]) {
    constraint_directional_impl(sys, q, None, w, out);
}

#[inline(always)]
fn constraint_directional_impl(
    sys: &System,
    q: &[f64],
    ang: Option<&BodyAngles>,
    w: &[f64],
    out: &mut [[f64; 3]],
) {
    for JointElement {
        joint: j,
        attach: at,
        row: o,
    } in sys.joint_elements()
    {
        let mut e = [Taylor4::cst(0.0); 3];
        j.eval(
            &loc_taylor(q, ang, w, at.a),
            &loc_taylor(q, ang, w, at.b),
            &mut e,
        );
        for (k, ek) in e.iter().enumerate().take(j.n_equations()) {
            out[o + k] = [ek.derivative(2), ek.derivative(3), ek.derivative(4)];
        }
    }
}

/// `[D^2 V(w, w), D^3 V(w, w, w), D^4 V(w, w, w, w)]` at `q` (gravity is linear and
/// contributes nothing; non-conservative elements have no potential).
pub(crate) fn potential_directional(sys: &System, q: &[f64], w: &[f64]) -> [f64; 3] {
    potential_directional_impl(sys, q, None, w)
}

#[inline(always)]
fn potential_directional_impl(
    sys: &System,
    q: &[f64],
    ang: Option<&BodyAngles>,
    w: &[f64],
) -> [f64; 3] {
    let mut d = [0.0; 3];
    for (f, at) in sys.force_elements() {
        let e = f.potential(&loc_taylor(q, ang, w, at.a), &loc_taylor(q, ang, w, at.b));
        for (k, dk) in d.iter_mut().enumerate() {
            *dk += e.derivative(k + 2);
        }
    }
    d
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::passes::*;

    /// Orders 2 and 3 against the exact jets (`v^T Hess v` from `gamma`, `D^3(v, v, v)` from
    /// the third-order rows and `potential_third`), order 4 against central differences of
    /// order 3 along `w`; on every joint kind, the manipulator and a model with springs.
    #[test]
    fn directional_derivatives_match_the_jets() {
        for sys in mbd_model::fixtures::derivative_test_systems() {
            let (n, m) = (sys.n_coords(), sys.n_constraints());
            let (q, w) = mbd_model::fixtures::generic_point(n);
            let mut rows = vec![[0.0; 3]; m];
            constraint_directional(&sys, &q, &w, &mut rows);
            let (mut g, mut hv, mut d3, mut vhv) = (
                vec![[0.0; 6]; m],
                vec![[0.0; 6]; m],
                vec![[0.0; 6]; m],
                vec![0.0; m],
            );
            constraint_third_local(&sys, &q, &w, &mut g, &mut hv, &mut d3, &mut vhv);
            let (ba, bb): (Vec<_>, Vec<_>) = (0..m)
                .map(|r| sys.joint_bodies(sys.equation_joint(r).unwrap()))
                .unzip();
            let local = |r: usize, x: &[f64]| -> [f64; 6] {
                let mut l = [0.0; 6];
                for (slot, body) in [(0, ba[r]), (3, bb[r])] {
                    if let Some(i) = body {
                        l[slot..slot + 3].copy_from_slice(&x[3 * i..3 * i + 3]);
                    }
                }
                l
            };
            // D^3 Phi_r(w, w, w) = D^3 Phi_r(w, w, .) . w; the central difference of D^3 in
            // w errs by step^2 / 6 D^6, which the distance driver's square root makes large
            // enough at 1e-3 to miss 1e-5
            let step = 2e-4;
            let mut qp = q.clone();
            let mut d3_at = |t: f64, rows_out: &mut Vec<[f64; 3]>| {
                for i in 0..n {
                    qp[i] = q[i] + t * w[i];
                }
                constraint_directional(&sys, &qp, &w, rows_out);
            };
            let (mut p1, mut m1) = (vec![[0.0; 3]; m], vec![[0.0; 3]; m]);
            d3_at(step, &mut p1);
            d3_at(-step, &mut m1);
            for r in 0..m {
                let wl = local(r, &w);
                let t3: f64 = d3[r].iter().zip(&wl).map(|(a, b)| a * b).sum();
                let tol = |x: f64| 1e-12 * (1.0 + x.abs());
                assert!((rows[r][0] - vhv[r]).abs() < tol(vhv[r]), "D2 row {r}");
                assert!((rows[r][1] - t3).abs() < tol(t3), "D3 row {r}");
                let fd4 = (p1[r][1] - m1[r][1]) / (2.0 * step);
                assert!(
                    (rows[r][2] - fd4).abs() < 1e-5 * (1.0 + fd4.abs()),
                    "D4 row {r}: {} vs {fd4}",
                    rows[r][2]
                );
            }
            let pd = potential_directional(&sys, &q, &w);
            let mut p3 = vec![0.0; n];
            potential_third(&sys, &q, &w, &mut p3);
            let t3: f64 = p3.iter().zip(&w).map(|(a, b)| a * b).sum();
            assert!((pd[1] - t3).abs() < 1e-12 * (1.0 + t3.abs()), "D3 V");
            let mut hm = nalgebra::DMatrix::zeros(n, n);
            sys.potential_hessian(&q, &mut hm);
            let wv = nalgebra::DVector::from_column_slice(&w);
            let t2 = wv.dot(&(&hm * &wv));
            assert!((pd[0] - t2).abs() < 1e-12 * (1.0 + t2.abs()), "D2 V");
        }
    }

    /// Every pass with precomputed body angles ([`BodyAngles`]) equals the plain pass bit for
    /// bit (the Hessian-vector, third-order and Hessian-row passes), on every
    /// joint kind, the manipulator and the spring model; and the table knows its `q`.
    #[test]
    fn passes_at_precomputed_angles_are_bitwise_the_plain_ones() {
        use mbd_model::BodyAngles;
        let same = |a: &[f64], b: &[f64], what: &str| {
            assert_eq!(a.len(), b.len());
            for (i, (x, y)) in a.iter().zip(b).enumerate() {
                assert_eq!(x.to_bits(), y.to_bits(), "{what} [{i}]: {x} vs {y}");
            }
        };
        for sys in mbd_model::fixtures::derivative_test_systems() {
            let (n, m) = (sys.n_coords(), sys.n_constraints());
            let (q, w) = mbd_model::fixtures::generic_point(n);
            let ang = BodyAngles::new(&sys, &q);
            assert!(ang.matches(&q));
            let mut q2 = q.clone();
            q2[2] += 1e-3;
            assert!(!ang.matches(&q2));
            // Hessian-vector products and third derivatives
            let wts: Vec<f64> = (0..m).map(|r| 0.3 - 0.11 * r as f64).collect();
            for pot in [0.0, 1.0] {
                let (mut h1, mut h2) = (vec![0.0; n], vec![0.0; n]);
                lagrangian_hessian_vector(&sys, &q, 0.0, &w, pot, &wts, &mut h1);
                lagrangian_hessian_vector_at(&sys, &q, 0.0, &ang, &w, pot, &wts, &mut h2);
                same(&h1, &h2, "lagrangian_hessian_vector");
                let (mut d1, mut d2) = (vec![0.0; n], vec![0.0; n]);
                lagrangian_third(&sys, &q, 0.0, &w, pot, &wts, &mut h1, &mut d1);
                lagrangian_third_at(&sys, &q, 0.0, &ang, &w, pot, &wts, &mut h2, &mut d2);
                same(&h1, &h2, "lagrangian_third H w");
                same(&d1, &d2, "lagrangian_third D3");
            }
            let dirs: Vec<[f64; 6]> = (0..m)
                .map(|r| std::array::from_fn(|l| 0.2 * ((r * 6 + l) as f64 * 0.37).sin()))
                .collect();
            let (mut o1, mut o2) = (vec![0.5; n], vec![0.5; n]);
            add_constraint_hessian_rows(&sys, &q, &dirs, &mut o1);
            add_constraint_hessian_rows_at(&sys, &q, &ang, &dirs, &mut o2);
            same(&o1, &o2, "add_constraint_hessian_rows");
        }
    }
}
