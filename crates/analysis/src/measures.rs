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
    /// Largest kinetic energy seen.
    pub max_kinetic: f64,
    /// Max position-constraint residual.
    pub e_phi: f64,
    /// Max velocity-constraint residual.
    pub e_phidot: f64,
    /// Max acceleration-constraint residual (NaN if accelerations were not evaluated).
    pub e_phiddot: f64,
}

impl RunMeasures {
    /// The energy scale of the run, `max(|H_0|, max_k T_k)`: `|H_0|` depends on the datum of the
    /// potential (zero for a pendulum released level with its pivot), the largest kinetic
    /// energy does not.
    pub fn energy_scale(&self) -> f64 {
        self.h0.abs().max(self.max_kinetic)
    }

    /// `max_k |H_k - H_0|` relative to [`RunMeasures::energy_scale`] (the absolute error where
    /// the scale is zero: a model at rest with `H_0 = 0`). Unlike paper C's `e_h`, it stays
    /// meaningful when `H_0` is near zero.
    pub fn e_h_scaled(&self) -> f64 {
        let scale = self.energy_scale();
        if scale > 0.0 {
            self.max_abs_dh / scale
        } else {
            self.max_abs_dh
        }
    }
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
        self.m.max_kinetic = self.m.max_kinetic.max(sys.kinetic(v));
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

#[cfg(test)]
mod tests {
    use super::*;
    use mbd_solve::{run, RunConfig};

    /// A pendulum released level with its pivot has `H_0 = 0` (the potential's datum at the
    /// pivot): paper C's `e_h` is then the absolute error, while `e_h_scaled` divides by the
    /// largest kinetic energy (`m g l / 2` at the bottom) and is of the order of the relative
    /// error of a pendulum released 1 rad from the vertical.
    #[test]
    fn the_scaled_energy_error_does_not_depend_on_the_potential_datum() {
        let mut scaled = Vec::new();
        for angle in [std::f64::consts::FRAC_PI_2, 1.0] {
            let sys = mbd_model::models::pendulum(1.0, 1.0, angle, 9.81).expect("model");
            let mut s = State::consistent(&sys, 0.0).expect("state");
            let mut integ = mbd_solve::Index1Rk::new(
                &sys,
                mbd_solve::ButcherTableau::rk4(),
                mbd_solve::Index1Options::default(),
            )
            .expect("solver");
            let mut obs = MeasureObserver::new(&sys, false);
            run(
                &mut integ,
                &sys,
                &mut s,
                RunConfig::new(1.0, 0.01),
                &mut obs,
            )
            .expect("run");
            let m = obs.measures();
            assert!(m.max_kinetic > 1.0 && m.max_abs_dh > 0.0, "{m:?}");
            assert_eq!(m.e_h_scaled(), m.max_abs_dh / m.energy_scale());
            if angle == std::f64::consts::FRAC_PI_2 {
                assert!(m.h0.abs() < 1e-12, "{m:?}");
                assert_eq!(m.e_h, m.max_abs_dh, "absolute where H0 = 0");
            }
            scaled.push(m.e_h_scaled());
        }
        // the same kind of swing: relative errors of one order of magnitude
        let r = scaled[0] / scaled[1];
        assert!((0.1..10.0).contains(&r), "{scaled:?}");
    }
}
