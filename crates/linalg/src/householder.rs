//! Householder QR on column-major slices with the reflectors stored full length, and the
//! triangular solves and products with its `R`: allocation-free kernels for small dense
//! systems (the tangent chart's QR of `[Phi_q^T | X^T]`). Every function is
//! `#[inline(always)]` and takes the length `n` (or `mm`) last, so a caller that passes a
//! literal (through a `match` on the small sizes it meets) gets each arm compiled with the
//! length known: unrolled loops, no bounds checks.

/// Householder QR of the first `kcols` columns of the `n x tcols` column-major matrix `a`
/// (`n >= kcols`), applying each reflector also to the columns `kcols..tcols`. Afterwards the
/// first `kcols` columns hold `R` on and above the diagonal and zeros below, the others
/// `H_(kcols-1) ... H_0` times their input; the reflectors `H_k = I - tau_k v_k v_k^T` are
/// stored full length in `v` (`n x kcols`: `v_k[i] = 0` for `i < k`, `v_k[k] = 1`), so that
/// applying one is a product over all `n` rows (see [`reflect`]). The reflector of a column is
/// LAPACK `dgeqr2`'s (`beta = -sign(x_0) |x|`, `tau = (beta - x_0) / beta`).
#[inline(always)]
pub fn qr_padded(
    a: &mut [f64],
    kcols: usize,
    tcols: usize,
    v: &mut [f64],
    tau: &mut [f64],
    n: usize,
) {
    for k in 0..kcols {
        let (head, tail) = a[..tcols * n].split_at_mut((k + 1) * n);
        let col = &mut head[k * n..];
        let vk = &mut v[k * n..(k + 1) * n];
        let x0 = col[k];
        let mut sigma = 0.0;
        for &x in &col[k + 1..] {
            sigma += x * x;
        }
        vk.fill(0.0);
        vk[k] = 1.0;
        if sigma == 0.0 {
            tau[k] = 0.0;
            continue;
        }
        let norm = (x0 * x0 + sigma).sqrt();
        let beta = if x0 >= 0.0 { -norm } else { norm };
        let tk = (beta - x0) / beta;
        tau[k] = tk;
        let scale = 1.0 / (x0 - beta);
        for (vi, ci) in vk[k + 1..].iter_mut().zip(col[k + 1..].iter_mut()) {
            *vi = *ci * scale;
            *ci = 0.0;
        }
        col[k] = beta;
        let vk = &v[k * n..(k + 1) * n];
        for cj in tail[..(tcols - k - 1) * n].chunks_exact_mut(n) {
            reflect(vk, tk, cj, n);
        }
    }
}

/// `y <- (I - tau v v^T) y` for vectors of length `n`.
#[inline(always)]
pub fn reflect(v: &[f64], tau: f64, y: &mut [f64], n: usize) {
    let (v, y) = (&v[..n], &mut y[..n]);
    let mut s = [0.0f64; 2];
    for i in 0..n {
        s[i % 2] += v[i] * y[i];
    }
    let w = tau * (s[0] + s[1]);
    if w != 0.0 {
        for i in 0..n {
            y[i] -= w * v[i];
        }
    }
}

/// The explicit orthogonal factor `Q = H_0 ... H_(k-1)` (`n x n`, column-major) of the
/// reflectors `v`, `tau` of [`qr_padded`] (`k = tau.len()`), by backward accumulation (LAPACK
/// `dorg2r`): `Q <- H_l Q` for `l = k-1, ..., 0` from the identity. `H_l` leaves the columns
/// `e_j`, `j < l`, alone (`v_l` vanishes above row `l`) and maps `e_l` to `e_l - tau_l v_l`
/// (`v_l[l] = 1`), so only the columns after `l` need a reflection: `sum_l (n - 1 - l)`
/// reflections instead of one per reflector and column.
#[inline(always)]
pub fn form_q_padded(v: &[f64], tau: &[f64], q: &mut [f64], n: usize) {
    let k = tau.len();
    let q = &mut q[..n * n];
    q.fill(0.0);
    for j in k..n {
        q[j * n + j] = 1.0;
    }
    for l in (0..k).rev() {
        let (vl, tl) = (&v[l * n..(l + 1) * n], tau[l]);
        let (head, tail) = q.split_at_mut((l + 1) * n);
        for col in tail.chunks_exact_mut(n) {
            reflect(vl, tl, col, n);
        }
        let col = &mut head[l * n..];
        for i in 0..n {
            col[i] = -tl * vl[i];
        }
        col[l] += 1.0;
    }
}

/// `u = R^-T f` for the upper triangular `R` (`mm x mm`, column `i` at `r[i * stride..]`)
/// with the reciprocals of its diagonal in `dinv`: forward substitution, row `i` of `R^T` being
/// column `i` of `R` above the diagonal.
#[inline(always)]
pub fn solve_rt(r: &[f64], stride: usize, dinv: &[f64], f: &[f64], u: &mut [f64], mm: usize) {
    let (f, u, dinv) = (&f[..mm], &mut u[..mm], &dinv[..mm]);
    for i in 0..mm {
        let col = &r[i * stride..i * stride + i];
        let mut acc = f[i];
        for k in 0..i {
            acc -= col[k] * u[k];
        }
        u[i] = acc * dinv[i];
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `Q [R | Q^T B] = [A | B]` with `R` upper triangular and `Q` orthogonal, and the
    /// triangular solve against the product with `R^T`.
    #[test]
    fn padded_qr_reconstructs_and_the_triangular_solve_inverts() {
        for rows in [6usize, 7] {
            let (kcols, tcols) = (3, 5);
            let a0: Vec<f64> = (0..rows * tcols)
                .map(|i| ((i * 37 % 11) as f64 - 5.0) * 0.3 + if i % 9 == 0 { 2.0 } else { 0.0 })
                .collect();
            let mut a = a0.clone();
            let (mut v, mut tau) = (vec![0.0; rows * kcols], vec![0.0; kcols]);
            qr_padded(&mut a, kcols, tcols, &mut v, &mut tau, rows);
            let mut q = vec![0.0; rows * rows];
            form_q_padded(&v, &tau, &mut q, rows);
            for i in 0..rows {
                for j in 0..rows {
                    let d: f64 = (0..rows).map(|k| q[i * rows + k] * q[j * rows + k]).sum();
                    let e = if i == j { 1.0 } else { 0.0 };
                    assert!((d - e).abs() < 1e-14, "({i},{j}) {d}");
                }
            }
            for j in 0..tcols {
                for i in 0..rows {
                    if j < kcols && i > j {
                        assert_eq!(a[j * rows + i], 0.0);
                    }
                    let s: f64 = (0..rows).map(|k| q[k * rows + i] * a[j * rows + k]).sum();
                    assert!((s - a0[j * rows + i]).abs() < 1e-13, "({i},{j})");
                }
            }
            // R (the first kcols columns, stride rows): R^-T (R^T x) = x
            let dinv: Vec<f64> = (0..kcols).map(|i| 1.0 / a[i * rows + i]).collect();
            let x = [0.7, -1.3, 2.1];
            let mut y = [0.0; 3];
            // R^T x by hand, then solve_rt
            let mut rtx = [0.0; 3];
            for i in 0..kcols {
                for k in 0..=i {
                    rtx[i] += a[i * rows + k] * x[k];
                }
            }
            solve_rt(&a, rows, &dinv, &rtx, &mut y, kcols);
            for i in 0..kcols {
                assert!((y[i] - x[i]).abs() < 1e-13, "R^-T R^T x [{i}]");
            }
        }
    }
}
