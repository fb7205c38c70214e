//! The local chart of the constraint manifold at an accepted point (paper B's "local
//! parameterisation"), allocation-free after [`TangentChart::new`].

use crate::kernels::{all_finite, gemv_cols, with_len};
use mbd_model::{BodyAngles, System};
use mbd_solve::linalg::DenseLu;
use mbd_solve::SolveError;
use nalgebra::DMatrix;

/// Multiple of the rounding estimate `eps (1 + ||x||_inf + L max_i (1 + |theta_i|)(1 + |omega_i|))`
/// taken as the round-off floor of evaluating `f(x)` (`L` the length scale, `theta_i`,
/// `omega_i` the planar bodies' angles and rates): a chord iteration that stalls (no progress)
/// below `max(10 tol, ROUNDOFF_FACTOR` times that estimate) has converged as far as `f` can be
/// evaluated.
pub const ROUNDOFF_FACTOR: f64 = 8.0;

/// Largest ratio of the distance a chart map's iteration (chord or exact Newton) moved its
/// point to its first correction: a contracting iteration with factor `theta` moves at most
/// `1 / (1 - theta)` times its first correction (4: `theta <= 3/4`). Beyond it the iteration did
/// not contract, and its limit need not be the solution nearest to the predictor (near a
/// singular configuration: another branch), so the map counts as failed.
pub const TRAVEL_FACTOR: f64 = 4.0;
mod accel;
mod apply;
mod blocks;
use blocks::{factor_blocks, form_factors, form_q_blocks};
mod chord;
mod exact;
mod rank;
mod residual;
mod rows;
mod settings;
#[cfg(test)]
mod tests;

pub(crate) use chord::{fast_max, loop_head, travel_within, ChordLoop, RoundoffFloor};
pub use settings::{ChartFailure, MapStats, NewtonSettings};

/// A chart of the manifold `f(x, t) = (Phi(q, t), Phi_q v + Phi_t) = 0` at a centre
/// `x_c = (q_c, v_c)`:
///
/// ```text
/// x(xi, zeta) = x_c + U xi + Q1 zeta,   Df(x_c)^T = Q1 R  (thin QR),   [Q1 U] orthogonal,
/// ```
///
/// with `U` (`2n x 2(n-m)`) an orthonormal basis of `ker Df(x_c)` and `zeta` (= `R eta` of the
/// paper's `Df(x_c)^T eta`) from a chord Newton iteration on `f(x(xi, zeta), t) = 0`:
/// `x <- x - Q1 J^-1 f`. With `J = R^T = Df(x_c) Q1` this is the paper's
/// `eta <- eta - (Df Df^T)^-1 f` (since `Df Df^T = R^T R`), written without forming
/// `Df Df^T`; [`TangentChart::select_iteration_matrix`] offers a better `J` for points away from
/// the centre. With `R^T` an iteration costs one residual evaluation, one triangular solve and
/// one `2n x 2m` product; the other matrices use `Q1 R^-T`, formed once per chart when needed.
///
/// The QR factorisation uses the block structure `Df = [[Phi_q, 0], [X, Phi_q]]`
/// (`X = (Phi_q v)_q`): `Phi_q^T = Qa [Ra; 0]` (`Qa = [Qa1 Na]`), then
/// `B = [Na^T X^T; Ra] = Qb [Rb; 0]`, both `n x m` Householder QRs on preallocated buffers; with
/// `C = Qa1^T X^T` and the isometry `W y = (Na y[..n-m], Qa1 y[n-m..])`,
/// `R = [[Ra, C], [0, Rb]]`, `Q1 = [(Qa1, 0), W Qb1]` and `U = [W Qb2, (0, Na)]`, a thin QR of
/// `Df^T` with an orthonormal complement, without factoring the `2n x 2m` matrix
/// (`docs/tangent.md` section 2; faer's blocked QR is several times slower at these sizes).
/// Everything lives in buffers allocated by [`TangentChart::new`].
#[derive(Clone, Debug)]
pub struct TangentChart {
    n: usize,
    m: usize,
    /// `Phi_q(q_c)`.
    phi_q: DMatrix<f64>,
    /// `(Phi_q v_c)_q` at `q_c`.
    dphi: DMatrix<f64>,
    /// `R` (`2m x 2m`, upper triangular) of `Df(x_c)^T = Q1 R`, column-major with column
    /// stride `2n` (entries below the diagonal unused).
    a: Vec<f64>,
    /// Householder coefficients of the two small QR factorisations.
    tau: Vec<f64>,
    tau_b: Vec<f64>,
    /// `[Phi_q^T | X^T]` (`n x 2m`) overwritten by `[Ra; 0]` and `Qa^T X^T`.
    aq: Vec<f64>,
    /// `B = [D; Ra]` (`n x m`) overwritten by `[Rb; 0]`.
    bq: Vec<f64>,
    /// The full-length Householder vectors of the two QRs (`n x m` each, see
    /// [`qr_padded`]).
    va: Vec<f64>,
    vb: Vec<f64>,
    /// `1 / R_ii` (`2m`).
    rdinv: Vec<f64>,
    /// Whether `rinv` and `p0` belong to the current centre ([`TangentChart::form_p0`]).
    p0_ready: bool,
    /// The orthogonal factors `Qa` of `Phi_q^T` and `Qb` of `B` (`n x n`, column-major).
    qa: Vec<f64>,
    qb: Vec<f64>,
    /// `Q = [Q1 U]` (`2n x 2n`, column-major), formed from `Qa` and `Qb` only when needed
    /// ([`TangentChart::form_q`]; the hot products use the factors, see `apply.rs`), valid if
    /// `q_ready`.
    q: Vec<f64>,
    q_ready: bool,
    /// Work space of the factored products (`4n`).
    nbuf: Vec<f64>,
    /// The centre in the chart's coordinates `(q_c, tau v_c)` (see
    /// [`TangentChart::set_velocity_weight`]), and as given, `(q_c, v_c)`.
    xc: Vec<f64>,
    xc_user: Vec<f64>,
    /// The velocity weight `tau` of the current centre, `1 / tau`, and the weight the next
    /// centre takes.
    vs: f64,
    vinv: f64,
    vs_next: f64,
    /// Work vectors: the velocities `v = tau v / tau` of a residual evaluation (`n`) and a
    /// weighted copy of a vector to split (`2n`).
    vbuf: Vec<f64>,
    sbuf: Vec<f64>,
    /// Whether the constraints are scleronomic (`Phi_t = 0`): then `Phi_q v` is linear in `v`
    /// and the weighted velocity rows are evaluated at `(q, tau v)` directly.
    scleronomic: bool,
    /// Time of the centre.
    tc: f64,
    /// Residual buffer `f` (`2m`).
    f: Vec<f64>,
    /// `Phi_q` and `(Phi_q v)_q` at the secondary point `x_e`.
    pq_e: DMatrix<f64>,
    dphi_e: DMatrix<f64>,
    /// `E = (Df(x_e) - Df(x_c)) Q1` (`2m x 2m`, column-major), valid if `has_e`.
    e: Vec<f64>,
    has_e: bool,
    /// `R^-1` (`2m x 2m`, column-major, upper triangular).
    rinv: Vec<f64>,
    /// `P0 = Q1 R^-T` (`2n x 2m`, column-major).
    p0: Vec<f64>,
    /// `x - x_c` (`2n`), work vector.
    dx: Vec<f64>,
    /// `K = E R^-T` (`2m x 2m`, column-major): `J_s = (I + s K) R^T`.
    k: Vec<f64>,
    /// Work vectors of the iteration (`2m`).
    u: Vec<f64>,
    w: Vec<f64>,
    /// Whether the chord iteration updates its matrix by good Broyden rank-one updates
    /// ([`TangentChart::set_broyden`]).
    broyden: bool,
    /// The Broyden-updated correction matrix `Q1 H` (`2n x 2m`, column-major; `H` the
    /// approximation of `(Df(x) Q1)^-1`), valid if `pb_active`; else the matrix is `P0`.
    pb: Vec<f64>,
    pb_active: bool,
    /// The last correction step `x_(k+1) - x_k` and the next one's direction `Q1 H f` (`2n`).
    step: Vec<f64>,
    wx: Vec<f64>,
    /// The residual before the last correction (`2m`).
    fprev: Vec<f64>,
    /// Broyden updates applied and resets to `P0` since the chart was created.
    broyden_updates: usize,
    broyden_resets: usize,
    /// The interpolation parameter of the active iteration matrix (0: the centre's).
    s: f64,
    /// `sin`/`cos` of the body angles of the last residual evaluation of a map.
    angles: BodyAngles,
    /// The starting point of the map in progress (`2n`), for the exact Newton fallback.
    x0: Vec<f64>,
    /// `||x_1 - x_0||_inf`: the first correction of the iteration in progress (chord or exact
    /// Newton), the bound on its travel ([`TRAVEL_FACTOR`]).
    first_step: f64,
    /// `Phi_q` and `(Phi_q v)_q` at an iterate of the exact Newton fallback.
    pq_x: DMatrix<f64>,
    dphi_x: DMatrix<f64>,
    /// `Df(x) Q1` (`2m x 2m`, column-major), and the shared dense LU that factors it (pivot
    /// threshold `2m eps max |J|`: numerically singular only at round-off level).
    jn: Vec<f64>,
    jn_lu: DenseLu,
    /// Maps completed by the exact Newton fallback since the chart was created.
    exact_maps: usize,
    /// `min |R_ii| / max |R_ii|` at the last centre.
    rcond: f64,
    /// Work space of the rank report: `Phi_q^T` (`n x m`) and its pivoted QR, the column
    /// permutation, the column norms and a Householder vector.
    rr: Vec<f64>,
    /// Square roots of [`System::rank_weights`]: the rank report's column weights.
    rank_w: Vec<f64>,
    /// The round-off floor below which a stalled map has converged.
    roundoff: RoundoffFloor,
    perm: Vec<usize>,
    norms: Vec<f64>,
    hv: Vec<f64>,
    /// Relative threshold on the diagonal of `R` below which `Df(x_c)` counts as rank deficient.
    pub singular_tol: f64,
    /// Work space of the accelerations at the centre ([`TangentChart::centre_accelerations`]).
    centre_acc: accel::CentreAccel,
    centred: bool,
    /// The constraint rows the chart works with (all of them without redundant equations).
    sel: rows::RowSelection,
    /// The largest contraction factor the chord iteration showed since the last centre, and at
    /// the chart before it (0: none seen).
    theta_seen: f64,
    theta_seen_prev: f64,
    /// The estimate the stage maps stop on after their first correction (infinite: off;
    /// [`TangentChart::set_contraction_prior`]).
    theta_prior: f64,
    /// `eps (1 + ||x_c||_inf)`: the rounding floor of the residual near the centre, below which
    /// an observed contraction is chance.
    floor: f64,
}

impl TangentChart {
    /// A chart workspace for `sys` (allocates once).
    pub fn new(sys: &System) -> Self {
        // a model with k redundant equations: m - k independent rows, chosen at each centre
        Self::with_dims(sys, sys.n_coords(), sys.n_constraints() - sys.n_redundant())
    }

    fn with_dims(sys: &System, n: usize, m: usize) -> Self {
        let (nn, mm) = (2 * n, 2 * m);
        let mut q = vec![0.0; nn * nn];
        for i in 0..nn {
            q[i * nn + i] = 1.0;
        }
        // Qa = Qb = I until the first centre with constraints (without any, Q = I)
        let mut qa = vec![0.0; n * n];
        for i in 0..n {
            qa[i * n + i] = 1.0;
        }
        TangentChart {
            centre_acc: accel::CentreAccel::new(n, m),
            n,
            m,
            phi_q: DMatrix::zeros(m, n),
            dphi: DMatrix::zeros(m, n),
            a: vec![0.0; nn * mm],
            tau: vec![0.0; m],
            tau_b: vec![0.0; m],
            aq: vec![0.0; 2 * n * m],
            va: vec![0.0; n * m],
            vb: vec![0.0; n * m],
            rdinv: vec![0.0; mm],
            p0_ready: false,
            bq: vec![0.0; n * m],
            qb: qa.clone(),
            qa,
            q,
            q_ready: false,
            nbuf: vec![0.0; 4 * n],
            xc: vec![0.0; nn],
            xc_user: vec![0.0; nn],
            vs: 1.0,
            vinv: 1.0,
            vs_next: 1.0,
            vbuf: vec![0.0; n],
            sbuf: vec![0.0; nn],
            scleronomic: !sys.is_rheonomic(),
            tc: 0.0,
            f: vec![0.0; mm],
            pq_e: DMatrix::zeros(m, n),
            dphi_e: DMatrix::zeros(m, n),
            e: vec![0.0; mm * mm],
            has_e: false,
            angles: BodyAngles::sized(sys),
            rinv: vec![0.0; mm * mm],
            p0: vec![0.0; nn * mm],
            dx: vec![0.0; nn],
            k: vec![0.0; mm * mm],
            u: vec![0.0; mm],
            w: vec![0.0; mm],
            broyden: false,
            pb: vec![0.0; nn * mm],
            pb_active: false,
            step: vec![0.0; nn],
            wx: vec![0.0; nn],
            fprev: vec![0.0; mm],
            broyden_updates: 0,
            broyden_resets: 0,
            s: 0.0,
            x0: vec![0.0; nn],
            first_step: 0.0,
            pq_x: DMatrix::zeros(m, n),
            dphi_x: DMatrix::zeros(m, n),
            jn: vec![0.0; mm * mm],
            jn_lu: {
                let mut lu = DenseLu::new(mm);
                lu.pivot_tol = f64::EPSILON;
                lu
            },
            exact_maps: 0,
            rcond: 1.0,
            rr: vec![0.0; n * m],
            rank_w: sys.rank_weights().iter().map(|w| w.sqrt()).collect(),
            roundoff: RoundoffFloor::new(sys),
            perm: vec![0; m],
            norms: vec![0.0; m],
            hv: vec![0.0; n],
            singular_tol: 1e-8,
            centred: false,
            sel: rows::RowSelection::new(sys),
            theta_seen: 0.0,
            theta_seen_prev: 0.0,
            theta_prior: f64::INFINITY,
            floor: 0.0,
        }
    }

    /// Dimension of the chart, `2 (n - m)`: twice the degrees of freedom.
    pub fn dim(&self) -> usize {
        2 * (self.n - self.m)
    }

    /// Dimension of the ambient space, `2n`.
    #[cfg(test)]
    pub fn ambient_dim(&self) -> usize {
        2 * self.n
    }

    /// Number of constraint equations of `f`, `2m`.
    #[cfg(test)]
    pub fn codim(&self) -> usize {
        2 * self.m
    }

    /// The centre `x_c = (q_c, v_c)` (length `2n`).
    pub fn centre_point(&self) -> &[f64] {
        &self.xc_user
    }

    /// Sets the weight `tau > 0` of the velocities in the chart's metric from the next
    /// [`TangentChart::centre`] on: the chart is built in the coordinates `(q, tau v)`, so its
    /// tangent and normal directions are orthogonal in `|dq|^2 + tau^2 |dv|^2`. `tau = 1` is
    /// the Euclidean metric of `(q, v)` in the model's units (paper B); a step-sized `tau`
    /// measures a velocity change by the displacement it makes over a step (docs/tangent.md,
    /// "The chart's metric"). Every input and output of the chart stays in `(q, v)`. A
    /// non-finite or non-positive `tau` is ignored.
    pub fn set_velocity_weight(&mut self, tau: f64) {
        if tau.is_finite() && tau > 0.0 {
            self.vs_next = tau;
        }
    }

    #[cfg(test)]
    fn col(&self, k: usize) -> &[f64] {
        let nn = 2 * self.n;
        &self.q[k * nn..(k + 1) * nn]
    }

    /// Column `k` of the tangent basis `U` (`k < dim()`), a unit vector of length `2n` (after
    /// [`TangentChart::form_q`]).
    #[cfg(test)]
    pub fn tangent(&self, k: usize) -> &[f64] {
        debug_assert!(self.q_ready, "form_q first");
        self.col(2 * self.m + k)
    }

    /// Column `k` of the normal basis `Q1` (`k < 2m`): an orthonormal basis of the range of
    /// `Df(x_c)^T` (after [`TangentChart::form_q`]).
    #[cfg(test)]
    pub fn normal(&self, k: usize) -> &[f64] {
        debug_assert!(self.q_ready, "form_q first");
        self.col(k)
    }

    /// Entry `(i, j)` of the triangular factor `R` (`2m x 2m`) of `Df(x_c)^T = Q1 R`.
    #[cfg(test)]
    pub fn r(&self, i: usize, j: usize) -> f64 {
        if i > j {
            0.0
        } else {
            self.a[j * 2 * self.n + i]
        }
    }

    /// `Df(x_c) = [[Phi_q, 0], [(Phi_q v)_q, Phi_q]]` as a dense `2m x 2n` matrix (allocates; for
    /// tests and diagnostics).
    #[cfg(test)]
    pub fn jacobian(&self) -> DMatrix<f64> {
        let (n, m) = (self.n, self.m);
        let mut d = DMatrix::zeros(2 * m, 2 * n);
        for r in 0..m {
            for c in 0..n {
                d[(r, c)] = self.phi_q[(r, c)];
                d[(m + r, c)] = self.dphi[(r, c)];
                d[(m + r, n + c)] = self.phi_q[(r, c)];
            }
        }
        d
    }

    /// Centres the chart at `(q, v)` at time `t`: evaluates `Df`, factors `Df^T = Q1 R` and forms
    /// `Q = [Q1 U]` from the QRs of `Phi_q^T` and of the `n x m` block `[Na^T X^T; Ra]` (see the
    /// type's documentation). A rank-deficient `Df` (redundant constraints or a singular configuration) is
    /// [`SolveError::Singular`] naming the first dependent equation. Resets the iteration
    /// matrix to the centre's.
    pub fn centre(&mut self, sys: &System, q: &[f64], v: &[f64], t: f64) -> Result<(), SolveError> {
        let (n, m) = (self.n, self.m);
        let (nn, mm) = (2 * n, 2 * m);
        self.centred = false;
        self.q_ready = false;
        self.has_e = false;
        self.s = 0.0;
        self.pb_active = false;
        self.theta_seen_prev = self.theta_seen;
        self.theta_seen = 0.0;
        self.theta_prior = f64::INFINITY;
        if q.len() != n || v.len() != n {
            return Err(SolveError::Dimension {
                what: "chart centre (q, v)",
                expected: n,
                got: if q.len() != n { q.len() } else { v.len() },
            });
        }
        self.vs = self.vs_next;
        self.vinv = 1.0 / self.vs;
        self.xc_user[..n].copy_from_slice(q);
        self.xc_user[n..].copy_from_slice(v);
        self.xc[..n].copy_from_slice(q);
        for (c, &vi) in self.xc[n..].iter_mut().zip(v) {
            *c = self.vs * vi;
        }
        self.floor = f64::EPSILON
            * (1.0
                + self
                    .xc_user
                    .iter()
                    .fold(0.0f64, |m, v| fast_max(m, v.abs())));
        self.tc = t;
        self.rcond = 1.0;
        if m == 0 {
            self.centred = true;
            return Ok(());
        }
        // (the end-point map's verified residual was evaluated at q: the rotation is empty)
        self.angles.update_near(sys, q);
        let selected = self.sel.jacobian(
            sys,
            q,
            Some(&self.angles),
            v,
            t,
            &mut self.phi_q,
            &mut self.dphi,
            true,
        );
        if !all_finite(self.phi_q.as_slice()) || !all_finite(self.dphi.as_slice()) {
            return Err(SolveError::NonFinite {
                t,
                what: "constraint Jacobian at the chart centre",
            });
        }
        if !selected {
            // the model's redundant equations are not the only dependent ones here
            let tol = self.singular_tol.max(1e-6);
            return Err(self
                .singular_error(sys, t, tol)
                .unwrap_or(SolveError::Singular {
                    t,
                    what: "constraint Jacobian Df of the tangent chart",
                    detail: "the rows dependent at this centre are not the model's redundant \
                         equations alone"
                        .into(),
                }));
        }
        if m > n {
            // more constraint equations than coordinates: necessarily dependent
            return Err(SolveError::Singular {
                t,
                what: "constraint Jacobian Df of the tangent chart",
                detail: format!("position constraint {}", sys.equation_name(n)),
            });
        }
        // 1. and 2.: the two QRs (see `factor_blocks`)
        with_len!(n, factor_blocks(self));
        // (a NaN diagonal entry is caught by the loop below)
        let (mut dmax, mut dmin) = (0.0f64, f64::INFINITY);
        for i in 0..mm {
            let d = self.a[i * nn + i].abs();
            dmax = if d > dmax { d } else { dmax };
            dmin = if d < dmin { d } else { dmin };
        }
        self.rcond = dmin / dmax;
        for i in 0..mm {
            let rii = self.a[i * nn + i].abs();
            if rii.is_nan() || rii <= self.singular_tol * dmax {
                let tol = self.singular_tol;
                return Err(self.singular_error(sys, t, tol).unwrap_or_else(|| {
                    let detail = if i < m {
                        format!(
                            "position constraint {}",
                            sys.equation_name(self.sel.full_row(i))
                        )
                    } else {
                        format!(
                            "velocity constraint {}",
                            sys.equation_name(self.sel.full_row(i - m))
                        )
                    };
                    SolveError::Singular {
                        t,
                        what: "constraint Jacobian Df of the tangent chart",
                        detail,
                    }
                }));
            }
            self.rdinv[i] = 1.0 / self.a[i * nn + i];
        }
        // 3.: Qa and Qb (Q itself only on demand, `form_q`)
        with_len!(n, form_factors(self));
        // P0 = Q1 R^-T only for the Broyden and interpolated matrices (the plain chord solves
        // with R^T per iteration)
        self.p0_ready = false;
        if self.broyden {
            self.form_p0();
        }
        self.centred = true;
        Ok(())
    }

    /// Forms the explicit `Q = [Q1 U]` of the current centre from its factors `Qa` and `Qb`
    /// (once per centre; for the interpolated and Broyden matrices, the exact Newton fallback
    /// and the column accessors).
    pub(crate) fn form_q(&mut self) {
        if !self.q_ready {
            with_len!(self.n, form_q_blocks(self));
            self.q_ready = true;
        }
    }

    /// Forms `R^-1` and `P0 = Q1 R^-T` (the correction matrix of the Broyden and interpolated
    /// iterations) for the current centre, once.
    pub(crate) fn form_p0(&mut self) {
        if self.p0_ready {
            return;
        }
        self.form_q();
        let (nn, mm) = (2 * self.n, 2 * self.m);
        // R^-1 by back substitution, column by column (diagonal first: 1 / R_ii)
        self.rinv.fill(0.0);
        for i in 0..mm {
            self.rinv[i * mm + i] = self.rdinv[i];
        }
        for j in 0..mm {
            for i in (0..j).rev() {
                let mut acc = 0.0;
                for k in i + 1..=j {
                    acc -= self.a[k * nn + i] * self.rinv[j * mm + k];
                }
                self.rinv[j * mm + i] = acc * self.rinv[i * mm + i];
            }
        }
        // P0 = Q1 R^-T: column k = sum_{j >= k} (R^-1)_{kj} Q1_j
        self.p0.fill(0.0);
        for k in 0..mm {
            for j in k..mm {
                self.u[j] = self.rinv[j * mm + k];
            }
            let col = &mut self.p0[k * nn..(k + 1) * nn];
            gemv_cols(&self.q[k * nn..mm * nn], &self.u[k..mm], col);
        }
        self.p0_ready = true;
    }

    /// `min_i |R_ii| / max_i |R_ii|` of the last [`TangentChart::centre`] (1 without
    /// constraints): a cheap estimate of the reciprocal condition number of `Df(x_c)`, small near
    /// a singular configuration (the centre is an error below `singular_tol`).
    pub fn rcond(&self) -> f64 {
        self.rcond
    }

    /// The chart's angle table, holding the angles of its last residual evaluation: for the
    /// index-1 solve at a point the chart has just mapped, whose angles moved by the last
    /// correction only (the solve rotates it there, [`mbd_model::BodyAngles::update_near`]).
    pub(crate) fn angles_mut(&mut self) -> &mut mbd_model::BodyAngles {
        &mut self.angles
    }

    /// Writes `x = x_c + U xi + Q1 zeta` into `x` (no Newton) in the chart's coordinates
    /// `(q, tau v)`.
    fn point_weighted(&mut self, xi: &[f64], zeta: &[f64], x: &mut [f64]) {
        x.copy_from_slice(&self.xc);
        self.add_q(zeta, xi, x);
    }

    /// Maps chart coordinates `xi` (length [`TangentChart::dim`]) to the point `x` (length
    /// `2n`) of the manifold at time `t`: `x = x_c + U xi + Q1 zeta` with `zeta` from chord
    /// Newton started at the value passed in (the caller's predictor; 0 is valid) and left at
    /// the converged value. Fails with a [`ChartFailure`] if the iteration diverges, produces
    /// non-finite values or reaches the iteration limit.
    pub fn map(
        &mut self,
        sys: &System,
        xi: &[f64],
        t: f64,
        zeta: &mut [f64],
        x: &mut [f64],
        newton: &NewtonSettings,
    ) -> Result<MapStats, ChartFailure> {
        self.point_weighted(xi, zeta, x);
        let out = self.run_chord(sys, t, zeta, x, newton, false);
        self.unweight(x);
        out
    }

    /// [`TangentChart::map`] for a Runge-Kutta stage point, whose constraint residual only
    /// needs to be small, not verified: the iteration may also stop on the predicted residual.
    /// After an iteration `k >= 1` with observed contraction `theta = ||f_k|| / ||f_(k-1)||
    /// <= 1/2`, the chord correction computed from `f_k` is applied without evaluating `f` again
    /// when `theta ||f_k||_inf <= tol`: the chord iteration contracts linearly with a rate that
    /// does not grow from one iteration to the next (the quadratic part of the error only
    /// shrinks), so the point it returns has a residual of about `theta ||f_k|| <= tol`, and
    /// [`MapStats::residual`] reports that estimate. This saves the last residual evaluation of
    /// a map; the step's end point is always mapped with [`TangentChart::map`], which verifies
    /// the residual.
    pub fn map_predicted(
        &mut self,
        sys: &System,
        xi: &[f64],
        t: f64,
        zeta: &mut [f64],
        x: &mut [f64],
        newton: &NewtonSettings,
    ) -> Result<MapStats, ChartFailure> {
        self.point_weighted(xi, zeta, x);
        let out = self.run_chord(sys, t, zeta, x, newton, true);
        self.unweight(x);
        out
    }

    /// The normal coordinates `zeta` (in the basis `Q1`) as coordinates in the chart's
    /// canonical normal basis: `Q1` with each column's sign chosen so that the diagonal of `R`
    /// is positive. `Df(x_c)^T = Q1 R` with a positive diagonal is the unique thin QR, a smooth
    /// function of the centre where `Df` has full rank, so these coordinates vary smoothly from
    /// one chart to the next along a trajectory, whatever signs the Householder reflectors
    /// chose. Unlike the paper's coefficients `eta = R^-1 zeta` of `Df^T eta`, they measure the
    /// normal offset itself (`|canonical| = |Q1 zeta|`): extrapolating them loses nothing to the
    /// conditioning of `R` (badly balanced units, such as a model in millimetres with unitless
    /// directors, make `R` ill-conditioned and `eta` the small difference of large terms).
    pub(crate) fn canonical_from_zeta(&self, zeta: &[f64], out: &mut [f64]) {
        for ((o, z), d) in out.iter_mut().zip(zeta).zip(&self.rdinv) {
            *o = if *d < 0.0 { -z } else { *z };
        }
    }

    /// The inverse of [`TangentChart::canonical_from_zeta`] (the same sign flips).
    pub(crate) fn zeta_from_canonical(&self, canonical: &[f64], zeta: &mut [f64]) {
        self.canonical_from_zeta(canonical, zeta);
    }
}
