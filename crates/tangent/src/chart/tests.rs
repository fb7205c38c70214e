//! Unit tests of the dense chart and its kernels.

use super::*;
use crate::kernels::{dot, form_q, form_q_padded, householder_qr, qr_padded, with_len};

/// The block-structured chart: `[Q1 U]` orthonormal, `Q1 R = Df^T`, `Df U = 0`.
#[test]
fn block_chart_factors_df() {
    for sys in [
        mbd_model::models::manipulator().expect("model"),
        mbd_model::models::four_bar().expect("model"),
        mbd_model::models::slider_crank().expect("model"),
    ] {
        let st = mbd_solve::State::consistent(&sys, 0.0).expect("state");
        let mut v = st.v.clone();
        for (i, x) in v.iter_mut().enumerate() {
            *x += 0.1 * (i as f64 + 1.0); // off the manifold in v: Df is all that matters
        }
        let mut chart = TangentChart::new(&sys);
        chart
            .centre(&sys, st.q.as_slice(), v.as_slice(), 0.0)
            .expect("centre");
        let (dim, mm, nn) = (chart.dim(), chart.codim(), chart.ambient_dim());
        let col = |k: usize| {
            if k < mm {
                chart.normal(k)
            } else {
                chart.tangent(k - mm)
            }
        };
        for i in 0..nn {
            for j in 0..nn {
                let d = dot(col(i), col(j));
                let e = if i == j { 1.0 } else { 0.0 };
                assert!((d - e).abs() < 1e-14, "({i},{j}) {d}");
            }
        }
        let df = chart.jacobian();
        let scale = df.amax();
        for j in 0..mm {
            for i in 0..nn {
                let qr: f64 = (0..=j).map(|k| chart.normal(k)[i] * chart.r(k, j)).sum();
                assert!((qr - df[(j, i)]).abs() < 1e-13 * scale, "Q1 R ({i},{j})");
            }
        }
        for k in 0..dim {
            for r in 0..mm {
                let d: f64 = (0..nn).map(|c| df[(r, c)] * chart.tangent(k)[c]).sum();
                assert!(d.abs() < 1e-13 * scale, "Df U ({r},{k}) {d}");
            }
        }
    }
}

/// The Broyden iteration reaches the same chart points as the plain chord (to 1e-13) with
/// fewer iterations, also when its updated matrix is carried to a second map.
#[test]
fn broyden_reaches_the_chord_point_in_fewer_iterations() {
    let sys = mbd_model::models::manipulator().expect("model");
    let st = mbd_solve::State::consistent(&sys, 0.0).expect("state");
    let newton = NewtonSettings::default();
    let mut chart = TangentChart::new(&sys);
    let (dim, mm, nn) = (chart.dim(), chart.codim(), chart.ambient_dim());
    let mut pts = vec![];
    let mut iters = vec![];
    for broyden in [false, true] {
        chart.set_broyden(broyden);
        chart
            .centre(&sys, st.q.as_slice(), st.v.as_slice(), 0.0)
            .expect("centre");
        let mut total = 0;
        let mut xs = vec![];
        for scale in [0.2, 0.25] {
            let xi: Vec<f64> = (0..dim).map(|k| scale * (1.0 + 0.3 * k as f64)).collect();
            let mut zeta = vec![0.0; mm];
            let mut x = vec![0.0; nn];
            let ms = chart
                .map(&sys, &xi, 0.0, &mut zeta, &mut x, &newton)
                .expect("map");
            assert!(ms.residual <= newton.tol, "{ms:?}");
            total += ms.iterations;
            xs.push(x);
        }
        iters.push(total);
        pts.push(xs);
    }
    let (updates, _) = chart.broyden_counts();
    println!(
        "chord {} iterations, Broyden {} ({updates} updates)",
        iters[0], iters[1]
    );
    for (a, b) in pts[0].iter().zip(&pts[1]) {
        let d = a
            .iter()
            .zip(b)
            .fold(0.0f64, |d, (p, q)| d.max((p - q).abs()));
        assert!(d < 1e-13, "{d:e}");
    }
    assert!(updates > 0);
    assert!(iters[1] < iters[0], "{iters:?}");
}

#[test]
fn householder_qr_reconstructs_and_q_is_orthogonal() {
    // 8 x 4 with the first 2 columns zero below row 4 (the structure of Df^T)
    let (rows, cols, short, half) = (8, 4, 2, 4);
    let mut a0: Vec<f64> = (0..rows * cols)
        .map(|i| ((i * 37 % 11) as f64 - 5.0) * 0.3 + if i % 9 == 0 { 2.0 } else { 0.0 })
        .collect();
    for k in 0..short {
        for r in half..rows {
            a0[k * rows + r] = 0.0;
        }
    }
    for (short, half) in [(0, rows), (short, half)] {
        let mut a = a0.clone();
        let mut tau = vec![0.0; cols];
        householder_qr(&mut a, &mut tau, rows, cols, short, half);
        let mut q = vec![0.0; rows * rows];
        form_q(&a, &tau, rows, cols, short, half, &mut q);
        for i in 0..rows {
            for j in 0..rows {
                let d = dot(&q[i * rows..(i + 1) * rows], &q[j * rows..(j + 1) * rows]);
                let e = if i == j { 1.0 } else { 0.0 };
                assert!((d - e).abs() < 1e-14, "({i},{j}) {d}");
            }
        }
        for j in 0..cols {
            for i in 0..rows {
                let mut s = 0.0;
                for k in 0..=j {
                    s += q[k * rows + i] * a[j * rows + k];
                }
                assert!((s - a0[j * rows + i]).abs() < 1e-13, "({i},{j})");
            }
        }
    }
}

#[test]
fn padded_householder_qr_reconstructs_and_q_is_orthogonal() {
    // 6 x 4 QR of the first 3 columns of a 6 x 5 matrix (the last two get Q^T applied), at a
    // length with a fixed-size arm (6) and one without (7: the same code with a run-time length)
    for rows in [6usize, 7] {
        let (kcols, tcols) = (3, 5);
        let a0: Vec<f64> = (0..rows * tcols)
            .map(|i| ((i * 37 % 11) as f64 - 5.0) * 0.3 + if i % 9 == 0 { 2.0 } else { 0.0 })
            .collect();
        let mut a = a0.clone();
        let (mut v, mut tau) = (vec![0.0; rows * kcols], vec![0.0; kcols]);
        with_len!(rows, qr_padded(&mut a, kcols, tcols, &mut v, &mut tau));
        let mut q = vec![0.0; rows * rows];
        with_len!(rows, form_q_padded(&v, &tau, &mut q));
        for i in 0..rows {
            for j in 0..rows {
                let d = dot(&q[i * rows..(i + 1) * rows], &q[j * rows..(j + 1) * rows]);
                let e = if i == j { 1.0 } else { 0.0 };
                assert!((d - e).abs() < 1e-14, "({i},{j}) {d}");
            }
        }
        // Q [R | Q^T B] = [A | B], R upper triangular
        for j in 0..tcols {
            for i in 0..rows {
                if j < kcols && i > j {
                    assert_eq!(a[j * rows + i], 0.0);
                }
                let s: f64 = (0..rows).map(|k| q[k * rows + i] * a[j * rows + k]).sum();
                assert!((s - a0[j * rows + i]).abs() < 1e-13, "({i},{j})");
            }
        }
    }
}
