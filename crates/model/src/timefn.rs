//! Functions of time for rheonomic drivers and applied loads.

use serde::{Deserialize, Serialize};

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
        }
    }
    /// Whether the function is constant in time.
    pub fn is_constant(&self) -> bool {
        match self {
            TimeFunction::Constant { .. } => true,
            TimeFunction::Polynomial { coeffs } => coeffs.iter().skip(1).all(|&c| c == 0.0),
            TimeFunction::Harmonic {
                amplitude, omega, ..
            } => *amplitude == 0.0 || *omega == 0.0,
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
        ];
        for f in &fs {
            let t = 0.37;
            let e = 1e-5;
            let [_, d1, d2] = f.eval(t);
            let fd1 = (f.eval(t + e)[0] - f.eval(t - e)[0]) / (2.0 * e);
            let fd2 = (f.eval(t + e)[1] - f.eval(t - e)[1]) / (2.0 * e);
            assert!((d1 - fd1).abs() < 1e-8, "{f:?}");
            assert!((d2 - fd2).abs() < 1e-8, "{f:?}");
        }
        assert_eq!(fs[0].eval(2.0)[0], 0.5 - 2.0 + 8.0 + 0.3 * 8.0);
    }
}
