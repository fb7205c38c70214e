//! The one max-norm of the workspace.
//!
//! Every crate that measures a residual (`mbd-solve`'s Newton, the solvers' stopping rules,
//! `mbd-analysis`' error measures, this crate's consistent initial conditions) uses
//! [`max_abs`], so a NaN anywhere in a residual is seen everywhere. It lives here, at the bottom
//! of the dependency graph, because the model's own initial-condition projection needs it;
//! `mbd-solve` re-exports it as `mbd_solve::linalg::max_abs`.

/// `max_i |x_i|`, or NaN when any entry is NaN (0 for an empty slice).
///
/// `f64::max` ignores a NaN operand, so a plain fold loses a NaN that is followed by a finite
/// entry (`[NaN, 1e-20]` would give `1e-20`) and a Newton iteration could report convergence
/// on a NaN residual. This helper returns NaN as soon as it sees one.
///
/// ```
/// use mbd_model::numeric::max_abs;
/// assert_eq!(max_abs(&[1.0, -3.0, 2.0]), 3.0);
/// assert!(max_abs(&[f64::NAN, 1e-20]).is_nan());
/// assert!(max_abs(&[1e-20, f64::NAN]).is_nan());
/// assert_eq!(max_abs(&[]), 0.0);
/// ```
#[inline]
pub fn max_abs(x: &[f64]) -> f64 {
    let mut m = 0.0f64;
    for &v in x {
        let a = v.abs();
        if a > m {
            m = a;
        } else if a.is_nan() {
            return f64::NAN;
        }
    }
    m
}

/// `max_i |a_i - b_i|` over the common length, NaN when any difference is NaN.
///
/// ```
/// use mbd_model::numeric::max_abs_diff;
/// assert_eq!(max_abs_diff(&[1.0, 2.0], &[1.5, 0.0]), 2.0);
/// assert!(max_abs_diff(&[f64::NAN, 0.0], &[0.0, 1.0]).is_nan());
/// ```
#[inline]
pub fn max_abs_diff(a: &[f64], b: &[f64]) -> f64 {
    let mut m = 0.0f64;
    for (x, y) in a.iter().zip(b) {
        let d = (x - y).abs();
        if d > m {
            m = d;
        } else if d.is_nan() {
            return f64::NAN;
        }
    }
    m
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nan_is_never_lost_wherever_it_sits() {
        for pos in 0..4 {
            let mut x = [1e-20, 5.0, -7.0, 1e-30];
            x[pos] = f64::NAN;
            assert!(max_abs(&x).is_nan(), "NaN at {pos} lost");
            let y = [0.0; 4];
            assert!(max_abs_diff(&x, &y).is_nan(), "NaN diff at {pos} lost");
        }
    }

    #[test]
    fn infinities_and_signs() {
        assert_eq!(max_abs(&[-f64::INFINITY, 1.0]), f64::INFINITY);
        assert_eq!(max_abs(&[-2.0, 1.0]), 2.0);
        assert_eq!(max_abs(&[0.0, -0.0]), 0.0);
    }
}
