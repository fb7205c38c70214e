//! The workspace of the reverse pass of `e4` (`reverse.rs`): the adjoints of the intermediates
//! and of `G`.

use super::passes::{BasisR, Pass, NA, NB, NC, NR, R_OUTPUTS};
use crate::preadjust::{LocalRow, ZERO_ROW};
use mbd_model::System;

/// The element-local columns of a constraint row: the first coordinate of the joint's body a
/// (local columns 0..3) and of its body b (3..6), `None` for ground.
pub(super) type Cols = [Option<usize>; 2];

/// Adjoints (suffix `b`) of the intermediates, of the passes, of `G`, and scratch.
#[derive(Debug)]
pub(super) struct Adjoints {
    pub(super) ub: Vec<f64>,
    pub(super) nnb: Vec<f64>,
    pub(super) k2b: Vec<f64>,
    pub(super) k3b: Vec<f64>,
    pub(super) gradb: Vec<f64>,
    pub(super) hvb: Vec<f64>,
    pub(super) hub: Vec<f64>,
    pub(super) hnb: Vec<f64>,
    pub(super) hmu_vb: Vec<f64>,
    pub(super) hmu_ub: Vec<f64>,
    pub(super) hsig_vb: Vec<f64>,
    pub(super) hsig_ub: Vec<f64>,
    pub(super) mu0b: Vec<f64>,
    pub(super) sigb: Vec<f64>,
    pub(super) betab: Vec<f64>,
    pub(super) kap3b: Vec<f64>,
    pub(super) kap3ub: Vec<f64>,
    pub(super) kap4b: Vec<f64>,
    /// Adjoint weights of the coefficients of passes A, B, C per constraint row, and of
    /// passes A and B's potential.
    pub(super) wa: Vec<[f64; NA]>,
    pub(super) wb: Vec<[f64; NB]>,
    pub(super) wc: Vec<[f64; NC]>,
    pub(super) pa: [f64; NA],
    pub(super) pb: [f64; NB],
    /// Pass R (the weighted Hessian-vector products' adjoints): coefficients, gradients and
    /// contraction weights per row.
    pub(super) rpass: Pass<NR, BasisR>,
    pub(super) rw: Vec<[[f64; NR]; R_OUTPUTS]>,

    /// `Gb` in element-local form (planar rows).
    pub(super) gbar: Vec<LocalRow>,
    /// The spatial rows' share of `sum_r Hess Phi_r Gb_r` (length n), added as `Gb` grows.
    pub(super) sgq: Vec<f64>,
    /// Scratch: n-vectors and m-vectors.
    pub(super) tn: [Vec<f64>; 8],
    pub(super) tm: [Vec<f64>; 4],
}

impl Adjoints {
    pub(super) fn new(n: usize, m: usize) -> Self {
        let (zn, zm) = (|| vec![0.0; n], || vec![0.0; m]);
        Adjoints {
            ub: zn(),
            nnb: zn(),
            k2b: zn(),
            k3b: zn(),
            gradb: zn(),
            hvb: zn(),
            hub: zn(),
            hnb: zn(),
            hmu_vb: zn(),
            hmu_ub: zn(),
            hsig_vb: zn(),
            hsig_ub: zn(),
            mu0b: zm(),
            sigb: zm(),
            betab: zm(),
            kap3b: zm(),
            kap3ub: zm(),
            kap4b: zm(),
            wa: vec![[0.0; NA]; m],
            wb: vec![[0.0; NB]; m],
            wc: vec![[0.0; NC]; m],
            pa: [0.0; NA],
            pb: [0.0; NB],
            rpass: Pass::new(m, 0),
            rw: vec![[[0.0; NR]; R_OUTPUTS]; m],

            gbar: vec![ZERO_ROW; m],
            sgq: zn(),
            tn: std::array::from_fn(|_| zn()),
            tm: std::array::from_fn(|_| zm()),
        }
    }

    pub(super) fn clear(&mut self) {
        for x in [
            &mut self.ub,
            &mut self.nnb,
            &mut self.k2b,
            &mut self.k3b,
            &mut self.gradb,
            &mut self.hvb,
            &mut self.hub,
            &mut self.hnb,
            &mut self.hmu_vb,
            &mut self.hmu_ub,
            &mut self.hsig_vb,
            &mut self.hsig_ub,
            &mut self.mu0b,
            &mut self.sigb,
            &mut self.betab,
            &mut self.kap3b,
            &mut self.kap3ub,
            &mut self.kap4b,
        ] {
            x.fill(0.0);
        }
        self.wa.fill([0.0; NA]);
        self.wb.fill([0.0; NB]);
        self.wc.fill([0.0; NC]);
        self.pa = [0.0; NA];
        self.pb = [0.0; NB];
        self.gbar.fill(ZERO_ROW);
        self.sgq.fill(0.0);
    }
}

/// What `Gb += c alpha beta^T` needs: the planar rows' local columns, and for the spatial rows
/// (whose Hessians are constant in `q`) the model, `q` and the time (an angle driver's Hessian
/// turns with it) at which their share `sum_r c alpha_r Hess Phi_r beta` is applied at once.
#[derive(Clone, Copy)]
pub(super) struct GbCtx<'a> {
    sys: &'a System,
    q: &'a [f64],
    t: f64,
    cols: &'a [Cols],
    spatial: bool,
}

impl<'a> GbCtx<'a> {
    pub(super) fn new(sys: &'a System, q: &'a [f64], t: f64, cols: &'a [Cols]) -> Self {
        GbCtx {
            sys,
            q,
            t,
            cols,
            spatial: sys.has_spatial(),
        }
    }
}

/// `Gb += c alpha beta^T`: in element-local form on the planar rows; on the spatial rows its
/// contribution to `qb`, `c sum_r alpha_r Hess Phi_r beta`, into `sgq`.
pub(super) fn gbar_add(
    gbar: &mut [LocalRow],
    sgq: &mut [f64],
    cx: GbCtx,
    c: f64,
    al: &[f64],
    be: &[f64],
) {
    if cx.spatial {
        cx.sys
            .add_spatial_hessian_vector(cx.q, cx.t, be, al, c, sgq);
    }
    for ((g, cols), &a) in gbar.iter_mut().zip(cx.cols).zip(al) {
        if a == 0.0 {
            continue;
        }
        let ca = c * a;
        for (h, col) in cols.iter().enumerate() {
            if let Some(i) = *col {
                let b = &be[i..i + 3];
                for l in 0..3 {
                    g[3 * h + l] += ca * b[l];
                }
            }
        }
    }
}
