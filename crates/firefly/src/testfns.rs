//! Classic benchmark functions for testing optimisers (all have their global
//! minimum 0 at the origin, except Rosenbrock whose minimum 0 is at
//! `(1, ..., 1)`), with the search domains used in this crate's tests and by
//! NiaPy's defaults.

use std::f64::consts::PI;

/// A benchmark function with its conventional search domain `[lo, hi]^d`.
#[derive(Debug, Clone, Copy)]
pub struct TestFunction {
    /// Lower-case name (`"sphere"`, ...).
    pub name: &'static str,
    /// The function.
    pub f: fn(&[f64]) -> f64,
    /// Lower bound of every coordinate.
    pub lo: f64,
    /// Upper bound of every coordinate.
    pub hi: f64,
}

/// Sphere, Rosenbrock, Rastrigin, Ackley and Griewank with their domains.
pub const ALL: [TestFunction; 5] = [
    TestFunction {
        name: "sphere",
        f: sphere,
        lo: -5.12,
        hi: 5.12,
    },
    TestFunction {
        name: "rosenbrock",
        f: rosenbrock,
        lo: -30.0,
        hi: 30.0,
    },
    TestFunction {
        name: "rastrigin",
        f: rastrigin,
        lo: -5.12,
        hi: 5.12,
    },
    TestFunction {
        name: "ackley",
        f: ackley,
        lo: -32.768,
        hi: 32.768,
    },
    TestFunction {
        name: "griewank",
        f: griewank,
        lo: -600.0,
        hi: 600.0,
    },
];

/// Looks a function of [`ALL`] up by name.
pub fn by_name(name: &str) -> Option<TestFunction> {
    ALL.iter().copied().find(|t| t.name == name)
}

/// Sphere `sum x_k^2`.
pub fn sphere(x: &[f64]) -> f64 {
    x.iter().map(|v| v * v).sum()
}

/// Rosenbrock `sum_{k<d-1} 100 (x_{k+1} - x_k^2)^2 + (1 - x_k)^2`.
pub fn rosenbrock(x: &[f64]) -> f64 {
    x.windows(2)
        .map(|w| 100.0 * (w[1] - w[0] * w[0]).powi(2) + (1.0 - w[0]).powi(2))
        .sum()
}

/// Rastrigin `10 d + sum (x_k^2 - 10 cos(2 pi x_k))`.
pub fn rastrigin(x: &[f64]) -> f64 {
    10.0 * x.len() as f64
        + x.iter()
            .map(|v| v * v - 10.0 * (2.0 * PI * v).cos())
            .sum::<f64>()
}

/// Ackley `-20 exp(-0.2 sqrt(mean x^2)) - exp(mean cos(2 pi x)) + 20 + e`
/// (0 for an empty input).
pub fn ackley(x: &[f64]) -> f64 {
    if x.is_empty() {
        return 0.0;
    }
    let n = x.len() as f64;
    let s2 = x.iter().map(|v| v * v).sum::<f64>() / n;
    let sc = x.iter().map(|v| (2.0 * PI * v).cos()).sum::<f64>() / n;
    (-20.0 * (-0.2 * s2.sqrt()).exp() - sc.exp() + 20.0 + std::f64::consts::E).max(0.0)
}

/// Griewank `1 + sum x_k^2 / 4000 - prod cos(x_k / sqrt(k + 1))`.
pub fn griewank(x: &[f64]) -> f64 {
    let s = x.iter().map(|v| v * v).sum::<f64>() / 4000.0;
    let p: f64 = x
        .iter()
        .enumerate()
        .map(|(k, v)| (v / ((k + 1) as f64).sqrt()).cos())
        .product();
    (1.0 + s - p).max(0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn minima_are_zero() {
        let z = [0.0; 7];
        assert_eq!(sphere(&z), 0.0);
        assert_eq!(rastrigin(&z), 0.0);
        assert!(ackley(&z).abs() < 1e-15);
        assert!(griewank(&z).abs() < 1e-15);
        assert_eq!(rosenbrock(&[1.0; 7]), 0.0);
        assert!(sphere(&[1.0, 2.0]) == 5.0);
        assert!(by_name("ackley").is_some() && by_name("nope").is_none());
    }
}
