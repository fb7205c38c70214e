//! The local chart of the constraint manifold at an accepted point (paper B's "local
//! parameterisation"), allocation-free after [`TangentChart::new`].

use crate::kernels::{axpy, dot, form_q, gemv_cols, gemv_t_cols, householder_qr, rank_one_update};
use mbd_model::numeric::{max_abs, max_abs_diff};
use mbd_model::{AngleCache, System};
use mbd_solve::linalg::DenseLu;
use mbd_solve::SolveError;
use nalgebra::DMatrix;

/// Multiple of `eps (1 + ||x||_inf)` taken as the round-off floor of evaluating `f(x)`: a chord
/// iteration that stalls (no progress) below `max(10 tol, ROUNDOFF_FACTOR eps (1 + ||x||_inf))`
/// has converged as far as `f` can be evaluated.
pub const ROUNDOFF_FACTOR: f64 = 8.0;

/// Largest ratio of the distance a chart map's iteration (chord or exact Newton) moved its
/// point to its first correction: a contracting iteration with factor `theta` moves at most
/// `1 / (1 - theta)` times its first correction (4: `theta <= 3/4`). Beyond it the iteration did
/// not contract, and its limit need not be the solution nearest to the predictor (near a
/// singular configuration: another branch), so the map counts as failed.
pub const TRAVEL_FACTOR: f64 = 4.0;

/// Settings of the chord Newton iteration that maps chart coordinates to the manifold.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NewtonSettings {
    /// Converged when `||f(x(xi), t)||_inf <= tol` (position and velocity constraints), or
    /// when the residual stalls at the round-off floor of evaluating `f`: an iteration that
    /// leaves it at 0.9 of the previous value or more, below
    /// `max(10 tol, ROUNDOFF_FACTOR eps (1 + ||x||_inf))` (fast motion, or angles wound up over
    /// long runs, raise the floor of `Phi_q v` and `sin theta`).
    pub tol: f64,
    /// Iteration limit; reaching it is a [`ChartFailure`].
    pub max_iter: usize,
    /// Divergence test: an iteration whose residual exceeds `divergence` times the previous one
    /// ends the iteration with a [`ChartFailure`] (the point has left the chart's domain).
    pub divergence: f64,
    /// Near-singular charts: a chord iteration that fails is retried by Newton's method with
    /// the exact matrix `Df(x) Q1` at every iterate (one `Df` and a `2m x 2m` LU per
    /// iteration) when `Df` at the starting point differs from `Df(x_c)` by at most
    /// `fallback_change` relative (`max |Df(x) - Df(x_c)| <= fallback_change max |Df(x_c)|`).
    /// Then the step is small for the geometry and the chord failed because `Df(x_c)` is
    /// nearly rank deficient (its smallest singular value is of the size of the change), as
    /// near a singular configuration: shorter steps would not help there. A larger change
    /// means the step is too large for the chart, which stays a [`ChartFailure`] (halving or
    /// rejection). Default 0.1; 0 turns the fallback off.
    pub fallback_change: f64,
}

impl Default for NewtonSettings {
    fn default() -> Self {
        NewtonSettings {
            tol: 1e-13,
            max_iter: 50,
            divergence: 2.0,
            fallback_change: 0.1,
        }
    }
}

impl NewtonSettings {
    /// Checks the settings: `tol` positive and finite, `max_iter >= 1`, `divergence >= 1`,
    /// `fallback_change` finite and non-negative.
    pub fn validate(&self) -> Result<(), SolveError> {
        if !(self.tol.is_finite() && self.tol > 0.0) {
            return Err(SolveError::InvalidParameter {
                parameter: "newton.tol",
                value: self.tol,
                reason: "must be positive and finite",
            });
        }
        if self.max_iter == 0 {
            return Err(SolveError::InvalidParameter {
                parameter: "newton.max_iter",
                value: 0.0,
                reason: "must be at least 1",
            });
        }
        if !(self.divergence.is_finite() && self.divergence >= 1.0) {
            return Err(SolveError::InvalidParameter {
                parameter: "newton.divergence",
                value: self.divergence,
                reason: "must be finite and at least 1",
            });
        }
        if !(self.fallback_change.is_finite() && self.fallback_change >= 0.0) {
            return Err(SolveError::InvalidParameter {
                parameter: "newton.fallback_change",
                value: self.fallback_change,
                reason: "must be finite and non-negative",
            });
        }
        Ok(())
    }
}

/// The chord Newton iteration of a chart map did not converge: the point `xi` lies outside the
/// chart's domain (step too large, or a singular configuration near).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ChartFailure {
    /// Time at which the map was evaluated.
    pub t: f64,
    /// `||f||_inf` when the iteration stopped (may be NaN or infinite).
    pub residual: f64,
    /// Iterations done.
    pub iterations: usize,
}

impl ChartFailure {
    /// The failure as a [`SolveError::Newton`] with context `"tangent chart"`.
    pub fn into_error(self) -> SolveError {
        SolveError::Newton {
            t: self.t,
            residual: self.residual,
            iterations: self.iterations,
            context: "tangent chart (chord Newton on f(x(xi)) = 0)".into(),
        }
    }
}

/// What a successful chart map did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MapStats {
    /// Chord Newton iterations.
    pub iterations: usize,
    /// Final `||f||_inf`; for a map that stopped on the predicted residual
    /// ([`TangentChart::map_predicted`]), that prediction.
    pub residual: f64,
    /// `||f||_inf` at the starting point, before the first iteration.
    pub initial_residual: f64,
    /// Whether the chord iteration failed and Newton's method with the exact matrix took over
    /// ([`NewtonSettings::fallback_change`]); `iterations` then counts both.
    pub exact: bool,
}

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
/// the centre. The correction matrices (`Q1 R^-T`, `2n x 2m`) are formed once per chart, so an
/// iteration costs one residual evaluation and one or two `2n x 2m` products.
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
    /// `Phi_q^T` (`n x m`) overwritten by its QR factors (`Ra` and reflectors).
    aq: Vec<f64>,
    /// `B = [D; Ra]` (`n x m`) overwritten by its QR factors (`Rb` and reflectors).
    bq: Vec<f64>,
    /// The orthogonal factors `Qa` of `Phi_q^T` and `Qb` of `B` (`n x n`, column-major).
    qa: Vec<f64>,
    qb: Vec<f64>,
    /// A row of `(Phi_q v)_q`, and `Qa^T` times it (`n`), work vectors.
    xt: Vec<f64>,
    g: Vec<f64>,
    /// `Q = [Q1 U]` (`2n x 2n`, column-major).
    q: Vec<f64>,
    /// The centre `(q_c, v_c)`.
    xc: Vec<f64>,
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
    angles: AngleCache,
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
    perm: Vec<usize>,
    norms: Vec<f64>,
    hv: Vec<f64>,
    /// Relative threshold on the diagonal of `R` below which `Df(x_c)` counts as rank deficient.
    pub singular_tol: f64,
    centred: bool,
}

impl TangentChart {
    /// A chart workspace for `sys` (allocates once).
    pub fn new(sys: &System) -> Self {
        let (n, m) = (sys.n_coords(), sys.n_constraints());
        let (nn, mm) = (2 * n, 2 * m);
        let mut q = vec![0.0; nn * nn];
        for i in 0..nn {
            q[i * nn + i] = 1.0;
        }
        TangentChart {
            n,
            m,
            phi_q: DMatrix::zeros(m, n),
            dphi: DMatrix::zeros(m, n),
            a: vec![0.0; nn * mm],
            tau: vec![0.0; m],
            aq: vec![0.0; n * m],
            bq: vec![0.0; n * m],
            qa: vec![0.0; n * n],
            qb: vec![0.0; n * n],
            xt: vec![0.0; n],
            g: vec![0.0; n],
            q,
            xc: vec![0.0; nn],
            tc: 0.0,
            f: vec![0.0; mm],
            pq_e: DMatrix::zeros(m, n),
            dphi_e: DMatrix::zeros(m, n),
            e: vec![0.0; mm * mm],
            has_e: false,
            angles: AngleCache::new(sys),
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
            perm: vec![0; m],
            norms: vec![0.0; m],
            hv: vec![0.0; n],
            singular_tol: 1e-8,
            centred: false,
        }
    }

    /// Dimension of the chart, `2 (n - m)`: twice the degrees of freedom.
    pub fn dim(&self) -> usize {
        2 * (self.n - self.m)
    }

    /// Dimension of the ambient space, `2n`.
    pub fn ambient_dim(&self) -> usize {
        2 * self.n
    }

    /// Number of constraint equations of `f`, `2m`.
    pub fn codim(&self) -> usize {
        2 * self.m
    }

    /// The centre `x_c = (q_c, v_c)` (length `2n`).
    pub fn centre_point(&self) -> &[f64] {
        &self.xc
    }

    /// Time at which the chart was centred.
    pub fn centre_time(&self) -> f64 {
        self.tc
    }

    #[inline]
    fn col(&self, k: usize) -> &[f64] {
        let nn = 2 * self.n;
        &self.q[k * nn..(k + 1) * nn]
    }

    /// Column `k` of the tangent basis `U` (`k < dim()`), a unit vector of length `2n`.
    pub fn tangent(&self, k: usize) -> &[f64] {
        self.col(2 * self.m + k)
    }

    /// Column `k` of the normal basis `Q1` (`k < 2m`): an orthonormal basis of the range of
    /// `Df(x_c)^T`.
    pub fn normal(&self, k: usize) -> &[f64] {
        self.col(k)
    }

    /// `Phi_q` at the centre (`m x n`), from the last [`TangentChart::centre`].
    pub fn centre_phi_q(&self) -> &DMatrix<f64> {
        &self.phi_q
    }

    /// `(Phi_q v)_q` at the centre (`m x n`), from the last [`TangentChart::centre`].
    pub fn centre_phi_q_dot_jacobian(&self) -> &DMatrix<f64> {
        &self.dphi
    }

    /// Entry `(i, j)` of the triangular factor `R` (`2m x 2m`) of `Df(x_c)^T = Q1 R`.
    pub fn r(&self, i: usize, j: usize) -> f64 {
        if i > j {
            0.0
        } else {
            self.a[j * 2 * self.n + i]
        }
    }

    /// `Df(x_c) = [[Phi_q, 0], [(Phi_q v)_q, Phi_q]]` as a dense `2m x 2n` matrix (allocates; for
    /// tests and diagnostics).
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
        self.has_e = false;
        self.s = 0.0;
        self.pb_active = false;
        if q.len() != n || v.len() != n {
            return Err(SolveError::Dimension {
                what: "chart centre (q, v)",
                expected: n,
                got: if q.len() != n { q.len() } else { v.len() },
            });
        }
        self.xc[..n].copy_from_slice(q);
        self.xc[n..].copy_from_slice(v);
        self.tc = t;
        self.rcond = 1.0;
        if m == 0 {
            self.centred = true;
            return Ok(());
        }
        sys.phi_q_dot_jacobian(q, v, &mut self.phi_q, &mut self.dphi);
        if self
            .phi_q
            .as_slice()
            .iter()
            .chain(self.dphi.as_slice())
            .any(|x| !x.is_finite())
        {
            return Err(SolveError::NonFinite {
                t,
                what: "constraint Jacobian at the chart centre",
            });
        }
        if m > n {
            // more constraint equations than coordinates: necessarily dependent
            return Err(SolveError::Singular {
                t,
                what: "constraint Jacobian Df of the tangent chart",
                detail: format!("position constraint {}", sys.equation_name(n)),
            });
        }
        let nm = n - m;
        // 1. Phi_q^T = Qa [Ra; 0] (n x m), Qa = [Qa1 Na] explicit (n x n)
        let pq = self.phi_q.as_slice(); // column-major m x n: (r, c) at c m + r
        for k in 0..m {
            for c in 0..n {
                self.aq[k * n + c] = pq[c * m + k];
            }
        }
        householder_qr(&mut self.aq, &mut self.tau, n, m, 0, n);
        form_q(&self.aq, &self.tau, n, m, 0, n, &mut self.qa);
        // 2. Qa^T X^T with X = (Phi_q v)_q: its first m rows are the block C of R, the other
        //    n - m rows (D = Na^T X^T) stacked on Ra form B = [D; Ra] (n x m)
        let xs = self.dphi.as_slice();
        for j in 0..m {
            for c in 0..n {
                self.xt[c] = xs[c * m + j];
            }
            gemv_t_cols(&self.qa, &self.xt, &mut self.g);
            self.a[(m + j) * nn..(m + j) * nn + m].copy_from_slice(&self.g[..m]);
            self.bq[j * n..j * n + nm].copy_from_slice(&self.g[m..]);
            for i in 0..m {
                self.bq[j * n + nm + i] = if i <= j { self.aq[j * n + i] } else { 0.0 };
                // R's leading block: Ra
                self.a[j * nn + i] = if i <= j { self.aq[j * n + i] } else { 0.0 };
            }
        }
        // 3. B = Qb [Rb; 0], Qb explicit (n x n)
        householder_qr(&mut self.bq, &mut self.tau, n, m, 0, n);
        for j in 0..m {
            for i in 0..=j {
                self.a[(m + j) * nn + m + i] = self.bq[j * n + i];
            }
        }
        let dmax = (0..mm).fold(0.0f64, |d, i| d.max(self.a[i * nn + i].abs()));
        let dmin = (0..mm).fold(f64::INFINITY, |d, i| d.min(self.a[i * nn + i].abs()));
        self.rcond = dmin / dmax;
        for i in 0..mm {
            let rii = self.a[i * nn + i].abs();
            if rii.is_nan() || rii <= self.singular_tol * dmax {
                let tol = self.singular_tol;
                return Err(self.singular_error(sys, t, tol).unwrap_or_else(|| {
                    let detail = if i < m {
                        format!("position constraint {}", sys.equation_name(i))
                    } else {
                        format!("velocity constraint {}", sys.equation_name(i - m))
                    };
                    SolveError::Singular {
                        t,
                        what: "constraint Jacobian Df of the tangent chart",
                        detail,
                    }
                }));
            }
        }
        form_q(&self.bq, &self.tau, n, m, 0, n, &mut self.qb);
        // 4. Q = [[Qa1, W Qb, 0], [0, ., Na]] with W y = (Na y[..n-m], Qa1 y[n-m..]): columns
        //    0..m = (Qa1, 0), m..m+n = W Qb (the last n - m of them tangent), m+n..2n = (0, Na)
        for k in 0..m {
            let col = &mut self.q[k * nn..(k + 1) * nn];
            col[..n].copy_from_slice(&self.qa[k * n..(k + 1) * n]);
            col[n..].fill(0.0);
        }
        for j in 0..n {
            let y = &self.qb[j * n..(j + 1) * n];
            let col = &mut self.q[(m + j) * nn..(m + j + 1) * nn];
            let (cq, cv) = col.split_at_mut(n);
            cq.fill(0.0);
            cv.fill(0.0);
            gemv_cols(&self.qa[m * n..], &y[..nm], cq);
            gemv_cols(&self.qa[..m * n], &y[nm..], cv);
        }
        for l in 0..nm {
            let col = &mut self.q[(m + n + l) * nn..(m + n + l + 1) * nn];
            col[..n].fill(0.0);
            col[n..].copy_from_slice(&self.qa[(m + l) * n..(m + l + 1) * n]);
        }
        // R^-1 by back substitution, column by column (diagonal first: 1 / R_ii)
        self.rinv.fill(0.0);
        for i in 0..mm {
            self.rinv[i * mm + i] = 1.0 / self.a[i * nn + i];
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
        self.centred = true;
        Ok(())
    }

    /// A singular configuration at the last centre: the numerical rank of `Phi_q(q_c)` (`m x n`)
    /// from a column-pivoted Householder QR of `Phi_q^T` (rank `r`: the pivots
    /// `|R_kk| > rel_tol |R_00|`), the dependent equations (the pivots after `r`) and the
    /// joints involved in the dependency (the rows with a weight above `1e-6` of the largest in
    /// a left null vector `z`, `Phi_q^T z ~ 0`, of each dependent equation:
    /// `z = P [R11^-1 R12 e_j; -e_j]`), as [`SolveError::Singular`]
    /// (`what` = `"configuration (rank-deficient constraint Jacobian Phi_q)"`, `detail` =
    /// `"rank r of m; dependent equations ...; joints ..."`). `None` if `Phi_q` has full
    /// rank at that threshold or was not evaluated. Allocates (an error path).
    pub fn singular_error(&mut self, sys: &System, t: f64, rel_tol: f64) -> Option<SolveError> {
        let (n, m) = (self.n, self.m);
        if m == 0 || m > n {
            return None;
        }
        self.pq_x.copy_from(&self.phi_q);
        self.rank_report(sys, t, rel_tol)
    }

    /// [`TangentChart::singular_error`] for `Phi_q` at the configuration `q` (length `n`; e.g.
    /// a stage point whose index-1 solve was singular). `None` if `Phi_q(q)` has full rank at
    /// `rel_tol` or `q` has the wrong length.
    pub fn singular_error_at(
        &mut self,
        sys: &System,
        q: &[f64],
        t: f64,
        rel_tol: f64,
    ) -> Option<SolveError> {
        let (n, m) = (self.n, self.m);
        if m == 0 || m > n || q.len() != n {
            return None;
        }
        sys.phi_q(q, &mut self.pq_x);
        self.rank_report(sys, t, rel_tol)
    }

    /// The rank report of `Phi_q` held in `pq_x`.
    fn rank_report(&mut self, sys: &System, t: f64, rel_tol: f64) -> Option<SolveError> {
        let (n, m) = (self.n, self.m);
        // Phi_q^T (n x m), column j = row j of Phi_q
        // (allocation-free unless rank deficient: the report's strings)
        let pq = self.pq_x.as_slice();
        let a = &mut self.rr;
        for j in 0..m {
            for c in 0..n {
                a[j * n + c] = pq[c * m + j];
            }
        }
        let perm = &mut self.perm;
        for (j, p) in perm.iter_mut().enumerate() {
            *p = j;
        }
        let norms = &mut self.norms;
        let v = &mut self.hv;
        let mut r00 = 0.0f64;
        let mut rank = m;
        for k in 0..m {
            // pivot: the remaining column of largest norm (recomputed: tiny matrices)
            for (j, nj) in norms.iter_mut().enumerate().skip(k) {
                *nj = dot(&a[j * n + k..(j + 1) * n], &a[j * n + k..(j + 1) * n]);
            }
            let p = (k..m).fold(k, |p, j| if norms[j] > norms[p] { j } else { p });
            if p != k {
                for c in 0..n {
                    a.swap(k * n + c, p * n + c);
                }
                perm.swap(k, p);
                norms.swap(k, p);
            }
            let col_norm = norms[k].sqrt();
            if k == 0 {
                r00 = col_norm;
            }
            if col_norm.is_nan() || col_norm <= rel_tol * r00 || k >= n {
                rank = k;
                break;
            }
            // Householder reflector on rows k..n of column k, applied to the columns after it
            let x0 = a[k * n + k];
            let beta = if x0 >= 0.0 { -col_norm } else { col_norm };
            let v = &mut v[..n - k];
            v.copy_from_slice(&a[k * n + k..(k + 1) * n]);
            v[0] -= beta;
            let vv = dot(v, v);
            if vv > 0.0 {
                for j in k + 1..m {
                    let cj = &mut a[j * n + k..(j + 1) * n];
                    let s = 2.0 * dot(v, cj) / vv;
                    axpy(-s, v, cj);
                }
            }
            a[k * n + k] = beta;
            for x in a[k * n + k + 1..(k + 1) * n].iter_mut() {
                *x = 0.0;
            }
        }
        if rank == m {
            return None;
        }
        let mut dependent = Vec::new();
        let mut joints: Vec<String> = Vec::new();
        for j in rank..m {
            // y = R11^-1 R12 e_j by back substitution (R11 = rank x rank upper triangle)
            let mut y: Vec<f64> = (0..rank).map(|i| a[j * n + i]).collect();
            for i in (0..rank).rev() {
                let mut acc = y[i];
                for k in i + 1..rank {
                    acc -= a[k * n + i] * y[k];
                }
                y[i] = acc / a[i * n + i];
            }
            let wmax = max_abs(&y).max(1.0);
            dependent.push(sys.equation_name(perm[j]));
            let mut rows: Vec<usize> = vec![perm[j]];
            rows.extend(
                (0..rank)
                    .filter(|&i| y[i].abs() > 1e-6 * wmax)
                    .map(|i| perm[i]),
            );
            rows.sort_unstable();
            for r in rows {
                if let Some(h) = sys.equation_joint(r) {
                    let name = sys.joints()[h.0].name.clone();
                    if !joints.contains(&name) {
                        joints.push(name);
                    }
                }
            }
        }
        Some(SolveError::Singular {
            t,
            what: "configuration (rank-deficient constraint Jacobian Phi_q)",
            detail: format!(
                "rank {rank} of {m}; dependent equations {}; joints {}",
                dependent.join(", "),
                joints.join(", ")
            ),
        })
    }

    /// `min_i |R_ii| / max_i |R_ii|` of the last [`TangentChart::centre`] (1 without
    /// constraints): a cheap estimate of the reciprocal condition number of `Df(x_c)`, small near
    /// a singular configuration (the centre is an error below `singular_tol`).
    pub fn rcond(&self) -> f64 {
        self.rcond
    }

    /// Whether [`TangentChart::centre`] succeeded since the last attempt.
    pub fn is_centred(&self) -> bool {
        self.centred
    }

    /// Evaluates `Df` at a second point `x_e` (typically the Euler prediction `x_c + h F(x_c)` of
    /// the step's end point) and stores `E = (Df(x_e) - Df(x_c)) Q1`, so that
    /// [`TangentChart::select_iteration_matrix`] can interpolate the Newton matrix along the
    /// step. A non-finite `Df(x_e)` leaves the chart with the centre matrix `R^T` only.
    pub fn set_secondary_point(&mut self, sys: &System, x_e: &[f64]) {
        let (n, m) = (self.n, self.m);
        let (nn, mm) = (2 * n, 2 * m);
        self.has_e = false;
        self.s = 0.0;
        if m == 0 || x_e.len() != nn || !self.centred {
            return;
        }
        sys.phi_q_dot_jacobian(&x_e[..n], &x_e[n..], &mut self.pq_e, &mut self.dphi_e);
        // Delta Df = [[dP, 0], [dX, dP]] with dP = Phi_q(e) - Phi_q(c), dX likewise
        self.pq_e -= &self.phi_q;
        self.dphi_e -= &self.dphi;
        // column k of E: (dP cq, dX cq + dP cv) for Q1_k = (cq, cv); dP, dX column-major m x n
        let (dp, dx) = (self.pq_e.as_slice(), self.dphi_e.as_slice());
        self.e.fill(0.0);
        for k in 0..mm {
            let col = &self.q[k * nn..(k + 1) * nn];
            let (cq, cv) = col.split_at(n);
            let (ep, ev) = self.e[k * mm..(k + 1) * mm].split_at_mut(m);
            gemv_cols(dp, cq, ep);
            gemv_cols(dx, cq, ev);
            gemv_cols(dp, cv, ev);
        }
        if !self.e.iter().all(|x| x.is_finite()) {
            return;
        }
        // K = E R^-T: column k = sum_{j >= k} (R^-1)_{kj} E_j
        self.k.fill(0.0);
        for k in 0..mm {
            for j in k..mm {
                self.u[j] = self.rinv[j * mm + k];
            }
            gemv_cols(
                &self.e[k * mm..],
                &self.u[k..mm],
                &mut self.k[k * mm..(k + 1) * mm],
            );
        }
        self.has_e = true;
    }

    /// Chooses the matrix `J` of the chord iteration for the next maps: `R^T = Df(x_c) Q1` if
    /// `s` is 0 or no secondary point is set, else `J_s = R^T + s E`, the linear interpolation of
    /// `Df Q1` between the centre (`s = 0`) and the secondary point (`s = 1`); for a stage at
    /// `t_c + c h` pass `s = c`. With `K = E R^-T`, `J_s = (I + s K) R^T`, and the iteration
    /// applies `J_s^-1 = R^-T (I + s K)^-1` through the expansion
    /// `(I + s K)^-1 ~ I - s K + s^2 K^2` (`|s K| = O(h)`, so the neglected `O(h^3)` is below the
    /// `O(h^2)` interpolation error): `x <- x - P0 (f - s K f + s^2 K K f)` with `P0 = Q1 R^-T`
    /// formed once per chart and `K` once per step. Whatever the matrix, the iteration converges
    /// to the same point of the chart: the matrix only sets its speed.
    pub fn select_iteration_matrix(&mut self, s: f64) {
        self.s = if self.has_e && s.is_finite() { s } else { 0.0 };
    }

    /// Turns the quasi-Newton (good Broyden) chord iteration on or off (off by default). On,
    /// the iteration keeps an approximation `H` of `(Df(x) Q1)^-1`, starts each chart from the
    /// centre's `R^-T`, and after each correction `s = x_(k+1) - x_k` with residual change
    /// `y = f_(k+1) - f_k` applies the Sherman-Morrison rank-one update
    /// `H <- H + (s - H y) s^T H / (s^T H y)` (in the ambient space: on `P = Q1 H`, `O(n m)` per
    /// iteration). The updated matrix carries over from one map to the next until the chart is
    /// re-centred: the stage points of a step are close, so later maps start with a matrix that
    /// has already learnt how `Df` changed along the step. An update whose denominator is small
    /// (`|s^T H y| <= 0.1 |s|^2`) is skipped; an iteration that does not reduce the residual
    /// with an updated matrix is undone and restarted from `R^-T`. Only the speed changes: the
    /// limit is the same chart point. Ignored while an interpolated matrix
    /// ([`TangentChart::select_iteration_matrix`] with `s != 0`) is selected.
    pub fn set_broyden(&mut self, on: bool) {
        self.broyden = on;
        self.pb_active = false;
    }

    /// Whether the Broyden iteration is on ([`TangentChart::set_broyden`]).
    pub fn broyden(&self) -> bool {
        self.broyden
    }

    /// Broyden updates applied, and resets of the updated matrix to the centre's `R^-T` after
    /// an iteration without progress, since the chart was created (diagnostics).
    pub fn broyden_counts(&self) -> (usize, usize) {
        (self.broyden_updates, self.broyden_resets)
    }

    /// `f(x, t) = (Phi(q, t), Phi_q v + Phi_t)` into `out` (length `2m`); returns its max-norm
    /// (NaN if any entry is not finite).
    pub fn residual(&self, sys: &System, x: &[f64], t: f64, out: &mut [f64]) -> f64 {
        let (n, m) = (self.n, self.m);
        let (q, v) = x.split_at(n);
        let (p, pd) = out[..2 * m].split_at_mut(m);
        sys.phi_and_phi_dot(q, v, t, p, pd);
        let mut r = 0.0f64;
        for &e in out[..2 * m].iter() {
            if !e.is_finite() {
                return f64::NAN;
            }
            r = r.max(e.abs());
        }
        r
    }

    /// [`TangentChart::residual`] with the bodies' `sin`/`cos` rotated from the previous
    /// evaluation ([`AngleCache`]: a few ulps from the exact values; the chord's iterates move
    /// by small angles).
    fn residual_cached(&mut self, sys: &System, x: &[f64], t: f64, out: &mut [f64]) -> f64 {
        let (n, m) = (self.n, self.m);
        let (q, v) = x.split_at(n);
        let (p, pd) = out[..2 * m].split_at_mut(m);
        sys.phi_and_phi_dot_cached(q, v, t, p, pd, &mut self.angles);
        let mut r = 0.0f64;
        for &e in out[..2 * m].iter() {
            if !e.is_finite() {
                return f64::NAN;
            }
            r = r.max(e.abs());
        }
        r
    }

    /// Writes `x = x_c + U xi + Q1 zeta` into `x` (no Newton).
    pub fn point(&self, xi: &[f64], zeta: &[f64], x: &mut [f64]) {
        let (nn, mm) = (2 * self.n, 2 * self.m);
        x.copy_from_slice(&self.xc);
        gemv_cols(&self.q[..mm * nn], &zeta[..mm], x);
        gemv_cols(&self.q[mm * nn..], xi, x);
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
        self.point(xi, zeta, x);
        self.run_chord(sys, t, zeta, x, newton, false)
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
        self.point(xi, zeta, x);
        self.run_chord(sys, t, zeta, x, newton, true)
    }

    /// Chord Newton along the normal directions from the point `x`: on success `x` is on the
    /// manifold at time `t` (with the same tangent coordinates `U^T (x - x_c)`) and `zeta` is
    /// set to its normal coordinates `Q1^T (x - x_c)`.
    pub fn solve_normal(
        &mut self,
        sys: &System,
        t: f64,
        zeta: &mut [f64],
        x: &mut [f64],
        newton: &NewtonSettings,
    ) -> Result<MapStats, ChartFailure> {
        if self.m == 0 {
            return Ok(MapStats::default());
        }
        self.run_chord(sys, t, zeta, x, newton, false)
    }

    /// The chord iteration from `x`; on success `zeta = Q1^T (x - x_c)`.
    fn run_chord(
        &mut self,
        sys: &System,
        t: f64,
        zeta: &mut [f64],
        x: &mut [f64],
        newton: &NewtonSettings,
        predicted: bool,
    ) -> Result<MapStats, ChartFailure> {
        if self.m == 0 {
            return Ok(MapStats::default());
        }
        let nn = 2 * self.n;
        let mut f = std::mem::take(&mut self.f);
        // the first residual of a map is evaluated exactly, the iterates' with rotated sin/cos
        self.angles.invalidate();
        self.x0.copy_from_slice(x);
        let res = self.residual_cached(sys, x, t, &mut f);
        let res_start = res;
        self.first_step = 0.0;
        let mut out = if self.broyden && self.s == 0.0 {
            self.chord_broyden(sys, t, x, newton, &mut f, res, predicted)
        } else {
            self.chord(sys, t, x, newton, &mut f, res, predicted)
        };
        if let Ok(ms) = out {
            // a chord iteration that converged far from where it started (relative to its
            // first correction) did not contract on the way: near a singular configuration it
            // can drift along the nearly singular direction onto another branch
            if !self.travel_ok(x, &self.x0, ms.iterations) {
                out = Err(ChartFailure {
                    t,
                    residual: ms.residual,
                    iterations: ms.iterations,
                });
            }
        }
        if let Err(failure) = out {
            // whatever the failure taught the matrix is suspect
            self.pb_active = false;
            if newton.fallback_change > 0.0 {
                let failure_iterations = failure.iterations;
                x.copy_from_slice(&self.x0);
                out = self.exact_newton(sys, t, x, newton, &mut f, failure, res_start);
                if let Ok(ms) = out {
                    // the same bound on the travel from the exact iteration's start
                    let exact_iterations = ms.iterations - failure_iterations;
                    if !self.travel_ok(x, &self.wx, exact_iterations) {
                        out = Err(ChartFailure {
                            t,
                            residual: ms.residual,
                            iterations: ms.iterations,
                        });
                    }
                }
            }
        }
        self.f = f;
        if out.is_ok() {
            for ((d, xv), xc) in self.dx.iter_mut().zip(x.iter()).zip(&self.xc) {
                *d = xv - xc;
            }
            let mm = 2 * self.m;
            gemv_t_cols(&self.q[..mm * nn], &self.dx, &mut zeta[..mm]);
        }
        out
    }

    /// Whether an iteration that ended at `x` from `start` travelled at most [`TRAVEL_FACTOR`]
    /// times its first correction ([`TangentChart::first_step`]), up to rounding. A
    /// contracting iteration (factor `theta`) travels at most `1 / (1 - theta)` times its first
    /// correction and its limit is the solution nearest to the start; one that travelled
    /// further wandered, and near a singular configuration it may have reached another branch.
    fn travel_ok(&self, x: &[f64], start: &[f64], iterations: usize) -> bool {
        if iterations <= 1 {
            // the travel is the first correction
            return true;
        }
        // one pass: the travel and the size of the start (for the rounding floor); a NaN in
        // `x` cannot reach here (its residual would not be finite)
        let (mut travel, mut size) = (0.0f64, 0.0f64);
        for (a, b) in x.iter().zip(start) {
            travel = fast_max(travel, (a - b).abs());
            size = fast_max(size, b.abs());
        }
        travel <= TRAVEL_FACTOR * self.first_step + 16.0 * f64::EPSILON * (1.0 + size)
    }

    /// Maps completed by Newton's method with the exact matrix after the chord iteration failed
    /// ([`NewtonSettings::fallback_change`]), since the chart was created.
    pub fn exact_maps(&self) -> usize {
        self.exact_maps
    }

    /// The fallback after a failed chord iteration from `x` (its starting point): if `Df(x)`
    /// is within `fallback_change` (relative) of `Df(x_c)`, Newton's method along the normal
    /// directions with the exact matrix `J = Df(x_k) Q1` at every iterate,
    /// `x <- x - Q1 J^-1 f(x)`; otherwise `failure` as it was. Same stopping rules as the chord
    /// iteration; a numerically singular `J` is a failure. Starts from the map's predictor
    /// (`x`); the caller bounds its travel ([`TRAVEL_FACTOR`], start copied to `wx`).
    #[allow(clippy::too_many_arguments)]
    fn exact_newton(
        &mut self,
        sys: &System,
        t: f64,
        x: &mut [f64],
        newton: &NewtonSettings,
        f: &mut [f64],
        failure: ChartFailure,
        res_start: f64,
    ) -> Result<MapStats, ChartFailure> {
        let (n, m) = (self.n, self.m);
        let (nn, mm) = (2 * n, 2 * m);
        // start from the caller's starting point (the predictor). Its projection onto the
        // tangent plane, x_c + U xi, is only used when the predictor's residual is not finite:
        // the residual is no measure of the distance to the branch near a singular
        // configuration (it grows only quadratically along the nearly singular direction), and
        // without degrees of freedom the projection is the centre itself, a whole step away
        if res_start.is_nan() {
            for ((d, xv), xc) in self.dx.iter_mut().zip(x.iter()).zip(&self.xc) {
                *d = xv - xc;
            }
            gemv_t_cols(&self.q[..mm * nn], &self.dx, &mut self.w);
            for wk in self.w.iter_mut() {
                *wk = -*wk;
            }
            self.step.copy_from_slice(x);
            gemv_cols(&self.q[..mm * nn], &self.w, &mut self.step);
            if self.residual(sys, &self.step, t, f).is_finite() {
                x.copy_from_slice(&self.step);
            }
        }
        self.wx.copy_from_slice(x);
        self.first_step = 0.0;
        sys.phi_q_dot_jacobian(&x[..n], &x[n..], &mut self.pq_x, &mut self.dphi_x);
        let scale = max_abs(self.phi_q.as_slice()).max(max_abs(self.dphi.as_slice()));
        let change = max_abs_diff(self.pq_x.as_slice(), self.phi_q.as_slice())
            .max(max_abs_diff(self.dphi_x.as_slice(), self.dphi.as_slice()));
        if change.is_nan() || change > newton.fallback_change * scale {
            return Err(failure);
        }
        let tol = newton.tol;
        let xmax = max_abs(x);
        let stall_cap = (10.0 * tol).max(ROUNDOFF_FACTOR * f64::EPSILON * (1.0 + xmax));
        let res0 = self.residual(sys, x, t, f);
        let mut res = res0;
        let mut it = failure.iterations;
        let max_iter = failure.iterations + newton.max_iter;
        let mut first = true;
        let done = |it: usize, res: f64| MapStats {
            iterations: it,
            residual: res,
            initial_residual: res0,
            exact: true,
        };
        loop {
            if let Some(verdict) = loop_head(t, res, res0, it, tol, max_iter) {
                if verdict.is_ok() {
                    self.exact_maps += 1;
                }
                return verdict.map(|_| done(it, res));
            }
            if !first {
                sys.phi_q_dot_jacobian(&x[..n], &x[n..], &mut self.pq_x, &mut self.dphi_x);
            }
            first = false;
            // J = Df(x) Q1: column k = (Phi_q cq, X cq + Phi_q cv) for Q1_k = (cq, cv)
            let (dp, dx) = (self.pq_x.as_slice(), self.dphi_x.as_slice());
            self.jn.fill(0.0);
            for k in 0..mm {
                let col = &self.q[k * nn..(k + 1) * nn];
                let (cq, cv) = col.split_at(n);
                let (jp, jv) = self.jn[k * mm..(k + 1) * mm].split_at_mut(m);
                gemv_cols(dp, cq, jp);
                gemv_cols(dx, cq, jv);
                gemv_cols(dp, cv, jv);
            }
            for (u, fk) in self.u.iter_mut().zip(f.iter()) {
                *u = -fk;
            }
            let solved = {
                let mut a = self.jn_lu.matrix_mut();
                for c in 0..mm {
                    for r in 0..mm {
                        a[(r, c)] = self.jn[c * mm + r];
                    }
                }
                self.jn_lu.factor_in_place().is_ok() && {
                    self.jn_lu.solve_in_place(&mut self.u);
                    self.u.iter().all(|x| x.is_finite())
                }
            };
            if !solved {
                if res <= stall_cap {
                    // J numerically singular: x is at a singular configuration, with the
                    // residual at the round-off floor (the next centre reports it)
                    self.exact_maps += 1;
                    return Ok(done(it, res));
                }
                return Err(ChartFailure {
                    t,
                    residual: res,
                    iterations: it,
                });
            }
            gemv_cols(&self.q[..mm * nn], &self.u, x);
            it += 1;
            if it == failure.iterations + 1 {
                self.first_step = max_abs_diff(x, &self.wx);
            }
            let prev = res;
            res = self.residual(sys, x, t, f);
            if res > tol && res <= stall_cap && res >= 0.9 * prev {
                self.exact_maps += 1;
                return Ok(done(it, res));
            }
            if res > newton.divergence * prev && res > tol {
                return Err(ChartFailure {
                    t,
                    residual: res,
                    iterations: it,
                });
            }
            if res <= tol {
                self.exact_maps += 1;
                return Ok(done(it, res));
            }
        }
    }

    /// The chord iteration on `x` from its residual `f`.
    #[allow(clippy::too_many_arguments)]
    fn chord(
        &mut self,
        sys: &System,
        t: f64,
        x: &mut [f64],
        newton: &NewtonSettings,
        f: &mut [f64],
        res0: f64,
        predicted: bool,
    ) -> Result<MapStats, ChartFailure> {
        let s = self.s;
        let tol = newton.tol;
        // f cannot be evaluated more accurately than about eps |Phi_q| |v| (and eps |theta| in
        // sin theta): a stall below this cap is the round-off floor, not slow convergence
        let xmax = x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let stall_cap = (10.0 * tol).max(ROUNDOFF_FACTOR * f64::EPSILON * (1.0 + xmax));
        let mut res = res0;
        let mut prev = f64::INFINITY;
        let mut it = 0;
        loop {
            if let Some(verdict) = loop_head(t, res, res0, it, tol, newton.max_iter) {
                return verdict;
            }
            // x <- x - Q1 J^-1 f = x - P0 (I + s K)^-1 f
            if s != 0.0 {
                // u = K f, f <- f - s u + s^2 K u
                self.u.fill(0.0);
                gemv_cols(&self.k, f, &mut self.u);
                let s2 = s * s;
                for ((fi, ui), wi) in f.iter_mut().zip(&self.u).zip(self.w.iter_mut()) {
                    *fi -= s * ui;
                    *wi = s2 * ui;
                }
                gemv_cols(&self.k, &self.w, f);
            }
            // f is overwritten by the next residual: negate it in place
            for fk in f.iter_mut() {
                *fk = -*fk;
            }
            gemv_cols(&self.p0, f, x);
            it += 1;
            if it == 1 {
                self.first_step = x
                    .iter()
                    .zip(&self.x0)
                    .fold(0.0f64, |d, (a, b)| fast_max(d, (a - b).abs()));
            }
            // predicted stop (stage points only): the residual after this correction is about
            // theta * res with theta the contraction just observed
            let theta = res / prev;
            if predicted && prev.is_finite() && theta <= 0.5 && theta * res <= tol {
                return Ok(MapStats {
                    iterations: it,
                    residual: theta * res,
                    initial_residual: res0,
                    exact: false,
                });
            }
            prev = res;
            res = self.residual_cached(sys, x, t, f);
            // stall at the round-off floor (no progress, not slow convergence)
            if res > tol && res <= stall_cap && res >= 0.9 * prev {
                return Ok(MapStats {
                    iterations: it,
                    residual: res,
                    initial_residual: res0,
                    exact: false,
                });
            }
            if res > newton.divergence * prev && res > tol {
                return Err(ChartFailure {
                    t,
                    residual: res,
                    iterations: it,
                });
            }
        }
    }

    /// The chord iteration on `x` from its residual `f` with good Broyden updates of its matrix
    /// (see [`TangentChart::set_broyden`]); stopping rules as [`TangentChart::map`] and
    /// [`TangentChart::map_predicted`].
    #[allow(clippy::too_many_arguments)]
    fn chord_broyden(
        &mut self,
        sys: &System,
        t: f64,
        x: &mut [f64],
        newton: &NewtonSettings,
        f: &mut [f64],
        res0: f64,
        predicted: bool,
    ) -> Result<MapStats, ChartFailure> {
        let tol = newton.tol;
        let xmax = x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let stall_cap = (10.0 * tol).max(ROUNDOFF_FACTOR * f64::EPSILON * (1.0 + xmax));
        let mut res = res0;
        let mut prev = f64::INFINITY;
        let mut it = 0;
        // whether `wx` holds `Q1 H f` for the current `f` and `H`
        let mut have_w = false;
        loop {
            if let Some(verdict) = loop_head(t, res, res0, it, tol, newton.max_iter) {
                return verdict;
            }
            if !have_w {
                let p = if self.pb_active { &self.pb } else { &self.p0 };
                self.wx.fill(0.0);
                gemv_cols(p, f, &mut self.wx);
            }
            // x <- x - Q1 H f
            for ((xi, si), wi) in x.iter_mut().zip(self.step.iter_mut()).zip(&self.wx) {
                *si = -wi;
                *xi -= wi;
            }
            it += 1;
            if it == 1 {
                self.first_step = max_abs(&self.wx);
            }
            let theta = res / prev;
            if predicted && prev.is_finite() && theta <= 0.5 && theta * res <= tol {
                return Ok(MapStats {
                    iterations: it,
                    residual: theta * res,
                    initial_residual: res0,
                    exact: false,
                });
            }
            prev = res;
            self.fprev.copy_from_slice(f);
            res = self.residual_cached(sys, x, t, f);
            if res > tol && res <= stall_cap && res >= 0.9 * prev {
                return Ok(MapStats {
                    iterations: it,
                    residual: res,
                    initial_residual: res0,
                    exact: false,
                });
            }
            if self.pb_active && (res.is_nan() || res >= prev) {
                // the updated matrix made no progress: undo the step, restart from R^-T
                for (xi, si) in x.iter_mut().zip(&self.step) {
                    *xi -= si;
                }
                f.copy_from_slice(&self.fprev);
                res = prev;
                prev = f64::INFINITY;
                self.pb_active = false;
                self.broyden_resets += 1;
                have_w = false;
                continue;
            }
            if res > newton.divergence * prev && res > tol {
                return Err(ChartFailure {
                    t,
                    residual: res,
                    iterations: it,
                });
            }
            if res <= tol {
                continue;
            }
            // w = Q1 H f_(k+1); with s = step: H y = w + s, so the good Broyden update is
            // H <- H - w (s^T H) / (s^T w + s^T s) and the next step is -w |s|^2 / den
            {
                let p = if self.pb_active { &self.pb } else { &self.p0 };
                self.wx.fill(0.0);
                gemv_cols(p, f, &mut self.wx);
            }
            have_w = true;
            let ss = dot(&self.step, &self.step);
            let den = dot(&self.step, &self.wx) + ss;
            if den.is_finite() && den.abs() > 0.1 * ss && ss > 0.0 {
                if !self.pb_active {
                    self.pb.copy_from_slice(&self.p0);
                    self.pb_active = true;
                }
                let inv = 1.0 / den;
                rank_one_update(&mut self.pb, &self.step, &self.wx, inv);
                let g = ss * inv;
                for w in self.wx.iter_mut() {
                    *w *= g;
                }
                self.broyden_updates += 1;
            }
        }
    }

    /// The paper's normal coefficients `eta = R^-1 zeta` of a normal part `Q1 zeta =
    /// Df(x_c)^T eta` (both of length `2m`). Unlike `zeta`, `eta` does not depend on the
    /// choice of the orthonormal basis `Q1` (`eta = (Df Df^T)^-1 Df (x - x_c)`), so it varies
    /// smoothly from one chart to the next along a trajectory.
    pub fn eta_from_zeta(&self, zeta: &[f64], eta: &mut [f64]) {
        let mm = 2 * self.m;
        let eta = &mut eta[..mm];
        eta.fill(0.0);
        for (j, &zj) in zeta.iter().enumerate().take(mm) {
            axpy(zj, &self.rinv[j * mm..j * mm + j + 1], &mut eta[..j + 1]);
        }
    }

    /// `zeta = R eta`: the normal coordinates in the basis `Q1` of the paper's `Df(x_c)^T eta`
    /// (the inverse of [`TangentChart::eta_from_zeta`]).
    pub fn zeta_from_eta(&self, eta: &[f64], zeta: &mut [f64]) {
        let (nn, mm) = (2 * self.n, 2 * self.m);
        let zeta = &mut zeta[..mm];
        zeta.fill(0.0);
        for (j, &ej) in eta.iter().enumerate().take(mm) {
            axpy(ej, &self.a[j * nn..j * nn + j + 1], &mut zeta[..j + 1]);
        }
    }

    /// `out = [Q1 U]^T y`: the normal components (first `2m`) and the tangent components (last
    /// `2(n - m)`) of a vector `y` of length `2n`.
    pub fn coordinates(&self, y: &[f64], out: &mut [f64]) {
        gemv_t_cols(&self.q, y, out);
    }
}

/// `max(a, b)` for non-NaN `b` (one `maxsd`; `f64::max`'s NaN handling costs several
/// instructions more in the short loops of the travel bound).
#[inline(always)]
fn fast_max(a: f64, b: f64) -> f64 {
    if b > a {
        b
    } else {
        a
    }
}

/// The verdict at the head of a chord iteration: failed (residual not finite, or `max_iter`
/// iterations used), converged (`res <= tol`), or `None` to go on.
fn loop_head(
    t: f64,
    res: f64,
    res0: f64,
    it: usize,
    tol: f64,
    max_iter: usize,
) -> Option<Result<MapStats, ChartFailure>> {
    let failure = || ChartFailure {
        t,
        residual: res,
        iterations: it,
    };
    if !res.is_finite() {
        Some(Err(failure()))
    } else if res <= tol {
        Some(Ok(MapStats {
            iterations: it,
            residual: res,
            initial_residual: res0,
            exact: false,
        }))
    } else if it >= max_iter {
        Some(Err(failure()))
    } else {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The block-structured chart: `[Q1 U]` orthonormal, `Q1 R = Df^T`, `Df U = 0`.
    #[test]
    fn block_chart_factors_df() {
        for sys in [
            mbd_model::models::manipulator().expect("model"),
            mbd_model::models::four_bar().expect("model"),
            mbd_model::models::slider_crank().expect("model"),
        ] {
            let st = mbd_solve::State::consistent(&sys, 0.0).expect("state");
            let mut v = st.v.clone();
            for (i, x) in v.iter_mut().enumerate() {
                *x += 0.1 * (i as f64 + 1.0); // off the manifold in v: Df is all that matters
            }
            let mut chart = TangentChart::new(&sys);
            chart
                .centre(&sys, st.q.as_slice(), v.as_slice(), 0.0)
                .expect("centre");
            let (dim, mm, nn) = (chart.dim(), chart.codim(), chart.ambient_dim());
            let col = |k: usize| {
                if k < mm {
                    chart.normal(k)
                } else {
                    chart.tangent(k - mm)
                }
            };
            for i in 0..nn {
                for j in 0..nn {
                    let d = dot(col(i), col(j));
                    let e = if i == j { 1.0 } else { 0.0 };
                    assert!((d - e).abs() < 1e-14, "({i},{j}) {d}");
                }
            }
            let df = chart.jacobian();
            let scale = df.amax();
            for j in 0..mm {
                for i in 0..nn {
                    let qr: f64 = (0..=j).map(|k| chart.normal(k)[i] * chart.r(k, j)).sum();
                    assert!((qr - df[(j, i)]).abs() < 1e-13 * scale, "Q1 R ({i},{j})");
                }
            }
            for k in 0..dim {
                for r in 0..mm {
                    let d: f64 = (0..nn).map(|c| df[(r, c)] * chart.tangent(k)[c]).sum();
                    assert!(d.abs() < 1e-13 * scale, "Df U ({r},{k}) {d}");
                }
            }
        }
    }

    /// The Broyden iteration reaches the same chart points as the plain chord (to 1e-13) with
    /// fewer iterations, also when its updated matrix is carried to a second map.
    #[test]
    fn broyden_reaches_the_chord_point_in_fewer_iterations() {
        let sys = mbd_model::models::manipulator().expect("model");
        let st = mbd_solve::State::consistent(&sys, 0.0).expect("state");
        let newton = NewtonSettings::default();
        let mut chart = TangentChart::new(&sys);
        let (dim, mm, nn) = (chart.dim(), chart.codim(), chart.ambient_dim());
        let mut pts = vec![];
        let mut iters = vec![];
        for broyden in [false, true] {
            chart.set_broyden(broyden);
            chart
                .centre(&sys, st.q.as_slice(), st.v.as_slice(), 0.0)
                .expect("centre");
            let mut total = 0;
            let mut xs = vec![];
            for scale in [0.2, 0.25] {
                let xi: Vec<f64> = (0..dim).map(|k| scale * (1.0 + 0.3 * k as f64)).collect();
                let mut zeta = vec![0.0; mm];
                let mut x = vec![0.0; nn];
                let ms = chart
                    .map(&sys, &xi, 0.0, &mut zeta, &mut x, &newton)
                    .expect("map");
                assert!(ms.residual <= newton.tol, "{ms:?}");
                total += ms.iterations;
                xs.push(x);
            }
            iters.push(total);
            pts.push(xs);
        }
        let (updates, _) = chart.broyden_counts();
        println!(
            "chord {} iterations, Broyden {} ({updates} updates)",
            iters[0], iters[1]
        );
        for (a, b) in pts[0].iter().zip(&pts[1]) {
            let d = a
                .iter()
                .zip(b)
                .fold(0.0f64, |d, (p, q)| d.max((p - q).abs()));
            assert!(d < 1e-13, "{d:e}");
        }
        assert!(updates > 0);
        assert!(iters[1] < iters[0], "{iters:?}");
    }

    #[test]
    fn householder_qr_reconstructs_and_q_is_orthogonal() {
        // 8 x 4 with the first 2 columns zero below row 4 (the structure of Df^T)
        let (rows, cols, short, half) = (8, 4, 2, 4);
        let mut a0: Vec<f64> = (0..rows * cols)
            .map(|i| ((i * 37 % 11) as f64 - 5.0) * 0.3 + if i % 9 == 0 { 2.0 } else { 0.0 })
            .collect();
        for k in 0..short {
            for r in half..rows {
                a0[k * rows + r] = 0.0;
            }
        }
        for (short, half) in [(0, rows), (short, half)] {
            let mut a = a0.clone();
            let mut tau = vec![0.0; cols];
            householder_qr(&mut a, &mut tau, rows, cols, short, half);
            let mut q = vec![0.0; rows * rows];
            form_q(&a, &tau, rows, cols, short, half, &mut q);
            for i in 0..rows {
                for j in 0..rows {
                    let d = dot(&q[i * rows..(i + 1) * rows], &q[j * rows..(j + 1) * rows]);
                    let e = if i == j { 1.0 } else { 0.0 };
                    assert!((d - e).abs() < 1e-14, "({i},{j}) {d}");
                }
            }
            for j in 0..cols {
                for i in 0..rows {
                    let mut s = 0.0;
                    for k in 0..=j {
                        s += q[k * rows + i] * a[j * rows + k];
                    }
                    assert!((s - a0[j * rows + i]).abs() < 1e-13, "({i},{j})");
                }
            }
        }
    }
}
