//! The velocity of a consistent state on a singular configuration: on a branch of the motion.
//!
//! Where `Phi_q` loses rank beyond the model's structural redundancy (a parallelogram four-bar
//! with its cranks in line with the ground), `Phi_q v + Phi_t = 0` leaves `v` free along the
//! extra null directions, and the velocity projection's choice (the nearest solution to the
//! guess) is in general on no branch of the motion: the accelerations then have no solution,
//! `Phi_q a = gamma(q, v, t)` being solvable only if every left null vector `y` of `Phi_q` has
//! `y^T gamma(q, v, t) = 0` (`docs/singular.md`, section 7). For holonomic constraints `gamma`
//! is quadratic in `v`, so on the affine set `v = v_0 + S N alpha` (`N` an orthonormal basis of
//! the null space of `Phi_q S`, `S` the square root of the rank test's unit-free weights) the
//! conditions are quadratics in `alpha`; their zero set is the union of the branches' velocity
//! spaces (for a mechanism without a degree of freedom: one velocity per branch). A structural
//! redundancy's left null vectors give conditions that hold identically, mixed by the left null
//! basis with the others: an SVD of the conditions' coefficient rows keeps their independent
//! combinations. One condition (one singular equation): the nearest zero to `alpha = 0` (the
//! projection's choice), from the monotone derivative of the dual function
//! (`Quadratics::nearest_root`); several: Gauss-Newton with minimum-norm steps from
//! `alpha = 0`, a zero near it.

use crate::error::SolveError;
use crate::linalg::max_abs;
use mbd_linalg::{min_norm_solve, null_space};
use mbd_model::{System, SPARSE_RANK_THRESHOLD};
use nalgebra::{DMatrix, DVector};

/// A singular value of `Phi_q S` below this fraction of the largest is a dependence (the
/// model's own dense redundancy test uses the same `1e-9`).
const NULL_TOL: f64 = 1e-9;

/// Singular values of the conditions' Jacobian below this fraction of the largest are left out
/// of the Gauss-Newton step (the structural redundancy's identically vanishing conditions).
const STEP_RANK_TOL: f64 = 1e-10;

/// Gauss-Newton iterations at most (the conditions are quadratic: a few suffice from a point
/// off the vertex).
const MAX_ITER: usize = 50;

/// The conditions count as met below this fraction of their scale (the size of their linear
/// part times the velocity scale, and of their value at the projection's choice).
const BRANCH_TOL: f64 = 1e-9;

/// Moves the consistent velocity `v` at a singular configuration `q` onto the nearest branch
/// of the motion (module docs). `keep` marks velocities held as given (inputs): they do not
/// move. Returns whether `v` moved; it does not on a regular configuration (or one with only the
/// structural redundancy), above [`SPARSE_RANK_THRESHOLD`] equations (the test is dense),
/// a velocity already on a branch, or conditions with no real solution near it (no branch
/// passes the configuration with these drivers: the solvers report that configuration).
pub(crate) fn onto_branch(
    sys: &System,
    q: &[f64],
    v: &mut [f64],
    t: f64,
    keep: &[bool],
) -> Result<bool, SolveError> {
    let (n, m) = (sys.n_coords(), sys.n_constraints());
    if m == 0 || m > SPARSE_RANK_THRESHOLD {
        return Ok(false);
    }
    // the cheap test first: a well-conditioned or structurally redundant configuration
    if sys.redundant_at(q, t)?.len() <= sys.n_redundant() {
        return Ok(false);
    }
    let s: Vec<f64> = sys
        .rank_weights()
        .iter()
        .zip(keep)
        .map(|(&w, &k)| if k { 0.0 } else { w.sqrt() })
        .collect();
    let mut a = DMatrix::zeros(m, n);
    sys.phi_q(q, t, &mut a);
    for (j, &sj) in s.iter().enumerate() {
        a.column_mut(j).scale_mut(sj);
    }
    let y = null_space(&a.transpose(), NULL_TOL);
    if y.ncols() <= sys.n_redundant() {
        return Ok(false);
    }
    let mut dirs = null_space(&a, NULL_TOL);
    for (i, &si) in s.iter().enumerate() {
        dirs.row_mut(i).scale_mut(si);
    }
    let d = dirs.ncols();
    if d == 0 {
        return Ok(false);
    }
    let v0 = DVector::from_column_slice(v);
    let mut cond = Conditions {
        sys,
        q,
        t,
        y: &y,
        dirs: &dirs,
        v0: &v0,
        vbuf: vec![0.0; n],
        gamma: vec![0.0; m],
    };
    let Some(quad) = Quadratics::of(&mut cond, max_abs(v).max(1.0)) else {
        return Ok(false);
    };
    let alpha = match quad.c.len() {
        1 => quad.nearest_root(),
        _ => quad.gauss_newton(),
    };
    // the exact conditions at the result (the quadratic model is exact up to round-off)
    let Some(alpha) = alpha.filter(|a| cond.eval(a).amax() <= BRANCH_TOL * quad.scale) else {
        return Ok(false);
    };
    let dv = &dirs * &alpha;
    for (vi, dvi) in v.iter_mut().zip(dv.iter()) {
        *vi += dvi;
    }
    Ok(true)
}

/// The independent solvability conditions as quadratics in `alpha`:
/// `g_l(alpha) = c_l + b_l . alpha + alpha^T H_l alpha`.
struct Quadratics {
    c: Vec<f64>,
    b: Vec<DVector<f64>>,
    h: Vec<DMatrix<f64>>,
    /// The conditions' scale: their linear part times the velocity scale, their curvature
    /// times its square, and their value at `alpha = 0`.
    scale: f64,
}

impl Quadratics {
    /// The coefficients from `1 + 2d + d (d - 1) / 2` evaluations at steps `eps` (exact for a
    /// quadratic), reduced to independent combinations (a structural redundancy's conditions
    /// vanish identically, and the left null basis mixes them with the others); `None` when
    /// the conditions already hold at `alpha = 0` or vanish identically.
    fn of(cond: &mut Conditions<'_>, eps: f64) -> Option<Self> {
        let d = cond.dirs.ncols();
        let k = cond.y.ncols();
        let width = 1 + d + d * d;
        let mut rows = DMatrix::zeros(k, width);
        let mut x = DVector::zeros(d);
        let c0 = cond.eval(&x);
        rows.column_mut(0).copy_from(&c0);
        let mut diag = vec![DVector::zeros(k); d];
        for i in 0..d {
            x[i] = eps;
            let gp = cond.eval(&x);
            x[i] = -eps;
            let gm = cond.eval(&x);
            x[i] = 0.0;
            rows.column_mut(1 + i)
                .copy_from(&((&gp - &gm) / (2.0 * eps)));
            diag[i] = (&gp + &gm - 2.0 * &c0) / (2.0 * eps * eps);
            rows.column_mut(1 + d + i * d + i).copy_from(&diag[i]);
        }
        for i in 0..d {
            for j in i + 1..d {
                x[i] = eps;
                x[j] = eps;
                let gpp = cond.eval(&x);
                x[i] = 0.0;
                x[j] = 0.0;
                let bi = rows.column(1 + i).clone_owned();
                let bj = rows.column(1 + j).clone_owned();
                // g(eps (e_i + e_j)) = c + eps (b_i + b_j) + eps^2 (H_ii + H_jj + 2 H_ij)
                let hij = (gpp - &c0 - eps * (bi + bj)) / (eps * eps) - &diag[i] - &diag[j];
                let hij = hij / 2.0;
                rows.column_mut(1 + d + i * d + j).copy_from(&hij);
                rows.column_mut(1 + d + j * d + i).copy_from(&hij);
            }
        }
        // coefficients in the units of a value: the linear ones times eps, the quadratic ones
        // times eps^2, for one relative rank test over the whole row
        let mut scaled = rows.clone();
        for col in 1..=d {
            scaled.column_mut(col).scale_mut(eps);
        }
        for col in 1 + d..width {
            scaled.column_mut(col).scale_mut(eps * eps);
        }
        let scale = scaled.amax();
        if scale == 0.0 || c0.amax() <= BRANCH_TOL * scale {
            return None;
        }
        let svd = scaled.svd(true, false);
        let u = svd.u?;
        let sv = &svd.singular_values;
        let smax = sv.amax();
        let (mut c, mut b, mut h) = (Vec::new(), Vec::new(), Vec::new());
        for l in 0..sv.len() {
            if sv[l] <= STEP_RANK_TOL * smax {
                continue;
            }
            // the combination u_l^T of the original rows
            let comb = rows.tr_mul(&u.column(l));
            c.push(comb[0]);
            b.push(comb.rows(1, d).clone_owned());
            h.push(DMatrix::from_column_slice(
                d,
                d,
                comb.rows(1 + d, d * d).as_slice(),
            ));
        }
        if c.is_empty() {
            return None;
        }
        Some(Quadratics { c, b, h, scale })
    }

    /// The nearest zero of the one condition `g(alpha) = c + b . alpha + alpha^T H alpha` to
    /// `alpha = 0`: with `H = Q diag(lambda) Q^T` and `b' = Q^T b`, the minimiser of
    /// `|alpha|^2` on `g = 0` is `beta_i = -mu b'_i / (1 + 2 mu lambda_i)` (`beta = Q^T
    /// alpha`) for the root `mu` of `phi(mu) = g(alpha(mu))` where `I + 2 mu H` is positive
    /// semidefinite (one quadratic constraint: no duality gap); `phi` is the derivative of the
    /// concave dual function there, so it decreases from `phi(0) = c` and its root is found by
    /// bisection. Where it has none inside (the "hard case": `b'` vanishes on an extreme
    /// eigenvector), the free component along that eigenvector closes the gap.
    fn nearest_root(&self) -> Option<DVector<f64>> {
        let (c, b, h) = (self.c[0], &self.b[0], &self.h[0]);
        let eig = h.clone().symmetric_eigen();
        let (lam, qm) = (&eig.eigenvalues, &eig.eigenvectors);
        let bp = qm.tr_mul(b);
        let beta = |mu: f64| -> DVector<f64> {
            DVector::from_fn(lam.len(), |i, _| {
                let den = 1.0 + 2.0 * mu * lam[i];
                if den.abs() <= 1e-12 {
                    0.0
                } else {
                    -mu * bp[i] / den
                }
            })
        };
        let phi = |be: &DVector<f64>| -> f64 {
            c + bp.dot(be)
                + lam
                    .iter()
                    .zip(be.iter())
                    .map(|(l, x)| l * x * x)
                    .sum::<f64>()
        };
        // the root lies on c's side of 0 (phi decreases), before the pole on that side:
        // mu = -1 / (2 lambda) for the extreme eigenvalue of the opposite sign
        let toward = if c > 0.0 { 1.0 } else { -1.0 };
        let extreme = if c > 0.0 { lam.min() } else { lam.max() };
        let pole = (extreme * toward < 0.0).then(|| -1.0 / (2.0 * extreme));
        let mut hi = match pole {
            Some(p) => p,
            None => {
                let mut hi = toward;
                while phi(&beta(hi)) * toward > 0.0 {
                    hi *= 2.0;
                    if !hi.is_finite() {
                        return None;
                    }
                }
                hi
            }
        };
        let mut lo = 0.0f64;
        loop {
            let mid = 0.5 * (lo + hi);
            if mid == lo || mid == hi {
                break;
            }
            if phi(&beta(mid)) * toward > 0.0 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let mut be = beta(lo);
        if let Some(p) = pole {
            let rest = phi(&beta(p));
            if rest * toward > 0.0 && (lo - p).abs() <= 1e-9 * p.abs() {
                // the hard case: phi keeps c's sign up to the pole, where the extreme
                // eigenvector (b' vanishes on it) is free and closes the gap
                be = beta(p);
                let j = lam.iter().position(|&l| l == extreme)?;
                let x2 = -rest / lam[j];
                if !(x2 >= 0.0) {
                    return None;
                }
                be[j] = x2.sqrt();
            }
        }
        Some(qm * be)
    }

    /// Several conditions: Gauss-Newton with minimum-norm steps from `alpha = 0` (a point on
    /// their common zero set near the projection's choice, not always the nearest).
    fn gauss_newton(&self) -> Option<DVector<f64>> {
        let d = self.b[0].len();
        let k = self.c.len();
        let mut alpha = DVector::zeros(d);
        for _ in 0..MAX_ITER {
            let mut g = DVector::zeros(k);
            let mut jac = DMatrix::zeros(k, d);
            for l in 0..k {
                let ha = &self.h[l] * &alpha;
                g[l] = self.c[l] + self.b[l].dot(&alpha) + alpha.dot(&ha);
                let grad = &self.b[l] + 2.0 * ha;
                jac.row_mut(l).copy_from(&grad.transpose());
            }
            let step = min_norm_solve(jac, &g, STEP_RANK_TOL)?;
            alpha -= &step;
            if step.amax() <= 8.0 * f64::EPSILON * (alpha.amax() + 1.0) {
                break;
            }
        }
        Some(alpha)
    }
}

/// The solvability conditions `Y^T gamma(q, v_0 + D alpha, t)` (`D = S N`).
struct Conditions<'a> {
    sys: &'a System,
    q: &'a [f64],
    t: f64,
    y: &'a DMatrix<f64>,
    dirs: &'a DMatrix<f64>,
    v0: &'a DVector<f64>,
    vbuf: Vec<f64>,
    gamma: Vec<f64>,
}

impl Conditions<'_> {
    fn eval(&mut self, alpha: &DVector<f64>) -> DVector<f64> {
        let v = self.v0 + self.dirs * alpha;
        self.vbuf.copy_from_slice(v.as_slice());
        self.sys.gamma(self.q, &self.vbuf, self.t, &mut self.gamma);
        self.y.tr_mul(&DVector::from_column_slice(&self.gamma))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `g(alpha) = (alpha + p)^T H (alpha + p)` with `H = diag(1, -1)`: the zero set is the two
    /// lines `z_1 = +-z_2` through `-p`.
    fn cone(p: [f64; 2]) -> Quadratics {
        let h = DMatrix::from_diagonal(&DVector::from_vec(vec![1.0, -1.0]));
        let pv = DVector::from_vec(p.to_vec());
        let hp = &h * &pv;
        Quadratics {
            c: vec![pv.dot(&hp)],
            b: vec![2.0 * hp],
            h: vec![h],
            scale: 1.0,
        }
    }

    /// The nearest zero of one quadratic: the nearer of two lines (projections of `p` onto
    /// them at squared distances 3.125 and 6.125), the equidistant "hard case" (both at
    /// 4.5: the root sits at the pole and the free eigenvector closes the gap), and a scalar
    /// quadratic's nearer root (a mechanism without a degree of freedom: two branches).
    #[test]
    fn the_nearest_zero_of_one_quadratic() {
        let a = cone([3.0, 0.5]).nearest_root().unwrap();
        assert!(
            (a[0] + 1.25).abs() < 1e-12 && (a[1] - 1.25).abs() < 1e-12,
            "{a}"
        );
        let a = cone([3.0, 0.0]).nearest_root().unwrap();
        assert!(
            (a[0] + 1.5).abs() < 1e-12 && (a[1].abs() - 1.5).abs() < 1e-12,
            "{a}"
        );
        // the negative side: c < 0 (p = (0.5, 3))
        let a = cone([0.5, 3.0]).nearest_root().unwrap();
        assert!(
            (a[0] - 1.25).abs() < 1e-12 && (a[1] + 1.25).abs() < 1e-12,
            "{a}"
        );
        // (alpha - 1)(alpha + 4): roots 1 and -4, nearest 1
        let q = Quadratics {
            c: vec![-4.0],
            b: vec![DVector::from_vec(vec![3.0])],
            h: vec![DMatrix::from_element(1, 1, 1.0)],
            scale: 1.0,
        };
        let a = q.nearest_root().unwrap();
        assert!((a[0] - 1.0).abs() < 1e-12, "{a}");
        // 1 + alpha^2 = 0 has no real root
        let q = Quadratics {
            c: vec![1.0],
            b: vec![DVector::zeros(1)],
            h: vec![DMatrix::from_element(1, 1, 1.0)],
            scale: 1.0,
        };
        assert!(q.nearest_root().is_none());
    }
}
