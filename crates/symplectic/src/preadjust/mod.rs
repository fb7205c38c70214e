//! The preadjustment terms of the symplectic scheme, each a type owning its workspace, on one
//! shared projected metric.
//!
//! With `g = grad V`, `G = Phi_q`, `S = G M^-1 G^T`, the `M^-1`-projector
//! `Pi = M^-1 - M^-1 G^T S^-1 G M^-1`, the rest multipliers `mu0 = S^-1 G M^-1 g`,
//! `u = M^-1 f_T = -Pi g` and the tangential stiffness `A = Hess V - mu0 . Hess Phi`:
//!
//! | term | type (file) | value (forward) | gradient (adjoint) | Newton matrix | `docs/symplectic.md` |
//! |---|---|---|---|---|---|
//! | paper A's `W_s(q) = 1/2 u^T A (Pi A)^(s-2) u` (`W_1 = 1/2 u^T M u`), `gamma kappa_s h^(2s) W_s` at the Gauss points | [`PaperTerm`] (`paper.rs`) | `PaperTerm::value`: the Krylov vectors `a_i = (Pi A)^i u` | `PaperTerm::gradient`: by hand through the Krylov recursion, exact third derivatives | `A (Pi A)^s` ([`TangentStiffness::a_pi_a_power`]) | section 5 |
//! | the s = 1 modified Lagrangian `e(q, v)`, `h^3 e` at the chord midpoint of a (1,1) step | [`ModifiedS1`] (`modified_s1.rs`) | `ModifiedS1::evaluate` | `ModifiedS1::gradients`: closed form, one Hessian-vector and one third-order pass | `ModifiedS1::add_velocity_hessian` and `A_s Pi A_s`, `A_s = A + H_sigma` ([`TangentStiffness::a_pi_a`]); on the sparse path the blocks' diagonals (`ModifiedS1::newton_diagonals`) and `A_s Pi A_s` through augmented unknowns (`galerkin/sparse/projected.rs`) | section 5a |
//! | the s = 2 modified Lagrangian `e4(q, v)`, 23 invariants ([`modified_s2::E4_TERMS`]), `h^5 e4` at the chord midpoint of a (2,2) step | [`modified_s2::ModifiedS2`] (`modified_s2/`) | `modified_s2/forward.rs`: jet passes A, B, C (`modified_s2/passes.rs`) | `modified_s2/reverse.rs`: reverse pass through the forward's intermediates (workspace `modified_s2/adjoints.rs`) | none (left out of the Newton matrix) | section 5b |
//!
//! Shared by the terms:
//!
//! * [`ProjectedMetric`] (`metric.rs`): `g`, `G`, the factor of `S` (dense, or sparse for the
//!   modified Lagrangian on large models), `mu0`, `u` at one point, kept while the point does not
//!   change bit for bit, and the products with `Pi`, `S^-1`, `G`, `M^-1 G^T` and `A`;
//! * [`TangentStiffness`] (`stiffness.rs`): `A` assembled at the metric's point, and its
//!   Newton matrices on the block of coordinates where `A` is not zero (dense layout).
//!
//! [`Preadjustment`] is the public face: one metric, the stiffness and the three terms, with the
//! methods the integrator (`galerkin/`) and the tests call. Every method prepares the metric at
//! its `q` (a no-op when `q` repeats), then asks one term.

use mbd_model::System;
use mbd_solve::linalg::dot;
use mbd_solve::SolveError;
use nalgebra::DMatrix;

mod augmented;
mod metric;
mod modified_s1;
mod modified_s2;
mod paper;
mod stiffness;

use metric::ProjectedMetric;
use modified_s1::ModifiedS1;
use modified_s2::E4_TERM_COUNT;
use paper::PaperTerm;
use stiffness::TangentStiffness;

/// A constraint row in element-local form: its derivatives in the coordinates `(x, y, theta)`
/// of the joint's two bodies.
type LocalRow = [f64; 6];

/// A zero [`LocalRow`].
const ZERO_ROW: LocalRow = [0.0; 6];

/// The preadjustment terms at one point, with their shared metric: paper A's `W_s` (value,
/// gradient, Newton Hessian), the tangential force, and the modified-Lagrangian terms `e`
/// (s = 1) and `e4` (s = 2) with their gradients (allocation-free after the first use).
///
/// Every method evaluates the shared quantities at its `q` first, and keeps them while `q`
/// does not change bit for bit.
#[derive(Debug)]
pub struct Preadjustment {
    metric: ProjectedMetric,
    stiffness: TangentStiffness,
    paper: PaperTerm,
    s1: ModifiedS1,
    /// The `s = 2` term (allocated on first use).
    s2: Option<Box<modified_s2::ModifiedS2>>,
    /// Relative step of the finite-difference checks of the derivatives (tests); the
    /// derivatives used by the integrator are exact.
    pub(crate) fd_step: f64,
}

impl Preadjustment {
    /// A workspace for `W_s` on `sys`.
    pub fn new(sys: &System, s: usize) -> Result<Self, SolveError> {
        Self::with_layout(sys, s, false)
    }

    /// A workspace for the modified Lagrangian alone ([`Preadjustment::modified_term`],
    /// [`Preadjustment::modified_gradients`] for `s = 1`, [`Preadjustment::modified_term_s2`],
    /// [`Preadjustment::modified_gradients_s2`] for `s = 2`) with `S = Phi_q M^-1 Phi_q^T`
    /// held sparse ([`mbd_solve::sparse::ConstraintSchur`], or [`mbd_solve::sparse::BlockSchur`]
    /// with spatial bodies, whose `M^-1` is then regularised on a massless director as the
    /// s = 2 term's is on either layout): `O(N)` storage and work per evaluation on a chain of
    /// `N` bodies (the symplectic scheme's sparse stage solve). `W_s`'s value and gradient
    /// ([`Preadjustment::value`], [`Preadjustment::gradient`]) work on it too, for `W_1`
    /// (this constructor's degree; [`Preadjustment::with_layout`] for another); the dense
    /// Hessians need the dense matrices and return [`SolveError::Unsupported`] on it.
    pub fn new_sparse(sys: &System) -> Result<Self, SolveError> {
        Self::with_layout(sys, 1, true)
    }

    /// A workspace for `W_s` of degree `s` (and the modified Lagrangian), with `S` held
    /// sparse when `sparse` ([`Preadjustment::new_sparse`]) or dense ([`Preadjustment::new`]).
    pub fn with_layout(sys: &System, s: usize, sparse: bool) -> Result<Self, SolveError> {
        if s == 0 {
            return Err(SolveError::InvalidParameter {
                parameter: "s",
                value: 0.0,
                reason: "W_s needs s >= 1",
            });
        }
        let (n, m) = (sys.n_coords(), sys.n_constraints());
        Ok(Preadjustment {
            metric: ProjectedMetric::new(sys, sparse)?,
            stiffness: TangentStiffness::new(n, m, sparse),
            paper: PaperTerm::new(n, m, s),
            s1: ModifiedS1::new(n, m, sparse),
            s2: None,
            fd_step: 2e-3,
        })
    }

    /// Sets the time `t` at which the next evaluations take the model's constraints, on a
    /// model whose `Phi_q` depends on time (a spatial angle driver, whose equation turns with
    /// `theta(t)`: [`System::jacobian_depends_on_time`]); every term is then that of the
    /// model frozen at `t`. Nothing on every other model, whose terms do not depend on the
    /// time. The scheme sets it to the time of each evaluation point (the chord midpoint
    /// `t + h/2` of the modified Lagrangian, the Gauss points of `W_s`); the default is 0.
    pub fn set_time(&mut self, t: f64) {
        self.metric.set_time(t);
    }

    /// The degree `s`.
    pub fn s(&self) -> usize {
        self.paper.s()
    }

    /// The tangential force `f_T(q) = P(q) (-grad V(q))` into `out`.
    pub fn tangential_force(
        &mut self,
        sys: &System,
        q: &[f64],
        out: &mut [f64],
    ) -> Result<(), SolveError> {
        self.metric.prepare(sys, q)?;
        let (mass, u) = (self.metric.mass(), self.metric.u());
        for k in 0..self.metric.n() {
            out[k] = mass[k] * u[k];
        }
        Ok(())
    }

    /// `W_s(q)`.
    pub fn value(&mut self, sys: &System, q: &[f64]) -> Result<f64, SolveError> {
        self.metric.prepare(sys, q)?;
        Ok(self.paper.value(&mut self.metric, sys, q))
    }

    /// `grad W_s(q)` into `out`; returns `W_s(q)`. Matrix-free: every product with `A` or
    /// with a weighted constraint Hessian is one Hessian-vector pass over the elements
    /// (`passes::lagrangian_hessian_vector`), the third derivatives are exact.
    pub fn gradient(
        &mut self,
        sys: &System,
        q: &[f64],
        out: &mut [f64],
    ) -> Result<f64, SolveError> {
        self.metric.prepare(sys, q)?;
        Ok(self.paper.gradient(&mut self.metric, sys, q, out))
    }

    /// A bound on the spectral radius of `M^-1 A` (Gershgorin: `max_i minv_i sum_l |A_il|`; the
    /// eigenvalues are those of the symmetric `M^-1/2 A M^-1/2`), so the Newton Hessian
    /// [`Preadjustment::approximate_hessian`] is at most `bound^(s+1)` in the mass metric.
    pub fn hessian_bound(&mut self, sys: &System, q: &[f64]) -> Result<f64, SolveError> {
        self.metric.require_dense("Preadjustment::hessian_bound")?;
        self.metric.prepare(sys, q)?;
        self.stiffness.ensure(&self.metric, sys, q);
        Ok(self.stiffness.bound(&self.metric))
    }

    /// The diagonal stand-in for `W_s`'s Newton Hessian on the sparse stage solve at `q`
    /// (either layout): `out_i = A_ii (w_i A_ii)^s`, the diagonal of `A (W A)^s` with `A`'s
    /// off-diagonal entries left out and `Pi` replaced by the diagonal `w` (the caller's
    /// inverse masses, finite on a massless coordinate), `O(N)`; returns `max_i w_i |A_ii|`, a
    /// lower bound of the spectral radius of `W A`.
    pub(crate) fn newton_diagonal(
        &mut self,
        sys: &System,
        q: &[f64],
        w: &[f64],
        out: &mut [f64],
    ) -> Result<f64, SolveError> {
        self.metric.prepare(sys, q)?;
        Ok(self.paper.newton_diagonal(&self.metric, sys, q, w, out))
    }

    /// After [`Preadjustment::newton_diagonal`] at `q`: the constraint weights `-mu0` of
    /// `A = Hess V - mu0 . Hess Phi` there, and the diagonal of `M^-1` of the metric (a
    /// massless coordinate's regularised), for `W_1`'s Newton Hessian `A Pi A` on the sparse
    /// stage solve (`galerkin/sparse/projected.rs`).
    pub(crate) fn paper_stiffness_weights(&self) -> (&[f64], &[f64]) {
        (self.metric.neg_mu0(), self.metric.minv())
    }

    /// An approximate Hessian of `W_s` for Newton: `A (Pi A)^s` (exact at an equilibrium),
    /// symmetrised, into `out` (overwritten).
    ///
    /// `A` is symmetric, so its zero columns (coordinates that enter `V` and the constraints
    /// linearly, e.g. the positions of bodies with revolute joints under gravity) are zero rows
    /// too, and `A (Pi A)^s` lives on the block `K x K` of the other coordinates:
    /// `A_KK (Pi_KK A_KK)^s`, with `Pi_KK = M^-1_KK - (G M^-1)_K^T S^-1 (G M^-1)_K` from `|K|`
    /// Cholesky solves. Dense products of size `|K|` only.
    pub fn approximate_hessian(
        &mut self,
        sys: &System,
        q: &[f64],
        out: &mut DMatrix<f64>,
    ) -> Result<(), SolveError> {
        self.metric
            .require_dense("Preadjustment::approximate_hessian")?;
        self.metric.prepare(sys, q)?;
        self.paper
            .newton_hessian(&self.metric, &mut self.stiffness, sys, q, out);
        Ok(())
    }

    /// The leading position Hessian of [`Preadjustment::modified_term`] at `(q, v)`, up to its
    /// factor `-1/12`: `(A + H_sigma) Pi (A + H_sigma)` into `out` (overwritten), with
    /// `H_sigma = sum_k sigma_k Hess Phi_k`, `sigma = S^-1 gamma_c(q, v)` (the modified
    /// Lagrangian's Newton matrix, `galerkin/dense.rs`; docs/symplectic.md section 5a). At
    /// `v = 0` it is [`Preadjustment::approximate_hessian`] with `s = 1` to rounding; symmetric
    /// by construction ([`TangentStiffness::a_pi_a`]).
    pub(crate) fn modified_position_hessian(
        &mut self,
        sys: &System,
        q: &[f64],
        v: &[f64],
        out: &mut DMatrix<f64>,
    ) -> Result<(), SolveError> {
        self.metric
            .require_dense("Preadjustment::modified_position_hessian")?;
        self.metric.check_v(v)?;
        let n = self.metric.n();
        if out.shape() != (n, n) {
            return Err(SolveError::Dimension {
                what: "the modified position Hessian",
                expected: n,
                got: out.nrows(),
            });
        }
        self.s1.prepare(&mut self.metric, sys, q, v)?;
        self.s1
            .position_newton_hessian(&mut self.metric, &mut self.stiffness, sys, q, v, out);
        Ok(())
    }

    /// The velocity-dependent modified-Lagrangian term of the (1,1) scheme (without its `h^2`):
    /// `e(q, v) = -1/24 f_T^T M^-1 f_T + 1/12 v^T A v - 1/8 v^T Hess V v
    /// + 1/24 gamma_c^T S^-1 gamma_c` with `gamma_c,k = v^T Hess Phi_k v` (derivation in
    /// `docs/modified-lagrangian.md`, use in `docs/symplectic.md` section 5a). Independent of the
    /// `s` of the workspace.
    pub fn modified_term(&mut self, sys: &System, q: &[f64], v: &[f64]) -> Result<f64, SolveError> {
        self.metric.check_v(v)?;
        self.metric.prepare(sys, q)?;
        Ok(self.s1.evaluate(&mut self.metric, sys, q, v))
    }

    /// Gradients of [`Preadjustment::modified_term`], into `dq` and `dv`; returns `e(q, v)`.
    /// With `sigma = S^-1 gamma_c`, `H_sigma = sum_k sigma_k Hess Phi_k`, `u = M^-1 f_T` and
    /// `w = M^-1 Phi_q^T sigma` (derivation in `docs/symplectic.md` section 5a):
    ///
    /// * `d e / d v = 1/6 (A + H_sigma - 3/2 Hess V) v` (exact),
    /// * `d e / d q = 1/12 [(A + H_sigma)(u - w) + D^3(-1/2 V + (sigma - mu0) . Phi)(v, v)]`,
    ///   where the third-derivative term is the derivative along `v` of
    ///   `Hess(-1/2 V + (sigma - mu0) . Phi) v` (`sigma`, `mu0` frozen), exact
    ///   (`passes::lagrangian_third`).
    pub fn modified_gradients(
        &mut self,
        sys: &System,
        q: &[f64],
        v: &[f64],
        dq: &mut [f64],
        dv: &mut [f64],
    ) -> Result<f64, SolveError> {
        self.metric.check_v(v)?;
        let n = self.metric.n();
        if dq.len() != n || dv.len() != n {
            return Err(SolveError::Dimension {
                what: "gradient buffers of the modified-Lagrangian term",
                expected: n,
                got: dq.len().min(dv.len()),
            });
        }
        self.s1.prepare(&mut self.metric, sys, q, v)?;
        Ok(self.s1.gradients(&mut self.metric, sys, q, v, dq, dv))
    }

    /// `6 d^2 e / dv^2 = B + 2 C S^-1 C^T` at `q` into `out` (overwritten), with
    /// `B = A + H_sigma - 3/2 Hess V` (`H_sigma = sum_k sigma_k Hess Phi_k`,
    /// `sigma = S^-1 gamma_c(q, v)`) and `C = [Hess Phi_k v]_k` (the derivative of `sigma` in
    /// `v`), used for the Newton Jacobian.
    pub fn modified_velocity_hessian(
        &mut self,
        sys: &System,
        q: &[f64],
        v: &[f64],
        out: &mut DMatrix<f64>,
    ) -> Result<(), SolveError> {
        self.metric
            .require_dense("Preadjustment::modified_velocity_hessian")?;
        out.fill(0.0);
        self.add_modified_velocity_hessian(sys, q, v, 1.0, out)
    }

    /// `out += scale * (B + 2 C S^-1 C^T)` at `(q, v)` ([`Preadjustment::modified_velocity_hessian`]),
    /// without the overwrite, from one Hessian pass over the elements
    /// (`passes::add_lagrangian_hessian_pair`); the same pass assembles
    /// `A = Hess V - mu0 . Hess Phi`, which [`Preadjustment::approximate_hessian`] at the same `q`
    /// then reuses.
    pub fn add_modified_velocity_hessian(
        &mut self,
        sys: &System,
        q: &[f64],
        v: &[f64],
        scale: f64,
        out: &mut DMatrix<f64>,
    ) -> Result<(), SolveError> {
        self.metric
            .require_dense("Preadjustment::add_modified_velocity_hessian")?;
        self.metric.check_v(v)?;
        let n = self.metric.n();
        if out.shape() != (n, n) {
            return Err(SolveError::Dimension {
                what: "the modified velocity Hessian",
                expected: n,
                got: out.nrows(),
            });
        }
        self.metric.prepare(sys, q)?;
        self.s1
            .add_velocity_hessian(&mut self.metric, &mut self.stiffness, sys, q, v, scale, out);
        Ok(())
    }

    /// Diagonals of the `s = 1` Newton blocks at `(q, v)`, for the sparse stage solve
    /// (`docs/symplectic.md` section 5a), `O(N)`, overwritten: `wd = diag(B)` (the velocity
    /// Hessian `6 d^2 e / dv^2 = B + 2 C S^-1 C^T` without its dense part), `sd = diag(A_s)`
    /// (`A_s = Hess V + (sigma - mu0) . Hess Phi`, the position block's stiffness) and
    /// `ad_i = A_ii^2 / m_i` (the diagonal of `A M^-1 A`, the sparse part of `A Pi A`, with
    /// the off-diagonal entries of `A = Hess V - mu0 . Hess Phi` left out). Returns
    /// `max_i m_i^-1 |A_s,ii|` (the metric's `M^-1`), a lower bound of the spectral radius of
    /// `M^-1 A_s`.
    pub(crate) fn modified_newton_diagonals(
        &mut self,
        sys: &System,
        q: &[f64],
        v: &[f64],
        diagonals: [&mut [f64]; 3],
    ) -> Result<f64, SolveError> {
        self.metric.check_v(v)?;
        self.s1.prepare(&mut self.metric, sys, q, v)?;
        Ok(self
            .s1
            .newton_diagonals(&mut self.metric, sys, (q, v), diagonals))
    }

    /// After [`Preadjustment::modified_newton_diagonals`] at `(q, v)`: the constraint weights
    /// `sigma - mu0` of the stiffness `A_s = Hess V + (sigma - mu0) . Hess Phi` there, and the
    /// diagonal of `M^-1` of the metric (a massless coordinate's regularised), for the sparse
    /// position block `A_s Pi A_s` (`galerkin/sparse/projected.rs`).
    pub(crate) fn modified_stiffness_weights(&self) -> (&[f64], &[f64]) {
        (self.s1.stiffness_weights(), self.metric.minv())
    }

    /// The 23 terms of `e4(q, v)` (`E4_TERMS`, without their coefficients), at `q` with
    /// the velocity `v` (tangent, or a step's chord). Allocates its workspace on first use.
    pub fn modified_terms_s2(
        &mut self,
        sys: &System,
        q: &[f64],
        v: &[f64],
    ) -> Result<[f64; E4_TERM_COUNT], SolveError> {
        self.metric.check_v(v)?;
        self.metric.use_plain_inverse(sys);
        let term = modified_s2::ensure_s2(&mut self.s2, &self.metric, sys);
        term.forward(&mut self.metric, sys, q, v)?;
        Ok(term.terms())
    }

    /// The `h^4` modified-Lagrangian term of the (2,2) scheme, `e4(q, v) = sum_i c_i T_i`
    /// (`E4_TERMS`, [`Preadjustment::modified_terms_s2`]).
    pub fn modified_term_s2(
        &mut self,
        sys: &System,
        q: &[f64],
        v: &[f64],
    ) -> Result<f64, SolveError> {
        let t = self.modified_terms_s2(sys, q, v)?;
        Ok(modified_s2::e4_value(&t))
    }

    /// The value of `e4(q, v)` ([`Preadjustment::modified_term_s2`]) and its exact gradients
    /// `de4/dq` into `gq` and `de4/dv` into `gv` (both length n, overwritten), by one forward
    /// evaluation and a reverse pass. Allocates its workspace on first use only.
    pub fn modified_gradients_s2(
        &mut self,
        sys: &System,
        q: &[f64],
        v: &[f64],
        gq: &mut [f64],
        gv: &mut [f64],
    ) -> Result<f64, SolveError> {
        self.metric.check_v(v)?;
        let n = self.metric.n();
        for (what, got) in [("de4/dq", gq.len()), ("de4/dv", gv.len())] {
            if got != n {
                return Err(SolveError::Dimension {
                    what,
                    expected: n,
                    got,
                });
            }
        }
        self.metric.use_plain_inverse(sys);
        let term = modified_s2::ensure_s2(&mut self.s2, &self.metric, sys);
        term.gradients(&mut self.metric, sys, q, v, gq, gv)
    }
}
