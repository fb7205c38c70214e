//! Helpers shared by the integration tests.
#![allow(dead_code)]

use mbd_model::System;
use mbd_solve::{Flow, Observer, SolveError, State};

/// `(||Phi||_inf, ||Phi_q v + Phi_t||_inf)` at a state.
pub fn residuals(sys: &System, s: &State, buf: &mut [Vec<f64>; 2]) -> (f64, f64) {
    let m = sys.n_constraints();
    buf[0].resize(m, 0.0);
    buf[1].resize(m, 0.0);
    sys.phi(s.q.as_slice(), s.t, &mut buf[0]);
    sys.phi_dot(s.q.as_slice(), s.v.as_slice(), s.t, &mut buf[1]);
    let inf = |x: &[f64]| x.iter().fold(0.0f64, |a, b| a.max(b.abs()));
    (inf(&buf[0]), inf(&buf[1]))
}

/// Tracks the largest position and velocity constraint residual over every sample.
#[derive(Default)]
pub struct ResidualWatch {
    pub max_phi: f64,
    pub max_phidot: f64,
    pub samples: usize,
    buf: [Vec<f64>; 2],
}

impl Observer for ResidualWatch {
    fn observe(&mut self, sys: &System, s: &State, _step: usize) -> Result<Flow, SolveError> {
        let (p, d) = residuals(sys, s, &mut self.buf);
        self.max_phi = self.max_phi.max(p);
        self.max_phidot = self.max_phidot.max(d);
        self.samples += 1;
        Ok(Flow::Continue)
    }
}

/// Max-norm difference of positions and velocities.
pub fn state_error(s: &State, q: &[f64], v: &[f64]) -> f64 {
    s.q.iter()
        .zip(q)
        .chain(s.v.iter().zip(v))
        .fold(0.0f64, |a, (x, y)| a.max((x - y).abs()))
}

/// Least-squares slope of `log(err)` against `log(h)`.
pub fn fitted_order(h: &[f64], err: &[f64]) -> f64 {
    let n = h.len() as f64;
    let xs: Vec<f64> = h.iter().map(|x| x.ln()).collect();
    let ys: Vec<f64> = err.iter().map(|x| x.ln()).collect();
    let mx = xs.iter().sum::<f64>() / n;
    let my = ys.iter().sum::<f64>() / n;
    let sxy: f64 = xs.iter().zip(&ys).map(|(x, y)| (x - mx) * (y - my)).sum();
    let sxx: f64 = xs.iter().map(|x| (x - mx) * (x - mx)).sum();
    sxy / sxx
}

/// A slider-crank as in `mbd_model::models::slider_crank` with crank length `r`, rod length `l`
/// and crank angle `th` (slider on the x-axis through the crank pivot), optionally with the
/// crank driven at `omega` rad/s (`theta = th + omega t`, no degree of freedom left).
pub fn slider_crank(r: f64, l: f64, th: f64, driven: Option<f64>) -> System {
    mbd_model::models::slider_crank_with(&mbd_model::models::SliderCrankParams {
        crank: r,
        rod: l,
        angle: th,
        speed: driven.unwrap_or(0.0),
        driven: driven.is_some(),
    })
    .expect("slider-crank")
}
