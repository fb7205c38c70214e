//! Constraint rows over **body blocks** in element-local form: the layout shared by the sparse
//! kernels that work on bodies of any kind (the body-eliminated Schur complement of the
//! index-1 solve and the projections, the tangent solver's sparse chart).
//!
//! Each row acts on at most two blocks (`mbd_model::System::body_block`: 3 coordinates for a
//! planar body, 12 for a spatial one); its local gradient on each side is stored in one flat
//! array, side after side, so a product with the row costs its width and nothing else. Two rows
//! couple in `A A^T`-like matrices only when they share a block ([`BlockRows::shared_pairs`]),
//! so for a chain those matrices are banded and every operation is `O(N)`.

use crate::error::SolveError;
use mbd_model::System;

/// One side of a row: its block, first coordinate, width and the offset of its local gradient
/// in the flat value array.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RowSide {
    /// The body block ([`System::body_block`]).
    pub block: usize,
    /// The block's first coordinate.
    pub col: usize,
    /// The block's width (3 planar, 12 spatial).
    pub width: usize,
    /// Offset of this side's values in the flat value array.
    pub off: usize,
}

/// The kept rows of a model's constraint Jacobian over body blocks (see the module docs).
#[derive(Clone, Debug)]
pub struct BlockRows {
    /// Each kept row's global row.
    rows: Vec<usize>,
    /// Each global row's kept index (`usize::MAX`: not kept).
    index: Vec<usize>,
    sides: Vec<[Option<RowSide>; 2]>,
    /// Per block: the kept rows acting on it (kept index, side).
    by_block: Vec<Vec<(usize, usize)>>,
    n_values: usize,
    /// Every side in storage order: its first coordinate and its kept row; and the width all
    /// sides share (`None`: mixed widths, planar and spatial bodies in one model).
    side_col: Vec<usize>,
    side_row: Vec<usize>,
    uniform: Option<usize>,
}

impl BlockRows {
    /// The layout of the rows `r` of `sys` with `keep(r)` (allocates; once per model).
    pub fn new(sys: &System, keep: impl Fn(usize) -> bool) -> Result<Self, SolveError> {
        let m = sys.n_constraints();
        type Sides = [Option<(usize, usize)>; 2];
        let mut all: Vec<(usize, Sides)> = Vec::with_capacity(m);
        let q = sys.initial_guess().0;
        sys.local_rows_gamma(q.as_slice(), None, 0.0, |r, s, _| {
            all.push((r, s.map(|s| s.map(|(b, g)| (b, g.len())))));
        });
        all.sort_by_key(|&(r, _)| r);
        let (mut rows, mut index, mut sides) = (Vec::new(), vec![usize::MAX; m], Vec::new());
        let mut off = 0;
        for (r, s) in all {
            if !keep(r) {
                continue;
            }
            index[r] = rows.len();
            rows.push(r);
            let mut side = [None; 2];
            for (k, s) in s.iter().enumerate() {
                if let Some((block, width)) = *s {
                    let (col, w) = sys
                        .body_block(block)
                        .filter(|&(_, w)| w == width)
                        .ok_or_else(|| {
                            SolveError::Unsupported(format!(
                                "row {r} names body block {block} of width {width}, which the \
                                 model does not have"
                            ))
                        })?;
                    side[k] = Some(RowSide {
                        block,
                        col,
                        width: w,
                        off,
                    });
                    off += w;
                }
            }
            sides.push(side);
        }
        let mut by_block: Vec<Vec<(usize, usize)>> = vec![Vec::new(); sys.n_body_blocks()];
        for (e, s) in sides.iter().enumerate() {
            for (k, side) in s.iter().enumerate() {
                if let Some(side) = side {
                    by_block[side.block].push((e, k));
                }
            }
        }
        let (mut side_col, mut side_row, mut widths) = (Vec::new(), Vec::new(), Vec::new());
        for (e, s) in sides.iter().enumerate() {
            for side in s.iter().flatten() {
                side_col.push(side.col);
                side_row.push(e);
                widths.push(side.width);
            }
        }
        let uniform = match widths.first() {
            Some(&w) if widths.iter().all(|&x| x == w) => Some(w),
            _ => None,
        };
        Ok(BlockRows {
            rows,
            index,
            sides,
            by_block,
            n_values: off,
            side_col,
            side_row,
            uniform,
        })
    }

    /// Every side in storage order as (first coordinate, kept row), and the width all sides
    /// share (`None`: mixed widths). The values of side `k` start at the sum of the widths
    /// before it.
    pub fn side_order(&self) -> (&[usize], &[usize], Option<usize>) {
        (&self.side_col, &self.side_row, self.uniform)
    }

    /// `out += Phi^T y` for the kept rows' gradients `vals` (`y` by kept row): every side's
    /// gradient times its row's `y` added on its block, the loops unrolled when all sides
    /// have one width.
    pub fn add_transpose(&self, vals: &[f64], y: &[f64], out: &mut [f64]) {
        match self.uniform {
            Some(3) => self.add_transpose_w::<3>(vals, y, out),
            Some(12) => self.add_transpose_w::<12>(vals, y, out),
            _ => {
                for (e, &ye) in y.iter().enumerate().take(self.len()) {
                    if ye != 0.0 {
                        self.add_scaled(vals, e, ye, out);
                    }
                }
            }
        }
    }

    fn add_transpose_w<const W: usize>(&self, vals: &[f64], y: &[f64], out: &mut [f64]) {
        let sides = self.side_col.iter().zip(&self.side_row);
        for (g, (&c, &e)) in vals.chunks_exact(W).zip(sides) {
            let ye = y[e];
            if ye == 0.0 {
                continue;
            }
            if let (Some(g), Some(o)) = (g.first_chunk::<W>(), out[c..].first_chunk_mut::<W>()) {
                for l in 0..W {
                    o[l] += g[l] * ye;
                }
            }
        }
    }

    /// Number of kept rows.
    pub fn len(&self) -> usize {
        self.rows.len()
    }

    /// Whether no row is kept.
    pub fn is_empty(&self) -> bool {
        self.rows.is_empty()
    }

    /// Length of the flat value array (the sum of the kept rows' side widths).
    pub fn n_values(&self) -> usize {
        self.n_values
    }

    /// Kept row `e`'s global row.
    pub fn row(&self, e: usize) -> usize {
        self.rows[e]
    }

    /// Global row `r`'s kept index (`None`: not kept).
    pub fn index(&self, r: usize) -> Option<usize> {
        self.index.get(r).copied().filter(|&e| e != usize::MAX)
    }

    /// Every kept row's sides.
    pub fn sides(&self) -> &[[Option<RowSide>; 2]] {
        &self.sides
    }

    /// Per body block, the kept rows acting on it as (kept index, side).
    pub fn by_block(&self) -> &[Vec<(usize, usize)>] {
        &self.by_block
    }

    /// Every pair of kept rows `e1 >= e2` sharing a block, once per shared block:
    /// `visit(side of e1, side of e2, e1, e2)` (both sides on that block).
    pub fn shared_pairs(&self, mut visit: impl FnMut(RowSide, RowSide, usize, usize)) {
        for rows in &self.by_block {
            for &(e1, k1) in rows {
                for &(e2, k2) in rows {
                    if e1 < e2 {
                        continue;
                    }
                    if let (Some(s1), Some(s2)) = (self.sides[e1][k1], self.sides[e2][k2]) {
                        visit(s1, s2, e1, e2);
                    }
                }
            }
        }
    }

    /// `sum over the sides of kept row e: vals[side] . x[block]`.
    #[inline]
    pub fn dot(&self, vals: &[f64], e: usize, x: &[f64]) -> f64 {
        let mut acc = 0.0;
        for s in self.sides[e].iter().flatten() {
            let g = &vals[s.off..s.off + s.width];
            acc += g
                .iter()
                .zip(&x[s.col..s.col + s.width])
                .map(|(g, x)| g * x)
                .sum::<f64>();
        }
        acc
    }

    /// `out[block] += alpha vals[side]` over the sides of kept row `e`.
    #[inline]
    pub fn add_scaled(&self, vals: &[f64], e: usize, alpha: f64, out: &mut [f64]) {
        for s in self.sides[e].iter().flatten() {
            let g = &vals[s.off..s.off + s.width];
            for (o, g) in out[s.col..s.col + s.width].iter_mut().zip(g) {
                *o += alpha * g;
            }
        }
    }

    /// The kept rows' local gradients at `(q, v, t)` into `vals` (length
    /// [`BlockRows::n_values`]), and, if asked for, `gamma` for every row (length m; `v = None`:
    /// zero velocities).
    pub fn gather(
        &self,
        sys: &System,
        q: &[f64],
        v: Option<&[f64]>,
        t: f64,
        vals: &mut [f64],
        mut gamma: Option<&mut [f64]>,
    ) {
        sys.local_rows_gamma(q, v, t, |r, s, gm| {
            if let Some(g) = gamma.as_deref_mut() {
                g[r] = gm;
            }
            let Some(e) = self.index(r) else {
                return;
            };
            for (side, g) in self.sides[e].iter().zip(s) {
                if let (Some(side), Some((_, g))) = (side, g) {
                    vals[side.off..side.off + side.width].copy_from_slice(g);
                }
            }
        });
    }

    /// The kept rows of `Phi_q` into `vals` and of `(Phi_q v + Phi_t)_q` into `dvals` at time
    /// `t` (both of length [`BlockRows::n_values`]).
    pub fn gather_tan(
        &self,
        sys: &System,
        q: &[f64],
        v: &[f64],
        t: f64,
        vals: &mut [f64],
        dvals: &mut [f64],
    ) {
        sys.local_rows_tan(q, v, t, |r, s| {
            let Some(e) = self.index(r) else {
                return;
            };
            for (side, g) in self.sides[e].iter().zip(s) {
                if let (Some(side), Some((_, g, dg))) = (side, g) {
                    let range = side.off..side.off + side.width;
                    vals[range.clone()].copy_from_slice(g);
                    dvals[range].copy_from_slice(dg);
                }
            }
        });
    }
}
