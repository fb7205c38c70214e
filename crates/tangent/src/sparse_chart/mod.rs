//! The sparse chart for large mechanisms: redundant tangent coordinates `y` in `ker Df(x_c)`,
//! the projector `P = I - Df^T G^-1 Df` and the chord iteration on `eta`, all through one sparse
//! Cholesky factorisation of `G = Df(x_c) Df(x_c)^T` per centre (`docs/tangent.md` section 9).

use crate::chart::{fast_max, travel_within, ChordLoop, RoundoffFloor};
use crate::chart::{ChartFailure, MapStats, NewtonSettings};
use mbd_model::{BodyAngles, System};
use mbd_solve::linalg::max_abs;
use mbd_solve::linalg::FactorError;
use mbd_solve::sparse::{BlockRows, SparseCholesky};
use mbd_solve::SolveError;

mod rank;
#[cfg(test)]
mod tests;

/// One contribution of a block shared by rows `r1 >= r2` to the four entries of `G` that
/// couple them: `o1`, `o2` are the offsets of the rows' sides on that block in the flat
/// gradient arrays, `w` the block's width, and `pp`, `vp`, `pv`, `vv` the value slots of
/// (position `r1`, position `r2`), (velocity `r1`, position `r2`), (position `r1`, velocity
/// `r2`) and (velocity `r1`, velocity `r2`) (`pv` is unused when `r1 == r2`: it is `vp` by
/// symmetry).
#[derive(Clone, Copy, Debug)]
struct Contribution {
    r1: usize,
    r2: usize,
    o1: usize,
    o2: usize,
    w: usize,
    pp: usize,
    vp: usize,
    pv: usize,
    vv: usize,
}

/// One contribution of a shared block to `Phi_q W Phi_q^T` (rank report): gradient offsets,
/// width, value slot.
#[derive(Clone, Copy, Debug)]
struct PosContribution {
    o1: usize,
    o2: usize,
    w: usize,
    /// The block's first coordinate (its weights in `rank_w`).
    col: usize,
    idx: usize,
}

/// A chart of the manifold `f(x, t) = (Phi, Phi_q v + Phi_t) = 0` at a centre `x_c` without an
/// explicit basis of `ker Df(x_c)` (which is dense for a chain):
///
/// ```text
/// x(y) = x_c + y + Df(x_c)^T eta(y),   y in ker Df(x_c) (redundant coordinates in R^2n),
/// ```
///
/// with `eta` (`2m`) from the chord iteration `G d = -f(x)`, `x <- x + Df^T d`, `eta <- eta + d`
/// and `G = Df(x_c) Df(x_c)^T` (`2m x 2m`). `Df = [[Phi_q, 0], [X, Phi_q]]` (`X = (Phi_q v)_q`)
/// is kept in element-local form over body blocks of any kind ([`BlockRows`]: each equation
/// acts on at most two bodies, planar or spatial), so `G` couples two equations only when they
/// act on a common body: block tridiagonal for a chain. Its pattern
/// is analysed once in [`SparseChart::new`]; [`SparseChart::centre`] refills and refactors it,
/// and the same factorisation gives the projector `P F = F - Df^T G^-1 Df F` of the state
/// equation `y' = P F(x(y), t)` ([`SparseChart::split`]). Every operation costs `O(n + m)` for
/// a chain, and none allocates after [`SparseChart::new`].
///
/// The chord iteration is the dense chart's ([`crate::TangentChart`]: `Q1 R^-T = Df^T G^-1`),
/// so from the same starting point it reaches the same chart point; `y = U xi` maps the dense
/// chart's coordinates to these. Unlike the dense chart it has no exact-Newton fallback, no
/// Broyden updates and no interpolated iteration matrix (a failed chord iteration is a
/// [`ChartFailure`]: halving or rejection). The Cholesky factorisation of `G` squares the
/// condition number of `Df` (the QR of the dense chart does not), so near-singular
/// configurations are detected at `cond(Df) ~ 1e7` (the kernel's pivot test
/// `L_jj^2 >= 1e-14 G_jj`) or earlier by [`SparseChart::singular_tol`].
#[derive(Debug)]
pub struct SparseChart {
    n: usize,
    m: usize,
    /// The model's redundant equations (dropped by each factorisation).
    redundant: usize,
    /// Every equation over body blocks.
    rows: BlockRows,
    /// Element-local rows of `Phi_q` and `(Phi_q v)_q` at the centre (the layout of `rows`).
    grads: Vec<f64>,
    dgrads: Vec<f64>,
    contributions: Vec<Contribution>,
    /// `G = Df Df^T` (`2m x 2m`; index `r` position equation `r`, `m + r` velocity equation `r`).
    chol: SparseCholesky,
    /// `Phi_q W Phi_q^T` at a configuration (rank report), its contributions and rows of `Phi_q`.
    pos_chol: SparseCholesky,
    pos_contributions: Vec<PosContribution>,
    /// [`System::rank_weights`]: the rank report factors `Phi_q W Phi_q^T`.
    rank_w: Vec<f64>,
    /// The round-off floor below which a stalled map has converged.
    roundoff: RoundoffFloor,
    grads_x: Vec<f64>,
    /// The centre in the chart's coordinates `(q_c, tau v_c)` (see
    /// [`SparseChart::set_velocity_weight`]) and as given, `(q_c, v_c)`, and its time.
    xc: Vec<f64>,
    xc_user: Vec<f64>,
    tc: f64,
    /// The velocity weight `tau` of the current centre, `1 / tau`, and the next centre's.
    vs: f64,
    vinv: f64,
    vs_next: f64,
    /// The velocities `v` of a residual evaluation at a chart point (`n`).
    vbuf: Vec<f64>,
    /// Whether the constraints are scleronomic: the weighted velocity rows are then evaluated
    /// at `(q, tau v)` directly (`Phi_q v` is linear in `v`).
    scleronomic: bool,
    /// Residual and correction buffers (`2m`).
    f: Vec<f64>,
    d: Vec<f64>,
    /// The starting point of the map in progress (`2n`), for the travel bound.
    x0: Vec<f64>,
    first_step: f64,
    angles: BodyAngles,
    rcond: f64,
    centred: bool,
    /// Relative threshold: the centre is singular when `1 / sqrt(cond(G))` (the estimate of
    /// the smallest relative singular value of `Df`) is below it. Default 1e-8 (then the
    /// kernel's pivot test, at about 1e-7, decides).
    pub singular_tol: f64,
}

impl SparseChart {
    /// A sparse chart workspace for `sys`: analyses the patterns of `G` and of
    /// `Phi_q W Phi_q^T` (allocates once).
    pub fn new(sys: &System) -> Result<Self, SolveError> {
        let (n, m) = (sys.n_coords(), sys.n_constraints());
        let rows = BlockRows::new(sys, |_| true)?;
        let mut pairs = Vec::new();
        rows.shared_pairs(|s1, s2, r1, r2| pairs.push((s1, s2, r1, r2)));
        let mut pattern = Vec::with_capacity(4 * pairs.len());
        let mut pos_pattern = Vec::with_capacity(pairs.len());
        for &(_, _, r1, r2) in &pairs {
            pattern.push((r1, r2));
            pattern.push((m + r1, r2));
            pattern.push((m + r2, r1));
            pattern.push((m + r1, m + r2));
            pos_pattern.push((r1, r2));
        }
        let mut chol = SparseCholesky::new(2 * m, &pattern)?;
        let mut pos_chol = SparseCholesky::new(m, &pos_pattern)?;
        // k redundant equations: k dependent position rows and k velocity rows, dropped at
        // each factorisation (the projector and the chord then work with the independent
        // rows, whose span is the same: docs/architecture.md, "Redundant constraints")
        let k = sys.n_redundant();
        chol.set_max_dependent(2 * k);
        pos_chol.set_max_dependent(k);
        let missing = |r: usize, c: usize| {
            SolveError::Unsupported(format!("sparse chart: pattern lacks entry ({r}, {c})"))
        };
        let slot =
            |ch: &SparseCholesky, r: usize, c: usize| ch.slot(r, c).ok_or_else(|| missing(r, c));
        let mut contributions = Vec::with_capacity(pairs.len());
        let mut pos_contributions = Vec::with_capacity(pairs.len());
        for (s1, s2, r1, r2) in pairs {
            let (o1, o2, w) = (s1.off, s2.off, s1.width);
            contributions.push(Contribution {
                r1,
                r2,
                o1,
                o2,
                w,
                pp: slot(&chol, r1, r2)?,
                vp: slot(&chol, m + r1, r2)?,
                pv: slot(&chol, r1, m + r2)?,
                vv: slot(&chol, m + r1, m + r2)?,
            });
            pos_contributions.push(PosContribution {
                o1,
                o2,
                w,
                col: s1.col,
                idx: slot(&pos_chol, r1, r2)?,
            });
        }
        let nv = rows.n_values();
        Ok(SparseChart {
            n,
            m,
            redundant: k,
            rows,
            grads: vec![0.0; nv],
            dgrads: vec![0.0; nv],
            contributions,
            chol,
            pos_chol,
            pos_contributions,
            rank_w: sys.rank_weights(),
            roundoff: RoundoffFloor::new(sys),
            grads_x: vec![0.0; nv],
            xc: vec![0.0; 2 * n],
            xc_user: vec![0.0; 2 * n],
            tc: 0.0,
            vs: 1.0,
            vinv: 1.0,
            vs_next: 1.0,
            vbuf: vec![0.0; n],
            scleronomic: !sys.is_rheonomic(),
            f: vec![0.0; 2 * m],
            d: vec![0.0; 2 * m],
            x0: vec![0.0; 2 * n],
            first_step: 0.0,
            angles: BodyAngles::sized(sys),
            rcond: 1.0,
            centred: false,
            singular_tol: 1e-8,
        })
    }

    /// Dimension of the manifold, `2 (n - m + k)` with `k` redundant equations (the chart's
    /// coordinates `y` are redundant: `2n` numbers in a `2 (n - m + k)`-dimensional subspace).
    pub fn dim(&self) -> usize {
        2 * (self.n - self.independent().min(self.n))
    }

    /// The number of independent equations, `m - k`.
    pub(super) fn independent(&self) -> usize {
        self.m - self.redundant.min(self.m)
    }

    /// Dimension of the ambient space, `2n`: the length of `y`.
    pub fn ambient_dim(&self) -> usize {
        2 * self.n
    }

    /// Number of constraint equations of `f`, `2m`: the length of `eta`.
    #[cfg(test)]
    pub fn codim(&self) -> usize {
        2 * self.m
    }

    /// The centre `x_c = (q_c, v_c)` (length `2n`).
    pub fn centre_point(&self) -> &[f64] {
        &self.xc_user
    }

    /// Sets the weight `tau > 0` of the velocities in the chart's metric from the next
    /// [`SparseChart::centre`] on, as [`crate::TangentChart::set_velocity_weight`]: the chart
    /// works in `(q, tau v)` (its `y`, `eta`, `Df` and `G`), its inputs and outputs in
    /// `(q, v)`. A non-finite or non-positive `tau` is ignored.
    pub fn set_velocity_weight(&mut self, tau: f64) {
        if tau.is_finite() && tau > 0.0 {
            self.vs_next = tau;
        }
    }

    /// A vector `e` of chart coordinates `y` in the model's `(q, v)` (the velocity half divided
    /// by the velocity weight).
    pub fn tangent_to_ambient(&self, e: &[f64], out: &mut [f64]) {
        out.copy_from_slice(e);
        self.unweight(out);
    }

    /// `(q, tau v)` of the chart to the model's `(q, v)`, in place.
    fn unweight(&self, x: &mut [f64]) {
        if self.vs != 1.0 {
            for xv in x[self.n..].iter_mut() {
                *xv *= self.vinv;
            }
        }
    }

    /// `1 / sqrt(cond(G))` of the last centre, from the sparse Cholesky's condition estimate
    /// (1 without constraints): the analogue of [`crate::TangentChart::rcond`].
    pub fn rcond(&self) -> f64 {
        self.rcond
    }

    /// Centres the chart at `(q, v)` at time `t`: evaluates `Df` in element-local form,
    /// assembles `G = Df Df^T` and factors it. A failing pivot (or a condition estimate beyond
    /// `1 / singular_tol^2`) is [`SolveError::Singular`] naming the equation.
    pub fn centre(&mut self, sys: &System, q: &[f64], v: &[f64], t: f64) -> Result<(), SolveError> {
        let (n, m) = (self.n, self.m);
        self.centred = false;
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
        self.tc = t;
        self.rcond = 1.0;
        if m == 0 {
            self.centred = true;
            return Ok(());
        }
        self.rows
            .gather_tan(sys, q, v, t, &mut self.grads, &mut self.dgrads);
        if self
            .grads
            .iter()
            .chain(&self.dgrads)
            .any(|x| !x.is_finite())
        {
            return Err(SolveError::NonFinite {
                t,
                what: "constraint Jacobian at the chart centre",
            });
        }
        // the chart's velocity coordinates are tau v: Df's block X enters weighted, tau X (and
        // the velocity rows of the residual by tau)
        if self.vs != 1.0 {
            for d in self.dgrads.iter_mut() {
                *d *= self.vs;
            }
        }
        if self.independent() > n {
            return Err(SolveError::Singular {
                t,
                what: "constraint Jacobian Df of the tangent chart",
                detail: format!("position constraint {}", sys.equation_name(n)),
            });
        }
        self.chol.clear();
        let vals = self.chol.values_mut();
        for c in &self.contributions {
            let (a1, a2) = (&self.grads[c.o1..c.o1 + c.w], &self.grads[c.o2..c.o2 + c.w]);
            let (x1, x2) = (
                &self.dgrads[c.o1..c.o1 + c.w],
                &self.dgrads[c.o2..c.o2 + c.w],
            );
            let (mut aa, mut xa, mut ax, mut xx) = (0.0, 0.0, 0.0, 0.0);
            for l in 0..c.w {
                let (p1, p2) = (a1[l], a2[l]);
                let (d1, d2) = (x1[l], x2[l]);
                aa += p1 * p2;
                xa += d1 * p2;
                ax += p1 * d2;
                xx += d1 * d2;
            }
            vals[c.pp] += aa;
            vals[c.vp] += xa;
            if c.r1 != c.r2 {
                vals[c.pv] += ax;
            }
            vals[c.vv] += xx + aa;
        }
        let tol = self.singular_tol;
        match self.chol.factor() {
            Ok(()) => {
                self.rcond = 1.0 / self.chol.condition_estimate().sqrt();
                if self.rcond.is_nan() || self.rcond <= tol {
                    return Err(SolveError::Singular {
                        t,
                        what: "constraint Jacobian Df of the sparse tangent chart",
                        detail: format!(
                            "condition estimate {:.3e} of Df Df^T beyond 1 / singular_tol^2",
                            self.chol.condition_estimate()
                        ),
                    });
                }
            }
            Err(FactorError::Singular(i) | FactorError::NotPositiveDefinite(i)) => {
                self.rcond = 0.0;
                return Err(self.singular_error(sys, t, tol).unwrap_or_else(|| {
                    SolveError::Singular {
                        t,
                        what: "constraint Jacobian Df of the sparse tangent chart (Cholesky of Df Df^T)",
                        detail: if i < m {
                            format!("position constraint {}", sys.equation_name(i))
                        } else {
                            format!("velocity constraint {}", sys.equation_name(i - m))
                        },
                    }
                }));
            }
        }
        self.centred = true;
        Ok(())
    }

    /// Every row side with its row, in storage order.
    fn sides(&self) -> impl Iterator<Item = (usize, mbd_solve::sparse::RowSide)> + '_ {
        self.rows
            .sides()
            .iter()
            .enumerate()
            .flat_map(|(r, s)| s.iter().flatten().map(move |&side| (r, side)))
    }

    /// `out = Df(x_c) z` for `z` of length `2n` (`out` of length `2m`).
    pub fn apply_df(&self, z: &[f64], out: &mut [f64]) {
        let (n, m) = (self.n, self.m);
        let (zq, zv) = z.split_at(n);
        let (op, ov) = out[..2 * m].split_at_mut(m);
        op.fill(0.0);
        ov.fill(0.0);
        match self.rows.side_order().2 {
            Some(3) => self.apply_df_w::<3>(zq, zv, op, ov),
            Some(12) => self.apply_df_w::<12>(zq, zv, op, ov),
            _ => {
                for (r, side) in self.sides() {
                    let (o, w, c) = (side.off, side.width, side.col);
                    let (a, x) = (&self.grads[o..o + w], &self.dgrads[o..o + w]);
                    let (zq, zv) = (&zq[c..c + w], &zv[c..c + w]);
                    for l in 0..w {
                        op[r] += a[l] * zq[l];
                        ov[r] += x[l] * zq[l] + a[l] * zv[l];
                    }
                }
            }
        }
    }

    /// [`SparseChart::apply_df`] when every side has width `W` (the loops unrolled).
    fn apply_df_w<const W: usize>(&self, zq: &[f64], zv: &[f64], op: &mut [f64], ov: &mut [f64]) {
        let (a, x) = (self.grads.chunks_exact(W), self.dgrads.chunks_exact(W));
        let (cols, rows, _) = self.rows.side_order();
        for ((a, x), (&c, &r)) in a.zip(x).zip(cols.iter().zip(rows)) {
            let (Some(a), Some(x), Some(zq), Some(zv)) = (
                a.first_chunk::<W>(),
                x.first_chunk::<W>(),
                zq[c..].first_chunk::<W>(),
                zv[c..].first_chunk::<W>(),
            ) else {
                continue;
            };
            let (mut p, mut d) = (0.0, 0.0);
            for l in 0..W {
                p += a[l] * zq[l];
                d += x[l] * zq[l] + a[l] * zv[l];
            }
            op[r] += p;
            ov[r] += d;
        }
    }

    /// `out += alpha Df(x_c)^T e` for `e` of length `2m` (`out` of length `2n`).
    pub fn add_df_t(&self, alpha: f64, e: &[f64], out: &mut [f64]) {
        let (n, m) = (self.n, self.m);
        let (oq, ov) = out.split_at_mut(n);
        let (ep, ev) = e[..2 * m].split_at(m);
        match self.rows.side_order().2 {
            Some(3) => self.add_df_t_w::<3>(alpha, ep, ev, oq, ov),
            Some(12) => self.add_df_t_w::<12>(alpha, ep, ev, oq, ov),
            _ => {
                for (r, side) in self.sides() {
                    let (o, w, c) = (side.off, side.width, side.col);
                    let (a, x) = (&self.grads[o..o + w], &self.dgrads[o..o + w]);
                    let (p, v) = (alpha * ep[r], alpha * ev[r]);
                    for l in 0..w {
                        oq[c + l] += a[l] * p + x[l] * v;
                        ov[c + l] += a[l] * v;
                    }
                }
            }
        }
    }

    /// [`SparseChart::add_df_t`] when every side has width `W` (the loops unrolled).
    fn add_df_t_w<const W: usize>(
        &self,
        alpha: f64,
        ep: &[f64],
        ev: &[f64],
        oq: &mut [f64],
        ov: &mut [f64],
    ) {
        let (a, x) = (self.grads.chunks_exact(W), self.dgrads.chunks_exact(W));
        let (cols, rows, _) = self.rows.side_order();
        for ((a, x), (&c, &r)) in a.zip(x).zip(cols.iter().zip(rows)) {
            let (p, v) = (alpha * ep[r], alpha * ev[r]);
            let (Some(a), Some(x), Some(oq), Some(ov)) = (
                a.first_chunk::<W>(),
                x.first_chunk::<W>(),
                oq[c..].first_chunk_mut::<W>(),
                ov[c..].first_chunk_mut::<W>(),
            ) else {
                continue;
            };
            for l in 0..W {
                oq[l] += a[l] * p + x[l] * v;
                ov[l] += a[l] * v;
            }
        }
    }

    /// Splits `F` (length `2n`) into its normal coefficients `g = G^-1 Df F` (length `2m`:
    /// `F = P F + Df^T g`) and its tangent part `dy = P F = F - Df^T g` (length `2n`), the
    /// right-hand side of the state equation `y' = P F`.
    ///
    /// `fx` is in the model's `(q, v)`; `g` and `dy` are in the chart's `(q, tau v)`.
    pub fn split(&mut self, fx: &[f64], g: &mut [f64], dy: &mut [f64]) {
        dy.copy_from_slice(fx);
        if self.vs != 1.0 {
            for d in dy[self.n..].iter_mut() {
                *d *= self.vs;
            }
        }
        if self.m == 0 {
            return;
        }
        self.apply_df(dy, g);
        self.chol.solve_in_place(g);
        self.add_df_t(-1.0, g, dy);
    }

    /// Writes `x = x_c + U xi + Q1 zeta` into `x` (no Newton) in the chart's coordinates
    /// `(q, tau v)`.
    fn point_weighted(&self, y: &[f64], eta: &[f64], x: &mut [f64]) {
        for ((xv, c), yv) in x.iter_mut().zip(&self.xc).zip(y) {
            *xv = c + yv;
        }
        if self.m > 0 {
            self.add_df_t(1.0, eta, x);
        }
    }

    /// `f(x, t) = (Phi(q, t), Phi_q v + Phi_t)` into `out` (length `2m`); returns its max-norm
    /// (NaN if any entry is not finite).
    pub fn residual(&self, sys: &System, x: &[f64], t: f64, out: &mut [f64]) -> f64 {
        let (n, m) = (self.n, self.m);
        let (q, v) = x.split_at(n);
        let (p, pd) = out[..2 * m].split_at_mut(m);
        sys.phi_and_phi_dot(q, v, t, p, pd);
        max_abs(&out[..2 * m])
    }

    /// [`SparseChart::residual`] with rotated `sin`/`cos` ([`BodyAngles::update_near`]).
    /// At a chart point `x = (q, tau v)`: the velocity rows come back weighted,
    /// `tau (Phi_q v + Phi_t)`, and the norm returned is the unweighted residual's.
    fn residual_cached(&mut self, sys: &System, x: &[f64], t: f64, out: &mut [f64]) -> f64 {
        let (n, m) = (self.n, self.m);
        let (q, v) = x.split_at(n);
        let (p, pd) = out[..2 * m].split_at_mut(m);
        if self.vs == 1.0 {
            sys.phi_and_phi_dot_cached(q, v, t, p, pd, &mut self.angles);
            return max_abs(&out[..2 * m]);
        }
        if self.scleronomic {
            // Phi_q v is linear in v: at (q, tau v) it is the weighted row tau Phi_q v itself
            sys.phi_and_phi_dot_cached(q, v, t, p, pd, &mut self.angles);
            let (a, b) = (max_abs(p), max_abs(pd) * self.vinv);
            return if a.is_nan() || b.is_nan() {
                f64::NAN
            } else {
                fast_max(a, b)
            };
        }
        for (b, &vi) in self.vbuf.iter_mut().zip(v) {
            *b = vi * self.vinv;
        }
        sys.phi_and_phi_dot_cached(q, &self.vbuf, t, p, pd, &mut self.angles);
        let r = max_abs(&out[..2 * m]);
        for o in out[m..2 * m].iter_mut() {
            *o *= self.vs;
        }
        r
    }

    /// Maps `y` (length `2n`, in `ker Df(x_c)`) to the point `x` of the manifold at time `t`:
    /// `x = x_c + y + Df^T eta` with `eta` by chord Newton started at the value passed in and
    /// left at the converged value. Stopping rules and travel bound as
    /// [`crate::TangentChart::map`].
    pub fn map(
        &mut self,
        sys: &System,
        y: &[f64],
        t: f64,
        eta: &mut [f64],
        x: &mut [f64],
        newton: &NewtonSettings,
    ) -> Result<MapStats, ChartFailure> {
        self.point_weighted(y, eta, x);
        let out = self.chord(sys, t, eta, x, newton, false);
        self.unweight(x);
        out
    }

    /// [`SparseChart::map`] for a Runge-Kutta stage point: may stop on the predicted residual
    /// (as [`crate::TangentChart::map_predicted`]).
    pub fn map_predicted(
        &mut self,
        sys: &System,
        y: &[f64],
        t: f64,
        eta: &mut [f64],
        x: &mut [f64],
        newton: &NewtonSettings,
    ) -> Result<MapStats, ChartFailure> {
        self.point_weighted(y, eta, x);
        let out = self.chord(sys, t, eta, x, newton, true);
        self.unweight(x);
        out
    }

    /// The chord iteration `G d = -f(x)`, `x <- x + Df^T d`, `eta <- eta + d` from `x`.
    fn chord(
        &mut self,
        sys: &System,
        t: f64,
        eta: &mut [f64],
        x: &mut [f64],
        newton: &NewtonSettings,
        predicted: bool,
    ) -> Result<MapStats, ChartFailure> {
        if self.m == 0 {
            return Ok(MapStats::default());
        }
        let mut f = std::mem::take(&mut self.f);
        let mut d = std::mem::take(&mut self.d);
        let out = self.chord_loop(sys, t, eta, x, newton, predicted, &mut f, &mut d);
        self.f = f;
        self.d = d;
        let ms = out?;
        if ms.iterations > 1 && !travel_within(x, &self.x0, self.first_step) {
            return Err(ChartFailure {
                t,
                residual: ms.residual,
                iterations: ms.iterations,
            });
        }
        Ok(ms)
    }

    #[allow(clippy::too_many_arguments)]
    fn chord_loop(
        &mut self,
        sys: &System,
        t: f64,
        eta: &mut [f64],
        x: &mut [f64],
        newton: &NewtonSettings,
        predicted: bool,
        f: &mut [f64],
        d: &mut [f64],
    ) -> Result<MapStats, ChartFailure> {
        self.angles.invalidate();
        self.x0.copy_from_slice(x);
        self.first_step = 0.0;
        let res0 = self.residual_cached(sys, x, t, f);
        let mut lp = ChordLoop::new(t, res0, newton, predicted);
        loop {
            if let Some(verdict) = lp.head() {
                return verdict;
            }
            for (dk, fk) in d.iter_mut().zip(f.iter()) {
                *dk = -fk;
            }
            self.chol.solve_in_place(d);
            self.add_df_t(1.0, d, x);
            for (e, dk) in eta.iter_mut().zip(d.iter()) {
                *e += dk;
            }
            if lp.it == 0 {
                self.first_step = x
                    .iter()
                    .zip(&self.x0)
                    .fold(0.0f64, |s, (a, b)| fast_max(s, (a - b).abs()));
            }
            if let Some(ms) = lp.corrected() {
                return Ok(ms);
            }
            let res = self.residual_cached(sys, x, t, f);
            if let Some(ms) =
                lp.evaluated(res, || self.roundoff.stall_cap(x, newton.tol, self.vinv))
            {
                return Ok(ms);
            }
            if let Some(e) = lp.diverged() {
                return Err(e);
            }
        }
    }
}
