//! A projected-stiffness Newton block of the (1,1) scheme on the sparse path, exactly and in
//! `O(N)`: `c M^-1 A_s Pi A_s`, the s = 1 modified Lagrangian's position block
//! (`A_s = Hess V + (sigma - mu0) . Hess Phi`, the stiffness of the whole multiplier) or paper
//! A's `W_1` Newton Hessian (`A_s = A = Hess V - mu0 . Hess Phi`, `c = -h^2 a b gk` of the
//! one Gauss point), with `Pi = M^-1 - M^-1 G^T S^-1 G M^-1`. It is dense, but it is the Schur
//! complement of a sparse block: with `n + m` more unknowns `y`, `z` the stage Jacobian gets
//! the rows
//!
//! ```text
//!   momentum:  J0 x + c M^-1 A_s y              = r
//!   y:         A_s x - M y + G^T z              = 0
//!   z:                     G y                  = 0
//! ```
//!
//! and eliminating `y`, `z` (`y = Pi A_s x`) leaves `(J0 + c M^-1 A_s Pi A_s) x = r`, the dense
//! path's block (docs/symplectic.md section 5a). `A_s` and `G` are element-local, so the
//! augmented matrix is as sparse as the stage Jacobian and its LU stays `O(N)` on chains.
//!
//! Its LU costs two to three times the stage Jacobian's, and the block only pays where it is
//! not small against the identity: its norm is `|c| rho^2` (`c = -h^4 / 48` for the modified
//! Lagrangian, `rho` the spectral radius of `M^-1 A_s`). A Jacobian whose bound is below
//! [`PROJECTED_BLOCK_THRESHOLD`] factors the stage matrix alone, with a diagonal in the
//! block's place.

use super::{SparseStage, NONE};
use mbd_model::System;
use mbd_solve::linalg::LuError;
use mbd_solve::sparse::{ColumnOrder, SparseLu};

/// The bound `|c| rho^2` on the block's norm (against the identity of the stage
/// Jacobian) from which a Jacobian takes the exact block. Below it the diagonal leaves a
/// chord iteration that contracts by about this factor or better; measured (the modified
/// Lagrangian on planar and spatial chains, docs/symplectic.md section 5a) the exact block
/// saved no iteration where the bound was `3.4e-3` or below and saved 30 to 60% of them from
/// `0.17` up, while its LU costs two to three times the stage Jacobian's.
pub(crate) const PROJECTED_BLOCK_THRESHOLD: f64 = 0.1;

/// Pattern, slots and workspaces of the augmented block.
#[derive(Debug)]
pub(in crate::galerkin) struct ProjectedStiffness {
    /// The entries `(i, l)` of `A_s`'s pattern, sorted; their values at the last Jacobian,
    /// and their slots in the `y` rows (`(y_i, Z_1,l)`) and the momentum rows (`(i, y_l)`).
    ent: Vec<(usize, usize)>,
    aval: Vec<f64>,
    yslot: Vec<usize>,
    mslot: Vec<usize>,
    /// Slots `(y_i, y_i)`.
    dslot: Vec<usize>,
    /// Per local value `k` of the constraint rows: slots `(y_vcol[k], z_r)` and
    /// `(z_r, y_vcol[k])`.
    gyz: Vec<usize>,
    gzy: Vec<usize>,
    /// Slots `(z_r, z_r)` of a model with redundant equations (else empty): a dropped row's
    /// `z` is pinned.
    zdiag: Vec<usize>,
    /// The right-hand side and solution of a stage solve (the stage's unknowns, then `y`, `z`).
    rhs: Vec<f64>,
    /// The augmented matrix and its LU, and the slot in it of each slot of the stage
    /// Jacobian's.
    lu: SparseLu,
    map: Vec<usize>,
    /// Whether the last Jacobian took the block (`lu` is the factored matrix).
    active: bool,
}

/// `f(i, l, value)` for the entries of `sum_r w_r Hess Phi_r` at `(q, t)`: the planar joints'
/// local Hessians and the spatial rows' nonzeros.
fn constraint_hessian_entries(
    sys: &System,
    q: &[f64],
    t: f64,
    w: &[f64],
    mut f: impl FnMut(usize, usize, f64),
) {
    sys.element_hessians(q, false, |el| {
        if let mbd_model::ElementHessian::Joint {
            attach,
            row,
            equations,
            ..
        } = el
        {
            let coord = |k: usize| {
                if k < 3 {
                    attach.a.map(|i| 3 * i + k)
                } else {
                    attach.b.map(|i| 3 * i + k - 3)
                }
            };
            for (k, ek) in equations.iter().enumerate() {
                let wk = w[row + k];
                for (a, ha) in ek.h.iter().enumerate() {
                    let Some(i) = coord(a) else { continue };
                    for (c, &x) in ha.iter().enumerate() {
                        if x != 0.0 {
                            if let Some(l) = coord(c) {
                                f(i, l, wk * x);
                            }
                        }
                    }
                }
            }
        }
    });
    if sys.has_spatial() {
        for (r, &wr) in w.iter().enumerate() {
            sys.spatial_row_hessian_at(q, t, r, |i, l, x| f(i, l, wr * x));
        }
    }
}

impl ProjectedStiffness {
    /// The block for the (1,1) stage Jacobian of `sys` (`n + m` unknowns, the pattern
    /// `entries`, analysed in `base`): the augmented pattern and its analysis. `A_s`'s pattern
    /// is taken from the constraint Hessians at a generic configuration (the initial guess,
    /// perturbed) and the force entries `fent`.
    pub(super) fn new(
        sys: &System,
        (vcol, rstart): (&[usize], &[usize]),
        fent: &[(usize, usize)],
        entries: &[(usize, usize)],
        base: &SparseLu,
    ) -> Result<Self, mbd_solve::linalg::LinalgError> {
        let (n, m) = (sys.n_coords(), sys.n_constraints());
        let (y0, z0) = (n + m, 2 * n + m);
        let mut q: Vec<f64> = sys.initial_guess().0.iter().copied().collect();
        for (k, x) in q.iter_mut().enumerate() {
            // (a generic point: no angle where a Hessian entry vanishes by accident)
            *x += 0.05 * ((k as f64 * 0.618_033_988_749_895).fract() - 0.5);
        }
        let ones = vec![1.0; m];
        let mut ent: Vec<(usize, usize)> = fent.to_vec();
        constraint_hessian_entries(sys, &q, 0.37, &ones, |i, l, _| ent.push((i, l)));
        ent.sort_unstable();
        ent.dedup();
        let mut all = entries.to_vec();
        for &(i, l) in &ent {
            all.push((y0 + i, l));
            all.push((i, y0 + l));
        }
        for i in 0..n {
            all.push((y0 + i, y0 + i));
        }
        for r in 0..m {
            for &c in &vcol[rstart[r]..rstart[r + 1]] {
                all.push((y0 + c, z0 + r));
                all.push((z0 + r, y0 + c));
            }
        }
        let redundant = sys.dependency_budget() > 0;
        if redundant {
            for r in 0..m {
                all.push((z0 + r, z0 + r));
            }
        }
        let lu = SparseLu::with_order(2 * (n + m), &all, ColumnOrder::SymmetricAmd)?;
        let mut map = vec![NONE; base.nnz()];
        for &(r, c) in entries {
            if let (Some(k), Some(ka)) = (base.slot(r, c), lu.slot(r, c)) {
                map[k] = ka;
            }
        }
        let slot = |r: usize, c: usize| lu.slot(r, c).unwrap_or(NONE);
        let mut gyz = vec![NONE; vcol.len()];
        let mut gzy = vec![NONE; vcol.len()];
        for r in 0..m {
            for k in rstart[r]..rstart[r + 1] {
                gyz[k] = slot(y0 + vcol[k], z0 + r);
                gzy[k] = slot(z0 + r, y0 + vcol[k]);
            }
        }
        Ok(ProjectedStiffness {
            aval: vec![0.0; ent.len()],
            yslot: ent.iter().map(|&(i, l)| slot(y0 + i, l)).collect(),
            mslot: ent.iter().map(|&(i, l)| slot(i, y0 + l)).collect(),
            dslot: (0..n).map(|i| slot(y0 + i, y0 + i)).collect(),
            gyz,
            gzy,
            zdiag: if redundant {
                (0..m).map(|r| slot(z0 + r, z0 + r)).collect()
            } else {
                Vec::new()
            },
            rhs: vec![0.0; 2 * (n + m)],
            ent,
            lu,
            map,
            active: false,
        })
    }

    /// Whether the last Jacobian took the block.
    pub(in crate::galerkin) fn is_active(&self) -> bool {
        self.active
    }

    /// The last Jacobian did not take the block.
    pub(super) fn deactivate(&mut self) {
        self.active = false;
    }

    /// Solves the factored augmented matrix for the stage unknowns `b` (in place; `y`, `z`
    /// start at zero and are dropped).
    pub(in crate::galerkin) fn solve_in_place(&mut self, b: &mut [f64]) {
        let k = b.len();
        self.rhs[..k].copy_from_slice(b);
        self.rhs[k..].fill(0.0);
        self.lu.solve_in_place(&mut self.rhs);
        b.copy_from_slice(&self.rhs[..k]);
    }

    /// Factors the augmented matrix.
    pub(super) fn factor(&mut self) -> Result<(), LuError> {
        self.lu.factor()
    }
}

/// Whether a Jacobian takes the exact block: `|c| rho^2 >= PROJECTED_BLOCK_THRESHOLD`, with
/// `rho = max_i w_i |A_ii|` from the diagonal pass of the block's stiffness (a lower bound of
/// the spectral radius of `M^-1 A`: each term is a Rayleigh quotient of `M^-1/2 A M^-1/2`).
pub(super) fn takes_block(sp: &SparseStage, rho: f64, c: f64) -> bool {
    sp.proj.is_some() && c.abs() * rho * rho >= PROJECTED_BLOCK_THRESHOLD
}

/// The position block's stiffness `A_s = Hess V + cm . Hess Phi` at the chord midpoint `q`
/// (time `t`): the force entries' values `hq` (at the Gauss point, which for s = 1 is the
/// midpoint) and the constraint Hessians weighted by `cm`.
fn assemble(sp: &mut SparseStage, sys: &System, (q, t): (&[f64], f64), cm: &[f64]) {
    let Some(ps) = sp.proj.as_deref_mut() else {
        return;
    };
    ps.aval.fill(0.0);
    let ent = &ps.ent;
    let aval = &mut ps.aval;
    for (e, &(i, l)) in sp.fent.iter().enumerate() {
        if let Ok(k) = ent.binary_search(&(i, l)) {
            aval[k] += sp.hq[e];
        }
    }
    constraint_hessian_entries(sys, q, t, cm, |i, l, x| {
        if let Ok(k) = ent.binary_search(&(i, l)) {
            aval[k] += x;
        }
    });
}

/// Where [`takes_block`] holds: the stage Jacobian just filled in `sp.lu` (not factored) goes
/// into the augmented matrix with `A_s = Hess V + cm . Hess Phi` at `q` (time `t`; the chord
/// midpoint, which for s = 1 is the Gauss point), `c minv_rows A_s` in the momentum rows,
/// `-M` (`M = 1 / mass_inv`, the metric's regularised inverse) and `G` (the end point's local gradients `grads`); a row
/// dropped as dependent (`dep`) pins its `z`.
#[allow(clippy::too_many_arguments)]
pub(super) fn fill(
    sp: &mut SparseStage,
    sys: &System,
    at: (&[f64], f64),
    cm: &[f64],
    mass_inv: &[f64],
    minv_rows: &[f64],
    grads: &[f64],
    c: f64,
) {
    assemble(sp, sys, at, cm);
    let Some(ps) = sp.proj.as_deref_mut() else {
        return;
    };
    ps.active = true;
    let base = sp.lu.values();
    let vals = ps.lu.values_mut();
    vals.fill(0.0);
    for (&k, &x) in ps.map.iter().zip(base) {
        if k != NONE {
            vals[k] = x;
        }
    }
    for (e, &(i, _)) in ps.ent.iter().enumerate() {
        let a = ps.aval[e];
        if ps.yslot[e] != NONE {
            vals[ps.yslot[e]] = a;
        }
        if ps.mslot[e] != NONE {
            vals[ps.mslot[e]] = c * minv_rows[i] * a;
        }
    }
    for (&d, &mi) in ps.dslot.iter().zip(mass_inv) {
        if d != NONE {
            vals[d] = if mi > 0.0 { -1.0 / mi } else { -1.0 };
        }
    }
    for (k, &g) in grads.iter().enumerate() {
        for slot in [ps.gyz[k], ps.gzy[k]] {
            if slot != NONE {
                vals[slot] = g;
            }
        }
    }
    for &r in &sp.dep {
        for k in sp.rstart[r]..sp.rstart[r + 1] {
            for slot in [ps.gyz[k], ps.gzy[k]] {
                if slot != NONE {
                    vals[slot] = 0.0;
                }
            }
        }
        if let Some(&d) = ps.zdiag.get(r) {
            if d != NONE {
                vals[d] = 1.0;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::PROJECTED_BLOCK_THRESHOLD;

    /// docs/symplectic.md states the threshold the code uses.
    #[test]
    fn the_docs_state_the_threshold() {
        let doc = include_str!("../../../../../docs/symplectic.md");
        let stated = format!("`|c| rho^2 >= {PROJECTED_BLOCK_THRESHOLD}`");
        assert!(doc.contains(&stated), "docs/symplectic.md lacks '{stated}'");
    }
}
