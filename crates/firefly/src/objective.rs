//! Objective function traits.

/// A (possibly stateful) objective to minimise, evaluated serially.
///
/// Implemented for every `FnMut(&[f64]) -> f64`, so plain functions and
/// closures work directly. Closures usually need their argument type spelled
/// out to be accepted (`|x: &[f64]| ...`).
///
/// Returning NaN or an infinity is allowed: the point is treated as the worst
/// possible (brightness `+inf`) and counted in
/// [`FireflyResult::nan_evaluations`](crate::FireflyResult::nan_evaluations).
pub trait Objective {
    /// Value of the objective at `x` (`x.len()` equals the box dimension).
    fn eval(&mut self, x: &[f64]) -> f64;

    /// The dimension the objective expects, if it knows it. When `Some(d)`,
    /// the run checks it against the box and fails with
    /// [`FireflyError::ObjectiveDimension`](crate::FireflyError::ObjectiveDimension)
    /// on mismatch. Defaults to `None` (no check).
    fn dim(&self) -> Option<usize> {
        None
    }
}

impl<F> Objective for F
where
    F: FnMut(&[f64]) -> f64,
{
    fn eval(&mut self, x: &[f64]) -> f64 {
        self(x)
    }
}

/// An objective that can be evaluated from several threads at once (no
/// mutable state, or interior synchronisation), used by
/// [`Firefly::minimize_parallel`](crate::Firefly::minimize_parallel).
///
/// Implemented for every `Fn(&[f64]) -> f64 + Sync`. The value at a point
/// must not depend on which thread computes it or on evaluation order,
/// otherwise the parallel run cannot reproduce the serial one.
pub trait SyncObjective: Sync {
    /// Value of the objective at `x` (`x.len()` equals the box dimension).
    fn eval(&self, x: &[f64]) -> f64;

    /// The dimension the objective expects, if it knows it (see
    /// [`Objective::dim`]).
    fn dim(&self) -> Option<usize> {
        None
    }
}

impl<F> SyncObjective for F
where
    F: Fn(&[f64]) -> f64 + Sync,
{
    fn eval(&self, x: &[f64]) -> f64 {
        self(x)
    }
}
