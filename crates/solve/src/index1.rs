//! Explicit Runge-Kutta on the index-1 form `q' = v, v' = a(q, v, t)`, for any tableau, with
//! optional Baumgarte stabilisation and post-step projection. It is the engine of the RK4
//! baseline (`mbd-rk4`) and, with a high-order tableau and a small step plus projection, an
//! independent reference solver for the other methods.

use crate::accel::Accel;
use crate::adaptive::{AdaptiveIntegrator, StepAttempt};
use crate::bridge::SingularBridge;
use crate::error::SolveError;
use crate::integrator::{Integrator, StepStats};
use crate::projection::{ProjectionSettings, Projector};
use crate::sparse::LinearSolver;
use crate::state::State;
use crate::tableau::{ButcherTableau, ExplicitRk, StepController};
use mbd_model::System;

/// Settings of [`Index1Rk`].
#[derive(Clone, Debug, PartialEq)]
pub struct Index1Options {
    /// Baumgarte parameters `(alpha, beta)`: the acceleration constraint becomes
    /// `Phi_q a = gamma - 2 alpha Phidot - beta^2 Phi`. `None` (default) = off.
    pub baumgarte: Option<(f64, f64)>,
    /// Project `(q, v)` onto the constraints after every step (default off).
    pub projection: Option<ProjectionSettings>,
    /// Dense or sparse index-1 solve and projection (default: sparse above
    /// [`crate::SPARSE_THRESHOLD`] constraints).
    pub linear: LinearSolver,
    /// Bridge the stage accelerations through singular configurations
    /// ([`crate::SingularBridge`]; default on). Off, a stage near a singular configuration
    /// takes the solve's accelerations as they are.
    pub bridge: bool,
}

impl Default for Index1Options {
    fn default() -> Self {
        Index1Options {
            baumgarte: None,
            projection: None,
            linear: LinearSolver::default(),
            bridge: true,
        }
    }
}

/// Explicit RK on the index-1 equations, allocation-free per step.
#[derive(Debug)]
pub struct Index1Rk {
    rk: ExplicitRk,
    acc: Accel,
    projector: Option<Projector>,
    options: Index1Options,
    y: Vec<f64>,
    /// Stage of the last acceleration evaluated (its slope `k_i = (v_i, a_i)` holds it).
    last: usize,
    lambda: Vec<f64>,
    phi: Vec<f64>,
    phid: Vec<f64>,
    /// Start of an adaptive attempt (restored on rejection).
    y0: Vec<f64>,
    n: usize,
    /// The accelerations of the last step starts, for stages near a singular configuration.
    bridge: SingularBridge,
}

impl Index1Rk {
    /// A solver for `sys` with the given tableau and options.
    pub fn new(
        sys: &System,
        tableau: ButcherTableau,
        options: Index1Options,
    ) -> Result<Self, SolveError> {
        if let Some((a, b)) = options.baumgarte {
            if !(a.is_finite() && b.is_finite() && a >= 0.0 && b >= 0.0) {
                return Err(SolveError::InvalidParameter {
                    parameter: "baumgarte (alpha, beta)",
                    value: if a.is_finite() && a >= 0.0 { b } else { a },
                    reason: "must be non-negative and finite",
                });
            }
        }
        if let Some(p) = &options.projection {
            if !(p.tol > 0.0 && p.tol.is_finite()) {
                return Err(SolveError::InvalidParameter {
                    parameter: "projection.tol",
                    value: p.tol,
                    reason: "must be positive and finite",
                });
            }
        }
        let (n, m) = (sys.n_coords(), sys.n_constraints());
        Ok(Index1Rk {
            rk: ExplicitRk::new(tableau, 2 * n)?,
            acc: Accel::new(sys, options.linear)?,
            projector: match options.projection {
                Some(p) => Some(Projector::with_linear(sys, p, options.linear)?),
                None => None,
            },
            options,
            y: vec![0.0; 2 * n],
            last: 0,
            lambda: vec![0.0; m],
            phi: vec![0.0; m],
            phid: vec![0.0; m],
            y0: vec![0.0; 2 * n],
            n,
            bridge: SingularBridge::new(sys),
        })
    }

    /// The tableau.
    pub fn tableau(&self) -> &ButcherTableau {
        &self.rk.tableau
    }

    /// The options.
    pub fn options(&self) -> &Index1Options {
        &self.options
    }

    /// The accelerations and multipliers of the last right-hand-side evaluation.
    pub fn last_acceleration(&self) -> (&[f64], &[f64]) {
        (&self.rk.slope(self.last)[self.n..], &self.lambda)
    }
}

impl Integrator for Index1Rk {
    fn name(&self) -> String {
        let mut s = self.rk.tableau.name.to_string();
        if let Some((a, b)) = self.options.baumgarte {
            s += &format!(" + Baumgarte({a}, {b})");
        }
        if self.options.projection.is_some() {
            s += " + projection";
        }
        s
    }

    fn order(&self) -> Option<u32> {
        Some(self.rk.tableau.order)
    }

    fn keeps_constraints(&self) -> bool {
        self.options.projection.is_some()
    }

    fn as_adaptive(&mut self) -> Option<&mut dyn AdaptiveIntegrator> {
        if self.embedded_order().is_some() {
            Some(self)
        } else {
            None
        }
    }

    fn step(&mut self, sys: &System, state: &mut State, h: f64) -> Result<StepStats, SolveError> {
        state.check(sys)?;
        if !(h.is_finite() && h > 0.0) {
            return Err(SolveError::InvalidStep { h });
        }
        let n = self.n;
        self.y[..n].copy_from_slice(state.q.as_slice());
        self.y[n..].copy_from_slice(state.v.as_slice());
        let acc = &mut self.acc;
        let (lambda, phi, phid) = (&mut self.lambda, &mut self.phi, &mut self.phid);
        let baum = self.options.baumgarte;
        let mut evals = 0usize;
        let mut condition = 0.0f64;
        let mut bridged = 0usize;
        let mut bridge = self.options.bridge.then_some(&mut self.bridge);
        if let Some(b) = bridge.as_deref_mut() {
            b.begin(state.t, state.q.as_slice());
        }
        // the stage slope k_i = (v_i, a_i): the accelerations are solved into it directly;
        // near a singular configuration the bridge replaces their ill-determined components
        let mut f = |t: f64, y: &[f64], dy: &mut [f64]| -> Result<(), SolveError> {
            let (q, v) = y.split_at(n);
            let (dq, dv) = dy.split_at_mut(n);
            acc.stage(sys, q, v, t, baum, phi, phid, dv, lambda)?;
            let c = acc.condition();
            condition = condition.max(c);
            if let Some(b) = bridge.as_deref_mut() {
                if b.correct(acc.rows(), sys, t, c, dv, lambda) {
                    bridged += 1;
                }
                if evals == 0 {
                    b.hold(t, c, dv);
                }
            }
            dq.copy_from_slice(v);
            evals += 1;
            Ok(())
        };
        let stepped = self.rk.step(&mut f, state.t, &mut self.y, h);
        self.last = evals.saturating_sub(1);
        stepped?;
        state.q.as_mut_slice().copy_from_slice(&self.y[..n]);
        state.v.as_mut_slice().copy_from_slice(&self.y[n..]);
        state.t += h;
        let mut stats = StepStats {
            rhs_evals: evals,
            condition,
            bridged_stages: bridged,
            ..Default::default()
        };
        if let Some(p) = &mut self.projector {
            let s = p.project(sys, state.q.as_mut_slice(), state.v.as_mut_slice(), state.t)?;
            stats.newton_iterations = s.iterations;
            stats.residual = s.residual;
        }
        self.bridge.accept(state.t, state.q.as_slice());
        Ok(stats)
    }
}

/// Adaptive steps with the tableau's embedded estimate (DOPRI5, Bogacki-Shampine, Heun-Euler)
/// through [`crate::run_adaptive`]. The error norm is the RMS over the `2n` components of
/// `(q, v)` of `err_i / (atol + rtol max(|y0_i|, |y1_i|))`, taken before any projection; a
/// rejected attempt restores the start state.
impl AdaptiveIntegrator for Index1Rk {
    fn embedded_order(&self) -> Option<u32> {
        self.rk.tableau.error_estimate_order()
    }

    fn attempt_step(
        &mut self,
        sys: &System,
        state: &mut State,
        h: f64,
        ctrl: &StepController,
    ) -> Result<StepAttempt, SolveError> {
        state.check(sys)?;
        if self.embedded_order().is_none() {
            return Err(SolveError::Unsupported(format!(
                "'{}' has no embedded error estimate",
                self.rk.tableau.name
            )));
        }
        let n = self.n;
        let t = state.t;
        self.y0[..n].copy_from_slice(state.q.as_slice());
        self.y0[n..].copy_from_slice(state.v.as_slice());
        let stats = self.step(sys, state, h)?;
        // `self.y` holds the RK end point (before projection)
        let mut sum = 0.0;
        for i in 0..2 * n {
            let sc = ctrl.atol + ctrl.rtol * self.y0[i].abs().max(self.y[i].abs());
            sum += (self.rk.err[i] / sc).powi(2);
        }
        let error_norm = (sum / (2 * n).max(1) as f64).sqrt();
        let accepted = error_norm <= 1.0;
        if !accepted {
            state.q.as_mut_slice().copy_from_slice(&self.y0[..n]);
            state.v.as_mut_slice().copy_from_slice(&self.y0[n..]);
            state.t = t;
            // the retry starts where the rejected attempt did
            self.bridge.retry_from(t, state.q.as_slice());
        }
        Ok(StepAttempt {
            accepted,
            error_norm,
            stats,
            shrink: None,
        })
    }
}

/// Samples of a reference solution on a uniform grid.
#[derive(Clone, Debug)]
pub struct ReferenceTrajectory {
    /// What produced it, e.g. "DOPRI5 + projection, h/64".
    pub method: String,
    /// Sample times.
    pub t: Vec<f64>,
    /// Positions at the sample times.
    pub q: Vec<Vec<f64>>,
    /// Velocities at the sample times.
    pub v: Vec<Vec<f64>>,
}

/// Integrates `state0` with `tableau` on the index-1 form with projection after every step, at
/// step `h / substeps`, and samples positions and velocities every `h` for `n_steps` steps
/// (`n_steps + 1` samples including the initial state). With DOPRI5 and `substeps` of 16 or
/// more it is an accurate reference independent of the method being checked.
pub fn reference_trajectory(
    sys: &System,
    state0: &State,
    h: f64,
    n_steps: usize,
    substeps: usize,
    tableau: ButcherTableau,
) -> Result<ReferenceTrajectory, SolveError> {
    if substeps == 0 {
        return Err(SolveError::InvalidParameter {
            parameter: "substeps",
            value: 0.0,
            reason: "must be at least 1",
        });
    }
    if !(h.is_finite() && h > 0.0) {
        return Err(SolveError::InvalidStep { h });
    }
    let name = format!("{} + projection, h/{}", tableau.name, substeps);
    let mut rk = Index1Rk::new(
        sys,
        tableau,
        Index1Options {
            baumgarte: None,
            projection: Some(ProjectionSettings::default()),
            ..Default::default()
        },
    )?;
    let mut s = state0.clone();
    let mut out = ReferenceTrajectory {
        method: name,
        t: Vec::with_capacity(n_steps + 1),
        q: Vec::with_capacity(n_steps + 1),
        v: Vec::with_capacity(n_steps + 1),
    };
    let t0 = s.t;
    let hs = h / substeps as f64;
    out.t.push(s.t);
    out.q.push(s.q.as_slice().to_vec());
    out.v.push(s.v.as_slice().to_vec());
    for k in 1..=n_steps {
        for j in 1..=substeps {
            rk.step(sys, &mut s, hs)?;
            s.t = t0 + (k - 1) as f64 * h + j as f64 * hs;
        }
        s.t = t0 + k as f64 * h;
        out.t.push(s.t);
        out.q.push(s.q.as_slice().to_vec());
        out.v.push(s.v.as_slice().to_vec());
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::AccelerationSolver;
    use crate::tableau::ExplicitRk;

    /// A step is the generic explicit Runge-Kutta stepper on `y = (q, v)`, `y' = (v, a)` with
    /// the public acceleration solve, bit for bit (end points, embedded error estimates), and
    /// `last_acceleration` holds the last stage's accelerations (solved into the stage slope),
    /// for tableaus with and without embedded weights and with zero entries in `a` and `b`.
    #[test]
    fn stages_equal_the_generic_stepper_bit_for_bit() {
        let sys = mbd_model::models::slider_crank().unwrap();
        let n = sys.n_coords();
        let s0 = State::consistent(&sys, 0.0).unwrap();
        for tb in [
            ButcherTableau::rk4(),
            ButcherTableau::rk38(),
            ButcherTableau::dopri5(),
            ButcherTableau::bogacki_shampine(),
            ButcherTableau::midpoint(),
        ] {
            let mut rk = Index1Rk::new(&sys, tb.clone(), Index1Options::default()).unwrap();
            let mut generic = ExplicitRk::new(tb.clone(), 2 * n).unwrap();
            let mut acc = AccelerationSolver::new(&sys);
            let (mut a, mut l) = (vec![0.0; n], vec![0.0; sys.n_constraints()]);
            let mut s = s0.clone();
            let mut y: Vec<f64> = s0.q.iter().chain(s0.v.iter()).copied().collect();
            let mut t = s0.t;
            for _ in 0..20 {
                rk.step(&sys, &mut s, 1e-3).unwrap();
                let mut f = |t: f64, y: &[f64], dy: &mut [f64]| {
                    acc.solve(&sys, &y[..n], &y[n..], t, &mut a, &mut l)?;
                    dy[..n].copy_from_slice(&y[n..]);
                    dy[n..].copy_from_slice(&a);
                    Ok(())
                };
                generic.step(&mut f, t, &mut y, 1e-3).unwrap();
                t += 1e-3;
                let mine: Vec<f64> = s.q.iter().chain(s.v.iter()).copied().collect();
                assert_eq!(mine, y, "{}", tb.name);
                if tb.b_hat.is_some() {
                    assert_eq!(rk.rk.err, generic.err, "{}", tb.name);
                }
                assert_eq!(rk.last_acceleration().0, &a[..], "{}", tb.name);
            }
        }
    }
}
