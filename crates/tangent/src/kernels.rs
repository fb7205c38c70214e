//! Small dense kernels of the tangent chart: column-blocked matrix-vector products with the
//! lengths of small planar charts fixed at compile time, rank-one updates, a four-sum `dot` and
//! branch-free max-norms (allocation-free, on column-major slices). The Householder QR and the
//! triangular kernels are `mbd-linalg`'s (`mbd_solve::linalg::qr_padded`, ...), and so is
//! `axpy`.

use mbd_solve::linalg::axpy;

/// Calls `$f::<r>(args)` for the column lengths `r` of the planar mechanisms' small charts
/// (`n` and `2n` for up to four bodies, `m` and `2m` for their constraints), else evaluates
/// `$other`: with the length known the compiler unrolls the column loops and keeps the
/// accumulators in registers, where loops of run-time length spent most of their
/// instructions on loop control and bounds at these sizes.
macro_rules! by_length {
    ($r:expr, $f:ident($($arg:expr),*), $other:expr) => {
        match $r {
            2 => $f::<2>($($arg),*),
            3 => $f::<3>($($arg),*),
            4 => $f::<4>($($arg),*),
            6 => $f::<6>($($arg),*),
            8 => $f::<8>($($arg),*),
            9 => $f::<9>($($arg),*),
            12 => $f::<12>($($arg),*),
            16 => $f::<16>($($arg),*),
            18 => $f::<18>($($arg),*),
            24 => $f::<24>($($arg),*),
            _ => $other,
        }
    };
}

/// `y += sum_k a_k c_k` for the column-major matrix `cols` whose columns `c_k` have the length
/// of `y` (`a.len()` of them).
#[inline]
pub(crate) fn gemv_cols(cols: &[f64], a: &[f64], y: &mut [f64]) {
    let r = y.len();
    if r == 0 {
        return;
    }
    by_length!(r, gemv_cols_fixed(cols, a, y), gemv_cols_any(cols, a, y))
}

/// Calls `$f::<R, C>(args)` for the column counts `C` of the small charts (`2m` and
/// `2(n - m)` of the planar mechanisms: 2, 4, 6, 8, 12, 16), else evaluates `$other`.
macro_rules! by_count {
    ($c:expr, $r:ident, $f:ident($($arg:expr),*), $other:expr) => {
        match $c {
            2 => $f::<$r, 2>($($arg),*),
            4 => $f::<$r, 4>($($arg),*),
            6 => $f::<$r, 6>($($arg),*),
            8 => $f::<$r, 8>($($arg),*),
            12 => $f::<$r, 12>($($arg),*),
            16 => $f::<$r, 16>($($arg),*),
            _ => $other,
        }
    };
}

/// [`gemv_cols`] for columns of the fixed length `R`: `y` stays in registers; the column
/// count fixed too where it is a common one ([`gemv_cols_rc`]).
#[inline]
fn gemv_cols_fixed<const R: usize>(cols: &[f64], a: &[f64], y: &mut [f64]) {
    by_count!(
        a.len(),
        R,
        gemv_cols_rc(cols, a, y),
        gemv_cols_r::<R>(cols, a, y)
    )
}

/// [`gemv_cols`] for `C` columns of the fixed length `R` (the loops unroll), in the
/// order of [`gemv_cols_r`] (the same sums).
#[inline]
fn gemv_cols_rc<const R: usize, const C: usize>(cols: &[f64], a: &[f64], y: &mut [f64]) {
    let y: &mut [f64; R] = (&mut y[..R]).try_into().unwrap();
    let cols: &[f64] = &cols[..R * C];
    let a: &[f64; C] = (&a[..C]).try_into().unwrap();
    let mut acc = *y;
    for k in 0..C {
        let ak = a[k];
        for i in 0..R {
            acc[i] += ak * cols[k * R + i];
        }
    }
    *y = acc;
}

/// [`gemv_cols`] for columns of the fixed length `R` and any count.
#[inline]
fn gemv_cols_r<const R: usize>(cols: &[f64], a: &[f64], y: &mut [f64]) {
    let y: &mut [f64; R] = (&mut y[..R]).try_into().unwrap();
    let mut acc = *y;
    for (c, &ak) in cols.chunks_exact(R).zip(a) {
        let c: &[f64; R] = c.try_into().unwrap();
        for i in 0..R {
            acc[i] += ak * c[i];
        }
    }
    *y = acc;
}

/// [`gemv_cols`] for any length: four columns per pass over `y`.
fn gemv_cols_any(cols: &[f64], a: &[f64], y: &mut [f64]) {
    let r = y.len();
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
/// column-major matrix `cols`.
#[inline]
pub(crate) fn gemv_t_cols(cols: &[f64], y: &[f64], out: &mut [f64]) {
    let r = y.len();
    if r == 0 {
        out.fill(0.0);
        return;
    }
    by_length!(
        r,
        gemv_t_cols_fixed(cols, y, out),
        gemv_t_cols_any(cols, y, out)
    )
}

/// [`gemv_t_cols`] for columns of the fixed length `R`: `y` in registers, two partial sums
/// per column (pairs of lanes).
#[inline]
fn gemv_t_cols_fixed<const R: usize>(cols: &[f64], y: &[f64], out: &mut [f64]) {
    by_count!(
        out.len(),
        R,
        gemv_t_cols_rc(cols, y, out),
        gemv_t_cols_r::<R>(cols, y, out)
    )
}

/// [`gemv_t_cols`] for `C` columns of the fixed length `R` (the same sums as
/// [`gemv_t_cols_r`]).
#[inline]
fn gemv_t_cols_rc<const R: usize, const C: usize>(cols: &[f64], y: &[f64], out: &mut [f64]) {
    let y: &[f64; R] = (&y[..R]).try_into().unwrap();
    let cols: &[f64] = &cols[..R * C];
    let out: &mut [f64; C] = (&mut out[..C]).try_into().unwrap();
    for k in 0..C {
        let c: &[f64; R] = (&cols[k * R..(k + 1) * R]).try_into().unwrap();
        out[k] = dot_fixed(c, y);
    }
}

/// [`gemv_t_cols`] for columns of the fixed length `R` and any count.
#[inline]
fn gemv_t_cols_r<const R: usize>(cols: &[f64], y: &[f64], out: &mut [f64]) {
    let y: &[f64; R] = (&y[..R]).try_into().unwrap();
    for (c, o) in cols.chunks_exact(R).zip(out.iter_mut()) {
        let c: &[f64; R] = c.try_into().unwrap();
        *o = dot_fixed(c, y);
    }
}

/// `a . b` for arrays of the fixed length `R`, in two interleaved partial sums.
#[inline(always)]
pub(crate) fn dot_fixed<const R: usize>(a: &[f64; R], b: &[f64; R]) -> f64 {
    let mut s = [0.0f64; 2];
    for i in 0..R {
        s[i % 2] += a[i] * b[i];
    }
    s[0] + s[1]
}

/// [`gemv_t_cols`] for any length: four columns per pass over `y`.
fn gemv_t_cols_any(cols: &[f64], y: &[f64], out: &mut [f64]) {
    let r = y.len();
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

/// `||x[..len]||_inf`, or NaN if an entry is not finite: one pass without branches (`e * 0`
/// is 0 for a finite `e` and NaN otherwise); `len` a literal through `with_codim!`.
#[inline(always)]
pub(crate) fn max_abs_finite(x: &[f64], len: usize) -> f64 {
    let (mut r, mut bad) = (0.0f64, 0.0f64);
    for &e in &x[..len] {
        let a = e.abs();
        r = if a > r { a } else { r };
        bad += e * 0.0;
    }
    if bad == 0.0 {
        r
    } else {
        f64::NAN
    }
}

/// Whether every entry of `x` is finite (one pass without branches, as [`max_abs_finite`]).
#[inline]
pub(crate) fn all_finite(x: &[f64]) -> bool {
    x.iter().fold(0.0f64, |bad, &e| bad + e * 0.0) == 0.0
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

/// Calls `$f(args, len)` with `len` a literal for the coordinate counts of planar mechanisms
/// of one to four bodies (3, 6, 9, 12), else with `$n` itself: `$f` is `#[inline(always)]`,
/// so each arm is compiled with the length known (loops unrolled, no bounds checks).
macro_rules! with_len {
    ($n:expr, $f:ident($($arg:expr),*)) => {
        match $n {
            3 => $f($($arg,)* 3),
            6 => $f($($arg,)* 6),
            9 => $f($($arg,)* 9),
            12 => $f($($arg,)* 12),
            n => $f($($arg,)* n),
        }
    };
}
pub(crate) use with_len;

/// Calls `$f(args, m)` with `m` a literal for the constraint counts of the planar mechanisms'
/// small charts (4: two revolute joints; 6; 8: a four-bar or slider-crank), else with `$m`
/// itself; for the loops over the constraints of the chart's centre (see [`with_len`]).
macro_rules! with_rows {
    ($m:expr, $f:ident($($arg:expr),*)) => {
        match $m {
            4 => $f($($arg,)* 4),
            6 => $f($($arg,)* 6),
            8 => $f($($arg,)* 8),
            m => $f($($arg,)* m),
        }
    };
}
pub(crate) use with_rows;

/// Calls `$f(args, len)` with `len` a literal for the constraint counts `2m` of small planar
/// mechanisms (2 to 16), else with `$mm` itself (see [`with_len`]).
macro_rules! with_codim {
    ($mm:expr, $f:ident($($arg:expr),*)) => {
        match $mm {
            2 => $f($($arg,)* 2),
            4 => $f($($arg,)* 4),
            6 => $f($($arg,)* 6),
            8 => $f($($arg,)* 8),
            10 => $f($($arg,)* 10),
            12 => $f($($arg,)* 12),
            16 => $f($($arg,)* 16),
            mm => $f($($arg,)* mm),
        }
    };
}
pub(crate) use with_codim;
