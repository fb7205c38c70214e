//! Mixed directional derivatives of the constraints and of the potential along several
//! directions at once, with their gradients, from one [`PolyJet`] pass per element: what the
//! higher-order modified-Lagrangian terms need (`D^2 Phi(a, b)`, `D^3 Phi(a, a, b)`, ... and
//! their gradients with respect to `q` and to every direction), without the polarisations of
//! single-direction passes.

use super::scatter_grad;
use mbd_model::jet::{set_var_frame, Basis, Frame, PolyJet, Scalar, MAX_DIRS, NV};
use mbd_model::{Attach, BodyAngles, JointElement, RevoluteSide, System};

/// The workspace of the [`PolyJet`] passes of one basis: the frames of an element's bodies,
/// built in place and reused from element to element and from pass to pass (every
/// entry that can be non-zero is written: body a in slots `0..3`, body b in `3..6`, ground constant), and
/// the element's equations. Make it once (it is large: boxed) and hand it to every pass.
#[derive(Debug)]
pub(crate) struct PolyWorkspace<const K: usize, B> {
    a: Frame<PolyJet<K, B>>,
    b: Frame<PolyJet<K, B>>,
    ground: Frame<PolyJet<K, B>>,
    e: [PolyJet<K, B>; 3],
}

impl<const K: usize, B: Basis<K>> PolyWorkspace<K, B> {
    /// A fresh workspace.
    pub fn new() -> Box<Self> {
        Box::new(PolyWorkspace {
            a: Frame::fixed(),
            b: Frame::fixed(),
            ground: Frame::fixed(),
            e: [PolyJet::cst(0.0); 3],
        })
    }

    fn set(
        f: &mut Frame<PolyJet<K, B>>,
        slot: usize,
        q: &[f64],
        ang: &BodyAngles,
        dirs: &[&[f64]],
        i: usize,
    ) {
        let qi = [q[3 * i], q[3 * i + 1], q[3 * i + 2]];
        let mut w = [[0.0; 3]; MAX_DIRS];
        for (wd, d) in w.iter_mut().zip(dirs) {
            *wd = [d[3 * i], d[3 * i + 1], d[3 * i + 2]];
        }
        let [_, s, c] = ang.sin_cos_of(i);
        set_var_frame(f, slot, qi, &w[..B::ND], s, c);
    }

    /// Sets the frames of the bodies `at` and returns them with the equations' buffer.
    #[allow(clippy::type_complexity)]
    fn get(
        &mut self,
        q: &[f64],
        ang: &BodyAngles,
        dirs: &[&[f64]],
        at: Attach,
    ) -> (
        &Frame<PolyJet<K, B>>,
        &Frame<PolyJet<K, B>>,
        &mut [PolyJet<K, B>; 3],
    ) {
        if let Some(i) = at.a {
            Self::set(&mut self.a, 0, q, ang, dirs, i);
        }
        if let Some(i) = at.b {
            Self::set(&mut self.b, 3, q, ang, dirs, i);
        }
        let fa = if at.a.is_some() {
            &self.a
        } else {
            &self.ground
        };
        let fb = if at.b.is_some() {
            &self.b
        } else {
            &self.ground
        };
        (fa, fb, &mut self.e)
    }
}

/// The two rows `point_a(pa) - point_b(pb)` of a revolute joint in closed form (what the
/// generic evaluation gives, up to rounding): the point `r + R(theta) p` of a body along the
/// directions has the coefficients `r + sum_j w_j^r x_j` (position part) plus `R(theta + d
/// pi/2) p prod_j (w_j^theta)^(e_j) / e_j!` for a monomial of degree `d` (each derivative of
/// the rotation turns the vector by a quarter turn), whose gradient in `theta` is the next
/// quarter turn's. A ground point is constant.
#[allow(clippy::too_many_arguments)]
fn revolute_rows<const K: usize, B: Basis<K>>(
    q: &[f64],
    angles: &BodyAngles,
    dirs: &[&[f64]],
    sides: [RevoluteSide; 2],
    vals: &mut [[f64; K]],
    grads: &mut [[[f64; NV]; K]],
) {
    for r in 0..2 {
        vals[r] = [0.0; K];
        grads[r] = [[0.0; NV]; K];
    }
    for RevoluteSide {
        body,
        slot,
        p,
        sign,
    } in sides
    {
        let Some(i) = body else {
            vals[0][0] += sign * p[0];
            vals[1][0] += sign * p[1];
            continue;
        };
        // R(theta) p and its quarter turns
        let r0 = BodyAngles::rotate(Some(angles), q, i, p);
        let turns = [r0, [-r0[1], r0[0]], [-r0[0], -r0[1]], [r0[1], -r0[0]]];
        let mut wth = [0.0; MAX_DIRS];
        for (wj, d) in wth.iter_mut().zip(dirs) {
            *wj = d[3 * i + 2];
        }
        let pw = PolyJet::<K, B>::powers(&wth);
        for k in 0..K {
            let d = B::DEG[k] as usize;
            let (rk, gk) = (turns[d % 4], turns[(d + 1) % 4]);
            for c in 0..2 {
                vals[c][k] += sign * rk[c] * pw[k];
                grads[c][k][slot + 2] += sign * gk[c] * pw[k];
            }
        }
        for c in 0..2 {
            vals[c][0] += sign * q[3 * i + c];
            grads[c][0][slot + c] += sign;
            for (j, d) in dirs.iter().enumerate() {
                vals[c][B::LIN[j] as usize] += sign * d[3 * i + c];
            }
        }
    }
}

/// Per constraint row `r`, the coefficients `vals[r]` of the [`PolyJet`] of `Phi_r(q +
/// sum_j x_j dirs[j])` in the basis `B` (`dirs.len() == B::ND`, each of length n) and their
/// element-local gradients `grads[r]` with respect to `q` (the six columns of the joint's
/// two bodies, as in [`System::phi_q_local`]). The time part of rheonomic constraints is
/// left out (it does not depend on `q`). One pass per joint; no allocation.
pub(crate) fn constraint_poly_series<const K: usize, B: Basis<K>>(
    sys: &System,
    ws: &mut PolyWorkspace<K, B>,
    q: &[f64],
    angles: &BodyAngles,
    dirs: &[&[f64]],
    vals: &mut [[f64; K]],
    grads: &mut [[[f64; NV]; K]],
) {
    debug_assert!(angles.matches(q) && dirs.len() == B::ND);
    debug_assert!(vals.len() == sys.n_constraints() && grads.len() == vals.len());
    constraint_poly_series_impl(sys, ws, q, angles, dirs, vals, grads, true);
}

/// [`constraint_poly_series`]; `closed_form`: revolute joints by
/// [`revolute_rows`] (otherwise every joint by its generic equations, the oracle of the
/// tests).
#[allow(clippy::too_many_arguments)]
pub(crate) fn constraint_poly_series_impl<const K: usize, B: Basis<K>>(
    sys: &System,
    ws: &mut PolyWorkspace<K, B>,
    q: &[f64],
    angles: &BodyAngles,
    dirs: &[&[f64]],
    vals: &mut [[f64; K]],
    grads: &mut [[[f64; NV]; K]],
    closed_form: bool,
) {
    for JointElement {
        joint: j,
        attach: at,
        row: o,
    } in sys.joint_elements()
    {
        if let Some(sides) = j.revolute_sides(at).filter(|_| closed_form) {
            let (v, g) = (&mut vals[o..o + 2], &mut grads[o..o + 2]);
            revolute_rows::<K, B>(q, angles, dirs, sides, v, g);
            continue;
        }
        let (fa, fb, e) = ws.get(q, angles, dirs, at);
        j.eval(fa, fb, e);
        for (k, ek) in e.iter().enumerate().take(j.n_equations()) {
            vals[o + k] = ek.c;
            grads[o + k] = ek.g;
        }
    }
}

/// The coefficients of the [`PolyJet`] of the potential `V(q + sum_j x_j dirs[j])` in the
/// basis `B` (force elements only: gravity is linear, and only its value and first
/// coefficients would change, which no caller reads; non-conservative elements have no
/// potential), and per force element (in the order of [`System::forces`]) their
/// element-local gradients. One pass per force element; no allocation.
pub(crate) fn potential_poly_series<const K: usize, B: Basis<K>>(
    sys: &System,
    ws: &mut PolyWorkspace<K, B>,
    q: &[f64],
    angles: &BodyAngles,
    dirs: &[&[f64]],
    grads: &mut [[[f64; NV]; K]],
) -> [f64; K] {
    debug_assert!(angles.matches(q) && dirs.len() == B::ND);
    debug_assert_eq!(grads.len(), sys.forces().len());
    let mut sum = [0.0; K];
    if sys.forces().is_empty() {
        return sum;
    }
    for (fi, (f, at)) in sys.force_elements().enumerate() {
        let (fa, fb, _) = ws.get(q, angles, dirs, at);
        let e = f.potential(fa, fb);
        for k in 0..K {
            sum[k] += e.c[k];
        }
        grads[fi] = e.g;
    }
    sum
}

/// `outs[p] += sum_r sum_k w[r][p][k] grads[r][k]` (length n each) for the element-local
/// coefficient gradients of [`constraint_poly_series`] and `P` weight sets, in one
/// sweep over the rows: gradients with respect to `q` of weighted coefficients.
pub(crate) fn add_constraint_poly_grads_many<const K: usize, const P: usize>(
    sys: &System,
    grads: &[[[f64; NV]; K]],
    w: &[[[f64; K]; P]],
    outs: [&mut [f64]; P],
) {
    debug_assert!(w.len() == sys.n_constraints() && grads.len() == w.len());
    let mut outs = outs;
    for JointElement {
        joint: j,
        attach: at,
        row: o,
    } in sys.joint_elements()
    {
        let ne = j.n_equations();
        let mut g = [[0.0; NV]; P];
        for (gr, wr) in grads[o..o + ne].iter().zip(&w[o..o + ne]) {
            for (gp, wp) in g.iter_mut().zip(wr) {
                for k in 0..K {
                    if wp[k] != 0.0 {
                        for l in 0..NV {
                            gp[l] += wp[k] * gr[k][l];
                        }
                    }
                }
            }
        }
        for (gp, out) in g.iter().zip(outs.iter_mut()) {
            scatter_grad(at, gp, 1.0, out);
        }
    }
}

/// The adjoint of a [`constraint_poly_series`] pass with the adjoint weights `w`
/// of its rows' coefficients, in one sweep over the rows: `qb += sum_r sum_k w[r][k]
/// grads[r][k]` (the gradient with respect to `q`) and, for every direction `j <
/// dirs.len()`, `dirs[j] += sum_r sum_k w[r][k] grads[r][DIV[k][j]]` (the gradient with
/// respect to direction `j`, [`Basis::DIV`]). Rows whose weights are all zero are skipped.
pub(crate) fn add_constraint_poly_adjoint<const K: usize, B: Basis<K>>(
    sys: &System,
    grads: &[[[f64; NV]; K]],
    w: &[[f64; K]],
    qb: &mut [f64],
    dirs: &mut [&mut [f64]],
) {
    debug_assert!(w.len() == sys.n_constraints() && grads.len() == w.len());
    debug_assert!(dirs.len() <= B::ND);
    for JointElement {
        joint: j,
        attach: at,
        row: o,
    } in sys.joint_elements()
    {
        let ne = j.n_equations();
        let mut gq = [0.0; NV];
        let mut gd = [[0.0; NV]; MAX_DIRS];
        let mut any = false;
        for (gr, wr) in grads[o..o + ne].iter().zip(&w[o..o + ne]) {
            poly_local_adjoint::<K, B>(gr, wr, dirs.len(), &mut gq, &mut gd, &mut any);
        }
        if any {
            scatter_grad(at, &gq, 1.0, qb);
            for (d, out) in dirs.iter_mut().enumerate() {
                scatter_grad(at, &gd[d], 1.0, out);
            }
        }
    }
}

/// [`add_constraint_poly_adjoint`] for a [`potential_poly_series`] pass
/// (one weight vector for every force element).
pub(crate) fn add_potential_poly_adjoint<const K: usize, B: Basis<K>>(
    sys: &System,
    grads: &[[[f64; NV]; K]],
    w: &[f64; K],
    qb: &mut [f64],
    dirs: &mut [&mut [f64]],
) {
    debug_assert_eq!(grads.len(), sys.forces().len());
    debug_assert!(dirs.len() <= B::ND);
    for (gr, (_, at)) in grads.iter().zip(sys.force_elements()) {
        let mut gq = [0.0; NV];
        let mut gd = [[0.0; NV]; MAX_DIRS];
        let mut any = false;
        poly_local_adjoint::<K, B>(gr, w, dirs.len(), &mut gq, &mut gd, &mut any);
        if any {
            scatter_grad(at, &gq, 1.0, qb);
            for (d, out) in dirs.iter_mut().enumerate() {
                scatter_grad(at, &gd[d], 1.0, out);
            }
        }
    }
}

/// One element row's share of the adjoints: `gq += sum_k w[k] g[k]`, `gd[j] += sum_k w[k]
/// g[DIV[k][j]]` for `j < nd`.
#[inline(always)]
fn poly_local_adjoint<const K: usize, B: Basis<K>>(
    g: &[[f64; NV]; K],
    w: &[f64; K],
    nd: usize,
    gq: &mut [f64; NV],
    gd: &mut [[f64; NV]; MAX_DIRS],
    any: &mut bool,
) {
    for k in 0..K {
        let wk = w[k];
        if wk == 0.0 {
            continue;
        }
        *any = true;
        for l in 0..NV {
            gq[l] += wk * g[k][l];
        }
        for (j, gdj) in gd.iter_mut().enumerate().take(nd) {
            let d = B::DIV[k][j];
            if d != u8::MAX {
                for l in 0..NV {
                    gdj[l] += wk * g[d as usize][l];
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::directional::{constraint_directional, potential_directional};
    use super::*;
    use mbd_model::fixtures::{derivative_test_systems, generic_point, TwoDirections};
    use mbd_model::JointKind;

    /// The closed-form revolute rows equal the generic evaluation's (to rounding), on systems
    /// with revolute joints between bodies and to ground.
    #[test]
    fn revolute_closed_form_matches_the_generic_rows() {
        let mut systems = derivative_test_systems().to_vec();
        systems.push(mbd_model::models::n_link_chain(4).expect("chain"));
        let mut revolute = 0;
        for sys in &systems {
            revolute += sys
                .joints()
                .iter()
                .filter(|j| matches!(j.kind, JointKind::Revolute(_)))
                .count();
            let (n, m) = (sys.n_coords(), sys.n_constraints());
            let (q, v) = generic_point(n);
            let u: Vec<f64> = (0..n).map(|i| 0.3 - 0.11 * i as f64).collect();
            let mut ang = BodyAngles::default();
            ang.update(sys, &q);
            let mut out = Vec::new();
            for closed in [true, false] {
                let (mut vals, mut grads) = (vec![[0.0; 8]; m], vec![[[0.0; NV]; 8]; m]);
                let mut ws = PolyWorkspace::<8, TwoDirections>::new();
                constraint_poly_series_impl(
                    sys,
                    &mut ws,
                    &q,
                    &ang,
                    &[&v, &u],
                    &mut vals,
                    &mut grads,
                    closed,
                );
                out.push((vals, grads));
            }
            let ((va, ga), (vb, gb)) = (&out[0], &out[1]);
            for r in 0..m {
                for k in 0..8 {
                    let close = |a: f64, b: f64| (a - b).abs() <= 1e-15 * (1.0 + b.abs());
                    assert!(close(va[r][k], vb[r][k]), "row {r} coef {k}");
                    for l in 0..NV {
                        assert!(close(ga[r][k][l], gb[r][k][l]), "row {r} coef {k} grad {l}");
                    }
                }
            }
        }
        assert!(
            revolute >= 6,
            "the systems have revolute joints ({revolute})"
        );
    }

    /// On systems with every joint kind and with springs: the coefficients against the
    /// single-direction passes (and their polarisation), and the weighted gradients (with
    /// respect to `q` and to both directions) against central differences of the coefficients.
    #[test]
    fn poly_passes_match_directional_passes_and_differences() {
        for sys in derivative_test_systems() {
            let (n, m, nf) = (sys.n_coords(), sys.n_constraints(), sys.forces().len());
            let (q, v) = generic_point(n);
            let u: Vec<f64> = (0..n).map(|i| 0.3 - 0.11 * i as f64).collect();
            let mut ang = BodyAngles::default();
            let series = |q: &[f64], v: &[f64], u: &[f64]| {
                let mut ang = BodyAngles::default();
                ang.update(&sys, q);
                let (mut vals, mut grads) = (vec![[0.0; 8]; m], vec![[[0.0; NV]; 8]; m]);
                let mut ws = PolyWorkspace::<8, TwoDirections>::new();
                constraint_poly_series(&sys, &mut ws, q, &ang, &[v, u], &mut vals, &mut grads);
                let mut pg = vec![[[0.0; NV]; 8]; nf];
                let pot = potential_poly_series(&sys, &mut ws, q, &ang, &[v, u], &mut pg);
                (vals, grads, pot, pg)
            };
            let (vals, grads, pot, pg) = series(&q, &v, &u);
            ang.update(&sys, &q);
            let dir = |w: &[f64]| {
                let mut rows = vec![[0.0; 3]; m];
                constraint_directional(&sys, &q, w, &mut rows);
                (rows, potential_directional(&sys, &q, w))
            };
            let (dv, pv) = dir(&v);
            let upv: Vec<f64> = u.iter().zip(&v).map(|(a, b)| a + b).collect();
            let umv: Vec<f64> = u.iter().zip(&v).map(|(a, b)| a - b).collect();
            let (dp, pp) = dir(&upv);
            let (dm, pm) = dir(&umv);
            let close = |a: f64, b: f64, what: &str| {
                assert!(
                    (a - b).abs() <= 1e-12 * (1.0 + b.abs()),
                    "{what}: {a} vs {b}"
                );
            };
            for r in 0..m {
                close(2.0 * vals[r][3], dv[r][0], "D^2 Phi(v, v)");
                close(6.0 * vals[r][5], dv[r][1], "D^3 Phi(v^3)");
                close(24.0 * vals[r][7], dv[r][2], "D^4 Phi(v^4)");
                close(vals[r][4], 0.25 * (dp[r][0] - dm[r][0]), "D^2 Phi(u, v)");
            }
            close(24.0 * pot[7], pv[2], "D^4 V(v^4)");
            close(pot[4], 0.25 * (pp[0] - pm[0]), "D^2 V(u, v)");
            // weighted gradients against differences
            let w: Vec<[f64; 8]> = (0..m)
                .map(|r| std::array::from_fn(|k| 0.1 * (r + 1) as f64 - 0.07 * k as f64))
                .collect();
            let wp: [f64; 8] = std::array::from_fn(|k| 0.2 - 0.05 * k as f64);
            let total = |vals: &[[f64; 8]], pot: &[f64; 8]| -> f64 {
                let c: f64 = vals
                    .iter()
                    .zip(&w)
                    .map(|(a, b)| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>())
                    .sum();
                c + pot.iter().zip(&wp).map(|(x, y)| x * y).sum::<f64>()
            };
            let mut gq = vec![0.0; n];
            let (mut gdv, mut gdu) = (vec![0.0; n], vec![0.0; n]);
            let mut gd = [gdv.as_mut_slice(), gdu.as_mut_slice()];
            add_constraint_poly_adjoint::<8, TwoDirections>(&sys, &grads, &w, &mut gq, &mut gd);
            add_potential_poly_adjoint::<8, TwoDirections>(&sys, &pg, &wp, &mut gq, &mut gd);
            let gd = [gdv, gdu];
            let h = 1e-4;
            for i in 0..n {
                let mut fd = [0.0; 3];
                for (s, c) in [(1.0, 8.0), (-1.0, -8.0), (2.0, -1.0), (-2.0, 1.0)] {
                    for (which, f) in fd.iter_mut().enumerate() {
                        let (mut qq, mut vv, mut uu) = (q.clone(), v.clone(), u.clone());
                        [&mut qq, &mut vv, &mut uu][which][i] += s * h;
                        let (a, _, b, _) = series(&qq, &vv, &uu);
                        *f += c * total(&a, &b) / (12.0 * h);
                    }
                }
                for (got, want, what) in [
                    (gq[i], fd[0], "q"),
                    (gd[0][i], fd[1], "v"),
                    (gd[1][i], fd[2], "u"),
                ] {
                    assert!(
                        (got - want).abs() <= 1e-7 * (1.0 + want.abs()),
                        "grad {what}[{i}]: {got} vs {want}"
                    );
                }
            }
        }
    }
}
