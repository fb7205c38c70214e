//! Energy and constraint measures (paper C's e(H), MRE(H), e(Phi), e(Phidot), e(Phiddot)),
//! accumulated online.

use crate::error::AnalysisError;
use mbd_model::System;
use mbd_solve::linalg::max_abs;
use mbd_solve::{AccelerationSolver, Flow, Observer, SolveError, State};
use serde::Serialize;

/// Energy and constraint errors of a run.
///
/// * `e_h = max_k |H_k - H_0| / |H_0|`, `mre_h = mean_k |H_k - H_0| / |H_0|`
/// * `e_phi = max_k ||Phi(q_k, t_k)||_inf`, `e_phidot = max_k ||Phi_q v_k + Phi_t||_inf`,
///   `e_phiddot = max_k ||Phi_q a_k - gamma_k||_inf` with `a_k` from the index-1 solve at
///   `(q_k, v_k)`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct RunMeasures {
    /// Samples seen.
    pub samples: usize,
    /// Initial energy.
    pub h0: f64,
    /// Max relative energy error.
    pub e_h: f64,
    /// Mean relative energy error.
    pub mre_h: f64,
    /// Max absolute energy error.
    pub max_abs_dh: f64,
    /// Max position-constraint residual.
    pub e_phi: f64,
    /// Max velocity-constraint residual.
    pub e_phidot: f64,
    /// Max acceleration-constraint residual (NaN if accelerations were not evaluated).
    pub e_phiddot: f64,
}

/// An [`Observer`] that accumulates [`RunMeasures`] without storing the trajectory.
#[derive(Debug)]
pub struct MeasureObserver {
    m: RunMeasures,
    sum_rel: f64,
    phi: Vec<f64>,
    acc: Option<AccelWorkspace>,
    /// Optional per-sample record `(t, |H - H0|/|H0|, ||Phi||, ||Phidot||)` for figures.
    pub series: Option<Vec<[f64; 4]>>,
}

/// Index-1 solver with buffers for `a`, `lambda` and the residual.
type AccelWorkspace = (AccelerationSolver, Vec<f64>, Vec<f64>, Vec<f64>);

impl MeasureObserver {
    /// Accumulates energy and position/velocity constraint errors; with `accelerations`, also the
    /// acceleration-level residual (one index-1 solve per sample).
    pub fn new(sys: &System, accelerations: bool) -> Self {
        let (n, m) = (sys.n_coords(), sys.n_constraints());
        MeasureObserver {
            m: RunMeasures {
                e_phiddot: if accelerations { 0.0 } else { f64::NAN },
                ..Default::default()
            },
            sum_rel: 0.0,
            phi: vec![0.0; m],
            acc: accelerations.then(|| {
                (
                    AccelerationSolver::new(sys),
                    vec![0.0; n],
                    vec![0.0; m],
                    vec![0.0; m],
                )
            }),
            series: None,
        }
    }
    /// Also keep the per-sample series (for plots).
    pub fn with_series(mut self) -> Self {
        self.series = Some(Vec::new());
        self
    }
    /// Adds one sample.
    pub fn add(&mut self, sys: &System, s: &State) -> Result<(), SolveError> {
        let (q, v) = (s.q.as_slice(), s.v.as_slice());
        let h = sys.energy(q, v);
        if self.m.samples == 0 {
            self.m.h0 = h;
        }
        let dh = (h - self.m.h0).abs();
        let rel = if self.m.h0 != 0.0 {
            dh / self.m.h0.abs()
        } else {
            dh
        };
        self.m.samples += 1;
        self.m.e_h = self.m.e_h.max(rel);
        self.m.max_abs_dh = self.m.max_abs_dh.max(dh);
        self.sum_rel += rel;
        self.m.mre_h = self.sum_rel / self.m.samples as f64;
        sys.phi(q, s.t, &mut self.phi);
        let ep = max_abs(&self.phi);
        self.m.e_phi = self.m.e_phi.max(ep);
        sys.phi_dot(q, v, s.t, &mut self.phi);
        let ev = max_abs(&self.phi);
        self.m.e_phidot = self.m.e_phidot.max(ev);
        if let Some((acc, a, lambda, r)) = &mut self.acc {
            acc.solve(sys, q, v, s.t, a, lambda)?;
            // residual Phi_q a - gamma with the Jacobian and gamma of that solve
            for (k, rk) in r.iter_mut().enumerate() {
                let mut x = -acc.gamma[k];
                for (i, ai) in a.iter().enumerate() {
                    x += acc.phi_q[(k, i)] * ai;
                }
                *rk = x;
            }
            self.m.e_phiddot = self.m.e_phiddot.max(max_abs(r));
        }
        if let Some(sr) = &mut self.series {
            sr.push([s.t, rel, ep, ev]);
        }
        Ok(())
    }
    /// The measures so far.
    pub fn measures(&self) -> RunMeasures {
        self.m
    }
}

impl Observer for MeasureObserver {
    fn observe(&mut self, sys: &System, state: &State, _step: usize) -> Result<Flow, SolveError> {
        self.add(sys, state)?;
        Ok(Flow::Continue)
    }
}

/// [`RunMeasures`] of a stored trajectory.
pub fn measure_trajectory(
    sys: &System,
    traj: &crate::Trajectory,
    accelerations: bool,
) -> Result<RunMeasures, AnalysisError> {
    traj.check(sys)?;
    let mut obs = MeasureObserver::new(sys, accelerations);
    for k in 0..traj.len() {
        let s = traj.state(k);
        obs.add(sys, &s)?;
    }
    Ok(obs.measures())
}
