//! The constraint curvature `sum_r lambda_r Hess(Phi_r)` at the interior control points of the
//! sparse stage Jacobian: from coloured seed passes over the rows (`System::local_rows_tan`),
//! or, for rows whose Hessian is constant (`System::constant_hessian_rows`: the quadratic
//! spatial rows), from the local Hessians the first Jacobian keeps (docs/symplectic.md,
//! "Sparse stage solve").

use super::{SparseStage, NONE};
use crate::tables::Tables;
use mbd_model::System;

/// Adds `-h^2 M^-1 lambda_nu . Hess(Phi)(Q_nu)` for the interior control points `nu = 1..s-1`
/// into the stage Jacobian's values (`qn`: the control points, `x`: the unknowns, their
/// multipliers after the `s n` displacements; `minv`: the momentum rows' scale).
#[allow(clippy::too_many_arguments)]
pub(super) fn add(
    sp: &mut SparseStage,
    sys: &System,
    qn: &[f64],
    x: &[f64],
    tab: &Tables,
    minv: &[f64],
    (n, m): (usize, usize),
    (t, h): (f64, f64),
) {
    let s = tab.s;
    let h2 = h * h;
    // constraint curvature at the interior control points: `lambda_r Hess Phi_r` row by
    // row, from the seed passes (rows whose Hessian varies, and every row at the first
    // Jacobian, which keeps the constant ones) or from the kept constant Hessians
    let rheonomic = sys.jacobian_depends_on_time();
    let nc = sp.cstart.last().copied().unwrap_or(0);
    let cached = sp.hess_ready;
    for nu in 1..s {
        let q = &qn[nu * n..(nu + 1) * n];
        let tn = t + tab.tau[nu] * h;
        let lam = &x[s * n + nu * m..s * n + (nu + 1) * m];
        if rheonomic && (!cached || sp.hess_varies) {
            // (Phi_q 0 + Phi_t)_q = Phi_tq: not curvature, subtracted below
            sp.rows
                .gather_tan(sys, q, &sp.zero, tn, &mut sp.gscratch, &mut sp.dtime);
        }
        for (k, blocks) in sp.color_blocks.iter().enumerate() {
            if cached && !sp.hess_varies {
                break;
            }
            for l in 0..sp.max_width {
                let mut any = false;
                for &b in blocks {
                    let (c0, w) = sp.blocks[b];
                    if l < w {
                        sp.vdir[c0 + l] = 1.0;
                        any = true;
                    }
                }
                if !any {
                    continue;
                }
                sp.rows
                    .gather_tan(sys, q, &sp.vdir, tn, &mut sp.gscratch, &mut sp.dgrads);
                for &b in blocks {
                    let (c0, w) = sp.blocks[b];
                    if l < w {
                        sp.vdir[c0 + l] = 0.0;
                    }
                }
                if rheonomic {
                    for (d, z) in sp.dgrads.iter_mut().zip(&sp.dtime) {
                        *d -= z;
                    }
                }
                let vals = sp.lu.values_mut();
                for (r, sides) in sp.rows.sides().iter().enumerate() {
                    let constant = sp.hess_const[r];
                    if cached && constant {
                        continue;
                    }
                    let (r0, len) = (sp.rstart[r], sp.rstart[r + 1] - sp.rstart[r]);
                    for side in sides.iter().flatten() {
                        if sp.color[side.block] != k || l >= side.width {
                            continue;
                        }
                        let a = side.off - r0 + l;
                        let at = sp.cstart[r] + a * len;
                        if constant {
                            sp.hess[at..at + len].copy_from_slice(&sp.dgrads[r0..r0 + len]);
                        }
                        let lr = lam[r];
                        if lr == 0.0 {
                            continue;
                        }
                        let f = -h2 * minv[side.col + l] * lr;
                        let sl = &sp.curv_slot[(nu - 1) * nc + at..(nu - 1) * nc + at + len];
                        for (&slot, &d) in sl.iter().zip(&sp.dgrads[r0..r0 + len]) {
                            if slot != NONE {
                                vals[slot] += f * d;
                            }
                        }
                    }
                }
            }
        }
        if cached {
            let vals = sp.lu.values_mut();
            for (r, sides) in sp.rows.sides().iter().enumerate() {
                let lr = lam[r];
                if !sp.hess_const[r] || lr == 0.0 {
                    continue;
                }
                let (r0, len) = (sp.rstart[r], sp.rstart[r + 1] - sp.rstart[r]);
                for side in sides.iter().flatten() {
                    for l in 0..side.width {
                        let at = sp.cstart[r] + (side.off - r0 + l) * len;
                        let f = -h2 * minv[side.col + l] * lr;
                        let sl = &sp.curv_slot[(nu - 1) * nc + at..(nu - 1) * nc + at + len];
                        for (&slot, &d) in sl.iter().zip(&sp.hess[at..at + len]) {
                            if slot != NONE {
                                vals[slot] += f * d;
                            }
                        }
                    }
                }
            }
        }
    }
    if s > 1 {
        sp.hess_ready = true;
    }
}
