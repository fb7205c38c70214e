//! The jet passes of `e4`: their monomial bases ([`mbd_model::Basis`]) and the workspace of a
//! pass ([`Pass`]: its coefficients per constraint row and of the potential, with their
//! element-local gradients).

use mbd_model::{Basis, BodyAngles, PolyWorkspace, System, MAX_DIRS};

/// The monomial bases of the passes of `e4` ([`mbd_model::PolyJet`]; `t` stands for the
/// velocity `v` throughout). Pass A, directions `(v, u)`: `{1, t, e, t^2, e t, t^3, e t^2,
/// t^4}`.
#[derive(Clone, Copy, Debug)]
pub(super) struct BasisA;
impl Basis<8> for BasisA {
    const ND: usize = 2;
    const EXP: [[u8; MAX_DIRS]; 8] = [
        [0, 0, 0, 0, 0, 0],
        [1, 0, 0, 0, 0, 0],
        [0, 1, 0, 0, 0, 0],
        [2, 0, 0, 0, 0, 0],
        [1, 1, 0, 0, 0, 0],
        [3, 0, 0, 0, 0, 0],
        [2, 1, 0, 0, 0, 0],
        [4, 0, 0, 0, 0, 0],
    ];
}
/// Pass A's monomials `t`, `e` (= `u`), `t^2`, `e t`, `t^3`, `e t^2`, `t^4`.
pub(super) const A_T: usize = 1;
pub(super) const A_E: usize = 2;
pub(super) const A_TT: usize = 3;
pub(super) const A_ET: usize = 4;
pub(super) const A_TTT: usize = 5;
pub(super) const A_ETT: usize = 6;
pub(super) const A_T4: usize = 7;

/// Pass B, directions `(v, n, u)`: `{1, t, e, d, t^2, e t, e^2, e d, e t^2}` (`e` for `n`,
/// `d` for `u`).
#[derive(Clone, Copy, Debug)]
pub(super) struct BasisB;
impl Basis<9> for BasisB {
    const ND: usize = 3;
    const EXP: [[u8; MAX_DIRS]; 9] = [
        [0, 0, 0, 0, 0, 0],
        [1, 0, 0, 0, 0, 0],
        [0, 1, 0, 0, 0, 0],
        [0, 0, 1, 0, 0, 0],
        [2, 0, 0, 0, 0, 0],
        [1, 1, 0, 0, 0, 0],
        [0, 2, 0, 0, 0, 0],
        [0, 1, 1, 0, 0, 0],
        [2, 1, 0, 0, 0, 0],
    ];
}
/// Pass B's monomials `e` (= `n`), `e t`, `e^2`, `e d` (`d` = `u`), `e t^2`.
pub(super) const B_E: usize = 2;
pub(super) const B_ET: usize = 5;
pub(super) const B_EE: usize = 6;
pub(super) const B_ED: usize = 7;
pub(super) const B_ETT: usize = 8;

/// Pass C, directions `(v, K2, K3)`: `{1, t, a, b, a t, b t}`.
#[derive(Clone, Copy, Debug)]
pub(super) struct BasisC;
impl Basis<6> for BasisC {
    const ND: usize = 3;
    const EXP: [[u8; MAX_DIRS]; 6] = [
        [0, 0, 0, 0, 0, 0],
        [1, 0, 0, 0, 0, 0],
        [0, 1, 0, 0, 0, 0],
        [0, 0, 1, 0, 0, 0],
        [1, 1, 0, 0, 0, 0],
        [1, 0, 1, 0, 0, 0],
    ];
}
/// Pass C's monomials `a t` (`a` = `K2`) and `b t` (`b` = `K3`).
pub(super) const C_AT: usize = 4;
pub(super) const C_BT: usize = 5;

/// One pass's coefficients per constraint row and of the potential, with their element-local
/// gradients (per row, and per force element), and its jets' workspace.
#[derive(Debug)]
pub(super) struct Pass<const K: usize, B> {
    pub(super) vals: Vec<[f64; K]>,
    pub(super) grads: Vec<[[f64; 6]; K]>,
    pub(super) pot: [f64; K],
    pub(super) pgrads: Vec<[[f64; 6]; K]>,
    ws: Box<PolyWorkspace<K, B>>,
}

impl<const K: usize, B: Basis<K>> Pass<K, B> {
    pub(super) fn new(m: usize, nf: usize) -> Self {
        Pass {
            vals: vec![[0.0; K]; m],
            grads: vec![[[0.0; 6]; K]; m],
            pot: [0.0; K],
            pgrads: vec![[[0.0; 6]; K]; nf],
            ws: PolyWorkspace::new(),
        }
    }

    /// The pass along `dirs` at `q` (constraints and potential).
    pub(super) fn eval(&mut self, sys: &System, q: &[f64], a: &BodyAngles, dirs: &[&[f64]]) {
        let ws = &mut self.ws;
        sys.constraint_poly_series(ws, q, a, dirs, &mut self.vals, &mut self.grads);
        self.pot = sys.potential_poly_series(ws, q, a, dirs, &mut self.pgrads);
    }

    /// The pass along `dirs` at `q`, constraints only.
    pub(super) fn eval_constraints(
        &mut self,
        sys: &System,
        q: &[f64],
        a: &BodyAngles,
        dirs: &[&[f64]],
    ) {
        sys.constraint_poly_series(&mut self.ws, q, a, dirs, &mut self.vals, &mut self.grads);
    }

    /// `out = sum_f grad_q` of the potential's coefficient `k` (length n; zero without force
    /// elements): a Hessian-vector product of `V` for a coefficient of degree 1.
    pub(super) fn pot_grad_into(&self, sys: &System, k: usize, out: &mut [f64]) {
        out.fill(0.0);
        let mut w = [0.0; K];
        w[k] = 1.0;
        sys.add_potential_poly_adjoint::<K, B>(&self.pgrads, &w, out, &mut []);
    }
}

/// Pass R's basis, directions `(v, u, y1, y2, y3, y4)` with the adjoints `y1 = (H_sigma
/// v)b`, `y2 = (H_mu v)b`, `y3 = (H_sigma u)b`, `y4 = (H_mu u)b`: `{1, t, e, y1, y2, y3, y4,
/// t y1, t y2, e y3, e y4}` (`t` for `v`, `e` for `u`).
#[derive(Clone, Copy, Debug)]
pub(super) struct BasisR;
impl Basis<11> for BasisR {
    const ND: usize = 6;
    const EXP: [[u8; MAX_DIRS]; 11] = [
        [0, 0, 0, 0, 0, 0],
        [1, 0, 0, 0, 0, 0],
        [0, 1, 0, 0, 0, 0],
        [0, 0, 1, 0, 0, 0],
        [0, 0, 0, 1, 0, 0],
        [0, 0, 0, 0, 1, 0],
        [0, 0, 0, 0, 0, 1],
        [1, 0, 1, 0, 0, 0],
        [1, 0, 0, 1, 0, 0],
        [0, 1, 0, 0, 1, 0],
        [0, 1, 0, 0, 0, 1],
    ];
}
/// Pass R's monomials `y1 .. y4`, then `t y1`, `t y2`, `e y3`, `e y4`.
pub(super) const R_Y: [usize; 4] = [3, 4, 5, 6];
pub(super) const R_XY: [usize; 4] = [7, 8, 9, 10];
