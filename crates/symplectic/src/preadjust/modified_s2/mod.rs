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
//! the terms and their coefficients are those of [`E4_TERMS`], each named by an [`Invariant`]
//! (the term values are a [`PerInvariant`], indexed by name). The directional derivatives of
//! orders 2 to 4, mixed ones included, come from three passes of multivariate truncated
//! Taylor jets ([`mbd_model::PolyJet`], [`passes::constraint_poly_series`](crate::passes::constraint_poly_series),
//! [`passes::potential_poly_series`](crate::passes::potential_poly_series)): pass A along `(v, u)`, pass B along `(v, n, u)` (after
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
mod spatial;
mod spatial_potential;

/// The invariants of `e4` (module doc for the symbols), in the order of [`E4_TERMS`]: the
/// term values ([`PerInvariant`]) and the public arrays of
/// [`crate::Preadjustment::modified_terms_s2`] are indexed by them.
// (the names spell the formulas: `UHN` is `u H n`)
#[allow(clippy::upper_case_acronyms)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Invariant {
    /// `v H_sigma Pi H_mu v`
    VHsigPiHmuV,
    /// `v H_mu Pi H_mu v`
    VHmuPiHmuV,
    /// `u H_mu u`
    UHmuU,
    /// `v H_mu Pi H v`
    VHmuPiHV,
    /// `beta S^-1 beta`
    BetaSBeta,
    /// `u H_sigma u`
    UHsigU,
    /// `kappa3 S^-1 beta`
    Kappa3SBeta,
    /// `v H K2`
    VHK2,
    /// `mu0 . kappa3u`
    Mu0Kappa3u,
    /// `sigma . kappa3u`
    SigmaKappa3u,
    /// `mu0 . kappa4`
    Mu0Kappa4,
    /// `u H n`
    UHN,
    /// `u H u`
    UHU,
    /// `D^3 V(u, v, v)`
    D3VUVV,
    /// `n H n`
    NHN,
    /// `v H Pi H_sigma v`
    VHPiHsigV,
    /// `v H K3`
    VHK3,
    /// `D^3 V(n, v, v)`
    D3VNVV,
    /// `v H Pi H v`
    VHPiHV,
    /// `D^4 V(v, v, v, v)`
    D4V,
    /// `v H_sigma Pi H_sigma v`
    VHsigPiHsigV,
    /// `sigma . kappa4`
    SigmaKappa4,
    /// `kappa3 S^-1 kappa3`
    Kappa3SKappa3,
}

/// The number of invariants of `e4`.
pub(crate) const E4_TERM_COUNT: usize = Invariant::Kappa3SKappa3 as usize + 1;

/// One invariant of `e4` with its name (`S` stands for `S^-1`) and its coefficient.
#[derive(Clone, Copy, Debug)]
pub(crate) struct E4Term {
    pub(crate) invariant: Invariant,
    /// (Read by the tests, which compare the terms by name.)
    #[cfg_attr(not(test), allow(dead_code))]
    pub(crate) name: &'static str,
    pub(crate) coefficient: f64,
}

const fn term(invariant: Invariant, name: &'static str, coefficient: f64) -> E4Term {
    E4Term {
        invariant,
        name,
        coefficient,
    }
}

/// The invariants of `e4` with their names and coefficients
/// (`e4 = sum_i coefficient_i T_i`), in the order of [`Invariant`].
pub(crate) const E4_TERMS: [E4Term; E4_TERM_COUNT] = {
    use Invariant::*;
    [
        term(VHsigPiHmuV, "v H_sigma Pi H_mu v", 1.0 / 720.0),
        term(VHmuPiHmuV, "v H_mu Pi H_mu v", -1.0 / 1440.0),
        term(UHmuU, "u H_mu u", -1.0 / 960.0),
        term(VHmuPiHV, "v H_mu Pi H v", 1.0 / 720.0),
        term(BetaSBeta, "beta S beta", 1.0 / 160.0),
        term(UHsigU, "u H_sigma u", 1.0 / 960.0),
        term(Kappa3SBeta, "kappa3 S beta", 1.0 / 240.0),
        term(VHK2, "v H K2", 1.0 / 240.0),
        term(Mu0Kappa3u, "mu0 . kappa3u", -1.0 / 480.0),
        term(SigmaKappa3u, "sigma . kappa3u", 1.0 / 480.0),
        term(Mu0Kappa4, "mu0 . kappa4", -1.0 / 2880.0),
        term(UHN, "u H n", -1.0 / 720.0),
        term(UHU, "u H u", -1.0 / 1440.0),
        term(D3VUVV, "D3V(u, v, v)", -1.0 / 720.0),
        term(NHN, "n H n", -1.0 / 1440.0),
        term(VHPiHsigV, "v H Pi H_sigma v", -1.0 / 720.0),
        term(VHK3, "v H K3", 1.0 / 720.0),
        term(D3VNVV, "D3V(n, v, v)", -1.0 / 720.0),
        term(VHPiHV, "v H Pi H v", -1.0 / 1440.0),
        term(D4V, "D4V(v, v, v, v)", -1.0 / 4320.0),
        term(VHsigPiHsigV, "v H_sigma Pi H_sigma v", -1.0 / 1440.0),
        term(SigmaKappa4, "sigma . kappa4", 1.0 / 2880.0),
        term(Kappa3SKappa3, "kappa3 S kappa3", 1.0 / 1440.0),
    ]
};

// E4_TERMS lists the invariants in their order (checked at compile time).
const _: () = {
    let mut i = 0;
    while i < E4_TERM_COUNT {
        assert!(E4_TERMS[i].invariant as usize == i);
        i += 1;
    }
};

/// One value per invariant of `e4` (the terms, or their coefficients), indexed by
/// [`Invariant`].
#[derive(Clone, Copy, Debug)]
pub(crate) struct PerInvariant(pub(crate) [f64; E4_TERM_COUNT]);

impl PerInvariant {
    /// The coefficients of [`E4_TERMS`].
    pub(crate) fn coefficients() -> Self {
        PerInvariant(std::array::from_fn(|i| E4_TERMS[i].coefficient))
    }
}

impl std::ops::Index<Invariant> for PerInvariant {
    type Output = f64;
    fn index(&self, t: Invariant) -> &f64 {
        &self.0[t as usize]
    }
}

impl std::ops::IndexMut<Invariant> for PerInvariant {
    fn index_mut(&mut self, t: Invariant) -> &mut f64 {
        &mut self.0[t as usize]
    }
}

/// `e4 = sum_i c_i T_i` from the terms `T_i` (in the order of [`E4_TERMS`]).
pub(crate) fn e4_value(terms: &[f64; E4_TERM_COUNT]) -> f64 {
    terms
        .iter()
        .zip(E4_TERMS.iter())
        .map(|(x, t)| t.coefficient * x)
        .sum()
}

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

/// Whether `sys` has force elements with a potential (planar ones, or spatial springs and
/// constant global forces): without them `V` is gravity alone, linear, and every term with
/// `Hess V` or a higher derivative of `V` vanishes.
pub(super) fn has_potential(sys: &System) -> bool {
    !sys.forces().is_empty() || sys.spatial_force_elements().any(|e| e.has_potential())
}
