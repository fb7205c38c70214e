#![allow(dead_code)]
use mbd_model::System;
use mbd_solve::{Integrator, State};
use mbd_symplectic::{Galerkin, SymplecticOptions};

pub mod reduced;

/// Least-squares slope of log(err) against log(h).
pub fn slope(h: &[f64], e: &[f64]) -> f64 {
    let x: Vec<f64> = h.iter().map(|v| v.ln()).collect();
    let y: Vec<f64> = e.iter().map(|v| v.ln()).collect();
    let n = x.len() as f64;
    let mx = x.iter().sum::<f64>() / n;
    let my = y.iter().sum::<f64>() / n;
    let sxy: f64 = x.iter().zip(&y).map(|(a, b)| (a - mx) * (b - my)).sum();
    let sxx: f64 = x.iter().map(|a| (a - mx) * (a - mx)).sum();
    sxy / sxx
}

/// Options with Newton converged to round-off (for measurements near the floor).
pub fn tight(s: usize) -> SymplecticOptions {
    let mut o = SymplecticOptions::new(s);
    o.newton.tol = 1e-17;
    o
}

/// Runs `n` steps of `h`; returns the final state and max |H - H0| over the run.
pub fn run(sys: &System, s0: &State, opts: SymplecticOptions, h: f64, n: usize) -> (State, f64) {
    let mut g = Galerkin::new(sys, opts).unwrap();
    let mut st = s0.clone();
    let h0 = sys.energy(st.q.as_slice(), st.v.as_slice());
    let mut eh: f64 = 0.0;
    for k in 1..=n {
        g.step(sys, &mut st, h).unwrap();
        st.t = s0.t + k as f64 * h;
        eh = eh.max((sys.energy(st.q.as_slice(), st.v.as_slice()) - h0).abs());
    }
    (st, eh)
}

pub fn max_abs_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

// (shared with the crate's unit tests, which include the file)
include!("damped.rs");

/// Relative period error of the scheme `opts` on the uniform rod pendulum (1 kg, 1 m,
/// g = 9.81) released at rest `theta0` from the downward vertical: crossings of
/// `psi = theta + pi/2` through 0, each located by the polynomial through `points` samples
/// around it, the period as twice the least-squares slope of the crossing times over about
/// `periods` periods (`mbd_analysis::period`), against the exact (AGM) period.
pub fn rod_period_error(
    theta0: f64,
    h: f64,
    opts: SymplecticOptions,
    periods: f64,
    points: usize,
) -> f64 {
    use mbd_analysis::period;
    let (l, g) = (1.0, 9.81);
    let sys = mbd_model::models::pendulum(1.0, l, theta0, g).unwrap();
    let te = period::pendulum_period((1.5 * g / l).sqrt(), theta0).unwrap();
    let mut st = State::consistent(&sys, 0.0).unwrap();
    let mut sch = Galerkin::new(&sys, opts).unwrap();
    let n = (periods * te / h).ceil() as usize + 4;
    let mut psi = Vec::with_capacity(n + 1);
    psi.push(st.q[2] + std::f64::consts::FRAC_PI_2);
    for _ in 0..n {
        sch.step(&sys, &mut st, h).unwrap();
        psi.push(st.q[2] + std::f64::consts::FRAC_PI_2);
    }
    period::oscillation_period(&psi, 0.0, h, points).unwrap() / te - 1.0
}
