//! Tests of the third-derivative passes against differences of assembled Hessians.

use super::*;
use mbd_model::{models, Body, BodyRef, Force, Joint, System, SystemBuilder, TimeFunction};
use nalgebra::DMatrix;

/// Every conservative force kind (springs with and without rest length, rotary spring,
/// constant force and torque) besides gravity, and a damper and a time-dependent load
/// (no potential).
fn forces_system() -> System {
    let mut b = SystemBuilder::new();
    b.set_gravity([0.3, -9.81]);
    let b1 = b.add_body(Body::new("b1").rod(1.0, 1.0).position(0.3, -0.2, 0.4));
    let b2 = b.add_body(Body::new("b2").rod(2.0, 0.7).position(1.1, 0.5, -0.9));
    let b3 = b.add_body(Body::new("b3").rod(0.5, 0.4).position(-0.6, 1.3, 2.1));
    b.add_joint(Joint::revolute(
        "r",
        BodyRef::Ground,
        [0.1, 0.2],
        b1,
        [-0.5, 0.1],
    ));
    b.add_force(Force::spring_damper(
        "s",
        b1,
        [0.4, 0.1],
        b2,
        [-0.2, 0.3],
        30.0,
        0.0,
        0.5,
    ));
    b.add_force(Force::spring_damper(
        "s0",
        BodyRef::Ground,
        [1.0, 1.0],
        b3,
        [0.1, -0.2],
        12.0,
        0.0,
        0.0,
    ));
    b.add_force(Force::spring_damper(
        "sd",
        b2,
        [0.3, 0.0],
        b3,
        [0.0, 0.2],
        7.0,
        0.5,
        0.9,
    ));
    b.add_force(Force::rotary_spring_damper("k", b1, b2, 4.0, 0.0, 0.3));
    b.add_force(Force::rotary_spring_damper(
        "k0",
        BodyRef::Ground,
        b3,
        2.5,
        0.1,
        -0.2,
    ));
    b.add_force(Force::force(
        "f",
        b2,
        [0.3, -0.4],
        TimeFunction::constant(1.5),
        TimeFunction::constant(-2.0),
    ));
    b.add_force(Force::force(
        "ft",
        b3,
        [0.1, 0.1],
        TimeFunction::linear(1.0, 2.0),
        TimeFunction::constant(0.0),
    ));
    b.add_force(Force::torque("tq", b3, TimeFunction::constant(0.7)));
    b.build().unwrap()
}

/// `grad_q (v^T H(q) v)` by central differences of the exact Hessians, Richardson
/// extrapolated (error `O(e^4)`).
fn fd_third(hess: &dyn Fn(&[f64], &mut DMatrix<f64>), q: &[f64], v: &[f64]) -> Vec<f64> {
    let n = q.len();
    let vv = nalgebra::DVector::from_column_slice(v);
    let mut hm = DMatrix::zeros(n, n);
    let quad = |qq: &[f64], hm: &mut DMatrix<f64>| -> f64 {
        hess(qq, hm);
        vv.dot(&(&*hm * &vv))
    };
    let e = 1e-3;
    (0..n)
        .map(|i| {
            let mut acc = 0.0;
            for (c, s) in [(8.0, 0.5), (-8.0, -0.5), (-1.0, 1.0), (1.0, -1.0)] {
                let mut qq = q.to_vec();
                qq[i] += s * e;
                acc += c * quad(&qq, &mut hm);
            }
            acc / (6.0 * e)
        })
        .collect()
}

fn check(exact: &[f64], fd: &[f64], what: &str) {
    let scale = fd.iter().fold(1.0f64, |a, &b| a.max(b.abs()));
    for (i, (a, b)) in exact.iter().zip(fd).enumerate() {
        assert!(
            (a - b).abs() < 1e-9 * scale,
            "{what}[{i}]: exact {a} vs differences {b}"
        );
    }
}

fn point(n: usize) -> (Vec<f64>, Vec<f64>) {
    let q = (0..n)
        .map(|i| 0.3 + 0.17 * i as f64 - 0.05 * (i * i) as f64)
        .collect();
    let v = (0..n).map(|i| 1.3 - 0.41 * i as f64).collect();
    (q, v)
}

#[test]
fn constraint_third_matches_hessian_differences() {
    let systems = [
        mbd_model::fixtures::every_joint_kind(),
        forces_system(),
        models::slider_crank().unwrap(),
        models::manipulator().unwrap(),
        models::n_link_chain(5).unwrap(),
    ];
    for sys in &systems {
        let (n, m) = (sys.n_coords(), sys.n_constraints());
        let (q, v) = point(n);
        // one joint equation at a time, then a generic weighting
        let mut weights: Vec<Vec<f64>> = (0..m)
            .map(|k| (0..m).map(|r| if r == k { 1.0 } else { 0.0 }).collect())
            .collect();
        weights.push((0..m).map(|r| 0.7 - 0.3 * r as f64).collect());
        let mut out = vec![0.0; n];
        for w in &weights {
            constraint_third(sys, &q, &v, w, &mut out);
            let fd = fd_third(&|qq, hm| sys.constraint_hessian(qq, 0.0, w, hm), &q, &v);
            check(&out, &fd, "constraint_third");
        }
    }
}

#[test]
fn potential_third_matches_hessian_differences() {
    for (k, sys) in [forces_system(), models::manipulator().unwrap()]
        .iter()
        .enumerate()
    {
        let n = sys.n_coords();
        let (q, v) = point(n);
        let mut out = vec![0.0; n];
        potential_third(sys, &q, &v, &mut out);
        // (the springs make it non-zero; the manipulator's potential may be linear)
        assert!(k > 0 || out.iter().any(|&x| x != 0.0));
        let fd = fd_third(&|qq, hm| sys.potential_hessian(qq, hm), &q, &v);
        check(&out, &fd, "potential_third");
        // add_ with a scale accumulates
        let mut acc = vec![1.0; n];
        add_potential_third(sys, &q, &v, -2.0, &mut acc);
        for i in 0..n {
            assert!((acc[i] - (1.0 - 2.0 * out[i])).abs() < 1e-12 * (1.0 + out[i].abs()));
        }
    }
}
#[test]
fn lagrangian_products_match_assembled_hessians() {
    for sys in [
        forces_system(),
        mbd_model::fixtures::every_joint_kind(),
        models::manipulator().unwrap(),
    ] {
        let (n, m) = (sys.n_coords(), sys.n_constraints());
        let (q, v) = point(n);
        let w: Vec<f64> = (0..m).map(|r| 0.7 - 0.3 * r as f64).collect();
        let mut hm = DMatrix::zeros(n, n);
        sys.potential_hessian(&q, &mut hm);
        hm *= 0.5;
        sys.add_constraint_hessian(&q, 0.0, &w, 1.0, &mut hm);
        let dense = &hm * nalgebra::DVector::from_column_slice(&v);
        let (mut hv, mut hv2, mut d3) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
        lagrangian_hessian_vector(&sys, &q, 0.0, &v, 0.5, &w, &mut hv);
        lagrangian_third(&sys, &q, 0.0, &v, 0.5, &w, &mut hv2, &mut d3);
        let (mut p3, mut c3) = (vec![0.0; n], vec![0.0; n]);
        potential_third(&sys, &q, &v, &mut p3);
        constraint_third(&sys, &q, &v, &w, &mut c3);
        for i in 0..n {
            let tol = 1e-12 * (1.0 + dense[i].abs());
            assert!((hv[i] - dense[i]).abs() < tol, "Hess L v [{i}]");
            assert!((hv2[i] - dense[i]).abs() < tol, "lagrangian_third hv [{i}]");
            let e3 = 0.5 * p3[i] + c3[i];
            assert!((d3[i] - e3).abs() < 1e-12 * (1.0 + e3.abs()), "D3 L [{i}]");
        }
    }
}

/// The local third-order rows equal the dense passes: `Phi_q` and `gamma`
/// ([`System::phi_q_gamma`]), and, weighted, `Hess(w . Phi) v` and `D^3(w . Phi)(v, v, .)`
/// ([`lagrangian_third`]).
#[test]
fn local_third_rows_match_the_dense_passes() {
    for sys in [
        mbd_model::fixtures::every_joint_kind(),
        models::manipulator().unwrap(),
    ] {
        let (n, m) = (sys.n_coords(), sys.n_constraints());
        let (q, v) = point(n);
        let w: Vec<f64> = (0..m).map(|r| 0.7 - 0.3 * r as f64).collect();
        let (mut g, mut hv, mut d3, mut vhv) = (
            vec![[0.0; 6]; m],
            vec![[0.0; 6]; m],
            vec![[0.0; 6]; m],
            vec![0.0; m],
        );
        constraint_third_local(&sys, &q, &v, &mut g, &mut hv, &mut d3, &mut vhv);
        let mut gq = DMatrix::from_element(m, n, 3.0);
        sys.local_rows_dense(&g, &mut gq);
        let (mut gq2, mut gamma) = (DMatrix::zeros(m, n), vec![0.0; m]);
        sys.phi_q_gamma(&q, &v, 0.0, &mut gq2, &mut gamma);
        assert!((&gq - &gq2).amax() < 1e-14 * (1.0 + gq2.amax()));
        for r in 0..m {
            assert!(
                (vhv[r] + gamma[r]).abs() < 1e-13 * (1.0 + gamma[r].abs()),
                "row {r}"
            );
        }
        let (mut a, mut b) = (vec![0.0; n], vec![0.0; n]);
        add_local_rows(&sys, &hv, &w, &mut a);
        add_local_rows(&sys, &d3, &w, &mut b);
        let (mut ea, mut eb) = (vec![0.0; n], vec![0.0; n]);
        lagrangian_third(&sys, &q, 0.0, &v, 0.0, &w, &mut ea, &mut eb);
        for i in 0..n {
            assert!(
                (a[i] - ea[i]).abs() < 1e-13 * (1.0 + ea[i].abs()),
                "Hv [{i}]"
            );
            assert!(
                (b[i] - eb[i]).abs() < 1e-13 * (1.0 + eb[i].abs()),
                "D3 [{i}]"
            );
        }
    }
}

/// `sum_r Hess Phi_r d_r` with element-local directions against the assembled Hessian of
/// each row (`constraint_hessian` with a unit multiplier) times the row's direction.
#[test]
fn hessian_rows_match_assembled_hessians() {
    for sys in mbd_model::fixtures::derivative_test_systems() {
        let (n, m) = (sys.n_coords(), sys.n_constraints());
        let (q, _) = mbd_model::fixtures::generic_point(n);
        let dirs: Vec<[f64; 6]> = (0..m)
            .map(|r| std::array::from_fn(|l| 0.3 + 0.1 * r as f64 - 0.07 * (l * l) as f64))
            .collect();
        let mut got = vec![0.0; n];
        add_constraint_hessian_rows(&sys, &q, &dirs, &mut got);
        let mut want = vec![0.0; n];
        let mut h = DMatrix::zeros(n, n);
        for (r, d) in dirs.iter().enumerate() {
            let mut e = vec![0.0; m];
            e[r] = 1.0;
            sys.constraint_hessian(&q, 0.0, &e, &mut h);
            let (a, b) = sys.joint_bodies(sys.equation_joint(r).unwrap());
            let mut g = vec![0.0; n];
            for (slot, body) in [(0, a), (3, b)] {
                if let Some(i) = body {
                    for k in 0..3 {
                        g[3 * i + k] = d[slot + k];
                    }
                }
            }
            for i in 0..n {
                want[i] += (0..n).map(|l| h[(i, l)] * g[l]).sum::<f64>();
            }
        }
        let scale = want.iter().fold(1.0f64, |a, x| a.max(x.abs()));
        for i in 0..n {
            assert!(
                (got[i] - want[i]).abs() < 1e-12 * scale,
                "{i}: {} vs {}",
                got[i],
                want[i]
            );
        }
    }
}
