//! Convergence-order fits: the least-squares slope of `log(error)` against `log(h)`, and the
//! local order of each consecutive pair, ignoring points at the round-off floor.

use crate::error::AnalysisError;
use serde::Serialize;

/// Result of [`fit_order`].
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct OrderFit {
    /// Least-squares slope over the points used (the global order).
    pub order: f64,
    /// Intercept of the fit, `log(error) = order * log(h) + intercept`.
    pub intercept: f64,
    /// Local orders `log(e_i / e_{i+1}) / log(h_i / h_{i+1})` of consecutive used points.
    pub local: Vec<f64>,
    /// Which points were used (not at the round-off floor, finite and positive).
    pub used: Vec<bool>,
}

/// Fits the convergence order of `errors` against step sizes `hs`. Points with an error at or
/// below `floor` (the round-off level) or non-finite are dropped; at least two must remain.
pub fn fit_order(hs: &[f64], errors: &[f64], floor: f64) -> Result<OrderFit, AnalysisError> {
    if hs.len() != errors.len() {
        return Err(AnalysisError::Dimension {
            what: "errors (one per step size)",
            expected: hs.len(),
            got: errors.len(),
        });
    }
    if let Some(&h) = hs.iter().find(|h| !(h.is_finite() && **h > 0.0)) {
        return Err(AnalysisError::InvalidValue {
            what: "step size",
            value: h,
            reason: "must be positive and finite",
        });
    }
    let used: Vec<bool> = errors
        .iter()
        .map(|&e| e.is_finite() && e > floor && e > 0.0)
        .collect();
    let pts: Vec<(f64, f64)> = hs
        .iter()
        .zip(errors)
        .zip(&used)
        .filter(|(_, &u)| u)
        .map(|((h, e), _)| (h.ln(), e.ln()))
        .collect();
    if pts.len() < 2 {
        return Err(AnalysisError::TooFewPoints {
            what: "errors above the round-off floor",
            need: 2,
            got: pts.len(),
        });
    }
    let n = pts.len() as f64;
    let mx = pts.iter().map(|p| p.0).sum::<f64>() / n;
    let my = pts.iter().map(|p| p.1).sum::<f64>() / n;
    let sxx: f64 = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
    if sxx == 0.0 {
        return Err(AnalysisError::InvalidValue {
            what: "step sizes",
            value: hs[0],
            reason: "must not all be equal",
        });
    }
    let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let order = sxy / sxx;
    let local = pts
        .windows(2)
        .map(|w| (w[0].1 - w[1].1) / (w[0].0 - w[1].0))
        .collect();
    Ok(OrderFit {
        order,
        intercept: my - order * mx,
        local,
        used,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn recovers_slope_and_drops_floor() {
        let hs = [0.1, 0.05, 0.025, 0.0125, 0.00625];
        let errs: Vec<f64> = hs.iter().map(|h: &f64| 3.0 * h.powi(4)).collect();
        let f = fit_order(&hs, &errs, 0.0).unwrap();
        assert!((f.order - 4.0).abs() < 1e-12);
        assert!(f.local.iter().all(|o| (o - 4.0).abs() < 1e-12));
        let mut e2 = errs.clone();
        e2[4] = 1e-17;
        let f2 = fit_order(&hs, &e2, 1e-15).unwrap();
        assert_eq!(f2.used, vec![true, true, true, true, false]);
        assert!((f2.order - 4.0).abs() < 1e-12);
        assert!(fit_order(&hs[..1], &errs[..1], 0.0).is_err());
        assert!(fit_order(&[0.1, -0.1], &[1.0, 2.0], 0.0).is_err());
        assert!(fit_order(&[0.1, 0.1], &[1.0, 2.0], 0.0).is_err());
        assert!(fit_order(&[0.1, 0.05], &[1.0], 0.0).is_err());
    }
}
