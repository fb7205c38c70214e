//! The Hessian pass over the elements: every force element's potential and every joint's
//! equations as local Hessian jets (revolute joints in closed form), handed to a visitor one
//! element at a time. The model's constraint and potential Hessians use it, and so do passes
//! above the model that combine the same element Hessians differently (the symplectic
//! preadjustment's pair of weighted Lagrangian Hessians in `mbd-symplectic`).

use crate::jet::{HessJet, Scalar, NV};
use crate::joints::RevoluteSide;
use crate::rows::SinCos;
use crate::system::{Attach, System};

/// One element's local Hessians in [`System::element_hessians`]'s pass: local coordinates are
/// side `a`'s `(x, y, theta)` then side `b`'s (see [`Attach`]). Exhaustive on purpose: a pass
/// that combines the element Hessians must handle every kind of element.
#[derive(Clone, Copy, Debug)]
pub enum ElementHessian<'e> {
    /// A force element's potential: its attachment and the local Hessian of its potential.
    Force(Attach, &'e [[f64; NV]; NV]),
    /// A joint and its equations.
    Joint {
        /// Index of the joint in [`System::joints`].
        joint: usize,
        /// The bodies it attaches.
        attach: Attach,
        /// Its first equation row.
        row: usize,
        /// Its equations, one jet each (value, local gradient, local Hessian).
        equations: &'e [HessJet],
    },
}

impl System {
    /// The Hessian pass over the elements at `q`: every force element's potential (when
    /// `forces`), then every joint's equations, handed to `visit` one element at a time (each
    /// body's `sin`/`cos` evaluated once; revolute joints in closed form, which equals the
    /// generic jet evaluation up to rounding). Scatter the local blocks with
    /// [`Attach::scatter_hess`] and [`Attach::scatter_row`].
    pub fn element_hessians(&self, q: &[f64], forces: bool, mut visit: impl FnMut(ElementHessian)) {
        // each body's sin/cos once for the joints (the forces' own frames evaluate theirs)
        let sc = SinCos::new(self, q, None);
        let hess_var = |slot: usize| {
            move |i: usize| -> [HessJet; 3] {
                std::array::from_fn(|k| HessJet::var(slot + k, q[3 * i + k]))
            }
        };
        if forces {
            for (fi, f) in self.forces.iter().enumerate() {
                let at = self.force_attach[fi];
                let e = f.potential(&Self::loc_hess(q, at.a, 0), &Self::loc_hess(q, at.b, 3));
                visit(ElementHessian::Force(at, &e.h));
            }
        }
        for (ji, j) in self.joints.iter().enumerate() {
            let at = self.joint_attach[ji];
            let mut e = [HessJet::cst(0.0); 3];
            if let Some(sides) = j.revolute_sides(at) {
                // closed form (what the generic evaluation gives, up to rounding): a body
                // point r + R(theta) p has the gradient e_x or e_y plus R'(theta) p in theta
                // and the one second derivative -R(theta) p in theta-theta
                for RevoluteSide {
                    body,
                    slot,
                    p,
                    sign,
                } in sides
                {
                    let Some(i) = body else {
                        for c in 0..2 {
                            e[c].v += sign * p[c];
                        }
                        continue;
                    };
                    let r0 = sc.rotate(i, p);
                    let r1 = [-r0[1], r0[0]];
                    for c in 0..2 {
                        e[c].v += sign * (q[3 * i + c] + r0[c]);
                        e[c].g[slot + c] = sign;
                        e[c].g[slot + 2] = sign * r1[c];
                        e[c].h[slot + 2][slot + 2] = -sign * r0[c];
                    }
                }
                visit(ElementHessian::Joint {
                    joint: ji,
                    attach: at,
                    row: self.row_offset[ji],
                    equations: &e[..2],
                });
                continue;
            }
            j.eval(
                &sc.frame(at.a, hess_var(0)),
                &sc.frame(at.b, hess_var(3)),
                &mut e,
            );
            visit(ElementHessian::Joint {
                joint: ji,
                attach: at,
                row: self.row_offset[ji],
                equations: &e[..j.n_equations()],
            });
        }
    }
}
