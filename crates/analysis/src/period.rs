//! Periods of oscillations from equally spaced samples: zero crossings located by local Lagrange
//! interpolation, the period as twice the least-squares slope of the crossing times against
//! their index (so the errors of the individual crossings average out), and the exact period of
//! the pendulum from the arithmetic-geometric mean (the reference of paper A's period orders).

use crate::error::AnalysisError;
use std::f64::consts::PI;

/// Arithmetic-geometric mean of `a` and `b` (both positive), to round-off.
pub fn agm(mut a: f64, mut b: f64) -> f64 {
    // quadratic convergence: a handful of iterations reach round-off; stop when they agree
    for _ in 0..64 {
        let (a1, b1) = (0.5 * (a + b), (a * b).sqrt());
        if a1 == a && b1 == b {
            break;
        }
        a = a1;
        b = b1;
    }
    a
}

/// Exact period of a pendulum with small-amplitude angular frequency `omega0` released at rest
/// at angle `amplitude` (rad) from the downward vertical: `2 pi / (omega0 agm(1, cos(a / 2)))`.
/// For a uniform rod of length `l` pinned at one end, `omega0 = sqrt(3 g / (2 l))`.
pub fn pendulum_period(omega0: f64, amplitude: f64) -> Result<f64, AnalysisError> {
    if !(omega0.is_finite() && omega0 > 0.0) {
        return Err(AnalysisError::InvalidValue {
            what: "omega0",
            value: omega0,
            reason: "must be positive and finite",
        });
    }
    if !(amplitude.is_finite() && amplitude.abs() < PI) {
        return Err(AnalysisError::InvalidValue {
            what: "amplitude",
            value: amplitude,
            reason: "must be finite and below pi in magnitude",
        });
    }
    Ok(2.0 * PI / omega0 / agm(1.0, (0.5 * amplitude).cos()))
}

/// Times where the signal sampled at `t0 + k h` (`samples[k]`) crosses zero, in either
/// direction. Each crossing is located as the root, by bisection to round-off, of the Lagrange
/// polynomial through the `points` samples centred on the bracketing interval (`points` even,
/// at least 2: 2 is linear, 4 cubic, 6 quintic interpolation); crossings too close to either end
/// for the stencil are skipped. A sample exactly at zero counts once, at its own time.
pub fn zero_crossings(
    samples: &[f64],
    t0: f64,
    h: f64,
    points: usize,
) -> Result<Vec<f64>, AnalysisError> {
    if points < 2 || points % 2 != 0 {
        return Err(AnalysisError::InvalidValue {
            what: "interpolation points",
            value: points as f64,
            reason: "must be even and at least 2",
        });
    }
    if !(h.is_finite() && h > 0.0) {
        return Err(AnalysisError::InvalidValue {
            what: "sample spacing h",
            value: h,
            reason: "must be positive and finite",
        });
    }
    if let Some(&x) = samples.iter().find(|x| !x.is_finite()) {
        return Err(AnalysisError::InvalidValue {
            what: "sample",
            value: x,
            reason: "must be finite",
        });
    }
    let half = points / 2;
    let mut out = Vec::new();
    for k in (half - 1)..samples.len().saturating_sub(half) {
        let (a, b) = (samples[k], samples[k + 1]);
        if a == 0.0 {
            out.push(t0 + k as f64 * h);
            continue;
        }
        if b == 0.0 || a.signum() == b.signum() {
            continue;
        }
        // the stencil k - half + 1 ..= k + half, in local time s = (t - t_k) / h
        let first = k + 1 - half;
        let stencil = &samples[first..first + points];
        let nodes: Vec<f64> = (0..points).map(|i| (first + i) as f64 - k as f64).collect();
        let poly = |s: f64| -> f64 {
            let mut sum = 0.0;
            for (i, &yi) in stencil.iter().enumerate() {
                let mut w = yi;
                for (j, &xj) in nodes.iter().enumerate() {
                    if j != i {
                        w *= (s - xj) / (nodes[i] - xj);
                    }
                }
                sum += w;
            }
            sum
        };
        // the polynomial equals the samples at s = 0 and s = 1, so it changes sign in [0, 1]
        let (mut lo, mut hi) = (0.0f64, 1.0f64);
        let flo = poly(lo).signum();
        for _ in 0..100 {
            let mid = 0.5 * (lo + hi);
            if mid <= lo || mid >= hi {
                break;
            }
            if poly(mid).signum() == flo {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        out.push(t0 + (k as f64 + 0.5 * (lo + hi)) * h);
    }
    Ok(out)
}

/// Least-squares slope of `times[i]` against `i`: the mean spacing of events that recur at a
/// constant interval (for the two zero crossings per period of a symmetric oscillation, half the
/// period). Needs at least two times.
pub fn mean_spacing(times: &[f64]) -> Result<f64, AnalysisError> {
    if times.len() < 2 {
        return Err(AnalysisError::TooFewPoints {
            what: "event times",
            need: 2,
            got: times.len(),
        });
    }
    let n = times.len() as f64;
    let im = (n - 1.0) / 2.0;
    let tm = times.iter().sum::<f64>() / n;
    let (mut sxy, mut sxx) = (0.0, 0.0);
    for (i, &t) in times.iter().enumerate() {
        let di = i as f64 - im;
        sxy += di * (t - tm);
        sxx += di * di;
    }
    Ok(sxy / sxx)
}

/// Period of a symmetric oscillation sampled at `t0 + k h`: twice the [`mean_spacing`] of its
/// [`zero_crossings`] (interpolated through `points` samples). Needs at least two crossings.
pub fn oscillation_period(
    samples: &[f64],
    t0: f64,
    h: f64,
    points: usize,
) -> Result<f64, AnalysisError> {
    let c = zero_crossings(samples, t0, h, points)?;
    Ok(2.0 * mean_spacing(&c)?)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn agm_and_the_pendulum_period() {
        assert!((agm(1.0, 1.0) - 1.0).abs() < 1e-15);
        // agm(1, sqrt 2) = 1.19814023473559220744 (Gauss's constant relation)
        assert!((agm(1.0, 2f64.sqrt()) - 1.198_140_234_735_592_2).abs() < 1e-15);
        let w = 3.0;
        let t0 = pendulum_period(w, 1e-8).unwrap();
        assert!((t0 - 2.0 * PI / w).abs() < 1e-14);
        // 90 degrees: T = 4 K(1/sqrt 2) / omega0 = 7.416298709205487 / omega0
        let t90 = pendulum_period(1.0, PI / 2.0).unwrap();
        assert!((t90 - 7.416_298_709_205_487).abs() < 1e-12, "{t90}");
        assert!(pendulum_period(0.0, 0.1).is_err());
        assert!(pendulum_period(1.0, PI).is_err());
        assert!(pendulum_period(1.0, f64::NAN).is_err());
    }

    #[test]
    fn crossings_of_a_sine_and_its_period() {
        let (w, h, t0) = (2.0f64, 0.1, 0.3);
        let x: Vec<f64> = (0..400)
            .map(|k| (w * (t0 + k as f64 * h) + 0.2).sin())
            .collect();
        let c = zero_crossings(&x, t0, h, 6).unwrap();
        for (i, t) in c.iter().enumerate() {
            // crossings at w t + 0.2 = m pi; the first after t0 + 2 h (the stencil's reach)
            let m = ((w * c[0] + 0.2) / PI).round() + i as f64;
            assert!((t - (m * PI - 0.2) / w).abs() < 1e-6, "{i}: {t}");
        }
        let p4 = oscillation_period(&x, t0, h, 4).unwrap();
        let p6 = oscillation_period(&x, t0, h, 6).unwrap();
        let exact = 2.0 * PI / w;
        assert!((p4 / exact - 1.0).abs() < 1e-6, "{p4}");
        assert!((p6 / exact - 1.0).abs() < 1e-8, "{p6}");
        // linear interpolation is visibly worse on single crossings
        let c2 = zero_crossings(&x, t0, h, 2).unwrap();
        let worst2 = c2
            .iter()
            .map(|t| {
                let m = ((w * t + 0.2) / PI).round();
                (t - (m * PI - 0.2) / w).abs()
            })
            .fold(0.0, f64::max);
        assert!(worst2 > 1e-5, "{worst2}");
    }

    #[test]
    fn exact_zeros_count_once_and_inputs_are_checked() {
        let x = [1.0, 0.5, 0.0, -0.5, -1.0, -0.5, 0.0, 0.5, 1.0];
        let c = zero_crossings(&x, 0.0, 1.0, 2).unwrap();
        assert_eq!(c, vec![2.0, 6.0]);
        assert!((mean_spacing(&c).unwrap() - 4.0).abs() < 1e-15);
        assert!(zero_crossings(&x, 0.0, 1.0, 3).is_err());
        assert!(zero_crossings(&x, 0.0, 0.0, 4).is_err());
        assert!(zero_crossings(&[0.0, f64::NAN], 0.0, 1.0, 2).is_err());
        assert!(mean_spacing(&[1.0]).is_err());
        assert!(oscillation_period(&[1.0, 2.0, 3.0], 0.0, 1.0, 2).is_err());
    }
}
