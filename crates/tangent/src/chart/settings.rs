//! Settings and outcomes of the chart maps: [`NewtonSettings`], chart failure, [`MapStats`].

use mbd_solve::SolveError;

/// Settings of the chord Newton iteration that maps chart coordinates to the manifold.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NewtonSettings {
    /// Converged when `||f(x(xi), t)||_inf <= tol` (position and velocity constraints), or
    /// when the residual stalls at the round-off floor of evaluating `f`: an iteration that
    /// leaves it at 0.9 of the previous value or more, below
    /// `max(10 tol, ROUNDOFF_FACTOR eps (1 + ||x||_inf))` (fast motion, or angles wound up over
    /// long runs, raise the floor of `Phi_q v` and `sin theta`).
    pub tol: f64,
    /// Iteration limit; reaching it is a chart failure.
    pub max_iter: usize,
    /// Divergence test: an iteration whose residual exceeds `divergence` times the previous one
    /// ends the iteration with a chart failure (the point has left the chart's domain).
    pub divergence: f64,
    /// Near-singular charts: a chord iteration that fails is retried by Newton's method with
    /// the exact matrix `Df(x) Q1` at every iterate (one `Df` and a `2m x 2m` LU per
    /// iteration) when `Df` at the starting point differs from `Df(x_c)` by at most
    /// `fallback_change` relative (`max |Df(x) - Df(x_c)| <= fallback_change max |Df(x_c)|`).
    /// Then the step is small for the geometry and the chord failed because `Df(x_c)` is
    /// nearly rank deficient (its smallest singular value is of the size of the change), as
    /// near a singular configuration: shorter steps would not help there. A larger change
    /// means the step is too large for the chart, which stays a chart failure (halving or
    /// rejection). Default 0.1; 0 turns the fallback off.
    pub fallback_change: f64,
}

impl Default for NewtonSettings {
    fn default() -> Self {
        NewtonSettings {
            tol: 1e-13,
            max_iter: 50,
            divergence: 2.0,
            fallback_change: 0.1,
        }
    }
}

impl NewtonSettings {
    /// Checks the settings: `tol` positive and finite, `max_iter >= 1`, `divergence >= 1`,
    /// `fallback_change` finite and non-negative.
    pub fn validate(&self) -> Result<(), SolveError> {
        if !(self.tol.is_finite() && self.tol > 0.0) {
            return Err(SolveError::InvalidParameter {
                parameter: "newton.tol",
                value: self.tol,
                reason: "must be positive and finite",
            });
        }
        if self.max_iter == 0 {
            return Err(SolveError::InvalidParameter {
                parameter: "newton.max_iter",
                value: 0.0,
                reason: "must be at least 1",
            });
        }
        if !(self.divergence.is_finite() && self.divergence >= 1.0) {
            return Err(SolveError::InvalidParameter {
                parameter: "newton.divergence",
                value: self.divergence,
                reason: "must be finite and at least 1",
            });
        }
        if !(self.fallback_change.is_finite() && self.fallback_change >= 0.0) {
            return Err(SolveError::InvalidParameter {
                parameter: "newton.fallback_change",
                value: self.fallback_change,
                reason: "must be finite and non-negative",
            });
        }
        Ok(())
    }
}

/// The chord Newton iteration of a chart map did not converge: the point `xi` lies outside the
/// chart's domain (step too large, or a singular configuration near).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ChartFailure {
    /// Time at which the map was evaluated.
    pub t: f64,
    /// `||f||_inf` when the iteration stopped (may be NaN or infinite).
    pub residual: f64,
    /// Iterations done.
    pub iterations: usize,
}

impl ChartFailure {
    /// The failure as a [`SolveError::Newton`] with context `"tangent chart"`.
    pub fn into_error(self) -> SolveError {
        SolveError::Newton {
            t: self.t,
            residual: self.residual,
            iterations: self.iterations,
            context: "tangent chart (chord Newton on f(x(xi)) = 0)".into(),
        }
    }
}

/// What a successful chart map did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MapStats {
    /// Chord Newton iterations.
    pub iterations: usize,
    /// Final `||f||_inf`; for a map that stopped on the predicted residual
    /// ([`TangentChart::map_predicted`](crate::TangentChart::map_predicted)), that prediction.
    pub residual: f64,
    /// `||f||_inf` at the starting point, before the first iteration.
    pub initial_residual: f64,
    /// Whether the chord iteration failed and Newton's method with the exact matrix took over
    /// ([`NewtonSettings::fallback_change`]); `iterations` then counts both.
    pub exact: bool,
}
