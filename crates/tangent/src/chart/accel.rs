//! The index-1 accelerations at the chart's centre from the chart's own factorisation.
//!
//! The centre factors `Phi_q^T = Qa1 Ra` (`Qa = [Qa1 Na]` orthogonal, `Ra` upper triangular,
//! step 1 of [`TangentChart::centre`]). The index-1 system `M a = f + Phi_q^T lambda`,
//! `Phi_q a = gamma` then splits along `Qa` (the null-space method):
//!
//! * the constrained part: `a = Qa1 p + Na y` with `Phi_q a = Ra^T p = gamma`, so
//!   `p = Ra^-T gamma` (forward substitution with `R`'s leading block);
//! * the free part: `Na^T Phi_q^T = 0`, so `Na^T M a = Na^T f`, that is
//!   `(Na^T M Na) y = Na^T (f - M Qa1 p)`.
//!
//! `K = Na^T M Na` is positive definite exactly when `M` is definite on the tangent space of
//! the constraints (a spatial body with a zero `E_i` included), and it is `(n - m) x (n - m)`:
//! this costs a few small products and one small Cholesky factorisation, where the general
//! solver forms and factors `Phi_q M^-1 Phi_q^T` again. `gamma = -(Phi_q v)_q v` needs the
//! constraints to be scleronomic; the caller checks it.

use super::TangentChart;
use crate::kernels::{with_len, with_rows};
use mbd_model::System;
use mbd_solve::linalg::{solve_rt, DenseCholesky};

/// Work space of [`TangentChart::centre_accelerations`] (allocated once with the chart).
#[derive(Debug)]
pub(super) struct CentreAccel {
    /// Applied forces `f` and the residual `f - M Qa1 p` (`n` each).
    force: Vec<f64>,
    /// `gamma` and `p = Ra^-T gamma` (`m` each).
    gamma: Vec<f64>,
    p: Vec<f64>,
    /// `Na^T (f - M Qa1 p)`, then `y` (`n - m`).
    rhs: Vec<f64>,
    /// `K = Na^T M Na`.
    k: DenseCholesky,
}

impl CentreAccel {
    pub(super) fn new(n: usize, m: usize) -> Self {
        let d = n.saturating_sub(m);
        CentreAccel {
            force: vec![0.0; n],
            gamma: vec![0.0; m],
            p: vec![0.0; m],
            rhs: vec![0.0; d],
            k: DenseCholesky::new(d),
        }
    }
}

impl Clone for CentreAccel {
    /// A fresh work space of the same sizes (its contents are scratch).
    fn clone(&self) -> Self {
        CentreAccel::new(self.force.len(), self.gamma.len())
    }
}

impl TangentChart {
    /// The index-1 accelerations `a` (`n`) at the centre `(q, v)` at its time, for scleronomic
    /// constraints (the caller checks), by the null-space method on the centre's QR (see the
    /// module doc). `false` (and `a` unspecified) where it does not apply: no centre, no
    /// constraints, or `Na^T M Na` not numerically positive definite; the caller then solves
    /// the general way.
    pub(crate) fn centre_accelerations(&mut self, sys: &System, a: &mut [f64]) -> bool {
        let (n, m) = (self.n, self.m);
        if !self.centred || m == 0 || m >= n || a.len() != n {
            return false;
        }
        let d = n - m;
        let (q, v) = self.xc_user.split_at(n);
        let ws = &mut self.centre_acc;
        sys.forces_into(q, v, self.tc, &mut ws.force);
        let mass = sys.mass_diag().as_slice();
        let (qa1, na) = self.qa[..n * n].split_at(m * n);
        let (dp, r, rdinv) = (self.dphi.as_slice(), &self.a[..], &self.rdinv[..]);
        let (gamma, p, force) = (&mut ws.gamma[..], &mut ws.p[..], &mut ws.force[..]);
        with_len!(
            n,
            constrained_n(dp, v, r, rdinv, qa1, mass, gamma, p, a, force, m)
        );
        with_len!(
            n,
            free_n(na, mass, force, ws.k.values_mut(), &mut ws.rhs, d)
        );
        if ws.k.factor_in_place().is_err() {
            return false;
        }
        ws.k.solve_in_place(&mut ws.rhs);
        with_len!(n, add_free_n(na, &ws.rhs, a, d));
        a.iter().all(|x| x.is_finite())
    }
}

/// The constrained part for `n` coordinates (a literal through `with_len!`): `gamma =
/// -(Phi_q v)_q v` from the `m x n` column-major `dp`, `p = Ra^-T gamma`, `a = Qa1 p` and
/// `force <- force - M a`.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn constrained_n(
    dp: &[f64],
    v: &[f64],
    r: &[f64],
    rdinv: &[f64],
    qa1: &[f64],
    mass: &[f64],
    gamma: &mut [f64],
    p: &mut [f64],
    a: &mut [f64],
    force: &mut [f64],
    m: usize,
    n: usize,
) {
    with_rows!(
        m,
        constrained_nm(dp, v, r, rdinv, qa1, mass, gamma, p, a, force, n)
    );
}

/// [`constrained_n`] with `m` a literal too (through `with_rows!`).
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn constrained_nm(
    dp: &[f64],
    v: &[f64],
    r: &[f64],
    rdinv: &[f64],
    qa1: &[f64],
    mass: &[f64],
    gamma: &mut [f64],
    p: &mut [f64],
    a: &mut [f64],
    force: &mut [f64],
    n: usize,
    m: usize,
) {
    let (dp, v, gamma) = (&dp[..m * n], &v[..n], &mut gamma[..m]);
    gamma.fill(0.0);
    for c in 0..n {
        let vc = v[c];
        for k in 0..m {
            gamma[k] -= dp[c * m + k] * vc;
        }
    }
    // R's leading m x m block is Ra (columns of stride 2n), its diagonal reciprocals first in
    // rdinv
    solve_rt(r, 2 * n, rdinv, gamma, p, m);
    let (qa1, a, mass, force) = (&qa1[..m * n], &mut a[..n], &mass[..n], &mut force[..n]);
    a.fill(0.0);
    for k in 0..m {
        let pk = p[k];
        for i in 0..n {
            a[i] += pk * qa1[k * n + i];
        }
    }
    for i in 0..n {
        force[i] -= mass[i] * a[i];
    }
}

/// The free part's matrix `K = Na^T M Na` (lower triangle into `kv`, `d x d` column-major)
/// and right-hand side `Na^T force` (into `rhs`), for `n` coordinates (a literal through
/// `with_len!`) and `d = n - m`.
#[inline(always)]
fn free_n(
    na: &[f64],
    mass: &[f64],
    force: &[f64],
    kv: &mut [f64],
    rhs: &mut [f64],
    d: usize,
    n: usize,
) {
    let (mass, force) = (&mass[..n], &force[..n]);
    for j in 0..d {
        let cj = &na[j * n..(j + 1) * n];
        let mut acc = 0.0;
        for l in 0..n {
            acc += cj[l] * force[l];
        }
        rhs[j] = acc;
        for i in j..d {
            let ci = &na[i * n..(i + 1) * n];
            let mut acc = 0.0;
            for l in 0..n {
                acc += mass[l] * ci[l] * cj[l];
            }
            kv[i + j * d] = acc;
        }
    }
}

/// `a += Na y` for `n` coordinates (a literal through `with_len!`), `y` of length `d`.
#[inline(always)]
fn add_free_n(na: &[f64], y: &[f64], a: &mut [f64], d: usize, n: usize) {
    let a = &mut a[..n];
    for j in 0..d {
        let (yj, col) = (y[j], &na[j * n..(j + 1) * n]);
        for i in 0..n {
            a[i] += yj * col[i];
        }
    }
}
