//! Two weighted Lagrangian Hessians and the velocity-constraint Jacobian from one Hessian pass
//! over the elements ([`System::element_hessians`]): what the preadjustment's Newton matrix
//! needs when it combines the same element Hessians with two sets of multipliers
//! (`A = Hess V - mu0 . Hess Phi` and `B = p Hess V + w . Hess Phi`), at the cost of one
//! assembly instead of three passes.

use mbd_model::jet::NV;
use mbd_model::{Attach, ElementHessian, System};
use nalgebra::DMatrix;

/// One weighted Lagrangian `potential * V + sum_k weights_k Phi_k` (`weights` has length m):
/// the weights of one Hessian of [`add_lagrangian_hessian_pair`].
#[derive(Clone, Copy, Debug)]
pub(crate) struct LagrangianWeights<'a> {
    /// Weight of the potential `V`.
    pub(crate) potential: f64,
    /// Weights of the constraint equations (length m).
    pub(crate) constraints: &'a [f64],
}

/// In one Hessian pass over the forces and joints at `q`, for the pairs `(a, out_a)` and
/// `(b, out_b)`: `out_a += Hess(a.potential V + a.constraints . Phi)`,
/// `out_b += Hess(b.potential V + b.constraints . Phi)` (both n x n) and
/// `ct = (Phi_q v)_q` (m x n, overwritten; row `k` is `v^T Hess Phi_k`, as in
/// [`System::phi_q_dot_jacobian`]).
pub(crate) fn add_lagrangian_hessian_pair(
    sys: &System,
    q: &[f64],
    t: f64,
    v: &[f64],
    (a, out_a): (LagrangianWeights<'_>, &mut DMatrix<f64>),
    (b, out_b): (LagrangianWeights<'_>, &mut DMatrix<f64>),
    ct: &mut DMatrix<f64>,
) {
    ct.fill(0.0);
    let forces = a.potential != 0.0 || b.potential != 0.0;
    sys.element_hessians(q, forces, |el| {
        let (at, o, e) = match el {
            ElementHessian::Force(at, h) => {
                for (w, out) in [(a.potential, &mut *out_a), (b.potential, &mut *out_b)] {
                    if w != 0.0 {
                        at.scatter_hess(&scaled(h, w), out);
                    }
                }
                return;
            }
            ElementHessian::Joint {
                attach,
                row,
                equations,
                ..
            } => (attach, row, equations),
        };
        // the joint's local velocity
        let mut vl = [0.0; NV];
        for (slot, body) in [(0, at.a), (3, at.b)] {
            if let Some(i) = body {
                vl[slot..slot + 3].copy_from_slice(&v[3 * i..3 * i + 3]);
            }
        }
        let (mut ha, mut hb) = ([[0.0; NV]; NV], [[0.0; NV]; NV]);
        for (k, ek) in e.iter().enumerate() {
            let (wa, wb) = (a.constraints[o + k], b.constraints[o + k]);
            let mut hv = [0.0; NV];
            for r in 0..NV {
                for c in 0..NV {
                    let x = ek.h[r][c];
                    ha[r][c] += wa * x;
                    hb[r][c] += wb * x;
                    hv[r] += x * vl[c];
                }
            }
            at.scatter_row(o + k, &hv, ct);
        }
        at.scatter_hess(&ha, out_a);
        at.scatter_hess(&hb, out_b);
    });
    if sys.has_spatial() {
        // the spatial force elements and rows (the element pass hands out planar ones only)
        sys.add_spatial_force_hessian(q, a.potential, out_a);
        sys.add_spatial_force_hessian(q, b.potential, out_b);
        sys.add_spatial_constraint_hessian(q, t, a.constraints, 1.0, out_a);
        sys.add_spatial_constraint_hessian(q, t, b.constraints, 1.0, out_b);
        if sys.jacobian_depends_on_time() {
            // row k of ct is v^T Hess Phi_k, without the Phi_tq of an angle driver's row that
            // (Phi_q v + Phi_t)_q holds
            for r in 0..sys.n_constraints() {
                sys.spatial_row_hessian_at(q, t, r, |i, j, h| ct[(r, j)] += h * v[i]);
            }
        } else {
            sys.add_spatial_phi_q_dot(q, v, t, ct);
        }
    }
}

/// The diagonals of weighted Lagrangian Hessians of [`add_lagrangian_hessian_pair`], each
/// added into its `out` (length n), from one pass in `O(elements)` with nothing assembled
/// (diagonal Newton blocks on a sparse path): every planar element and the spatial constraint
/// rows (the spatial force elements are left out).
pub(crate) fn add_lagrangian_hessian_diagonals<const K: usize>(
    sys: &System,
    q: &[f64],
    t: f64,
    mut sets: [(LagrangianWeights<'_>, &mut [f64]); K],
) {
    // (the local diagonal h[l][l] of each of the element's bodies)
    let scatter = |at: Attach, h: &[[f64; NV]; NV], wk: f64, out: &mut [f64]| {
        for (slot, body) in [(0, at.a), (3, at.b)] {
            if let Some(i) = body {
                for l in 0..3 {
                    out[3 * i + l] += wk * h[slot + l][slot + l];
                }
            }
        }
    };
    let forces = sets.iter().any(|(w, _)| w.potential != 0.0);
    sys.element_hessians(q, forces, |el| match el {
        ElementHessian::Force(at, h) => {
            for (w, out) in sets.iter_mut() {
                scatter(at, h, w.potential, out);
            }
        }
        ElementHessian::Joint {
            attach: at,
            row: o,
            equations: e,
            ..
        } => {
            for (k, ek) in e.iter().enumerate() {
                for (w, out) in sets.iter_mut() {
                    scatter(at, &ek.h, w.constraints[o + k], out);
                }
            }
        }
    });
    if sys.has_spatial() {
        // the spatial rows' constant Hessians (the spatial force elements' Hessians are left
        // out: these diagonals only shape a Newton matrix)
        for r in 0..sys.n_constraints() {
            sys.spatial_row_hessian_at(q, t, r, |i, j, h| {
                if i == j {
                    for (w, out) in sets.iter_mut() {
                        out[i] += w.constraints[r] * h;
                    }
                }
            });
        }
    }
}

fn scaled(h: &[[f64; NV]; NV], w: f64) -> [[f64; NV]; NV] {
    let mut out = *h;
    for row in out.iter_mut() {
        for x in row.iter_mut() {
            *x *= w;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::{add_lagrangian_hessian_diagonals, add_lagrangian_hessian_pair, LagrangianWeights};
    use nalgebra::DMatrix;

    /// The pair equals two separate assemblies ([`System::potential_hessian`] and
    /// [`System::add_constraint_hessian`]) and `ct` equals
    /// [`System::phi_q_dot_jacobian`], and the diagonals alone equal theirs, on every
    /// joint kind and on a model with springs.
    #[test]
    fn pair_matches_separate_assemblies() {
        for sys in mbd_model::fixtures::derivative_test_systems() {
            let (n, m) = (sys.n_coords(), sys.n_constraints());
            let (q, v) = mbd_model::fixtures::generic_point(n);
            let wa: Vec<f64> = (0..m).map(|r| 0.7 - 0.3 * r as f64).collect();
            let wb: Vec<f64> = (0..m).map(|r| -0.2 + 0.11 * r as f64).collect();
            let (mut a, mut b) = (DMatrix::from_element(n, n, 0.25), DMatrix::zeros(n, n));
            let mut ct = DMatrix::from_element(m, n, 9.0);
            add_lagrangian_hessian_pair(
                &sys,
                &q,
                0.0,
                &v,
                (
                    LagrangianWeights {
                        potential: 1.0,
                        constraints: &wa,
                    },
                    &mut a,
                ),
                (
                    LagrangianWeights {
                        potential: -0.5,
                        constraints: &wb,
                    },
                    &mut b,
                ),
                &mut ct,
            );
            let mut hv = DMatrix::zeros(n, n);
            sys.potential_hessian(&q, &mut hv);
            let mut ea = DMatrix::from_element(n, n, 0.25) + &hv;
            sys.add_constraint_hessian(&q, 0.0, &wa, 1.0, &mut ea);
            let mut eb = &hv * -0.5;
            sys.add_constraint_hessian(&q, 0.0, &wb, 1.0, &mut eb);
            let (mut gq, mut ect) = (DMatrix::zeros(m, n), DMatrix::zeros(m, n));
            sys.phi_q_dot_jacobian(&q, &v, 0.0, &mut gq, &mut ect);
            let close = |x: &DMatrix<f64>, y: &DMatrix<f64>, what: &str| {
                let scale = 1.0 + y.amax();
                assert!((x - y).amax() < 1e-13 * scale, "{what}: {}", (x - y).amax());
            };
            close(&a, &ea, "out_a");
            close(&b, &eb, "out_b");
            close(&ct, &ect, "ct");
            // the diagonals alone, added to what the buffers hold
            let (mut da, mut db) = (vec![0.5; n], vec![0.0; n]);
            add_lagrangian_hessian_diagonals(
                &sys,
                &q,
                0.0,
                [
                    (
                        LagrangianWeights {
                            potential: 1.0,
                            constraints: &wa,
                        },
                        &mut da,
                    ),
                    (
                        LagrangianWeights {
                            potential: -0.5,
                            constraints: &wb,
                        },
                        &mut db,
                    ),
                ],
            );
            for i in 0..n {
                let tol = 1e-13 * (1.0 + ea[(i, i)].abs() + eb[(i, i)].abs());
                assert!(
                    (da[i] - (ea[(i, i)] - 0.25 + 0.5)).abs() < tol,
                    "diag a {i}"
                );
                assert!((db[i] - eb[(i, i)]).abs() < tol, "diag b {i}");
            }
        }
    }
}
