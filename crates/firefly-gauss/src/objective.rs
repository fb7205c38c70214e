//! The per-step objective: complete a candidate `(z, zdot)` at `t_{k+1}` to a consistent state,
//! interpolate over the step (cubic Hermite), and measure the equations of motion at the two
//! Gauss points with the multipliers eliminated (null-space projection).
//!
//! [`StepProblem`] holds what is fixed during one step; [`Workspace`] the scratch buffers of one
//! evaluation. An evaluation is a pure function of the candidate and the step problem: the
//! Newton iteration for the dependent coordinates always starts from the same point (the
//! predictor's), so the serial and the parallel optimiser see identical values.
//!
//! Only the partition's `r` equations enter (`r = m - k` with `k` redundant equations): the
//! full `Phi` and `Phi_q` are evaluated into scratch and their rows gathered, so the dependent
//! block is square (`r x r`). Without redundant equations the rows are `0..m` and the gathered
//! values are the evaluated ones.

use crate::partition::Partition;
use mbd_model::System;
use mbd_solve::linalg::max_abs;
use mbd_solve::linalg::DenseLu;
use nalgebra::DMatrix;

/// Cubic Hermite weights at one Gauss point `tau` of `[0, 1]`, for the forms
/// `q(tau) = q0 + c01 (q1 - q0) + h (c10 v0 + c11 v1)` and its first and second derivatives.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct GaussNode {
    pub tau: f64,
    /// `h01, h10, h11`.
    pub q: [f64; 3],
    /// `h01', h10', h11'`.
    pub v: [f64; 3],
    /// `h01'', h10'', h11''`.
    pub a: [f64; 3],
}

impl GaussNode {
    fn new(tau: f64) -> Self {
        let t2 = tau * tau;
        let t3 = t2 * tau;
        GaussNode {
            tau,
            q: [-2.0 * t3 + 3.0 * t2, t3 - 2.0 * t2 + tau, t3 - t2],
            v: [
                -6.0 * t2 + 6.0 * tau,
                3.0 * t2 - 4.0 * tau + 1.0,
                3.0 * t2 - 2.0 * tau,
            ],
            a: [-12.0 * tau + 6.0, 6.0 * tau - 4.0, 6.0 * tau - 2.0],
        }
    }
}

/// The two Gauss-Legendre nodes on `[0, 1]`, `1/2 -/+ sqrt(3)/6` (weights 1/2 each).
pub(crate) fn gauss_nodes() -> [GaussNode; 2] {
    let d = 3f64.sqrt() / 6.0;
    [GaussNode::new(0.5 - d), GaussNode::new(0.5 + d)]
}

/// Everything fixed during one step.
#[derive(Debug)]
pub(crate) struct StepProblem {
    pub n: usize,
    /// Number of equations in use (the rank of `Phi_q`), `dep.len() == rows.len()`.
    pub r: usize,
    pub dof: usize,
    pub ind: Vec<usize>,
    pub dep: Vec<usize>,
    /// The equations in use (rows of `Phi`, ascending).
    pub rows: Vec<usize>,
    pub t0: f64,
    pub t1: f64,
    pub h: f64,
    pub q0: Vec<f64>,
    pub v0: Vec<f64>,
    /// Start of the Newton iteration for the dependent coordinates (predicted `q_{k+1}`).
    pub q_start: Vec<f64>,
    /// LU of the dependent block of `Phi_q(q_start)` (chord Newton).
    pub chord: DenseLu,
    /// LU of `G0 = N0^T M N0` at `q0` (the tangent metric that turns the projected residual
    /// into independent-coordinate accelerations).
    pub metric: DenseLu,
    pub mass: Vec<f64>,
    pub nodes: [GaussNode; 2],
    /// Newton tolerance on `||Phi||_inf` (absolute, already scaled by the coordinates).
    pub newton_tol: f64,
    pub newton_max_iter: usize,
}

impl StepProblem {
    pub fn new(sys: &System, part: &Partition) -> Self {
        let n = sys.n_coords();
        let r = part.dependent.len();
        let dof = n - r;
        StepProblem {
            n,
            r,
            dof,
            ind: part.independent.clone(),
            dep: part.dependent.clone(),
            rows: part.equations.clone(),
            t0: 0.0,
            t1: 0.0,
            h: 0.0,
            q0: vec![0.0; n],
            v0: vec![0.0; n],
            q_start: vec![0.0; n],
            chord: crate::objective::small_lu(r),
            metric: crate::objective::small_lu(dof),
            mass: sys.mass_diag().iter().copied().collect(),
            nodes: gauss_nodes(),
            newton_tol: 1e-14,
            newton_max_iter: 10,
        }
    }

    /// Re-targets the problem to another partition (same sizes: no allocation).
    pub fn set_partition(&mut self, part: &Partition) {
        self.ind.clone_from(&part.independent);
        self.dep.clone_from(&part.dependent);
        self.rows.clone_from(&part.equations);
    }

    /// Number of decision variables `2 dof`.
    pub fn dim(&self) -> usize {
        2 * self.dof
    }

    /// Fills the per-step data. `q_start` must already hold the predicted positions.
    /// Returns `Err(what)` if the dependent block or the metric is singular.
    pub fn prepare(
        &mut self,
        sys: &System,
        ws: &mut Workspace,
        t0: f64,
        h: f64,
        q0: &[f64],
        v0: &[f64],
    ) -> Result<(), &'static str> {
        self.t0 = t0;
        self.h = h;
        self.t1 = t0 + h;
        self.q0.copy_from_slice(q0);
        self.v0.copy_from_slice(v0);
        // chord Jacobian at the predicted positions
        sys.phi_q(&self.q_start, self.t1, &mut ws.jac);
        fill_block(&ws.jac, &self.rows, &self.dep, self.chord.rows_mut());
        self.chord
            .factor_lu()
            .map_err(|_| "dependent block of Phi_q at the predicted state")?;
        // metric G0 = M_z + X^T M_d X with X = Phi_d^-1 Phi_z at q0
        sys.phi_q(q0, t0, &mut ws.jac);
        fill_block(&ws.jac, &self.rows, &self.dep, ws.lu.rows_mut());
        ws.lu
            .factor_lu()
            .map_err(|_| "dependent block of Phi_q at the step's start")?;
        let (m, dof) = (self.r, self.dof);
        for (c, &zc) in self.ind.iter().enumerate() {
            for (r, &row) in self.rows.iter().enumerate() {
                ws.x[c * m + r] = ws.jac[(row, zc)];
            }
            ws.lu.solve_in_place(&mut ws.x[c * m..(c + 1) * m]);
        }
        let g = self.metric.rows_mut();
        for a in 0..dof {
            for b in 0..dof {
                let mut s = if a == b { self.mass[self.ind[a]] } else { 0.0 };
                for (r, &d) in self.dep.iter().enumerate() {
                    s += ws.x[a * m + r] * self.mass[d] * ws.x[b * m + r];
                }
                g[a * dof + b] = s;
            }
        }
        self.metric
            .factor_lu()
            .map_err(|_| "tangent mass metric N^T M N")?;
        Ok(())
    }

    /// Completes the candidate `x = (z, zdot)` into `ws.q1`, `ws.v1`: dependent coordinates by
    /// chord Newton on `Phi(q, t1) = 0` from `q_start`, dependent velocities from the velocity
    /// constraint with the Jacobian at the converged positions. Returns the Newton iterations,
    /// or `None` if Newton did not reach the tolerance (or met a singular block).
    pub fn complete(&self, sys: &System, ws: &mut Workspace, x: &[f64]) -> Option<usize> {
        let dof = self.dof;
        ws.q1.copy_from_slice(&self.q_start);
        for (k, &i) in self.ind.iter().enumerate() {
            ws.q1[i] = x[k];
        }
        let mut iters = 0;
        loop {
            sys.phi(&ws.q1, self.t1, &mut ws.phi);
            // the test covers every equation: a redundant one is a combination of the rows in
            // use, with coefficients that grow as their block loses conditioning
            let res = max_abs(&ws.phi);
            if !res.is_finite() {
                return None;
            }
            // at least one iteration, so the accepted residual is at round-off even when the
            // start already meets the tolerance
            if res <= self.newton_tol && (iters > 0 || res == 0.0) {
                break;
            }
            if iters >= self.newton_max_iter {
                return None;
            }
            for (k, &row) in self.rows.iter().enumerate() {
                ws.phi_r[k] = ws.phi[row];
            }
            self.chord.solve_with(&mut ws.phi_r, &mut ws.ly, &mut ws.lx);
            for (r, &d) in self.dep.iter().enumerate() {
                ws.q1[d] -= ws.phi_r[r];
            }
            iters += 1;
        }
        // velocities: Phi_d v_d = -Phi_t - Phi_z zdot at the converged q1 (Phi_t into the
        // residual's buffer, free now)
        sys.phi_q(&ws.q1, self.t1, &mut ws.jac);
        sys.phi_t(&ws.q1, self.t1, &mut ws.phi);
        fill_block(&ws.jac, &self.rows, &self.dep, ws.lu.rows_mut());
        ws.lu.factor_lu().ok()?;
        for (r, &row) in self.rows.iter().enumerate() {
            let mut s = -ws.phi[row];
            for (k, &i) in self.ind.iter().enumerate() {
                s -= ws.jac[(row, i)] * x[dof + k];
            }
            ws.rhs[r] = s;
        }
        ws.lu.solve_in_place(&mut ws.rhs);
        for (k, &i) in self.ind.iter().enumerate() {
            ws.v1[i] = x[dof + k];
        }
        for (r, &d) in self.dep.iter().enumerate() {
            ws.v1[d] = ws.rhs[r];
        }
        Some(iters)
    }

    /// The scaled Gauss residuals of the completed state in `ws.q1, ws.v1` into `out`
    /// (length `2 dof`): `out[g dof + i] = sqrt(1/2) h^2 delta_g,i`, where `delta_g` is the
    /// projected residual of the equations of motion at Gauss node `g` in independent-coordinate
    /// accelerations. The objective is `||out||^2`.
    pub fn gauss_residuals(&self, sys: &System, ws: &mut Workspace, out: &mut [f64]) -> bool {
        let (n, dof, h) = (self.n, self.dof, self.h);
        let scale = std::f64::consts::FRAC_1_SQRT_2 * h * h;
        for i in 0..n {
            ws.dq[i] = ws.q1[i] - self.q0[i];
        }
        for (g, node) in self.nodes.iter().enumerate() {
            for i in 0..n {
                let (d, v0, v1) = (ws.dq[i], self.v0[i], ws.v1[i]);
                ws.qg[i] = self.q0[i] + node.q[0] * d + h * (node.q[1] * v0 + node.q[2] * v1);
                ws.vg[i] = node.v[0] * d / h + node.v[1] * v0 + node.v[2] * v1;
                let ag = (node.a[0] * d / h + node.a[1] * v0 + node.a[2] * v1) / h;
                ws.r[i] = self.mass[i] * ag;
            }
            let tg = self.t0 + node.tau * h;
            sys.forces_into(&ws.qg, &ws.vg, tg, &mut ws.force);
            for i in 0..n {
                ws.r[i] -= ws.force[i];
            }
            // eliminate lambda: rho = N^T r = r_z - Phi_z^T mu,  Phi_d^T mu = r_d
            sys.phi_q(&ws.qg, tg, &mut ws.jac);
            fill_block(&ws.jac, &self.rows, &self.dep, ws.lu.rows_mut());
            if ws.lu.factor_lu().is_err() {
                return false;
            }
            for (k, &d) in self.dep.iter().enumerate() {
                ws.mu[k] = ws.r[d];
            }
            ws.lu.solve_transpose_in_place(&mut ws.mu);
            let rho = &mut out[g * dof..(g + 1) * dof];
            for (k, &i) in self.ind.iter().enumerate() {
                let mut s = ws.r[i];
                for (r, &row) in self.rows.iter().enumerate() {
                    s -= ws.jac[(row, i)] * ws.mu[r];
                }
                rho[k] = s;
            }
            self.metric.solve_with(rho, &mut ws.ly, &mut ws.lx);
            for x in rho.iter_mut() {
                *x *= scale;
            }
        }
        out.iter().all(|x| x.is_finite())
    }

    /// The objective at `x`: `||gauss_residuals||^2`, NaN if the candidate cannot be completed.
    pub fn objective(&self, sys: &System, ws: &mut Workspace, x: &[f64]) -> f64 {
        if self.complete(sys, ws, x).is_none() {
            return f64::NAN;
        }
        let mut res = std::mem::take(&mut ws.res);
        let ok = self.gauss_residuals(sys, ws, &mut res);
        let f = if ok {
            res.iter().map(|r| r * r).sum()
        } else {
            f64::NAN
        };
        ws.res = res;
        f
    }

    /// The residual vector at `x` into `out` (for Gauss-Newton); false if infeasible.
    pub fn residual_vector(
        &self,
        sys: &System,
        ws: &mut Workspace,
        x: &[f64],
        out: &mut [f64],
    ) -> bool {
        self.complete(sys, ws, x).is_some() && self.gauss_residuals(sys, ws, out)
    }
}

/// Copies the square block `Phi_q[rows, dep]` row-major into `out` (`rows.len() == dep.len()`).
#[inline]
pub(crate) fn fill_block(j: &DMatrix<f64>, rows: &[usize], dep: &[usize], out: &mut [f64]) {
    let r = dep.len();
    for (k, &row) in rows.iter().enumerate() {
        for (c, &col) in dep.iter().enumerate() {
            out[k * r + c] = j[(row, col)];
        }
    }
}

/// Scratch buffers of one objective evaluation.
#[derive(Debug, Clone)]
pub(crate) struct Workspace {
    pub q1: Vec<f64>,
    pub v1: Vec<f64>,
    /// `Phi` (all `m` equations).
    pub phi: Vec<f64>,
    /// The `r` equations in use, gathered from `phi`.
    pub phi_r: Vec<f64>,
    pub rhs: Vec<f64>,
    pub mu: Vec<f64>,
    pub jac: DMatrix<f64>,
    pub lu: DenseLu,
    pub dq: Vec<f64>,
    pub qg: Vec<f64>,
    pub vg: Vec<f64>,
    pub r: Vec<f64>,
    pub force: Vec<f64>,
    pub x: Vec<f64>,
    pub res: Vec<f64>,
    /// Workspace of the solves with the shared LUs (`max(r, dof)` each).
    pub ly: Vec<f64>,
    pub lx: Vec<f64>,
}

impl Workspace {
    /// Buffers for `sys`: `r = m - k` equations in use (`k` redundant), `dof = n - r`.
    pub fn new(sys: &System) -> Self {
        let (n, m) = (sys.n_coords(), sys.n_constraints());
        let r = m - sys.n_redundant().min(m);
        let dof = n.saturating_sub(r);
        Workspace {
            q1: vec![0.0; n],
            v1: vec![0.0; n],
            phi: vec![0.0; m],
            phi_r: vec![0.0; r],
            rhs: vec![0.0; r],
            mu: vec![0.0; r],
            jac: DMatrix::zeros(m, n),
            lu: crate::objective::small_lu(r),
            dq: vec![0.0; n],
            qg: vec![0.0; n],
            vg: vec![0.0; n],
            r: vec![0.0; n],
            force: vec![0.0; n],
            x: vec![0.0; r * dof],
            res: vec![0.0; 2 * dof],
            ly: vec![0.0; r.max(dof)],
            lx: vec![0.0; r.max(dof)],
        }
    }
}

/// The project's dense LU ([`DenseLu`]) as the small LUs here use it: only an exactly zero (or
/// non-finite) pivot fails the factorisation; the callers judge the conditioning themselves
/// from [`DenseLu::pivot_range`] or [`DenseLu::log_abs_det`].
pub(crate) fn small_lu(n: usize) -> DenseLu {
    let mut lu = DenseLu::new(n);
    lu.pivot_tol = 0.0;
    lu
}
