//! Spatial bodies in the symplectic scheme: what it runs (the preadjusted schemes with their
//! limits), the momentum rows' scale on massless
//! coordinates and the end velocity by the constrained solve (docs/spatial.md, "The symplectic
//! scheme with a singular mass matrix").

use mbd_model::System;
use mbd_solve::{ConstrainedSolve, LinearSolver, SolveError};

/// What the symplectic scheme runs with spatial bodies: the plain (s,s) scheme on either
/// path, singular mass matrices included (their massless coordinates' momentum rows are force
/// balances, and the end velocity comes from the constrained solve); paper A's `W_s` (gamma)
/// and the modified Lagrangian on either path (a singular mass matrix
/// included: the dense metric of `W_s` and the s = 1 term uses the augmented `M_W^-1`, the
/// s = 2 term and the sparse layout a regularised diagonal on a massless director), angle
/// drivers included (each term evaluated with the constraints frozen at its point's time;
/// docs/spatial.md, "The preadjusted schemes"). Each refusal names what stands in the way.
pub(super) fn spatial_support(
    sys: &System,
    s: usize,
    modlag: bool,
    gamma: f64,
    linear: LinearSolver,
) -> Result<(), SolveError> {
    if !modlag && gamma == 0.0 {
        return Ok(());
    }
    let scheme = if modlag {
        format!("the ({s},{s}) modified-Lagrangian preadjustment (:modified)")
    } else {
        "paper A's preadjustment W_s (gamma != 0)".to_string()
    };
    if linear.use_sparse(sys.n_constraints()) {
        // the sparse layout (W_s's and the modified Lagrangian's): O(N), any size
        return Ok(());
    }
    mbd_solve::refuse_large_spatial(sys, &scheme, linear)
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
