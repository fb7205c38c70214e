//! The spatial rows of a pass of `e4` (docs/spatial.md, "The preadjusted symplectic
//! schemes"): every spatial equation is quadratic in the natural coordinates, so along
//! directions `d_1 .. d_D` the series of row `r` ends at degree two,
//!
//! `Phi_r(q + sum_j x_j d_j) = Phi_r(q) + sum_j x_j g_r . d_j + sum_(j<l) x_j x_l d_j . H_r d_l
//! + sum_j x_j^2 d_j . H_r d_j / 2`,
//!
//! with `g_r` the row of `Phi_q` and `H_r` its constant Hessian. The coefficients' gradients
//! with respect to `q` are `g_r` (degree 0), `H_r d_j` (the coefficient of `x_j`) and zero
//! above, and the gradient of the coefficient of `x^e` with respect to direction `j` is the
//! `q`-gradient of the coefficient of `x^e / x_j` (the planar passes' division table). So a
//! pass keeps, per spatial row, `g_r` in the element-local columns of the row's two bodies and
//! the few nonzeros of `H_r` (a quadratic row's Hessian has at most a few dozen; a joint row
//! that is linear in the coordinates has none), and the directions: every product `H_r d_j`
//! is formed from them where it is used, so a pass's memory is `O(rows)` small records and
//! not `O(rows x directions x 24)`. The spatial model's time
//! does not enter: the preadjustments refuse constraints whose Jacobian depends on time, and no
//! term reads a degree-0 coefficient (left zero).

use mbd_model::{Basis, System, MAX_DIRS};

/// The element-local width of a spatial row: twelve columns per side (a point mass uses three).
const W: usize = 24;
/// A local column that no coordinate fills.
const NONE: usize = usize::MAX;

/// One spatial row's data in a pass.
#[derive(Clone, Debug)]
struct Row {
    /// The row's index in `Phi`.
    r: usize,
    /// The coordinate of each local column ([`NONE`] where the side is ground or narrower).
    cols: [usize; W],
    /// `g_r` in local columns.
    g: [f64; W],
    /// `H_r`'s nonzeros `(row coordinate, column coordinate, value)`, for a row whose Hessian
    /// is constant (kept from the first evaluation).
    nz: Vec<(usize, usize, f64)>,
    /// A row whose Hessian is not constant: `H_r d_j` in local columns for every direction,
    /// from a pass along each (empty for a constant Hessian).
    hd: Vec<[f64; W]>,
}

impl Row {
    fn dot(&self, x: &[f64; W], d: &[f64]) -> f64 {
        let mut s = 0.0;
        for (l, &c) in self.cols.iter().enumerate() {
            if c != NONE {
                s += x[l] * d[c];
            }
        }
        s
    }

    fn scatter(&self, c: f64, x: &[f64; W], out: &mut [f64]) {
        if c == 0.0 {
            return;
        }
        for (l, &k) in self.cols.iter().enumerate() {
            if k != NONE {
                out[k] += c * x[l];
            }
        }
    }

    /// `x . H_r d_j` (`d` the pass's directions).
    fn hd_dot(&self, j: usize, d: &[Vec<f64>], x: &[f64]) -> f64 {
        if self.hd.is_empty() {
            let dj = &d[j];
            self.nz.iter().map(|&(i, c, v)| x[i] * v * dj[c]).sum()
        } else {
            self.dot(&self.hd[j], x)
        }
    }

    /// `out += c H_r d_j`.
    fn hd_scatter(&self, c: f64, j: usize, d: &[Vec<f64>], out: &mut [f64]) {
        if c == 0.0 {
            return;
        }
        if self.hd.is_empty() {
            let dj = &d[j];
            for &(i, k, v) in &self.nz {
                out[i] += c * v * dj[k];
            }
        } else {
            self.scatter(c, &self.hd[j], out);
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

/// The spatial rows of one pass ([`super::passes::Pass`]): filled by [`SpatialRows::gather`]
/// at every evaluation (the row list, the columns and the constant Hessians are built at the
/// first and kept).
#[derive(Debug, Default)]
pub(super) struct SpatialRows {
    rows: Vec<Row>,
    /// The pass's directions, copied at every evaluation (the products `H_r d_j` of the rows
    /// with constant Hessians are formed from them where they are used, not kept per row).
    dirs: Vec<Vec<f64>>,
    /// Whether the row list is built and every row's Hessian constant (then an evaluation
    /// only refreshes `g_r`).
    constant: bool,
    /// Each constraint row's place in `rows` ([`NONE`]: not a spatial row).
    slot: Vec<usize>,
}

impl SpatialRows {
    /// `g_r` of every spatial row at `q`, and the directions `dirs`. At the first evaluation
    /// one pass of the rows along `d_1` gives the rows and their columns; each row keeps its
    /// constant Hessian ([`System::spatial_row_hessian`]), or, if a row's Hessian is not
    /// constant, `H_r d_j` from a pass along each direction at every evaluation.
    pub(super) fn gather(&mut self, sys: &System, q: &[f64], dirs: &[&[f64]]) {
        if dirs.is_empty() {
            self.rows.clear();
            self.constant = false;
            return;
        }
        self.dirs.resize_with(dirs.len(), Vec::new);
        for (kept, d) in self.dirs.iter_mut().zip(dirs) {
            kept.clear();
            kept.extend_from_slice(d);
        }
        if self.constant {
            self.refresh_gradients(sys, q);
            return;
        }
        for (j, d) in dirs.iter().enumerate() {
            self.pass(sys, q, d, j, dirs.len());
        }
        let mut constant = true;
        for row in &mut self.rows {
            row.nz.clear();
            match sys.spatial_row_hessian(q, row.r) {
                Some(h) => row.nz.extend_from_slice(h),
                None => constant = false,
            }
        }
        if constant {
            self.slot.clear();
            self.slot.resize(sys.n_constraints(), NONE);
            for (k, row) in self.rows.iter_mut().enumerate() {
                row.hd = Vec::new();
                self.slot[row.r] = k;
            }
            self.constant = true;
        }
    }

    /// `g_r` of every kept row at `q` (the rows and their columns do not change).
    fn refresh_gradients(&mut self, sys: &System, q: &[f64]) {
        let (rows, slot) = (&mut self.rows, &self.slot);
        sys.local_rows_gamma(q, None, 0.0, |r, sides, _| {
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

    /// One pass of the rows along `d` (direction `j` of `nd`): `H_r d` into each row's
    /// `hd[j]`, and for `j = 0` the row list, the columns and `g_r`.
    fn pass(&mut self, sys: &System, q: &[f64], d: &[f64], j: usize, nd: usize) {
        let planar = sys.bodies().len();
        let mut k = 0;
        let rows = &mut self.rows;
        sys.local_rows_tan(q, d, 0.0, |r, sides| {
            let spatial = sides.iter().flatten().any(|s| s.0 >= planar);
            if !spatial {
                return;
            }
            if k == rows.len() {
                rows.push(Row {
                    r,
                    cols: [NONE; W],
                    g: [0.0; W],
                    nz: Vec::new(),
                    hd: Vec::new(),
                });
            }
            let row = &mut rows[k];
            k += 1;
            if j == 0 {
                row.r = r;
                row.cols = [NONE; W];
                row.g = [0.0; W];
                row.hd.resize(nd, [0.0; W]);
            }
            row.hd[j] = [0.0; W];
            for (s, side) in sides.iter().enumerate() {
                let Some((block, g, dg)) = side else {
                    continue;
                };
                let Some((o, _)) = sys.body_block(*block) else {
                    continue;
                };
                for l in 0..g.len().min(12) {
                    if j == 0 {
                        row.cols[12 * s + l] = o + l;
                        row.g[12 * s + l] = g[l];
                    }
                    row.hd[j][12 * s + l] = dg[l];
                }
            }
        });
        self.rows.truncate(k);
    }

    /// The coefficients of the spatial rows in the basis `B` into `vals` (module doc).
    pub(super) fn coefficients<const K: usize, B: Basis<K>>(
        &self,
        dirs: &[&[f64]],
        vals: &mut [[f64; K]],
    ) {
        let d = &self.dirs;
        let splits = splits::<K, B>();
        for row in &self.rows {
            let out = &mut vals[row.r];
            for (k, sp) in splits.iter().enumerate() {
                out[k] = match *sp {
                    (1, j, _) => row.dot(&row.g, dirs[j]),
                    (2, j, l) if j == l => 0.5 * row.hd_dot(j, d, dirs[j]),
                    (2, j, l) => row.hd_dot(l, d, dirs[j]),
                    _ => 0.0,
                };
            }
        }
    }

    /// `out += sum_r w_r H_r d_j` over the spatial rows.
    pub(super) fn add_hessian_direction(&self, j: usize, w: &[f64], out: &mut [f64]) {
        for row in &self.rows {
            row.hd_scatter(w[row.r], j, &self.dirs, out);
        }
    }

    /// The spatial rows' share of [`crate::passes::add_constraint_poly_adjoint`] with the
    /// weights `w` of the coefficients: `qb += sum_k w_k grad_q c_k`, `dirs[j] += sum_k w_k
    /// grad_q c_(k / x_j)`.
    pub(super) fn adjoint<const K: usize, B: Basis<K>>(
        &self,
        w: &[[f64; K]],
        qb: &mut [f64],
        dirs: &mut [&mut [f64]],
    ) {
        let nd = dirs.len();
        let d = &self.dirs;
        let splits = splits::<K, B>();
        for row in &self.rows {
            let wr = &w[row.r];
            for (&c, sp) in wr.iter().zip(&splits) {
                if c == 0.0 {
                    continue;
                }
                match *sp {
                    (0, _, _) => row.scatter(c, &row.g, qb),
                    (1, j, _) => {
                        row.hd_scatter(c, j, d, qb);
                        if j < nd {
                            row.scatter(c, &row.g, dirs[j]);
                        }
                    }
                    (2, j, l) => {
                        if j < nd {
                            row.hd_scatter(c, l, d, dirs[j]);
                        }
                        if l != j && l < nd {
                            row.hd_scatter(c, j, d, dirs[l]);
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
        w: &[[[f64; K]; P]],
        outs: &mut [&mut [f64]; P],
    ) {
        let d = &self.dirs;
        let splits = splits::<K, B>();
        for row in &self.rows {
            for (wp, out) in w[row.r].iter().zip(outs.iter_mut()) {
                for (&c, sp) in wp.iter().zip(&splits) {
                    if c == 0.0 {
                        continue;
                    }
                    match *sp {
                        (0, _, _) => row.scatter(c, &row.g, out),
                        (1, j, _) => row.hd_scatter(c, j, d, out),
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
