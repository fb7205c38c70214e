//! The secant calibration of `gamma_opt` (paper A; `docs/symplectic.md` section 6): the root of
//! the calibration target `dW(gamma) = E[dx] + E[dy]` of runs against a reference.
//!
//! The measure itself (running the scheme and comparing with a reference) is the caller's:
//! paper A's averaged errors are `mbd_analysis::trajectory_errors` (its `d_w`), and the solver
//! crate does not depend on the analysis crate. A run through `mbd_solve::run` with an
//! `mbd_solve::Recorder`, then `trajectory_errors` against the reference, is the usual measure:
//!
//! ```
//! use mbd_symplectic::{calibrate_gamma, CalibrationSettings};
//! // a stand-in measure with its root at gamma = 0.8 (a real one runs the scheme)
//! let c = calibrate_gamma(CalibrationSettings::default(), |g| Ok((0.5 * (g - 0.8), ())))?;
//! assert!((c.gamma_opt - 0.8).abs() < 1e-12);
//! # Ok::<(), mbd_symplectic::SymplecticError>(())
//! ```

use crate::error::SymplecticError;
use mbd_solve::SolveError;

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

/// The result of [`calibrate_gamma`]; `M` is what the caller's measure returns beside `dW`.
#[derive(Clone, Debug, PartialEq)]
pub struct Calibration<M> {
    /// The calibrated parameter: the root of `dW(gamma)`.
    pub gamma_opt: f64,
    /// Every `(gamma, dW(gamma))` evaluated, in order (the first two are paper A's `dW_1`,
    /// `dW_2`).
    pub history: Vec<(f64, f64)>,
    /// Secant iterations after the two starting evaluations.
    pub iterations: usize,
    /// The measure's output for `gamma_opt`.
    pub measures: M,
}

/// Calibrates `gamma_opt`: the secant method on `dW(gamma)`, from `settings.start` (paper A:
/// `gamma = 0` and `gamma_T = 1`). `measure(gamma)` returns `dW(gamma)` and whatever the caller
/// wants kept for the best run (e.g. its full error measures). Fails with
/// [`SymplecticError::Calibration`] (with the history) if the secant stalls or does not
/// converge, and passes on the measure's errors.
pub fn calibrate_gamma<M>(
    settings: CalibrationSettings,
    mut measure: impl FnMut(f64) -> Result<(f64, M), SymplecticError>,
) -> Result<Calibration<M>, SymplecticError> {
    let mut history: Vec<(f64, f64)> = Vec::new();
    let mut eval = |g: f64, history: &mut Vec<(f64, f64)>| -> Result<(f64, M), SymplecticError> {
        let (dw, m) = measure(g)?;
        history.push((g, dw));
        Ok((dw, m))
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
    let mut d0 = eval(g0, &mut history)?.0;
    let (mut d1, mut best) = eval(g1, &mut history)?;
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
        let (d2, e2) = eval(g2, &mut history)?;
        g0 = g1;
        d0 = d1;
        g1 = g2;
        d1 = d2;
        best = e2;
        if (g1 - g0).abs() <= settings.tol * (1.0 + g1.abs()) || d1.abs() <= settings.dw_tol {
            return Ok(Calibration {
                gamma_opt: g1,
                history,
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
