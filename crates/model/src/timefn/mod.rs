//! Functions of time for rheonomic drivers and applied loads.

use serde::{Deserialize, Serialize};

mod table;
pub(crate) use table::with_base_dir;
pub use table::{Extrapolation, Interpolation, Table, TableError, TableSpec, MAX_TABLE_FILE_BYTES};

/// A scalar function of time with its first two derivatives, serialisable for model files.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum TimeFunction {
    /// `c`.
    Constant {
        /// The value.
        value: f64,
    },
    /// `c0 + c1 t + c2 t^2 + ...`.
    Polynomial {
        /// Coefficients, lowest degree first.
        coeffs: Vec<f64>,
    },
    /// `offset + amplitude sin(omega t + phase)`.
    Harmonic {
        /// Constant part.
        #[serde(default)]
        offset: f64,
        /// Amplitude.
        amplitude: f64,
        /// Angular frequency (rad/s).
        omega: f64,
        /// Phase (rad).
        #[serde(default)]
        phase: f64,
    },
    /// `from` until `t0`, `to` from `t1`, and between them the quintic smooth step
    /// `from + (to - from) (10 s^3 - 15 s^4 + 6 s^5)`, `s = (t - t0) / (t1 - t0)`: its first
    /// and second derivatives vanish at both ends, so a driver started with it has continuous
    /// accelerations.
    SmoothStep {
        /// Start of the transition.
        t0: f64,
        /// End of the transition (after `t0`).
        t1: f64,
        /// Value before `t0`.
        from: f64,
        /// Value after `t1`.
        to: f64,
    },
    /// `from` until `t0`, `to` from `t1`, linear between (its first derivative jumps at `t0`
    /// and `t1`: the accelerations of a driver jump there; see `smooth_step` for a smooth one).
    Ramp {
        /// Start of the ramp.
        t0: f64,
        /// End of the ramp (after `t0`).
        t1: f64,
        /// Value before `t0`.
        from: f64,
        /// Value after `t1`.
        to: f64,
    },
    /// Samples interpolated linearly or by a natural cubic spline, inline or from a CSV file
    /// (see [`Table`] and [`TableSpec`]).
    Table(Table),
}

impl TimeFunction {
    /// A constant function.
    pub fn constant(value: f64) -> Self {
        TimeFunction::Constant { value }
    }
    /// `c0 + c1 t`.
    pub fn linear(c0: f64, c1: f64) -> Self {
        TimeFunction::Polynomial {
            coeffs: vec![c0, c1],
        }
    }
    /// `(f(t), f'(t), f''(t))`.
    pub fn eval(&self, t: f64) -> [f64; 3] {
        match self {
            TimeFunction::Constant { value } => [*value, 0.0, 0.0],
            TimeFunction::Polynomial { coeffs } => {
                let (mut f, mut d1, mut d2) = (0.0, 0.0, 0.0);
                for &c in coeffs.iter().rev() {
                    d2 = d2 * t + d1 * 2.0;
                    d1 = d1 * t + f;
                    f = f * t + c;
                }
                [f, d1, d2]
            }
            TimeFunction::Harmonic {
                offset,
                amplitude,
                omega,
                phase,
            } => {
                let (s, c) = (omega * t + phase).sin_cos();
                [
                    offset + amplitude * s,
                    amplitude * omega * c,
                    -amplitude * omega * omega * s,
                ]
            }
            TimeFunction::SmoothStep { t0, t1, from, to } => {
                let (d, span) = (to - from, t1 - t0);
                if t <= *t0 {
                    [*from, 0.0, 0.0]
                } else if t >= *t1 {
                    [*to, 0.0, 0.0]
                } else {
                    let x = (t - t0) / span;
                    let (x2, x3) = (x * x, x * x * x);
                    [
                        from + d * x3 * (10.0 - 15.0 * x + 6.0 * x2),
                        d * 30.0 * x2 * (1.0 - 2.0 * x + x2) / span,
                        d * 60.0 * x * (1.0 - 3.0 * x + 2.0 * x2) / (span * span),
                    ]
                }
            }
            TimeFunction::Ramp { t0, t1, from, to } => {
                if t <= *t0 {
                    [*from, 0.0, 0.0]
                } else if t >= *t1 {
                    [*to, 0.0, 0.0]
                } else {
                    let rate = (to - from) / (t1 - t0);
                    [from + rate * (t - t0), rate, 0.0]
                }
            }
            TimeFunction::Table(table) => table.eval(t),
        }
    }
    /// A quintic smooth step from `from` to `to` over `[t0, t1]` (see
    /// [`TimeFunction::SmoothStep`]).
    pub fn smooth_step(t0: f64, t1: f64, from: f64, to: f64) -> Self {
        TimeFunction::SmoothStep { t0, t1, from, to }
    }
    /// A linear ramp from `from` to `to` over `[t0, t1]` (see [`TimeFunction::Ramp`]).
    pub fn ramp(t0: f64, t1: f64, from: f64, to: f64) -> Self {
        TimeFunction::Ramp { t0, t1, from, to }
    }
    /// Whether the function is constant in time.
    pub fn is_constant(&self) -> bool {
        match self {
            TimeFunction::Constant { .. } => true,
            TimeFunction::Polynomial { coeffs } => coeffs.iter().skip(1).all(|&c| c == 0.0),
            TimeFunction::Harmonic {
                amplitude, omega, ..
            } => *amplitude == 0.0 || *omega == 0.0,
            TimeFunction::SmoothStep { from, to, .. } | TimeFunction::Ramp { from, to, .. } => {
                from == to
            }
            TimeFunction::Table(table) => table.is_constant(),
        }
    }
    /// Whether every parameter is finite.
    pub fn is_finite(&self) -> bool {
        match self {
            TimeFunction::Constant { value } => value.is_finite(),
            TimeFunction::Polynomial { coeffs } => coeffs.iter().all(|c| c.is_finite()),
            TimeFunction::Harmonic {
                offset,
                amplitude,
                omega,
                phase,
            } => {
                offset.is_finite()
                    && amplitude.is_finite()
                    && omega.is_finite()
                    && phase.is_finite()
            }
            TimeFunction::SmoothStep { t0, t1, from, to }
            | TimeFunction::Ramp { t0, t1, from, to } => {
                [t0, t1, from, to].iter().all(|x| x.is_finite())
            }
            // checked when the table was built
            TimeFunction::Table(_) => true,
        }
    }
    /// Why the function's parameters are invalid, if they are: not finite, or a transition
    /// whose end `t1` is not after its start `t0`.
    pub fn invalid_reason(&self) -> Option<&'static str> {
        if !self.is_finite() {
            return Some("time function coefficients must be finite");
        }
        match self {
            TimeFunction::SmoothStep { t0, t1, .. } | TimeFunction::Ramp { t0, t1, .. }
                if t1 <= t0 =>
            {
                Some("a step's or ramp's end t1 must be after its start t0")
            }
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn derivatives_match_finite_differences() {
        let fs = [
            TimeFunction::Polynomial {
                coeffs: vec![0.5, -1.0, 2.0, 0.3],
            },
            TimeFunction::Harmonic {
                offset: 0.1,
                amplitude: 0.7,
                omega: 2.3,
                phase: 0.4,
            },
            TimeFunction::constant(3.0),
            TimeFunction::smooth_step(0.2, 0.9, -1.0, 2.5),
            TimeFunction::ramp(0.1, 0.6, 0.5, -1.5),
        ];
        for f in &fs {
            let t = 0.37;
            let e = 1e-5;
            let [_, d1, d2] = f.eval(t);
            let fd1 = (f.eval(t + e)[0] - f.eval(t - e)[0]) / (2.0 * e);
            let fd2 = (f.eval(t + e)[1] - f.eval(t - e)[1]) / (2.0 * e);
            // (the differences' own error: 1e-10 / 6 times the third and fourth derivatives,
            // up to about 5e3 for the smooth step)
            assert!((d1 - fd1).abs() < 1e-7, "{f:?}: {d1} {fd1}");
            assert!((d2 - fd2).abs() < 1e-7, "{f:?}: {d2} {fd2}");
        }
        assert_eq!(fs[0].eval(2.0)[0], 0.5 - 2.0 + 8.0 + 0.3 * 8.0);
    }

    /// The smooth step is C2: value, first and second derivative continuous at both ends (and
    /// its values there the given ones); the ramp is C0 with its rate between the ends.
    #[test]
    fn steps_and_ramps_join_their_ends() {
        let f = TimeFunction::smooth_step(0.2, 0.9, -1.0, 2.5);
        for (t, v) in [(0.2, -1.0), (0.9, 2.5)] {
            for e in [-1e-9, 1e-9] {
                let [a, b, c] = f.eval(t + e);
                assert!(
                    (a - v).abs() < 1e-8 && b.abs() < 1e-6 && c.abs() < 1e-6,
                    "{t} {e}"
                );
            }
        }
        assert!((f.eval(0.55)[0] - (-1.0 + 3.5 * 0.5)).abs() < 1e-15);
        let r = TimeFunction::ramp(0.1, 0.6, 0.5, -1.5);
        assert_eq!(r.eval(0.0), [0.5, 0.0, 0.0]);
        assert_eq!(r.eval(1.0), [-1.5, 0.0, 0.0]);
        assert!((r.eval(0.35)[1] + 4.0).abs() < 1e-12);
        assert_eq!(
            TimeFunction::ramp(1.0, 1.0, 0.0, 1.0).invalid_reason(),
            Some("a step's or ramp's end t1 must be after its start t0")
        );
        assert!(TimeFunction::smooth_step(0.0, 1.0, 2.0, 2.0).is_constant());
    }
}
