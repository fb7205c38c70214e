//! The (s,s) constrained Galerkin variational integrator, optionally preadjusted.

use crate::options::{kappa, Nodes, PreadjustMode, SymplecticOptions, MAX_PREDICTOR_ORDER};
use crate::preadjust::Preadjustment;
use crate::tables::Tables;
use dense::stage_lu;
use mbd_model::System;
use mbd_solve::linalg::{Anderson, DenseCholesky, DenseLu};
use mbd_solve::{
    AccelerationSolver, ButcherTableau, ConstrainedSolve, Integrator, LinearSolver,
    SingularStarter, SolveError, State, StepStats,
};
use nalgebra::DMatrix;
use sparse::{add_transpose, SparseStage};
use spatial::{row_scale, spatial_support, EndSolve};

mod dense;
mod modlag;
mod newton;
mod sparse;
mod spatial;
mod step;
#[cfg(test)]
mod tests;

/// The parameter-preadjusted (s,s) constrained Galerkin variational integrator (paper A).
///
/// One step solves the `s (n + m)` stage equations for the control-point displacements
/// `Z_nu = Q_nu - q_k` (`nu = 1..s`) and the scaled multipliers (see `docs/symplectic.md`) by
/// Newton with an analytic Jacobian, then projects the end momentum onto the hidden constraint.
/// Every buffer is allocated in [`Galerkin::new`]; [`Integrator::step`] allocates nothing
/// (except to format an error message).
#[derive(Debug)]
pub struct Galerkin {
    opts: SymplecticOptions,
    tab: Tables,
    n: usize,
    m: usize,
    dim: usize,
    /// The momentum rows' scale: `M^-1` on coordinates with mass; on a massless one (a
    /// director of a spatial body with `E_i = 0`) the inverse of its body's largest second
    /// moment, its row being a force balance (`unit` 0).
    minv: Vec<f64>,
    /// 1 on coordinates with mass, 0 on massless ones: the kinetic terms' factor in the
    /// `M^-1`-scaled momentum rows.
    unit: Vec<f64>,
    /// Models with spatial bodies: the end velocity from the end momentum by the constrained
    /// solve (`M` may be singular), with its right-hand side and multipliers.
    end_solve: Option<Box<EndSolve>>,
    kappa: f64,
    nonconservative: bool,
    x: Vec<f64>,
    dx: Vec<f64>,
    /// The previous Newton update (swapped with `dx` at each iteration).
    dx_prev: Vec<f64>,
    r: Vec<f64>,
    xt: Vec<f64>,
    /// Anderson mixing of the Newton updates (`newton.rs`), and the plain contraction that
    /// switched it on in the last step (0: off), which carries it over with the Jacobian.
    aa: Anderson,
    aa_theta: f64,
    lu: DenseLu,
    qk: Vec<f64>,
    hvk: Vec<f64>,
    qn: Vec<f64>,
    qj: Vec<f64>,
    hvj: Vec<f64>,
    gj: Vec<f64>,
    hq: Vec<DMatrix<f64>>,
    hv: Vec<DMatrix<f64>>,
    hess_nz: Vec<bool>,
    /// Dense path: `Phi_q` at the control points `0..=s` (empty on the sparse path).
    phiq: Vec<DMatrix<f64>>,
    /// Sparse path: `Phi_q` at the control points in element-local rows (empty when dense).
    grads: Vec<Vec<f64>>,
    /// The sparse stage solve, if the system takes the sparse path.
    sparse: Option<Box<SparseStage>>,
    hc: DMatrix<f64>,
    /// `grad W_s` at each Gauss point of the last evaluation (`s x n`).
    wgrad: Vec<f64>,
    wh: DMatrix<f64>,
    pre: Vec<Preadjustment>,
    /// The modified-Lagrangian workspace (`PreadjustMode::ModifiedLagrangian`, `s = 1`).
    ml: Vec<Preadjustment>,
    /// `h^2 d e / d q` at the chord midpoint `(Q_0 + Q_1) / 2` of the step.
    mlq: Vec<f64>,
    /// `h^2 d e / d v` there.
    mlv: Vec<f64>,
    /// The chord midpoint `(Q_0 + Q_1) / 2`.
    mlmid: Vec<f64>,
    /// The step's constant velocity `(Q_1 - Q_0) / h`.
    mlvel: Vec<f64>,
    /// The `s = 2` gradients of the last steps, extrapolated at the predictor (`modlag.rs`).
    mlhist: modlag::GradientHistory,
    /// The first step from a singular configuration where the stage equations have no
    /// solution (`step.rs`).
    starter: SingularStarter,
    /// Sparse path, s = 1 modified Lagrangian: the diagonals of its Newton blocks
    /// (`Preadjustment::modified_newton_diagonals`).
    mldiag: [Vec<f64>; 3],
    /// Sparse path with `W_s`: the diagonal stand-in for its Newton Hessian at a Gauss point
    /// (`Preadjustment::newton_diagonal`).
    wdiag: Vec<f64>,
    tn: [Vec<f64>; 4],
    proj: DenseCholesky,
    vm: Vec<f64>,
    mu: Vec<f64>,
    /// The dense index-1 solve of the first step's predictor (None on the sparse path).
    acc: Option<AccelerationSolver>,
    acc_a: Vec<f64>,
    acc_l: Vec<f64>,
    hist_valid: bool,
    hist_t: f64,
    hist_h: f64,
    hist_q: Vec<f64>,
    /// The last `hist_len` converged unknown vectors of consecutive steps with the same `h`,
    /// newest first (`(MAX_PREDICTOR_ORDER + 1) * dim`); the first is the last step's solution.
    hist_multi: Vec<f64>,
    hist_len: usize,
    /// `phiq[s]` holds `Phi_q` at the end of the last step.
    end_phiq_valid: bool,
    gk: f64,
    has_forces: bool,
    jac_valid: bool,
    jac_h: f64,
    jac_gk: f64,
    jacobians: usize,
    /// Whether the `W_s` term is left out of the Newton Jacobian (`dense.rs`), and for how
    /// many more Jacobians that decision stands (0: check again), made at `h^2 |gk|` =
    /// `w_skip_scale`.
    w_skip: bool,
    w_skip_left: usize,
    w_skip_scale: f64,
}
impl Galerkin {
    /// A scheme for `sys` with the given options (validated). Models with non-conservative
    /// forces are integrated by the discrete Lagrange-d'Alembert principle (forces at the Gauss
    /// points).
    pub fn new(sys: &System, options: SymplecticOptions) -> Result<Galerkin, SolveError> {
        options.validate()?;
        let s = options.s;
        let (n, m) = (sys.n_coords(), sys.n_constraints());
        let dim = s * (n + m);
        let tab = Tables::new(s, options.nodes);
        let modlag = options.preadjust == PreadjustMode::ModifiedLagrangian;
        if sys.has_spatial() {
            spatial_support(sys, s, modlag, options.gamma, options.linear_solver)?;
        }
        if modlag && !sys.is_conservative() {
            let elements: Vec<String> = sys
                .forces()
                .iter()
                .filter(|f| f.is_nonconservative())
                .map(|f| format!("'{}' ({})", f.name, f.kind_name()))
                .chain(
                    sys.spatial_forces()
                        .iter()
                        .filter(|f| f.is_nonconservative())
                        .map(|f| format!("'{}' ({})", f.name, f.kind_name())),
                )
                .collect();
            return Err(SolveError::Unsupported(format!(
                "the modified-Lagrangian preadjustment (:modified) is derived for a conservative \
                 model, and force element(s) {} damp or load it with time: use symplectic:S \
                 without :modified (it takes such forces by the discrete Lagrange-d'Alembert \
                 principle)",
                elements.join(", ")
            )));
        }
        // (W_s and the modified Lagrangian add dense blocks to the Newton matrix; the sparse
        // path takes diagonal or augmented stand-ins for them: docs/symplectic.md, "Sparse
        // stage solve")
        let use_sparse = options.linear_solver.use_sparse(m) && m > 0;
        let sparse = if use_sparse {
            Some(Box::new(SparseStage::new(
                sys,
                s,
                s == 1 && (modlag || options.gamma != 0.0),
            )?))
        } else {
            None
        };
        // the dense matrices are not allocated on the sparse path
        let (nd, md) = if use_sparse { (0, 0) } else { (n, m) };
        // one workspace per Gauss point (W_s) or per control point (modified Lagrangian), so
        // each keeps its evaluation while its point does not move
        // (on the sparse path S is held sparse: O(N) per evaluation of the modified terms)
        let workspace = |degree: usize, sparse: bool| -> Result<Preadjustment, SolveError> {
            let mut p = Preadjustment::with_layout(sys, degree, sparse)?;
            p.fd_step = options.fd_step;
            Ok(p)
        };
        let pre = if options.gamma != 0.0 {
            (0..s)
                .map(|_| workspace(s, use_sparse))
                .collect::<Result<Vec<_>, _>>()?
        } else {
            Vec::new()
        };
        let ml = if modlag {
            vec![workspace(1, use_sparse)?]
        } else {
            Vec::new()
        };
        let nl = if modlag { n } else { 0 };
        Ok(Galerkin {
            ml,
            mlq: vec![0.0; nl],
            mlv: vec![0.0; nl],
            mlmid: vec![0.0; nl],
            mlvel: vec![0.0; nl],
            wdiag: if options.gamma != 0.0 && use_sparse {
                vec![0.0; n]
            } else {
                Vec::new()
            },
            mldiag: if modlag && use_sparse && s == 1 {
                [vec![0.0; n], vec![0.0; n], vec![0.0; n]]
            } else {
                [Vec::new(), Vec::new(), Vec::new()]
            },
            mlhist: modlag::GradientHistory::new(if modlag && options.s == 2 { n } else { 0 }),
            // (DOPRI5: one step's local error O(h^6), below the scheme's global error for
            // the orders up to 6)
            starter: SingularStarter::new(ButcherTableau::dopri5()),
            opts: options,
            tab,
            n,
            m,
            dim,
            minv: row_scale(sys),
            unit: sys
                .mass_diag()
                .iter()
                .map(|&m| if m > 0.0 { 1.0 } else { 0.0 })
                .collect(),
            end_solve: if sys.has_spatial() {
                Some(Box::new(EndSolve {
                    solve: ConstrainedSolve::new(
                        sys,
                        if use_sparse {
                            LinearSolver::Sparse
                        } else {
                            LinearSolver::Dense
                        },
                    )?,
                    p: vec![0.0; n],
                    r: vec![0.0; m],
                }))
            } else {
                None
            },
            kappa: kappa(s),
            nonconservative: !sys.is_conservative(),
            x: vec![0.0; dim],
            dx: vec![0.0; dim],
            dx_prev: vec![0.0; dim],
            r: vec![0.0; dim],
            xt: vec![0.0; dim],
            aa: Anderson::new(dim, s * n, options.anderson_depth),
            aa_theta: 0.0,
            lu: if use_sparse {
                DenseLu::with_ordering(Vec::new(), Vec::new())
            } else {
                stage_lu(n, m, s, sys.dependency_budget())
            },
            qk: vec![0.0; n],
            hvk: vec![0.0; n],
            qn: vec![0.0; (s + 1) * n],
            qj: vec![0.0; s * n],
            hvj: vec![0.0; s * n],
            gj: vec![0.0; s * n],
            hq: vec![DMatrix::zeros(nd, nd); s],
            hv: vec![DMatrix::zeros(nd, nd); s],
            hess_nz: vec![false; s],
            phiq: if use_sparse {
                Vec::new()
            } else {
                vec![DMatrix::zeros(m, n); s + 1]
            },
            grads: if let Some(sp) = &sparse {
                vec![vec![0.0; sp.rows.n_values()]; s + 1]
            } else {
                Vec::new()
            },
            sparse,
            hc: DMatrix::zeros(nd, nd),
            wgrad: vec![0.0; s * n],
            wh: DMatrix::zeros(nd, nd),
            pre,
            tn: std::array::from_fn(|_| vec![0.0; n]),
            proj: {
                let mut c = DenseCholesky::new(md);
                c.set_max_dependent(sys.dependency_budget());
                c
            },
            vm: vec![0.0; n],
            mu: vec![0.0; m],
            acc: if use_sparse {
                None
            } else {
                Some(AccelerationSolver::new(sys))
            },
            acc_a: vec![0.0; n],
            acc_l: vec![0.0; m],
            hist_valid: false,
            hist_t: f64::NAN,
            hist_h: f64::NAN,
            hist_q: vec![0.0; n],
            hist_multi: vec![0.0; (MAX_PREDICTOR_ORDER + 1) * dim],
            hist_len: 0,
            end_phiq_valid: false,
            gk: 0.0,
            has_forces: sys.has_force_elements(),
            jac_valid: false,
            jac_h: f64::NAN,
            jac_gk: f64::NAN,
            jacobians: 0,
            w_skip: false,
            w_skip_left: 0,
            w_skip_scale: f64::NAN,
        })
    }

    /// The options.
    pub fn options(&self) -> &SymplecticOptions {
        &self.opts
    }

    /// The control-point abscissae `tau_0 = 0 < ... < tau_s = 1`.
    pub fn control_points(&self) -> &[f64] {
        &self.tab.tau
    }

    /// The Gauss-Legendre nodes and weights on `[0, 1]`.
    pub fn quadrature(&self) -> (&[f64], &[f64]) {
        (&self.tab.c, &self.tab.b)
    }

    /// Positions of the control points of the last step (`(s + 1) n` values, `Q_0` first).
    pub fn last_control_points(&self) -> &[f64] {
        &self.qn
    }

    /// The effective preadjustment factor `gamma kappa_s h^(2s)` of the last step.
    pub fn preadjustment_factor(&self) -> f64 {
        self.gk
    }

    /// Number of Jacobian evaluations (and LU factorisations) since the integrator was built.
    pub fn jacobian_count(&self) -> usize {
        self.jacobians
    }

    /// Whether the stage equations are solved by the sparse path (see
    /// [`SymplecticOptions::linear_solver`]).
    pub fn is_sparse(&self) -> bool {
        self.sparse.is_some()
    }

    /// Stored entries of the sparse stage Jacobian and of its LU factors (0, 0 on the dense
    /// path; the factors' count after the first factorisation).
    pub fn sparse_nnz(&self) -> (usize, usize) {
        self.sparse
            .as_ref()
            .map_or((0, 0), |sp| (sp.lu.nnz(), sp.lu.factor_nnz()))
    }

    /// `Phi_q` at the start of a step, `q_k` at time `t` (or copied from the end of the last
    /// step).
    fn start_phiq(&mut self, sys: &System, t: f64, reuse: bool) {
        let s = self.tab.s;
        if let Some(sp) = self.sparse.as_deref_mut() {
            if reuse {
                let (first, rest) = self.grads.split_at_mut(1);
                first[0].copy_from_slice(&rest[s - 1]);
            } else {
                sp.gather(sys, &self.qk, t, &mut self.grads[0]);
            }
        } else if reuse {
            let (first, rest) = self.phiq.split_at_mut(1);
            first[0].copy_from(&rest[s - 1]);
        } else {
            sys.phi_q(&self.qk, t, &mut self.phiq[0]);
        }
    }

    /// Solves the factored stage Jacobian in place.
    fn solve_stage(&mut self, b: &mut [f64]) {
        match &mut self.sparse {
            // (where the last Jacobian took the projected block: its augmented matrix)
            Some(sp) => match sp.proj.as_deref_mut().filter(|p| p.is_active()) {
                Some(p) => p.solve_in_place(b),
                None => sp.lu.solve_in_place(b),
            },
            None => self.lu.solve_in_place(b),
        }
    }

    /// Residual of the stage equations at `self.x` into `self.r`.
    fn residual(&mut self, sys: &System, t: f64, h: f64) -> Result<(), SolveError> {
        self.kinematics(sys, t, h)?;
        self.momentum_rows(sys, t, h);
        self.constraint_rows(sys, t, h);
        Ok(())
    }

    /// The constraint rows of the residual, `Phi(Q_nu, t + tau_nu h)` (after `kinematics`).
    fn constraint_rows(&mut self, sys: &System, t: f64, h: f64) {
        let (n, m, s) = (self.n, self.m, self.tab.s);
        for nu in 1..=s {
            let o = s * n + (nu - 1) * m;
            sys.phi(
                &self.qn[nu * n..(nu + 1) * n],
                t + self.tab.tau[nu] * h,
                &mut self.r[o..o + m],
            );
        }
    }

    /// The control points `Q_nu = q_k + Z_nu` at `self.x`.
    fn place_control_points(&mut self) {
        let n = self.n;
        self.qn[..n].copy_from_slice(&self.qk);
        for (qn, z) in self.qn[n..].chunks_exact_mut(n).zip(self.x.chunks_exact(n)) {
            for ((q, &qk), &z) in qn.iter_mut().zip(&self.qk).zip(z) {
                *q = qk + z;
            }
        }
    }

    /// Control points, Gauss-point positions, displacements and forces at `self.x`, with the
    /// preadjustment terms.
    fn kinematics(&mut self, sys: &System, t: f64, h: f64) -> Result<(), SolveError> {
        self.kinematics_with(sys, t, h, true)
    }

    /// [`Galerkin::kinematics`]; with `fresh_preadjustment = false` the preadjustment terms
    /// (`grad W_s` at the Gauss points, the modified-Lagrangian terms) of the last evaluation
    /// are kept instead of evaluated (the Newton iteration's final constraint check).
    pub(super) fn kinematics_with(
        &mut self,
        sys: &System,
        t: f64,
        h: f64,
        fresh_preadjustment: bool,
    ) -> Result<(), SolveError> {
        let (n, s) = (self.n, self.tab.s);
        let s1 = s + 1;
        self.place_control_points();
        let tab = &self.tab;
        for j in 0..s {
            // Q(c_j) - q_k and h Q'(c_j): combinations of the displacements Z_nu
            let qj = &mut self.qj[j * n..(j + 1) * n];
            let hvj = &mut self.hvj[j * n..(j + 1) * n];
            qj.fill(0.0);
            hvj.fill(0.0);
            for nu in 1..=s {
                let (a, d) = (tab.a[j * s1 + nu], tab.d[j * s1 + nu]);
                let z = &self.x[(nu - 1) * n..nu * n];
                for ((q, hv), &z) in qj.iter_mut().zip(hvj.iter_mut()).zip(z) {
                    *q += a * z;
                    *hv += d * z;
                }
            }
            for (q, &qk) in qj.iter_mut().zip(&self.qk) {
                *q += qk;
            }
            let qj = &self.qj[j * n..(j + 1) * n];
            let gj = &mut self.gj[j * n..(j + 1) * n];
            sys.potential_gradient(qj, gj);
            if let Some(pre) = self.pre.get_mut(j) {
                let wg = &mut self.wgrad[j * n..(j + 1) * n];
                if fresh_preadjustment {
                    pre.set_time(t + tab.c[j] * h);
                    pre.gradient(sys, qj, wg).map_err(|e| with_time(e, t))?;
                }
                for i in 0..n {
                    gj[i] += self.gk * wg[i];
                }
            }
            if self.nonconservative {
                let [v, f, ..] = &mut self.tn;
                for i in 0..n {
                    v[i] = self.hvj[j * n + i] / h;
                }
                sys.nonconservative_forces(qj, v, t + tab.c[j] * h, f);
                for i in 0..n {
                    gj[i] -= f[i];
                }
            }
        }
        if fresh_preadjustment {
            self.modified_terms(sys, t, h)?;
        }
        Ok(())
    }

    /// `Phi_q` at the interior control points `Q_1 .. Q_(s-1)` at `self.x` (after
    /// `place_control_points`): what the end momentum needs when Newton's last update was
    /// applied without a new residual (`momentum_rows` evaluates them otherwise).
    pub(super) fn refresh_interior_phiq(&mut self, sys: &System, t: f64, h: f64) {
        let (n, s) = (self.n, self.tab.s);
        for nu in 1..s {
            let q = &self.qn[nu * n..(nu + 1) * n];
            if let Some(sp) = self.sparse.as_deref_mut() {
                sp.gather(sys, q, t + self.tab.tau[nu] * h, &mut self.grads[nu]);
            } else {
                sys.phi_q(q, t + self.tab.tau[nu] * h, &mut self.phiq[nu]);
            }
        }
    }

    /// The momentum rows of the residual (after `kinematics`).
    fn momentum_rows(&mut self, sys: &System, t: f64, h: f64) {
        let (n, m, s) = (self.n, self.m, self.tab.s);
        let tab = &self.tab;
        let h2 = h * h;
        if let Some(sp) = &mut self.sparse {
            for nu in 0..s {
                if nu >= 1 {
                    let tn = t + tab.tau[nu] * h;
                    sp.gather(sys, &self.qn[nu * n..(nu + 1) * n], tn, &mut self.grads[nu]);
                }
                let lam = &self.x[s * n + nu * m..s * n + (nu + 1) * m];
                sp.al.fill(0.0);
                add_transpose(&sp.rows, &self.grads[nu], lam, &mut sp.al);
                let (bd, ba) = (&tab.bd[nu * s..(nu + 1) * s], &tab.ba[nu * s..(nu + 1) * s]);
                for i in 0..n {
                    let mut ak = 0.0;
                    let mut ag = 0.0;
                    for j in 0..s {
                        ak += bd[j] * self.hvj[j * n + i];
                        ag += ba[j] * self.gj[j * n + i];
                    }
                    let mut res = self.unit[i] * ak - h2 * self.minv[i] * (ag + sp.al[i]);
                    if nu == 0 {
                        res += self.unit[i] * self.hvk[i];
                    }
                    self.r[nu * n + i] = res;
                }
            }
            self.add_modified_rows(h);
            return;
        }
        for nu in 0..s {
            if nu >= 1 {
                sys.phi_q(
                    &self.qn[nu * n..(nu + 1) * n],
                    t + tab.tau[nu] * h,
                    &mut self.phiq[nu],
                );
            }
            let g = self.phiq[nu].as_slice();
            let lam = &self.x[s * n + nu * m..s * n + (nu + 1) * m];
            let (bd, ba) = (&tab.bd[nu * s..(nu + 1) * s], &tab.ba[nu * s..(nu + 1) * s]);
            for i in 0..n {
                let mut ak = 0.0;
                let mut ag = 0.0;
                for j in 0..s {
                    ak += bd[j] * self.hvj[j * n + i];
                    ag += ba[j] * self.gj[j * n + i];
                }
                // (Phi_q^T lam)_i: column i of the column-major m x n Phi_q
                let al: f64 = g[i * m..(i + 1) * m]
                    .iter()
                    .zip(lam)
                    .map(|(a, b)| a * b)
                    .sum();
                let mut res = self.unit[i] * ak - h2 * self.minv[i] * (ag + al);
                if nu == 0 {
                    res += self.unit[i] * self.hvk[i];
                }
                self.r[nu * n + i] = res;
            }
        }
        self.add_modified_rows(h);
    }

    /// The modified-Lagrangian terms of the first momentum rows (nothing without the mode):
    /// `h M^-1 D_1 E_d`, with `D_1 E_d = h^3 (1/2 de/dq - 1/h de/dv)` at `(qbar, v)` for
    /// `s = 1` (`h^5` and `e4` for `s = 2`), `mlq`, `mlv` holding the scaled gradients.
    fn add_modified_rows(&mut self, h: f64) {
        if !self.ml.is_empty() {
            for i in 0..self.n {
                self.r[i] += h * self.minv[i] * (0.5 * h * self.mlq[i] - self.mlv[i]);
            }
        }
    }

    /// Jacobian of the stage equations at `self.x` (after `residual` at the same point),
    /// factored: dense or sparse assembly (`dense.rs`, `sparse.rs`).
    fn jacobian(&mut self, sys: &System, t: f64, h: f64) -> Result<(), SolveError> {
        if self.sparse.is_some() {
            self.jacobian_sparse(sys, t, h)
        } else {
            self.jacobian_dense(sys, t, h)
        }
    }

    /// What stage equation `row` is, for error messages: the momentum equation of a coordinate
    /// (`nu = 0..s-1`) or a constraint at a control point (`nu = 1..s`).
    fn equation_name(&self, sys: &System, row: usize) -> String {
        let (n, m, s) = (self.n, self.m, self.tab.s);
        if row < s * n {
            let names = sys.coordinate_names();
            let coord = names.get(row % n).map_or("?", |c| c.as_str());
            format!("momentum equation of {coord} at control point {}", row / n)
        } else {
            let r = row - s * n;
            format!(
                "constraint {} at control point {}",
                sys.equation_name(r % m.max(1)),
                r / m.max(1) + 1
            )
        }
    }

    /// What unknown `col` is, for error messages: a displacement `Z_nu` (`nu = 1..s`) or a
    /// multiplier `lt_nu` (`nu = 0..s-1`).
    fn unknown_name(&self, sys: &System, col: usize) -> String {
        let (n, m, s) = (self.n, self.m, self.tab.s);
        if col < s * n {
            let names = sys.coordinate_names();
            let coord = names.get(col % n).map_or("?", |c| c.as_str());
            format!("displacement of {coord} at control point {}", col / n + 1)
        } else {
            let r = col - s * n;
            format!(
                "multiplier of {} at control point {}",
                sys.equation_name(r % m.max(1)),
                r / m.max(1)
            )
        }
    }
}

pub(super) fn with_time(e: SolveError, t: f64) -> SolveError {
    match e {
        SolveError::Singular { what, detail, .. } => SolveError::Singular { t, what, detail },
        other => other,
    }
}
