//! Gauss-Legendre quadrature and Lagrange interpolation on `[0, 1]`, for any number of points.

/// Nodes and weights of the `s`-point Gauss-Legendre rule on `[0, 1]` (exact for polynomials of
/// degree `2s - 1`). Nodes by Newton on the Legendre polynomial `P_s` from Chebyshev-like
/// guesses, converged to round-off.
pub fn gauss_legendre(s: usize) -> (Vec<f64>, Vec<f64>) {
    let mut nodes = vec![0.0; s];
    let mut weights = vec![0.0; s];
    for i in 0..s {
        // i-th root of P_s on [-1, 1], descending
        let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (s as f64 + 0.5)).cos();
        let mut dp = 1.0;
        for _ in 0..100 {
            let (p, d) = legendre(s, x);
            dp = d;
            let dx = p / d;
            x -= dx;
            if dx.abs() <= 1e-16 {
                break;
            }
        }
        let (_, d) = legendre(s, x);
        if d.is_finite() {
            dp = d;
        }
        let w = 2.0 / ((1.0 - x * x) * dp * dp);
        // map to [0, 1], ascending
        nodes[s - 1 - i] = 0.5 * (1.0 + x);
        weights[s - 1 - i] = 0.5 * w;
    }
    (nodes, weights)
}

/// The Legendre polynomial and its derivative, `(P_n(x), P_n'(x))`, by the three-term
/// recurrence (the derivative formula needs `|x| != 1`).
pub fn legendre(n: usize, x: f64) -> (f64, f64) {
    if n == 0 {
        return (1.0, 0.0);
    }
    let (mut p0, mut p1) = (1.0, x);
    for k in 2..=n {
        let kf = k as f64;
        let p2 = ((2.0 * kf - 1.0) * x * p1 - (kf - 1.0) * p0) / kf;
        p0 = p1;
        p1 = p2;
    }
    let d = n as f64 * (x * p1 - p0) / (x * x - 1.0);
    (p1, d)
}

/// Lagrange basis on the equally spaced points `tau_nu = nu / s`, `nu = 0..s`.
#[derive(Clone, Debug, PartialEq)]
pub struct LagrangeBasis {
    /// The interpolation points.
    pub points: Vec<f64>,
}

impl LagrangeBasis {
    /// Equally spaced points `0, 1/s, ..., 1` (`s >= 1`).
    pub fn equispaced(s: usize) -> Self {
        LagrangeBasis {
            points: (0..=s).map(|k| k as f64 / s as f64).collect(),
        }
    }
    /// Values `l_nu(tau)` into `out` (length `s + 1`).
    pub fn values(&self, tau: f64, out: &mut [f64]) {
        let p = &self.points;
        for (nu, o) in out.iter_mut().enumerate().take(p.len()) {
            let mut v = 1.0;
            for (k, &pk) in p.iter().enumerate() {
                if k != nu {
                    v *= (tau - pk) / (p[nu] - pk);
                }
            }
            *o = v;
        }
    }
    /// Derivatives `l_nu'(tau)` into `out`.
    pub fn derivatives(&self, tau: f64, out: &mut [f64]) {
        let p = &self.points;
        for (nu, o) in out.iter_mut().enumerate().take(p.len()) {
            let mut sum = 0.0;
            for (j, &pj) in p.iter().enumerate() {
                if j == nu {
                    continue;
                }
                let mut prod = 1.0 / (p[nu] - pj);
                for (k, &pk) in p.iter().enumerate() {
                    if k != nu && k != j {
                        prod *= (tau - pk) / (p[nu] - pk);
                    }
                }
                sum += prod;
            }
            *o = sum;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn gauss_rules_are_exact_to_degree_2s_minus_1() {
        for s in 1..=8 {
            let (x, w) = gauss_legendre(s);
            for deg in 0..2 * s {
                let q: f64 = x.iter().zip(&w).map(|(x, w)| w * x.powi(deg as i32)).sum();
                assert!(
                    (q - 1.0 / (deg as f64 + 1.0)).abs() < 1e-14,
                    "s={s} deg={deg}"
                );
            }
            let deg = 2 * s;
            let q: f64 = x.iter().zip(&w).map(|(x, w)| w * x.powi(deg as i32)).sum();
            assert!(
                (q - 1.0 / (deg as f64 + 1.0)).abs() > 1e-13,
                "s={s} not exact at 2s"
            );
        }
        let (x, _) = gauss_legendre(2);
        assert!((x[0] - (0.5 - 3f64.sqrt() / 6.0)).abs() < 1e-15);
    }
    #[test]
    fn lagrange_interpolates_and_differentiates_polynomials() {
        let b = LagrangeBasis::equispaced(3);
        let f = |t: f64| 1.0 - 2.0 * t + 0.5 * t * t * t;
        let df = |t: f64| -2.0 + 1.5 * t * t;
        let vals: Vec<f64> = b.points.iter().map(|&t| f(t)).collect();
        let mut l = vec![0.0; 4];
        let mut dl = vec![0.0; 4];
        for &t in &[0.1, 0.37, 0.9] {
            b.values(t, &mut l);
            b.derivatives(t, &mut dl);
            let fi: f64 = l.iter().zip(&vals).map(|(a, b)| a * b).sum();
            let dfi: f64 = dl.iter().zip(&vals).map(|(a, b)| a * b).sum();
            assert!((fi - f(t)).abs() < 1e-14);
            assert!((dfi - df(t)).abs() < 1e-13);
        }
    }
}
