//! Exact third derivatives of the potential and of the constraints, contracted twice with a
//! direction: `D^3 V(q)(v, v, .)` and `sum_k w_k D^3 Phi_k(q)(v, v, .)`. They are what the
//! gradients of Hessian-weighted terms need (e.g. `grad (v^T Hess V(q) v)`), and come from one
//! forward pass per element with [`ThirdJet`]s seeded along `v` (only the rotation angles enter
//! nonlinearly, so most entries vanish; the local jets do not care). Mixed contractions
//! `D^3 f(a, b, .)` follow by polarisation:
//! `D^3 f(a, b, .) = 1/4 [D^3 f(a + b, a + b, .) - D^3 f(a - b, a - b, .)]`.

use crate::cache::BodyAngles;
use crate::jet::{Frame, Scalar, TanJet, ThirdJet, NV};
use crate::joints::RevoluteSide;
use crate::system::{Attach, System};
use nalgebra::DMatrix;

impl System {
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

    #[inline(always)]
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

    /// The third derivative of the potential contracted twice with `v`,
    /// `D^3 V(q)(v, v, .) = grad_q (v^T Hess V(q) v)` (length n), into `out` (overwritten).
    /// Gravity is linear and contributes nothing; non-conservative elements (dampers,
    /// time-dependent loads) have no potential and contribute nothing either.
    pub fn potential_third(&self, q: &[f64], v: &[f64], out: &mut [f64]) {
        out.fill(0.0);
        self.add_potential_third(q, v, 1.0, out);
    }

    /// Adds `scale * D^3 V(q)(v, v, .)` into `out` (see [`System::potential_third`]).
    pub fn add_potential_third(&self, q: &[f64], v: &[f64], scale: f64, out: &mut [f64]) {
        let ang = None;
        for (fi, f) in self.forces.iter().enumerate() {
            let at = self.force_attach[fi];
            let e = f.potential(
                &Self::loc_third(q, ang, v, at.a, 0),
                &Self::loc_third(q, ang, v, at.b, 3),
            );
            Self::scatter_grad(at, &e.g2, scale, out);
        }
    }

    /// The weighted third derivative of the constraints contracted twice with `v`,
    /// `sum_k weights_k D^3 Phi_k(q)(v, v, .) = grad_q (sum_k weights_k v^T Hess Phi_k(q) v)`
    /// (length n; `weights` has length m), into `out` (overwritten). Time enters the joint
    /// equations only additively, so this does not depend on `t`.
    pub fn constraint_third(&self, q: &[f64], v: &[f64], weights: &[f64], out: &mut [f64]) {
        out.fill(0.0);
        self.add_constraint_third(q, v, weights, 1.0, out);
    }

    /// Adds `scale * sum_k weights_k D^3 Phi_k(q)(v, v, .)` into `out` (see
    /// [`System::constraint_third`]).
    pub fn add_constraint_third(
        &self,
        q: &[f64],
        v: &[f64],
        weights: &[f64],
        scale: f64,
        out: &mut [f64],
    ) {
        let ang = None;
        for (ji, j) in self.joints.iter().enumerate() {
            let at = self.joint_attach[ji];
            let o = self.row_offset[ji];
            let ne = j.n_equations();
            if weights[o..o + ne].iter().all(|&w| w == 0.0) {
                continue;
            }
            let mut e = [ThirdJet::cst(0.0); 3];
            j.eval(
                &Self::loc_third(q, ang, v, at.a, 0),
                &Self::loc_third(q, ang, v, at.b, 3),
                &mut e,
            );
            let mut g = [0.0; NV];
            for k in 0..ne {
                let w = weights[o + k];
                for l in 0..NV {
                    g[l] += w * e[k].g2[l];
                }
            }
            Self::scatter_grad(at, &g, scale, out);
        }
    }
    /// `L = potential * V + sum_k weights_k Phi_k`: its Hessian-vector product
    /// `Hess L(q) w` (length n) into `out` (overwritten), one forward pass per element without
    /// forming a Hessian (`potential = 0` for the constraints alone).
    pub fn lagrangian_hessian_vector(
        &self,
        q: &[f64],
        w: &[f64],
        potential: f64,
        weights: &[f64],
        out: &mut [f64],
    ) {
        self.lagrangian_hessian_vector_impl(q, None, w, potential, weights, out);
    }

    /// [`System::lagrangian_hessian_vector`] with the body angles' `sin`/`cos` from `angles`
    /// (evaluated at this `q`, [`BodyAngles`]): bit for bit the same.
    pub fn lagrangian_hessian_vector_at(
        &self,
        q: &[f64],
        angles: &BodyAngles,
        w: &[f64],
        potential: f64,
        weights: &[f64],
        out: &mut [f64],
    ) {
        debug_assert!(angles.matches(q));
        self.lagrangian_hessian_vector_impl(q, Some(angles), w, potential, weights, out);
    }

    #[inline(always)]
    fn lagrangian_hessian_vector_impl(
        &self,
        q: &[f64],
        ang: Option<&BodyAngles>,
        w: &[f64],
        potential: f64,
        weights: &[f64],
        out: &mut [f64],
    ) {
        out.fill(0.0);
        if potential != 0.0 {
            for (fi, f) in self.forces.iter().enumerate() {
                let at = self.force_attach[fi];
                let e = f.potential(
                    &Self::loc_tan_at(q, ang, w, at.a, 0),
                    &Self::loc_tan_at(q, ang, w, at.b, 3),
                );
                Self::scatter_grad(at, &e.dg, potential, out);
            }
        }
        for (ji, j) in self.joints.iter().enumerate() {
            let at = self.joint_attach[ji];
            let o = self.row_offset[ji];
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
                &Self::loc_tan_at(q, ang, w, at.a, 0),
                &Self::loc_tan_at(q, ang, w, at.b, 3),
                &mut e,
            );
            let mut g = [0.0; NV];
            for k in 0..ne {
                for l in 0..NV {
                    g[l] += weights[o + k] * e[k].dg[l];
                }
            }
            Self::scatter_grad(at, &g, 1.0, out);
        }
    }

    /// `L = potential * V + sum_k weights_k Phi_k` along `v`: `Hess L(q) v` into `hv` and
    /// `D^3 L(q)(v, v, .)` into `d3` (both length n, overwritten), in one forward pass per
    /// element.
    pub fn lagrangian_third(
        &self,
        q: &[f64],
        v: &[f64],
        potential: f64,
        weights: &[f64],
        hv: &mut [f64],
        d3: &mut [f64],
    ) {
        self.lagrangian_third_impl(q, None, v, potential, weights, hv, d3);
    }

    /// [`System::lagrangian_third`] with the body angles' `sin`/`cos` from `angles` (evaluated
    /// at this `q`, [`BodyAngles`]): bit for bit the same.
    #[allow(clippy::too_many_arguments)]
    pub fn lagrangian_third_at(
        &self,
        q: &[f64],
        angles: &BodyAngles,
        v: &[f64],
        potential: f64,
        weights: &[f64],
        hv: &mut [f64],
        d3: &mut [f64],
    ) {
        debug_assert!(angles.matches(q));
        self.lagrangian_third_impl(q, Some(angles), v, potential, weights, hv, d3);
    }

    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn lagrangian_third_impl(
        &self,
        q: &[f64],
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
            for (fi, f) in self.forces.iter().enumerate() {
                let at = self.force_attach[fi];
                let e = f.potential(
                    &Self::loc_third(q, ang, v, at.a, 0),
                    &Self::loc_third(q, ang, v, at.b, 3),
                );
                Self::scatter_grad(at, &e.g1, potential, hv);
                Self::scatter_grad(at, &e.g2, potential, d3);
            }
        }
        for (ji, j) in self.joints.iter().enumerate() {
            let at = self.joint_attach[ji];
            let o = self.row_offset[ji];
            let ne = j.n_equations();
            if weights[o..o + ne].iter().all(|&x| x == 0.0) {
                continue;
            }
            let mut e = [ThirdJet::cst(0.0); 3];
            j.eval(
                &Self::loc_third(q, ang, v, at.a, 0),
                &Self::loc_third(q, ang, v, at.b, 3),
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
            Self::scatter_grad(at, &g1, 1.0, hv);
            Self::scatter_grad(at, &g2, 1.0, d3);
        }
    }

    /// Per constraint row `r` at `q` along `v`, in element-local form (as
    /// [`System::phi_q_local`]: six numbers in the columns of the joint's two bodies), from one
    /// third-order pass over the joints: the gradient `grads[r]` (row `r` of `Phi_q`),
    /// `hv[r] = Hess Phi_r v`, `d3[r] = D^3 Phi_r(v, v, .)` and `vhv[r] = v^T Hess Phi_r v`
    /// (so `gamma = -vhv` plus the time part). Everything a constraint-weighted Hessian term
    /// needs before its weights are known ([`System::add_local_rows`] applies them).
    pub fn constraint_third_local(
        &self,
        q: &[f64],
        v: &[f64],
        grads: &mut [[f64; NV]],
        hv: &mut [[f64; NV]],
        d3: &mut [[f64; NV]],
        vhv: &mut [f64],
    ) {
        self.constraint_third_local_impl(q, None, v, grads, hv, d3, vhv);
    }

    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn constraint_third_local_impl(
        &self,
        q: &[f64],
        ang: Option<&BodyAngles>,
        v: &[f64],
        grads: &mut [[f64; NV]],
        hv: &mut [[f64; NV]],
        d3: &mut [[f64; NV]],
        vhv: &mut [f64],
    ) {
        for (ji, j) in self.joints.iter().enumerate() {
            let at = self.joint_attach[ji];
            let o = self.row_offset[ji];
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
                &Self::loc_third(q, ang, v, at.a, 0),
                &Self::loc_third(q, ang, v, at.b, 3),
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
    /// `weights` of length m; see [`System::constraint_third_local`]).
    pub fn add_local_rows(&self, rows: &[[f64; NV]], weights: &[f64], out: &mut [f64]) {
        for (ji, j) in self.joints.iter().enumerate() {
            let at = self.joint_attach[ji];
            let o = self.row_offset[ji];
            let mut g = [0.0; NV];
            for k in 0..j.n_equations() {
                let w = weights[o + k];
                for l in 0..NV {
                    g[l] += w * rows[o + k][l];
                }
            }
            Self::scatter_grad(at, &g, 1.0, out);
        }
    }

    /// `out += sum_r Hess Phi_r(q) d_r` for one element-local direction `d_r` per constraint
    /// row (`dirs` of length m, in the columns of the row's joint as in
    /// [`System::phi_q_local`]): the gradient in `q` of `sum_r d_r . grad Phi_r`, i.e. what the
    /// adjoint of `Phi_q` gives back to `q` (one tangent pass per nonzero row).
    pub fn add_constraint_hessian_rows(&self, q: &[f64], dirs: &[[f64; NV]], out: &mut [f64]) {
        self.add_constraint_hessian_rows_impl(q, None, dirs, out);
    }

    /// [`System::add_constraint_hessian_rows`] with the body angles' `sin`/`cos` from `angles`
    /// (evaluated at this `q`, [`BodyAngles`]): bit for bit the same.
    pub fn add_constraint_hessian_rows_at(
        &self,
        q: &[f64],
        angles: &BodyAngles,
        dirs: &[[f64; NV]],
        out: &mut [f64],
    ) {
        debug_assert!(angles.matches(q));
        self.add_constraint_hessian_rows_impl(q, Some(angles), dirs, out);
    }

    #[inline(always)]
    fn add_constraint_hessian_rows_impl(
        &self,
        q: &[f64],
        ang: Option<&BodyAngles>,
        dirs: &[[f64; NV]],
        out: &mut [f64],
    ) {
        for (ji, j) in self.joints.iter().enumerate() {
            let at = self.joint_attach[ji];
            let o = self.row_offset[ji];
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
                Self::scatter_grad(at, &e[k].dg, 1.0, out);
            }
        }
    }

    /// The dense `m x n` matrix of element-local constraint rows (e.g. `Phi_q` from the
    /// `grads` of [`System::constraint_third_local`]) into `out` (overwritten).
    pub fn local_rows_dense(&self, rows: &[[f64; NV]], out: &mut DMatrix<f64>) {
        out.as_mut_slice().fill(0.0);
        for ji in 0..self.joints.len() {
            let o = self.row_offset[ji];
            for k in 0..self.joints[ji].n_equations() {
                self.scatter_row(ji, o + k, &rows[o + k], out);
            }
        }
    }
}

#[cfg(test)]
mod tests;
