//! Spatial bodies in the symplectic scheme: what it runs, the momentum rows' scale on massless
//! coordinates and the end velocity by the constrained solve (docs/spatial.md, "The symplectic
//! scheme with a singular mass matrix").

use mbd_model::System;
use mbd_solve::{ConstrainedSolve, SolveError};

/// What the symplectic scheme runs with spatial bodies: the plain (s,s) scheme on the dense
/// path, singular mass matrices included (their massless coordinates' momentum rows are force
/// balances, and the end velocity comes from the constrained solve). The preadjustments'
/// derivative passes are planar.
pub(super) fn spatial_support(sys: &System, modlag: bool, gamma: f64) -> Result<(), SolveError> {
    if modlag || gamma != 0.0 {
        return mbd_solve::refuse_spatial(
            sys,
            "the preadjusted symplectic scheme (gamma or :modified)",
        );
    }
    Ok(())
}

/// The momentum rows' scale ([`Galerkin`]'s `minv`): `M^-1`, and on a massless coordinate of
/// a spatial body the inverse of that body's largest second moment.
pub(super) fn row_scale(sys: &System) -> Vec<f64> {
    let mut w = sys.inv_mass_diag().as_slice().to_vec();
    let q0 = sys.spatial_offset();
    for (k, b) in sys.spatial_bodies().iter().enumerate() {
        let e = b.inertia.second_moments();
        let e_max = e[0].max(e[1]).max(e[2]);
        for x in &mut w[q0 + 12 * k + 3..q0 + 12 * k + 12] {
            if !x.is_finite() {
                *x = 1.0 / e_max;
            }
        }
    }
    w
}

/// The end velocity of a model with spatial bodies: `M v + Phi_q^T mu = p`,
/// `Phi_q v = -Phi_t` at the end of the step.
#[derive(Debug)]
pub(super) struct EndSolve {
    pub(super) solve: ConstrainedSolve,
    pub(super) p: Vec<f64>,
    pub(super) r: Vec<f64>,
}
