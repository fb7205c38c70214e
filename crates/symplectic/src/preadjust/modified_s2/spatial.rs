//! The spatial rows of the passes of `e4` (docs/spatial.md, "The preadjusted symplectic
//! schemes"): every spatial equation is quadratic in the natural coordinates, so along
//! directions `d_1 .. d_D` the series of row `r` ends at degree two,
//!
//! `Phi_r(q + sum_j x_j d_j) = Phi_r(q) + sum_j x_j g_r . d_j + sum_(j<l) x_j x_l d_j . H_r d_l
//! + sum_j x_j^2 d_j . H_r d_j / 2`,
//!
//! with `g_r` the row of `Phi_q` and `H_r` its constant Hessian. The coefficients' gradients
//! with respect to `q` are `g_r` (degree 0), `H_r d_j` (the coefficient of `x_j`) and zero
//! above, and the gradient of the coefficient of `x^e` with respect to direction `j` is the
//! `q`-gradient of the coefficient of `x^e / x_j` (the planar passes' division table). So the
//! passes at one `q` share, per spatial row, `g_r` in the element-local columns of the row's
//! two bodies and the few nonzeros of `H_r` (a quadratic row's Hessian has a handful; a joint
//! row that is linear in the coordinates has none): [`SpatialRowSet`], evaluated once per
//! `q`. Each pass keeps its directions ([`SpatialRows`]), and every product `H_r d_j` is formed
//! from them where it is used, so a pass's memory is its directions, not
//! `O(rows x directions x 24)`. The series are those at the evaluation's time `t`: `g_r` is
//! taken at `t`, and an angle driver's Hessian, `cos theta(t) H_0 - sin theta(t) H_1`, is
//! refreshed at every update (every other row's is constant); no term reads a degree-0
//! coefficient (left zero).

use mbd_model::{Basis, System, MAX_DIRS};

/// The element-local width of a spatial row: twelve columns per side (a point mass uses three).
const W: usize = 24;
/// The `slot` of a constraint row that is not a spatial row.
const NONE: usize = usize::MAX;

/// One spatial row at the set's `q`.
#[derive(Clone, Debug)]
struct Row {
    /// The row's index in `Phi`.
    r: usize,
    /// Each side's first coordinate and width (0 for ground): local column `12 s + l` is
    /// coordinate `o + l` for `l < width`, and no coordinate past it.
    sides: [(usize, usize); 2],
    /// `g_r` in local columns.
    g: [f64; W],
    /// `H_r`'s nonzeros `(row coordinate, column coordinate, value)` at the set's time.
    nz: Vec<(usize, usize, f64)>,
    /// Whether `H_r` depends on time (an angle driver's row): refreshed at every update.
    timed: bool,
}

impl Row {
    /// `x . d` over the row's local columns (side by side, in column order).
    fn dot(&self, x: &[f64; W], d: &[f64]) -> f64 {
        let mut s = 0.0;
        for (side, &(o, w)) in self.sides.iter().enumerate() {
            for (xl, dl) in x[12 * side..12 * side + w].iter().zip(&d[o..o + w]) {
                s += xl * dl;
            }
        }
        s
    }

    /// `out += c x` on the row's coordinates.
    fn scatter(&self, c: f64, x: &[f64; W], out: &mut [f64]) {
        if c == 0.0 {
            return;
        }
        for (side, &(o, w)) in self.sides.iter().enumerate() {
            for (ol, xl) in out[o..o + w].iter_mut().zip(&x[12 * side..12 * side + w]) {
                *ol += c * xl;
            }
        }
    }
}

/// The degree of a monomial and its directions (`(j, l)` with `j <= l` for degree two, `j`
/// twice for a square).
fn split(e: &[u8; MAX_DIRS]) -> (usize, usize, usize) {
    let mut deg = 0usize;
    let (mut a, mut b) = (0usize, 0usize);
    for (j, &x) in e.iter().enumerate() {
        for _ in 0..x {
            if deg == 0 {
                a = j;
            }
            b = j;
            deg += 1;
        }
    }
    (deg, a, b)
}

/// [`split`] of every monomial of the basis `B`.
fn splits<const K: usize, B: Basis<K>>() -> [(usize, usize, usize); K] {
    std::array::from_fn(|k| split(&B::EXP[k]))
}

/// The spatial rows at one `(q, t)`, shared by the passes of an evaluation (module doc): the
/// row list, the columns and the constant Hessians are built at the first
/// [`SpatialRowSet::update`] and kept; every update refreshes `g_r` and the Hessians that
/// depend on time (an angle driver's), in place.
#[derive(Debug, Default)]
pub(super) struct SpatialRowSet {
    rows: Vec<Row>,
    /// Each constraint row's place in `rows` ([`NONE`]: not a spatial row).
    slot: Vec<usize>,
    /// Whether the rows are built.
    built: bool,
}

impl SpatialRowSet {
    /// `g_r` of every spatial row at `(q, t)`, and the Hessians that depend on time (nothing on
    /// a planar model).
    pub(super) fn update(&mut self, sys: &System, q: &[f64], t: f64) {
        if !sys.has_spatial() {
            return;
        }
        if !self.built {
            self.build(sys, q, t);
            return;
        }
        for row in self.rows.iter_mut().filter(|row| row.timed) {
            row.nz.clear();
            sys.spatial_row_hessian_at(q, t, row.r, |i, j, h| row.nz.push((i, j, h)));
        }
        let (rows, slot) = (&mut self.rows, &self.slot);
        sys.local_rows_gamma(q, None, t, |r, sides, _| {
            let Some(row) = slot.get(r).and_then(|&k| rows.get_mut(k)) else {
                return;
            };
            for (s, side) in sides.iter().enumerate() {
                if let Some((_, g)) = side {
                    let n = g.len().min(12);
                    row.g[12 * s..12 * s + n].copy_from_slice(&g[..n]);
                }
            }
        });
    }

    /// The row list, columns, `g_r` and Hessians at `(q, t)`.
    fn build(&mut self, sys: &System, q: &[f64], t: f64) {
        let planar = sys.bodies().len();
        let rows = &mut self.rows;
        rows.clear();
        sys.local_rows_gamma(q, None, t, |r, sides, _| {
            if !sides.iter().flatten().any(|s| s.0 >= planar) {
                return;
            }
            let mut row = Row {
                r,
                sides: [(0, 0); 2],
                g: [0.0; W],
                nz: Vec::new(),
                timed: false,
            };
            for (s, side) in sides.iter().enumerate() {
                let Some((block, g)) = side else {
                    continue;
                };
                let Some((o, _)) = sys.body_block(*block) else {
                    continue;
                };
                let w = g.len().min(12);
                row.sides[s] = (o, w);
                row.g[12 * s..12 * s + w].copy_from_slice(&g[..w]);
            }
            rows.push(row);
        });
        self.slot.clear();
        self.slot.resize(sys.n_constraints(), NONE);
        for (k, row) in self.rows.iter_mut().enumerate() {
            self.slot[row.r] = k;
            // (every row but an angle driver's has a constant Hessian)
            row.timed = sys.spatial_row_hessian(q, row.r).is_none();
            sys.spatial_row_hessian_at(q, t, row.r, |i, j, h| row.nz.push((i, j, h)));
        }
        self.built = true;
    }
}

/// One pass's share of the spatial rows ([`super::passes::Pass`]): its directions, copied at
/// every evaluation.
#[derive(Debug, Default)]
pub(super) struct SpatialRows {
    dirs: Vec<Vec<f64>>,
}

impl SpatialRows {
    /// The directions `dirs` of a pass.
    pub(super) fn gather(&mut self, dirs: &[&[f64]]) {
        self.dirs.resize_with(dirs.len(), Vec::new);
        for (kept, d) in self.dirs.iter_mut().zip(dirs) {
            kept.clear();
            kept.extend_from_slice(d);
        }
    }

    /// `x . H_r d_j` of the set's row `k`.
    fn hd_dot(&self, set: &SpatialRowSet, k: usize, j: usize, x: &[f64]) -> f64 {
        let dj = &self.dirs[j];
        set.rows[k]
            .nz
            .iter()
            .map(|&(i, c, v)| x[i] * v * dj[c])
            .sum()
    }

    /// `out += c H_r d_j` of the set's row `k`.
    fn hd_scatter(&self, set: &SpatialRowSet, k: usize, c: f64, j: usize, out: &mut [f64]) {
        if c == 0.0 {
            return;
        }
        let dj = &self.dirs[j];
        for &(i, col, v) in &set.rows[k].nz {
            out[i] += c * v * dj[col];
        }
    }

    /// The coefficients of the spatial rows in the basis `B` into `vals` (module doc).
    pub(super) fn coefficients<const K: usize, B: Basis<K>>(
        &self,
        set: &SpatialRowSet,
        dirs: &[&[f64]],
        vals: &mut [[f64; K]],
    ) {
        let splits = splits::<K, B>();
        for (k, row) in set.rows.iter().enumerate() {
            let out = &mut vals[row.r];
            for (o, sp) in out.iter_mut().zip(&splits) {
                *o = match *sp {
                    (1, j, _) => row.dot(&row.g, dirs[j]),
                    (2, j, l) if j == l => 0.5 * self.hd_dot(set, k, j, dirs[j]),
                    (2, j, l) => self.hd_dot(set, k, l, dirs[j]),
                    _ => 0.0,
                };
            }
        }
    }

    /// `out += sum_r w_r H_r d_j` over the spatial rows.
    pub(super) fn add_hessian_direction(
        &self,
        set: &SpatialRowSet,
        j: usize,
        w: &[f64],
        out: &mut [f64],
    ) {
        for (k, row) in set.rows.iter().enumerate() {
            self.hd_scatter(set, k, w[row.r], j, out);
        }
    }

    /// The spatial rows' share of [`crate::passes::add_constraint_poly_adjoint`] with the
    /// weights `w` of the coefficients: `qb += sum_k w_k grad_q c_k`, `dirs[j] += sum_k w_k
    /// grad_q c_(k / x_j)`.
    pub(super) fn adjoint<const K: usize, B: Basis<K>>(
        &self,
        set: &SpatialRowSet,
        w: &[[f64; K]],
        qb: &mut [f64],
        dirs: &mut [&mut [f64]],
    ) {
        let nd = dirs.len();
        let splits = splits::<K, B>();
        for (k, row) in set.rows.iter().enumerate() {
            for (&c, sp) in w[row.r].iter().zip(&splits) {
                if c == 0.0 {
                    continue;
                }
                match *sp {
                    (0, _, _) => row.scatter(c, &row.g, qb),
                    (1, j, _) => {
                        self.hd_scatter(set, k, c, j, qb);
                        if j < nd {
                            row.scatter(c, &row.g, dirs[j]);
                        }
                    }
                    (2, j, l) => {
                        if j < nd {
                            self.hd_scatter(set, k, c, l, dirs[j]);
                        }
                        if l != j && l < nd {
                            self.hd_scatter(set, k, c, j, dirs[l]);
                        }
                    }
                    _ => {}
                }
            }
        }
    }

    /// The spatial rows' share of [`crate::passes::add_constraint_poly_grads_many`]:
    /// `outs[p] += sum_r sum_k w[r][p][k] grad_q c_k`.
    pub(super) fn add_grads_many<const K: usize, const P: usize, B: Basis<K>>(
        &self,
        set: &SpatialRowSet,
        w: &[[[f64; K]; P]],
        outs: &mut [&mut [f64]; P],
    ) {
        let splits = splits::<K, B>();
        for (k, row) in set.rows.iter().enumerate() {
            for (wp, out) in w[row.r].iter().zip(outs.iter_mut()) {
                for (&c, sp) in wp.iter().zip(&splits) {
                    if c == 0.0 {
                        continue;
                    }
                    match *sp {
                        (0, _, _) => row.scatter(c, &row.g, out),
                        (1, j, _) => self.hd_scatter(set, k, c, j, out),
                        _ => {}
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::split;

    #[test]
    fn monomials_split_into_degree_and_directions() {
        assert_eq!(split(&[0; 6]), (0, 0, 0));
        assert_eq!(split(&[0, 1, 0, 0, 0, 0]), (1, 1, 1));
        assert_eq!(split(&[2, 0, 0, 0, 0, 0]), (2, 0, 0));
        assert_eq!(split(&[1, 0, 1, 0, 0, 0]), (2, 0, 2));
        assert_eq!(split(&[2, 1, 0, 0, 0, 0]).0, 3);
    }
}
