//! Dense output and event location: [`DenseOutput`], an [`Observer`] adaptor that interpolates
//! between accepted states with a quintic Hermite polynomial, samples the solution at given
//! times and locates zero crossings of user functions ([`Event`]).
//!
//! Between two accepted states `(t0, q0, v0)` and `(t1, q1, v1)` the accelerations `a0`, `a1`
//! of the index-1 solve ([`AccelerationSolver`]) complete the data of the quintic Hermite
//! interpolant of `q` (values, first and second derivatives at both ends); `v` is its
//! derivative. The interpolation error of `q` is `O(h^6)` for a smooth solution (below the
//! local error of a fifth-order method), of `v` `O(h^5)`. One acceleration solve per step is
//! added (the one at `t1` is reused as `a0` of the next step).
//!
//! Events: after every step each event function `g(t, q, v)` is evaluated at the new state; a
//! sign change over the step (or an exact zero at its end) is located on the interpolant by the
//! Illinois variant of regula falsi, safeguarded by bisection, until the bracket is shorter than
//! [`DenseOutput::with_time_tol`] (default `1e-13` times `max(1, |t|)`).

use crate::accel::Accel;
use crate::error::SolveError;
use crate::integrator::{Flow, Observer, Recorder, StopReason};
use crate::sparse::LinearSolver;
use crate::state::State;
use mbd_model::System;

/// An event function `g(t, q, v)` of [`Event`].
pub type EventFn = Box<dyn FnMut(f64, &[f64], &[f64]) -> f64>;

/// Which sign changes of an event function count.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Crossing {
    /// Both directions (default).
    #[default]
    Any,
    /// `g` going from negative to positive.
    Rising,
    /// `g` going from positive to negative.
    Falling,
}

/// A zero crossing to locate: a function `g(t, q, v)`, the directions that count and whether
/// the run stops at the first one.
pub struct Event {
    /// A name for the report.
    pub name: String,
    g: EventFn,
    /// Which crossings count (default [`Crossing::Any`]).
    pub crossing: Crossing,
    /// Stop the run at the first crossing (default: record and go on).
    pub terminal: bool,
}

impl std::fmt::Debug for Event {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Event")
            .field("name", &self.name)
            .field("crossing", &self.crossing)
            .field("terminal", &self.terminal)
            .finish_non_exhaustive()
    }
}

impl Event {
    /// An event recording every zero crossing of `g(t, q, v)`.
    pub fn new(
        name: impl Into<String>,
        g: impl FnMut(f64, &[f64], &[f64]) -> f64 + 'static,
    ) -> Self {
        Event {
            name: name.into(),
            g: Box::new(g),
            crossing: Crossing::Any,
            terminal: false,
        }
    }
    /// Only crossings from negative to positive.
    pub fn rising(mut self) -> Self {
        self.crossing = Crossing::Rising;
        self
    }
    /// Only crossings from positive to negative.
    pub fn falling(mut self) -> Self {
        self.crossing = Crossing::Falling;
        self
    }
    /// Stop the run at the first crossing.
    pub fn terminal(mut self) -> Self {
        self.terminal = true;
        self
    }
}

/// A located zero crossing.
#[derive(Clone, Debug, PartialEq)]
pub struct EventHit {
    /// Index of the event (order of [`DenseOutput::with_event`] calls).
    pub event: usize,
    /// Its time.
    pub t: f64,
    /// Interpolated positions at `t`.
    pub q: Vec<f64>,
    /// Interpolated velocities at `t`.
    pub v: Vec<f64>,
    /// Whether `g` rose through zero (false: it fell).
    pub rising: bool,
    /// Index of the step (as passed to the observer) at whose end the crossing was detected.
    pub step: usize,
}

/// The quintic Hermite interpolant of one step.
#[derive(Clone, Debug)]
struct Segment {
    t0: f64,
    t1: f64,
    q0: Vec<f64>,
    v0: Vec<f64>,
    a0: Vec<f64>,
    q1: Vec<f64>,
    v1: Vec<f64>,
    a1: Vec<f64>,
}

impl Segment {
    fn new(n: usize) -> Self {
        Segment {
            t0: f64::NAN,
            t1: f64::NAN,
            q0: vec![0.0; n],
            v0: vec![0.0; n],
            a0: vec![0.0; n],
            q1: vec![0.0; n],
            v1: vec![0.0; n],
            a1: vec![0.0; n],
        }
    }

    /// `q(t)` and `v(t)` of the quintic Hermite interpolant.
    fn eval(&self, t: f64, q: &mut [f64], v: &mut [f64]) {
        let h = self.t1 - self.t0;
        // the step's ends exactly (the quintic's velocity at s = 1 is (h v1) / h, which need
        // not round back to v1)
        if h == 0.0 || t == self.t1 {
            q.copy_from_slice(&self.q1);
            v.copy_from_slice(&self.v1);
            return;
        }
        if t == self.t0 {
            q.copy_from_slice(&self.q0);
            v.copy_from_slice(&self.v0);
            return;
        }
        let s = (t - self.t0) / h;
        let (s2, s3) = (s * s, s * s * s);
        let (s4, s5) = (s3 * s, s3 * s2);
        let h0 = 1.0 - 10.0 * s3 + 15.0 * s4 - 6.0 * s5;
        let h1 = s - 6.0 * s3 + 8.0 * s4 - 3.0 * s5;
        let h2 = 0.5 * (s2 - 3.0 * s3 + 3.0 * s4 - s5);
        let h3 = 10.0 * s3 - 15.0 * s4 + 6.0 * s5;
        let h4 = -4.0 * s3 + 7.0 * s4 - 3.0 * s5;
        let h5 = 0.5 * (s3 - 2.0 * s4 + s5);
        let d0 = -30.0 * s2 + 60.0 * s3 - 30.0 * s4;
        let d1 = 1.0 - 18.0 * s2 + 32.0 * s3 - 15.0 * s4;
        let d2 = 0.5 * (2.0 * s - 9.0 * s2 + 12.0 * s3 - 5.0 * s4);
        let d4 = -12.0 * s2 + 28.0 * s3 - 15.0 * s4;
        let d5 = 0.5 * (3.0 * s2 - 8.0 * s3 + 5.0 * s4);
        let hh = h * h;
        for i in 0..q.len() {
            let (q0, v0, a0) = (self.q0[i], self.v0[i], self.a0[i]);
            let (q1, v1, a1) = (self.q1[i], self.v1[i], self.a1[i]);
            q[i] = h0 * q0 + h1 * h * v0 + h2 * hh * a0 + h3 * q1 + h4 * h * v1 + h5 * hh * a1;
            v[i] = (d0 * (q0 - q1) + d1 * h * v0 + d2 * hh * a0 + d4 * h * v1 + d5 * hh * a1) / h;
        }
    }
}

/// An [`Observer`] adaptor adding dense output and event location to any run (fixed-step
/// [`crate::run`], [`crate::run_adaptive`], or any loop that calls observers after accepted
/// steps), forwarding every sample to an inner observer.
///
/// * [`DenseOutput::at_times`]: states at given times are interpolated into
///   [`DenseOutput::samples`] (a [`Recorder`] whose `step` field holds the index of the step
///   that covered the time).
/// * [`DenseOutput::with_event`]: zero crossings are located and kept in
///   [`DenseOutput::events`]; a terminal event stops the run ([`Flow::Stop`]) after the step
///   in which it occurred: the integrator's state is then the end of that step, the event's
///   state is in its [`EventHit`].
///
/// Allocation-free per step (after [`DenseOutput::new`]) except for the samples and hits kept.
///
/// ```
/// use mbd_model::models;
/// use mbd_solve::{run, ButcherTableau, DenseOutput, Event, Index1Options, Index1Rk, NoObserver,
///     RunConfig, SolveError, State};
///
/// let sys = models::pendulum(1.0, 1.0, 0.5, 9.81)?;
/// let mut state = State::consistent(&sys, 0.0)?;
/// let mut rk = Index1Rk::new(&sys, ButcherTableau::rk4(), Index1Options::default())?;
/// // the angle from the downward vertical is q[2] + pi/2: record its zero crossings
/// let mut dense = DenseOutput::new(&sys, NoObserver)
///     .at_times([0.25, 0.5, 0.75])?
///     .with_event(Event::new("bottom", |_t, q, _v| q[2] + std::f64::consts::FRAC_PI_2));
/// run(&mut rk, &sys, &mut state, RunConfig::new(3.0, 0.01), &mut dense)?;
/// assert_eq!(dense.samples().len(), 3);
/// assert!(dense.events().len() >= 2);
/// # Ok::<(), SolveError>(())
/// ```
pub struct DenseOutput<O> {
    /// The observer every step sample is forwarded to.
    pub inner: O,
    acc: Accel,
    lambda: Vec<f64>,
    seg: Segment,
    /// Whether `seg.*0` holds a state (false before step 0).
    started: bool,
    times: Vec<f64>,
    next_time: usize,
    samples: Recorder,
    events: Vec<Event>,
    g_prev: Vec<f64>,
    hits: Vec<EventHit>,
    time_tol: f64,
    qb: Vec<f64>,
    vb: Vec<f64>,
    /// Crossings of the current step: (time, event index, rising).
    pending: Vec<(f64, usize, bool)>,
    /// The terminal event that stopped the run, if one did.
    stopped_by: Option<StopReason>,
}

impl<O> std::fmt::Debug for DenseOutput<O> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("DenseOutput")
            .field("times", &self.times.len())
            .field("events", &self.events)
            .field("hits", &self.hits.len())
            .finish_non_exhaustive()
    }
}

impl<O: Observer> DenseOutput<O> {
    /// Dense output for `sys`, forwarding every step sample to `inner` (use
    /// [`crate::NoObserver`] for none). The acceleration solve takes the path
    /// [`LinearSolver::Auto`] picks (sparse above [`crate::SPARSE_THRESHOLD`] constraints), as
    /// the solvers do; should the sparse pattern analysis fail (it cannot for the joints of
    /// `mbd-model`), the dense path is used. [`DenseOutput::with_linear`] chooses explicitly.
    pub fn new(sys: &System, inner: O) -> Self {
        let n = sys.n_coords();
        let acc = Accel::new(sys, LinearSolver::Auto)
            .unwrap_or_else(|_| Accel::Dense(crate::AccelerationSolver::new(sys)));
        DenseOutput {
            inner,
            acc,
            lambda: vec![0.0; sys.n_constraints()],
            seg: Segment::new(n),
            started: false,
            times: Vec::new(),
            next_time: 0,
            samples: Recorder::new(),
            events: Vec::new(),
            g_prev: Vec::new(),
            hits: Vec::new(),
            time_tol: 1e-13,
            qb: vec![0.0; n],
            vb: vec![0.0; n],
            pending: Vec::new(),
            stopped_by: None,
        }
    }

    /// Output times (non-decreasing, finite); the samples are kept in
    /// [`DenseOutput::samples`]. Times before the run's start or after its end are not sampled.
    pub fn at_times(mut self, times: impl IntoIterator<Item = f64>) -> Result<Self, SolveError> {
        let times: Vec<f64> = times.into_iter().collect();
        for (i, &t) in times.iter().enumerate() {
            if !t.is_finite() {
                return Err(SolveError::InvalidParameter {
                    parameter: "output time",
                    value: t,
                    reason: "must be finite",
                });
            }
            if i > 0 && t < times[i - 1] {
                return Err(SolveError::InvalidParameter {
                    parameter: "output time",
                    value: t,
                    reason: "output times must be non-decreasing",
                });
            }
        }
        self.times = times;
        self.next_time = 0;
        Ok(self)
    }

    /// The same dense output with the acceleration solve on the path `linear` picks for `sys`
    /// (the system given to [`DenseOutput::new`]). Errors if the sparse pattern analysis fails.
    pub fn with_linear(mut self, sys: &System, linear: LinearSolver) -> Result<Self, SolveError> {
        if sys.n_coords() != self.seg.q0.len() {
            return Err(SolveError::Dimension {
                what: "DenseOutput::with_linear system coordinates",
                expected: self.seg.q0.len(),
                got: sys.n_coords(),
            });
        }
        self.acc = Accel::new(sys, linear)?;
        Ok(self)
    }

    /// Adds an event to locate.
    pub fn with_event(mut self, event: Event) -> Self {
        self.events.push(event);
        self.g_prev.push(f64::NAN);
        self.pending.reserve(self.events.len());
        self
    }

    /// The relative time tolerance of event location (the bracket is shrunk below
    /// `tol * max(1, |t|)`); default `1e-13`. Must be positive.
    pub fn with_time_tol(mut self, tol: f64) -> Result<Self, SolveError> {
        if !(tol.is_finite() && tol > 0.0) {
            return Err(SolveError::InvalidParameter {
                parameter: "time_tol",
                value: tol,
                reason: "must be positive and finite",
            });
        }
        self.time_tol = tol;
        Ok(self)
    }
}

impl<O> DenseOutput<O> {
    /// The states interpolated at the output times.
    pub fn samples(&self) -> &Recorder {
        &self.samples
    }

    /// Whether the acceleration solve takes the sparse path ([`DenseOutput::with_linear`]).
    pub fn is_sparse(&self) -> bool {
        self.acc.is_sparse()
    }

    /// The zero crossings located so far, in time order.
    pub fn events(&self) -> &[EventHit] {
        &self.hits
    }

    /// Interpolates the last step at `t` into `q` and `v` (length `n`). Errors if no step was
    /// observed yet or `t` lies outside the last step (`[t0, t1]`).
    pub fn interpolate(&self, t: f64, q: &mut [f64], v: &mut [f64]) -> Result<(), SolveError> {
        let (t0, t1) = (self.seg.t0, self.seg.t1);
        if !(t >= t0.min(t1) && t <= t0.max(t1)) {
            return Err(SolveError::InvalidInterval {
                t0,
                t_end: t1,
                reason: "interpolation time outside the last step (or no step observed yet)",
            });
        }
        let n = self.seg.q0.len();
        if q.len() != n || v.len() != n {
            return Err(SolveError::Dimension {
                what: "interpolate q/v",
                expected: n,
                got: q.len().min(v.len()),
            });
        }
        self.seg.eval(t, q, v);
        Ok(())
    }

    /// Records the output times in `(lo, hi]` (or `[lo, hi]` if `closed`) from the segment.
    fn sample_upto(&mut self, lo: f64, hi: f64, closed: bool, step: usize) {
        while self.next_time < self.times.len() {
            let t = self.times[self.next_time];
            if t < lo || (!closed && t == lo) {
                self.next_time += 1;
                continue;
            }
            if t > hi {
                break;
            }
            self.seg.eval(t, &mut self.qb, &mut self.vb);
            self.samples.t.push(t);
            self.samples.q.push(self.qb.clone());
            self.samples.v.push(self.vb.clone());
            self.samples.step.push(step);
            self.next_time += 1;
        }
    }

    /// Locates the zero of event `e` in the segment between `ta` (value `ga`) and `tb` (`gb`),
    /// with opposite signs.
    fn locate(&mut self, e: usize, mut ta: f64, mut ga: f64, mut tb: f64, mut gb: f64) -> f64 {
        let g = &mut self.events[e].g;
        let mut side = 0i32;
        for it in 0..200 {
            let tol = self.time_tol * ta.abs().max(tb.abs()).max(1.0);
            if (tb - ta).abs() <= tol {
                break;
            }
            // Illinois regula falsi; bisection every fourth iteration as a safeguard
            let mut tc = if it % 4 == 3 {
                0.5 * (ta + tb)
            } else {
                (ta * gb - tb * ga) / (gb - ga)
            };
            if !(tc > ta.min(tb) && tc < ta.max(tb)) {
                tc = 0.5 * (ta + tb);
            }
            self.seg.eval(tc, &mut self.qb, &mut self.vb);
            let gc = g(tc, &self.qb, &self.vb);
            if gc == 0.0 {
                return tc;
            }
            if (gc > 0.0) == (gb > 0.0) {
                tb = tc;
                gb = gc;
                if side == -1 {
                    ga *= 0.5;
                }
                side = -1;
            } else {
                ta = tc;
                ga = gc;
                if side == 1 {
                    gb *= 0.5;
                }
                side = 1;
            }
        }
        // the end whose |g| is smaller
        if ga.abs() <= gb.abs() {
            ta
        } else {
            tb
        }
    }
}

impl<O: Observer> Observer for DenseOutput<O> {
    /// The terminal event that stopped the run ([`StopReason::Event`]), or the inner
    /// observer's reason.
    fn stop_reason(&self) -> Option<StopReason> {
        self.stopped_by
    }

    fn observe(&mut self, sys: &System, state: &State, step: usize) -> Result<Flow, SolveError> {
        let (q, v, t) = (state.q.as_slice(), state.v.as_slice(), state.t);
        if step == 0 {
            self.stopped_by = None;
        }
        if q.len() != self.seg.q1.len() {
            return Err(SolveError::Dimension {
                what: "DenseOutput state",
                expected: self.seg.q1.len(),
                got: q.len(),
            });
        }
        if self.started {
            // the last end point becomes this step's start
            std::mem::swap(&mut self.seg.q0, &mut self.seg.q1);
            std::mem::swap(&mut self.seg.v0, &mut self.seg.v1);
            std::mem::swap(&mut self.seg.a0, &mut self.seg.a1);
            self.seg.t0 = self.seg.t1;
        }
        // the new end point with its accelerations
        self.acc
            .solve(sys, q, v, t, &mut self.seg.a1, &mut self.lambda)?;
        self.seg.t1 = t;
        self.seg.q1.copy_from_slice(q);
        self.seg.v1.copy_from_slice(v);
        let mut flow = Flow::Continue;
        if !self.started {
            self.started = true;
            self.seg.t0 = t;
            self.seg.q0.copy_from_slice(q);
            self.seg.v0.copy_from_slice(v);
            self.seg.a0.copy_from_slice(&self.seg.a1);
            for (e, ev) in self.events.iter_mut().enumerate() {
                self.g_prev[e] = (ev.g)(t, q, v);
            }
            self.sample_upto(t, t, true, step);
        } else {
            let t0 = self.seg.t0;
            self.pending.clear();
            for e in 0..self.events.len() {
                let g1 = (self.events[e].g)(t, q, v);
                let g0 = self.g_prev[e];
                self.g_prev[e] = g1;
                if !(g0.is_finite() && g1.is_finite()) {
                    return Err(SolveError::NonFinite {
                        t,
                        what: "event function value",
                    });
                }
                // a crossing: strict sign change, or a zero reached at the end of the step
                if g0 == 0.0 || !(g1 == 0.0 || (g0 > 0.0) != (g1 > 0.0)) {
                    continue;
                }
                let rising = g0 < 0.0;
                let wanted = match self.events[e].crossing {
                    Crossing::Any => true,
                    Crossing::Rising => rising,
                    Crossing::Falling => !rising,
                };
                if !wanted {
                    continue;
                }
                let tc = if g1 == 0.0 {
                    t
                } else {
                    self.locate(e, t0, g0, t, g1)
                };
                self.pending.push((tc, e, rising));
            }
            self.pending.sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
            let mut t_stop = t;
            for k in 0..self.pending.len() {
                let (tc, e, rising) = self.pending[k];
                self.seg.eval(tc, &mut self.qb, &mut self.vb);
                self.hits.push(EventHit {
                    event: e,
                    t: tc,
                    q: self.qb.clone(),
                    v: self.vb.clone(),
                    rising,
                    step,
                });
                if self.events[e].terminal {
                    t_stop = tc;
                    flow = Flow::Stop;
                    self.stopped_by = Some(StopReason::Event { event: e, t: tc });
                    break;
                }
            }
            self.sample_upto(t0, t_stop, false, step);
        }
        let inner = self.inner.observe(sys, state, step)?;
        if inner == Flow::Stop && self.stopped_by.is_none() {
            self.stopped_by = self.inner.stop_reason();
        }
        Ok(if inner == Flow::Stop {
            Flow::Stop
        } else {
            flow
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The quintic Hermite interpolant reproduces a quintic polynomial (and its derivative)
    /// from values, first and second derivatives at both ends.
    #[test]
    fn quintic_hermite_is_exact_for_quintics() {
        let p =
            |t: f64| 1.0 - 2.0 * t + 0.5 * t * t + 3.0 * t.powi(3) - t.powi(4) + 0.7 * t.powi(5);
        let dp = |t: f64| -2.0 + t + 9.0 * t * t - 4.0 * t.powi(3) + 3.5 * t.powi(4);
        let ddp = |t: f64| 1.0 + 18.0 * t - 12.0 * t * t + 14.0 * t.powi(3);
        let (t0, t1) = (0.3, 1.1);
        let mut s = Segment::new(1);
        s.t0 = t0;
        s.t1 = t1;
        s.q0[0] = p(t0);
        s.v0[0] = dp(t0);
        s.a0[0] = ddp(t0);
        s.q1[0] = p(t1);
        s.v1[0] = dp(t1);
        s.a1[0] = ddp(t1);
        let (mut q, mut v) = ([0.0], [0.0]);
        for k in 0..=20 {
            let t = t0 + (t1 - t0) * k as f64 / 20.0;
            s.eval(t, &mut q, &mut v);
            assert!(
                (q[0] - p(t)).abs() < 1e-14,
                "q at {t}: {} vs {}",
                q[0],
                p(t)
            );
            assert!(
                (v[0] - dp(t)).abs() < 1e-13,
                "v at {t}: {} vs {}",
                v[0],
                dp(t)
            );
        }
    }

    #[test]
    fn output_times_must_be_sorted_and_finite() {
        let sys = mbd_model::models::pendulum(1.0, 1.0, 0.3, 9.81).unwrap();
        let d = DenseOutput::new(&sys, crate::NoObserver);
        assert!(matches!(
            d.at_times([0.2, 0.1]),
            Err(SolveError::InvalidParameter { value, .. }) if value == 0.1
        ));
        let d = DenseOutput::new(&sys, crate::NoObserver);
        assert!(d.at_times([f64::NAN]).is_err());
    }
}
