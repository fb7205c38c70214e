//! Products with the chart's orthogonal `Q = [Q1 U]` in its factored form.
//!
//! With `Qa = [Qa1 Na]` (QR of `Phi_q^T`) and `Qb` (QR of `[Na^T X^T; Ra]`), both `n x n`, the
//! chart's columns are `(Qa1, 0)` (`m`), `W Qb` (`n`; `W y = (Na y[..n-m], Qa1 y[n-m..])`) and
//! `(0, Na)` (`n - m`), so `Q = diag(Qa, Qa) Qt` with `Qt` made of unit columns and `Qb`:
//!
//! ```text
//! Q (z1, z2, z3) = (Qa (z1, w[..n-m]), Qa (w[n-m..], z3)),     w = Qb z2,
//! Q^T (yq, yv)   = (a[..m], d, b[m..]),   a = Qa^T yq, b = Qa^T yv, d = Qb^T (a[m..], b[..m]).
//! ```
//!
//! Three `n x n` products instead of one `2n x 2n` (three quarters of the multiplications), and
//! the centre need not form the `2n x 2n` matrix: the hot operations (chart points, chord
//! corrections, the split of `F`) use these; the explicit `Q` is formed on demand
//! ([`TangentChart::form_q`]) for the interpolated and Broyden matrices and the exact Newton
//! fallback.

/// `$fixed::<N, M>(args)` for the chart sizes compiled with fixed loop bounds (the planar
/// chains of 1 to 4 bodies the benchmarks and most models have), `$any` for the others.
macro_rules! by_chart_size {
    ($n:expr, $m:expr, $fixed:ident($($arg:expr),*), $any:expr) => {
        match ($n, $m) {
            (3, 2) => $fixed::<3, 2>($($arg),*),
            (6, 4) => $fixed::<6, 4>($($arg),*),
            (6, 5) => $fixed::<6, 5>($($arg),*),
            (9, 6) => $fixed::<9, 6>($($arg),*),
            (9, 8) => $fixed::<9, 8>($($arg),*),
            (12, 8) => $fixed::<12, 8>($($arg),*),
            _ => $any,
        }
    };
}

use super::TangentChart;
use crate::kernels::{dot_fixed, gemv_cols, with_len, with_rows};

impl TangentChart {
    /// `x += Q (zeta, xi)` for normal coordinates `zeta` (`2m`) and tangent coordinates `xi`
    /// (`2 (n - m)`, or empty for zero).
    pub(super) fn add_q(&mut self, zeta: &[f64], xi: &[f64], x: &mut [f64]) {
        let (n, m) = (self.n, self.m);
        let (qa, qb, buf) = (&self.qa, &self.qb, &mut self.nbuf);
        with_len!(n, add_q_n(qa, qb, zeta, xi, x, buf, m));
    }

    /// `[Q1 U]^T y` for a vector `y` of length `2n`, in two parts: its normal components
    /// `normal = Q1^T y` (`2m`) and its tangent components `tangent = U^T y` (`2(n - m)`).
    ///
    /// `y` is a vector of the model's `(q, v)` space (a velocity `F = (v, a)`); it is split in
    /// the chart's coordinates `(q, tau v)` ([`TangentChart::set_velocity_weight`]).
    pub fn split_coordinates(&mut self, y: &[f64], normal: &mut [f64], tangent: &mut [f64]) {
        let (n, m) = (self.n, self.m);
        let y = if self.vs == 1.0 {
            y
        } else {
            let (yq, yv) = y.split_at(n);
            let (bq, bv) = self.sbuf.split_at_mut(n);
            bq.copy_from_slice(yq);
            for (b, &v) in bv.iter_mut().zip(yv) {
                *b = self.vs * v;
            }
            &self.sbuf[..]
        };
        let (qa, qb, buf) = (&self.qa, &self.qb, &mut self.nbuf);
        with_len!(n, split_n(qa, qb, y, normal, tangent, buf, m));
    }

    /// `out = U e` for tangent coordinates `e` (`2 (n - m)`): a chart-coordinate vector in the
    /// ambient space, returned in the model's `(q, v)` (the velocity half divided by the
    /// chart's velocity weight).
    pub(crate) fn tangent_to_ambient(&mut self, e: &[f64], out: &mut [f64]) {
        out.fill(0.0);
        // (the zero normal part borrows a work vector, moved out for the call)
        let mut zeta = std::mem::take(&mut self.w);
        zeta.fill(0.0);
        self.add_q(&zeta, e, out);
        self.w = zeta;
        self.unweight(out);
    }

    /// `x += Q1 w` for the work vector `w` (`2m`): a chord correction.
    pub(super) fn add_q1_w(&mut self, x: &mut [f64]) {
        let (n, m) = (self.n, self.m);
        let (qa, qb, buf, w) = (&self.qa, &self.qb, &mut self.nbuf, &self.w);
        by_chart_size!(
            n,
            m,
            add_q1_fixed(qa, qb, w, x),
            add_q_any(qa, qb, w, &[], x, buf, n, m)
        )
    }
}

/// [`TangentChart::add_q`] for `n` coordinates (a literal through `with_len!`).
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn add_q_n(
    qa: &[f64],
    qb: &[f64],
    zeta: &[f64],
    xi: &[f64],
    x: &mut [f64],
    buf: &mut [f64],
    m: usize,
    n: usize,
) {
    with_rows!(m, add_q_mn(qa, qb, zeta, xi, x, buf, n));
}

/// [`TangentChart::add_q`] for `n` coordinates and `m` constraints: the planar mechanisms'
/// common sizes with both fixed at compile time (the products in registers), others through
/// [`add_q_any`].
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn add_q_mn(
    qa: &[f64],
    qb: &[f64],
    zeta: &[f64],
    xi: &[f64],
    x: &mut [f64],
    buf: &mut [f64],
    n: usize,
    m: usize,
) {
    by_chart_size!(
        n,
        m,
        add_q_fixed(qa, qb, zeta, xi, x),
        add_q_any(qa, qb, zeta, xi, x, buf, n, m)
    )
}

/// [`TangentChart::add_q`] with `N` coordinates and `M` constraints fixed: every product
/// accumulates column by column in a local array.
#[inline(always)]
fn add_q_fixed<const N: usize, const M: usize>(
    qa: &[f64],
    qb: &[f64],
    zeta: &[f64],
    xi: &[f64],
    x: &mut [f64],
) {
    let nm = N - M;
    let (qa, qb, zeta) = (&qa[..N * N], &qb[..N * N], &zeta[..2 * M]);
    // w = Qb z2, z2 = (zeta[m..], xi[..n-m])
    let mut w = [0.0f64; N];
    for j in 0..M {
        let a = zeta[M + j];
        let c: &[f64; N] = qb[j * N..(j + 1) * N].try_into().unwrap_or(&[0.0; N]);
        for i in 0..N {
            w[i] += a * c[i];
        }
    }
    let xi = if xi.is_empty() {
        None
    } else {
        Some(&xi[..2 * nm])
    };
    if let Some(xi) = xi {
        for j in 0..nm {
            let a = xi[j];
            let c: &[f64; N] = qb[(M + j) * N..(M + j + 1) * N]
                .try_into()
                .unwrap_or(&[0.0; N]);
            for i in 0..N {
                w[i] += a * c[i];
            }
        }
    }
    // positions: Qa (z1, w[..n-m]); velocities: Qa (w[n-m..], z3)
    let (xq, xv) = x.split_at_mut(N);
    let mut top: [f64; N] = xq[..N].try_into().unwrap_or([0.0; N]);
    let mut bot: [f64; N] = xv[..N].try_into().unwrap_or([0.0; N]);
    for k in 0..N {
        let c: &[f64; N] = qa[k * N..(k + 1) * N].try_into().unwrap_or(&[0.0; N]);
        let (a, b) = if k < M {
            (zeta[k], w[nm + k])
        } else {
            (w[k - M], xi.map_or(0.0, |xi| xi[nm + k - M]))
        };
        for i in 0..N {
            top[i] += a * c[i];
        }
        if k < M || xi.is_some() {
            for i in 0..N {
                bot[i] += b * c[i];
            }
        }
    }
    xq[..N].copy_from_slice(&top);
    xv[..N].copy_from_slice(&bot);
}

/// `x += Q1 u` (`u` of length `2M`) with `N` coordinates and `M` constraints fixed:
/// `w = Qb[:, ..m] u[m..]`, positions `Qa (u[..m], w[..n-m])`, velocities
/// `Qa[:, ..m] w[n-m..]`.
#[inline(always)]
fn add_q1_fixed<const N: usize, const M: usize>(qa: &[f64], qb: &[f64], u: &[f64], x: &mut [f64]) {
    let nm = N - M;
    let (qa, qb, u) = (&qa[..N * N], &qb[..M * N], &u[..2 * M]);
    let mut w = [0.0f64; N];
    for j in 0..M {
        let a = u[M + j];
        let c: &[f64; N] = qb[j * N..(j + 1) * N].try_into().unwrap_or(&[0.0; N]);
        for i in 0..N {
            w[i] += a * c[i];
        }
    }
    let (xq, xv) = x.split_at_mut(N);
    let mut top: [f64; N] = xq[..N].try_into().unwrap_or([0.0; N]);
    let mut bot: [f64; N] = xv[..N].try_into().unwrap_or([0.0; N]);
    for k in 0..M {
        let c: &[f64; N] = qa[k * N..(k + 1) * N].try_into().unwrap_or(&[0.0; N]);
        let (a, b) = (u[k], w[nm + k]);
        for i in 0..N {
            top[i] += a * c[i];
            bot[i] += b * c[i];
        }
    }
    for k in 0..nm {
        let c: &[f64; N] = qa[(M + k) * N..(M + k + 1) * N]
            .try_into()
            .unwrap_or(&[0.0; N]);
        let a = w[k];
        for i in 0..N {
            top[i] += a * c[i];
        }
    }
    xq[..N].copy_from_slice(&top);
    xv[..N].copy_from_slice(&bot);
}

/// [`TangentChart::add_q`] for any size: the same products through [`gemv_cols`].
#[allow(clippy::too_many_arguments)]
fn add_q_any(
    qa: &[f64],
    qb: &[f64],
    zeta: &[f64],
    xi: &[f64],
    x: &mut [f64],
    buf: &mut [f64],
    n: usize,
    m: usize,
) {
    let nm = n - m;
    let (qa, qb) = (&qa[..n * n], &qb[..n * n]);
    let (w, rest) = buf.split_at_mut(n);
    let (z, _) = rest.split_at_mut(n);
    let (w, z) = (&mut w[..n], &mut z[..n]);
    let (xq, xv) = x.split_at_mut(n);
    w.fill(0.0);
    if xi.is_empty() {
        gemv_cols(&qb[..m * n], &zeta[m..2 * m], w);
    } else {
        z[..m].copy_from_slice(&zeta[m..2 * m]);
        z[m..].copy_from_slice(&xi[..nm]);
        gemv_cols(qb, z, w);
    }
    z[..m].copy_from_slice(&zeta[..m]);
    z[m..].copy_from_slice(&w[..nm]);
    gemv_cols(qa, z, &mut xq[..n]);
    if xi.is_empty() {
        gemv_cols(&qa[..m * n], &w[nm..], &mut xv[..n]);
    } else {
        z[..m].copy_from_slice(&w[nm..]);
        z[m..].copy_from_slice(&xi[nm..2 * nm]);
        gemv_cols(qa, z, &mut xv[..n]);
    }
}

/// `c . y` in two partial sums (pairs of lanes), as the chart's other products.
#[inline(always)]
fn dot_col(c: &[f64], y: &[f64]) -> f64 {
    let mut s = [0.0f64; 2];
    for (i, (a, b)) in c.iter().zip(y).enumerate() {
        s[i % 2] += a * b;
    }
    s[0] + s[1]
}

/// [`TangentChart::split_coordinates`] for `n` coordinates (a literal through `with_len!`).
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn split_n(
    qa: &[f64],
    qb: &[f64],
    y: &[f64],
    normal: &mut [f64],
    tangent: &mut [f64],
    buf: &mut [f64],
    m: usize,
    n: usize,
) {
    with_rows!(m, split_mn(qa, qb, y, normal, tangent, buf, n));
}

/// [`TangentChart::split_coordinates`] for `n` coordinates and `m` constraints (both fixed
/// at compile time for the common sizes, see [`add_q_mn`]).
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn split_mn(
    qa: &[f64],
    qb: &[f64],
    y: &[f64],
    normal: &mut [f64],
    tangent: &mut [f64],
    buf: &mut [f64],
    n: usize,
    m: usize,
) {
    by_chart_size!(
        n,
        m,
        split_fixed(qa, qb, y, normal, tangent),
        split_any(qa, qb, y, normal, tangent, buf, n, m)
    )
}

/// [`TangentChart::split_coordinates`] with `N` coordinates and `M` constraints fixed.
#[inline(always)]
fn split_fixed<const N: usize, const M: usize>(
    qa: &[f64],
    qb: &[f64],
    y: &[f64],
    normal: &mut [f64],
    tangent: &mut [f64],
) {
    let nm = N - M;
    let (qa, qb) = (&qa[..N * N], &qb[..N * N]);
    let yq: &[f64; N] = y[..N].try_into().unwrap_or(&[0.0; N]);
    let yv: &[f64; N] = y[N..2 * N].try_into().unwrap_or(&[0.0; N]);
    let (normal, tangent) = (&mut normal[..2 * M], &mut tangent[..2 * nm]);
    // c = (a[m..], b[..m]) with a = Qa^T yq, b = Qa^T yv
    let mut c = [0.0f64; N];
    for k in 0..N {
        let col: &[f64; N] = qa[k * N..(k + 1) * N].try_into().unwrap_or(&[0.0; N]);
        let (a, b) = (dot_fixed(col, yq), dot_fixed(col, yv));
        if k < M {
            normal[k] = a;
            c[nm + k] = b;
        } else {
            c[k - M] = a;
            tangent[nm + k - M] = b;
        }
    }
    // d = Qb^T c: its first m entries are normal, the others tangent
    for j in 0..N {
        let col: &[f64; N] = qb[j * N..(j + 1) * N].try_into().unwrap_or(&[0.0; N]);
        let d = dot_fixed(col, &c);
        if j < M {
            normal[M + j] = d;
        } else {
            tangent[j - M] = d;
        }
    }
}

/// [`TangentChart::split_coordinates`] for any size.
#[allow(clippy::too_many_arguments)]
fn split_any(
    qa: &[f64],
    qb: &[f64],
    y: &[f64],
    normal: &mut [f64],
    tangent: &mut [f64],
    buf: &mut [f64],
    n: usize,
    m: usize,
) {
    let nm = n - m;
    let (qa, qb) = (&qa[..n * n], &qb[..n * n]);
    let (yq, yv) = (&y[..n], &y[n..2 * n]);
    let (normal, tangent) = (&mut normal[..2 * m], &mut tangent[..2 * nm]);
    // c = (a[m..], b[..m]) with a = Qa^T yq, b = Qa^T yv
    let c = &mut buf[..n];
    for k in 0..m {
        let col = &qa[k * n..(k + 1) * n];
        normal[k] = dot_col(col, yq);
        c[nm + k] = dot_col(col, yv);
    }
    for k in 0..nm {
        let col = &qa[(m + k) * n..(m + k + 1) * n];
        c[k] = dot_col(col, yq);
        tangent[nm + k] = dot_col(col, yv);
    }
    // d = Qb^T c: its first m entries are normal, the others tangent
    for j in 0..m {
        normal[m + j] = dot_col(&qb[j * n..(j + 1) * n], c);
    }
    for j in 0..nm {
        tangent[j] = dot_col(&qb[(m + j) * n..(m + j + 1) * n], c);
    }
}
