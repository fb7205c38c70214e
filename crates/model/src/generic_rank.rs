//! Redundant equations against a singular initial configuration: the rank of `Phi_q` on the
//! constraint manifold near the build configuration.
//!
//! An equation that depends on the others at the build configuration `q0` is either
//! *redundant* (the dependence holds all along the motion: a double parallelogram's third
//! crank) or `q0` is a *singular configuration* (the dependence holds at isolated points of
//! the motion: a parallelogram four-bar started with its cranks in line with the ground).
//! The two differ in what the solvers may do with the equation: a redundant one is dropped
//! at every factorisation and the mechanism has `n - rank` degrees of freedom with the rank
//! of the generic configuration; a singular configuration is passed on its branch. Both look
//! alike at `q0`. Near `q0` on the manifold they do not: a structural dependence persists, a
//! singular one does not (a singular configuration is a lower-dimensional subset of the
//! manifold). So the test moves from `q0` along a generic direction of the tangent cone
//! (the null space of `Phi_q(q0)`), projects back onto `Phi = 0`, and counts the dependent
//! equations there; the fewest found over two directions are the redundant ones.
//!
//! The probes move on the manifold of the scleronomic equations: a driver's equation (one
//! that depends on time) is left out of the projection and of the null space, so the driven
//! coordinates move too, as they do along the motion. A fully driven mechanism has no free
//! direction at a fixed time, and a singular configuration of it is passed in time, not in
//! space. The rank test at a probe takes every row (a driver's gradient does not depend on
//! the value its function takes).

use crate::init::RedundantEquation;
use crate::system::System;
use mbd_linalg::min_norm_solve;
use nalgebra::{DMatrix, DVector};

/// Distance of the probe points from the build configuration, relative to the mechanism's
/// length scale (in the unit-free coordinates of [`System::rank_weights`], where an angle
/// counts as the arc it turns the body's radius of gyration through), before the projection
/// back onto the manifold (which takes up the part of the step along directions that are
/// tangent to the manifold at `q0` only). Far enough that a singular configuration's
/// dependence, which grows linearly with the distance, is far above [`PROBE_RANK_TOL`] at the
/// probe, near enough to stay on the branches through `q0`.
const PROBE_DISTANCE: f64 = 1e-2;

/// The rank test's relative tolerance at a probe point. Near a singular configuration the
/// manifold is nearly wider than it is (the rows that depend on the others at `q0` nearly do
/// near it), so a projection leaves the probe slightly off the exact motion (a coupler turned
/// by 1e-9 rad at 1e-4 rad from a flat triple parallelogram with `|Phi|` at 1e-13), and such
/// an offset breaks a structural dependence by as much; the singular dependence at the probe
/// is about the probe's distance. The tolerance lies between the two.
const PROBE_RANK_TOL: f64 = 1e-6;

/// Most Gauss-Newton corrections of a projection onto `Phi = 0`.
const MAX_PROJECTION_ITER: usize = 50;

/// Singular values of the weighted `Phi_q` below this fraction of the largest are treated as
/// zero in the minimum-norm corrections (the rank test's relative tolerance).
const RANK_CUTOFF: f64 = 1e-9;

/// The split of the equations dependent at the build configuration.
pub(crate) struct DependenceSplit {
    /// Dependent near `q0` as at `q0`: the redundant equations.
    pub(crate) redundant: Vec<RedundantEquation>,
    /// Dependent at `q0` only (a singular initial configuration).
    pub(crate) singular: Vec<RedundantEquation>,
}

impl System {
    /// Splits `found`, the equations dependent at `q0` (time `t`), into the redundant ones and
    /// those dependent at the start only (see the module documentation). `q0` may be a rough
    /// guess off the manifold (an assembly finds the consistent configuration later): the start
    /// is then `q0` projected onto it, and rows dependent at the guess only are neither. Where
    /// no probe point can be reached (no free direction, a projection that does not converge,
    /// or more than [`crate::SPARSE_RANK_THRESHOLD`] equations, where the dense test is not
    /// run) every equation of `found` counts as redundant.
    pub(crate) fn split_dependence(
        &self,
        q0: &[f64],
        t: f64,
        found: Vec<RedundantEquation>,
    ) -> Result<DependenceSplit, crate::ModelError> {
        let keep = |found| {
            Ok(DependenceSplit {
                redundant: found,
                singular: Vec::new(),
            })
        };
        if found.is_empty() || self.m > crate::SPARSE_RANK_THRESHOLD {
            return keep(found);
        }
        let probe = Probe::new(self, q0, t);
        let Some(base) = probe.project(q0) else {
            return keep(found);
        };
        let mut fewest: Option<Vec<RedundantEquation>> = None;
        // two generic directions (Weyl sequences of the golden ratio and of the plastic
        // number): a structural dependence holds along both, a singular one along neither
        for ratio in [0.618_033_988_749_894_9, 0.754_877_666_246_692_8] {
            let Some(point) = probe.point(&base, ratio) else {
                continue;
            };
            let mut jac = DMatrix::zeros(self.m, self.n);
            self.phi_q(&point, t, &mut jac);
            let there = self.redundant_dense(&jac, PROBE_RANK_TOL);
            if fewest.as_ref().map_or(true, |f| there.len() < f.len()) {
                fewest = Some(there);
            }
        }
        let Some(redundant) = fewest else {
            return keep(found);
        };
        // the rows dependent at the start itself (the guess, if it was on the manifold)
        let at_start = if base == q0 {
            found
        } else {
            self.redundant_at(&base, t)?
        };
        // (the rank near a point is at least the rank there: more rows dependent at a probe
        // than at the start are the probe's tolerance, and the start's count stands)
        if redundant.len() >= at_start.len() {
            return keep(at_start);
        }
        let extra = at_start.len() - redundant.len();
        let singular = at_start
            .into_iter()
            .filter(|e| redundant.iter().all(|r| r.row != e.row))
            .take(extra)
            .collect();
        Ok(DependenceSplit {
            redundant,
            singular,
        })
    }
}

/// What the probes of a system share: the time, the unit-free scaling of the coordinates, the
/// length scale and the scleronomic rows they move on.
struct Probe<'a> {
    sys: &'a System,
    t: f64,
    /// Square roots of [`System::rank_weights`].
    sqrt_w: Vec<f64>,
    length: f64,
    /// The rows whose equation does not depend on time.
    rows: Vec<usize>,
}

impl<'a> Probe<'a> {
    fn new(sys: &'a System, q0: &[f64], t: f64) -> Self {
        // a row depends on time where its value changes with `t` at fixed `q` (two offsets:
        // a periodic driver does not hide behind one of them)
        let value = |t: f64| {
            let mut phi = vec![0.0; sys.m];
            sys.phi(q0, t, &mut phi);
            phi
        };
        let (now, later, other) = (value(t), value(t + 0.37), value(t + 1.91));
        let rows = (0..sys.m)
            .filter(|&r| now[r] == later[r] && now[r] == other[r])
            .collect();
        Probe {
            sys,
            t,
            sqrt_w: sys.rank_weights().iter().map(|w| w.sqrt()).collect(),
            length: sys.length_scale(),
            rows,
        }
    }

    /// A point of the manifold at about [`PROBE_DISTANCE`] times the length scale from `base`
    /// (on it) along the part of the generic vector `g_i = frac((i + 1) ratio) - 1/2`
    /// (unit-free coordinates) in the null space of the scleronomic rows of `Phi_q(base)`;
    /// `None` if that part vanishes or the projection fails.
    fn point(&self, base: &[f64], ratio: f64) -> Option<Vec<f64>> {
        let n = self.sys.n;
        let jac = self.jacobian(base);
        let g: Vec<f64> = (0..n)
            .map(|i| ((i + 1) as f64 * ratio).fract() - 0.5)
            .collect();
        let g = DVector::from_vec(g);
        // d = g - J^+ J g: the minimum-norm solution removes g's part in the row space
        let row_part = min_norm_solve(jac.clone(), &(&jac * &g), RANK_CUTOFF)?;
        let d = g - row_part;
        let dmax = d.amax();
        // (a NaN is no direction either)
        if dmax.is_nan() || dmax <= 1e-6 {
            return None;
        }
        let scale = PROBE_DISTANCE * self.length / dmax;
        let start: Vec<f64> = (0..n)
            .map(|i| base[i] + scale * d[i] / self.sqrt_w[i])
            .collect();
        self.project(&start)
    }

    /// Gauss-Newton from `q` onto the scleronomic equations with minimum-norm corrections in
    /// the unit-free coordinates (rank-deficient `Phi_q` allowed); `None` if it does not reach
    /// `|Phi| <= 1e-12 (1 + length)` on those rows within [`MAX_PROJECTION_ITER`] corrections.
    fn project(&self, q: &[f64]) -> Option<Vec<f64>> {
        let tol = 1e-12 * (1.0 + self.length);
        let mut q = q.to_vec();
        let mut phi = vec![0.0; self.sys.m];
        for _ in 0..=MAX_PROJECTION_ITER {
            self.sys.phi(&q, self.t, &mut phi);
            let res: DVector<f64> =
                DVector::from_iterator(self.rows.len(), self.rows.iter().map(|&r| phi[r]));
            let size = res.amax();
            if !size.is_finite() {
                return None;
            }
            if size <= tol {
                return Some(q);
            }
            let dz = min_norm_solve(self.jacobian(&q), &res, RANK_CUTOFF)?;
            for (i, qi) in q.iter_mut().enumerate() {
                *qi -= dz[i] * self.sqrt_w[i];
            }
        }
        None
    }

    /// The scleronomic rows of `Phi_q(q, t) W^(1/2)` (the unit-free coordinates' Jacobian).
    fn jacobian(&self, q: &[f64]) -> DMatrix<f64> {
        let mut full = DMatrix::zeros(self.sys.m, self.sys.n);
        self.sys.phi_q(q, self.t, &mut full);
        let mut jac = DMatrix::zeros(self.rows.len(), self.sys.n);
        for (i, &r) in self.rows.iter().enumerate() {
            for k in 0..self.sys.n {
                jac[(i, k)] = full[(r, k)] * self.sqrt_w[k];
            }
        }
        jac
    }
}
