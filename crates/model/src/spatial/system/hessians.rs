//! The constant Hessians of the spatial rows. Every spatial equation but an angle driver's is
//! quadratic in the natural coordinates (docs/spatial.md), so its Hessian is the same at every
//! `q` and `t`: it is evaluated once, by one pass of Hessian jets, and kept as its nonzeros in
//! global columns. The weighted Hessian `sum_r w_r Hess Phi_r` and the products
//! `sum_r w_r Hess Phi_r x` are then sums over those nonzeros, where each evaluation took a pass
//! of 24-variable Hessian jets over every row (the dense symplectic Newton matrix and the
//! preadjustments' passes call them at every iteration).

use super::{Item, SpatialPart, SW};
use mbd_jet::HessJetN;

/// Per spatial row (in the order of the rows), its Hessian's nonzeros `(row column, column,
/// value)`, or `None` where the Hessian depends on time (an angle driver's rows).
#[derive(Clone, Debug, Default)]
pub(crate) struct ConstantHessians {
    rows: Vec<Option<Vec<(usize, usize, f64)>>>,
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
        for (item, sides, row, n) in part.items() {
            if let Item::Joint(j) = item {
                if part.lowered[j].kind() == crate::spatial::joints::SpatialJointKind::AngleDriver {
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
        ConstantHessians { rows }
    }

    /// The nonzeros of global row `row`'s Hessian, or `None` if it is not constant.
    pub(super) fn row(&self, part: &SpatialPart, row: usize) -> Option<&[(usize, usize, f64)]> {
        self.rows.get(row.checked_sub(part.r0)?)?.as_deref()
    }

    /// Whether every spatial row's Hessian is constant.
    pub(super) fn all_constant(&self) -> bool {
        self.rows.iter().all(Option::is_some)
    }
}
