//! Gradients of weighted directional derivatives of orders 2 to 4 of the constraints and of the
//! potential, with respect to the configuration `q` and to the direction `w`, from one
//! [`TaylorGrad4`] pass per element: `grad_q D^k f(q)(w^k) = D^(k+1) f(q)(w^k, .)` and
//! `grad_w D^k f(q)(w^k) = k D^k f(q)(w^(k-1), .)` (what the gradients of the higher-order
//! modified-Lagrangian terms built from [`System::constraint_directional`] and
//! [`System::potential_directional`] need).

use crate::directional::BodyAngles;
use crate::jet::{Frame, Scalar, TaylorGrad4, NV};
use crate::system::{Attach, System};

/// The element-local gradients of the five Taylor coefficients of one element equation along
/// one direction (`TaylorGrad4::g`): entry `[k][i]` is `D^(k+1) f(q)(w, ..., w, e_i) / k!`.
type SeriesGrads = [[f64; NV]; 5];

/// The [`TaylorGrad4`] frames of one element's bodies, built in place and reused from element
/// to element (see [`TaylorGrad4::set_var_frame`]): body a in slots `0..3`, body b in `3..6`,
/// ground constant.
struct VarFrames {
    a: Frame<TaylorGrad4>,
    b: Frame<TaylorGrad4>,
}

/// The ground frame (constant).
const GROUND: Frame<TaylorGrad4> = Frame {
    q: [TaylorGrad4::ZERO; 3],
    c: TaylorGrad4::ONE,
    s: TaylorGrad4::ZERO,
};

impl VarFrames {
    #[inline(always)]
    fn new() -> Self {
        VarFrames {
            a: Frame::fixed(),
            b: Frame::fixed(),
        }
    }

    /// Frame `f` (variables `slot..slot + 3`) of body `i`.
    #[inline(always)]
    fn set(
        f: &mut Frame<TaylorGrad4>,
        slot: usize,
        q: &[f64],
        ang: Option<&BodyAngles>,
        w: &[f64],
        i: usize,
    ) {
        let (qi, wi) = (&q[3 * i..3 * i + 3], &w[3 * i..3 * i + 3]);
        let qi = [qi[0], qi[1], qi[2]];
        // (sin, cos) of the angle from the table or evaluated, as `BodyAngles::frame` does
        let sc = BodyAngles::frame(ang, i, qi);
        TaylorGrad4::set_var_frame(f, slot, qi, [wi[0], wi[1], wi[2]], sc.s, sc.c);
    }

    /// The frames of the bodies `at` at `q` along `w` (the angles' sines and cosines from `ang`
    /// or, without it, evaluated here as `Frame::new` does): bit for bit the frames of
    /// `TaylorGrad4::var` coordinates.
    #[inline(always)]
    fn get(
        &mut self,
        q: &[f64],
        ang: Option<&BodyAngles>,
        w: &[f64],
        at: Attach,
    ) -> (&Frame<TaylorGrad4>, &Frame<TaylorGrad4>) {
        if let Some(i) = at.a {
            Self::set(&mut self.a, 0, q, ang, w, i);
        }
        if let Some(i) = at.b {
            Self::set(&mut self.b, 3, q, ang, w, i);
        }
        (
            if at.a.is_some() { &self.a } else { &GROUND },
            if at.b.is_some() { &self.b } else { &GROUND },
        )
    }
}

impl System {
    /// `gq += c[k-2] grad_q D^k f(w^k)`, `gw += c[k-2] grad_w D^k f(w^k)`, `k = 2..=4`, for one
    /// element-local series with the coefficient gradients `g` (local gradients).
    #[inline(always)]
    fn add_weighted_grads(g: &SeriesGrads, c: [f64; 3], gq: &mut [f64; NV], gw: &mut [f64; NV]) {
        for (i, &ck) in c.iter().enumerate() {
            if ck == 0.0 {
                continue;
            }
            let dq = TaylorGrad4::derivative_grad_q(g, i + 2);
            let dw = TaylorGrad4::derivative_grad_w(g, i + 2);
            for l in 0..NV {
                gq[l] += ck * dq[l];
                gw[l] += ck * dw[l];
            }
        }
    }

    /// [`System::constraint_directional_at`] (the rows `out[r] = [D^2, D^3, D^4] Phi_r(w, ...)`,
    /// bit for bit) that also keeps, per constraint row `r`, the element-local gradients of the
    /// series coefficients with respect to the base point, `grads[r][k][i] = D^(k+1) Phi_r(q)(w,
    /// ..., w, e_i) / k!` (`k = 0..=4`, the six columns of the joint's two bodies as in
    /// [`System::phi_q_local`]). From them [`System::add_constraint_directional_grads`] gives
    /// the gradients of any weighted sum of the rows without another pass over the elements.
    /// One `TaylorGrad4` pass per joint; no allocation.
    pub fn constraint_directional_series(
        &self,
        q: &[f64],
        angles: &BodyAngles,
        w: &[f64],
        out: &mut [[f64; 3]],
        grads: &mut [[[f64; NV]; 5]],
    ) {
        debug_assert!(angles.matches(q));
        debug_assert!(out.len() == self.n_constraints() && grads.len() == out.len());
        let mut fr = VarFrames::new();
        // (eval sets the first n_equations entries, the only ones read)
        let mut e = [TaylorGrad4::cst(0.0); 3];
        for (ji, j) in self.joints.iter().enumerate() {
            let at = self.joint_attach[ji];
            let (fa, fb) = fr.get(q, Some(angles), w, at);
            j.eval(fa, fb, &mut e);
            let o = self.row_offset[ji];
            for (k, ek) in e.iter().enumerate().take(j.n_equations()) {
                out[o + k] = [ek.derivative(2), ek.derivative(3), ek.derivative(4)];
                grads[o + k] = ek.g;
            }
        }
    }

    /// Adds to `gq` and `gw` (length n each) the gradients with respect to `q` and to `w` of
    /// `sum_r sum_(k=2..4) c[r][k-2] D^k Phi_r(q)(w, ..., w)` from the coefficient gradients
    /// `grads` of [`System::constraint_directional_series`] at `(q, w)`: bit for bit what
    /// [`System::constraint_directional_grad`] adds, without evaluating the elements.
    pub fn add_constraint_directional_grads(
        &self,
        grads: &[[[f64; NV]; 5]],
        c: &[[f64; 3]],
        gq: &mut [f64],
        gw: &mut [f64],
    ) {
        let n = self.n_coords();
        debug_assert!(gq.len() == n && gw.len() == n);
        debug_assert!(c.len() == self.n_constraints() && grads.len() == c.len());
        for (ji, j) in self.joints.iter().enumerate() {
            let at = self.joint_attach[ji];
            let o = self.row_offset[ji];
            let ne = j.n_equations();
            let rows = &c[o..o + ne];
            if rows.iter().all(|r| r.iter().all(|&x| x == 0.0)) {
                continue;
            }
            let (mut lq, mut lw) = ([0.0; NV], [0.0; NV]);
            for (g, ck) in grads[o..o + ne].iter().zip(rows) {
                Self::add_weighted_grads(g, *ck, &mut lq, &mut lw);
            }
            Self::scatter_grad(at, &lq, 1.0, gq);
            Self::scatter_grad(at, &lw, 1.0, gw);
        }
    }

    /// [`System::potential_directional_at`] (`[D^2, D^3, D^4] V(w, ...)`, bit for bit) that also
    /// keeps, per force element `f` (in the order of [`System::forces`]; `grads` has one entry
    /// per element), the element-local gradients of its potential's series coefficients (as in
    /// [`System::constraint_directional_series`]), for
    /// [`System::add_potential_directional_grads`]. One `TaylorGrad4` pass per force element;
    /// no allocation.
    pub fn potential_directional_series(
        &self,
        q: &[f64],
        angles: &BodyAngles,
        w: &[f64],
        grads: &mut [[[f64; NV]; 5]],
    ) -> [f64; 3] {
        debug_assert!(angles.matches(q));
        debug_assert_eq!(grads.len(), self.forces.len());
        let mut d = [0.0; 3];
        if self.forces.is_empty() {
            return d;
        }
        let mut fr = VarFrames::new();
        for (fi, f) in self.forces.iter().enumerate() {
            let at = self.force_attach[fi];
            let (fa, fb) = fr.get(q, Some(angles), w, at);
            let e = f.potential(fa, fb);
            for (k, dk) in d.iter_mut().enumerate() {
                *dk += e.derivative(k + 2);
            }
            grads[fi] = e.g;
        }
        d
    }

    /// Adds to `gq` and `gw` (length n each) the gradients with respect to `q` and to `w` of
    /// `sum_(k=2..4) c[k-2] D^k V(q)(w, ..., w)` from the coefficient gradients `grads` of
    /// [`System::potential_directional_series`] at `(q, w)`: bit for bit what
    /// [`System::potential_directional_grad`] adds, without evaluating the elements.
    pub fn add_potential_directional_grads(
        &self,
        grads: &[[[f64; NV]; 5]],
        c: [f64; 3],
        gq: &mut [f64],
        gw: &mut [f64],
    ) {
        let n = self.n_coords();
        debug_assert!(gq.len() == n && gw.len() == n);
        debug_assert_eq!(grads.len(), self.forces.len());
        if c.iter().all(|&x| x == 0.0) {
            return;
        }
        for (fi, g) in grads.iter().enumerate() {
            let at = self.force_attach[fi];
            let (mut lq, mut lw) = ([0.0; NV], [0.0; NV]);
            Self::add_weighted_grads(g, c, &mut lq, &mut lw);
            Self::scatter_grad(at, &lq, 1.0, gq);
            Self::scatter_grad(at, &lw, 1.0, gw);
        }
    }

    /// Adds to `gq` and `gw` (length n each) the gradients with respect to `q` and to `w` of
    /// `sum_r sum_(k=2..4) c[r][k-2] D^k Phi_r(q)(w, ..., w)` (`c` has one entry per constraint
    /// row, in the row order of [`System::constraint_directional`]). One [`TaylorGrad4`] pass
    /// per joint whose weights are not all zero; no allocation. Time enters the joint equations
    /// only additively, so this does not depend on `t`.
    pub fn constraint_directional_grad(
        &self,
        q: &[f64],
        w: &[f64],
        c: &[[f64; 3]],
        gq: &mut [f64],
        gw: &mut [f64],
    ) {
        let n = self.n_coords();
        debug_assert!(q.len() == n && w.len() == n && gq.len() == n && gw.len() == n);
        debug_assert_eq!(c.len(), self.n_constraints());
        let mut fr = VarFrames::new();
        let mut e = [TaylorGrad4::cst(0.0); 3];
        for (ji, j) in self.joints.iter().enumerate() {
            let at = self.joint_attach[ji];
            let o = self.row_offset[ji];
            let ne = j.n_equations();
            let rows = &c[o..o + ne];
            if rows.iter().all(|r| r.iter().all(|&x| x == 0.0)) {
                continue;
            }
            let (fa, fb) = fr.get(q, None, w, at);
            j.eval(fa, fb, &mut e);
            let (mut lq, mut lw) = ([0.0; NV], [0.0; NV]);
            for (ek, ck) in e[..ne].iter().zip(rows) {
                Self::add_weighted_grads(&ek.g, *ck, &mut lq, &mut lw);
            }
            Self::scatter_grad(at, &lq, 1.0, gq);
            Self::scatter_grad(at, &lw, 1.0, gw);
        }
    }

    /// Adds to `gq` and `gw` (length n each) the gradients with respect to `q` and to `w` of
    /// `sum_(k=2..4) c[k-2] D^k V(q)(w, ..., w)` for the potential `V` of the force elements
    /// (as in [`System::potential_directional`]: gravity is linear and contributes nothing;
    /// non-conservative elements have no potential). One [`TaylorGrad4`] pass per force
    /// element; no allocation.
    pub fn potential_directional_grad(
        &self,
        q: &[f64],
        w: &[f64],
        c: [f64; 3],
        gq: &mut [f64],
        gw: &mut [f64],
    ) {
        let n = self.n_coords();
        debug_assert!(q.len() == n && w.len() == n && gq.len() == n && gw.len() == n);
        if c.iter().all(|&x| x == 0.0) {
            return;
        }
        let mut fr = VarFrames::new();
        for (fi, f) in self.forces.iter().enumerate() {
            let at = self.force_attach[fi];
            let (fa, fb) = fr.get(q, None, w, at);
            let e = f.potential(fa, fb);
            let (mut lq, mut lw) = ([0.0; NV], [0.0; NV]);
            Self::add_weighted_grads(&e.g, c, &mut lq, &mut lw);
            Self::scatter_grad(at, &lq, 1.0, gq);
            Self::scatter_grad(at, &lw, 1.0, gw);
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::System;

    /// "Random-ish" weights for `m` rows.
    fn weights(m: usize) -> Vec<[f64; 3]> {
        (0..m)
            .map(|r| {
                let x = r as f64;
                [
                    0.8 * (1.3 * x + 0.2).sin(),
                    0.6 * (0.7 * x + 1.1).cos(),
                    0.5 * (2.3 * x - 0.4).sin(),
                ]
            })
            .collect()
    }

    /// Fourth-order central differences of `s` in every entry of `x` (step `h (1 + |x_i|)`).
    fn fd_grad(s: &dyn Fn(&[f64]) -> f64, x: &[f64], h: f64) -> Vec<f64> {
        let mut xp = x.to_vec();
        (0..x.len())
            .map(|i| {
                let hi = h * (1.0 + x[i].abs());
                let mut at = |t: f64| {
                    xp[i] = x[i] + t * hi;
                    let v = s(&xp);
                    xp[i] = x[i];
                    v
                };
                (-at(2.0) + 8.0 * at(1.0) - 8.0 * at(-1.0) + at(-2.0)) / (12.0 * hi)
            })
            .collect()
    }

    /// Largest error relative to the largest entry of `fd` (which must not vanish).
    fn rel_err(exact: &[f64], fd: &[f64], what: &str) -> f64 {
        let scale = fd.iter().fold(0.0_f64, |a, x| a.max(x.abs()));
        assert!(scale > 1e-3, "{what}: the test needs a non-zero gradient");
        exact
            .iter()
            .zip(fd)
            .fold(0.0_f64, |a, (e, f)| a.max((e - f).abs()))
            / scale
    }

    const H: f64 = 1e-4;
    const TOL: f64 = 1e-7;

    /// Both gradients of `sum_r c_r . constraint_directional(q, w)_r` against fourth-order
    /// differences in `q` and in `w`, on every fixture with constraints.
    #[test]
    fn constraint_directional_grad_matches_differences() {
        let mut worst: f64 = 0.0;
        for sys in crate::fixtures::derivative_test_systems() {
            let (n, m) = (sys.n_coords(), sys.n_constraints());
            if m == 0 {
                continue;
            }
            let (q, w) = crate::fixtures::generic_point(n);
            let c = weights(m);
            let (mut gq, mut gw) = (vec![0.0; n], vec![0.0; n]);
            sys.constraint_directional_grad(&q, &w, &c, &mut gq, &mut gw);
            let s = |q: &[f64], w: &[f64]| -> f64 {
                let mut rows = vec![[0.0; 3]; m];
                sys.constraint_directional(q, w, &mut rows);
                rows.iter()
                    .zip(&c)
                    .map(|(r, c)| r[0] * c[0] + r[1] * c[1] + r[2] * c[2])
                    .sum()
            };
            let eq = rel_err(&gq, &fd_grad(&|x| s(x, &w), &q, H), "constraint grad_q");
            let ew = rel_err(&gw, &fd_grad(&|x| s(&q, x), &w, H), "constraint grad_w");
            assert!(eq < TOL && ew < TOL, "constraint grads: q {eq:e}, w {ew:e}");
            worst = worst.max(eq).max(ew);
        }
        eprintln!("constraint_directional_grad: worst relative error {worst:e}");
    }

    /// Both gradients of `c . potential_directional(q, w)` against fourth-order differences,
    /// on the spring fixture (non-zero derivatives of every order).
    #[test]
    fn potential_directional_grad_matches_differences() {
        let sys = crate::fixtures::two_springs();
        let n = sys.n_coords();
        let (q, w) = crate::fixtures::generic_point(n);
        let c = [0.7, -0.45, 0.3];
        let (mut gq, mut gw) = (vec![0.0; n], vec![0.0; n]);
        sys.potential_directional_grad(&q, &w, c, &mut gq, &mut gw);
        let s = |q: &[f64], w: &[f64]| -> f64 {
            let d = sys.potential_directional(q, w);
            d[0] * c[0] + d[1] * c[1] + d[2] * c[2]
        };
        let eq = rel_err(&gq, &fd_grad(&|x| s(x, &w), &q, H), "potential grad_q");
        let ew = rel_err(&gw, &fd_grad(&|x| s(&q, x), &w, H), "potential grad_w");
        eprintln!("potential_directional_grad: relative error q {eq:e}, w {ew:e}");
        assert!(eq < TOL && ew < TOL, "potential grads: q {eq:e}, w {ew:e}");
        // each order alone, too (so one order cannot hide another's error)
        for k in 0..3 {
            let mut ck = [0.0; 3];
            ck[k] = 1.0;
            let (mut gq, mut gw) = (vec![0.0; n], vec![0.0; n]);
            sys.potential_directional_grad(&q, &w, ck, &mut gq, &mut gw);
            let s = |q: &[f64], w: &[f64]| sys.potential_directional(q, w)[k];
            let eq = rel_err(&gq, &fd_grad(&|x| s(x, &w), &q, H), "potential grad_q");
            let ew = rel_err(&gw, &fd_grad(&|x| s(&q, x), &w, H), "potential grad_w");
            assert!(eq < TOL && ew < TOL, "order {}: q {eq:e}, w {ew:e}", k + 2);
        }
    }

    /// `gw`, `gq` of the `k = 2` term of one row and of the potential against the exact jets:
    /// `grad_w D^2 f(w, w) = 2 Hess f w` ([`System::lagrangian_hessian_vector`]) and
    /// `grad_q D^2 f(w, w) = D^3 f(w, w, .)` ([`System::constraint_third`],
    /// [`System::potential_third`]); and the methods add into their outputs.
    #[test]
    fn second_order_term_matches_exact_hessian_products() {
        let close = |a: &[f64], b: &[f64], what: &str| {
            let scale = b.iter().fold(1.0_f64, |s, x| s.max(x.abs()));
            for (i, (x, y)) in a.iter().zip(b).enumerate() {
                assert!((x - y).abs() < 1e-12 * scale, "{what} [{i}]: {x} vs {y}");
            }
        };
        let check = |sys: &System| {
            let (n, m) = (sys.n_coords(), sys.n_constraints());
            let (q, w) = crate::fixtures::generic_point(n);
            let (mut hv, mut d3) = (vec![0.0; n], vec![0.0; n]);
            for r in 0..m {
                let mut c = vec![[0.0; 3]; m];
                c[r] = [1.0, 0.0, 0.0];
                let (mut gq, mut gw) = (vec![0.0; n], vec![0.0; n]);
                sys.constraint_directional_grad(&q, &w, &c, &mut gq, &mut gw);
                let mut sel = vec![0.0; m];
                sel[r] = 1.0;
                sys.lagrangian_hessian_vector(&q, &w, 0.0, &sel, &mut hv);
                sys.constraint_third(&q, &w, &sel, &mut d3);
                let hv2: Vec<f64> = hv.iter().map(|x| 2.0 * x).collect();
                close(&gw, &hv2, &format!("row {r}: grad_w vs 2 H w"));
                close(&gq, &d3, &format!("row {r}: grad_q vs D3"));
                // accumulation: a second call doubles (exactly)
                let (g1q, g1w) = (gq.clone(), gw.clone());
                sys.constraint_directional_grad(&q, &w, &c, &mut gq, &mut gw);
                assert!(gq.iter().zip(&g1q).all(|(a, b)| *a == 2.0 * b));
                assert!(gw.iter().zip(&g1w).all(|(a, b)| *a == 2.0 * b));
            }
            let (mut gq, mut gw) = (vec![0.0; n], vec![0.0; n]);
            sys.potential_directional_grad(&q, &w, [1.0, 0.0, 0.0], &mut gq, &mut gw);
            sys.lagrangian_hessian_vector(&q, &w, 1.0, &vec![0.0; m], &mut hv);
            sys.potential_third(&q, &w, &mut d3);
            let hv2: Vec<f64> = hv.iter().map(|x| 2.0 * x).collect();
            close(&gw, &hv2, "potential grad_w vs 2 H w");
            close(&gq, &d3, "potential grad_q vs D3");
        };
        for sys in crate::fixtures::derivative_test_systems() {
            check(&sys);
        }
    }

    /// The stored-series passes: their rows equal [`System::constraint_directional`] and
    /// [`System::potential_directional`] bit for bit, and contracting their coefficient
    /// gradients gives bit for bit what [`System::constraint_directional_grad`] and
    /// [`System::potential_directional_grad`] add (also with some zero weights).
    #[test]
    fn stored_series_match_the_direct_passes_bitwise() {
        let same = |a: &[f64], b: &[f64], what: &str| {
            assert_eq!(a.len(), b.len());
            for (i, (x, y)) in a.iter().zip(b).enumerate() {
                assert_eq!(x.to_bits(), y.to_bits(), "{what} [{i}]: {x} vs {y}");
            }
        };
        for sys in crate::fixtures::derivative_test_systems() {
            let (n, m, nf) = (sys.n_coords(), sys.n_constraints(), sys.forces().len());
            let (q, w) = crate::fixtures::generic_point(n);
            let ang = crate::BodyAngles::new(&sys, &q);
            let (mut rows, mut series) = (vec![[0.0; 3]; m], vec![[0.0; 3]; m]);
            let mut grads = vec![[[0.0; 6]; 5]; m];
            sys.constraint_directional(&q, &w, &mut rows);
            sys.constraint_directional_series(&q, &ang, &w, &mut series, &mut grads);
            same(rows.as_flattened(), series.as_flattened(), "rows");
            let mut pgrads = vec![[[0.0; 6]; 5]; nf];
            let pot = sys.potential_directional_series(&q, &ang, &w, &mut pgrads);
            same(&pot, &sys.potential_directional(&q, &w), "potential");
            let mut c = weights(m);
            if m > 1 {
                c[1] = [0.0, 0.0, 0.0];
                c[0][1] = 0.0;
            }
            let (mut gq1, mut gw1) = (vec![0.1; n], vec![-0.2; n]);
            let (mut gq2, mut gw2) = (gq1.clone(), gw1.clone());
            sys.constraint_directional_grad(&q, &w, &c, &mut gq1, &mut gw1);
            sys.add_constraint_directional_grads(&grads, &c, &mut gq2, &mut gw2);
            same(&gq1, &gq2, "constraint grad_q");
            same(&gw1, &gw2, "constraint grad_w");
            for cp in [[0.7, -0.45, 0.3], [0.0, 1.0, 0.0]] {
                sys.potential_directional_grad(&q, &w, cp, &mut gq1, &mut gw1);
                sys.add_potential_directional_grads(&pgrads, cp, &mut gq2, &mut gw2);
                same(&gq1, &gq2, "potential grad_q");
                same(&gw1, &gw2, "potential grad_w");
            }
        }
    }
}
