//! Exact third derivatives of the potential and of the constraints, contracted twice with a
//! direction: `D^3 V(q)(v, v, .)` and `sum_k w_k D^3 Phi_k(q)(v, v, .)`. They are what the
//! gradients of Hessian-weighted terms need (e.g. `grad (v^T Hess V(q) v)`), and come from one
//! forward pass per element with [`ThirdJet`]s seeded along `v` (only the rotation angles enter
//! nonlinearly, so most entries vanish; the local jets do not care). Mixed contractions
//! `D^3 f(a, b, .)` follow by polarisation:
//! `D^3 f(a, b, .) = 1/4 [D^3 f(a + b, a + b, .) - D^3 f(a - b, a - b, .)]`.

use crate::directional::BodyAngles;
use crate::jet::{Frame, Scalar, TanJet, ThirdJet, NV};
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

    /// [`System::constraint_third_local`] with the body angles' `sin`/`cos` from `angles`
    /// (evaluated at this `q`, [`BodyAngles`]): bit for bit the same.
    #[allow(clippy::too_many_arguments)]
    pub fn constraint_third_local_at(
        &self,
        q: &[f64],
        angles: &BodyAngles,
        v: &[f64],
        grads: &mut [[f64; NV]],
        hv: &mut [[f64; NV]],
        d3: &mut [[f64; NV]],
        vhv: &mut [f64],
    ) {
        debug_assert!(angles.matches(q));
        self.constraint_third_local_impl(q, Some(angles), v, grads, hv, d3, vhv);
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
            let mut e = [ThirdJet::cst(0.0); 3];
            j.eval(
                &Self::loc_third(q, ang, v, at.a, 0),
                &Self::loc_third(q, ang, v, at.b, 3),
                &mut e,
            );
            let o = self.row_offset[ji];
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
mod tests {
    use crate::{models, Body, BodyRef, Force, Joint, System, SystemBuilder, TimeFunction};
    use nalgebra::DMatrix;

    /// Every conservative force kind (springs with and without rest length, rotary spring,
    /// constant force and torque) besides gravity, and a damper and a time-dependent load
    /// (no potential).
    fn forces_system() -> System {
        let mut b = SystemBuilder::new();
        b.set_gravity([0.3, -9.81]);
        let b1 = b.add_body(Body::new("b1").rod(1.0, 1.0).position(0.3, -0.2, 0.4));
        let b2 = b.add_body(Body::new("b2").rod(2.0, 0.7).position(1.1, 0.5, -0.9));
        let b3 = b.add_body(Body::new("b3").rod(0.5, 0.4).position(-0.6, 1.3, 2.1));
        b.add_joint(Joint::revolute(
            "r",
            BodyRef::Ground,
            [0.1, 0.2],
            b1,
            [-0.5, 0.1],
        ));
        b.add_force(Force::spring_damper(
            "s",
            b1,
            [0.4, 0.1],
            b2,
            [-0.2, 0.3],
            30.0,
            0.0,
            0.5,
        ));
        b.add_force(Force::spring_damper(
            "s0",
            BodyRef::Ground,
            [1.0, 1.0],
            b3,
            [0.1, -0.2],
            12.0,
            0.0,
            0.0,
        ));
        b.add_force(Force::spring_damper(
            "sd",
            b2,
            [0.3, 0.0],
            b3,
            [0.0, 0.2],
            7.0,
            0.5,
            0.9,
        ));
        b.add_force(Force::rotary_spring_damper("k", b1, b2, 4.0, 0.0, 0.3));
        b.add_force(Force::rotary_spring_damper(
            "k0",
            BodyRef::Ground,
            b3,
            2.5,
            0.1,
            -0.2,
        ));
        b.add_force(Force::force(
            "f",
            b2,
            [0.3, -0.4],
            TimeFunction::constant(1.5),
            TimeFunction::constant(-2.0),
        ));
        b.add_force(Force::force(
            "ft",
            b3,
            [0.1, 0.1],
            TimeFunction::linear(1.0, 2.0),
            TimeFunction::constant(0.0),
        ));
        b.add_force(Force::torque("tq", b3, TimeFunction::constant(0.7)));
        b.build().unwrap()
    }

    /// `grad_q (v^T H(q) v)` by central differences of the exact Hessians, Richardson
    /// extrapolated (error `O(e^4)`).
    fn fd_third(hess: &dyn Fn(&[f64], &mut DMatrix<f64>), q: &[f64], v: &[f64]) -> Vec<f64> {
        let n = q.len();
        let vv = nalgebra::DVector::from_column_slice(v);
        let mut hm = DMatrix::zeros(n, n);
        let quad = |qq: &[f64], hm: &mut DMatrix<f64>| -> f64 {
            hess(qq, hm);
            vv.dot(&(&*hm * &vv))
        };
        let e = 1e-3;
        (0..n)
            .map(|i| {
                let mut acc = 0.0;
                for (c, s) in [(8.0, 0.5), (-8.0, -0.5), (-1.0, 1.0), (1.0, -1.0)] {
                    let mut qq = q.to_vec();
                    qq[i] += s * e;
                    acc += c * quad(&qq, &mut hm);
                }
                acc / (6.0 * e)
            })
            .collect()
    }

    fn check(exact: &[f64], fd: &[f64], what: &str) {
        let scale = fd.iter().fold(1.0f64, |a, &b| a.max(b.abs()));
        for (i, (a, b)) in exact.iter().zip(fd).enumerate() {
            assert!(
                (a - b).abs() < 1e-9 * scale,
                "{what}[{i}]: exact {a} vs differences {b}"
            );
        }
    }

    fn point(n: usize) -> (Vec<f64>, Vec<f64>) {
        let q = (0..n)
            .map(|i| 0.3 + 0.17 * i as f64 - 0.05 * (i * i) as f64)
            .collect();
        let v = (0..n).map(|i| 1.3 - 0.41 * i as f64).collect();
        (q, v)
    }

    #[test]
    fn constraint_third_matches_hessian_differences() {
        let systems = [
            crate::fixtures::every_joint_kind(),
            forces_system(),
            models::slider_crank().unwrap(),
            models::manipulator().unwrap(),
            models::n_link_chain(5).unwrap(),
        ];
        for sys in &systems {
            let (n, m) = (sys.n_coords(), sys.n_constraints());
            let (q, v) = point(n);
            // one joint equation at a time, then a generic weighting
            let mut weights: Vec<Vec<f64>> = (0..m)
                .map(|k| (0..m).map(|r| if r == k { 1.0 } else { 0.0 }).collect())
                .collect();
            weights.push((0..m).map(|r| 0.7 - 0.3 * r as f64).collect());
            let mut out = vec![0.0; n];
            for w in &weights {
                sys.constraint_third(&q, &v, w, &mut out);
                let fd = fd_third(&|qq, hm| sys.constraint_hessian(qq, w, hm), &q, &v);
                check(&out, &fd, "constraint_third");
            }
        }
    }

    #[test]
    fn potential_third_matches_hessian_differences() {
        for (k, sys) in [forces_system(), models::manipulator().unwrap()]
            .iter()
            .enumerate()
        {
            let n = sys.n_coords();
            let (q, v) = point(n);
            let mut out = vec![0.0; n];
            sys.potential_third(&q, &v, &mut out);
            // (the springs make it non-zero; the manipulator's potential may be linear)
            assert!(k > 0 || out.iter().any(|&x| x != 0.0));
            let fd = fd_third(&|qq, hm| sys.potential_hessian(qq, hm), &q, &v);
            check(&out, &fd, "potential_third");
            // add_ with a scale accumulates
            let mut acc = vec![1.0; n];
            sys.add_potential_third(&q, &v, -2.0, &mut acc);
            for i in 0..n {
                assert!((acc[i] - (1.0 - 2.0 * out[i])).abs() < 1e-12 * (1.0 + out[i].abs()));
            }
        }
    }
    #[test]
    fn lagrangian_products_match_assembled_hessians() {
        for sys in [
            forces_system(),
            crate::fixtures::every_joint_kind(),
            models::manipulator().unwrap(),
        ] {
            let (n, m) = (sys.n_coords(), sys.n_constraints());
            let (q, v) = point(n);
            let w: Vec<f64> = (0..m).map(|r| 0.7 - 0.3 * r as f64).collect();
            let mut hm = DMatrix::zeros(n, n);
            sys.potential_hessian(&q, &mut hm);
            hm *= 0.5;
            sys.add_constraint_hessian(&q, &w, 1.0, &mut hm);
            let dense = &hm * nalgebra::DVector::from_column_slice(&v);
            let (mut hv, mut hv2, mut d3) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
            sys.lagrangian_hessian_vector(&q, &v, 0.5, &w, &mut hv);
            sys.lagrangian_third(&q, &v, 0.5, &w, &mut hv2, &mut d3);
            let (mut p3, mut c3) = (vec![0.0; n], vec![0.0; n]);
            sys.potential_third(&q, &v, &mut p3);
            sys.constraint_third(&q, &v, &w, &mut c3);
            for i in 0..n {
                let tol = 1e-12 * (1.0 + dense[i].abs());
                assert!((hv[i] - dense[i]).abs() < tol, "Hess L v [{i}]");
                assert!((hv2[i] - dense[i]).abs() < tol, "lagrangian_third hv [{i}]");
                let e3 = 0.5 * p3[i] + c3[i];
                assert!((d3[i] - e3).abs() < 1e-12 * (1.0 + e3.abs()), "D3 L [{i}]");
            }
        }
    }

    /// The local third-order rows equal the dense passes: `Phi_q` and `gamma`
    /// ([`System::phi_q_gamma`]), and, weighted, `Hess(w . Phi) v` and `D^3(w . Phi)(v, v, .)`
    /// ([`System::lagrangian_third`]).
    #[test]
    fn local_third_rows_match_the_dense_passes() {
        for sys in [
            crate::fixtures::every_joint_kind(),
            models::manipulator().unwrap(),
        ] {
            let (n, m) = (sys.n_coords(), sys.n_constraints());
            let (q, v) = point(n);
            let w: Vec<f64> = (0..m).map(|r| 0.7 - 0.3 * r as f64).collect();
            let (mut g, mut hv, mut d3, mut vhv) = (
                vec![[0.0; 6]; m],
                vec![[0.0; 6]; m],
                vec![[0.0; 6]; m],
                vec![0.0; m],
            );
            sys.constraint_third_local(&q, &v, &mut g, &mut hv, &mut d3, &mut vhv);
            let mut gq = DMatrix::from_element(m, n, 3.0);
            sys.local_rows_dense(&g, &mut gq);
            let (mut gq2, mut gamma) = (DMatrix::zeros(m, n), vec![0.0; m]);
            sys.phi_q_gamma(&q, &v, 0.0, &mut gq2, &mut gamma);
            assert!((&gq - &gq2).amax() < 1e-14 * (1.0 + gq2.amax()));
            for r in 0..m {
                assert!(
                    (vhv[r] + gamma[r]).abs() < 1e-13 * (1.0 + gamma[r].abs()),
                    "row {r}"
                );
            }
            let (mut a, mut b) = (vec![0.0; n], vec![0.0; n]);
            sys.add_local_rows(&hv, &w, &mut a);
            sys.add_local_rows(&d3, &w, &mut b);
            let (mut ea, mut eb) = (vec![0.0; n], vec![0.0; n]);
            sys.lagrangian_third(&q, &v, 0.0, &w, &mut ea, &mut eb);
            for i in 0..n {
                assert!(
                    (a[i] - ea[i]).abs() < 1e-13 * (1.0 + ea[i].abs()),
                    "Hv [{i}]"
                );
                assert!(
                    (b[i] - eb[i]).abs() < 1e-13 * (1.0 + eb[i].abs()),
                    "D3 [{i}]"
                );
            }
        }
    }

    /// `sum_r Hess Phi_r d_r` with element-local directions against the assembled Hessian of
    /// each row (`constraint_hessian` with a unit multiplier) times the row's direction.
    #[test]
    fn hessian_rows_match_assembled_hessians() {
        for sys in crate::fixtures::derivative_test_systems() {
            let (n, m) = (sys.n_coords(), sys.n_constraints());
            let (q, _) = crate::fixtures::generic_point(n);
            let dirs: Vec<[f64; 6]> = (0..m)
                .map(|r| std::array::from_fn(|l| 0.3 + 0.1 * r as f64 - 0.07 * (l * l) as f64))
                .collect();
            let mut got = vec![0.0; n];
            sys.add_constraint_hessian_rows(&q, &dirs, &mut got);
            let mut want = vec![0.0; n];
            let mut h = DMatrix::zeros(n, n);
            for (r, d) in dirs.iter().enumerate() {
                let mut e = vec![0.0; m];
                e[r] = 1.0;
                sys.constraint_hessian(&q, &e, &mut h);
                let (a, b) = sys.joint_bodies(sys.equation_joint(r).unwrap());
                let mut g = vec![0.0; n];
                for (slot, body) in [(0, a), (3, b)] {
                    if let Some(i) = body {
                        for k in 0..3 {
                            g[3 * i + k] = d[slot + k];
                        }
                    }
                }
                for i in 0..n {
                    want[i] += (0..n).map(|l| h[(i, l)] * g[l]).sum::<f64>();
                }
            }
            let scale = want.iter().fold(1.0f64, |a, x| a.max(x.abs()));
            for i in 0..n {
                assert!(
                    (got[i] - want[i]).abs() < 1e-12 * scale,
                    "{i}: {} vs {}",
                    got[i],
                    want[i]
                );
            }
        }
    }
}
