//! Evaluation of the constraints and their derivatives: `Phi`, `Phi_q`, `gamma`, `Phi_q v`,
//! their element-local forms for sparse assembly, and the constraint Hessians.

use crate::cache::BodyAngles;
use crate::element_hessians::ElementHessian;
use crate::jet::{point, sub2, Dual, Frame, Scalar, NV};
use crate::joints::{JointKind, Revolute};
use crate::rows::SinCos;
use crate::system::*;
use nalgebra::DMatrix;

impl System {
    /// `Phi(q, t)` into `out` (length m).
    pub fn phi(&self, q: &[f64], t: f64, out: &mut [f64]) {
        let sc = SinCos::new(self, q, None);
        let var = |i: usize| [q[3 * i], q[3 * i + 1], q[3 * i + 2]];
        for (ji, j) in self.joints.iter().enumerate() {
            let at = self.joint_attach[ji];
            let qa = sc.frame(at.a, var);
            let qb = sc.frame(at.b, var);
            let o = self.row_offset[ji];
            if let JointKind::Revolute(Revolute { pa, pb, .. }) = &j.kind {
                // the generic evaluation's operations, no time part
                let d = sub2(point(&qa, *pa), point(&qb, *pb));
                let p = &mut out[o..o + 2];
                (p[0], p[1]) = (d[0], d[1]);
                continue;
            }
            let mut e = [0.0; 3];
            j.eval(&qa, &qb, &mut e);
            for k in 0..j.n_equations() {
                out[o + k] = e[k] - j.time_part(k, t)[0];
            }
        }
        self.spatial.phi(q, t, out);
    }

    /// `Phi_t(q, t)` into `out` (length m). Planar drivers and the spatial slide and distance
    /// drivers subtract a function of time, so theirs does not depend on `q`; a spatial angle
    /// driver's does.
    pub fn phi_t(&self, q: &[f64], t: f64, out: &mut [f64]) {
        for (ji, j) in self.joints.iter().enumerate() {
            let o = self.row_offset[ji];
            for k in 0..j.n_equations() {
                out[o + k] = -j.time_part(k, t)[1];
            }
        }
        self.spatial.phi_t(q, t, out);
    }

    #[inline(always)]
    pub(crate) fn scatter_row(&self, ji: usize, row: usize, g: &[f64; NV], out: &mut DMatrix<f64>) {
        self.joint_attach[ji].scatter_row(row, g, out);
    }

    /// The constraint Jacobian `Phi_q(q, t)` (m x n, dense) into `out` (overwritten). It
    /// depends on `t` only through spatial angle drivers.
    pub fn phi_q(&self, q: &[f64], t: f64, out: &mut DMatrix<f64>) {
        out.as_mut_slice().fill(0.0);
        let sc = SinCos::new(self, q, None);
        self.for_each_row(q, None, t, &sc, |ji, r, g, _| {
            self.scatter_row(ji, r, g, out)
        });
        self.spatial.rows(q, None, t, |r, sides, jet| {
            self.spatial.scatter_row(r, sides, &jet.g, out)
        });
    }

    /// `Phi_q` and the acceleration right-hand side
    /// `gamma = -(Phi_q v)_q v - 2 Phi_qt v - Phi_tt` in one pass.
    pub fn phi_q_gamma(
        &self,
        q: &[f64],
        v: &[f64],
        t: f64,
        phi_q: &mut DMatrix<f64>,
        gamma: &mut [f64],
    ) {
        phi_q.as_mut_slice().fill(0.0);
        let sc = SinCos::new(self, q, None);
        self.for_each_row(q, Some(v), t, &sc, |ji, r, g, gm| {
            self.scatter_row(ji, r, g, phi_q);
            gamma[r] = gm;
        });
        self.spatial.rows(q, Some(v), t, |r, sides, jet| {
            self.spatial.scatter_row(r, sides, &jet.g, phi_q);
            gamma[r] = -jet.d2;
        });
    }

    /// `Phi_q` and the Jacobian of the velocity constraint with respect to `q`,
    /// `(Phi_q v + Phi_t)_q` (m x n; row `k` is `v^T Hess(Phi_k)`, plus `Phi_tq` on a spatial
    /// angle driver's row, the only rows whose `Phi_qt` is not zero), at time `t`, in one pass.
    /// Together they form the Jacobian `[[Phi_q, 0], [(Phi_q v + Phi_t)_q, Phi_q]]` of the
    /// first-order constraints `(Phi, Phi_q v + Phi_t)` in `(q, v)`. Exact (Hessian jets),
    /// both outputs overwritten.
    pub fn phi_q_dot_jacobian(
        &self,
        q: &[f64],
        v: &[f64],
        t: f64,
        phi_q: &mut DMatrix<f64>,
        out: &mut DMatrix<f64>,
    ) {
        self.phi_q_dot_jacobian_impl(q, None, v, t, phi_q, out);
    }

    /// [`System::phi_q_dot_jacobian`] with the bodies' `sin`/`cos` from `angles` (a
    /// [`BodyAngles`] table at this `q`, as for [`System::phi_q_local_gamma_at`]): the same
    /// values without a `sin_cos` per body.
    pub fn phi_q_dot_jacobian_at(
        &self,
        q: &[f64],
        angles: &BodyAngles,
        v: &[f64],
        t: f64,
        phi_q: &mut DMatrix<f64>,
        out: &mut DMatrix<f64>,
    ) {
        debug_assert!(angles.matches(q));
        self.phi_q_dot_jacobian_impl(q, Some(angles), v, t, phi_q, out);
    }

    #[inline(always)]
    fn phi_q_dot_jacobian_impl(
        &self,
        q: &[f64],
        angles: Option<&BodyAngles>,
        v: &[f64],
        t: f64,
        phi_q: &mut DMatrix<f64>,
        out: &mut DMatrix<f64>,
    ) {
        phi_q.as_mut_slice().fill(0.0);
        out.as_mut_slice().fill(0.0);
        let sc = SinCos::new(self, q, angles);
        self.for_each_row_tan(q, v, &sc, |ji, r, g, dg| {
            self.scatter_row(ji, r, g, phi_q);
            self.scatter_row(ji, r, dg, out);
        });
        self.spatial.rows_tan(q, v, t, |r, sides, g, dg| {
            self.spatial.scatter_row(r, sides, g, phi_q);
            self.spatial.scatter_row(r, sides, dg, out);
        });
    }

    /// [`System::phi_q_dot_jacobian`] in element-local form (see [`System::phi_q_local`]):
    /// `grads[r]` is row `r` of `Phi_q`, `dgrads[r]` row `r` of `(Phi_q v)_q`, each six numbers
    /// in the columns of the joint's two bodies ([`System::joint_bodies`]).
    pub fn phi_q_dot_local(
        &self,
        q: &[f64],
        v: &[f64],
        grads: &mut [[f64; 6]],
        dgrads: &mut [[f64; 6]],
    ) {
        let sc = SinCos::new(self, q, None);
        self.for_each_row_tan(q, v, &sc, |_, r, g, dg| {
            grads[r] = *g;
            dgrads[r] = *dg;
        });
    }

    /// The bodies a joint attaches, as coordinate-block indices (`None` = ground).
    pub fn joint_bodies(&self, j: JointHandle) -> (Option<usize>, Option<usize>) {
        let at = self.joint_attach[j.0];
        (at.a, at.b)
    }

    /// `Phi_q` in element-local form alone (see [`System::phi_q_local_gamma`]): row `r` is
    /// `grads[r][0..3]` in the columns of the joint's first body and `grads[r][3..6]` in those
    /// of its second ([`System::joint_bodies`]).
    pub fn phi_q_local(&self, q: &[f64], grads: &mut [[f64; 6]]) {
        let sc = SinCos::new(self, q, None);
        self.for_each_row(q, None, 0.0, &sc, |_, r, g, _| grads[r] = *g);
    }

    /// `Phi_q` in element-local form and `gamma`, for sparse assembly: row `r` of `Phi_q` is
    /// `grads[r][0..3]` in the columns of the joint's first body and `grads[r][3..6]` in those of
    /// its second ([`System::joint_bodies`]; entries for ground are zero).
    pub fn phi_q_local_gamma(
        &self,
        q: &[f64],
        v: &[f64],
        t: f64,
        grads: &mut [[f64; 6]],
        gamma: &mut [f64],
    ) {
        let sc = SinCos::new(self, q, None);
        self.for_each_row(q, Some(v), t, &sc, |_, r, g, gm| {
            grads[r] = *g;
            gamma[r] = gm;
        });
    }

    /// `gamma(q, v, t)` alone.
    pub fn gamma(&self, q: &[f64], v: &[f64], t: f64, out: &mut [f64]) {
        let sc = SinCos::new(self, q, None);
        self.for_each_row(q, Some(v), t, &sc, |_, r, _, gm| out[r] = gm);
        self.spatial
            .rows(q, Some(v), t, |r, _, jet| out[r] = -jet.d2);
    }

    /// The velocity constraint `Phi_q v + Phi_t` into `out`.
    pub fn phi_dot(&self, q: &[f64], v: &[f64], t: f64, out: &mut [f64]) {
        let sc = SinCos::new(self, q, None);
        let var = |i: usize| -> [Dual; 3] {
            let (qi, vi) = (&q[3 * i..3 * i + 3], &v[3 * i..3 * i + 3]);
            [
                Dual::var(qi[0], vi[0]),
                Dual::var(qi[1], vi[1]),
                Dual::var(qi[2], vi[2]),
            ]
        };
        for (ji, j) in self.joints.iter().enumerate() {
            let at = self.joint_attach[ji];
            let (fa, fb) = (sc.frame(at.a, var), sc.frame(at.b, var));
            let o = self.row_offset[ji];
            if let JointKind::Revolute(Revolute { pa, pb, .. }) = &j.kind {
                // the generic evaluation's operations, no time part
                let d = sub2(point(&fa, *pa), point(&fb, *pb));
                let p = &mut out[o..o + 2];
                (p[0], p[1]) = (d[0].d, d[1].d);
                continue;
            }
            let mut e = [Dual::cst(0.0); 3];
            j.eval(&fa, &fb, &mut e);
            for k in 0..j.n_equations() {
                out[o + k] = e[k].d - j.time_part(k, t)[1];
            }
        }
        self.spatial
            .rows(q, Some(v), t, |r, _, jet| out[r] = jet.d1);
    }

    /// Joint `ji`'s rows of `Phi` and `Phidot` from its bodies' frames.
    #[inline(always)]
    pub(crate) fn eval_phi_phi_dot(
        &self,
        ji: usize,
        fa: &Frame<Dual>,
        fb: &Frame<Dual>,
        t: f64,
        phi: &mut [f64],
        phi_dot: &mut [f64],
    ) {
        let j = &self.joints[ji];
        let o = self.row_offset[ji];
        if let JointKind::Revolute(Revolute { pa, pb, .. }) = &j.kind {
            // the generic evaluation's operations, no time part
            let d = sub2(point(fa, *pa), point(fb, *pb));
            let (p, pd) = (&mut phi[o..o + 2], &mut phi_dot[o..o + 2]);
            (p[0], p[1], pd[0], pd[1]) = (d[0].v, d[1].v, d[0].d, d[1].d);
            return;
        }
        let mut e = [Dual::cst(0.0); 3];
        j.eval(fa, fb, &mut e);
        for k in 0..j.n_equations() {
            let tp = j.time_part(k, t);
            phi[o + k] = e[k].v - tp[0];
            phi_dot[o + k] = e[k].d - tp[1];
        }
    }

    /// `Phi(q, t)` and the velocity constraint `Phi_q v + Phi_t` in one pass with dual numbers
    /// (no gradients formed): the cheapest evaluation of both constraint levels, e.g. for the
    /// residual of a Newton iteration on the first-order manifold.
    pub fn phi_and_phi_dot(
        &self,
        q: &[f64],
        v: &[f64],
        t: f64,
        phi: &mut [f64],
        phi_dot: &mut [f64],
    ) {
        let loc = |i: usize| -> Frame<Dual> {
            let (qi, vi) = (&q[3 * i..3 * i + 3], &v[3 * i..3 * i + 3]);
            Frame::new([
                Dual::var(qi[0], vi[0]),
                Dual::var(qi[1], vi[1]),
                Dual::var(qi[2], vi[2]),
            ])
        };
        let fixed = Frame::fixed();
        let mut eval = |ji: usize, fa: &Frame<Dual>, fb: &Frame<Dual>| {
            self.eval_phi_phi_dot(ji, fa, fb, t, phi, phi_dot);
        };
        // each body's sin/cos once (not once per joint) for models of up to 16 bodies
        const STACK: usize = 16;
        let nb = self.bodies.len();
        if nb <= STACK {
            let mut frames = [fixed; STACK];
            for (i, f) in frames.iter_mut().enumerate().take(nb) {
                *f = loc(i);
            }
            for ji in 0..self.joints.len() {
                let at = self.joint_attach[ji];
                let fa = at.a.map_or(&fixed, |i| &frames[i]);
                let fb = at.b.map_or(&fixed, |i| &frames[i]);
                eval(ji, fa, fb);
            }
        } else {
            for ji in 0..self.joints.len() {
                let at = self.joint_attach[ji];
                let fa = at.a.map_or(fixed, loc);
                let fb = at.b.map_or(fixed, loc);
                eval(ji, &fa, &fb);
            }
        }
        self.spatial_phi_and_phi_dot(q, v, t, phi, phi_dot);
    }

    /// The spatial rows of [`System::phi_and_phi_dot`].
    fn spatial_phi_and_phi_dot(
        &self,
        q: &[f64],
        v: &[f64],
        t: f64,
        phi: &mut [f64],
        phi_dot: &mut [f64],
    ) {
        self.spatial.rows(q, Some(v), t, |r, _, jet| {
            phi[r] = jet.v;
            phi_dot[r] = jet.d1;
        });
    }

    /// [`System::phi_and_phi_dot`] with the bodies' `sin`/`cos` brought to `q` by
    /// [`BodyAngles::update_near`] (rotation from the configuration `angles` held): the same
    /// values to a few units in the last place, cheaper when called repeatedly at nearby
    /// configurations (the chord iterations of a tangent chart, a projection). Revolute rows
    /// are written out in closed form (a body point `r + R(theta) p` and its velocity
    /// `v_r + omega R'(theta) p`, in the operations of the dual-number evaluation, so bit for
    /// bit its values); the other joint kinds go through that evaluation. Allocation-free.
    pub fn phi_and_phi_dot_cached(
        &self,
        q: &[f64],
        v: &[f64],
        t: f64,
        phi: &mut [f64],
        phi_dot: &mut [f64],
        angles: &mut BodyAngles,
    ) {
        angles.update_near(self, q);
        let angles = &*angles;
        if !self.revolute_rows.is_empty() {
            revolute_residuals(&self.revolute_rows, angles, q, v, phi, phi_dot);
            return;
        }
        for ji in 0..self.joints.len() {
            let at = self.joint_attach[ji];
            let j = &self.joints[ji];
            if let JointKind::Revolute(Revolute { pa, pb, .. }) = &j.kind {
                let (xa, va) = revolute_point(angles, q, v, at.a, *pa);
                let (xb, vb) = revolute_point(angles, q, v, at.b, *pb);
                let o = self.row_offset[ji];
                let (p, pd) = (&mut phi[o..o + 2], &mut phi_dot[o..o + 2]);
                (p[0], p[1]) = (xa[0] - xb[0], xa[1] - xb[1]);
                (pd[0], pd[1]) = (va[0] - vb[0], va[1] - vb[1]);
                continue;
            }
            let (fa, fb) = (
                dual_frame(angles, q, v, at.a),
                dual_frame(angles, q, v, at.b),
            );
            self.eval_phi_phi_dot(ji, &fa, &fb, t, phi, phi_dot);
        }
        self.spatial_phi_and_phi_dot(q, v, t, phi, phi_dot);
    }

    /// `Phi_q(q, t)` as (row, column, value) triplets of its structural non-zeros, for sparse
    /// factorisations. `out` is cleared first; its capacity is reused.
    pub fn phi_q_triplets(&self, q: &[f64], t: f64, out: &mut Vec<(usize, usize, f64)>) {
        out.clear();
        let sc = SinCos::new(self, q, None);
        self.for_each_row(q, None, t, &sc, |ji, r, g, _| {
            let at = self.joint_attach[ji];
            if let Some(i) = at.a {
                for l in 0..3 {
                    out.push((r, 3 * i + l, g[l]));
                }
            }
            if let Some(i) = at.b {
                for l in 0..3 {
                    out.push((r, 3 * i + l, g[3 + l]));
                }
            }
        });
        self.spatial.triplets(q, t, out);
    }

    /// The lambda-weighted constraint Hessian `sum_k lambda_k d^2 Phi_k / dq^2` (n x n) at time
    /// `t` into `out` (overwritten).
    pub fn constraint_hessian(&self, q: &[f64], t: f64, lambda: &[f64], out: &mut DMatrix<f64>) {
        out.as_mut_slice().fill(0.0);
        self.add_constraint_hessian(q, t, lambda, 1.0, out);
    }

    /// Adds `scale * sum_k lambda_k d^2 Phi_k / dq^2` at time `t` into `out`.
    pub fn add_constraint_hessian(
        &self,
        q: &[f64],
        t: f64,
        lambda: &[f64],
        scale: f64,
        out: &mut DMatrix<f64>,
    ) {
        // the joints' Hessians from the element pass (closed-form revolute rows)
        self.element_hessians(q, false, |el| {
            let ElementHessian::Joint {
                attach: at,
                row: o,
                equations: e,
                ..
            } = el
            else {
                return;
            };
            let mut h = [[0.0; NV]; NV];
            for (k, ek) in e.iter().enumerate() {
                let l = lambda[o + k] * scale;
                for r in 0..NV {
                    for c in 0..NV {
                        h[r][c] += l * ek.h[r][c];
                    }
                }
            }
            Self::scatter_hess(at, &h, out);
        });
        self.spatial.add_hessian(q, t, lambda, scale, out);
    }

    /// The nonzeros `(row column, column, value)` of row `r`'s Hessian in global columns, if
    /// `r` is a spatial row whose Hessian is constant (every spatial equation is quadratic;
    /// an angle driver's rows turn with time and give `None`, as every planar row does). The
    /// Hessians are evaluated once, at the first call of this or of the other spatial Hessian
    /// passes (`q` is only used then).
    pub fn spatial_row_hessian(&self, q: &[f64], r: usize) -> Option<&[(usize, usize, f64)]> {
        self.spatial.row_hessian(q, r)
    }

    /// `f(row column, column, value)` for the nonzeros of row `r`'s Hessian at time `t` in
    /// global columns, for every spatial row, an angle driver's included (whose Hessian turns
    /// with `theta(t)`: `cos theta H_0 - sin theta H_1` of its two bilinear components);
    /// nothing for a planar row. From the same cache as [`System::spatial_row_hessian`].
    pub fn spatial_row_hessian_at(
        &self,
        q: &[f64],
        t: f64,
        r: usize,
        f: impl FnMut(usize, usize, f64),
    ) {
        self.spatial.row_hessian_at(q, t, r, f);
    }

    /// The spatial rows' part of `out += scale sum_r w_r Hess(Phi_r) x` (`out` and `x` of
    /// length n, `weights` of length m) at time `t`: what a pass over the planar elements
    /// ([`System::joint_elements`], which hands out planar joints only) leaves out. An angle
    /// driver's row takes its Hessian at `t`.
    pub fn add_spatial_hessian_vector(
        &self,
        q: &[f64],
        t: f64,
        x: &[f64],
        weights: &[f64],
        scale: f64,
        out: &mut [f64],
    ) {
        self.spatial
            .add_hessian_vector(q, t, x, weights, scale, out);
    }

    /// The spatial rows' part of [`System::add_constraint_hessian`]: `out += scale
    /// sum_r lambda_r Hess(Phi_r)` over the spatial rows only (`n x n`).
    pub fn add_spatial_constraint_hessian(
        &self,
        q: &[f64],
        t: f64,
        lambda: &[f64],
        scale: f64,
        out: &mut DMatrix<f64>,
    ) {
        self.spatial.add_hessian(q, t, lambda, scale, out);
    }

    /// The spatial rows of `(Phi_q v + Phi_t)_q` added into the same rows of `out` (`m x n`):
    /// the spatial part of [`System::phi_q_dot_jacobian`]'s second output.
    pub fn add_spatial_phi_q_dot(&self, q: &[f64], v: &[f64], t: f64, out: &mut DMatrix<f64>) {
        self.spatial.rows_tan(q, v, t, |r, sides, _, dg| {
            self.spatial.scatter_row(r, sides, dg, out);
        });
    }

    pub(crate) fn scatter_hess(at: Attach, h: &[[f64; NV]; NV], out: &mut DMatrix<f64>) {
        at.scatter_hess(h, out);
    }

    // ---------------------------------------------------------------- forces and energy
}

/// A revolute joint of a model whose joints are all planar revolute ones: its bodies
/// (`GROUND` for the ground), points and first row.
#[derive(Clone, Copy, Debug)]
pub(crate) struct RevoluteRow {
    a: usize,
    b: usize,
    pa: [f64; 2],
    pb: [f64; 2],
    row: usize,
}

impl RevoluteRow {
    /// The ground's index in [`RevoluteRow::a`] and [`RevoluteRow::b`].
    const GROUND: usize = usize::MAX;

    /// The table of `sys`'s joints if they are all planar revolute ones (and there is no
    /// spatial part), else empty.
    pub(crate) fn table(sys: &System) -> Vec<Self> {
        if sys.has_spatial() {
            return Vec::new();
        }
        let mut out = Vec::with_capacity(sys.joints.len());
        for (ji, j) in sys.joints.iter().enumerate() {
            let JointKind::Revolute(Revolute { pa, pb, .. }) = &j.kind else {
                return Vec::new();
            };
            let at = sys.joint_attach[ji];
            out.push(RevoluteRow {
                a: at.a.unwrap_or(Self::GROUND),
                b: at.b.unwrap_or(Self::GROUND),
                pa: *pa,
                pb: *pb,
                row: sys.row_offset[ji],
            });
        }
        out
    }
}

/// `Phi` and `Phi_q v` of the all-revolute model `rows` (the values of the joint loop of
/// [`System::phi_and_phi_dot_cached`], operation for operation).
#[inline]
fn revolute_residuals(
    rows: &[RevoluteRow],
    angles: &BodyAngles,
    q: &[f64],
    v: &[f64],
    phi: &mut [f64],
    phi_dot: &mut [f64],
) {
    let side = |i: usize, p: [f64; 2]| {
        if i == RevoluteRow::GROUND {
            revolute_point(angles, q, v, None, p)
        } else {
            revolute_point(angles, q, v, Some(i), p)
        }
    };
    for r in rows {
        let (xa, va) = side(r.a, r.pa);
        let (xb, vb) = side(r.b, r.pb);
        let (p, pd) = (&mut phi[r.row..r.row + 2], &mut phi_dot[r.row..r.row + 2]);
        (p[0], p[1]) = (xa[0] - xb[0], xa[1] - xb[1]);
        (pd[0], pd[1]) = (va[0] - vb[0], va[1] - vb[1]);
    }
}

/// The point `r + R(theta) p` of body `i` (ground for `None`) and its velocity
/// `v_r + omega R'(theta) p`, from the cached `sin`/`cos`, written as the dual-number
/// evaluation ([`point`] on a [`Frame`] of [`Dual`]s) computes them: the same operations in
/// the same order, so the same bits.
#[inline(always)]
fn revolute_point(
    angles: &BodyAngles,
    q: &[f64],
    v: &[f64],
    i: Option<usize>,
    p: [f64; 2],
) -> ([f64; 2], [f64; 2]) {
    match i {
        Some(i) => {
            let [_, s, c] = angles.sin_cos_of(i);
            let (qi, vi) = (&q[3 * i..3 * i + 3], &v[3 * i..3 * i + 3]);
            // the derivatives of cos and sin along the velocity
            let (dc, ds) = (-s * vi[2], c * vi[2]);
            (
                [qi[0] + c * p[0] - s * p[1], qi[1] + s * p[0] + c * p[1]],
                [vi[0] + dc * p[0] - ds * p[1], vi[1] + ds * p[0] + dc * p[1]],
            )
        }
        // the ground frame: identity rotation, constant
        None => (
            [0.0 + 1.0 * p[0] - 0.0 * p[1], 0.0 + 0.0 * p[0] + 1.0 * p[1]],
            [0.0 + 0.0 * p[0] - 0.0 * p[1], 0.0 + 0.0 * p[0] + 0.0 * p[1]],
        ),
    }
}

/// Body `i`'s dual-number frame (value and derivative along `v`) with `sin`/`cos` from
/// `angles`; ground is fixed.
#[inline(always)]
fn dual_frame(angles: &BodyAngles, q: &[f64], v: &[f64], i: Option<usize>) -> Frame<Dual> {
    match i {
        Some(i) => {
            let [_, s, c] = angles.sin_cos_of(i);
            let (qi, vi) = (&q[3 * i..3 * i + 3], &v[3 * i..3 * i + 3]);
            let w = vi[2];
            Frame {
                q: [
                    Dual::var(qi[0], vi[0]),
                    Dual::var(qi[1], vi[1]),
                    Dual::var(qi[2], vi[2]),
                ],
                c: Dual { v: c, d: -s * w },
                s: Dual { v: s, d: c * w },
            }
        }
        None => Frame::fixed(),
    }
}

#[cfg(test)]
mod phi_q_dot_jacobian_tests {
    use crate::models;
    use nalgebra::DMatrix;

    #[test]
    fn matches_finite_differences_of_phi_q_v() {
        let systems = [
            crate::fixtures::every_joint_kind(),
            models::slider_crank().unwrap(),
            models::four_bar().unwrap(),
            models::manipulator().unwrap(),
            // more bodies than phi_and_phi_dot's stack of frames
            models::n_link_chain(20).unwrap(),
        ];
        for sys in &systems {
            let (n, m) = (sys.n_coords(), sys.n_constraints());
            let q: Vec<f64> = (0..n)
                .map(|i| 0.3 + 0.17 * i as f64 - 0.05 * (i * i) as f64)
                .collect();
            let v: Vec<f64> = (0..n).map(|i| 1.3 - 0.41 * i as f64).collect();
            let mut jq = DMatrix::zeros(m, n);
            let mut d = DMatrix::zeros(m, n);
            sys.phi_q_dot_jacobian(&q, &v, 0.0, &mut jq, &mut d);
            let mut jref = DMatrix::zeros(m, n);
            sys.phi_q(&q, 0.0, &mut jref);
            assert!((&jq - &jref).amax() < 1e-15);
            let (mut p1, mut p2, mut d1, mut d2) =
                (vec![0.0; m], vec![0.0; m], vec![0.0; m], vec![0.0; m]);
            sys.phi(&q, 0.7, &mut p1);
            sys.phi_dot(&q, &v, 0.7, &mut d1);
            sys.phi_and_phi_dot(&q, &v, 0.7, &mut p2, &mut d2);
            for r in 0..m {
                assert!((p1[r] - p2[r]).abs() < 1e-15);
                assert!((d1[r] - d2[r]).abs() < 1e-13);
            }
            let eps = 1e-6;
            let mut jp = DMatrix::zeros(m, n);
            let mut jm = DMatrix::zeros(m, n);
            let vv = nalgebra::DVector::from_column_slice(&v);
            for c in 0..n {
                let mut qp = q.clone();
                let mut qm = q.clone();
                qp[c] += eps;
                qm[c] -= eps;
                sys.phi_q(&qp, 0.0, &mut jp);
                sys.phi_q(&qm, 0.0, &mut jm);
                let fd = (&jp * &vv - &jm * &vv) / (2.0 * eps);
                for r in 0..m {
                    assert!(
                        (fd[r] - d[(r, c)]).abs() < 1e-8 * (1.0 + d[(r, c)].abs()),
                        "row {r} col {c}: fd {} exact {}",
                        fd[r],
                        d[(r, c)]
                    );
                }
            }
        }
    }

    /// The closed-form revolute rows of `phi_and_phi_dot_cached` give bit for bit what the
    /// dual-number evaluation at the same cached angles gives (and so the generic evaluation
    /// to a few ulps), on every joint kind, the manipulator and a chain longer than the stack
    /// of frames.
    #[test]
    fn closed_form_cached_residual_matches_the_dual_evaluation_bit_for_bit() {
        for sys in [
            crate::fixtures::every_joint_kind(),
            models::manipulator().unwrap(),
            models::n_link_chain(20).unwrap(),
        ] {
            let (n, m) = (sys.n_coords(), sys.n_constraints());
            let mut c1 = crate::BodyAngles::sized(&sys);
            let mut c2 = crate::BodyAngles::sized(&sys);
            let mut q: Vec<f64> = (0..n).map(|i| 0.3 + 0.17 * i as f64).collect();
            q[2] += 300.0;
            let v: Vec<f64> = (0..n).map(|i| 1.3 - 0.41 * i as f64).collect();
            let (mut p1, mut p2, mut d1, mut d2) =
                (vec![0.0; m], vec![1.0; m], vec![0.0; m], vec![1.0; m]);
            let (mut p0, mut d0) = (vec![0.0; m], vec![0.0; m]);
            let mut worst = 0.0f64;
            for k in 0..30 {
                let step = if k % 11 == 10 {
                    0.1
                } else {
                    1e-4 / (1 + k) as f64
                };
                for (i, qi) in q.iter_mut().enumerate() {
                    *qi += step * ((i + k) as f64 * 0.7).sin();
                }
                if k == 20 {
                    c1.invalidate();
                    c2.invalidate();
                }
                c1.update_near(&sys, &q);
                for ji in 0..sys.joints.len() {
                    let at = sys.joint_attach[ji];
                    let fa = super::dual_frame(&c1, &q, &v, at.a);
                    let fb = super::dual_frame(&c1, &q, &v, at.b);
                    sys.eval_phi_phi_dot(ji, &fa, &fb, 0.3, &mut p1, &mut d1);
                }
                sys.phi_and_phi_dot_cached(&q, &v, 0.3, &mut p2, &mut d2, &mut c2);
                sys.phi_and_phi_dot(&q, &v, 0.3, &mut p0, &mut d0);
                for r in 0..m {
                    assert_eq!(p1[r].to_bits(), p2[r].to_bits(), "phi row {r}");
                    assert_eq!(d1[r].to_bits(), d2[r].to_bits(), "phi_dot row {r}");
                    worst = worst.max((p0[r] - p2[r]).abs()).max((d0[r] - d2[r]).abs());
                }
            }
            assert!(worst < 1e-13, "near vs exact: {worst:e}");
        }
    }

    /// The angle cache gives phi and phi_dot to a few ulps of the exact evaluation along a
    /// Newton-like sequence of nearby configurations (rotations, large jumps, invalidation).
    #[test]
    fn angle_cache_matches_exact_evaluation() {
        for sys in [
            crate::fixtures::every_joint_kind(),
            models::manipulator().unwrap(),
        ] {
            let (n, m) = (sys.n_coords(), sys.n_constraints());
            let mut cache = crate::BodyAngles::sized(&sys);
            let mut q: Vec<f64> = (0..n).map(|i| 0.3 + 0.17 * i as f64).collect();
            // a wound-up angle
            q[2] += 300.0;
            let v: Vec<f64> = (0..n).map(|i| 1.3 - 0.41 * i as f64).collect();
            let (mut p1, mut p2, mut d1, mut d2) =
                (vec![0.0; m], vec![0.0; m], vec![0.0; m], vec![0.0; m]);
            let mut worst = 0.0f64;
            for k in 0..40 {
                // shrinking Newton-like increments, a jump every 13 evaluations
                let step = if k % 13 == 12 {
                    0.1
                } else {
                    1e-4 / (1 + k % 13) as f64
                };
                for (i, qi) in q.iter_mut().enumerate() {
                    *qi += step * ((i + k) as f64 * 0.7).sin();
                }
                if k == 30 {
                    cache.invalidate();
                }
                sys.phi_and_phi_dot(&q, &v, 0.3, &mut p1, &mut d1);
                sys.phi_and_phi_dot_cached(&q, &v, 0.3, &mut p2, &mut d2, &mut cache);
                for r in 0..m {
                    worst = worst.max((p1[r] - p2[r]).abs()).max((d1[r] - d2[r]).abs());
                }
            }
            println!("cached vs exact: {worst:e}");
            assert!(worst < 1e-13, "cached vs exact: {worst:e}");
        }
    }
}
