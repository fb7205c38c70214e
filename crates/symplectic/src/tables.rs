//! The coefficient tables of one (s,s) scheme: control-point abscissae, Gauss-Legendre nodes and
//! weights, Lagrange basis values and derivatives at the Gauss nodes, and the predictor's
//! extrapolation matrix.

use crate::options::Nodes;
use mbd_solve::quadrature::{gauss_legendre, legendre, LagrangeBasis};

/// Abscissae `0 = tau_0 < ... < tau_s = 1` of the `s + 1` Gauss-Lobatto points on `[0, 1]`
/// (the ends and the roots of `P_s'(2 tau - 1)`). For `s <= 2` they are the equally spaced
/// points `0, 1` and `0, 1/2, 1`, returned exactly.
pub fn lobatto_nodes(s: usize) -> Vec<f64> {
    if s <= 2 {
        return (0..=s).map(|k| k as f64 / s.max(1) as f64).collect();
    }
    let mut pts = vec![0.0; s + 1];
    pts[s] = 1.0;
    for i in 1..s {
        // i-th interior root of P_s' on [-1, 1], descending from the Chebyshev-Lobatto guess
        let mut x = (std::f64::consts::PI * i as f64 / s as f64).cos();
        for _ in 0..100 {
            let (p, dp) = legendre(s, x);
            // (1 - x^2) P'' = 2 x P' - s (s + 1) P
            let ddp = (2.0 * x * dp - (s * (s + 1)) as f64 * p) / (1.0 - x * x);
            let dx = dp / ddp;
            x -= dx;
            if dx.abs() <= 1e-16 {
                break;
            }
        }
        pts[s - i] = 0.5 * (1.0 + x);
    }
    // symmetrise (removes the last-bit asymmetry of the Newton iterates)
    for i in 1..s {
        let sym = 0.5 * (pts[i] + 1.0 - pts[s - i]);
        pts[i] = sym;
    }
    pts
}

/// All coefficients of the scheme, stored row-major.
#[derive(Clone, Debug)]
pub(crate) struct Tables {
    pub s: usize,
    /// Control-point abscissae (s + 1).
    pub tau: Vec<f64>,
    /// Gauss nodes (s).
    pub c: Vec<f64>,
    /// Gauss weights (s).
    pub b: Vec<f64>,
    /// `a[j * (s+1) + nu] = l_nu(c_j)`.
    pub a: Vec<f64>,
    /// `d[j * (s+1) + nu] = l_nu'(c_j)`.
    pub d: Vec<f64>,
    /// `k[nu * (s+1) + mu] = sum_j b_j d_{j nu} d_{j mu}`.
    pub k: Vec<f64>,
    /// `w[nu] = sum_j b_j a_{j nu}` (= integral of l_nu).
    pub w: Vec<f64>,
    /// `bd[nu * s + j] = b_j l_nu'(c_j)` and `ba[nu * s + j] = b_j l_nu(c_j)` (weights of the
    /// momentum rows), `nu = 0..=s`.
    pub bd: Vec<f64>,
    pub ba: Vec<f64>,
    /// `e[(nu-1) * (s+1) + mu] = l_mu(1 + tau_nu)`, nu = 1..s (extrapolation to the next step).
    pub e: Vec<f64>,
}

impl Tables {
    pub fn new(s: usize, nodes: Nodes) -> Tables {
        let tau = match nodes {
            Nodes::Lobatto => lobatto_nodes(s),
            Nodes::Equispaced => (0..=s).map(|k| k as f64 / s as f64).collect(),
        };
        let (c, b) = gauss_legendre(s);
        let basis = LagrangeBasis {
            points: tau.clone(),
        };
        let s1 = s + 1;
        let mut a = vec![0.0; s * s1];
        let mut d = vec![0.0; s * s1];
        for j in 0..s {
            basis.values(c[j], &mut a[j * s1..(j + 1) * s1]);
            basis.derivatives(c[j], &mut d[j * s1..(j + 1) * s1]);
        }
        let mut k = vec![0.0; s1 * s1];
        let mut w = vec![0.0; s1];
        for nu in 0..s1 {
            for mu in 0..s1 {
                k[nu * s1 + mu] = (0..s).map(|j| b[j] * d[j * s1 + nu] * d[j * s1 + mu]).sum();
            }
            w[nu] = (0..s).map(|j| b[j] * a[j * s1 + nu]).sum();
        }
        let mut bd = vec![0.0; s1 * s];
        let mut ba = vec![0.0; s1 * s];
        for nu in 0..s1 {
            for j in 0..s {
                bd[nu * s + j] = b[j] * d[j * s1 + nu];
                ba[nu * s + j] = b[j] * a[j * s1 + nu];
            }
        }
        let mut e = vec![0.0; s * s1];
        for nu in 1..=s {
            basis.values(1.0 + tau[nu], &mut e[(nu - 1) * s1..nu * s1]);
        }
        Tables {
            s,
            tau,
            c,
            b,
            a,
            d,
            k,
            w,
            bd,
            ba,
            e,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn lobatto_nodes_known_values() {
        let p = lobatto_nodes(3);
        assert!((p[1] - 0.5 * (1.0 - 1.0 / 5f64.sqrt())).abs() < 1e-15);
        let p = lobatto_nodes(4);
        assert!((p[1] - 0.5 * (1.0 - (3.0f64 / 7.0).sqrt())).abs() < 1e-15);
        assert_eq!(p[2], 0.5);
        assert_eq!(lobatto_nodes(2), vec![0.0, 0.5, 1.0]);
    }
    #[test]
    fn weights_integrate_the_basis() {
        for s in 1..=5 {
            let t = Tables::new(s, Nodes::Lobatto);
            let sum: f64 = t.w.iter().sum();
            assert!((sum - 1.0).abs() < 1e-14);
            // rows of k sum to zero (derivatives of a partition of unity)
            for nu in 0..=s {
                let r: f64 = (0..=s).map(|mu| t.k[nu * (s + 1) + mu]).sum();
                assert!(r.abs() < 1e-12, "s={s} row {nu}: {r}");
            }
        }
    }
}
