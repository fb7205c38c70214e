//! Tests of the dense Cholesky factorisation (`cholesky.rs`).

use super::*;

/// The Gram matrix of the rows `g` (each of length 3).
fn gram(c: &mut DenseCholesky, g: &[[f64; 3]]) {
    let mut a = c.matrix_mut();
    for (i, gi) in g.iter().enumerate() {
        for (j, gj) in g.iter().enumerate() {
            a[(i, j)] = gi.iter().zip(gj).map(|(x, y)| x * y).sum();
        }
    }
}

/// One redundant row beside one that is independent but nearly dependent (an angle of
/// 3e-6 rad to the first row: a mechanism near a singular configuration): the semidefinite
/// factorisation drops the redundant row and keeps the other, with a condition estimate
/// near `1 / (3e-6)^2`. With the single tolerant pass (pivot ratio 1e-10) the nearly
/// dependent row took the budget of one and the redundant row failed the factorisation.
/// A row nearly dependent within round-off (1e-7 rad) beside the redundant one still fails.
#[test]
fn a_nearly_dependent_row_is_not_taken_for_the_redundant_one() {
    let d = 3e-6f64;
    let mut c = DenseCholesky::new(3);
    c.set_max_dependent(1);
    let g0 = [1.0, 0.0, 0.0];
    gram(&mut c, &[g0, [d.cos(), d.sin(), 0.0], g0]);
    c.factor_in_place().expect("one redundant row");
    assert_eq!(c.dependent(), &[2]);
    let cond = c.condition_estimate();
    assert!(cond > 0.5 / (d * d) && cond < 2.0 / (d * d), "{cond:e}");
    // the basic solution of a consistent system: x_2 = 0
    let mut b = [1.0, d.cos(), 1.0];
    c.solve_in_place(&mut b);
    assert!(
        b[2] == 0.0 && (b[0] - 1.0).abs() < 1e-6 && b[1].abs() < 1e-6,
        "{b:?}"
    );
    // without a redundant row the tolerant pass takes the nearly dependent one
    let mut c = DenseCholesky::new(2);
    c.set_max_dependent(1);
    gram(&mut c, &[g0, [d.cos(), d.sin(), 0.0]]);
    c.factor_in_place().expect("tolerant pass");
    assert_eq!(c.dependent(), &[1]);
    // two dependencies at round-off with a budget of one: singular
    let e = 1e-7f64;
    let mut c = DenseCholesky::new(3);
    c.set_max_dependent(1);
    gram(&mut c, &[g0, [e.cos(), e.sin(), 0.0], g0]);
    assert!(c.factor_in_place().is_err());
}
#[test]
fn cholesky_solves_and_detects_indefinite() {
    let mut c = DenseCholesky::new(2);
    {
        let mut a = c.matrix_mut();
        a[(0, 0)] = 4.0;
        a[(1, 0)] = 1.0;
        a[(0, 1)] = 1.0;
        a[(1, 1)] = 3.0;
    }
    c.factor_in_place().unwrap();
    let mut b = [1.0, 2.0];
    c.solve_in_place(&mut b);
    assert!((4.0 * b[0] + b[1] - 1.0).abs() < 1e-14);
    assert!((b[0] + 3.0 * b[1] - 2.0).abs() < 1e-14);
    {
        let mut a = c.matrix_mut();
        a[(0, 0)] = 1.0;
        a[(1, 0)] = 1.0;
        a[(0, 1)] = 1.0;
        a[(1, 1)] = 1.0;
    }
    assert!(c.factor_in_place().is_err());
}

fn factor_2x2(c: &mut DenseCholesky, a: [[f64; 2]; 2]) -> Result<(), FactorError> {
    {
        let mut m = c.matrix_mut();
        for i in 0..2 {
            for j in 0..2 {
                m[(i, j)] = a[i][j];
            }
        }
    }
    c.factor_in_place()
}

#[test]
fn cholesky_pivot_test_and_condition_are_scale_invariant() {
    // [[1, 0.5], [0.5, 1]] scaled by D = diag(1e-8, 1e8): the old test (pivots relative to
    // the largest pivot) called this singular; the matrix is perfectly conditioned after
    // equilibration.
    let mut c = DenseCholesky::new(2);
    factor_2x2(&mut c, [[1.0, 0.5], [0.5, 1.0]]).unwrap();
    let k0 = c.condition_estimate();
    assert!((k0 - 4.0 / 3.0).abs() < 1e-12, "{k0}");
    let (d0, d1) = (1e-8, 1e8);
    factor_2x2(&mut c, [[d0 * d0, 0.5 * d0 * d1], [0.5 * d0 * d1, d1 * d1]]).unwrap();
    assert!((c.condition_estimate() - k0).abs() < 1e-10);
    // nearly dependent rows: the estimate grows like 1 / (1 - c^2)
    let eps = 1e-5;
    factor_2x2(&mut c, [[1.0, 1.0 - eps], [1.0 - eps, 1.0]]).unwrap();
    let k = c.condition_estimate();
    assert!(k > 0.4 / eps && k < 0.6 / eps, "{k}");
    // dependent to round-off: an error at any scale, and the estimate says so
    for scale in [1e-12, 1.0, 1e12] {
        let r = factor_2x2(&mut c, [[scale, scale], [scale, scale * (1.0 + 1e-16)]]);
        assert_eq!(r, Err(FactorError::NotPositiveDefinite(1)), "scale {scale}");
        assert!(c.condition_estimate().is_infinite());
    }
    // NaN on the diagonal
    assert!(factor_2x2(&mut c, [[f64::NAN, 0.0], [0.0, 1.0]]).is_err());
}

#[test]
fn small_and_blocked_cholesky_agree() {
    for m in [
        1usize,
        2,
        3,
        4,
        FIXED_CHOLESKY,
        FIXED_CHOLESKY + 1,
        SMALL_CHOLESKY,
        SMALL_CHOLESKY + 5,
        SMALL_CHOLESKY_SOLVE,
        SMALL_CHOLESKY_SOLVE + 5,
    ] {
        let mut c = DenseCholesky::new(m);
        // S = B B^T + I with a deterministic B
        let b: Vec<f64> = (0..m * m)
            .map(|k| ((k * 7919) % 23) as f64 / 23.0 - 0.4)
            .collect();
        c.clear();
        for k in 0..m {
            let col: Vec<f64> = (0..m).map(|r| b[r * m + k]).collect();
            c.add_rank_one(1.0, &col);
        }
        for i in 0..m {
            c.add_rank_one(
                1.0,
                &(0..m)
                    .map(|r| if r == i { 1.0 } else { 0.0 })
                    .collect::<Vec<_>>(),
            );
        }
        let s: Vec<f64> = c.a.clone();
        c.factor_in_place().unwrap();
        let x: Vec<f64> = (0..m).map(|i| (i as f64 * 0.37).sin()).collect();
        // b = S x using the lower triangle of s
        let mut rhs = vec![0.0; m];
        for i in 0..m {
            for j in 0..m {
                let sij = if i >= j { s[i + j * m] } else { s[j + i * m] };
                rhs[i] += sij * x[j];
            }
        }
        let mut sx = rhs.clone();
        c.solve_in_place(&mut rhs);
        for i in 0..m {
            assert!((rhs[i] - x[i]).abs() < 1e-12, "m = {m}");
        }
        // forward_in_place: (L^-1 (S x)) . (L^-1 y) = x . y for any y, on both paths
        let y: Vec<f64> = (0..m).map(|i| (i as f64 * 1.1 + 0.2).cos()).collect();
        let mut ly = y.clone();
        c.forward_in_place(&mut sx);
        c.forward_in_place(&mut ly);
        let lhs: f64 = sx.iter().zip(&ly).map(|(a, b)| a * b).sum();
        let xy: f64 = x.iter().zip(&y).map(|(a, b)| a * b).sum();
        assert!(
            (lhs - xy).abs() < 1e-12 * (1.0 + xy.abs()),
            "m = {m}: {lhs} vs {xy}"
        );
        // add() sums into the lower triangle like add_rank_one
        let mut d = DenseCholesky::new(m);
        d.clear();
        for cidx in 0..m {
            for r in cidx..m {
                d.add(r, cidx, s[r + cidx * m]);
            }
        }
        for cidx in 0..m {
            for r in cidx..m {
                assert_eq!(d.a[r + cidx * m], s[r + cidx * m]);
            }
        }
    }
}

/// The fixed-dimension kernels and the run-time-length small path are the textbook
/// dot-product Cholesky and triangular solves, operation for operation (bit for bit).
#[test]
fn small_kernels_are_the_textbook_factorisation_bit_for_bit() {
    for m in 1..=SMALL_CHOLESKY {
        // a well-conditioned SPD matrix with distinct entries
        let s: Vec<f64> = (0..m * m)
            .map(|k| {
                let (i, j) = (k % m, k / m);
                let x = 0.3 * ((i * 7 + j * 7 + i * j) as f64 * 0.61).sin();
                if i == j {
                    2.0 + m as f64 * 0.5 + x
                } else {
                    x
                }
            })
            .collect();
        // textbook L (lower, column-major) and 1 / L_jj
        let mut l = vec![0.0; m * m];
        for j in 0..m {
            let mut d = s[j + j * m];
            for k in 0..j {
                d -= l[j + k * m] * l[j + k * m];
            }
            l[j + j * m] = d.sqrt();
            let inv = 1.0 / l[j + j * m];
            for i in j + 1..m {
                let mut y = s[i + j * m];
                for k in 0..j {
                    y -= l[i + k * m] * l[j + k * m];
                }
                l[i + j * m] = y * inv;
            }
        }
        let mut c = DenseCholesky::new(m);
        c.values_mut().copy_from_slice(&s);
        c.factor_in_place().unwrap();
        for j in 0..m {
            for i in j..m {
                assert_eq!(c.a[i + j * m].to_bits(), l[i + j * m].to_bits(), "m = {m}");
            }
        }
        let b: Vec<f64> = (0..m).map(|i| (i as f64 * 0.37 + 0.1).cos()).collect();
        let mut y = b.clone();
        for i in 0..m {
            for k in 0..i {
                y[i] -= l[i + k * m] * y[k];
            }
            y[i] *= 1.0 / l[i + i * m];
        }
        let mut fwd = b.clone();
        c.forward_in_place(&mut fwd);
        let mut x = y.clone();
        for i in (0..m).rev() {
            let mut acc = 0.0;
            for k in i + 1..m {
                acc += l[k + i * m] * x[k];
            }
            x[i] = (x[i] - acc) * (1.0 / l[i + i * m]);
        }
        let mut sol = b.clone();
        c.solve_in_place(&mut sol);
        for i in 0..m {
            assert_eq!(fwd[i].to_bits(), y[i].to_bits(), "forward, m = {m}");
            assert_eq!(sol[i].to_bits(), x[i].to_bits(), "solve, m = {m}");
        }
    }
}
