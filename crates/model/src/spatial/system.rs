//! The spatial bodies and joints of a [`crate::System`]: their place in `q` and `Phi`, and
//! their rows of the constraint functions, written over the jets of 24 variables.
//!
//! Coordinates: after the planar bodies' `3 nb`, spatial body `k` holds
//! `q[q0 + 12 k .. q0 + 12 k + 12] = (x, d_1, d_2, d_3)`, then point mass `p` holds
//! `q[q0 + 12 ns + 3 p ..][..3] = x`. Rows: after the planar joints' rows, body `k`'s six
//! internal constraints, then each spatial joint's equations. Every row is an element of one
//! or two sides (local variables `0..12` the first side's coordinates, `12..24` the second's;
//! ground has none, a point mass only its first three, its directors being the constant global
//! axes), evaluated with `f64`, `DirJetN<24>` (gradient, `Phi_q v`, `v^T H v`; `H v` as the
//! difference of two gradients, every equation being quadratic) or `HessJetN<24>` (the
//! Hessian). A side is a slot: rigid body `k` is slot `k`, point mass `p` slot `ns + p`.

use super::body::{SpatialBody, SpatialBodyRef};
use super::forces::SpatialForce;
use super::joints::{MarkerAt, SpatialFrame, SpatialJoint};
use super::point_mass::{as_side, SpatialPointMass};
use hessians::ConstantHessians;
use mbd_jet::{DirJetN, Scalar};
use nalgebra::DMatrix;

mod hessians;

/// The local width of a spatial element: two bodies' natural coordinates.
pub(crate) const SW: usize = 24;

/// A side's 12 local coordinates at the origin with the global axes as directors (what a point
/// mass's constant directors take).
pub(crate) const IDENTITY: [f64; 12] = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0];

/// A spatial joint of a model: its name, the bodies its markers sit on, and the joint (markers
/// in each body's frame, as given).
#[derive(Clone, Debug, PartialEq)]
pub struct SpatialJointEntry {
    /// Unique joint name.
    pub name: String,
    /// The body of the first marker.
    pub a: SpatialBodyRef,
    /// The body of the second marker.
    pub b: SpatialBodyRef,
    /// The joint, its markers in the bodies' frames.
    pub joint: SpatialJoint,
    /// A driver's motion: the slide `s(t)` (m) of a [`super::SpatialJointKind::SlideDriver`],
    /// the distance `L(t)` (m) of a [`super::SpatialJointKind::DistanceDriver`], the angle
    /// `theta(t)` (rad) of a [`super::SpatialJointKind::AngleDriver`]; `None` for every other
    /// kind.
    pub motion: Option<crate::timefn::TimeFunction>,
}

/// One element of the spatial rows: a body's internal constraints or a joint.
#[derive(Clone, Copy, Debug)]
enum Item {
    Internal,
    Joint(usize),
}

/// The spatial part of a model (empty for a planar model).
#[derive(Clone, Debug, Default)]
pub(crate) struct SpatialPart {
    pub(crate) bodies: Vec<SpatialBody>,
    /// The point masses (coordinates after the bodies').
    pub(crate) points: Vec<SpatialPointMass>,
    pub(crate) joints: Vec<SpatialJointEntry>,
    /// The joints with their markers in the principal frames (what the equations use).
    pub(crate) lowered: Vec<SpatialJoint>,
    /// Each joint's sides (slots; `None`: ground).
    pub(crate) attach: Vec<[Option<usize>; 2]>,
    /// Each joint's first row.
    pub(crate) joint_row: Vec<usize>,
    /// The first spatial coordinate and row.
    pub(crate) q0: usize,
    pub(crate) r0: usize,
    /// The number of spatial rows.
    pub(crate) m: usize,
    /// Gravity (m/s^2).
    pub(crate) gravity: [f64; 3],
    /// The force elements as given, and with their points and axes in the principal frames.
    pub(crate) forces: Vec<SpatialForce>,
    pub(crate) lowered_forces: Vec<SpatialForce>,
    /// Each force element's sides (slots; `None`: ground).
    pub(crate) force_attach: Vec<[Option<usize>; 2]>,
    /// The initial natural coordinates and velocities, body after body, then the point
    /// masses' positions and velocities.
    pub(crate) q_init: Vec<f64>,
    pub(crate) v_init: Vec<f64>,
    /// The rows' constant Hessians, evaluated at first use ([`ConstantHessians`]).
    hessians: std::sync::OnceLock<ConstantHessians>,
}

impl SpatialPart {
    /// The part for `bodies` and `points` (valid: natural states `q_init`, `v_init`) and
    /// `joints` (their markers lowered to the principal frames in `lowered`, attachments
    /// resolved), after `q0` planar coordinates and `r0` planar rows.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn new(
        bodies: Vec<SpatialBody>,
        points: Vec<SpatialPointMass>,
        joints: Vec<SpatialJointEntry>,
        lowered: Vec<SpatialJoint>,
        gravity: [f64; 3],
        q0: usize,
        r0: usize,
        q_init: Vec<f64>,
        v_init: Vec<f64>,
    ) -> Self {
        let ns = bodies.len();
        let attach = joints
            .iter()
            .map(|j| [j.a.slot(ns), j.b.slot(ns)])
            .collect();
        let mut joint_row = Vec::with_capacity(joints.len());
        let mut m = 6 * bodies.len();
        for j in &lowered {
            joint_row.push(r0 + m);
            m += j.n_equations();
        }
        SpatialPart {
            bodies,
            points,
            joints,
            lowered,
            attach,
            joint_row,
            q0,
            r0,
            m,
            gravity,
            forces: Vec::new(),
            lowered_forces: Vec::new(),
            force_attach: Vec::new(),
            q_init,
            v_init,
            hessians: std::sync::OnceLock::new(),
        }
    }

    /// Whether the model has no spatial body and no spatial point mass.
    pub(crate) fn is_empty(&self) -> bool {
        self.bodies.is_empty() && self.points.is_empty()
    }

    /// Every element: its sides, first row and row count.
    fn items(&self) -> impl Iterator<Item = (Item, [Option<usize>; 2], usize, usize)> + '_ {
        let internal =
            (0..self.bodies.len()).map(|k| (Item::Internal, [Some(k), None], self.r0 + 6 * k, 6));
        let joints = (0..self.lowered.len()).map(|j| {
            (
                Item::Joint(j),
                self.attach[j],
                self.joint_row[j],
                self.lowered[j].n_equations(),
            )
        });
        internal.chain(joints)
    }

    /// The global column of local variable `l` (side `l / 12`) of an element with `sides`
    /// (`None` on ground and on a point mass's directors, which are constants).
    pub(crate) fn col(&self, sides: [Option<usize>; 2], l: usize) -> Option<usize> {
        let (o, w) = self.slot_block(sides[l / 12]?);
        (l % 12 < w).then_some(o + l % 12)
    }

    /// An element's equations at the frames of its sides at time `t`, a driver's without the
    /// motion it subtracts; an angle driver's equation in `out[0]` and its derivative in
    /// `theta` in `out[1]` ([`angle_combine`]).
    fn eval<T: Scalar>(
        &self,
        item: Item,
        fa: &SpatialFrame<T>,
        fb: &SpatialFrame<T>,
        t: f64,
    ) -> [T; 6] {
        let mut out = [T::cst(0.0); 6];
        match item {
            Item::Internal => out = super::internal_eval(fa),
            Item::Joint(j) => {
                self.lowered[j].eval(fa, fb, &mut out);
                self.combine_angle(j, t, &mut out);
            }
        }
        out
    }

    /// An angle driver's equation at `t` in `e[0]` (and its derivative in `theta` in `e[1]`)
    /// from the components [`SpatialJoint::eval`] writes; nothing for every other joint.
    pub(crate) fn combine_angle<T: Scalar>(&self, j: usize, t: f64, e: &mut [T; 6]) {
        if let Some([theta, ..]) = self.angle(j, t) {
            (e[0], e[1]) = angle_combine(theta, e[0], e[1]);
        }
    }

    /// An angle driver's `theta`, `theta'`, `theta''` at `t` (`None` for every other joint).
    pub(crate) fn angle(&self, j: usize, t: f64) -> Option<[f64; 3]> {
        if self.lowered[j].kind() != super::joints::SpatialJointKind::AngleDriver {
            return None;
        }
        self.joints[j].motion.as_ref().map(|m| m.eval(t))
    }

    /// An element's equations at time `t` with jets: local variable `l` made by
    /// `var(l, column)` (see [`SpatialPart::eval`]).
    fn eval_jets<T: Scalar>(
        &self,
        item: Item,
        sides: [Option<usize>; 2],
        t: f64,
        var: impl Fn(usize, usize) -> T,
    ) -> [T; 6] {
        let [fa, fb] = self.frames(sides, var);
        self.eval(item, &fa, &fb, t)
    }

    /// The frames of an element's two sides, local variable `l` made by `var(l, column)`
    /// (ground: the constant global frame).
    pub(crate) fn frames<T: Scalar>(
        &self,
        sides: [Option<usize>; 2],
        var: impl Fn(usize, usize) -> T,
    ) -> [SpatialFrame<T>; 2] {
        std::array::from_fn(|s| match sides[s] {
            // a point mass's directors are the constant global axes
            Some(_) => SpatialFrame::new(&std::array::from_fn(|k| {
                let l = 12 * s + k;
                match self.col(sides, l) {
                    Some(c) => var(l, c),
                    None => T::cst(IDENTITY[k]),
                }
            })),
            None => SpatialFrame::ground(),
        })
    }

    /// The spatial rows of `Phi(q, t)` into `out` (the whole vector).
    pub(crate) fn phi(&self, q: &[f64], t: f64, out: &mut [f64]) {
        for (item, sides, row, n) in self.items() {
            let e = self.eval_jets(item, sides, t, |_, c| q[c]);
            out[row..row + n].copy_from_slice(&e[..n]);
            if let Item::Joint(j) = item {
                out[row] -= self.drive(j, t)[0];
            }
        }
    }

    /// The time part `c(t)`, `c'`, `c''` a driver joint's equation subtracts (zeros for
    /// every other joint, the angle driver included: its time enters through its Jacobian):
    /// `s(t)` for a slide driver, `1/2 L(t)^2` for a distance driver.
    pub(crate) fn drive(&self, j: usize, t: f64) -> [f64; 3] {
        let Some(motion) = &self.joints[j].motion else {
            return [0.0; 3];
        };
        let [f, df, ddf] = motion.eval(t);
        match self.lowered[j].kind() {
            super::joints::SpatialJointKind::DistanceDriver => {
                [0.5 * f * f, f * df, df * df + f * ddf]
            }
            super::joints::SpatialJointKind::AngleDriver => [0.0; 3],
            _ => [f, df, ddf],
        }
    }

    /// `Phi_t(q, t)` of the spatial rows into `out` (the whole vector): `-c'(t)` on slide and
    /// distance driver rows, `theta' dE/dtheta` on angle driver rows.
    pub(crate) fn phi_t(&self, q: &[f64], t: f64, out: &mut [f64]) {
        out[self.r0..self.r0 + self.m].fill(0.0);
        for (j, &row) in self.joint_row.iter().enumerate() {
            out[row] = match self.angle(j, t) {
                Some([_, dtheta, _]) => {
                    let e = self.eval_jets(Item::Joint(j), self.attach[j], t, |_, c| q[c]);
                    dtheta * e[1]
                }
                None => -self.drive(j, t)[1],
            };
        }
    }

    /// Whether an angle driver makes `Phi_q` depend on time.
    pub(crate) fn has_angle_driver(&self) -> bool {
        (0..self.lowered.len())
            .any(|j| self.lowered[j].kind() == super::joints::SpatialJointKind::AngleDriver)
    }

    /// Marks in `out` (indexed by global row) the spatial rows whose Hessian is constant: every
    /// spatial equation is quadratic in `q`, and only an angle driver's Hessian moves with
    /// `theta(t)`.
    pub(crate) fn mark_constant_hessian_rows(&self, out: &mut [bool]) {
        for (item, _, row, n) in self.items() {
            let constant = match item {
                Item::Internal => true,
                Item::Joint(j) => {
                    self.lowered[j].kind() != super::joints::SpatialJointKind::AngleDriver
                }
            };
            for x in &mut out[row..row + n] {
                *x = constant;
            }
        }
    }

    /// Whether a spatial joint is a driver.
    pub(crate) fn is_rheonomic(&self) -> bool {
        self.joints.iter().any(|j| j.motion.is_some())
    }

    /// For every spatial row at time `t`: `visit(row, sides, jet)`, the jet holding the value
    /// `Phi`, the gradient `Phi_q`, `Phi_q v + Phi_t` (`d1`) and
    /// `v^T H v + 2 Phi_qt v + Phi_tt` (`d2`, so that `gamma = -d2`) (`v = None`: zero
    /// velocities). `Phi_qt` is zero but on angle driver rows.
    #[inline(always)]
    pub(crate) fn rows(
        &self,
        q: &[f64],
        v: Option<&[f64]>,
        t: f64,
        visit: impl FnMut(usize, [Option<usize>; 2], &DirJetN<SW>),
    ) {
        // a planar model: the residual passes call this at every evaluation, so the test is
        // inlined at the call site and the loop below stays out of line
        if self.m != 0 {
            self.rows_spatial(q, v, t, visit);
        }
    }

    /// [`SpatialPart::rows`] on a model with spatial rows.
    #[inline(never)]
    fn rows_spatial(
        &self,
        q: &[f64],
        v: Option<&[f64]>,
        t: f64,
        mut visit: impl FnMut(usize, [Option<usize>; 2], &DirJetN<SW>),
    ) {
        // scratch for every element: the rows' jets and the markers'
        let mut e = [DirJetN::<SW>::cst(0.0); 6];
        let mut markers = [MarkerAt::ZERO_JETS; 2];
        for (item, sides, row, n) in self.items() {
            if let (Item::Internal, Some(k)) = (item, sides[0]) {
                // in closed form: the generic jets spend most of a solve's time here
                self.internal_jets_into(q, v, k, &mut e);
                for (r, jet) in e.iter().enumerate() {
                    visit(row + r, sides, jet);
                }
                continue;
            }
            let Item::Joint(j) = item else {
                continue;
            };
            let [la, lb] = sides.map(|k| k.map(|k| self.local_state(k, q, v)));
            self.lowered[j].eval_jets_with(as_side(&la), as_side(&lb), &mut markers, &mut e);
            if let Some([theta, dth, ddth]) = self.angle(j, t) {
                // Phi = E(q, theta(t)): d/dt = E_q v + E_theta theta', and the second
                // derivative v^T E_qq v + 2 theta' E_theta,q v + theta'^2 E_theta,theta +
                // theta'' E_theta, with E_theta,theta = -E
                let (ee, et) = angle_combine(theta, e[0], e[1]);
                e[0] = ee;
                e[0].d1 += dth * et.v;
                e[0].d2 += 2.0 * dth * et.d1 + ddth * et.v - dth * dth * ee.v;
            } else if self.joints[j].motion.is_some() {
                let [c, dc, ddc] = self.drive(j, t);
                e[0].v -= c;
                e[0].d1 -= dc;
                e[0].d2 -= ddc;
            }
            for (k, ek) in e.iter().enumerate().take(n) {
                visit(row + k, sides, ek);
            }
        }
    }

    /// Body `k`'s six internal constraints, written into `out` as the jets [`SpatialPart::rows`] gives (local
    /// variables `0..12`): `1/2 (|d_i|^2 - 1)` has gradient `d_i` on director `i`,
    /// `d1 = d_i . d_i'`, `d2 = |d_i'|^2`; `d_i . d_j` has gradient `d_j` on `i` and `d_i` on
    /// `j`, `d1 = d_i' . d_j + d_i . d_j'`, `d2 = 2 d_i' . d_j'`.
    fn internal_jets_into(
        &self,
        q: &[f64],
        v: Option<&[f64]>,
        k: usize,
        out: &mut [DirJetN<SW>; 6],
    ) {
        let o = self.q0 + 12 * k;
        let d: [[f64; 3]; 3] =
            std::array::from_fn(|i| std::array::from_fn(|c| q[o + 3 + 3 * i + c]));
        let dd: [[f64; 3]; 3] = std::array::from_fn(|i| {
            std::array::from_fn(|c| v.map_or(0.0, |v| v[o + 3 + 3 * i + c]))
        });
        let dot = |a: &[f64; 3], b: &[f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        const PAIRS: [(usize, usize); 6] = [(0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2)];
        for (jet, (i, j)) in out.iter_mut().zip(PAIRS) {
            jet.g = [0.0; SW];
            if i == j {
                jet.g[3 + 3 * i..6 + 3 * i].copy_from_slice(&d[i]);
                jet.v = 0.5 * (dot(&d[i], &d[i]) - 1.0);
                jet.d1 = dot(&d[i], &dd[i]);
                jet.d2 = dot(&dd[i], &dd[i]);
            } else {
                jet.g[3 + 3 * i..6 + 3 * i].copy_from_slice(&d[j]);
                jet.g[3 + 3 * j..6 + 3 * j].copy_from_slice(&d[i]);
                jet.v = dot(&d[i], &d[j]);
                jet.d1 = dot(&dd[i], &d[j]) + dot(&d[i], &dd[j]);
                jet.d2 = 2.0 * dot(&dd[i], &dd[j]);
            }
        }
    }

    /// For every spatial row at time `t`: `visit(row, sides, gradient, (Phi_q v + Phi_t)_q)`
    /// (`H v`, plus `Phi_tq` on angle driver rows).
    #[inline(always)]
    pub(crate) fn rows_tan(
        &self,
        q: &[f64],
        v: &[f64],
        t: f64,
        visit: impl FnMut(usize, [Option<usize>; 2], &[f64; SW], &[f64; SW]),
    ) {
        // as `rows`: the planar models' test inlined, the loop out of line
        if self.m != 0 {
            self.rows_tan_spatial(q, v, t, visit);
        }
    }

    /// [`SpatialPart::rows_tan`] on a model with spatial rows.
    #[inline(never)]
    fn rows_tan_spatial(
        &self,
        q: &[f64],
        v: &[f64],
        t: f64,
        mut visit: impl FnMut(usize, [Option<usize>; 2], &[f64; SW], &[f64; SW]),
    ) {
        const PAIRS: [(usize, usize); 6] = [(0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2)];
        // scratch for every element (as in `rows_spatial`)
        let (mut e, mut es) = ([DirJetN::<SW>::cst(0.0); 6], [DirJetN::<SW>::cst(0.0); 6]);
        let mut markers = [MarkerAt::ZERO_JETS; 2];
        for (item, sides, row, n) in self.items() {
            if let (Item::Internal, Some(k)) = (item, sides[0]) {
                // in closed form (see `internal_jets_into`): the Hessian of 1/2 |d_i|^2 is the
                // identity on director i, that of d_i . d_j pairs directors i and j
                let o = self.q0 + 12 * k;
                let dv = |i: usize| &v[o + 3 + 3 * i..o + 6 + 3 * i];
                self.internal_jets_into(q, None, k, &mut e);
                for (r, (jet, (i, j))) in e.iter().zip(PAIRS).enumerate() {
                    let mut dg = [0.0; SW];
                    dg[3 + 3 * i..6 + 3 * i].copy_from_slice(dv(j));
                    if i != j {
                        dg[3 + 3 * j..6 + 3 * j].copy_from_slice(dv(i));
                    }
                    visit(row + r, sides, &jet.g, &dg);
                }
                continue;
            }
            let Item::Joint(j) = item else {
                continue;
            };
            // every joint equation is quadratic in q (at a fixed t), so its gradient is affine
            // and H v = g(q + v) - g(q) exactly: two passes of the closed-form marker jets
            let [la, lb] = sides.map(|k| k.map(|k| self.local_state(k, q, Some(v))));
            let shift = |l: &Option<([f64; 12], [f64; 12])>| {
                l.map(|(ql, vl)| (std::array::from_fn(|i| ql[i] + vl[i]), [0.0; 12]))
            };
            let (sa, sb) = (shift(&la), shift(&lb));
            let joint = &self.lowered[j];
            joint.eval_jets_with(as_side(&la), as_side(&lb), &mut markers, &mut e);
            joint.eval_jets_with(as_side(&sa), as_side(&sb), &mut markers, &mut es);
            self.combine_angle(j, t, &mut e);
            self.combine_angle(j, t, &mut es);
            // an angle driver's Phi_tq = theta' E_theta,q (e[1] after the combination)
            let dth = self.angle(j, t).map_or(0.0, |[_, d, _]| d);
            for (k, (ek, sk)) in e.iter().zip(&es).enumerate().take(n) {
                let mut dg: [f64; SW] = std::array::from_fn(|l| sk.g[l] - ek.g[l]);
                if dth != 0.0 && n == 1 {
                    for (d, g) in dg.iter_mut().zip(&e[1].g) {
                        *d += dth * g;
                    }
                }
                visit(row + k, sides, &ek.g, &dg);
            }
        }
    }

    /// `out[row, .] += g` in the columns of the element's sides.
    pub(crate) fn scatter_row(
        &self,
        row: usize,
        sides: [Option<usize>; 2],
        g: &[f64; SW],
        out: &mut DMatrix<f64>,
    ) {
        // per side: its block's columns (the first `w` of the side's 12 local variables)
        for (side, k) in sides.iter().enumerate() {
            let Some(k) = *k else {
                continue;
            };
            let (o, w) = self.slot_block(k);
            for (l, &x) in g[12 * side..12 * side + w].iter().enumerate() {
                out[(row, o + l)] += x;
            }
        }
    }

    /// `Phi_q`'s spatial non-zeros at time `t` as triplets.
    pub(crate) fn triplets(&self, q: &[f64], t: f64, out: &mut Vec<(usize, usize, f64)>) {
        self.rows(q, None, t, |row, sides, jet| {
            for (l, &x) in jet.g.iter().enumerate() {
                if let Some(c) = self.col(sides, l) {
                    if x != 0.0 {
                        out.push((row, c, x));
                    }
                }
            }
        });
    }

    /// `out += scale sum_k lambda_k Hess(Phi_k)` over the spatial rows at time `t`, from the
    /// cached Hessians (an angle driver's turned to `theta(t)`).
    pub(crate) fn add_hessian(
        &self,
        q: &[f64],
        t: f64,
        lambda: &[f64],
        scale: f64,
        out: &mut DMatrix<f64>,
    ) {
        let cache = self.constant_hessians(q);
        for r in self.r0..self.r0 + self.m {
            let w = scale * lambda[r];
            if w == 0.0 {
                continue;
            }
            cache.row_at(self, r, t, |i, j, h| out[(i, j)] += w * h);
        }
    }

    /// `out += scale sum_r w_r Hess(Phi_r) x` over the spatial rows at time `t`, from the
    /// cached Hessians (an angle driver's turned to `theta(t)`).
    pub(crate) fn add_hessian_vector(
        &self,
        q: &[f64],
        t: f64,
        x: &[f64],
        weights: &[f64],
        scale: f64,
        out: &mut [f64],
    ) {
        let cache = self.constant_hessians(q);
        for r in self.r0..self.r0 + self.m {
            let w = scale * weights[r];
            if w == 0.0 {
                continue;
            }
            cache.row_at(self, r, t, |i, j, h| out[i] += w * h * x[j]);
        }
    }

    /// The constant Hessians of the rows (evaluated at `q` on first use).
    fn constant_hessians(&self, q: &[f64]) -> &ConstantHessians {
        self.hessians.get_or_init(|| ConstantHessians::new(self, q))
    }

    /// Row `r`'s constant Hessian as nonzeros in global columns (`None`: not a spatial row, or
    /// an angle driver's).
    pub(crate) fn row_hessian(&self, q: &[f64], r: usize) -> Option<&[(usize, usize, f64)]> {
        if r < self.r0 || r >= self.r0 + self.m {
            return None;
        }
        self.constant_hessians(q).row(self, r)
    }

    /// `f(row column, column, value)` for the nonzeros of row `r`'s Hessian at time `t`:
    /// every spatial row's, an angle driver's included (nothing for a planar row).
    pub(crate) fn row_hessian_at(
        &self,
        q: &[f64],
        t: f64,
        r: usize,
        f: impl FnMut(usize, usize, f64),
    ) {
        if r < self.r0 || r >= self.r0 + self.m {
            return;
        }
        self.constant_hessians(q).row_at(self, r, t, f);
    }

    /// The potential of gravity on the spatial bodies and point masses, `-sum_k m_k g . x_k`.
    pub(crate) fn potential(&self, q: &[f64]) -> f64 {
        let g = self.gravity;
        (0..self.n_slots())
            .map(|k| {
                let o = self.slot_block(k).0;
                let x = &q[o..o + 3];
                -self.slot_mass(k) * (g[0] * x[0] + g[1] * x[1] + g[2] * x[2])
            })
            .sum()
    }

    /// Gravity's generalised forces `(m g, 0, 0, 0)` per spatial body, then `m g` per point
    /// mass, appended to `out`.
    pub(crate) fn gravity_forces(&self, out: &mut Vec<f64>) {
        for b in &self.bodies {
            let m = b.inertia.mass();
            out.extend(self.gravity.map(|g| m * g));
            out.extend([0.0; 9]);
        }
        for p in &self.points {
            out.extend(self.gravity.map(|g| p.mass * g));
        }
    }

    /// The coordinate names: `body.x`, `.y`, `.z`, then the directors `body.d1x`, ...,
    /// `body.d3z`.
    pub(crate) fn coordinate_names(&self, out: &mut Vec<String>) {
        for b in &self.bodies {
            for c in ["x", "y", "z"] {
                out.push(format!("{}.{c}", b.name));
            }
            for i in 1..=3 {
                for c in ["x", "y", "z"] {
                    out.push(format!("{}.d{i}{c}", b.name));
                }
            }
        }
        for p in &self.points {
            for c in ["x", "y", "z"] {
                out.push(format!("{}.{c}", p.name));
            }
        }
    }

    /// The unit of spatial row `row` for a model of length scale `l`: 1 for the internal
    /// constraints and orientation equations, `l` for positions, `l^2` for distances.
    pub(crate) fn equation_scale(&self, row: usize, l: f64) -> f64 {
        let Some(rel) = row.checked_sub(self.r0) else {
            return 1.0;
        };
        if rel < 6 * self.bodies.len() {
            return 1.0;
        }
        match self.joint_row.iter().rposition(|&r| r <= row) {
            Some(j) => l.powi(self.lowered[j].length_power(row - self.joint_row[j])),
            None => 1.0,
        }
    }

    /// The largest lever arm (marker point from a centre of mass), joint distance and radius
    /// of gyration of the spatial bodies (0 without them).
    pub(crate) fn length_scale(&self) -> f64 {
        let norm = |p: [f64; 3]| (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
        let mut l = 0.0f64;
        for b in &self.bodies {
            let j = b.inertia.moments();
            l = l.max((j[0].max(j[1]).max(j[2]) / b.inertia.mass()).sqrt());
        }
        for (entry, sides) in self.joints.iter().zip(&self.attach) {
            let (ma, mb) = entry.joint.markers();
            for (m, side) in [(ma, sides[0]), (mb, sides[1])] {
                if side.is_some() {
                    l = l.max(norm(m.point));
                }
            }
            if let super::joints::SpatialJointKind::Distance { length } = entry.joint.kind() {
                l = l.max(length);
            }
        }
        l
    }

    /// The name of spatial row `row`: `body.unit1`, ..., `body.orth23` for the internal
    /// constraints, `joint.eK` for a joint's `K`-th equation.
    pub(crate) fn equation_name(&self, row: usize) -> Option<String> {
        let rel = row.checked_sub(self.r0)?;
        let nb = self.bodies.len();
        if rel < 6 * nb {
            const LABELS: [&str; 6] = ["unit1", "unit2", "unit3", "orth12", "orth13", "orth23"];
            return Some(format!("{}.{}", self.bodies[rel / 6].name, LABELS[rel % 6]));
        }
        let j = self.joint_row.iter().rposition(|&r| r <= row)?;
        let k = row - self.joint_row[j];
        (k < self.lowered[j].n_equations()).then(|| format!("{}.e{}", self.joints[j].name, k + 1))
    }
}

impl crate::System {
    /// The angular momentum of the spatial bodies and point masses about the origin, global
    /// axes: `sum_k (m_k x_k x x_k' + sum_i E_ik d_ik x d_ik')` (the spin part is the body's
    /// `R J omega` on rigid motions; a point mass has only `m x x x'`).
    pub fn spatial_angular_momentum(&self, q: &[f64], v: &[f64]) -> [f64; 3] {
        let o = self.spatial.q0;
        let mut l = [0.0; 3];
        for (k, b) in self.spatial.bodies.iter().enumerate() {
            let at = |x: &[f64], i: usize| {
                let s = o + 12 * k + i;
                nalgebra::Vector3::new(x[s], x[s + 1], x[s + 2])
            };
            let mut lk = at(q, 0).cross(&at(v, 0)) * b.inertia.mass();
            for (i, e) in b.inertia.second_moments().iter().enumerate() {
                lk += at(q, 3 + 3 * i).cross(&at(v, 3 + 3 * i)) * *e;
            }
            for c in 0..3 {
                l[c] += lk[c];
            }
        }
        for (k, p) in self.spatial.points.iter().enumerate() {
            let o = self.spatial.point_offset() + 3 * k;
            let x = nalgebra::Vector3::new(q[o], q[o + 1], q[o + 2]);
            let u = nalgebra::Vector3::new(v[o], v[o + 1], v[o + 2]);
            let lk = x.cross(&u) * p.mass;
            for c in 0..3 {
                l[c] += lk[c];
            }
        }
        l
    }

    /// The angular velocity of spatial body `k` in its principal axes,
    /// `omega_i = d_i . omega` with `omega = 1/2 sum_i d_i x d_i'` (exact on rigid motions:
    /// `d_i x (omega x d_i)` sums to `2 omega`); `None` for a body index out of range.
    pub fn spatial_body_angular_velocity(
        &self,
        k: usize,
        q: &[f64],
        v: &[f64],
    ) -> Option<[f64; 3]> {
        if k >= self.spatial.bodies.len() {
            return None;
        }
        let s = self.spatial.q0 + 12 * k;
        let d = |x: &[f64], i: usize| {
            nalgebra::Vector3::new(x[s + 3 + 3 * i], x[s + 4 + 3 * i], x[s + 5 + 3 * i])
        };
        let w: nalgebra::Vector3<f64> = (0..3)
            .map(|i| d(q, i).cross(&d(v, i)))
            .sum::<nalgebra::Vector3<f64>>()
            * 0.5;
        Some([d(q, 0).dot(&w), d(q, 1).dot(&w), d(q, 2).dot(&w)])
    }
}

/// An angle driver's equation `E = cos theta e0 - sin theta e1` and its derivative in theta,
/// `E_theta = -sin theta e0 - cos theta e1`, from its components `e0 = X_b . Y_a`,
/// `e1 = X_b . X_a` (any scalar: values and jets alike, the combination being linear).
fn angle_combine<T: Scalar>(theta: f64, e0: T, e1: T) -> (T, T) {
    let (s, c) = theta.sin_cos();
    (e0 * c - e1 * s, -(e0 * s) - e1 * c)
}
