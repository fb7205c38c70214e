//! The `h^4` modified-Lagrangian term `e4(q, v)` of the constrained (2,2) scheme
//! (`docs/modified-lagrangian.md` section 3: 23 invariant terms, fitted exactly in a graph frame
//! and checked against the pendulum family and under changes of coordinates and of the
//! constraint representation). The integrator adds `h^5 e4` at the chord midpoint of a (2,2)
//! step (`PreadjustMode::ModifiedLagrangian`).
//!
//! With `G = Phi_q`, `S = G M^-1 G^T`, `Pi` the tangent projector, `E = M^-1 G^T S^-1`,
//! `mu0 = S^-1 G M^-1 grad V`, `u = -Pi grad V`, `gamma_k = Hess Phi_k(v, v)`,
//! `sigma = S^-1 gamma`, `n = -E gamma`, `beta_k = Hess Phi_k(u, v)`, `K2 = -E beta`,
//! `kappa3_k = D^3 Phi_k(v, v, v) + 3 Hess Phi_k(n, v)`, `K3 = -E kappa3`,
//! `kappa3u_k = D^3 Phi_k(u, v, v) + 2 Hess Phi_k(K2, v) + Hess Phi_k(n, u)`,
//! `kappa4_k = D^4 Phi_k(v, v, v, v) + 6 D^3 Phi_k(n, v, v) + 3 Hess Phi_k(n, n) +
//! 4 Hess Phi_k(K3, v)`, `H = Hess V`, `H_mu = mu0 . Hess Phi`, `H_sigma = sigma . Hess Phi`,
//! the terms and their coefficients are those of [`E4_TERMS`]. The directional derivatives of
//! orders 2 to 4, mixed ones included, come from three passes of multivariate truncated
//! Taylor jets ([`mbd_model::PolyJet`], [`System::constraint_poly_series`],
//! [`System::potential_poly_series`]): pass A along `(v, u)`, pass B along `(v, n, u)` (after
//! `n`, which needs pass A's `gamma`), pass C along `(v, K2, K3)`; each keeps its coefficients'
//! gradients for the reverse pass.
//!
//! * `passes.rs`: the passes' monomial bases and their workspace ([`passes::Pass`]);
//! * `forward.rs`: the evaluation of the intermediates and the 23 terms;
//! * `reverse.rs`: the exact gradients by a reverse (adjoint) pass through the intermediates;
//! * `adjoints.rs`: the reverse pass's workspace.

use super::metric::ProjectedMetric;
use adjoints::{Adjoints, Cols};
use forward::E4Forward;
use mbd_model::System;

mod adjoints;
mod forward;
mod passes;
mod reverse;

/// The terms of `e4` and their coefficients, in the order of [`crate::Preadjustment::modified_terms_s2`]'s
/// evaluation (`S` in a name stands for `S^-1`).
pub(crate) const E4_TERMS: [(&str, f64); 23] = [
    ("v H_sigma Pi H_mu v", 1.0 / 720.0),
    ("v H_mu Pi H_mu v", -1.0 / 1440.0),
    ("u H_mu u", -1.0 / 960.0),
    ("v H_mu Pi H v", 1.0 / 720.0),
    ("beta S beta", 1.0 / 160.0),
    ("u H_sigma u", 1.0 / 960.0),
    ("kappa3 S beta", 1.0 / 240.0),
    ("v H K2", 1.0 / 240.0),
    ("mu0 . kappa3u", -1.0 / 480.0),
    ("sigma . kappa3u", 1.0 / 480.0),
    ("mu0 . kappa4", -1.0 / 2880.0),
    ("u H n", -1.0 / 720.0),
    ("u H u", -1.0 / 1440.0),
    ("D3V(u, v, v)", -1.0 / 720.0),
    ("n H n", -1.0 / 1440.0),
    ("v H Pi H_sigma v", -1.0 / 720.0),
    ("v H K3", 1.0 / 720.0),
    ("D3V(n, v, v)", -1.0 / 720.0),
    ("v H Pi H v", -1.0 / 1440.0),
    ("D4V(v, v, v, v)", -1.0 / 4320.0),
    ("v H_sigma Pi H_sigma v", -1.0 / 1440.0),
    ("sigma . kappa4", 1.0 / 2880.0),
    ("kappa3 S kappa3", 1.0 / 1440.0),
];

/// The term `e4` and the workspace of its value and gradients: the forward intermediates, the
/// adjoints and the element-local columns of the constraint rows.
#[derive(Debug)]
pub(crate) struct ModifiedS2 {
    f: E4Forward,
    b: Adjoints,
    /// The element-local columns of each constraint row ([`Cols`]).
    cols: Vec<Cols>,
}

impl ModifiedS2 {
    fn new(sys: &System) -> Self {
        let (n, m) = (sys.n_coords(), sys.n_constraints());
        let mut w = ModifiedS2 {
            f: E4Forward::new(n, m, sys.forces().len()),
            b: Adjoints::new(n, m),
            cols: vec![[None; 2]; m],
        };
        w.set_cols(sys);
        w
    }

    /// The element-local columns of every constraint row of `sys` (in place: the workspace
    /// follows the system it is used with, not only the one it was made for).
    fn set_cols(&mut self, sys: &System) {
        for (r, c) in self.cols.iter_mut().enumerate() {
            let (a, b) = sys
                .equation_joint(r)
                .map_or((None, None), |j| sys.joint_bodies(j));
            *c = [a.map(|i| 3 * i), b.map(|i| 3 * i)];
        }
    }
}

/// The `e4` workspace in `slot` for `sys` and `metric` (allocated on first use, or again when
/// the system's sizes changed; the constraint rows' columns follow `sys`).
pub(super) fn ensure_s2<'a>(
    slot: &'a mut Option<Box<ModifiedS2>>,
    metric: &ProjectedMetric,
    sys: &System,
) -> &'a mut ModifiedS2 {
    let fits = slot.as_ref().is_some_and(|w| {
        w.f.u.len() == metric.n()
            && w.cols.len() == metric.m()
            && w.f.pa.pgrads.len() == sys.forces().len()
    });
    if !fits {
        *slot = None;
    }
    let w = slot.get_or_insert_with(|| Box::new(ModifiedS2::new(sys)));
    if fits {
        w.set_cols(sys);
    }
    w
}
