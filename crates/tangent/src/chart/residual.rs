//! The constraint residual `f(x, t)` at chart points: the model's `(q, v)` for callers, the
//! chart's weighted `(q, tau v)` inside the chord iterations (`docs/tangent.md`, "The chart's
//! metric").

use super::{fast_max, TangentChart};
use crate::kernels::{max_abs_finite, with_codim, with_rows};
use mbd_model::System;

impl TangentChart {
    /// `f(x, t) = (Phi(q, t), Phi_q v + Phi_t)` into `out` (length `2m`); returns its max-norm
    /// (NaN if any entry is not finite).
    pub fn residual(&mut self, sys: &System, x: &[f64], t: f64, out: &mut [f64]) -> f64 {
        let (q, v) = x.split_at(self.n);
        self.sel
            .residual(sys, q, v, t, &mut out[..2 * self.m], None);
        with_codim!(2 * self.m, max_abs_finite(out))
    }

    /// [`TangentChart::residual`] with the bodies' `sin`/`cos` rotated from the previous
    /// evaluation ([`mbd_model::BodyAngles::update_near`]: a few ulps from the exact values;
    /// the chord's iterates move by small angles).
    ///
    /// `x` is a chart point `(q, tau v)`; the velocity rows come back weighted like the chart's
    /// coordinates, `tau (Phi_q v + Phi_t)` (the rows of `Df` the chart factored), and the norm
    /// returned is that of the unweighted residual, the quantity the tolerances bound.
    pub(super) fn residual_cached(
        &mut self,
        sys: &System,
        x: &[f64],
        t: f64,
        out: &mut [f64],
    ) -> f64 {
        let (n, m) = (self.n, self.m);
        let (q, v) = x.split_at(n);
        if self.vs == 1.0 {
            self.sel
                .residual(sys, q, v, t, &mut out[..2 * m], Some(&mut self.angles));
            return with_codim!(2 * m, max_abs_finite(out));
        }
        if self.scleronomic {
            // Phi_q v is linear in v: at (q, tau v) it is the weighted row tau Phi_q v itself
            self.sel
                .residual(sys, q, v, t, &mut out[..2 * m], Some(&mut self.angles));
            let (p, pd) = out.split_at(m);
            let a = with_rows!(m, max_abs_finite(p));
            let b = with_rows!(m, max_abs_finite(pd)) * self.vinv;
            return if a.is_nan() || b.is_nan() {
                f64::NAN
            } else {
                fast_max(a, b)
            };
        }
        self.residual_at_weighted(sys, q, v, t, out, true)
    }

    /// [`TangentChart::residual`] at a chart point `(q, tau v)`, weighted as
    /// [`TangentChart::residual_cached`] (without the rotated `sin`/`cos`).
    pub(super) fn residual_weighted(
        &mut self,
        sys: &System,
        x: &[f64],
        t: f64,
        out: &mut [f64],
    ) -> f64 {
        let (q, v) = x.split_at(self.n);
        self.residual_at_weighted(sys, q, v, t, out, false)
    }

    /// The residual at `(q, tau v)` with the velocity rows weighted (`cached`: the `sin`/`cos`
    /// rotated from the last evaluation); returns the norm of the unweighted residual.
    #[inline(always)]
    fn residual_at_weighted(
        &mut self,
        sys: &System,
        q: &[f64],
        v: &[f64],
        t: f64,
        out: &mut [f64],
        cached: bool,
    ) -> f64 {
        let m = self.m;
        self.fill_velocities(v);
        let angles = cached.then_some(&mut self.angles);
        self.sel
            .residual(sys, q, &self.vbuf, t, &mut out[..2 * m], angles);
        let r = with_codim!(2 * m, max_abs_finite(out));
        self.weight_rows(out);
        r
    }

    /// The model's velocities `v` of the chart's `tau v` into the work vector `vbuf`.
    pub(super) fn fill_velocities(&mut self, v: &[f64]) {
        for (b, &vi) in self.vbuf.iter_mut().zip(v) {
            *b = vi * self.vinv;
        }
    }

    /// The velocity rows of a residual `out` (`2m`) weighted by `tau`, as the chart factored
    /// them.
    fn weight_rows(&self, out: &mut [f64]) {
        for o in out[self.m..2 * self.m].iter_mut() {
            *o *= self.vs;
        }
    }

    /// `(q, tau v)` of the chart to the model's `(q, v)`, in place.
    pub(super) fn unweight(&self, x: &mut [f64]) {
        if self.vs != 1.0 {
            for xv in x[self.n..].iter_mut() {
                *xv *= self.vinv;
            }
        }
    }
}
