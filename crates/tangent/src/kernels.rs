//! Small dense kernels of the tangent chart: Householder QR with its `Q`, column-blocked
//! matrix-vector products, rank-one updates, `axpy` and `dot` (allocation-free, on
//! column-major slices).

/// Householder QR of the `rows x cols` column-major matrix `a` (`rows >= cols`) in place
/// (LAPACK `dgeqr2` conventions): `R` in the upper triangle, the essential parts of the
/// Householder vectors `v_k` (with `v_k[k] = 1`) below the diagonal, `H_k = I - tau_k v_k v_k^T`,
/// `a = H_0 H_1 ... H_{cols-1} [R; 0]`. The first `short` columns must vanish below row `half`
/// (true of `Df^T`: its first `m` columns are `(Phi_q^T, 0)`); their reflectors then act on rows
/// `k..half` only and the others never refill those zeros.
pub(crate) fn householder_qr(
    a: &mut [f64],
    tau: &mut [f64],
    rows: usize,
    cols: usize,
    short: usize,
    half: usize,
) {
    for k in 0..cols {
        let end = if k < short { half } else { rows };
        let (head, tail) = a.split_at_mut((k + 1) * rows);
        let col = &mut head[k * rows..];
        let x0 = col[k];
        let sigma: f64 = col[k + 1..end].iter().map(|x| x * x).sum();
        if sigma == 0.0 {
            tau[k] = 0.0;
            continue;
        }
        let norm = (x0 * x0 + sigma).sqrt();
        let beta = if x0 >= 0.0 { -norm } else { norm };
        tau[k] = (beta - x0) / beta;
        let scale = 1.0 / (x0 - beta);
        for x in col[k + 1..end].iter_mut() {
            *x *= scale;
        }
        col[k] = beta;
        let v = &col[k + 1..end];
        let tk = tau[k];
        for j in 0..cols - k - 1 {
            let cj = &mut tail[j * rows..(j + 1) * rows];
            let w = cj[k] + dot(v, &cj[k + 1..end]);
            let s = tk * w;
            cj[k] -= s;
            axpy(-s, v, &mut cj[k + 1..end]);
        }
    }
}

/// `q = H_0 H_1 ... H_{cols-1}` (`rows x rows`, column-major) by backward accumulation, for the
/// factors of [`householder_qr`] with the same `short` and `half`.
pub(crate) fn form_q(
    a: &[f64],
    tau: &[f64],
    rows: usize,
    cols: usize,
    short: usize,
    half: usize,
    q: &mut [f64],
) {
    q.fill(0.0);
    for i in 0..rows {
        q[i * rows + i] = 1.0;
    }
    for k in (0..cols).rev() {
        let tk = tau[k];
        if tk == 0.0 {
            continue;
        }
        let end = if k < short { half } else { rows };
        let v = &a[k * rows + k + 1..k * rows + end];
        // columns < k of H_k ... H_{cols-1} are still unit vectors with zero rows >= k
        for j in k..rows {
            let cj = &mut q[j * rows..(j + 1) * rows];
            let w = cj[k] + dot(v, &cj[k + 1..end]);
            if w != 0.0 {
                let s = tk * w;
                cj[k] -= s;
                axpy(-s, v, &mut cj[k + 1..end]);
            }
        }
    }
}

/// `y += sum_k a_k c_k` for the column-major matrix `cols` whose columns `c_k` have the length
/// of `y` (`a.len()` of them), four columns per pass over `y`.
#[inline]
pub(crate) fn gemv_cols(cols: &[f64], a: &[f64], y: &mut [f64]) {
    let r = y.len();
    if r == 0 {
        return;
    }
    let cols = &cols[..a.len() * r];
    let mut blocks = cols.chunks_exact(4 * r);
    let mut coef = a.chunks_exact(4);
    for (b, c) in (&mut blocks).zip(&mut coef) {
        let (c0, rest) = b.split_at(r);
        let (c1, rest) = rest.split_at(r);
        let (c2, c3) = rest.split_at(r);
        let (a0, a1, a2, a3) = (c[0], c[1], c[2], c[3]);
        for ((((yi, x0), x1), x2), x3) in y.iter_mut().zip(c0).zip(c1).zip(c2).zip(c3) {
            *yi += (a0 * x0 + a1 * x1) + (a2 * x2 + a3 * x3);
        }
    }
    for (col, &ak) in blocks.remainder().chunks_exact(r).zip(coef.remainder()) {
        axpy(ak, col, y);
    }
}

/// `out_k = c_k . y` for the columns `c_k` (of the length of `y`, `out.len()` of them) of the
/// column-major matrix `cols`, four columns per pass over `y`.
#[inline]
pub(crate) fn gemv_t_cols(cols: &[f64], y: &[f64], out: &mut [f64]) {
    let r = y.len();
    if r == 0 {
        out.fill(0.0);
        return;
    }
    let cols = &cols[..out.len() * r];
    let mut blocks = cols.chunks_exact(4 * r);
    let mut outs = out.chunks_exact_mut(4);
    for (b, o) in (&mut blocks).zip(&mut outs) {
        let (c0, rest) = b.split_at(r);
        let (c1, rest) = rest.split_at(r);
        let (c2, c3) = rest.split_at(r);
        let mut d = [0.0f64; 4];
        for ((((yi, x0), x1), x2), x3) in y.iter().zip(c0).zip(c1).zip(c2).zip(c3) {
            d[0] += yi * x0;
            d[1] += yi * x1;
            d[2] += yi * x2;
            d[3] += yi * x3;
        }
        o.copy_from_slice(&d);
    }
    for (col, o) in blocks
        .remainder()
        .chunks_exact(r)
        .zip(outs.into_remainder())
    {
        *o = dot(col, y);
    }
}

/// `P <- P - c w (s^T P)` for the column-major matrix `p` with columns of the length of `s`
/// and `w`: per column `p_k -= c (s . p_k) w`, two columns per pass.
#[inline]
pub(crate) fn rank_one_update(p: &mut [f64], s: &[f64], w: &[f64], c: f64) {
    let r = s.len();
    if r == 0 {
        return;
    }
    let w = &w[..r];
    let mut pairs = p.chunks_exact_mut(2 * r);
    for pair in &mut pairs {
        let (c0, c1) = pair.split_at_mut(r);
        let (mut d0, mut d1) = (0.0, 0.0);
        for ((x0, x1), si) in c0.iter().zip(c1.iter()).zip(s) {
            d0 += si * x0;
            d1 += si * x1;
        }
        let (a0, a1) = (c * d0, c * d1);
        for ((x0, x1), wi) in c0.iter_mut().zip(c1.iter_mut()).zip(w) {
            *x0 -= a0 * wi;
            *x1 -= a1 * wi;
        }
    }
    for col in pairs.into_remainder().chunks_exact_mut(r) {
        let d = c * dot(s, col);
        axpy(-d, w, col);
    }
}

#[inline]
pub(crate) fn axpy(a: f64, x: &[f64], y: &mut [f64]) {
    for (yi, xi) in y.iter_mut().zip(x) {
        *yi += a * xi;
    }
}

/// Dot product with four partial sums (the short vectors of the chart gain most from it).
#[inline]
pub(crate) fn dot(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len());
    let (a, b) = (&a[..n], &b[..n]);
    let (ca, cb) = (a.chunks_exact(4), b.chunks_exact(4));
    let (ra, rb) = (ca.remainder(), cb.remainder());
    let mut s = [0.0f64; 4];
    for (x, y) in ca.zip(cb) {
        s[0] += x[0] * y[0];
        s[1] += x[1] * y[1];
        s[2] += x[2] * y[2];
        s[3] += x[3] * y[3];
    }
    let mut t = (s[0] + s[1]) + (s[2] + s[3]);
    for (x, y) in ra.iter().zip(rb) {
        t += x * y;
    }
    t
}
