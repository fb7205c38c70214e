//! Reduced coordinates of pinned rod chains (joint angles and their conjugate momenta): a chart
//! of the constrained phase space, in which a one-step map's Jacobian is taken by central
//! differences and its symplecticity checked (`J^T Omega J = Omega`).
use mbd_model::System;
use mbd_solve::{Integrator, State};
use mbd_symplectic::{Galerkin, SymplecticOptions};
use nalgebra::{DMatrix, DVector};

/// A chain of uniform rods (m = 1, L = 1) in joint angles: q(theta), T = dq/dtheta.
pub fn chain_q(theta: &[f64]) -> (DVector<f64>, DMatrix<f64>) {
    let k = theta.len();
    let mut q = DVector::zeros(3 * k);
    let mut t = DMatrix::zeros(3 * k, k);
    let mut tip = [0.0, 0.0];
    for i in 0..k {
        let (s, c) = theta[i].sin_cos();
        q[3 * i] = tip[0] + 0.5 * c;
        q[3 * i + 1] = tip[1] + 0.5 * s;
        q[3 * i + 2] = theta[i];
        for j in 0..=i {
            let (sj, cj) = theta[j].sin_cos();
            let f = if j == i { 0.5 } else { 1.0 };
            t[(3 * i, j)] = -f * sj;
            t[(3 * i + 1, j)] = f * cj;
        }
        t[(3 * i + 2, i)] = 1.0;
        tip = [tip[0] + c, tip[1] + s];
    }
    (q, t)
}

/// One step of `step` as a map of reduced coordinates `(theta, p_theta)`: the consistent state
/// with these angles and momenta (`v = T M_r^-1 p`, on the constraint manifold by construction),
/// the step, and the result read back as angles and `p_theta = T^T M v`.
pub fn reduced_map(sys: &System, z: &[f64], step: &mut dyn FnMut(&System, &mut State)) -> Vec<f64> {
    let k = z.len() / 2;
    let (q, t) = chain_q(&z[..k]);
    let m = DMatrix::from_diagonal(sys.mass_diag());
    let mr = t.transpose() * &m * &t;
    let p = DVector::from_column_slice(&z[k..]);
    let thd = mr.lu().solve(&p).unwrap();
    let v = &t * thd;
    let mut st = State::new(sys, 0.0, q, v).unwrap();
    step(sys, &mut st);
    let th: Vec<f64> = (0..k).map(|i| st.q[3 * i + 2]).collect();
    let (_, t1) = chain_q(&th);
    let p1 = t1.transpose() * &m * &st.v;
    th.into_iter().chain(p1.iter().copied()).collect()
}

/// One step of the (s,s) scheme `opts` as a map of reduced coordinates.
pub fn reduced_step(sys: &System, opts: SymplecticOptions, h: f64, z: &[f64]) -> Vec<f64> {
    let mut g = Galerkin::new(sys, opts).unwrap();
    reduced_map(sys, z, &mut |sys, st| {
        g.step(sys, st, h).unwrap();
    })
}

/// Jacobian of `f` at `z` by central differences of step `d`.
pub fn jacobian_of(z: &[f64], d: f64, f: &mut dyn FnMut(&[f64]) -> Vec<f64>) -> DMatrix<f64> {
    let n = z.len();
    let mut j = DMatrix::zeros(n, n);
    for c in 0..n {
        let mut zp = z.to_vec();
        zp[c] += d;
        let fp = f(&zp);
        zp[c] -= 2.0 * d;
        let fm = f(&zp);
        for r in 0..n {
            j[(r, c)] = (fp[r] - fm[r]) / (2.0 * d);
        }
    }
    j
}

/// Jacobian of one step of the (s,s) scheme in reduced coordinates.
pub fn jacobian(sys: &System, opts: SymplecticOptions, h: f64, z: &[f64], d: f64) -> DMatrix<f64> {
    jacobian_of(z, d, &mut |z| reduced_step(sys, opts, h, z))
}

/// The canonical symplectic form of `k` angles and their momenta.
pub fn omega(k: usize) -> DMatrix<f64> {
    let mut o = DMatrix::zeros(2 * k, 2 * k);
    for i in 0..k {
        o[(i, k + i)] = 1.0;
        o[(k + i, i)] = -1.0;
    }
    o
}

/// `max |J^T Omega J - Omega|`: zero for a symplectic map.
pub fn symplecticity_defect(j: &DMatrix<f64>) -> f64 {
    let o = omega(j.nrows() / 2);
    (j.transpose() * &o * j - &o).abs().max()
}
