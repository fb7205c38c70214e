//! The spatial force elements' share of a pass of `e4` (docs/spatial.md, "The s = 2 modified
//! Lagrangian", force elements): the series of each element's potential along the pass's
//! directions with the gradients of its coefficients, from the model's generic potential
//! ([`mbd_model::spatial::SpatialForceElement::potential`]) evaluated on multivariate Taylor
//! jets ([`PolyJet`]).
//!
//! A spatial element has 24 local variables and a jet carries the gradient with respect to
//! [`NV`] of them, so the element is evaluated once per block of [`NV`] local variables that has
//! a column: in block `b` the variables of the block are the jet's independent variables and the
//! others enter with their value and their components along the directions but no gradient. The
//! coefficients are the same in every block; each block fills its part of the gradients. The
//! gradient of the coefficient of `x^e` with respect to direction `j` is the `q`-gradient of the
//! coefficient of `x^e / x_j` (the planar passes' division table, [`Basis::DIV`]).

use mbd_model::jet::NV;
use mbd_model::spatial::SPATIAL_LOCAL_WIDTH;
use mbd_model::{Basis, PolyJet, System, MAX_DIRS};

/// The local width of a spatial element.
const W: usize = SPATIAL_LOCAL_WIDTH;
/// The blocks of [`NV`] local variables.
const BLOCKS: usize = W.div_ceil(NV);

/// One element's data in a pass: its columns and the gradients of its coefficients in local
/// variables.
#[derive(Clone, Debug)]
struct Element<const K: usize> {
    cols: [Option<usize>; W],
    g: [[f64; W]; K],
}

/// The spatial force elements with a potential, in one pass ([`super::passes::Pass`]): filled
/// by [`SpatialPotential::eval`] at every evaluation from the system it is given (the list
/// allocates only when it grows).
#[derive(Debug)]
pub(super) struct SpatialPotential<const K: usize> {
    elements: Vec<Element<K>>,
}

impl<const K: usize> Default for SpatialPotential<K> {
    fn default() -> Self {
        SpatialPotential {
            elements: Vec::new(),
        }
    }
}

impl<const K: usize> SpatialPotential<K> {
    /// Adds the coefficients of the elements' potentials along `dirs` at `q` to `pot` and keeps
    /// their gradients.
    pub(super) fn eval<B: Basis<K>>(
        &mut self,
        sys: &System,
        q: &[f64],
        dirs: &[&[f64]],
        pot: &mut [f64; K],
    ) {
        self.elements.clear();
        let nd = dirs.len().min(B::ND);
        for e in sys.spatial_force_elements() {
            if !e.has_potential() {
                continue;
            }
            let mut el = Element {
                cols: e.columns(),
                g: [[0.0; W]; K],
            };
            let mut first = true;
            for b in 0..BLOCKS {
                let block = b * NV..((b + 1) * NV).min(W);
                if el.cols[block.clone()].iter().all(Option::is_none) {
                    continue;
                }
                let jet = e.potential(|l, c| {
                    let mut w = [0.0; MAX_DIRS];
                    for (wj, d) in w.iter_mut().zip(&dirs[..nd]) {
                        *wj = d[c];
                    }
                    let mut x = PolyJet::<K, B>::var(l % NV, q[c], &w[..nd]);
                    if !block.contains(&l) {
                        x.g[0][l % NV] = 0.0;
                    }
                    x
                });
                if first {
                    for (p, c) in pot.iter_mut().zip(&jet.c) {
                        *p += c;
                    }
                    first = false;
                }
                for (gk, jg) in el.g.iter_mut().zip(&jet.g) {
                    gk[block.clone()].copy_from_slice(&jg[..block.len()]);
                }
            }
            self.elements.push(el);
        }
    }

    /// The elements' share of the potential's adjoint with the weights `w` of its
    /// coefficients: `qb += sum_k w_k grad_q c_k`, `dirs[j] += sum_k w_k grad_q c_(k / x_j)`.
    pub(super) fn adjoint<B: Basis<K>>(
        &self,
        w: &[f64; K],
        qb: &mut [f64],
        dirs: &mut [&mut [f64]],
    ) {
        let nd = dirs.len().min(B::ND);
        for el in &self.elements {
            let mut gq = [0.0; W];
            let mut gd = [[0.0; W]; MAX_DIRS];
            for (k, &wk) in w.iter().enumerate() {
                if wk == 0.0 {
                    continue;
                }
                for (a, g) in gq.iter_mut().zip(&el.g[k]) {
                    *a += wk * g;
                }
                for (j, gdj) in gd.iter_mut().enumerate().take(nd) {
                    let d = B::DIV[k][j];
                    if d != u8::MAX {
                        for (a, g) in gdj.iter_mut().zip(&el.g[d as usize]) {
                            *a += wk * g;
                        }
                    }
                }
            }
            for (l, c) in el.cols.iter().enumerate() {
                let Some(c) = *c else {
                    continue;
                };
                qb[c] += gq[l];
                for (out, gdj) in dirs.iter_mut().zip(&gd) {
                    out[c] += gdj[l];
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::passes::{BasisA, A_E, A_ET, A_T, A_T4, A_TT, NA};
    use super::*;
    use mbd_model::fixtures::{generic_point, spatial_springs};

    /// `V` without gravity: the spatial force elements' potential at `q`.
    fn elements_potential(sys: &System, q: &[f64]) -> f64 {
        sys.spatial_force_elements()
            .map(|e| e.potential(|_, c| q[c]))
            .sum()
    }

    /// The series along `(v, u)` against differences of the elements' potential: the
    /// coefficients of `t`, `e`, `t^2`, `e t` and `t^4`, and the `q`-gradients of the
    /// coefficients of `t` and `e t` (through the adjoint), on the fixture with every kind of
    /// spatial potential.
    #[test]
    fn series_and_gradients_match_differences() {
        let sys = spatial_springs();
        let n = sys.n_coords();
        let (q, v) = generic_point(n);
        let u: Vec<f64> = (0..n).map(|i| (1.3 * i as f64 + 0.2).cos()).collect();
        let mut sp = SpatialPotential::<NA>::default();
        let mut pot = [0.0; NA];
        sp.eval::<BasisA>(&sys, &q, &[&v, &u], &mut pot);
        // f(s, r) = V(q + s v + r u)
        let f = |s: f64, r: f64| {
            let x: Vec<f64> = (0..n).map(|i| q[i] + s * v[i] + r * u[i]).collect();
            elements_potential(&sys, &x)
        };
        let h = 1e-3;
        let d1 = |g: &dyn Fn(f64) -> f64| {
            (8.0 * (g(h) - g(-h)) - (g(2.0 * h) - g(-2.0 * h))) / (12.0 * h)
        };
        let ft = d1(&|s| f(s, 0.0));
        let fe = d1(&|r| f(0.0, r));
        let ftt = (-f(2.0 * h, 0.0) + 16.0 * f(h, 0.0) - 30.0 * f(0.0, 0.0) + 16.0 * f(-h, 0.0)
            - f(-2.0 * h, 0.0))
            / (12.0 * h * h);
        let fet = d1(&|r| d1(&|s| f(s, r)));
        let hh = 2e-2;
        let ft4 = (f(2.0 * hh, 0.0) - 4.0 * f(hh, 0.0) + 6.0 * f(0.0, 0.0) - 4.0 * f(-hh, 0.0)
            + f(-2.0 * hh, 0.0))
            / hh.powi(4);
        for (got, want, tol, what) in [
            (pot[A_T], ft, 1e-8, "t"),
            (pot[A_E], fe, 1e-8, "e"),
            (2.0 * pot[A_TT], ftt, 1e-5, "t^2"),
            (pot[A_ET], fet, 1e-5, "e t"),
            (24.0 * pot[A_T4], ft4, 1e-2, "t^4"),
        ] {
            assert!(
                (got - want).abs() <= tol * (1.0 + want.abs()),
                "{what}: {got} vs {want}"
            );
        }
        // q-gradients of the coefficients of t and e t: (d/dq) of the differences above
        for (k, what) in [(A_T, "t"), (A_ET, "e t")] {
            let mut w = [0.0; NA];
            w[k] = 1.0;
            let mut g = vec![0.0; n];
            sp.adjoint::<BasisA>(&w, &mut g, &mut []);
            for i in 0..n {
                let at = |y: f64| {
                    let mut qq = q.clone();
                    qq[i] += y;
                    let mut s = SpatialPotential::<NA>::default();
                    let mut p = [0.0; NA];
                    s.eval::<BasisA>(&sys, &qq, &[&v, &u], &mut p);
                    p[k]
                };
                let want = d1(&at);
                assert!(
                    (g[i] - want).abs() <= 1e-7 * (1.0 + want.abs()),
                    "d c_{what} / dq_{i}: {} vs {want}",
                    g[i]
                );
            }
        }
    }
}
