//! Energies and forces: potential, kinetic energy, applied and conservative forces and the
//! potential's derivatives.

use crate::system::*;
use nalgebra::DMatrix;

impl System {
    /// Potential energy `V(q)`: gravity, springs and constant loads.
    pub fn potential(&self, q: &[f64]) -> f64 {
        let mut v = 0.0;
        for (i, b) in self.bodies.iter().enumerate() {
            v -= b.mass * (self.gravity[0] * q[3 * i] + self.gravity[1] * q[3 * i + 1]);
        }
        for (fi, f) in self.forces.iter().enumerate() {
            let at = self.force_attach[fi];
            v += f.potential(&Self::frm_f64(q, at.a), &Self::frm_f64(q, at.b));
        }
        v + self.spatial.potential(q) + self.spatial.force_potential(q)
    }

    /// Kinetic energy `1/2 v^T M v`.
    pub fn kinetic(&self, v: &[f64]) -> f64 {
        0.5 * v
            .iter()
            .zip(self.mass.iter())
            .map(|(v, m)| m * v * v)
            .sum::<f64>()
    }

    /// Total energy `H = T + V`.
    pub fn energy(&self, q: &[f64], v: &[f64]) -> f64 {
        self.kinetic(v) + self.potential(q)
    }

    /// `grad V(q)` into `out` (overwritten).
    pub fn potential_gradient(&self, q: &[f64], out: &mut [f64]) {
        for (i, b) in self.bodies.iter().enumerate() {
            out[3 * i] = -b.mass * self.gravity[0];
            out[3 * i + 1] = -b.mass * self.gravity[1];
            out[3 * i + 2] = 0.0;
        }
        // spatial bodies: gravity alone, minus its generalised force
        let q0 = self.spatial.q0;
        for (o, g) in out[q0..].iter_mut().zip(&self.gravity_forces[q0..]) {
            *o = -g;
        }
        if self.spatial.has_forces() {
            self.spatial.add_force_gradient(q, 1.0, out);
        }
        for (fi, f) in self.forces.iter().enumerate() {
            let at = self.force_attach[fi];
            let e = f.potential(
                &Self::loc_dir(q, None, at.a, 0),
                &Self::loc_dir(q, None, at.b, 3),
            );
            if let Some(i) = at.a {
                for l in 0..3 {
                    out[3 * i + l] += e.g[l];
                }
            }
            if let Some(i) = at.b {
                for l in 0..3 {
                    out[3 * i + l] += e.g[3 + l];
                }
            }
        }
    }

    /// The Hessian of the potential `d^2 V / dq^2` (the stiffness) into `out` (overwritten).
    pub fn potential_hessian(&self, q: &[f64], out: &mut DMatrix<f64>) {
        out.as_mut_slice().fill(0.0);
        self.add_potential_hessian(q, 1.0, out);
    }

    /// The spatial force elements' part of `scale Hess V v` (into `hv`) and of
    /// `scale D^3 V(v, v, .)` (into `d3`), each if given, added: what a pass over the planar force elements
    /// ([`System::force_elements`], which hands out planar ones only) leaves out.
    pub fn add_spatial_force_third(
        &self,
        q: &[f64],
        v: &[f64],
        scale: f64,
        hv: Option<&mut [f64]>,
        d3: Option<&mut [f64]>,
    ) {
        if self.spatial.has_forces() {
            self.spatial.add_force_third(q, v, scale, hv, d3);
        }
    }

    /// The spatial force elements' part of [`System::add_potential_hessian`]: `out += scale
    /// d^2 V_forces / dq^2` over the spatial force elements only.
    pub fn add_spatial_force_hessian(&self, q: &[f64], scale: f64, out: &mut DMatrix<f64>) {
        if self.spatial.has_forces() {
            self.spatial.add_force_hessian(q, scale, out);
        }
    }

    /// Adds `scale * d^2 V / dq^2` into `out`.
    pub fn add_potential_hessian(&self, q: &[f64], scale: f64, out: &mut DMatrix<f64>) {
        if self.spatial.has_forces() {
            self.spatial.add_force_hessian(q, scale, out);
        }
        for (fi, f) in self.forces.iter().enumerate() {
            let at = self.force_attach[fi];
            let e = f.potential(&Self::loc_hess(q, at.a, 0), &Self::loc_hess(q, at.b, 3));
            let mut h = e.h;
            for row in h.iter_mut() {
                for x in row.iter_mut() {
                    *x *= scale;
                }
            }
            Self::scatter_hess(at, &h, out);
        }
    }

    /// The power of the non-conservative force elements at `(q, v, t)`: `(dissipated,
    /// external)`, the rate at which dampers (spring-dampers' and rotary spring-dampers'
    /// damping) take energy out (`>= 0`) and the power time-dependent loads put in. With the
    /// drivers' power `lambda . Phi_t` it is the whole rate of change of the energy:
    /// `dH/dt = external - dissipated + lambda . Phi_t` (docs/architecture.md, "Energy
    /// balance").
    pub fn nonconservative_power(&self, q: &[f64], v: &[f64], t: f64) -> (f64, f64) {
        let (mut dissipated, mut external) = self.spatial.nonconservative_power(q, v, t);
        for (fi, f) in self.forces.iter().enumerate() {
            if !f.is_nonconservative() {
                continue;
            }
            let at = self.force_attach[fi];
            let (va, vb) = (Self::loc_f64(v, at.a), Self::loc_f64(v, at.b));
            let mut loc = [0.0; 6];
            f.nonconservative(
                &Self::loc_f64(q, at.a),
                &Self::loc_f64(q, at.b),
                &va,
                &vb,
                t,
                &mut loc,
            );
            let p: f64 = (0..3).map(|l| loc[l] * va[l] + loc[3 + l] * vb[l]).sum();
            if f.dissipative() {
                dissipated -= p;
            } else {
                external += p;
            }
        }
        (dissipated, external)
    }

    /// Non-conservative generalized forces (dampers, time-dependent loads) into `out`
    /// (overwritten).
    pub fn nonconservative_forces(&self, q: &[f64], v: &[f64], t: f64, out: &mut [f64]) {
        out.fill(0.0);
        if self.spatial.has_forces() {
            self.spatial.add_nonconservative(q, v, t, out);
        }
        for (fi, f) in self.forces.iter().enumerate() {
            if !f.is_nonconservative() {
                continue;
            }
            let at = self.force_attach[fi];
            let mut loc = [0.0; 6];
            f.nonconservative(
                &Self::loc_f64(q, at.a),
                &Self::loc_f64(q, at.b),
                &Self::loc_f64(v, at.a),
                &Self::loc_f64(v, at.b),
                t,
                &mut loc,
            );
            if let Some(i) = at.a {
                for l in 0..3 {
                    out[3 * i + l] += loc[l];
                }
            }
            if let Some(i) = at.b {
                for l in 0..3 {
                    out[3 * i + l] += loc[3 + l];
                }
            }
        }
    }

    /// The Jacobians of [`System::nonconservative_forces`], element by element: calls
    /// `add(i, j, dQ_i/dq_j, dQ_i/dv_j)` for each entry of each non-conservative element's
    /// 6x6 blocks (entries of several elements on one `(i, j)` are to be summed). A custom
    /// law's own Jacobian is used where it has one, else central differences of the element
    /// alone (12 evaluations of one element, against `4 n` evaluations of all of them for
    /// differences of the whole force vector).
    pub fn nonconservative_jacobian(
        &self,
        q: &[f64],
        v: &[f64],
        t: f64,
        mut add: impl FnMut(usize, usize, f64, f64),
    ) {
        if self.spatial.has_forces() {
            self.spatial.nonconservative_jacobian(q, v, t, &mut add);
        }
        let (mut dq, mut dv) = ([[0.0; 6]; 6], [[0.0; 6]; 6]);
        for (fi, f) in self.forces.iter().enumerate() {
            if !f.is_nonconservative() {
                continue;
            }
            let at = self.force_attach[fi];
            let x = [
                Self::loc_f64(q, at.a),
                Self::loc_f64(q, at.b),
                Self::loc_f64(v, at.a),
                Self::loc_f64(v, at.b),
            ];
            f.nonconservative_jacobian(x, t, &mut dq, &mut dv);
            let global = |k: usize| {
                let side = if k < 3 { at.a } else { at.b };
                side.map(|b| 3 * b + k % 3)
            };
            for i in 0..6 {
                let Some(gi) = global(i) else { continue };
                for j in 0..6 {
                    if let Some(gj) = global(j) {
                        add(gi, gj, dq[i][j], dv[i][j]);
                    }
                }
            }
        }
    }

    /// All generalized applied forces `Q(q, v, t) = -grad V + Q_nc` into `out` (overwritten).
    #[inline]
    pub fn forces_into(&self, q: &[f64], v: &[f64], t: f64, out: &mut [f64]) {
        // gravity (constant), then minus the elements' potential gradients: what negating
        // `potential_gradient` gives, bit for bit
        out.copy_from_slice(&self.gravity_forces);
        if self.spatial.has_forces() {
            self.spatial.add_force_gradient(q, -1.0, out);
            self.spatial.add_nonconservative(q, v, t, out);
        }
        for (fi, f) in self.forces.iter().enumerate() {
            let at = self.force_attach[fi];
            let e = f.potential(
                &Self::loc_dir(q, None, at.a, 0),
                &Self::loc_dir(q, None, at.b, 3),
            );
            if let Some(i) = at.a {
                for l in 0..3 {
                    out[3 * i + l] -= e.g[l];
                }
            }
            if let Some(i) = at.b {
                for l in 0..3 {
                    out[3 * i + l] -= e.g[3 + l];
                }
            }
        }
        for (fi, f) in self.forces.iter().enumerate() {
            if !f.is_nonconservative() {
                continue;
            }
            let at = self.force_attach[fi];
            let mut loc = [0.0; 6];
            f.nonconservative(
                &Self::loc_f64(q, at.a),
                &Self::loc_f64(q, at.b),
                &Self::loc_f64(v, at.a),
                &Self::loc_f64(v, at.b),
                t,
                &mut loc,
            );
            if let Some(i) = at.a {
                for l in 0..3 {
                    out[3 * i + l] += loc[l];
                }
            }
            if let Some(i) = at.b {
                for l in 0..3 {
                    out[3 * i + l] += loc[3 + l];
                }
            }
        }
    }

    // ---------------------------------------------------------------- points
}
