//! The derivative passes only the preadjustment needs: third derivatives, Hessian-vector
//! products and Hessian rows of the constraints and the potential, the mixed directional
//! derivatives of several directions at once with their gradients ([`mbd_model::PolyJet`]),
//! and a pair of weighted Lagrangian Hessians from one element Hessian pass
//! ([`mbd_model::System::element_hessians`]).
//!
//! They evaluate the model through its one generic hook: [`mbd_model::System::joint_elements`] and
//! [`mbd_model::System::force_elements`] hand out every element with its attachment, and
//! [`mbd_model::Joint::eval`] / [`mbd_model::Force::potential`] evaluate it with whatever jet
//! type a pass seeds (`ThirdJet`, `TanJet`, `PolyJet`); revolute joints take closed-form rows
//! ([`mbd_model::Joint::revolute_sides`]). The body angles' `sin`/`cos` come from a
//! [`mbd_model::BodyAngles`] table when the `_at` variants are given one.

#[cfg(test)]
mod directional;
mod hessian_pair;
mod poly;
mod third;

pub(crate) use hessian_pair::*;
pub(crate) use poly::*;
pub(crate) use third::*;

use mbd_model::jet::NV;
use mbd_model::Attach;

/// `out += scale * g` in the columns of the element's bodies (`g[0..3]` on side a, `g[3..6]` on
/// side b; ground columns dropped).
pub(crate) fn scatter_grad(at: Attach, g: &[f64; NV], scale: f64, out: &mut [f64]) {
    if let Some(i) = at.a {
        for l in 0..3 {
            out[3 * i + l] += scale * g[l];
        }
    }
    if let Some(i) = at.b {
        for l in 0..3 {
            out[3 * i + l] += scale * g[3 + l];
        }
    }
}
