//! Tests of the dense LU: pivoting, pattern growth, fallback, scaling, transposed solves.

use super::*;

fn fill(lu: &mut DenseLu, a: &[f64]) {
    let n = lu.n;
    lu.clear();
    for i in 0..n {
        for j in 0..n {
            lu.set(i, j, a[i * n + j]);
        }
    }
}

#[test]
fn solves_with_pivoting() {
    let mut lu = DenseLu::new(3);
    let a = [0.0, 2.0, 1.0, 1.0, 1.0, 0.0, 3.0, 0.0, 1.0];
    fill(&mut lu, &a);
    lu.factor_lu().unwrap();
    let x = [1.0, -2.0, 0.5];
    let mut b: Vec<f64> = (0..3)
        .map(|i| (0..3).map(|j| a[i * 3 + j] * x[j]).sum())
        .collect();
    lu.solve_in_place(&mut b);
    for i in 0..3 {
        assert!((b[i] - x[i]).abs() < 1e-14);
    }
    let mut s = DenseLu::new(2);
    fill(&mut s, &[1.0, 2.0, 2.0, 4.0]);
    assert_eq!(s.factor_lu(), Err(LuError::Singular { row: 1, col: 1 }));
}

/// Sparse matrices with fill-in and pivoting: the solution satisfies `A x = b`.
#[test]
fn solves_sparse_systems_with_fill_in() {
    for (n, seed) in [(7usize, 1u64), (20, 2), (31, 3)] {
        let mut state = seed;
        let mut rnd = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 11) as f64) / ((1u64 << 53) as f64)
        };
        // a scrambled ordering: reversed rows, rotated columns
        let mut lu = DenseLu::with_ordering(
            (0..n).rev().collect(),
            (0..n).map(|j| (j + 3) % n).collect(),
        );
        let mut a = vec![0.0; n * n];
        for i in 0..n {
            for j in 0..n {
                // a sparse pattern plus a permuted diagonal (the system stays regular)
                a[i * n + j] = if rnd() < 0.2 { rnd() - 0.5 } else { 0.0 };
            }
            a[i * n + (i * 3 + 1) % n] += 2.0;
        }
        fill(&mut lu, &a);
        lu.factor_lu().unwrap();
        let x: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin()).collect();
        let mut b: Vec<f64> = (0..n)
            .map(|i| (0..n).map(|j| a[i * n + j] * x[j]).sum())
            .collect();
        lu.solve_in_place(&mut b);
        for i in 0..n {
            assert!(
                (b[i] - x[i]).abs() < 1e-12,
                "n = {n}: x[{i}] off by {:e}",
                b[i] - x[i]
            );
        }
    }
}

fn check(lu: &mut DenseLu, a: &[f64]) {
    let n = lu.n;
    let x: Vec<f64> = (0..n).map(|i| 1.0 + (i as f64 * 0.37).sin()).collect();
    let mut b: Vec<f64> = (0..n)
        .map(|i| (0..n).map(|j| a[i * n + j] * x[j]).sum())
        .collect();
    lu.solve_in_place(&mut b);
    for i in 0..n {
        assert!(
            (b[i] - x[i]).abs() < 1e-12,
            "x[{i}] off by {:e}",
            b[i] - x[i]
        );
    }
}

/// The pattern grows when a new entry becomes nonzero (a new symbolic factorisation), the
/// static pivots are used while they pass the threshold, and a failing diagonal pivot falls
/// back to partial pivoting with the same solution.
#[test]
fn pattern_growth_and_pivot_fallback() {
    let n = 4;
    let mut lu = DenseLu::new(n);
    let mut a = vec![
        4.0, 1.0, 0.0, 0.0, //
        1.0, 4.0, 0.0, 0.0, //
        0.0, 0.0, 4.0, 1.0, //
        0.0, 0.0, 1.0, 4.0,
    ];
    fill(&mut lu, &a);
    lu.factor_lu().unwrap();
    check(&mut lu, &a);
    assert_eq!((lu.analyses(), lu.fallbacks()), (1, 0));
    // same pattern: no new analysis
    a[0] = 5.0;
    fill(&mut lu, &a);
    lu.factor_lu().unwrap();
    check(&mut lu, &a);
    assert_eq!((lu.analyses(), lu.fallbacks()), (1, 0));
    // a coupling appears: re-analysed, with fill-in
    a[3] = 2.0;
    a[3 * n] = -1.0;
    fill(&mut lu, &a);
    lu.factor_lu().unwrap();
    check(&mut lu, &a);
    assert_eq!((lu.analyses(), lu.fallbacks()), (2, 0));
    // a zero diagonal: the static pivot fails, partial pivoting takes over
    a[0] = 0.0;
    fill(&mut lu, &a);
    lu.factor_lu().unwrap();
    check(&mut lu, &a);
    assert_eq!(lu.fallbacks(), 1);
    // singular: an error naming the pivot
    let z = vec![0.0; n * n];
    fill(&mut lu, &z);
    assert_eq!(lu.factor_lu(), Err(LuError::Singular { row: 0, col: 0 }));
    // non-finite entries are named, wherever they are
    for (pos, bad) in [(5, f64::NAN), (3 * n, f64::INFINITY), (3, f64::NAN)] {
        let mut m = a.clone();
        m[pos] = bad;
        fill(&mut lu, &m);
        assert_eq!(
            lu.factor_lu(),
            Err(LuError::NonFinite {
                row: pos / n,
                col: pos % n
            })
        );
    }
}

/// A test matrix shaped like the stage Jacobian: a regular `n x n` block `K` (momentum
/// rows, displacement unknowns) coupled to `m` multipliers through `B` (columns) and `C`
/// (constraint rows), zero multiplier block.
fn saddle(n: usize, m: usize, seed: u64) -> Vec<f64> {
    let mut state = seed;
    let mut rnd = || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((state >> 11) as f64) / ((1u64 << 53) as f64) - 0.5
    };
    let d = n + m;
    let mut a = vec![0.0; d * d];
    for i in 0..n {
        a[i * d + i] = 2.0 + rnd();
        if i + 1 < n {
            a[i * d + i + 1] = rnd();
            a[(i + 1) * d + i] = rnd();
        }
    }
    for r in 0..m {
        for i in 0..n {
            if (i + r) % 3 != 2 {
                let g = rnd();
                a[i * d + n + r] = g;
                a[(n + r) * d + i] = g + 0.1 * rnd();
            }
        }
    }
    a
}

/// `D_r A D_c` with row and column scales spanning `10^-span..10^span` (not powers of two).
fn scaled(a: &[f64], d: usize, span: f64) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let dr: Vec<f64> = (0..d)
        .map(|i| 10f64.powf(span * ((i * 7 % d) as f64 / d as f64 * 2.0 - 1.0)))
        .collect();
    let dc: Vec<f64> = (0..d)
        .map(|j| 10f64.powf(span * ((j * 5 % d) as f64 / d as f64 * 2.0 - 1.0)) * 1.37)
        .collect();
    let mut s = a.to_vec();
    for i in 0..d {
        for j in 0..d {
            s[i * d + j] *= dr[i] * dc[j];
        }
    }
    (s, dr, dc)
}

/// Regular matrices whose rows and columns are scaled by up to 1e+-12 (the stage equations
/// of a badly scaled mechanism at tiny h): factored, and solved to a relative accuracy that
/// does not depend on the scaling. Before the equilibration, every scaled case failed as
/// "singular" (pivot below 1e-14 max |A|).
#[test]
fn badly_scaled_regular_matrices_are_solved() {
    let (n, m) = (12, 4);
    let d = n + m;
    let order: Vec<usize> = (0..d).collect();
    for seed in 1..=3 {
        let a = saddle(n, m, seed);
        for span in [0.0, 4.0, 8.0, 12.0] {
            let (s, _, dc) = scaled(&a, d, span);
            let mut lu = DenseLu::with_ordering(order.clone(), order.clone());
            fill(&mut lu, &s);
            lu.factor_lu()
                .unwrap_or_else(|e| panic!("seed {seed}, span 1e{span}: {e:?}"));
            // x = D_c^-1 y with y of unit size, so the scaled system has a well-scaled answer
            let y: Vec<f64> = (0..d).map(|i| 1.0 + (i as f64 * 0.37).sin()).collect();
            let x: Vec<f64> = (0..d).map(|j| y[j] / dc[j]).collect();
            let mut b: Vec<f64> = (0..d)
                .map(|i| (0..d).map(|j| s[i * d + j] * x[j]).sum())
                .collect();
            lu.solve_in_place(&mut b);
            let err = (0..d)
                .map(|j| ((b[j] - x[j]) * dc[j]).abs())
                .fold(0.0, f64::max);
            assert!(err < 1e-12, "seed {seed}, span 1e{span}: error {err:e}");
        }
    }
}

/// Singular matrices stay singular at every scaling: a rank-deficient multiplier block
/// (two constraint rows equal: redundant constraints) and a zero column, scaled by up to
/// 1e+-12.
#[test]
fn singular_matrices_are_reported_at_every_scaling() {
    let (n, m) = (12, 4);
    let d = n + m;
    let order: Vec<usize> = (0..d).collect();
    let a = saddle(n, m, 7);
    // redundant: constraint row n + 3 repeats row n + 1 (and so does its column)
    let mut red = a.clone();
    for i in 0..n {
        red[(n + 3) * d + i] = red[(n + 1) * d + i];
        red[i * d + n + 3] = red[i * d + n + 1];
    }
    // a multiplier that enters no equation
    let mut zc = a.clone();
    for i in 0..d {
        zc[i * d + n + 2] = 0.0;
    }
    for span in [0.0, 4.0, 8.0, 12.0] {
        for (what, base) in [("redundant", &red), ("zero column", &zc)] {
            let (s, ..) = scaled(base, d, span);
            let mut lu = DenseLu::with_ordering(order.clone(), order.clone());
            fill(&mut lu, &s);
            match lu.factor_lu() {
                Err(LuError::Singular { row, col }) => {
                    assert!(row >= n && col >= n, "{what}, 1e{span}: ({row}, {col})")
                }
                other => panic!("{what}, span 1e{span}: expected singular, got {other:?}"),
            }
        }
    }
}

/// The matrix API (copy in, factor, solve) and its singular test, the transposed solve and
/// `ln |det|`, on both elimination paths (static pivots and the threshold-pivoting fallback).
#[test]
fn matrix_api_transpose_solve_and_determinant() {
    let a = DMatrix::from_row_slice(3, 3, &[2.0, 1.0, 0.0, 1.0, 3.0, 1.0, 0.0, 1.0, 4.0]);
    let mut lu = DenseLu::new(3);
    lu.factor(&a).unwrap();
    let x = [1.0, -2.0, 0.5];
    let mut b: Vec<f64> = (0..3)
        .map(|i| (0..3).map(|j| a[(i, j)] * x[j]).sum())
        .collect();
    lu.solve_in_place(&mut b);
    for i in 0..3 {
        assert!((b[i] - x[i]).abs() < 1e-14);
    }
    let s = DMatrix::from_row_slice(2, 2, &[1.0, 2.0, 2.0, 4.0]);
    let mut lu2 = DenseLu::new(2);
    assert!(matches!(lu2.factor(&s), Err(FactorError::Singular(_))));
    // a small diagonal entry sends the first pivot to the fallback path
    let m = [
        0.01, 2.0, -1.0, 0.5, //
        3.0, 0.2, 0.0, 1.0, //
        -1.0, 0.5, 4.0, 0.0, //
        0.0, 1.0, 1.0, -2.0,
    ];
    let det = {
        let d3 = |a: [f64; 9]| {
            a[0] * (a[4] * a[8] - a[5] * a[7]) - a[1] * (a[3] * a[8] - a[5] * a[6])
                + a[2] * (a[3] * a[7] - a[4] * a[6])
        };
        let minor = |c: usize| {
            let mut out = [0.0; 9];
            let mut k = 0;
            for r in 1..4 {
                for cc in (0..4).filter(|&cc| cc != c) {
                    out[k] = m[r * 4 + cc];
                    k += 1;
                }
            }
            d3(out)
        };
        (0..4)
            .map(|c| if c % 2 == 0 { 1.0 } else { -1.0 } * m[c] * minor(c))
            .sum::<f64>()
    };
    for (rows, cols) in [
        ((0..4).collect::<Vec<_>>(), (0..4).collect::<Vec<_>>()),
        (vec![2, 0, 3, 1], vec![1, 3, 0, 2]),
    ] {
        let mut lu = DenseLu::with_ordering(rows, cols);
        lu.clear();
        for r in 0..4 {
            for c in 0..4 {
                lu.set(r, c, m[r * 4 + c]);
            }
        }
        lu.factor_lu().unwrap();
        assert!((lu.log_abs_det() - det.abs().ln()).abs() < 1e-13, "{det}");
        let (lo, hi) = lu.pivot_range();
        assert!(lo > 0.0 && hi >= lo);
        let x = [1.0, -2.0, 0.5, 3.0];
        let mut b: Vec<f64> = (0..4)
            .map(|r| (0..4).map(|c| m[r * 4 + c] * x[c]).sum())
            .collect();
        lu.solve_in_place(&mut b);
        let mut bt: Vec<f64> = (0..4)
            .map(|c| (0..4).map(|r| m[r * 4 + c] * x[r]).sum())
            .collect();
        lu.solve_transpose_in_place(&mut bt);
        for i in 0..4 {
            assert!((b[i] - x[i]).abs() < 1e-13, "{b:?}");
            assert!((bt[i] - x[i]).abs() < 1e-13, "{bt:?}");
        }
    }
    // raw writes through the row-major storage, pivot_tol = 0: only exact zeros fail
    let mut lu = DenseLu::new(2);
    lu.pivot_tol = 0.0;
    lu.rows_mut().copy_from_slice(&[1.0, 2.0, 2.0, 4.0 + 1e-15]);
    assert!(lu.factor_lu().is_ok());
    lu.rows_mut().copy_from_slice(&[1.0, 2.0, 2.0, 4.0]);
    assert!(lu.factor_lu().is_err());
}

/// The 6 x 6 saddle-point matrix `[[diag(m), G^T], [G, 0]]` (row-major) whose constraint rows 1
/// and 2 of `G` are equal (a redundant equation).
fn redundant_saddle(m: [f64; 3]) -> Vec<f64> {
    let g = [[1.0, 0.0, 1.0], [0.0, 1.0, -1.0], [0.0, 1.0, -1.0]];
    let n = 6;
    let mut a = vec![0.0; n * n];
    for i in 0..3 {
        a[i * n + i] = m[i];
        for r in 0..3 {
            a[i * n + 3 + r] = g[r][i];
            a[(3 + r) * n + i] = g[r][i];
        }
    }
    a
}

/// A saddle-point matrix `[[M, G^T], [G, 0]]` whose constraint rows 1 and 2 of `G` are equal
/// (a redundant equation): singular as it is; with one droppable multiplier pivot the LU drops
/// the second of the two, gives it a zero unknown, and solves a consistent system exactly.
#[test]
fn a_dependent_multiplier_pivot_is_dropped_on_request() {
    // unknowns: x0, x1, x2 (M = diag(2, 1, 4)), then multipliers l0, l1, l2
    let (n, a) = (6, redundant_saddle([2.0, 1.0, 4.0]));
    let mut lu = DenseLu::new(n);
    fill(&mut lu, &a);
    assert!(lu.factor_lu().is_err());
    lu.set_droppable(3, 1);
    fill(&mut lu, &a);
    lu.factor_lu().unwrap();
    assert_eq!(lu.dropped().collect::<Vec<_>>(), [5]);
    // b = A [x; l] with l2 = 0 (in the range)
    let sol = [0.5, -1.0, 0.25, 2.0, -3.0, 0.0];
    let mut b: Vec<f64> = (0..n)
        .map(|i| (0..n).map(|j| a[i * n + j] * sol[j]).sum())
        .collect();
    lu.solve_in_place(&mut b);
    assert_eq!(b[5], 0.0);
    for i in 0..n {
        assert!((b[i] - sol[i]).abs() < 1e-14, "{i}: {} vs {}", b[i], sol[i]);
    }
}

/// The same redundant saddle-point matrix when the static order fails its threshold test
/// (a tiny first diagonal entry forces the pivoting fallback): the general path drops the
/// dependent multiplier column and leaves the dependent equation out, and the consistent
/// system is solved exactly, by both the direct and the transposed solve.
#[test]
fn the_pivoting_fallback_drops_a_dependent_multiplier_too() {
    let (n, a) = (6, redundant_saddle([1e-6, 1.0, 4.0]));
    let mut lu = DenseLu::new(n);
    lu.set_droppable(3, 1);
    fill(&mut lu, &a);
    lu.factor_lu().unwrap();
    assert_eq!(lu.fallbacks(), 1, "the static order must have failed");
    let dropped: Vec<usize> = lu.dropped().collect();
    assert_eq!(dropped.len(), 1);
    assert!(dropped[0] == 4 || dropped[0] == 5, "{dropped:?}");
    let mut sol = [0.5, -1.0, 0.25, 2.0, -3.0, 1.5];
    sol[dropped[0]] = 0.0;
    let mut b: Vec<f64> = (0..n)
        .map(|i| (0..n).map(|j| a[i * n + j] * sol[j]).sum())
        .collect();
    let mut bt = b.clone();
    lu.solve_in_place(&mut b);
    for i in 0..n {
        assert!((b[i] - sol[i]).abs() < 1e-12, "{i}: {} vs {}", b[i], sol[i]);
    }
    // A is symmetric: the transposed solve gives the same basic solution
    lu.solve_transpose_in_place(&mut bt);
    for i in 0..n {
        assert!(
            (bt[i] - sol[i]).abs() < 1e-12,
            "{i}: {} vs {}",
            bt[i],
            sol[i]
        );
    }
    // without the drop the fallback reports the dependent column
    let mut plain = DenseLu::new(n);
    fill(&mut plain, &a);
    assert!(plain.factor_lu().is_err());
}
