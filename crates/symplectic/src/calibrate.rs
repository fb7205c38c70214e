//! Paper A's error measures and the secant calibration of `gamma_opt` (methods.md 2.3-2.4).

use crate::error::SymplecticError;
use crate::galerkin::Galerkin;
use crate::options::SymplecticOptions;
use mbd_model::System;
use mbd_solve::{Integrator, ReferenceTrajectory, SolveError, State};

/// Paper A's averaged errors of one run against a reference (means over all bodies and all
/// samples `k = 0..=N`, the initial state included as in the paper's eqs. 38-39).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ErrorMeasures {
    /// `E|dx|`: mean of `|x_i - x_i,ref|` (centres of mass).
    pub mean_abs_dx: f64,
    /// `E|dy|`.
    pub mean_abs_dy: f64,
    /// `E|dH|`: mean of `|H_k - H_0|`.
    pub mean_abs_dh: f64,
    /// `E[dx]`: signed mean of `x_i - x_i,ref`.
    pub mean_dx: f64,
    /// `E[dy]`.
    pub mean_dy: f64,
    /// `E[dH]`: signed mean of `H_k - H_0`.
    pub mean_dh: f64,
    /// `max_k |H_k - H_0|`.
    pub max_abs_dh: f64,
    /// `max_k ||Phi(q_k, t_k)||_inf`.
    pub max_phi: f64,
    /// `max_k ||Phi_q v_k + Phi_t||_inf`.
    pub max_phi_dot: f64,
    /// Steps run.
    pub steps: usize,
}

impl ErrorMeasures {
    /// `dW = E[dx] + E[dy]`, the calibration target.
    pub fn dw(&self) -> f64 {
        self.mean_dx + self.mean_dy
    }
}

fn check_reference(
    reference: &ReferenceTrajectory,
    state0: &State,
    h: f64,
    n_steps: usize,
    n: usize,
) -> Result<(), SymplecticError> {
    let bad = |detail: String| SymplecticError::Reference {
        method: reference.method.clone(),
        detail,
    };
    if reference.q.len() < n_steps + 1 || reference.t.len() < n_steps + 1 {
        return Err(bad(format!(
            "{} samples, the run needs {} (n_steps + 1)",
            reference.q.len(),
            n_steps + 1
        )));
    }
    for k in [0, n_steps / 2, n_steps] {
        let tk = state0.t + k as f64 * h;
        if (reference.t[k] - tk).abs() > 1e-9 * (1.0 + tk.abs()) {
            return Err(bad(format!(
                "sample {k} is at t = {}, the run is at t = {tk} (h = {h})",
                reference.t[k]
            )));
        }
        if reference.q[k].len() != n {
            return Err(bad(format!(
                "sample {k} has {} coordinates, the model {n}",
                reference.q[k].len()
            )));
        }
    }
    Ok(())
}

/// Runs the scheme from `state0` for `n_steps` steps of `h` and measures paper A's errors
/// against `reference` (sampled every `h`, e.g. from [`mbd_solve::reference_trajectory`]).
pub fn error_measures(
    sys: &System,
    state0: &State,
    h: f64,
    n_steps: usize,
    reference: &ReferenceTrajectory,
    options: &SymplecticOptions,
) -> Result<ErrorMeasures, SymplecticError> {
    if !(h.is_finite() && h > 0.0) {
        return Err(SolveError::InvalidStep { h }.into());
    }
    state0.check(sys)?;
    let n = sys.n_coords();
    check_reference(reference, state0, h, n_steps, n)?;
    let mut scheme = Galerkin::new(sys, *options)?;
    let mut st = state0.clone();
    let nb = n / 3;
    let h0 = sys.energy(st.q.as_slice(), st.v.as_slice());
    let mut out = ErrorMeasures {
        steps: n_steps,
        ..Default::default()
    };
    let mut phi = vec![0.0; sys.n_constraints()];
    for k in 0..=n_steps {
        if k > 0 {
            scheme.step(sys, &mut st, h)?;
            st.t = state0.t + k as f64 * h;
        }
        let qr = &reference.q[k];
        for i in 0..nb {
            let dx = st.q[3 * i] - qr[3 * i];
            let dy = st.q[3 * i + 1] - qr[3 * i + 1];
            out.mean_abs_dx += dx.abs();
            out.mean_abs_dy += dy.abs();
            out.mean_dx += dx;
            out.mean_dy += dy;
        }
        let dh = sys.energy(st.q.as_slice(), st.v.as_slice()) - h0;
        out.mean_abs_dh += dh.abs();
        out.mean_dh += dh;
        out.max_abs_dh = out.max_abs_dh.max(dh.abs());
        sys.phi(st.q.as_slice(), st.t, &mut phi);
        out.max_phi = phi.iter().fold(out.max_phi, |a, &b| a.max(b.abs()));
        sys.phi_dot(st.q.as_slice(), st.v.as_slice(), st.t, &mut phi);
        out.max_phi_dot = phi.iter().fold(out.max_phi_dot, |a, &b| a.max(b.abs()));
    }
    let cnt = (n_steps + 1) as f64;
    let cb = cnt * nb.max(1) as f64;
    out.mean_abs_dx /= cb;
    out.mean_abs_dy /= cb;
    out.mean_dx /= cb;
    out.mean_dy /= cb;
    out.mean_abs_dh /= cnt;
    out.mean_dh /= cnt;
    Ok(out)
}

/// Settings of [`calibrate_gamma`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CalibrationSettings {
    /// The two starting values of the secant iteration (paper: `0` and `gamma_T = 1`).
    pub start: (f64, f64),
    /// Converged when `|gamma_{k+1} - gamma_k| <= tol (1 + |gamma_{k+1}|)`.
    pub tol: f64,
    /// Secant iterations allowed (after the two starting evaluations).
    pub max_iter: usize,
    /// Also converged when `|dW| <= dw_tol`: the round-off floor of the signed means (default
    /// 1e-14, for coordinates of order 1 m); below it the secant would only chase noise.
    pub dw_tol: f64,
}

impl Default for CalibrationSettings {
    fn default() -> Self {
        CalibrationSettings {
            start: (0.0, 1.0),
            tol: 1e-9,
            max_iter: 30,
            dw_tol: 1e-14,
        }
    }
}

/// The result of [`calibrate_gamma`].
#[derive(Clone, Debug, PartialEq)]
pub struct Calibration {
    /// The calibrated parameter: the root of `dW(gamma)`.
    pub gamma_opt: f64,
    /// Every `(gamma, dW(gamma))` evaluated, in order (the first two are paper A's `dW_1`,
    /// `dW_2`).
    pub history: Vec<(f64, f64)>,
    /// The reference trajectory's method (e.g. "DOPRI5 + projection, h/32").
    pub reference_method: String,
    /// Secant iterations after the two starting evaluations.
    pub iterations: usize,
    /// Error measures of the run with `gamma_opt`.
    pub measures: ErrorMeasures,
}

/// Calibrates `gamma_opt` for the scheme `options` (its `gamma` is ignored) on `sys` from
/// `state0` with `n_steps` steps of `h`: the secant method on
/// `dW(gamma) = E[dx] + E[dy]` against `reference`, from `gamma = 0` and `gamma_T = 1`.
/// Fails with [`SymplecticError::Calibration`] (with the history) if the secant stalls or does
/// not converge, and passes on integration errors.
pub fn calibrate_gamma(
    sys: &System,
    state0: &State,
    h: f64,
    n_steps: usize,
    reference: &ReferenceTrajectory,
    options: &SymplecticOptions,
    settings: CalibrationSettings,
) -> Result<Calibration, SymplecticError> {
    let mut history: Vec<(f64, f64)> = Vec::new();
    let eval = |g: f64, history: &mut Vec<(f64, f64)>| -> Result<ErrorMeasures, SymplecticError> {
        let mut o = *options;
        o.gamma = g;
        let e = error_measures(sys, state0, h, n_steps, reference, &o)?;
        history.push((g, e.dw()));
        Ok(e)
    };
    let (mut g0, mut g1) = settings.start;
    if !(g0.is_finite() && g1.is_finite()) || g0 == g1 {
        return Err(SolveError::InvalidParameter {
            parameter: "calibration start",
            value: g1,
            reason: "the two starting gammas must be finite and different",
        }
        .into());
    }
    let mut d0 = eval(g0, &mut history)?.dw();
    let e1 = eval(g1, &mut history)?;
    let mut d1 = e1.dw();
    let mut best = e1;
    let fail = |it: usize, g: f64, reason: String, history: &Vec<(f64, f64)>| {
        SymplecticError::Calibration {
            iterations: it,
            gamma: g,
            reason,
            history: history.clone(),
        }
    };
    for it in 1..=settings.max_iter {
        if d1.abs() <= settings.dw_tol {
            return Ok(Calibration {
                gamma_opt: g1,
                history,
                reference_method: reference.method.clone(),
                iterations: it - 1,
                measures: best,
            });
        }
        if d1 == d0 || !(d1.is_finite() && d0.is_finite()) {
            return Err(fail(
                it,
                g1,
                "dW did not change between the last two gammas (flat or non-finite)".into(),
                &history,
            ));
        }
        let g2 = g1 - d1 * (g1 - g0) / (d1 - d0);
        if !g2.is_finite() {
            return Err(fail(it, g1, "secant update is not finite".into(), &history));
        }
        let e2 = eval(g2, &mut history)?;
        g0 = g1;
        d0 = d1;
        g1 = g2;
        d1 = e2.dw();
        best = e2;
        if (g1 - g0).abs() <= settings.tol * (1.0 + g1.abs()) || d1.abs() <= settings.dw_tol {
            return Ok(Calibration {
                gamma_opt: g1,
                history,
                reference_method: reference.method.clone(),
                iterations: it,
                measures: best,
            });
        }
    }
    Err(fail(
        settings.max_iter,
        g1,
        format!("no convergence in {} secant iterations", settings.max_iter),
        &history,
    ))
}
