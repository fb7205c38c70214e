//! Every jet against finite differences of `f64` evaluations and against each other.

use super::*;

/// A smooth function of six variables through every operation of [`Scalar`]: products,
/// `sin_cos` of a variable and of a difference, `sqrt` of a positive sum of squares.
fn f<T: Scalar>(x: [T; 6]) -> T {
    let (s1, c1) = x[2].sin_cos();
    let (s2, c2) = (x[5] - x[1]).sin_cos();
    let r = x[3] - x[0] + c2 * 0.4 - s1 * 0.3;
    let u = x[4] - x[1] + s2 * 0.5 + c1 * 0.2;
    (r * r + u * u + 0.1).sqrt() * x[2] + x[0] * x[4] - 1.5
}

#[test]
fn jets_match_finite_differences() {
    let x0 = [0.1, -0.3, 0.7, 1.2, 0.4, -0.5];
    let dir = [0.3, -0.1, 0.9, 0.2, -0.6, 0.5];
    let dj: [DirJet; 6] = std::array::from_fn(|i| DirJet::var(i, x0[i], dir[i]));
    let hj: [HessJet; 6] = std::array::from_fn(|i| HessJet::var(i, x0[i]));
    let d = f(dj);
    let h = f(hj);
    let e = 1e-5;
    for i in 0..6 {
        let mut xp = x0;
        let mut xm = x0;
        xp[i] += e;
        xm[i] -= e;
        let fd = (f(xp) - f(xm)) / (2.0 * e);
        assert!((fd - d.g[i]).abs() < 1e-8, "grad {i}");
        assert!((fd - h.g[i]).abs() < 1e-8, "grad {i}");
        let gp = f(std::array::from_fn(|k| HessJet::var(k, xp[k]))).g;
        let gm = f(std::array::from_fn(|k| HessJet::var(k, xm[k]))).g;
        for j in 0..6 {
            let fd2 = (gp[j] - gm[j]) / (2.0 * e);
            assert!((fd2 - h.h[i][j]).abs() < 1e-7, "hess {i} {j}");
        }
    }
    let mut vhv = 0.0;
    for i in 0..6 {
        for j in 0..6 {
            vhv += dir[i] * h.h[i][j] * dir[j];
        }
    }
    assert!((vhv - d.d2).abs() < 1e-12);
    let gd: f64 = (0..6).map(|i| d.g[i] * dir[i]).sum();
    assert!((gd - d.d1).abs() < 1e-14);
    // TanJet: H w and the directional derivative, against the HessJet
    let tj = f(std::array::from_fn(|i| TanJet::var(i, x0[i], dir[i])));
    assert!((tj.v - h.v).abs() < 1e-15);
    assert!((tj.d - d.d1).abs() < 1e-14);
    for i in 0..6 {
        assert!((tj.g[i] - h.g[i]).abs() < 1e-14, "TanJet grad {i}");
        let hw: f64 = (0..6).map(|j| h.h[i][j] * dir[j]).sum();
        assert!((tj.dg[i] - hw).abs() < 1e-13, "TanJet H w {i}");
    }
    // ThirdJet: H w, w^T H w and grad(w^T H w) against differences of the HessJet
    let t3 = f(std::array::from_fn(|i| ThirdJet::var(i, x0[i], dir[i])));
    assert!((t3.v - h.v).abs() < 1e-15);
    assert!((t3.d1 - d.d1).abs() < 1e-14);
    assert!((t3.d2 - vhv).abs() < 1e-12);
    let quad = |x: [f64; 6]| -> f64 {
        let hh = f(std::array::from_fn(|k| HessJet::var(k, x[k]))).h;
        (0..6)
            .map(|i| (0..6).map(|j| dir[i] * hh[i][j] * dir[j]).sum::<f64>())
            .sum()
    };
    for i in 0..6 {
        assert!((t3.g[i] - h.g[i]).abs() < 1e-14, "ThirdJet grad {i}");
        let hw: f64 = (0..6).map(|j| h.h[i][j] * dir[j]).sum();
        assert!((t3.g1[i] - hw).abs() < 1e-13, "ThirdJet H w {i}");
        let (mut xp, mut xm) = (x0, x0);
        xp[i] += e;
        xm[i] -= e;
        let fd3 = (quad(xp) - quad(xm)) / (2.0 * e);
        assert!(
            (t3.g2[i] - fd3).abs() < 1e-7,
            "ThirdJet D3 {i}: {} vs {fd3}",
            t3.g2[i]
        );
    }
    let du = f(std::array::from_fn(|i| Dual::var(x0[i], dir[i])));
    assert!((du.v - d.v).abs() < 1e-15);
    assert!((du.d - d.d1).abs() < 1e-14);
}
