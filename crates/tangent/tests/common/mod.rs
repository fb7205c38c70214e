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
    use mbd_model::{Body, BodyRef, Joint, SystemBuilder, TimeFunction};
    let a = [r * th.cos(), r * th.sin()];
    let xs = a[0] + (l * l - a[1] * a[1]).sqrt();
    let phi = (-a[1]).atan2(xs - a[0]);
    let mut b = SystemBuilder::new();
    b.set_gravity([0.0, -9.81]);
    let crank = b.add_body(
        Body::new("crank")
            .rod(1.0, r)
            .position(0.5 * a[0], 0.5 * a[1], th),
    );
    let rod = b.add_body(
        Body::new("rod")
            .rod(1.0, l)
            .position(0.5 * (a[0] + xs), 0.5 * a[1], phi),
    );
    let slider = b.add_body(
        Body::new("slider")
            .mass(0.5)
            .inertia(0.01)
            .position(xs, 0.0, 0.0),
    );
    b.add_joint(Joint::revolute(
        "o",
        BodyRef::Ground,
        [0.0, 0.0],
        crank,
        [-0.5 * r, 0.0],
    ));
    b.add_joint(Joint::revolute(
        "a",
        crank,
        [0.5 * r, 0.0],
        rod,
        [-0.5 * l, 0.0],
    ));
    b.add_joint(Joint::revolute(
        "b",
        rod,
        [0.5 * l, 0.0],
        slider,
        [0.0, 0.0],
    ));
    b.add_joint(Joint::prismatic(
        "s",
        BodyRef::Ground,
        [0.0, 0.0],
        slider,
        [0.0, 0.0],
        [1.0, 0.0],
        0.0,
    ));
    if let Some(omega) = driven {
        b.add_joint(Joint::angle_driver(
            "d",
            BodyRef::Ground,
            crank,
            TimeFunction::linear(th, omega),
        ));
    }
    b.build().expect("slider-crank")
}
