//! The state every integrator advances.

use crate::error::SolveError;
use mbd_model::System;
use nalgebra::DVector;

/// Time, positions and velocities of a system.
#[derive(Clone, Debug, PartialEq)]
pub struct State {
    /// Time.
    pub t: f64,
    /// Positions (length `n`).
    pub q: DVector<f64>,
    /// Velocities (length `n`).
    pub v: DVector<f64>,
}

impl State {
    /// A state from parts (checked against the system's size).
    pub fn new(
        sys: &System,
        t: f64,
        q: DVector<f64>,
        v: DVector<f64>,
    ) -> Result<State, SolveError> {
        let n = sys.n_coords();
        if q.len() != n {
            return Err(SolveError::Dimension {
                what: "q",
                expected: n,
                got: q.len(),
            });
        }
        if v.len() != n {
            return Err(SolveError::Dimension {
                what: "v",
                expected: n,
                got: v.len(),
            });
        }
        if !t.is_finite() || q.iter().chain(v.iter()).any(|x| !x.is_finite()) {
            return Err(SolveError::NonFinite {
                t,
                what: "initial state",
            });
        }
        Ok(State { t, q, v })
    }

    /// The consistent initial state of the system's stored guess at time `t0` (projected onto
    /// the position and velocity constraints).
    pub fn consistent(sys: &System, t0: f64) -> Result<State, SolveError> {
        let c = crate::consistent::consistent_state(sys, t0)?;
        Ok(State {
            t: t0,
            q: c.q,
            v: c.v,
        })
    }

    /// Checks the lengths against a system.
    pub fn check(&self, sys: &System) -> Result<(), SolveError> {
        let n = sys.n_coords();
        if self.q.len() != n {
            return Err(SolveError::Dimension {
                what: "state.q",
                expected: n,
                got: self.q.len(),
            });
        }
        if self.v.len() != n {
            return Err(SolveError::Dimension {
                what: "state.v",
                expected: n,
                got: self.v.len(),
            });
        }
        Ok(())
    }

    /// Whether every entry is finite.
    // `x - x` on purpose: 0 for finite x, NaN otherwise
    #[allow(clippy::eq_op)]
    pub fn is_finite(&self) -> bool {
        // x - x is 0 for finite x and NaN for an infinity or NaN, so the sum is 0 exactly when
        // every entry is finite: one branch-free pass instead of a test per entry
        let sum = |xs: &[f64]| xs.iter().fold(0.0f64, |acc, &x| acc + (x - x));
        self.t.is_finite() && sum(self.q.as_slice()) + sum(self.v.as_slice()) == 0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use mbd_model::models;

    #[test]
    fn is_finite_catches_every_non_finite_entry() {
        let sys = models::manipulator().expect("model");
        let s = State::consistent(&sys, 0.0).expect("state");
        assert!(s.is_finite());
        let mut big = s.clone();
        big.q[0] = f64::MAX;
        big.v[1] = -f64::MAX;
        assert!(big.is_finite());
        for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            for i in 0..s.q.len() {
                let mut a = s.clone();
                a.q[i] = bad;
                assert!(!a.is_finite(), "q[{i}] = {bad}");
                let mut b = s.clone();
                b.v[i] = bad;
                assert!(!b.is_finite(), "v[{i}] = {bad}");
            }
            let mut c = s.clone();
            c.t = bad;
            assert!(!c.is_finite());
        }
    }
}
