//! The spatial force elements' contributions to a model's potential, generalised forces and
//! their derivatives, element by element (local variables as in [`SpatialPart`]: `0..12` the
//! first body's coordinates, `12..24` the second's).

use super::SW;
use crate::spatial::system::SpatialPart;
use mbd_jet::{DirJetN, HessJetN, ThirdJetN};
use nalgebra::DMatrix;

impl SpatialPart {
    /// Whether the model has spatial force elements.
    pub(crate) fn has_forces(&self) -> bool {
        !self.forces.is_empty()
    }

    /// Whether every spatial force element derives from the potential.
    pub(crate) fn forces_conservative(&self) -> bool {
        !self.forces.iter().any(|f| f.is_nonconservative())
    }

    /// The force elements' potential at `q`.
    pub(crate) fn force_potential(&self, q: &[f64]) -> f64 {
        let mut v = 0.0;
        for (f, &sides) in self.lowered_forces.iter().zip(&self.force_attach) {
            let [fa, fb] = self.frames(sides, |_, c| q[c]);
            v += f.potential(&fa, &fb);
        }
        v
    }

    /// `out += sign grad V_forces(q)`.
    pub(crate) fn add_force_gradient(&self, q: &[f64], sign: f64, out: &mut [f64]) {
        for (f, &sides) in self.lowered_forces.iter().zip(&self.force_attach) {
            let [fa, fb] = self.frames(sides, |l, c| DirJetN::<SW>::var(l, q[c], 0.0));
            let e = f.potential(&fa, &fb);
            for (l, &g) in e.g.iter().enumerate() {
                if let Some(c) = self.col(sides, l) {
                    out[c] += sign * g;
                }
            }
        }
    }

    /// Along `v`: `hv += scale (d^2 V_forces / dq^2) v` and `d3 += scale D^3 V_forces(v, v, .)`
    /// (each if given),
    /// one third-order jet pass per element (torques have no potential and are skipped, as in
    /// [`SpatialPart::add_force_hessian`]).
    pub(crate) fn add_force_third(
        &self,
        q: &[f64],
        v: &[f64],
        scale: f64,
        hv: Option<&mut [f64]>,
        d3: Option<&mut [f64]>,
    ) {
        let (mut hv, mut d3) = (hv, d3);
        for (f, &sides) in self.lowered_forces.iter().zip(&self.force_attach) {
            if matches!(f.kind, super::SpatialForceKind::Torque(_)) {
                continue;
            }
            let [fa, fb] = self.frames(sides, |l, c| ThirdJetN::<SW>::var(l, q[c], v[c]));
            let e = f.potential(&fa, &fb);
            for l in 0..SW {
                if let Some(c) = self.col(sides, l) {
                    if let Some(hv) = hv.as_deref_mut() {
                        hv[c] += scale * e.g1[l];
                    }
                    if let Some(d3) = d3.as_deref_mut() {
                        d3[c] += scale * e.g2[l];
                    }
                }
            }
        }
    }

    /// `out += scale d^2 V_forces / dq^2`.
    pub(crate) fn add_force_hessian(&self, q: &[f64], scale: f64, out: &mut DMatrix<f64>) {
        for (f, &sides) in self.lowered_forces.iter().zip(&self.force_attach) {
            if matches!(f.kind, super::SpatialForceKind::Torque(_)) {
                continue;
            }
            let [fa, fb] = self.frames(sides, |l, c| HessJetN::<SW>::var(l, q[c]));
            let e = f.potential(&fa, &fb);
            for r in 0..SW {
                let Some(gr) = self.col(sides, r) else {
                    continue;
                };
                for c in 0..SW {
                    if let Some(gc) = self.col(sides, c) {
                        out[(gr, gc)] += scale * e.h[r][c];
                    }
                }
            }
        }
    }

    /// Element `k`'s local non-conservative generalised force at local coordinates `x` and
    /// velocities `u`.
    fn local_nonconservative(&self, k: usize, x: &[f64; SW], u: &[f64; SW], t: f64) -> [f64; SW] {
        let [fa, fb] = self.frames(self.force_attach[k], |l, _| {
            DirJetN::<SW>::var(l, x[l], u[l])
        });
        let mut out = [0.0; SW];
        self.lowered_forces[k].nonconservative(&fa, &fb, t, &mut out);
        out
    }

    /// Element `k`'s local coordinates and velocities gathered from `q`, `v`.
    fn gather(&self, k: usize, q: &[f64], v: &[f64]) -> ([f64; SW], [f64; SW]) {
        let sides = self.force_attach[k];
        let at = |y: &[f64], l: usize| self.col(sides, l).map_or(0.0, |c| y[c]);
        (
            std::array::from_fn(|l| at(q, l)),
            std::array::from_fn(|l| at(v, l)),
        )
    }

    /// `out += Q_nc(q, v, t)` of the non-conservative elements.
    pub(crate) fn add_nonconservative(&self, q: &[f64], v: &[f64], t: f64, out: &mut [f64]) {
        for (k, f) in self.lowered_forces.iter().enumerate() {
            if !f.is_nonconservative() {
                continue;
            }
            let (x, u) = self.gather(k, q, v);
            let loc = self.local_nonconservative(k, &x, &u, t);
            for (l, &g) in loc.iter().enumerate() {
                if let Some(c) = self.col(self.force_attach[k], l) {
                    out[c] += g;
                }
            }
        }
    }

    /// The power of the non-conservative elements: `(dissipated, external)` (dampers' loss,
    /// loads' input).
    pub(crate) fn nonconservative_power(&self, q: &[f64], v: &[f64], t: f64) -> (f64, f64) {
        let (mut dissipated, mut external) = (0.0, 0.0);
        for (k, f) in self.lowered_forces.iter().enumerate() {
            if !f.is_nonconservative() {
                continue;
            }
            let (x, u) = self.gather(k, q, v);
            let loc = self.local_nonconservative(k, &x, &u, t);
            let p: f64 = loc.iter().zip(&u).map(|(f, u)| f * u).sum();
            if f.dissipative() {
                dissipated -= p;
            } else {
                external += p;
            }
        }
        (dissipated, external)
    }

    /// The Jacobians of the non-conservative forces by central differences of each element
    /// alone: `add(i, j, dQ_i/dq_j, dQ_i/dv_j)` per entry of each element's local blocks.
    pub(crate) fn nonconservative_jacobian(
        &self,
        q: &[f64],
        v: &[f64],
        t: f64,
        add: &mut impl FnMut(usize, usize, f64, f64),
    ) {
        let mut dq = [[0.0; SW]; SW];
        let mut dv = [[0.0; SW]; SW];
        for (k, f) in self.lowered_forces.iter().enumerate() {
            if !f.is_nonconservative() {
                continue;
            }
            let sides = self.force_attach[k];
            let (mut x, mut u) = self.gather(k, q, v);
            for j in 0..SW {
                if self.col(sides, j).is_none() {
                    continue;
                }
                for velocity in [false, true] {
                    let y0 = if velocity { u[j] } else { x[j] };
                    let d = 1e-6 * (1.0 + y0.abs());
                    let mut eval = |y: f64| {
                        if velocity {
                            u[j] = y;
                        } else {
                            x[j] = y;
                        }
                        self.local_nonconservative(k, &x, &u, t)
                    };
                    let (fp, fm) = (eval(y0 + d), eval(y0 - d));
                    eval_restore(velocity, &mut x, &mut u, j, y0);
                    let jac = if velocity { &mut dv } else { &mut dq };
                    for i in 0..SW {
                        jac[i][j] = (fp[i] - fm[i]) / (2.0 * d);
                    }
                }
            }
            for i in 0..SW {
                let Some(gi) = self.col(sides, i) else {
                    continue;
                };
                for j in 0..SW {
                    if let Some(gj) = self.col(sides, j) {
                        add(gi, gj, dq[i][j], dv[i][j]);
                    }
                }
            }
        }
    }
}

/// Puts back the unperturbed local variable `j`.
fn eval_restore(velocity: bool, x: &mut [f64; SW], u: &mut [f64; SW], j: usize, y0: f64) {
    if velocity {
        u[j] = y0;
    } else {
        x[j] = y0;
    }
}
