//! The constant Hessians of the spatial rows. Every spatial equation is quadratic in the
//! natural coordinates (docs/spatial.md), so its Hessian is the same at every `q`, and but for
//! an angle driver's at every `t`: it is evaluated once, by one pass of Hessian jets, and kept as
//! its nonzeros in global columns. An angle driver's equation `cos theta(t) E_0 - sin theta(t)
//! E_1` combines two bilinear components with constant Hessians, kept side by side, so its
//! Hessian at any `t` is `cos theta H_0 - sin theta H_1` ([`ConstantHessians::row_at`]). The
//! weighted Hessian `sum_r w_r Hess Phi_r` and the products
//! `sum_r w_r Hess Phi_r x` are then sums over those nonzeros, where each evaluation took a pass
//! of 24-variable Hessian jets over every row (the dense symplectic Newton matrix and the
//! preadjustments' passes call them at every iteration).

use super::{Item, SpatialPart, SW};
use mbd_jet::{HessJetN, Scalar};

/// An angle driver's row: the driver's index among the spatial joints and the nonzeros of its
/// two components' Hessians, `(row column, column, H_0, H_1)`.
type AngleRow = (usize, Vec<(usize, usize, f64, f64)>);

/// Per spatial row (in the order of the rows), its Hessian's nonzeros `(row column, column,
/// value)`, or `None` where the Hessian depends on time (an angle driver's rows, kept as
/// [`AngleRow`]s).
#[derive(Clone, Debug, Default)]
pub(crate) struct ConstantHessians {
    rows: Vec<Option<Vec<(usize, usize, f64)>>>,
    angle: Vec<Option<AngleRow>>,
}

/// `f(row column, column, value)` for every entry of an element's local Hessian `h` whose
/// local variables are coordinates (not ground, not a point mass's absent directors).
pub(super) fn for_each_entry(
    part: &SpatialPart,
    sides: [Option<usize>; 2],
    h: &[[f64; SW]; SW],
    mut f: impl FnMut(usize, usize, f64),
) {
    for (r, hr) in h.iter().enumerate() {
        let Some(gr) = part.col(sides, r) else {
            continue;
        };
        for (c, &x) in hr.iter().enumerate() {
            if let Some(gc) = part.col(sides, c) {
                f(gr, gc, x);
            }
        }
    }
}

impl ConstantHessians {
    /// The Hessians of `part`'s rows, evaluated at `q` (any configuration: they are constant).
    pub(super) fn new(part: &SpatialPart, q: &[f64]) -> Self {
        let mut rows = vec![None; part.m];
        let mut angle = vec![None; part.m];
        for (item, sides, row, n) in part.items() {
            if let Item::Joint(j) = item {
                if part.lowered[j].kind() == crate::spatial::joints::SpatialJointKind::AngleDriver {
                    // the two bilinear components, before `combine_angle` turns them by theta
                    let [fa, fb] = part.frames(sides, |l, c| HessJetN::<SW>::var(l, q[c]));
                    let mut e = [HessJetN::<SW>::cst(0.0); 6];
                    part.lowered[j].eval(&fa, &fb, &mut e);
                    let mut nz = Vec::new();
                    for_each_entry(part, sides, &e[0].h, |r, c, h0| nz.push((r, c, h0, 0.0)));
                    let mut k = 0;
                    for_each_entry(part, sides, &e[1].h, |_, _, h1| {
                        nz[k].3 = h1;
                        k += 1;
                    });
                    nz.retain(|&(_, _, h0, h1)| h0 != 0.0 || h1 != 0.0);
                    angle[row - part.r0] = Some((j, nz));
                    continue;
                }
            }
            let e = part.eval_jets(item, sides, 0.0, |l, c| HessJetN::<SW>::var(l, q[c]));
            for (k, ek) in e.iter().enumerate().take(n) {
                let mut nz = Vec::new();
                for_each_entry(part, sides, &ek.h, |r, c, h| {
                    if h != 0.0 {
                        nz.push((r, c, h));
                    }
                });
                rows[row - part.r0 + k] = Some(nz);
            }
        }
        ConstantHessians { rows, angle }
    }

    /// The nonzeros of global row `row`'s Hessian, or `None` if it is not constant.
    pub(super) fn row(&self, part: &SpatialPart, row: usize) -> Option<&[(usize, usize, f64)]> {
        self.rows.get(row.checked_sub(part.r0)?)?.as_deref()
    }

    /// `f(row column, column, value)` for the nonzeros of global row `row`'s Hessian at time
    /// `t`: the constant ones, or an angle driver's `cos theta(t) H_0 - sin theta(t) H_1`
    /// (nothing for a row that is not spatial).
    pub(super) fn row_at(
        &self,
        part: &SpatialPart,
        row: usize,
        t: f64,
        mut f: impl FnMut(usize, usize, f64),
    ) {
        let Some(k) = row.checked_sub(part.r0) else {
            return;
        };
        if let Some(Some(nz)) = self.rows.get(k) {
            for &(r, c, h) in nz {
                f(r, c, h);
            }
        } else if let Some(Some((j, nz))) = self.angle.get(k) {
            if let Some([theta, ..]) = part.angle(*j, t) {
                // `angle_combine`'s first output, with sin and cos evaluated once for the row
                let (sn, cs) = theta.sin_cos();
                for &(r, c, h0, h1) in nz {
                    f(r, c, h0 * cs - h1 * sn);
                }
            }
        }
    }
}
