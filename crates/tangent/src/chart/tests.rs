//! Unit tests of the dense chart and its kernels.

use super::*;
use crate::kernels::dot;

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
        chart.form_q();
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

/// The accelerations at the centre from the chart's QR (null-space method) equal the general
/// index-1 solve's, on planar mechanisms, a spatial thin disc (`E_2 = 0`: `M` singular, definite
/// on the tangent space only), a spatial double pendulum and the Bricard linkage (a redundant
/// equation: the chart's selected rows); and a chart without a centre declines.
#[test]
fn centre_accelerations_match_the_index1_solve() {
    use mbd_model::models;
    let disc = models::heavy_top([1.0, 2.0, 1.0], 0.3, 20.0).expect("model");
    assert!(disc.mass_diag().iter().any(|&m| m == 0.0), "a zero E_i");
    for (name, sys) in [
        ("manipulator", models::manipulator().expect("model")),
        ("four-bar", models::four_bar().expect("model")),
        ("slider-crank", models::slider_crank().expect("model")),
        ("thin disc top", disc),
        (
            "spatial double pendulum",
            models::spatial_double_pendulum().expect("model"),
        ),
        ("Bricard", models::bricard().expect("model")),
    ] {
        let st = mbd_solve::State::consistent(&sys, 0.0).expect("state");
        let (q, v) = (st.q.as_slice(), st.v.as_slice());
        let n = q.len();
        let mut chart = TangentChart::new(&sys);
        let mut a = vec![0.0; n];
        assert!(
            !chart.centre_accelerations(&sys, &mut a),
            "{name}: no centre yet"
        );
        chart.centre(&sys, q, v, 0.0).expect("centre");
        assert!(chart.centre_accelerations(&sys, &mut a), "{name}");
        let mut solver = mbd_solve::AccelerationSolver::new(&sys);
        let (mut a_ref, mut lambda) = (vec![0.0; n], vec![0.0; sys.n_constraints()]);
        solver
            .solve_accelerations(&sys, q, v, 0.0, None, &mut a_ref, &mut lambda)
            .expect("index-1 solve");
        let scale = 1.0 + a_ref.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let diff = a
            .iter()
            .zip(&a_ref)
            .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
        assert!(diff <= 1e-11 * scale, "{name}: {diff:e} (scale {scale:e})");
    }
}

/// A chart with a velocity weight `tau` is the chart of the coordinates `(q, tau v)`: its maps
/// land on the manifold, their derivative along a chart coordinate is the tangent vector
/// `tangent_to_ambient(e_k)` (checked by central differences), and splitting that vector
/// gives back `e_k` with a zero normal part.
#[test]
fn a_weighted_chart_maps_and_splits_consistently() {
    for tau in [1.0, 0.01, 1e-4] {
        let sys = mbd_model::models::manipulator().expect("model");
        let st = mbd_solve::State::consistent(&sys, 0.0).expect("state");
        let mut chart = TangentChart::new(&sys);
        chart.set_velocity_weight(tau);
        chart
            .centre(&sys, st.q.as_slice(), st.v.as_slice(), 0.0)
            .expect("centre");
        let (dim, mm, nn) = (chart.dim(), chart.codim(), chart.ambient_dim());
        let newton = NewtonSettings::default();
        let eps = 1e-4;
        let mut f = vec![0.0; mm];
        for k in 0..dim {
            let mut e = vec![0.0; dim];
            e[k] = 1.0;
            let mut u = vec![0.0; nn];
            chart.tangent_to_ambient(&e, &mut u);
            let mut pts = [vec![0.0; nn], vec![0.0; nn]];
            for (s, x) in [eps, -eps].iter().zip(pts.iter_mut()) {
                let xi: Vec<f64> = e.iter().map(|v| s * v).collect();
                let mut zeta = vec![0.0; mm];
                chart
                    .map(&sys, &xi, 0.0, &mut zeta, x, &newton)
                    .expect("map");
                assert!(chart.residual(&sys, x, 0.0, &mut f) <= 1e-12, "tau {tau}");
            }
            let scale = u.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            for i in 0..nn {
                let d = (pts[0][i] - pts[1][i]) / (2.0 * eps);
                assert!(
                    (d - u[i]).abs() <= 1e-6 * scale,
                    "tau {tau}, coordinate {k}, component {i}: {d} against {}",
                    u[i]
                );
            }
            let (mut g, mut back) = (vec![0.0; mm], vec![0.0; dim]);
            chart.split_coordinates(&u, &mut g, &mut back);
            for (i, b) in back.iter().enumerate() {
                assert!((b - e[i]).abs() < 1e-12, "tau {tau}: {back:?}");
            }
            assert!(g.iter().all(|v| v.abs() < 1e-12), "tau {tau}: {g:?}");
        }
    }
}
