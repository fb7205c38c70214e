//! The centre's block QR of `Df^T` and the orthogonal factors (steps 1 to 3 of
//! [`TangentChart::centre`]; the layout is in the type's documentation).

use super::TangentChart;
use crate::kernels::with_rows;
use mbd_solve::linalg::{form_q_padded, qr_padded};

/// Steps 1 and 2 of [`TangentChart::centre`] for `n` coordinates (`with_len!` passes the
/// planar mechanisms' `n` as a literal, so the copies and loops over `n` are unrolled).
///
/// 1. `[Phi_q^T | X^T]` (`n x 2m`), `X = (Phi_q v)_q`: the QR of its first `m` columns,
///    `Phi_q^T = Qa [Ra; 0]` (`Qa = [Qa1 Na]`), leaves `Qa^T X^T` in the last `m` columns: its
///    first `m` rows are the block `C` of `R`, the other `n - m` rows (`D = Na^T X^T`) stacked
///    on `Ra` form `B = [D; Ra]` (`n x m`).
/// 2. `B = Qb [Rb; 0]`.
#[inline(always)]
pub(super) fn factor_blocks(ch: &mut TangentChart, n: usize) {
    with_rows!(ch.m, factor_blocks_mn(ch, n));
}

/// [`factor_blocks`] for `m` constraints (a literal for the common counts through
/// `with_rows!`).
#[inline(always)]
fn factor_blocks_mn(ch: &mut TangentChart, n: usize, m: usize) {
    let (nn, mm, nm) = (2 * n, 2 * m, n - m);
    let (pq, xs) = (ch.phi_q.as_slice(), ch.dphi.as_slice()); // (r, c) at c m + r
                                                              // the chart's velocity coordinates are tau v: Df's block X enters weighted, tau X
    let vs = ch.vs;
    for k in 0..m {
        let (ca, cx) = ch.aq[k * n..].split_at_mut(m * n);
        for c in 0..n {
            ca[c] = pq[c * m + k];
            cx[c] = vs * xs[c * m + k];
        }
    }
    qr_padded(&mut ch.aq, m, mm, &mut ch.va, &mut ch.tau, n);
    for j in 0..m {
        let (ra, g) = (
            &ch.aq[j * n..(j + 1) * n],
            &ch.aq[(m + j) * n..(m + j + 1) * n],
        );
        let bj = &mut ch.bq[j * n..(j + 1) * n];
        // column j of R's leading block Ra (zero below its diagonal), column m + j of C
        let (left, right) = ch.a.split_at_mut((m + j) * nn);
        let (ar, ac) = (&mut left[j * nn..], right);
        ac[..m].copy_from_slice(&g[..m]);
        ar[..m].copy_from_slice(&ra[..m]);
        bj[nm..].copy_from_slice(&ra[..m]);
        bj[..nm].copy_from_slice(&g[m..]);
    }
    qr_padded(&mut ch.bq, m, m, &mut ch.vb, &mut ch.tau_b, n);
    for j in 0..m {
        let (col, b) = (&mut ch.a[(m + j) * nn + m..], &ch.bq[j * n..]);
        col[..=j].copy_from_slice(&b[..=j]);
    }
}

/// Step 3 of [`TangentChart::centre`] for `n` coordinates (literal through `with_len!`): the
/// orthogonal factors `Qa` and `Qb` (`n x n`) explicit from their reflectors.
#[inline(always)]
pub(super) fn form_factors(ch: &mut TangentChart, n: usize) {
    let m = ch.m;
    form_q_padded(&ch.va, &ch.tau[..m], &mut ch.qa, n);
    form_q_padded(&ch.vb, &ch.tau_b[..m], &mut ch.qb, n);
}

/// [`TangentChart::form_q`] for `n` coordinates (literal through `with_len!`): from `Qa` and
/// `Qb` (`n x n`, formed by the centre), `Q = [[Qa1, W Qb, 0], [0, ., Na]]` with `W y = (Na y[..n-m], Qa1 y[n-m..])`: columns
/// `0..m` are `(Qa1, 0)`, `m..m+n` are `W Qb` (the last `n - m` of them tangent), `m+n..2n`
/// are `(0, Na)`. The products `W Qb_j` accumulate column by column from zero, as
/// [`gemv_cols`](crate::kernels::gemv_cols) does.
#[inline(always)]
pub(super) fn form_q_blocks(ch: &mut TangentChart, n: usize) {
    with_rows!(ch.m, form_q_blocks_mn(ch, n));
}

/// [`form_q_blocks`] for `m` constraints (a literal for the common counts through
/// `with_rows!`).
#[inline(always)]
fn form_q_blocks_mn(ch: &mut TangentChart, n: usize, m: usize) {
    let (nn, nm) = (2 * n, n - m);
    let (qa, qb) = (&ch.qa[..n * n], &ch.qb[..n * n]);
    for k in 0..m {
        let col = &mut ch.q[k * nn..(k + 1) * nn];
        col[..n].copy_from_slice(&qa[k * n..(k + 1) * n]);
        col[n..].fill(0.0);
    }
    for j in 0..n {
        let y = &qb[j * n..(j + 1) * n];
        let col = &mut ch.q[(m + j) * nn..(m + j + 1) * nn];
        let (cq, cv) = col.split_at_mut(n);
        cq.fill(0.0);
        cv.fill(0.0);
        for (k, &yk) in y[..nm].iter().enumerate() {
            let c = &qa[(m + k) * n..(m + k + 1) * n];
            for i in 0..n {
                cq[i] += yk * c[i];
            }
        }
        for (k, &yk) in y[nm..].iter().enumerate() {
            let c = &qa[k * n..(k + 1) * n];
            for i in 0..n {
                cv[i] += yk * c[i];
            }
        }
    }
    for l in 0..nm {
        let col = &mut ch.q[(m + n + l) * nn..(m + n + l + 1) * nn];
        col[..n].fill(0.0);
        col[n..].copy_from_slice(&qa[(m + l) * n..(m + l + 1) * n]);
    }
}
