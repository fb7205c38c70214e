//! The everyday constraint pass: every row of `Phi_q` in element-local form (six numbers: the
//! columns of the joint's two bodies) with its `gamma`, what the index-1 acceleration solve,
//! the projections and the dense `Phi_q` all start from.
//!
//! Each body's `sin`/`cos` is evaluated once per pass ([`SinCos`]), not once per joint side.
//! Revolute and prismatic rows are written in closed form (a body point `r + R(theta) p` has
//! the gradient `e_x` or `e_y` plus `R'(theta) p` in `theta`, and the quadratic velocity term
//! `-omega^2 R(theta) p`); the other kinds go through the generic [`DirJet`] evaluation on the
//! shared rotations. Both give what the generic evaluation gives, up to rounding (the
//! revolute gradients bit for bit). [`System::for_each_row_tan`] does the same for the
//! gradients of the velocity constraint (`Hess(Phi_r) v`, the tangent chart's pass).

use crate::cache::BodyAngles;
use crate::jet::{DirJet, Frame, Scalar, TanJet, NV};
use crate::joints::{JointKind, Prismatic, RevoluteSide};
use crate::system::System;

/// Up to this many bodies a pass without a [`BodyAngles`] table keeps every body's `sin`/`cos`
/// on the stack (one evaluation per body); above it, it evaluates them once per joint side.
pub(crate) const STACK_BODIES: usize = 16;

/// `(sin, cos)` of every body's angle at one configuration, for one pass: from a
/// [`BodyAngles`] table, from a stack table filled once, or evaluated at each use (models of
/// more than [`STACK_BODIES`] bodies without a table). The same values whichever the source.
// a value on the stack of one pass: the size difference costs nothing, a box would allocate
#[allow(clippy::large_enum_variant)]
pub(crate) enum SinCos<'a> {
    /// A table evaluated at this configuration.
    Table(&'a BodyAngles),
    /// `[sin, cos]` per body (the first `nb` entries).
    Stack([[f64; 2]; STACK_BODIES]),
    /// `q`: evaluated at each use.
    Direct(&'a [f64]),
}

impl<'a> SinCos<'a> {
    /// The angles of `sys`'s bodies at `q`, from `table` if given (evaluated at this `q`).
    #[inline(always)]
    pub(crate) fn new(sys: &System, q: &'a [f64], table: Option<&'a BodyAngles>) -> Self {
        let nb = sys.bodies.len();
        match table {
            Some(t) => SinCos::Table(t),
            None if nb <= STACK_BODIES => {
                let mut stack = [[0.0; 2]; STACK_BODIES];
                for (i, e) in stack.iter_mut().enumerate().take(nb) {
                    let (s, c) = q[3 * i + 2].sin_cos();
                    *e = [s, c];
                }
                SinCos::Stack(stack)
            }
            None => SinCos::Direct(q),
        }
    }

    /// `(sin theta_i, cos theta_i)`.
    #[inline(always)]
    pub(crate) fn get(&self, i: usize) -> (f64, f64) {
        match self {
            SinCos::Table(t) => {
                let [_, s, c] = t.sin_cos_of(i);
                (s, c)
            }
            SinCos::Stack(st) => {
                let [s, c] = st[i];
                (s, c)
            }
            SinCos::Direct(q) => q[3 * i + 2].sin_cos(),
        }
    }

    /// `R(theta_i) p`.
    #[inline(always)]
    pub(crate) fn rotate(&self, i: usize, p: [f64; 2]) -> [f64; 2] {
        let (sn, cs) = self.get(i);
        [cs * p[0] - sn * p[1], sn * p[0] + cs * p[1]]
    }

    /// Body `i`'s frame with the jet coordinates `vars` (no trigonometry), or ground's.
    #[inline(always)]
    pub(crate) fn frame<T: Scalar>(
        &self,
        i: Option<usize>,
        vars: impl Fn(usize) -> [T; 3],
    ) -> Frame<T> {
        match i {
            Some(i) => {
                let (s, c) = self.get(i);
                Frame::with_sin_cos(vars(i), s, c)
            }
            None => Frame::fixed(),
        }
    }
}

/// `(-y, x)`: the quarter turn, `R'(theta) p = perp(R(theta) p)`.
#[inline(always)]
fn perp(u: [f64; 2]) -> [f64; 2] {
    [-u[1], u[0]]
}

#[inline(always)]
fn dot2(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}

impl System {
    /// The everyday pass: for every constraint row `r` (joint `ji`), its element-local gradient
    /// (row `r` of `Phi_q` in the columns of the joint's two bodies, zero for ground) and its
    /// `gamma_r = -(Phi_q v)_q v - Phi_tt` (`v = None`: zero velocities, so the time part alone)
    /// handed to `visit(ji, r, gradient, gamma_r)` in row order.
    #[inline(always)]
    pub(crate) fn for_each_row(
        &self,
        q: &[f64],
        v: Option<&[f64]>,
        t: f64,
        sc: &SinCos,
        mut visit: impl FnMut(usize, usize, &[f64; NV], f64),
    ) {
        let vel = |i: usize, k: usize| v.map_or(0.0, |v| v[3 * i + k]);
        for (ji, j) in self.joints.iter().enumerate() {
            let at = self.joint_attach[ji];
            let o = self.row_offset[ji];
            if let Some(sides) = j.revolute_sides(at) {
                // point_a - point_b: gradient e_x / e_y and R'(theta) p, gamma omega^2 R p
                let mut g = [[0.0; NV]; 2];
                let mut gamma = [0.0; 2];
                for RevoluteSide {
                    body,
                    slot,
                    p,
                    sign,
                } in sides
                {
                    let Some(i) = body else { continue };
                    let r0 = sc.rotate(i, p);
                    let r1 = perp(r0);
                    let w = vel(i, 2);
                    for c in 0..2 {
                        g[c][slot + c] = sign;
                        g[c][slot + 2] = sign * r1[c];
                        gamma[c] += sign * r0[c] * (w * w);
                    }
                }
                visit(ji, o, &g[0], gamma[0]);
                visit(ji, o + 1, &g[1], gamma[1]);
                continue;
            }
            if let JointKind::Prismatic(Prismatic { pa, pb, axis, .. }) = &j.kind {
                // n . d with the normal n = R_a (-axis_y, axis_x) and d = P_b - P_a; the
                // relative angle theta_b - theta_a
                let u = [-axis[1], axis[0]];
                let (mut xa, mut va, mut wa, mut nrm, mut ra) = ([0.0; 2], [0.0; 2], 0.0, u, *pa);
                if let Some(i) = at.a {
                    xa = [q[3 * i], q[3 * i + 1]];
                    va = [vel(i, 0), vel(i, 1)];
                    wa = vel(i, 2);
                    nrm = sc.rotate(i, u);
                    ra = sc.rotate(i, *pa);
                }
                let (mut xb, mut vb, mut wb, mut rb) = ([0.0; 2], [0.0; 2], 0.0, *pb);
                if let Some(i) = at.b {
                    xb = [q[3 * i], q[3 * i + 1]];
                    vb = [vel(i, 0), vel(i, 1)];
                    wb = vel(i, 2);
                    rb = sc.rotate(i, *pb);
                }
                let d = [xb[0] + rb[0] - xa[0] - ra[0], xb[1] + rb[1] - xa[1] - ra[1]];
                let (pra, prb, pn) = (perp(ra), perp(rb), perp(nrm));
                // d' = v_b + w_b perp(R_b p_b) - v_a - w_a perp(R_a p_a)
                let dd = [
                    vb[0] + wb * prb[0] - va[0] - wa * pra[0],
                    vb[1] + wb * prb[1] - va[1] - wa * pra[1],
                ];
                // (n . d)'' without the accelerations: n'' = -w_a^2 n, n' = w_a perp(n),
                // d'' = w_a^2 R_a p_a - w_b^2 R_b p_b
                let (wa2, wb2) = (wa * wa, wb * wb);
                let dd2 = [wa2 * ra[0] - wb2 * rb[0], wa2 * ra[1] - wb2 * rb[1]];
                let d2 = -wa2 * dot2(nrm, d) + 2.0 * wa * dot2(pn, dd) + dot2(nrm, dd2);
                let (mut g0, mut g1) = ([0.0; NV], [0.0; NV]);
                if at.a.is_some() {
                    g0[0] = -nrm[0];
                    g0[1] = -nrm[1];
                    g0[2] = dot2(pn, d) - dot2(nrm, pra);
                    g1[2] = -1.0;
                }
                if at.b.is_some() {
                    g0[3] = nrm[0];
                    g0[4] = nrm[1];
                    g0[5] = dot2(nrm, prb);
                    g1[5] = 1.0;
                }
                visit(ji, o, &g0, -d2);
                visit(ji, o + 1, &g1, 0.0);
                continue;
            }
            let var = |slot: usize| {
                move |i: usize| -> [DirJet; 3] {
                    std::array::from_fn(|k| DirJet::var(slot + k, q[3 * i + k], vel(i, k)))
                }
            };
            let mut e = [DirJet::cst(0.0); 3];
            j.eval(&sc.frame(at.a, var(0)), &sc.frame(at.b, var(3)), &mut e);
            for k in 0..j.n_equations() {
                visit(ji, o + k, &e[k].g, -e[k].d2 + j.time_part(k, t)[2]);
            }
        }
    }

    /// For every constraint row `r` (joint `ji`), its element-local gradient and the gradient
    /// of its velocity constraint, `Hess(Phi_r) v` (the row of `(Phi_q v)_q`), handed to
    /// `visit(ji, r, gradient, hess_v)`: revolute rows in closed form (one second derivative,
    /// `-R(theta) p` in theta-theta), the other kinds through [`TanJet`] on the shared
    /// rotations.
    #[inline(always)]
    pub(crate) fn for_each_row_tan(
        &self,
        q: &[f64],
        v: &[f64],
        sc: &SinCos,
        mut visit: impl FnMut(usize, usize, &[f64; NV], &[f64; NV]),
    ) {
        for (ji, j) in self.joints.iter().enumerate() {
            let at = self.joint_attach[ji];
            let o = self.row_offset[ji];
            if let Some(sides) = j.revolute_sides(at) {
                let (mut g, mut dg) = ([[0.0; NV]; 2], [[0.0; NV]; 2]);
                for RevoluteSide {
                    body,
                    slot,
                    p,
                    sign,
                } in sides
                {
                    let Some(i) = body else { continue };
                    let r0 = sc.rotate(i, p);
                    let r1 = perp(r0);
                    let w = v[3 * i + 2];
                    for c in 0..2 {
                        g[c][slot + c] = sign;
                        g[c][slot + 2] = sign * r1[c];
                        dg[c][slot + 2] = -sign * r0[c] * w;
                    }
                }
                visit(ji, o, &g[0], &dg[0]);
                visit(ji, o + 1, &g[1], &dg[1]);
                continue;
            }
            let var = |slot: usize| {
                move |i: usize| -> [TanJet; 3] {
                    std::array::from_fn(|k| TanJet::var(slot + k, q[3 * i + k], v[3 * i + k]))
                }
            };
            let mut e = [TanJet::cst(0.0); 3];
            j.eval(&sc.frame(at.a, var(0)), &sc.frame(at.b, var(3)), &mut e);
            for k in 0..j.n_equations() {
                visit(ji, o + k, &e[k].g, &e[k].dg);
            }
        }
    }

    /// [`System::phi_q_local_gamma`] with the bodies' `sin`/`cos` from `angles` (a
    /// [`BodyAngles`] table evaluated at this `q`): the same values, one `sin_cos` per body
    /// whatever the model's size (what a solver holding a table per configuration calls).
    pub fn phi_q_local_gamma_at(
        &self,
        q: &[f64],
        angles: &BodyAngles,
        v: &[f64],
        t: f64,
        grads: &mut [[f64; NV]],
        gamma: &mut [f64],
    ) {
        debug_assert!(angles.matches(q));
        let sc = SinCos::new(self, q, Some(angles));
        self.for_each_row(q, Some(v), t, &sc, |_, r, g, gm| {
            grads[r] = *g;
            gamma[r] = gm;
        });
    }
}

#[cfg(test)]
mod tests {
    use crate::jet::{DirJet, Scalar};
    use crate::{models, BodyAngles, System};
    use nalgebra::DMatrix;

    /// The generic forward-mode rows (every kind through [`DirJet`], one `sin_cos` per joint
    /// side): the reference of the closed forms.
    fn generic_rows(sys: &System, q: &[f64], v: &[f64], t: f64) -> (Vec<[f64; 6]>, Vec<f64>) {
        let m = sys.n_constraints();
        let (mut g, mut gamma) = (vec![[0.0; 6]; m], vec![0.0; m]);
        for (ji, j) in sys.joints.iter().enumerate() {
            let at = sys.joint_attach[ji];
            let mut e = [DirJet::cst(0.0); 3];
            j.eval(
                &System::loc_dir(q, Some(v), at.a, 0),
                &System::loc_dir(q, Some(v), at.b, 3),
                &mut e,
            );
            let o = sys.row_offset[ji];
            for k in 0..j.n_equations() {
                g[o + k] = e[k].g;
                gamma[o + k] = -e[k].d2 + j.time_part(k, t)[2];
            }
        }
        (g, gamma)
    }

    /// The everyday rows (closed-form revolute and prismatic rows, shared rotations) equal the
    /// generic jets to rounding, on every joint kind, the models with prismatic joints and a
    /// chain of more bodies than the stack table holds; the table-driven pass equals the plain
    /// one bit for bit; the dense, triplet, gamma-only and velocity-constraint passes agree
    /// with the local rows.
    #[test]
    fn everyday_rows_match_the_generic_jets() {
        let mut systems = crate::fixtures::derivative_test_systems().to_vec();
        systems.push(models::slider_crank().unwrap());
        systems.push(models::n_link_chain(super::STACK_BODIES + 4).unwrap());
        for sys in &systems {
            let (n, m) = (sys.n_coords(), sys.n_constraints());
            let (q, v) = crate::fixtures::generic_point(n);
            let t = 0.7;
            let (gref, gamma_ref) = generic_rows(sys, &q, &v, t);
            let (mut g, mut gamma) = (vec![[9.0; 6]; m], vec![9.0; m]);
            sys.phi_q_local_gamma(&q, &v, t, &mut g, &mut gamma);
            let scale = 1.0 + gamma_ref.iter().fold(0.0f64, |a, x| a.max(x.abs()));
            for r in 0..m {
                for l in 0..6 {
                    assert!(
                        (g[r][l] - gref[r][l]).abs() <= 1e-15 * (1.0 + gref[r][l].abs()),
                        "row {r} [{l}]: {} vs {}",
                        g[r][l],
                        gref[r][l]
                    );
                }
                assert!(
                    (gamma[r] - gamma_ref[r]).abs() <= 1e-14 * scale,
                    "gamma {r}: {} vs {}",
                    gamma[r],
                    gamma_ref[r]
                );
            }
            // with a table of the body angles: bit for bit
            let ang = BodyAngles::new(sys, &q);
            let (mut g2, mut gamma2) = (vec![[9.0; 6]; m], vec![9.0; m]);
            sys.phi_q_local_gamma_at(&q, &ang, &v, t, &mut g2, &mut gamma2);
            for r in 0..m {
                for l in 0..6 {
                    assert_eq!(g[r][l].to_bits(), g2[r][l].to_bits(), "table row {r}");
                }
                assert_eq!(gamma[r].to_bits(), gamma2[r].to_bits(), "table gamma {r}");
            }
            // the other passes of the same rows
            let mut gl = vec![[9.0; 6]; m];
            sys.phi_q_local(&q, &mut gl);
            let (mut dense, mut dense2) = (DMatrix::from_element(m, n, 9.0), DMatrix::zeros(m, n));
            let mut gamma3 = vec![9.0; m];
            sys.phi_q_gamma(&q, &v, t, &mut dense, &mut gamma3);
            sys.phi_q(&q, t, &mut dense2);
            assert_eq!(gl_dense(sys, &gl), gl_dense(sys, &g));
            let mut trip = Vec::new();
            sys.phi_q_triplets(&q, t, &mut trip);
            let mut from_trip = DMatrix::zeros(m, n);
            for &(r, c, x) in &trip {
                from_trip[(r, c)] += x;
            }
            let mut gamma4 = vec![9.0; m];
            sys.gamma(&q, &v, t, &mut gamma4);
            let (mut pd, mut phi, mut pd2) = (vec![0.0; m], vec![0.0; m], vec![0.0; m]);
            sys.phi_dot(&q, &v, t, &mut pd);
            sys.phi_and_phi_dot(&q, &v, t, &mut phi, &mut pd2);
            let mut phit = vec![0.0; m];
            sys.phi_t(&q, t, &mut phit);
            let mut local = DMatrix::zeros(m, n);
            sys.local_rows_dense(&g, &mut local);
            for r in 0..m {
                assert_eq!(gl[r], g[r], "phi_q_local row {r}");
                assert_eq!(gamma3[r].to_bits(), gamma[r].to_bits());
                assert_eq!(gamma4[r].to_bits(), gamma[r].to_bits());
                assert_eq!(pd[r].to_bits(), pd2[r].to_bits(), "phi_dot {r}");
                let pv: f64 = (0..n).map(|c| local[(r, c)] * v[c]).sum::<f64>() + phit[r];
                assert!((pd[r] - pv).abs() < 1e-14 * (1.0 + pv.abs()), "phi_dot {r}");
            }
            assert_eq!(dense, local);
            assert_eq!(dense2, local);
            assert_eq!(from_trip, local);
        }
    }

    fn gl_dense(sys: &System, g: &[[f64; 6]]) -> DMatrix<f64> {
        let mut d = DMatrix::zeros(sys.n_constraints(), sys.n_coords());
        sys.local_rows_dense(g, &mut d);
        d
    }

    /// The constraint Hessian from the element pass (closed-form revolute rows, shared
    /// rotations) against central differences of `Phi_q`, on every joint kind and a chain of
    /// more bodies than the stack table holds.
    #[test]
    fn constraint_hessian_matches_differences_of_phi_q() {
        for sys in [
            crate::fixtures::every_joint_kind(),
            models::slider_crank().unwrap(),
            models::n_link_chain(super::STACK_BODIES + 2).unwrap(),
        ] {
            let (n, m) = (sys.n_coords(), sys.n_constraints());
            let (q, _) = crate::fixtures::generic_point(n);
            let lambda: Vec<f64> = (0..m).map(|r| 0.4 - 0.13 * r as f64).collect();
            let mut h = DMatrix::from_element(n, n, 7.0);
            sys.constraint_hessian(&q, 0.0, &lambda, &mut h);
            let eps = 1e-6;
            let (mut jp, mut jm) = (DMatrix::zeros(m, n), DMatrix::zeros(m, n));
            let lv = nalgebra::DVector::from_column_slice(&lambda);
            for c in 0..n {
                let (mut qp, mut qm) = (q.clone(), q.clone());
                qp[c] += eps;
                qm[c] -= eps;
                sys.phi_q(&qp, 0.0, &mut jp);
                sys.phi_q(&qm, 0.0, &mut jm);
                let fd = (jp.transpose() * &lv - jm.transpose() * &lv) / (2.0 * eps);
                for r in 0..n {
                    assert!(
                        (fd[r] - h[(r, c)]).abs() < 1e-8 * (1.0 + h[(r, c)].abs()),
                        "({r}, {c}): fd {} exact {}",
                        fd[r],
                        h[(r, c)]
                    );
                }
            }
        }
    }
}
