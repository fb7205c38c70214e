//! The constraint rows over **body blocks**: every row's local gradient per body, whatever the
//! body's kind (planar, 3 coordinates; spatial, 12), with its `gamma`. What the solves over
//! bodies of any kind (`mbd_solve`'s sparse body-eliminated kernel, the sparse rank check) are
//! built from.

use crate::rows::SinCos;
use crate::system::System;

impl System {
    /// Every row of `Phi_q` in element-local form, with its `gamma` at `(q, v, t)` (`v = None`:
    /// zero velocities): `visit(row, sides, gamma)`, `sides` the row's bodies (at most two;
    /// `None`: ground) as `(block, local gradient)`. Block `b` is planar body `b` (3
    /// coordinates at `3 b`) for `b` below the planar body count, else spatial body
    /// `b - nb` (12 coordinates at [`System::spatial_offset`] `+ 12 (b - nb)`); see
    /// [`System::body_block`]; then spatial point mass `p` is block `nb + ns + p` (3
    /// coordinates, its position). What the sparse solves over bodies of any kind are built
    /// from.
    pub fn local_rows_gamma(
        &self,
        q: &[f64],
        v: Option<&[f64]>,
        t: f64,
        mut visit: impl FnMut(usize, [Option<(usize, &[f64])>; 2], f64),
    ) {
        let sc = SinCos::new(self, q, None);
        self.for_each_row(q, v, t, &sc, |ji, r, g, gm| {
            let at = self.joint_attach[ji];
            visit(
                r,
                [at.a.map(|i| (i, &g[0..3])), at.b.map(|i| (i, &g[3..6]))],
                gm,
            );
        });
        let nb = self.bodies.len();
        let width = |k: usize| self.spatial.slot_block(k).1;
        self.spatial.rows(q, v, t, |r, sides, jet| {
            visit(
                r,
                [
                    sides[0].map(|k| (nb + k, &jet.g[0..width(k)])),
                    sides[1].map(|k| (nb + k, &jet.g[12..12 + width(k)])),
                ],
                -jet.d2,
            );
        });
    }

    /// Every row of `Phi_q` and of `(Phi_q v + Phi_t)_q` at time `t` in element-local form over
    /// body blocks (see [`System::local_rows_gamma`]): `visit(row, sides)`, each side
    /// `(block, gradient, gradient of Phi_q v + Phi_t)`. What the sparse tangent chart's
    /// `Df = [[Phi_q, 0], [(Phi_q v + Phi_t)_q, Phi_q]]` is built from.
    pub fn local_rows_tan(
        &self,
        q: &[f64],
        v: &[f64],
        t: f64,
        mut visit: impl FnMut(usize, [Option<(usize, &[f64], &[f64])>; 2]),
    ) {
        let sc = SinCos::new(self, q, None);
        self.for_each_row_tan(q, v, &sc, |ji, r, g, dg| {
            let at = self.joint_attach[ji];
            visit(
                r,
                [
                    at.a.map(|i| (i, &g[0..3], &dg[0..3])),
                    at.b.map(|i| (i, &g[3..6], &dg[3..6])),
                ],
            );
        });
        let nb = self.bodies.len();
        let width = |k: usize| self.spatial.slot_block(k).1;
        self.spatial.rows_tan(q, v, t, |r, sides, g, dg| {
            visit(
                r,
                [
                    sides[0].map(|k| (nb + k, &g[0..width(k)], &dg[0..width(k)])),
                    sides[1].map(|k| (nb + k, &g[12..12 + width(k)], &dg[12..12 + width(k)])),
                ],
            );
        });
    }

    /// The number of body blocks (planar bodies, spatial bodies and spatial point masses) of
    /// [`System::local_rows_gamma`].
    pub fn n_body_blocks(&self) -> usize {
        self.bodies.len() + self.spatial.n_slots()
    }

    /// The body block of a spatial rigid body or point mass (`None` for ground): planar bodies
    /// come first, then the spatial rigid bodies, then the point masses.
    pub fn spatial_block(&self, r: crate::spatial::SpatialBodyRef) -> Option<usize> {
        r.slot(self.spatial.bodies.len())
            .map(|k| self.bodies.len() + k)
    }

    /// Body block `b`'s first coordinate and width (3 planar, 12 spatial, 3 spatial point
    /// mass), or `None` past the last block.
    pub fn body_block(&self, b: usize) -> Option<(usize, usize)> {
        let nb = self.bodies.len();
        if b < nb {
            Some((3 * b, 3))
        } else if b < self.n_body_blocks() {
            Some(self.spatial.slot_block(b - nb))
        } else {
            None
        }
    }
}
