//! The `s = 2` modified-Lagrangian term `e4` as a type ([`ModifiedS2`]: its workspace, the
//! forward evaluation in `modified2.rs`, the gradients in `modified2_grad.rs`) and the adjoints'
//! workspace.

use super::metric::ProjectedMetric;
use super::modified2::{E4Forward, Pass};
use super::modified2_grad::BasisR;
use mbd_model::System;

/// The element-local columns of a constraint row: the first coordinate of the joint's body a
/// (local columns 0..3) and of its body b (3..6), `None` for ground.
pub(super) type Cols = [Option<usize>; 2];

/// The term `e4` and the workspace of its value and gradients: the forward intermediates, the
/// adjoints and the element-local columns of the constraint rows.
#[derive(Debug)]
pub(crate) struct ModifiedS2 {
    pub(super) f: E4Forward,
    pub(super) b: Adjoints,
    /// The element-local columns of each constraint row ([`Cols`]).
    pub(super) cols: Vec<Cols>,
}

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
    pub(super) wa: Vec<[f64; 8]>,
    pub(super) wb: Vec<[f64; 9]>,
    pub(super) wc: Vec<[f64; 6]>,
    pub(super) pa: [f64; 8],
    pub(super) pb: [f64; 9],
    /// Pass R (the weighted Hessian-vector products' adjoints): coefficients, gradients and
    /// contraction weights per row.
    pub(super) rpass: Pass<11, BasisR>,
    pub(super) rw: Vec<[[f64; 11]; 3]>,

    /// `Gb` in element-local form.
    pub(super) gbar: Vec<[f64; 6]>,
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
            wa: vec![[0.0; 8]; m],
            wb: vec![[0.0; 9]; m],
            wc: vec![[0.0; 6]; m],
            pa: [0.0; 8],
            pb: [0.0; 9],
            rpass: Pass::new(m, 0),
            rw: vec![[[0.0; 11]; 3]; m],

            gbar: vec![[0.0; 6]; m],
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
        self.wa.fill([0.0; 8]);
        self.wb.fill([0.0; 9]);
        self.wc.fill([0.0; 6]);
        self.pa = [0.0; 8];
        self.pb = [0.0; 9];
        self.gbar.fill([0.0; 6]);
    }
}

/// `Gb += c alpha beta^T` in element-local form.
pub(super) fn gbar_add(gbar: &mut [[f64; 6]], cols: &[Cols], c: f64, al: &[f64], be: &[f64]) {
    for ((g, cols), &a) in gbar.iter_mut().zip(cols).zip(al) {
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

impl ModifiedS2 {
    fn new(sys: &System) -> Self {
        let (n, m) = (sys.n_coords(), sys.n_constraints());
        let mut w = ModifiedS2 {
            f: E4Forward::new(n, m, sys.forces().len()),
            b: Adjoints::new(n, m),
            cols: vec![[None; 2]; m],
        };
        w.set_cols(sys);
        w
    }

    /// The element-local columns of every constraint row of `sys` (in place: the workspace
    /// follows the system it is used with, not only the one it was made for).
    fn set_cols(&mut self, sys: &System) {
        for (r, c) in self.cols.iter_mut().enumerate() {
            let (a, b) = sys
                .equation_joint(r)
                .map_or((None, None), |j| sys.joint_bodies(j));
            *c = [a.map(|i| 3 * i), b.map(|i| 3 * i)];
        }
    }
}

/// The `e4` workspace in `slot` for `sys` and `metric` (allocated on first use, or again when
/// the system's sizes changed; the constraint rows' columns follow `sys`).
pub(super) fn ensure_s2<'a>(
    slot: &'a mut Option<Box<ModifiedS2>>,
    metric: &ProjectedMetric,
    sys: &System,
) -> &'a mut ModifiedS2 {
    let fits = slot.as_ref().is_some_and(|w| {
        w.f.u.len() == metric.n()
            && w.cols.len() == metric.m()
            && w.f.pa.pgrads.len() == sys.forces().len()
    });
    if !fits {
        *slot = None;
    }
    let w = slot.get_or_insert_with(|| Box::new(ModifiedS2::new(sys)));
    if fits {
        w.set_cols(sys);
    }
    w
}
