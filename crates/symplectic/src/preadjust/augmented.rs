//! The augmented inverse mass of spatial bodies, through which the preadjustment's projected
//! metric takes bodies with a zero second moment (a thin disc or plate: a singular `M`).
//!
//! With `G_b` a spatial body's six internal rows over its nine director coordinates and
//! `W = w I` (`w` the body's largest second moment), `M_W = M + G_int^T W G_int` is block
//! diagonal (a 9 x 9 block per body on its directors, the diagonal elsewhere) and definite
//! wherever `M` is definite on the tangent space of the internal constraints. The metric uses
//! `M_W^-1` where it used `M^-1`. What that changes (docs/spatial.md, "The preadjusted
//! symplectic schemes"):
//!
//! * nothing in a solve whose constraint part is zero: the projector `Pi`, the rest multipliers
//!   `mu0` and `u = -Pi g` are those of `M` (on `G x = 0` the added term vanishes);
//! * for a solve with constraint part `c` (`sigma = S^-1 gamma_c`, `rho = S^-1 h`), the
//!   minimum-norm solution `x = M_W^-1 G^T S_W^-1 c` is that of `M` (the added term is the
//!   constant `c_int^T W c_int` on `G x = c`), and the multipliers of `M` are
//!   `S_W^-1 c - W c_int` ([`Augmented::correct`]); the value `c^T S^-1 c = x^T M x` is
//!   `c^T S_W^-1 c - c_int^T W c_int` ([`Augmented::penalty`]).
//!
//! So every quantity is that of `M`, also where `M` is singular and `M^-1` does not exist.
//!
//! The s = 2 term's reverse pass needs a constant diagonal inverse mass instead:
//! [`regularised_inverse`].

use mbd_model::System;
use mbd_solve::linalg::DenseCholesky;
use mbd_solve::SolveError;

/// The internal rows' directions over a body's nine director coordinates: `(i, i)` the unit
/// row of director `i` (gradient `d_i` on its block), `(i, j)` the orthogonality row (`d_j` on
/// block `i`, `d_i` on block `j`), in the model's row order.
const PAIRS: [(usize, usize); 6] = [(0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2)];

/// One spatial body's block of `M_W^-1`.
#[derive(Debug, Clone)]
struct Block {
    /// The first director coordinate and the first internal row.
    c0: usize,
    r0: usize,
    /// The weight `w` and the second moments `E_i`.
    w: f64,
    e: [f64; 3],
    /// `M_W^-1` on the directors, column-major 9 x 9.
    inv: [f64; 81],
}

/// `M_W^-1` for a model with spatial bodies (module doc), evaluated at one configuration.
#[derive(Debug)]
pub(super) struct Augmented {
    blocks: Vec<Block>,
    /// `minv` of the coordinates outside the director blocks (the director entries are unused).
    minv: Vec<f64>,
    /// The block of each coordinate and its index in it (`usize::MAX`: none).
    owner: Vec<(usize, usize)>,
    chol: DenseCholesky,
}

impl Augmented {
    /// The blocks of `sys`'s spatial bodies, or `None` for a model without any.
    pub(super) fn new(sys: &System) -> Option<Self> {
        let bodies = sys.spatial_bodies();
        if bodies.is_empty() {
            return None;
        }
        let (q0, r0) = (sys.spatial_offset(), sys.spatial_internal_rows().start);
        let n = sys.n_coords();
        let mut owner = vec![(usize::MAX, 0); n];
        let blocks: Vec<Block> = bodies
            .iter()
            .enumerate()
            .map(|(k, b)| {
                let e = b.inertia.second_moments();
                let c0 = q0 + 12 * k + 3;
                for (l, o) in owner[c0..c0 + 9].iter_mut().enumerate() {
                    *o = (k, l);
                }
                Block {
                    c0,
                    r0: r0 + 6 * k,
                    w: e[0].max(e[1]).max(e[2]),
                    e,
                    inv: [0.0; 81],
                }
            })
            .collect();
        Some(Augmented {
            blocks,
            minv: sys.inv_mass_diag().as_slice().to_vec(),
            owner,
            chol: DenseCholesky::new(9),
        })
    }

    /// Evaluates every block at `q`: `M_W = diag(E_i I3) + w sum_r g_r g_r^T` over the six
    /// internal rows `g_r`, factored and inverted.
    pub(super) fn update(&mut self, q: &[f64]) -> Result<(), SolveError> {
        for b in &mut self.blocks {
            let d: [[f64; 3]; 3] =
                std::array::from_fn(|i| std::array::from_fn(|l| q[b.c0 + 3 * i + l]));
            self.chol.clear();
            for i in 0..9 {
                self.chol.add(i, i, b.e[i / 3]);
            }
            for (i, j) in PAIRS {
                let mut g = [0.0; 9];
                g[3 * i..3 * i + 3].copy_from_slice(&d[j]);
                if i != j {
                    g[3 * j..3 * j + 3].copy_from_slice(&d[i]);
                }
                for r in 0..9 {
                    for c in 0..=r {
                        self.chol.add(r, c, b.w * g[r] * g[c]);
                    }
                }
            }
            self.chol
                .factor_in_place()
                .map_err(|_| SolveError::Singular {
                    t: f64::NAN,
                    what: "augmented mass matrix of a spatial body in the preadjustment",
                    detail: "its directors are far from orthonormal".into(),
                })?;
            for c in 0..9 {
                let col = &mut b.inv[9 * c..9 * c + 9];
                col.fill(0.0);
                col[c] = 1.0;
                self.chol.solve_in_place(col);
            }
        }
        Ok(())
    }

    /// `out = M_W^-1 x`.
    pub(super) fn apply(&self, x: &[f64], out: &mut [f64]) {
        for (k, ((o, xi), mi)) in out.iter_mut().zip(x).zip(&self.minv).enumerate() {
            if self.owner[k].0 == usize::MAX {
                *o = mi * xi;
            }
        }
        for b in &self.blocks {
            let xb = &x[b.c0..b.c0 + 9];
            for (r, o) in out[b.c0..b.c0 + 9].iter_mut().enumerate() {
                *o = (0..9).map(|c| b.inv[9 * c + r] * xb[c]).sum();
            }
        }
    }

    /// `out += c M_W^-1 y` with `y` given by coordinate (`y(k)`, e.g. `(G^T x)_k`).
    pub(super) fn add_apply(&self, c: f64, y: impl Fn(usize) -> f64, out: &mut [f64]) {
        for (k, (o, mi)) in out.iter_mut().zip(&self.minv).enumerate() {
            if self.owner[k].0 == usize::MAX {
                *o += c * mi * y(k);
            }
        }
        for b in &self.blocks {
            let yb: [f64; 9] = std::array::from_fn(|l| y(b.c0 + l));
            for (r, o) in out[b.c0..b.c0 + 9].iter_mut().enumerate() {
                let acc: f64 = (0..9).map(|l| b.inv[9 * l + r] * yb[l]).sum();
                *o += c * acc;
            }
        }
    }

    /// The entry `(i, j)` of `M_W^-1`.
    pub(super) fn entry(&self, i: usize, j: usize) -> f64 {
        let (bi, li) = self.owner[i];
        let (bj, lj) = self.owner[j];
        if bi == usize::MAX || bj == usize::MAX {
            return if i == j { self.minv[i] } else { 0.0 };
        }
        if bi != bj {
            return 0.0;
        }
        self.blocks[bi].inv[9 * lj + li]
    }

    /// The coordinates that share a block of `M_W^-1` with coordinate `k` (itself included).
    pub(super) fn partners(&self, k: usize) -> std::ops::Range<usize> {
        match self.owner[k] {
            (usize::MAX, _) => k..k + 1,
            (b, _) => self.blocks[b].c0..self.blocks[b].c0 + 9,
        }
    }

    /// The multipliers of `M` from those of `M_W` for a solve whose constraint part is `c`:
    /// `mult -= W c_int` on the internal rows.
    pub(super) fn correct(&self, c: &[f64], mult: &mut [f64]) {
        for b in &self.blocks {
            for r in b.r0..b.r0 + 6 {
                mult[r] -= b.w * c[r];
            }
        }
    }

    /// `f(row, w)` for every internal row of a body block and its weight: the rows and
    /// weights of [`Augmented::penalty`].
    pub(super) fn for_each_penalty_row(&self, mut f: impl FnMut(usize, f64)) {
        for b in &self.blocks {
            for r in b.r0..b.r0 + 6 {
                f(r, b.w);
            }
        }
    }

    /// `c_int^T W c_int`: what `c^T S_W^-1 c` exceeds `c^T S^-1 c` by.
    pub(super) fn penalty(&self, c: &[f64]) -> f64 {
        self.blocks
            .iter()
            .map(|b| b.w * c[b.r0..b.r0 + 6].iter().map(|x| x * x).sum::<f64>())
            .sum()
    }

    /// Whether coordinate `k` is a director coordinate (in a block).
    pub(super) fn in_block(&self, k: usize) -> bool {
        self.owner[k].0 != usize::MAX
    }

    /// Adds `G_B M_W^-1 G_B^T` of every block `B` (its nine director columns of the
    /// column-major `m x n` matrix `gq`) into the lower triangle of `chol`; `rows` is scratch.
    pub(super) fn add_to_schur(
        &self,
        gq: &nalgebra::DMatrix<f64>,
        rows: &mut Vec<usize>,
        chol: &mut DenseCholesky,
    ) {
        let m = gq.nrows();
        let g = gq.as_slice();
        for b in &self.blocks {
            rows.clear();
            rows.extend((0..m).filter(|&r| (0..9).any(|l| g[(b.c0 + l) * m + r] != 0.0)));
            for (i, &r) in rows.iter().enumerate() {
                // y = G_rB M_W^-1 (the block is symmetric)
                let y: [f64; 9] = std::array::from_fn(|l| {
                    (0..9)
                        .map(|c| g[(b.c0 + c) * m + r] * b.inv[9 * l + c])
                        .sum()
                });
                for &r2 in &rows[..=i] {
                    let v: f64 = (0..9).map(|l| y[l] * g[(b.c0 + l) * m + r2]).sum();
                    // rows ascending: r >= r2, the lower triangle
                    chol.add(r, r2, v);
                }
            }
        }
    }

    /// A finite stand-in for `M^-1`'s diagonal (Gershgorin bounds): `M_W^-1`'s diagonal.
    pub(super) fn diagonal(&self, out: &mut [f64]) {
        for (k, o) in out.iter_mut().enumerate() {
            *o = self.entry(k, k);
        }
    }
}

/// The regularisation of a zero second moment in [`regularised_inverse`], relative to the
/// body's largest second moment.
pub(super) const MASSLESS_REGULARISATION: f64 = 1e-8;

/// A constant diagonal inverse mass for the s = 2 term (docs/spatial.md, "The s = 2 modified
/// Lagrangian"): `M^-1`, except on a director whose second moment is zero (a thin disc or
/// plate), which takes the moment `MASSLESS_REGULARISATION E_max`. Every term of `e4` has a
/// limit as that moment goes to zero (the KKT blocks stay regular), which the regularised value
/// meets to `O(MASSLESS_REGULARISATION)` relative, while the cancellation in `Pi = D - D G^T
/// S^-1 G D` costs about `eps / MASSLESS_REGULARISATION`: both near 1e-8.
pub(super) fn regularised_inverse(sys: &System, minv: &mut [f64]) {
    minv.copy_from_slice(sys.inv_mass_diag().as_slice());
    let q0 = sys.spatial_offset();
    for (k, b) in sys.spatial_bodies().iter().enumerate() {
        let e = b.inertia.second_moments();
        let e_max = e[0].max(e[1]).max(e[2]);
        for (i, &ei) in e.iter().enumerate() {
            if ei <= 0.0 || ei.is_nan() {
                let c = q0 + 12 * k + 3 + 3 * i;
                minv[c..c + 3].fill(1.0 / (MASSLESS_REGULARISATION * e_max));
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The regularisation is the one docs/spatial.md states; it replaces exactly the massless
    /// director's three entries of `M^-1` (the disc top: `E_3 = 0`, `E_max = 0.25`).
    #[test]
    fn the_regularised_inverse_touches_only_massless_directors() {
        let doc = include_str!("../../../../docs/spatial.md");
        let stated = format!("MASSLESS_REGULARISATION = {MASSLESS_REGULARISATION:e}");
        assert!(doc.contains(&stated), "docs/spatial.md lacks '{stated}'");
        let sys = mbd_model::models::heavy_top([0.25, 0.25, 0.5], 0.3, 20.0).unwrap();
        let mut minv = vec![0.0; sys.n_coords()];
        regularised_inverse(&sys, &mut minv);
        let plain = sys.inv_mass_diag();
        let d3 = sys.spatial_offset() + 9..sys.spatial_offset() + 12;
        for (i, (&a, &b)) in minv.iter().zip(plain.iter()).enumerate() {
            if d3.contains(&i) {
                assert!(!b.is_finite(), "{i}: {b}");
                assert_eq!(a, 1.0 / (MASSLESS_REGULARISATION * 0.25), "{i}");
            } else {
                assert_eq!(a, b, "{i}");
            }
        }
    }
}
