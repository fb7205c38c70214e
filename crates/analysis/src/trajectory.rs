//! Stored trajectories, interpolation of a reference at other times, and paper A's trajectory
//! error measures.

use crate::error::AnalysisError;
use mbd_model::System;
use mbd_solve::{Recorder, ReferenceTrajectory, State};
use nalgebra::DVector;
use serde::Serialize;

/// Samples `(t_k, q_k, v_k)` of a run, times strictly increasing.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Trajectory {
    /// Times.
    pub t: Vec<f64>,
    /// Positions.
    pub q: Vec<Vec<f64>>,
    /// Velocities.
    pub v: Vec<Vec<f64>>,
}

impl From<Recorder> for Trajectory {
    fn from(r: Recorder) -> Self {
        Trajectory {
            t: r.t,
            q: r.q,
            v: r.v,
        }
    }
}

impl From<ReferenceTrajectory> for Trajectory {
    fn from(r: ReferenceTrajectory) -> Self {
        Trajectory {
            t: r.t,
            q: r.q,
            v: r.v,
        }
    }
}

impl Trajectory {
    /// Number of samples.
    pub fn len(&self) -> usize {
        self.t.len()
    }
    /// Whether empty.
    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }
    /// Sample `k` as a [`State`].
    pub fn state(&self, k: usize) -> State {
        State {
            t: self.t[k],
            q: DVector::from_column_slice(&self.q[k]),
            v: DVector::from_column_slice(&self.v[k]),
        }
    }
    /// Checks sizes against `sys` and that times increase.
    pub fn check(&self, sys: &System) -> Result<(), AnalysisError> {
        let n = sys.n_coords();
        if self.q.len() != self.t.len() || self.v.len() != self.t.len() {
            return Err(AnalysisError::Dimension {
                what: "trajectory samples",
                expected: self.t.len(),
                got: self.q.len().min(self.v.len()),
            });
        }
        for (q, v) in self.q.iter().zip(&self.v) {
            if q.len() != n || v.len() != n {
                return Err(AnalysisError::Dimension {
                    what: "trajectory state",
                    expected: n,
                    got: q.len().min(v.len()),
                });
            }
        }
        if self.t.windows(2).any(|w| !(w[1] > w[0])) {
            return Err(AnalysisError::InvalidValue {
                what: "trajectory times",
                value: f64::NAN,
                reason: "must be strictly increasing",
            });
        }
        Ok(())
    }

    /// Positions and velocities at time `t` by interpolation: positions by cubic Hermite (using
    /// the stored velocities as derivatives), velocities by 4-point Lagrange interpolation; both
    /// are fourth-order accurate in the sample spacing. `t` must lie within the samples.
    pub fn interpolate(
        &self,
        t: f64,
        q_out: &mut [f64],
        v_out: &mut [f64],
    ) -> Result<(), AnalysisError> {
        let n = self.t.len();
        if n == 0 {
            return Err(AnalysisError::TooFewPoints {
                what: "reference trajectory",
                need: 1,
                got: 0,
            });
        }
        let (t0, t1) = (self.t[0], self.t[n - 1]);
        let tol = 1e-12 * (1.0 + t1.abs());
        if !(t >= t0 - tol && t <= t1 + tol) {
            return Err(AnalysisError::OutOfRange { t, t0, t1 });
        }
        let dim = self.q[0].len();
        if q_out.len() != dim || v_out.len() != dim {
            return Err(AnalysisError::Dimension {
                what: "interpolation output",
                expected: dim,
                got: q_out.len(),
            });
        }
        if n == 1 {
            q_out.copy_from_slice(&self.q[0]);
            v_out.copy_from_slice(&self.v[0]);
            return Ok(());
        }
        // interval index i with t_i <= t <= t_{i+1}
        let i = match self
            .t
            .binary_search_by(|x| x.partial_cmp(&t).unwrap_or(std::cmp::Ordering::Less))
        {
            Ok(i) => {
                q_out.copy_from_slice(&self.q[i]);
                v_out.copy_from_slice(&self.v[i]);
                return Ok(());
            }
            Err(i) => i.clamp(1, n - 1) - 1,
        };
        let (ta, tb) = (self.t[i], self.t[i + 1]);
        let h = tb - ta;
        let s = (t - ta) / h;
        let h00 = (1.0 + 2.0 * s) * (1.0 - s) * (1.0 - s);
        let h10 = s * (1.0 - s) * (1.0 - s);
        let h01 = s * s * (3.0 - 2.0 * s);
        let h11 = s * s * (s - 1.0);
        for d in 0..dim {
            q_out[d] = h00 * self.q[i][d]
                + h10 * h * self.v[i][d]
                + h01 * self.q[i + 1][d]
                + h11 * h * self.v[i + 1][d];
        }
        // velocities: Lagrange through up to 4 nodes around the interval
        let lo = i.saturating_sub(1).min(n.saturating_sub(4));
        let hi = (lo + 4).min(n);
        for d in 0..dim {
            let mut acc = 0.0;
            for j in lo..hi {
                let mut w = 1.0;
                for k in lo..hi {
                    if k != j {
                        w *= (t - self.t[k]) / (self.t[j] - self.t[k]);
                    }
                }
                acc += w * self.v[j][d];
            }
            v_out[d] = acc;
        }
        Ok(())
    }
}

/// Paper A's trajectory error measures: means over moving bodies `i` and samples `k` of the
/// centre-of-mass errors, and energy errors over samples (`d_w` is the calibration target of
/// `docs/symplectic.md` section 6).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct TrajectoryErrors {
    /// `E|dx| = mean_{i,k} |x_i^k - x_i,ref^k|`.
    pub e_abs_dx: f64,
    /// `E|dy|`.
    pub e_abs_dy: f64,
    /// `E|dH| = mean_k |H_k - H_0|`.
    pub e_abs_dh: f64,
    /// `E[dx]` (signed).
    pub e_dx: f64,
    /// `E[dy]` (signed).
    pub e_dy: f64,
    /// `E[dH]` (signed, `mean_k (H_k - H_0)`).
    pub e_dh: f64,
    /// `dW = E[dx] + E[dy]` (paper A's calibration target).
    pub d_w: f64,
    /// Largest position error `max_{k} ||q_k - q_ref||_inf`.
    pub max_q_err: f64,
    /// Samples compared.
    pub samples: usize,
}

/// Compares a trajectory with a reference sampled at (possibly) other times; the reference is
/// interpolated at the trajectory's times ([`Trajectory::interpolate`]).
pub fn trajectory_errors(
    sys: &System,
    traj: &Trajectory,
    reference: &Trajectory,
) -> Result<TrajectoryErrors, AnalysisError> {
    traj.check(sys)?;
    reference.check(sys)?;
    if traj.is_empty() {
        return Err(AnalysisError::TooFewPoints {
            what: "trajectory",
            need: 1,
            got: 0,
        });
    }
    let n = sys.n_coords();
    let nb = n / 3;
    let mut qr = vec![0.0; n];
    let mut vr = vec![0.0; n];
    let h0 = sys.energy(&traj.q[0], &traj.v[0]);
    let mut e = TrajectoryErrors::default();
    for k in 0..traj.len() {
        reference.interpolate(traj.t[k], &mut qr, &mut vr)?;
        let q = &traj.q[k];
        for b in 0..nb {
            let dx = q[3 * b] - qr[3 * b];
            let dy = q[3 * b + 1] - qr[3 * b + 1];
            e.e_abs_dx += dx.abs();
            e.e_abs_dy += dy.abs();
            e.e_dx += dx;
            e.e_dy += dy;
        }
        for d in 0..n {
            e.max_q_err = e.max_q_err.max((q[d] - qr[d]).abs());
        }
        let dh = sys.energy(q, &traj.v[k]) - h0;
        e.e_abs_dh += dh.abs();
        e.e_dh += dh;
    }
    let (kf, bf) = (traj.len() as f64, (traj.len() * nb) as f64);
    e.e_abs_dx /= bf;
    e.e_abs_dy /= bf;
    e.e_dx /= bf;
    e.e_dy /= bf;
    e.e_abs_dh /= kf;
    e.e_dh /= kf;
    e.d_w = e.e_dx + e.e_dy;
    e.samples = traj.len();
    Ok(e)
}

/// Max-norm difference of positions at time `t` between a state and a reference trajectory.
pub fn position_error_at(
    state_q: &[f64],
    t: f64,
    reference: &Trajectory,
) -> Result<f64, AnalysisError> {
    let n = state_q.len();
    let mut qr = vec![0.0; n];
    let mut vr = vec![0.0; n];
    reference.interpolate(t, &mut qr, &mut vr)?;
    Ok(state_q
        .iter()
        .zip(&qr)
        .fold(0.0f64, |a, (x, y)| a.max((x - y).abs())))
}
