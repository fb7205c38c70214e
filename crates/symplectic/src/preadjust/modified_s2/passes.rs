//! The jet passes of `e4`: their monomial bases ([`mbd_model::Basis`]) and the workspace of a
//! pass ([`Pass`]: its coefficients per constraint row and of the potential, with their
//! element-local gradients).
//!
//! A basis is a list of monomials in the pass's directions (infinitesimals), each given by its
//! exponents; `t` stands for the velocity `v` throughout. Its size, its number of directions
//! and the positions of the monomials the term reads are derived from the list.

use super::spatial::{SpatialRowSet, SpatialRows};
use super::spatial_potential::SpatialPotential;
use crate::passes;
use crate::passes::PolyWorkspace;
use crate::preadjust::{LocalRow, ZERO_ROW};
use mbd_model::{Basis, BodyAngles, System, MAX_DIRS};

/// A monomial by its exponents in the first directions of a pass (the others zero).
const fn mono<const D: usize>(e: [u8; D]) -> [u8; MAX_DIRS] {
    let mut out = [0; MAX_DIRS];
    let mut j = 0;
    while j < D {
        out[j] = e[j];
        j += 1;
    }
    out
}

/// The monomials `list` as a basis table of `K` entries (`K` must be `list.len()`).
const fn table<const K: usize>(list: &[[u8; MAX_DIRS]]) -> [[u8; MAX_DIRS]; K] {
    assert!(list.len() == K);
    let mut out = [[0; MAX_DIRS]; K];
    let mut k = 0;
    while k < K {
        out[k] = list[k];
        k += 1;
    }
    out
}

/// The number of directions `list` uses (one past the last with a nonzero exponent).
const fn directions(list: &[[u8; MAX_DIRS]]) -> usize {
    let mut nd = 0;
    let mut k = 0;
    while k < list.len() {
        let mut j = 0;
        while j < MAX_DIRS {
            if list[k][j] != 0 && j + 1 > nd {
                nd = j + 1;
            }
            j += 1;
        }
        k += 1;
    }
    nd
}

/// The position of the monomial `e` in `list` (a compile-time error if it is not there).
const fn position(list: &[[u8; MAX_DIRS]], e: [u8; MAX_DIRS]) -> usize {
    let mut k = 0;
    while k < list.len() {
        let mut j = 0;
        while j < MAX_DIRS && list[k][j] == e[j] {
            j += 1;
        }
        if j == MAX_DIRS {
            return k;
        }
        k += 1;
    }
    panic!("monomial not in the basis")
}

/// Pass A, directions `(v, u)` (`t`, `e`): `1, t, e, t^2, e t, t^3, e t^2, t^4`.
const A_LIST: &[[u8; MAX_DIRS]] = &[
    mono([0, 0]),
    mono([1, 0]),
    mono([0, 1]),
    mono([2, 0]),
    mono([1, 1]),
    mono([3, 0]),
    mono([2, 1]),
    mono([4, 0]),
];
/// The size of pass A's basis.
pub(super) const NA: usize = A_LIST.len();
/// Pass A's basis ([`A_LIST`]).
#[derive(Clone, Copy, Debug)]
pub(super) struct BasisA;
impl Basis<NA> for BasisA {
    const ND: usize = directions(A_LIST);
    const EXP: [[u8; MAX_DIRS]; NA] = table(A_LIST);
}
/// Pass A's monomials `t`, `e` (= `u`), `t^2`, `e t`, `t^3`, `e t^2`, `t^4`.
pub(super) const A_T: usize = position(A_LIST, mono([1, 0]));
pub(super) const A_E: usize = position(A_LIST, mono([0, 1]));
pub(super) const A_TT: usize = position(A_LIST, mono([2, 0]));
pub(super) const A_ET: usize = position(A_LIST, mono([1, 1]));
pub(super) const A_TTT: usize = position(A_LIST, mono([3, 0]));
pub(super) const A_ETT: usize = position(A_LIST, mono([2, 1]));
pub(super) const A_T4: usize = position(A_LIST, mono([4, 0]));

/// Pass B, directions `(v, n, u)` (`t`, `e`, `d`): `1, t, e, d, t^2, e t, e^2, e d, e t^2`.
const B_LIST: &[[u8; MAX_DIRS]] = &[
    mono([0, 0, 0]),
    mono([1, 0, 0]),
    mono([0, 1, 0]),
    mono([0, 0, 1]),
    mono([2, 0, 0]),
    mono([1, 1, 0]),
    mono([0, 2, 0]),
    mono([0, 1, 1]),
    mono([2, 1, 0]),
];
/// The size of pass B's basis.
pub(super) const NB: usize = B_LIST.len();
/// Pass B's basis ([`B_LIST`]).
#[derive(Clone, Copy, Debug)]
pub(super) struct BasisB;
impl Basis<NB> for BasisB {
    const ND: usize = directions(B_LIST);
    const EXP: [[u8; MAX_DIRS]; NB] = table(B_LIST);
}
/// Pass B's monomials `e` (= `n`), `e t`, `e^2`, `e d` (`d` = `u`), `e t^2`.
pub(super) const B_E: usize = position(B_LIST, mono([0, 1]));
pub(super) const B_ET: usize = position(B_LIST, mono([1, 1]));
pub(super) const B_EE: usize = position(B_LIST, mono([0, 2]));
pub(super) const B_ED: usize = position(B_LIST, mono([0, 1, 1]));
pub(super) const B_ETT: usize = position(B_LIST, mono([2, 1]));

/// Pass C, directions `(v, K2, K3)` (`t`, `a`, `b`): `1, t, a, b, a t, b t`.
const C_LIST: &[[u8; MAX_DIRS]] = &[
    mono([0, 0, 0]),
    mono([1, 0, 0]),
    mono([0, 1, 0]),
    mono([0, 0, 1]),
    mono([1, 1, 0]),
    mono([1, 0, 1]),
];
/// The size of pass C's basis.
pub(super) const NC: usize = C_LIST.len();
/// Pass C's basis ([`C_LIST`]).
#[derive(Clone, Copy, Debug)]
pub(super) struct BasisC;
impl Basis<NC> for BasisC {
    const ND: usize = directions(C_LIST);
    const EXP: [[u8; MAX_DIRS]; NC] = table(C_LIST);
}
/// Pass C's monomials `a t` (`a` = `K2`) and `b t` (`b` = `K3`).
pub(super) const C_AT: usize = position(C_LIST, mono([1, 1]));
pub(super) const C_BT: usize = position(C_LIST, mono([1, 0, 1]));

/// Pass R (the reverse pass's, `reverse.rs`), directions `(v, u, y1, y2, y3, y4)` (`t`, `e`,
/// `y1` .. `y4`) with the adjoints `y1 = (H_sigma v)b`, `y2 = (H_mu v)b`, `y3 = (H_sigma u)b`,
/// `y4 = (H_mu u)b`: `1, t, e, y1, y2, y3, y4, t y1, t y2, e y3, e y4`.
const R_LIST: &[[u8; MAX_DIRS]] = &[
    mono([0, 0, 0, 0, 0, 0]),
    mono([1, 0, 0, 0, 0, 0]),
    mono([0, 1, 0, 0, 0, 0]),
    mono([0, 0, 1, 0, 0, 0]),
    mono([0, 0, 0, 1, 0, 0]),
    mono([0, 0, 0, 0, 1, 0]),
    mono([0, 0, 0, 0, 0, 1]),
    mono([1, 0, 1, 0, 0, 0]),
    mono([1, 0, 0, 1, 0, 0]),
    mono([0, 1, 0, 0, 1, 0]),
    mono([0, 1, 0, 0, 0, 1]),
];
/// The size of pass R's basis and its number of directions.
pub(super) const NR: usize = R_LIST.len();
pub(super) const R_DIRS: usize = directions(R_LIST);
/// Pass R's basis ([`R_LIST`]).
#[derive(Clone, Copy, Debug)]
pub(super) struct BasisR;
impl Basis<NR> for BasisR {
    const ND: usize = R_DIRS;
    const EXP: [[u8; MAX_DIRS]; NR] = table(R_LIST);
}
/// The number of weighted Hessian-vector products pass R differentiates (`y1` .. `y4`).
pub(super) const R_PRODUCTS: usize = 4;
/// The gradients pass R's contraction adds to: with respect to `q`, `v` and `u`.
pub(super) const R_OUTPUTS: usize = 3;
/// Pass R's monomials `y1 .. y4`.
pub(super) const R_Y: [usize; R_PRODUCTS] = [
    position(R_LIST, mono([0, 0, 1])),
    position(R_LIST, mono([0, 0, 0, 1])),
    position(R_LIST, mono([0, 0, 0, 0, 1])),
    position(R_LIST, mono([0, 0, 0, 0, 0, 1])),
];
/// Pass R's monomials `t y1`, `t y2`, `e y3`, `e y4` (each product's `x yb`).
pub(super) const R_XY: [usize; R_PRODUCTS] = [
    position(R_LIST, mono([1, 0, 1])),
    position(R_LIST, mono([1, 0, 0, 1])),
    position(R_LIST, mono([0, 1, 0, 0, 1])),
    position(R_LIST, mono([0, 1, 0, 0, 0, 1])),
];

/// What the passes at one `q` share: the body angles' `sin`/`cos` and the spatial rows.
pub(super) type AtQ<'a> = (&'a BodyAngles, &'a SpatialRowSet);

/// One pass's coefficients per constraint row and of the potential, with their element-local
/// gradients (per planar row, and per force element; the spatial rows' in [`SpatialRows`]),
/// and its jets' workspace.
#[derive(Debug)]
pub(super) struct Pass<const K: usize, B> {
    pub(super) vals: Vec<[f64; K]>,
    pub(super) grads: Vec<[LocalRow; K]>,
    pub(super) pot: [f64; K],
    pub(super) pgrads: Vec<[LocalRow; K]>,
    /// The spatial rows (none on a planar model).
    pub(super) sp: SpatialRows,
    /// The spatial force elements with a potential (none on a planar model).
    pub(super) spp: SpatialPotential<K>,
    ws: Box<PolyWorkspace<K, B>>,
}

impl<const K: usize, B: Basis<K>> Pass<K, B> {
    pub(super) fn new(m: usize, nf: usize) -> Self {
        Pass {
            vals: vec![[0.0; K]; m],
            grads: vec![[ZERO_ROW; K]; m],
            pot: [0.0; K],
            pgrads: vec![[ZERO_ROW; K]; nf],
            sp: SpatialRows::default(),
            spp: SpatialPotential::default(),
            ws: PolyWorkspace::new(),
        }
    }

    /// The pass along `dirs` at `q` (constraints and potential), with the body angles and the
    /// spatial rows at `q`, shared by the passes (`at`).
    pub(super) fn eval(&mut self, sys: &System, q: &[f64], at: AtQ<'_>, dirs: &[&[f64]]) {
        let ws = &mut self.ws;
        let a = at.0;
        passes::constraint_poly_series(sys, ws, q, a, dirs, &mut self.vals, &mut self.grads);
        self.pot = passes::potential_poly_series(sys, ws, q, a, dirs, &mut self.pgrads);
        // (gravity, linear in q, enters through the metric's gradient of V alone)
        self.spp.eval::<B>(sys, q, dirs, &mut self.pot);
        self.eval_spatial(sys, at.1, dirs);
    }

    /// The spatial rows' coefficients and gradients.
    fn eval_spatial(&mut self, sys: &System, set: &SpatialRowSet, dirs: &[&[f64]]) {
        if sys.has_spatial() {
            self.sp.gather(dirs);
            self.sp.coefficients::<K, B>(set, dirs, &mut self.vals);
        }
    }

    /// The pass along `dirs` at `q`, constraints only.
    pub(super) fn eval_constraints(
        &mut self,
        sys: &System,
        q: &[f64],
        at: AtQ<'_>,
        dirs: &[&[f64]],
    ) {
        let a = at.0;
        passes::constraint_poly_series(
            sys,
            &mut self.ws,
            q,
            a,
            dirs,
            &mut self.vals,
            &mut self.grads,
        );
        self.eval_spatial(sys, at.1, dirs);
    }

    /// `out = sum_f grad_q` of the potential's coefficient `k` (length n; zero without force
    /// elements): a Hessian-vector product of `V` for a coefficient of degree 1.
    pub(super) fn pot_grad_into(&self, sys: &System, k: usize, out: &mut [f64]) {
        out.fill(0.0);
        let mut w = [0.0; K];
        w[k] = 1.0;
        passes::add_potential_poly_adjoint::<K, B>(sys, &self.pgrads, &w, out, &mut []);
        self.spp.adjoint::<B>(&w, out, &mut []);
    }
}
