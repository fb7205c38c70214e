//! [`PolyJet`] against polarisations of [`Taylor4`] series (values) and their differences in
//! the base point (gradients), and its direction gradients against differences.

use super::*;
use crate::Taylor4;

use crate::fixtures::TwoDirections;

/// `{1, t, e, d, t^2, e t, e^2, e d, e t^2}`.
#[derive(Clone, Copy, Debug)]
struct Three;
impl Basis<9> for Three {
    const ND: usize = 3;
    const EXP: [[u8; MAX_DIRS]; 9] = [
        [0, 0, 0, 0, 0, 0],
        [1, 0, 0, 0, 0, 0],
        [0, 1, 0, 0, 0, 0],
        [0, 0, 1, 0, 0, 0],
        [2, 0, 0, 0, 0, 0],
        [1, 1, 0, 0, 0, 0],
        [0, 2, 0, 0, 0, 0],
        [0, 1, 1, 0, 0, 0],
        [2, 1, 0, 0, 0, 0],
    ];
}

/// Products, `sin_cos` of variables and of a product, and `sqrt`.
fn f<T: Scalar>(x: [T; 6]) -> T {
    let (s1, c1) = x[2].sin_cos();
    let (s2, c2) = x[5].sin_cos();
    let r = x[3] - x[0] + c2 * 0.4 - s1 * 0.3;
    let u = x[4] - x[1] + s2 * 0.5 + c1 * 0.2;
    let (s, c) = (x[1] * x[5]).sin_cos();
    (r * r + u * u + 0.1).sqrt() * x[2] + x[0] * x[4] * s + c * c * c
}

const X0: [f64; 6] = [0.1, -0.3, 0.7, 1.2, 0.4, -0.5];
const V: [f64; 6] = [0.3, -0.1, 0.9, 0.2, -0.6, 0.5];
const U: [f64; 6] = [-0.4, 0.2, 0.6, -0.3, 0.1, 0.8];
const N: [f64; 6] = [0.2, 0.5, -0.7, 0.4, 0.3, -0.2];

fn poly<const K: usize, B: Basis<K>>(x: [f64; 6], dirs: &[[f64; 6]]) -> PolyJet<K, B> {
    f(std::array::from_fn(|i| {
        let w: Vec<f64> = dirs.iter().map(|d| d[i]).collect();
        PolyJet::<K, B>::var(i, x[i], &w)
    }))
}

/// The series along `w` at `x` (coefficients of `t^0 .. t^4`).
fn series_at(x: [f64; 6], w: [f64; 6]) -> [f64; 5] {
    let t = f(std::array::from_fn(|i| Taylor4::var(x[i], w[i])));
    std::array::from_fn(|k| t.coef(k))
}

/// The series along `w` at `X0` and the gradients of its coefficients with respect to the base
/// point by fourth-order central differences: `(coefficients, gradients)`.
fn series(w: [f64; 6]) -> ([f64; 5], [[f64; 6]; 5]) {
    let h = 1e-3;
    let mut g = [[0.0; 6]; 5];
    for i in 0..6 {
        let at = |s: f64| {
            let mut x = X0;
            x[i] += s;
            series_at(x, w)
        };
        let (p2, p1, m1, m2) = (at(2.0 * h), at(h), at(-h), at(-2.0 * h));
        for k in 0..5 {
            g[k][i] = (-p2[k] + 8.0 * p1[k] - 8.0 * m1[k] + m2[k]) / (12.0 * h);
        }
    }
    (series_at(X0, w), g)
}

fn comb(a: [f64; 6], s: f64, b: [f64; 6]) -> [f64; 6] {
    std::array::from_fn(|i| a[i] + s * b[i])
}

/// `(D^k f(a, .., a) / k!, its gradient)` as one vector of 7 numbers per polarisation term.
fn coef(w: [f64; 6], k: usize) -> [f64; 7] {
    let (c, g) = series(w);
    let mut out = [0.0; 7];
    out[0] = c[k];
    out[1..].copy_from_slice(&g[k]);
    out
}

fn lin(terms: &[(f64, [f64; 7])]) -> [f64; 7] {
    let mut out = [0.0; 7];
    for (c, t) in terms {
        for i in 0..7 {
            out[i] += c * t[i];
        }
    }
    out
}

/// Reference coefficients (with gradients) by polarisation: `D^2 f(a, b) = [D^2 f(a + b) -
/// D^2 f(a - b)] / 4`, `D^3 f(a, a, b) = [D^3 f(a + b) - D^3 f(a - b) - 2 D^3 f(b)] / 6`
/// (the coefficients of the series are `D^k / k!`).
fn d2(a: [f64; 6], b: [f64; 6]) -> [f64; 7] {
    // D^2(a, b) = 2 [c2(a + b) - c2(a - b)] / 4
    lin(&[
        (0.5, coef(comb(a, 1.0, b), 2)),
        (-0.5, coef(comb(a, -1.0, b), 2)),
    ])
}
fn d3_aab(a: [f64; 6], b: [f64; 6]) -> [f64; 7] {
    // D^3(a, a, b) = 6 [c3(a + b) + c3(b - a) ... ] / 6 with the odd order's sign
    lin(&[
        (1.0, coef(comb(b, 1.0, a), 3)),
        (1.0, coef(comb(b, -1.0, a), 3)),
        (-2.0, coef(b, 3)),
    ])
}

/// The value to 1e-13 and the gradient to 1e-8 (differences) of the reference.
fn check<const K: usize, B: Basis<K>>(j: &PolyJet<K, B>, k: usize, want: [f64; 7], what: &str) {
    let got: Vec<f64> = std::iter::once(j.derivative(k))
        .chain(j.g[k].iter().map(|g| B::FACT[k] as f64 * g))
        .collect();
    for i in 0..7 {
        let tol = if i == 0 { 1e-13 } else { 1e-8 };
        assert!(
            (got[i] - want[i]).abs() <= tol * (1.0 + want[i].abs()),
            "{what}, entry {i}: {} vs {}",
            got[i],
            want[i]
        );
    }
}

/// Every coefficient equals the polarisation of `Taylor4` series, its gradient the differences
/// of those.
#[test]
fn coefficients_match_polarised_series() {
    let j: PolyJet<8, TwoDirections> = poly(X0, &[V, U]);
    for (k, p) in [(0, 0), (1, 1), (3, 2), (5, 3), (7, 4)] {
        let mut want = coef(V, p);
        let fact = [1.0, 1.0, 2.0, 6.0, 24.0][p];
        want.iter_mut().for_each(|x| *x *= fact);
        check(&j, k, want, &format!("D^{p} f(v^{p})"));
    }
    check(&j, 2, coef(U, 1), "D f(u)");
    check(&j, 4, d2(U, V), "D^2 f(u, v)");
    check(&j, 6, d3_aab(V, U), "D^3 f(v, v, u)");
    let j: PolyJet<9, Three> = poly(X0, &[V, N, U]);
    check(&j, 5, d2(N, V), "D^2 f(n, v)");
    check(&j, 7, d2(N, U), "D^2 f(n, u)");
    let mut nn = coef(N, 2);
    nn.iter_mut().for_each(|x| *x *= 2.0);
    check(&j, 6, nn, "D^2 f(n, n)");
    check(&j, 8, d3_aab(V, N), "D^3 f(v, v, n)");
    assert!(
        j.c[8].abs() > 1e-2,
        "the test function has mixed third derivatives"
    );
}

/// The gradient of coefficient `k` with respect to direction `j`'s components is the
/// base-point gradient of coefficient `DIV[k][j]` (central differences; the coefficients are
/// polynomials of degree at most 2 in each direction here, so the difference is exact to
/// round-off for `e_j <= 2`).
#[test]
fn direction_gradients_are_shifted_base_gradients() {
    let dirs = [V, N, U];
    let j: PolyJet<9, Three> = poly(X0, &dirs);
    let h = 1e-3;
    for d in 0..3 {
        for i in 0..6 {
            let at = |s: f64| {
                let mut w = dirs;
                w[d][i] += s;
                poly::<9, Three>(X0, &w)
            };
            let (p, m) = (at(h), at(-h));
            for k in 0..9 {
                let fd = (p.c[k] - m.c[k]) / (2.0 * h);
                let want = match Three::DIV[k][d] {
                    NONE => 0.0,
                    q => j.g[q as usize][i],
                };
                assert!(
                    (fd - want).abs() < 1e-9 * (1.0 + want.abs()),
                    "coef {k} along dir {d} comp {i}: {fd} vs {want}"
                );
            }
        }
    }
}

/// The tables of a basis.
#[test]
fn tables() {
    assert_eq!(TwoDirections::PROD[1][1], 3); // t t = t^2
    assert_eq!(TwoDirections::PROD[2][2], NONE); // e^2 is not kept
    assert_eq!(TwoDirections::PROD[4][1], 6); // (e t) t = e t^2
    assert_eq!(TwoDirections::DIV[6][0], 4); // e t^2 / t = e t
    assert_eq!(TwoDirections::DIV[6][1], 3); // e t^2 / e = t^2
    assert_eq!(TwoDirections::FACT, [1, 1, 1, 2, 1, 6, 2, 24]);
    assert_eq!((TwoDirections::MAX_DEG, Three::MAX_DEG), (4, 3));
    assert_eq!(Three::LIN, [1, 2, 3, NONE, NONE, NONE]);
}

/// The closed form of `sin_cos` for a linear argument (an angle variable) against the general
/// composition with the series of `sin` and `cos`.
#[test]
fn sin_cos_of_a_linear_argument_matches_the_composition() {
    let mut x: PolyJet<9, Three> = PolyJet::var(2, 0.7, &[0.3, -1.1, 0.4]);
    x.g[0][4] = 0.25; // a value gradient that is not a unit vector
    let (sn, cs) = x.c[0].sin_cos();
    let (s, c) = x.sin_cos_with(sn, cs);
    let ds = [sn, cs, -sn, -cs];
    let mut a = [0.0; 6];
    let mut b = [0.0; 6];
    let mut fact = 1.0;
    for k in 0..6 {
        a[k] = ds[k % 4] / fact;
        b[k] = ds[(k + 1) % 4] / fact;
        fact *= (k + 1) as f64;
    }
    let (s2, c2) = (x.compose(&a), x.compose(&b));
    for k in 0..9 {
        assert!((s.c[k] - s2.c[k]).abs() < 1e-15 && (c.c[k] - c2.c[k]).abs() < 1e-15);
        for l in 0..NV {
            assert!((s.g[k][l] - s2.g[k][l]).abs() < 1e-15, "d sin {k} {l}");
            assert!((c.g[k][l] - c2.g[k][l]).abs() < 1e-15, "d cos {k} {l}");
        }
    }
}
