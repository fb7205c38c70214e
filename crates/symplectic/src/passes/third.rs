//! Exact third derivatives of the potential and of the constraints, contracted twice with a
//! direction: `D^3 V(q)(v, v, .)` and `sum_k w_k D^3 Phi_k(q)(v, v, .)`. They are what the
//! gradients of Hessian-weighted terms need (e.g. `grad (v^T Hess V(q) v)`), and come from one
//! forward pass per element with [`ThirdJet`]s seeded along `v` (only the rotation angles enter
//! nonlinearly, so most entries vanish; the local jets do not care). Mixed contractions
//! `D^3 f(a, b, .)` follow by polarisation:
//! `D^3 f(a, b, .) = 1/4 [D^3 f(a + b, a + b, .) - D^3 f(a - b, a - b, .)]`.

use super::scatter_grad;
use mbd_model::jet::{Frame, Scalar, TanJet, ThirdJet, NV};
use mbd_model::{BodyAngles, JointElement, RevoluteSide, System};

#[inline(always)]
fn loc_third(
    q: &[f64],
    ang: Option<&BodyAngles>,
    v: &[f64],
    i: Option<usize>,
    slot: usize,
) -> Frame<ThirdJet> {
    match i {
        Some(i) => BodyAngles::frame(
            ang,
            i,
            std::array::from_fn(|k| ThirdJet::var(slot + k, q[3 * i + k], v[3 * i + k])),
        ),
        None => Frame::fixed(),
    }
}

#[inline(always)]
fn loc_tan_at(
    q: &[f64],
    ang: Option<&BodyAngles>,
    v: &[f64],
    i: Option<usize>,
    slot: usize,
) -> Frame<TanJet> {
    match i {
        Some(i) => BodyAngles::frame(
            ang,
            i,
            std::array::from_fn(|k| TanJet::var(slot + k, q[3 * i + k], v[3 * i + k])),
        ),
        None => Frame::fixed(),
    }
}

/// The third derivative of the potential contracted twice with `v`,
/// `D^3 V(q)(v, v, .) = grad_q (v^T Hess V(q) v)` (length n), into `out` (overwritten).
/// Gravity is linear and contributes nothing; non-conservative elements (dampers,
/// time-dependent loads) have no potential and contribute nothing either.
#[cfg(test)]
pub(crate) fn potential_third(sys: &System, q: &[f64], v: &[f64], out: &mut [f64]) {
    out.fill(0.0);
    add_potential_third(sys, q, v, 1.0, out);
}

/// Adds `scale * D^3 V(q)(v, v, .)` into `out` (see [`potential_third`]).
pub(crate) fn add_potential_third(sys: &System, q: &[f64], v: &[f64], scale: f64, out: &mut [f64]) {
    let ang = None;
    for (f, at) in sys.force_elements() {
        let e = f.potential(
            &loc_third(q, ang, v, at.a, 0),
            &loc_third(q, ang, v, at.b, 3),
        );
        scatter_grad(at, &e.g2, scale, out);
    }
    if sys.has_spatial() {
        sys.add_spatial_force_third(q, v, scale, None, Some(out));
    }
}

/// The weighted third derivative of the constraints contracted twice with `v`,
/// `sum_k weights_k D^3 Phi_k(q)(v, v, .) = grad_q (sum_k weights_k v^T Hess Phi_k(q) v)`
/// (length n; `weights` has length m), into `out` (overwritten). Time enters the joint
/// equations only additively, so this does not depend on `t`.
#[cfg(test)]
pub(crate) fn constraint_third(
    sys: &System,
    q: &[f64],
    v: &[f64],
    weights: &[f64],
    out: &mut [f64],
) {
    out.fill(0.0);
    add_constraint_third(sys, q, v, weights, 1.0, out);
}

/// Adds `scale * sum_k weights_k D^3 Phi_k(q)(v, v, .)` into `out` (see
/// [`constraint_third`]). Spatial rows are quadratic and add nothing.
pub(crate) fn add_constraint_third(
    sys: &System,
    q: &[f64],
    v: &[f64],
    weights: &[f64],
    scale: f64,
    out: &mut [f64],
) {
    let ang = None;
    for JointElement {
        joint: j,
        attach: at,
        row: o,
    } in sys.joint_elements()
    {
        let ne = j.n_equations();
        if weights[o..o + ne].iter().all(|&w| w == 0.0) {
            continue;
        }
        let mut e = [ThirdJet::cst(0.0); 3];
        j.eval(
            &loc_third(q, ang, v, at.a, 0),
            &loc_third(q, ang, v, at.b, 3),
            &mut e,
        );
        let mut g = [0.0; NV];
        for k in 0..ne {
            let w = weights[o + k];
            for l in 0..NV {
                g[l] += w * e[k].g2[l];
            }
        }
        scatter_grad(at, &g, scale, out);
    }
}
/// `L = potential * V + sum_k weights_k Phi_k`: its Hessian-vector product
/// `Hess L(q) w` (length n) into `out` (overwritten), one forward pass per element without
/// forming a Hessian (`potential = 0` for the constraints alone). Spatial rows and force
/// elements included.
pub(crate) fn lagrangian_hessian_vector(
    sys: &System,
    q: &[f64],
    t: f64,
    w: &[f64],
    potential: f64,
    weights: &[f64],
    out: &mut [f64],
) {
    lagrangian_hessian_vector_impl(sys, q, t, None, w, potential, weights, out);
}

/// [`lagrangian_hessian_vector`] with the body angles' `sin`/`cos` from `angles`
/// (evaluated at this `q`, [`BodyAngles`]): bit for bit the same.
#[allow(clippy::too_many_arguments)]
pub(crate) fn lagrangian_hessian_vector_at(
    sys: &System,
    q: &[f64],
    t: f64,
    angles: &BodyAngles,
    w: &[f64],
    potential: f64,
    weights: &[f64],
    out: &mut [f64],
) {
    debug_assert!(angles.matches(q));
    lagrangian_hessian_vector_impl(sys, q, t, Some(angles), w, potential, weights, out);
}

#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn lagrangian_hessian_vector_impl(
    sys: &System,
    q: &[f64],
    t: f64,
    ang: Option<&BodyAngles>,
    w: &[f64],
    potential: f64,
    weights: &[f64],
    out: &mut [f64],
) {
    out.fill(0.0);
    if potential != 0.0 {
        for (f, at) in sys.force_elements() {
            let e = f.potential(
                &loc_tan_at(q, ang, w, at.a, 0),
                &loc_tan_at(q, ang, w, at.b, 3),
            );
            scatter_grad(at, &e.dg, potential, out);
        }
    }
    for JointElement {
        joint: j,
        attach: at,
        row: o,
    } in sys.joint_elements()
    {
        let ne = j.n_equations();
        if weights[o..o + ne].iter().all(|&x| x == 0.0) {
            continue;
        }
        if let Some(sides) = j.revolute_sides(at) {
            // closed form: the rows' only second derivatives are theta-theta, -R(theta) p
            // per body point (what the generic evaluation gives, up to rounding)
            for RevoluteSide { body, p, sign, .. } in sides {
                let Some(i) = body else { continue };
                let r0 = BodyAngles::rotate(ang, q, i, p);
                let wr = weights[o] * r0[0] + weights[o + 1] * r0[1];
                out[3 * i + 2] -= sign * wr * w[3 * i + 2];
            }
            continue;
        }
        let mut e = [TanJet::cst(0.0); 3];
        j.eval(
            &loc_tan_at(q, ang, w, at.a, 0),
            &loc_tan_at(q, ang, w, at.b, 3),
            &mut e,
        );
        let mut g = [0.0; NV];
        for k in 0..ne {
            for l in 0..NV {
                g[l] += weights[o + k] * e[k].dg[l];
            }
        }
        scatter_grad(at, &g, 1.0, out);
    }
    if sys.has_spatial() {
        // the spatial rows (quadratic: constant Hessians) and force elements
        if potential != 0.0 {
            sys.add_spatial_force_third(q, w, potential, Some(out), None);
        }
        sys.add_spatial_hessian_vector(q, t, w, weights, 1.0, out);
    }
}

/// `L = potential * V + sum_k weights_k Phi_k` along `v`: `Hess L(q) v` into `hv` and
/// `D^3 L(q)(v, v, .)` into `d3` (both length n, overwritten), in one forward pass per
/// element.
#[allow(clippy::too_many_arguments)]
pub(crate) fn lagrangian_third(
    sys: &System,
    q: &[f64],
    t: f64,
    v: &[f64],
    potential: f64,
    weights: &[f64],
    hv: &mut [f64],
    d3: &mut [f64],
) {
    lagrangian_third_impl(sys, q, t, None, v, potential, weights, hv, d3);
}

/// [`lagrangian_third`] with the body angles' `sin`/`cos` from `angles` (evaluated
/// at this `q`, [`BodyAngles`]): bit for bit the same.
#[allow(clippy::too_many_arguments)]
pub(crate) fn lagrangian_third_at(
    sys: &System,
    q: &[f64],
    t: f64,
    angles: &BodyAngles,
    v: &[f64],
    potential: f64,
    weights: &[f64],
    hv: &mut [f64],
    d3: &mut [f64],
) {
    debug_assert!(angles.matches(q));
    lagrangian_third_impl(sys, q, t, Some(angles), v, potential, weights, hv, d3);
}

#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn lagrangian_third_impl(
    sys: &System,
    q: &[f64],
    t: f64,
    ang: Option<&BodyAngles>,
    v: &[f64],
    potential: f64,
    weights: &[f64],
    hv: &mut [f64],
    d3: &mut [f64],
) {
    hv.fill(0.0);
    d3.fill(0.0);
    if potential != 0.0 {
        for (f, at) in sys.force_elements() {
            let e = f.potential(
                &loc_third(q, ang, v, at.a, 0),
                &loc_third(q, ang, v, at.b, 3),
            );
            scatter_grad(at, &e.g1, potential, hv);
            scatter_grad(at, &e.g2, potential, d3);
        }
    }
    for JointElement {
        joint: j,
        attach: at,
        row: o,
    } in sys.joint_elements()
    {
        let ne = j.n_equations();
        if weights[o..o + ne].iter().all(|&x| x == 0.0) {
            continue;
        }
        let mut e = [ThirdJet::cst(0.0); 3];
        j.eval(
            &loc_third(q, ang, v, at.a, 0),
            &loc_third(q, ang, v, at.b, 3),
            &mut e,
        );
        let (mut g1, mut g2) = ([0.0; NV], [0.0; NV]);
        for k in 0..ne {
            let w = weights[o + k];
            for l in 0..NV {
                g1[l] += w * e[k].g1[l];
                g2[l] += w * e[k].g2[l];
            }
        }
        scatter_grad(at, &g1, 1.0, hv);
        scatter_grad(at, &g2, 1.0, d3);
    }
    if sys.has_spatial() {
        // the spatial force elements; the spatial rows are quadratic: a Hessian-vector product
        // and no third derivative
        if potential != 0.0 {
            sys.add_spatial_force_third(q, v, potential, Some(hv), Some(d3));
        }
        sys.add_spatial_hessian_vector(q, t, v, weights, 1.0, hv);
    }
}

/// Per constraint row `r` at `q` along `v`, in element-local form (as
/// [`System::phi_q_local`]: six numbers in the columns of the joint's two bodies), from one
/// third-order pass over the joints: the gradient `grads[r]` (row `r` of `Phi_q`),
/// `hv[r] = Hess Phi_r v`, `d3[r] = D^3 Phi_r(v, v, .)` and `vhv[r] = v^T Hess Phi_r v`
/// (so `gamma = -vhv` plus the time part). Everything a constraint-weighted Hessian term
/// needs before its weights are known ([`add_local_rows`] applies them).
pub(crate) fn constraint_third_local(
    sys: &System,
    q: &[f64],
    v: &[f64],
    grads: &mut [[f64; NV]],
    hv: &mut [[f64; NV]],
    d3: &mut [[f64; NV]],
    vhv: &mut [f64],
) {
    constraint_third_local_impl(sys, q, None, v, grads, hv, d3, vhv);
}

#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn constraint_third_local_impl(
    sys: &System,
    q: &[f64],
    ang: Option<&BodyAngles>,
    v: &[f64],
    grads: &mut [[f64; NV]],
    hv: &mut [[f64; NV]],
    d3: &mut [[f64; NV]],
    vhv: &mut [f64],
) {
    for JointElement {
        joint: j,
        attach: at,
        row: o,
    } in sys.joint_elements()
    {
        if let Some(sides) = j.revolute_sides(at) {
            // closed form (what the generic evaluation gives, up to rounding): a body
            // point r + R(theta) p has the gradient e_x or e_y plus R'(theta) p in theta,
            // and only theta-theta second and third derivatives, -R p and -R' p
            for r in 0..2 {
                grads[o + r] = [0.0; NV];
                hv[o + r] = [0.0; NV];
                d3[o + r] = [0.0; NV];
                vhv[o + r] = 0.0;
            }
            for RevoluteSide {
                body,
                slot,
                p,
                sign,
            } in sides
            {
                let Some(i) = body else { continue };
                let r0 = BodyAngles::rotate(ang, q, i, p);
                let r1 = [-r0[1], r0[0]];
                let w = v[3 * i + 2];
                for c in 0..2 {
                    grads[o + c][slot + c] = sign;
                    grads[o + c][slot + 2] = sign * r1[c];
                    hv[o + c][slot + 2] = -sign * r0[c] * w;
                    d3[o + c][slot + 2] = -sign * r1[c] * (w * w);
                    vhv[o + c] -= sign * r0[c] * (w * w);
                }
            }
            continue;
        }
        let mut e = [ThirdJet::cst(0.0); 3];
        j.eval(
            &loc_third(q, ang, v, at.a, 0),
            &loc_third(q, ang, v, at.b, 3),
            &mut e,
        );
        for (k, ek) in e.iter().enumerate().take(j.n_equations()) {
            grads[o + k] = ek.g;
            hv[o + k] = ek.g1;
            d3[o + k] = ek.g2;
            vhv[o + k] = ek.d2;
        }
    }
}

/// `out += sum_r weights_r rows_r` for element-local constraint rows (length-n `out`,
/// `weights` of length m; see [`constraint_third_local`]).
pub(crate) fn add_local_rows(sys: &System, rows: &[[f64; NV]], weights: &[f64], out: &mut [f64]) {
    for JointElement {
        joint: j,
        attach: at,
        row: o,
    } in sys.joint_elements()
    {
        let mut g = [0.0; NV];
        for k in 0..j.n_equations() {
            let w = weights[o + k];
            for l in 0..NV {
                g[l] += w * rows[o + k][l];
            }
        }
        scatter_grad(at, &g, 1.0, out);
    }
}

/// `out += sum_r Hess Phi_r(q) d_r` for one element-local direction `d_r` per constraint
/// row (`dirs` of length m, in the columns of the row's joint as in
/// [`System::phi_q_local`]): the gradient in `q` of `sum_r d_r . grad Phi_r`, i.e. what the
/// adjoint of `Phi_q` gives back to `q` (one tangent pass per nonzero row).
#[cfg(test)]
pub(crate) fn add_constraint_hessian_rows(
    sys: &System,
    q: &[f64],
    dirs: &[[f64; NV]],
    out: &mut [f64],
) {
    add_constraint_hessian_rows_impl(sys, q, None, dirs, out);
}

/// [`add_constraint_hessian_rows`] with the body angles' `sin`/`cos` from `angles`
/// (evaluated at this `q`, [`BodyAngles`]): bit for bit the same.
pub(crate) fn add_constraint_hessian_rows_at(
    sys: &System,
    q: &[f64],
    angles: &BodyAngles,
    dirs: &[[f64; NV]],
    out: &mut [f64],
) {
    debug_assert!(angles.matches(q));
    add_constraint_hessian_rows_impl(sys, q, Some(angles), dirs, out);
}

#[inline(always)]
fn add_constraint_hessian_rows_impl(
    sys: &System,
    q: &[f64],
    ang: Option<&BodyAngles>,
    dirs: &[[f64; NV]],
    out: &mut [f64],
) {
    for JointElement {
        joint: j,
        attach: at,
        row: o,
    } in sys.joint_elements()
    {
        for k in 0..j.n_equations() {
            let d = &dirs[o + k];
            if d.iter().all(|&x| x == 0.0) {
                continue;
            }
            let frame = |i: Option<usize>, slot: usize| match i {
                Some(i) => BodyAngles::frame(
                    ang,
                    i,
                    std::array::from_fn(|c| TanJet::var(slot + c, q[3 * i + c], d[slot + c])),
                ),
                None => Frame::fixed(),
            };
            let mut e = [TanJet::cst(0.0); 3];
            j.eval(&frame(at.a, 0), &frame(at.b, 3), &mut e);
            scatter_grad(at, &e[k].dg, 1.0, out);
        }
    }
}

#[cfg(test)]
#[path = "third_tests.rs"]
mod tests;
