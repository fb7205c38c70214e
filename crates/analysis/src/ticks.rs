//! Axis ticks at "nice" values: 1, 2 or 5 times a power of ten on a linear axis, decades (or
//! 1-2-5 steps within a decade or two) on a logarithmic one.
//!
//! Each tick value is built from an exact decimal `mantissa x 10^exponent` with integer parts,
//! so a tick at zero is exactly `0.0` (never `-2e-21`) and the labels carry no rounding noise:
//! they are written from the integers, not from the floating-point value.
//!
//! ```
//! use mbd_analysis::ticks;
//! let t = ticks::linear(-0.3, 0.7, 6);
//! let labels: Vec<&str> = t.major.iter().map(|t| t.label.as_str()).collect();
//! assert_eq!(labels, ["-0.2", "0", "0.2", "0.4", "0.6"]);
//! let t = ticks::log(1e-6, 1e-2);
//! let labels: Vec<&str> = t.major.iter().map(|t| t.label.as_str()).collect();
//! assert_eq!(labels, ["1e-6", "1e-5", "1e-4", "1e-3", "1e-2"]);
//! ```

/// One labelled tick.
#[derive(Clone, Debug, PartialEq)]
pub struct Tick {
    /// Where it sits on the axis.
    pub value: f64,
    /// Its label, e.g. `0`, `0.25`, `-1.5e-6`.
    pub label: String,
}

/// The ticks of one axis.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Ticks {
    /// Labelled ticks (and the grid's bold lines).
    pub major: Vec<Tick>,
    /// Unlabelled ticks between them (the grid's light lines).
    pub minor: Vec<f64>,
}

/// The most labelled ticks a log axis gets; a wider range labels every 2nd, 3rd, ... decade.
const MAX_LOG_TICKS: usize = 12;

/// An exact decimal `mant x 10^exp`.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Dec {
    mant: i64,
    exp: i32,
}

impl Dec {
    /// The nearest `f64` (parsing the decimal string rounds correctly, so `0` stays `0.0`
    /// and `3 x 10^-1` is the same double as the literal `0.3`).
    fn value(self) -> f64 {
        format!("{}e{}", self.mant, self.exp)
            .parse()
            .unwrap_or(f64::NAN)
    }

    /// The same number with the mantissa's trailing zeros moved into the exponent.
    fn normalised(self) -> Dec {
        let (mut mant, mut exp) = (self.mant, self.exp);
        if mant == 0 {
            return Dec { mant: 0, exp: 0 };
        }
        while mant % 10 == 0 {
            mant /= 10;
            exp += 1;
        }
        Dec { mant, exp }
    }

    /// Positional notation: `-0.25`, `1200`, `12.7436000002`.
    fn plain(self) -> String {
        let d = self.normalised();
        if d.mant == 0 {
            return "0".into();
        }
        let sign = if d.mant < 0 { "-" } else { "" };
        let digits = d.mant.unsigned_abs().to_string();
        if d.exp >= 0 {
            return format!("{sign}{digits}{}", "0".repeat(d.exp as usize));
        }
        let frac = (-d.exp) as usize;
        let (int, frac_digits) = if digits.len() > frac {
            let (i, f) = digits.split_at(digits.len() - frac);
            (i.to_string(), f.to_string())
        } else {
            (
                "0".to_string(),
                format!("{}{digits}", "0".repeat(frac - digits.len())),
            )
        };
        format!("{sign}{int}.{frac_digits}")
    }

    /// Scientific notation with as many mantissa digits as the number has: `2e-6`,
    /// `1.25e5`; `0` for zero and `1` for one.
    fn scientific(self) -> String {
        let d = self.normalised();
        if d.mant == 0 {
            return "0".into();
        }
        let sign = if d.mant < 0 { "-" } else { "" };
        let digits = d.mant.unsigned_abs().to_string();
        let e = d.exp + digits.len() as i32 - 1;
        let mant = if digits.len() > 1 {
            format!("{}.{}", &digits[..1], &digits[1..])
        } else {
            digits
        };
        if e == 0 {
            format!("{sign}{mant}")
        } else {
            format!("{sign}{mant}e{e}")
        }
    }
}

/// Labels for ticks of one axis, all in one notation: positional when the largest magnitude
/// lies in `[1e-3, 1e5)`, else scientific.
fn labels(decs: &[Dec]) -> Vec<Tick> {
    let vals: Vec<f64> = decs.iter().map(|d| d.value()).collect();
    let big = vals.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let plain = big == 0.0 || (1e-3..1e5).contains(&big);
    decs.iter()
        .zip(vals)
        .map(|(d, value)| Tick {
            value,
            label: if plain { d.plain() } else { d.scientific() },
        })
        .collect()
}

/// The nice step `m x 10^e` (m = 1, 2 or 5) closest above `raw`'s bracket.
fn nice_step(raw: f64) -> Dec {
    let e = raw.log10().floor();
    let norm = raw / 10f64.powf(e);
    let (m, e) = if norm < 1.5 {
        (1, e)
    } else if norm < 3.5 {
        (2, e)
    } else if norm < 7.5 {
        (5, e)
    } else {
        (1, e + 1.0)
    };
    Dec {
        mant: m,
        exp: e as i32,
    }
}

/// The multiples of `step` within `[lo, hi]` (a step's billionth of slack at either end, so
/// a tick on the boundary is kept); `None` when there would be more than 10 000 of them or
/// their index does not fit exactly in a double.
fn multiples(lo: f64, hi: f64, step: Dec) -> Option<Vec<Dec>> {
    let s = step.value();
    let (k0, k1) = ((lo / s - 1e-9).ceil(), (hi / s + 1e-9).floor());
    if !(k0.is_finite() && k1.is_finite()) || k0.abs() > 1e15 || k1.abs() > 1e15 {
        return None;
    }
    if k1 - k0 > 1e4 {
        return None;
    }
    let (k0, k1) = (k0 as i64, k1 as i64);
    Some(
        (k0..=k1)
            .map(|k| Dec {
                mant: k * step.mant,
                exp: step.exp,
            })
            .collect(),
    )
}

/// Ticks of a linear axis over `[lo, hi]`: about `target` labelled ones at multiples of a
/// step of 1, 2 or 5 times a power of ten, and four or five unlabelled ones per step.
/// Empty for a non-finite or empty range.
pub fn linear(lo: f64, hi: f64, target: usize) -> Ticks {
    if !(lo.is_finite() && hi.is_finite() && hi > lo) {
        return Ticks::default();
    }
    let mut step = nice_step((hi - lo) / target.max(1) as f64);
    // a range far from zero relative to its width: coarser steps until the indices fit
    let major = loop {
        match multiples(lo, hi, step) {
            Some(m) => break m,
            None if step.exp < 300 => step.exp += 1,
            None => break vec![],
        }
    };
    let minor_step = match step.mant {
        1 => Dec {
            mant: 2,
            exp: step.exp - 1,
        },
        2 => Dec {
            mant: 5,
            exp: step.exp - 1,
        },
        _ => Dec {
            mant: 1,
            exp: step.exp,
        },
    };
    Ticks {
        major: labels(&major),
        minor: multiples(lo, hi, minor_step)
            .unwrap_or_default()
            .into_iter()
            .map(Dec::value)
            .collect(),
    }
}

/// Ticks of a logarithmic axis over `[lo, hi]` (`0 < lo < hi`): every decade inside the range
/// (every 2nd, 5th, ... when there are more than twelve), with 2..9 times each decade
/// unlabelled; a range that holds fewer than three decades gets 1-2-5 ticks, and one too
/// narrow even for those the ticks of a linear axis. Empty for a range that is not positive.
pub fn log(lo: f64, hi: f64) -> Ticks {
    if !(lo.is_finite() && hi.is_finite() && lo > 0.0 && hi > lo) {
        return Ticks::default();
    }
    let inside = |d: Dec| {
        let v = d.value();
        v >= lo && v <= hi
    };
    let (d0, d1) = (lo.log10().floor() as i32 - 1, hi.log10().ceil() as i32 + 1);
    let decades: Vec<i32> = (d0..=d1)
        .filter(|&e| inside(Dec { mant: 1, exp: e }))
        .collect();
    let in_decades = |ms: &[i64]| -> Vec<Dec> {
        (d0..=d1)
            .flat_map(|e| ms.iter().map(move |&m| Dec { mant: m, exp: e }))
            .filter(|&d| inside(d))
            .collect()
    };
    if decades.len() >= 3 {
        let stride = [1, 2, 3, 5, 10, 20, 50, 100]
            .into_iter()
            .find(|s| decades.len().div_ceil(*s as usize) <= MAX_LOG_TICKS)
            .unwrap_or(100);
        let major: Vec<Dec> = decades
            .iter()
            .filter(|e| e.rem_euclid(stride) == 0)
            .map(|&e| Dec { mant: 1, exp: e })
            .collect();
        let minor = if stride == 1 {
            in_decades(&[2, 3, 4, 5, 6, 7, 8, 9])
        } else {
            decades.iter().map(|&e| Dec { mant: 1, exp: e }).collect()
        };
        return Ticks {
            major: log_labels(&major),
            minor: minor.into_iter().map(Dec::value).collect(),
        };
    }
    let major = in_decades(&[1, 2, 5]);
    if major.len() >= 2 {
        return Ticks {
            major: log_labels(&major),
            minor: in_decades(&[3, 4, 6, 7, 8, 9])
                .into_iter()
                .map(Dec::value)
                .collect(),
        };
    }
    linear(lo, hi, 5)
}

/// Labels of a log axis: positional when every tick lies in `[1e-3, 1e5)`, else scientific
/// (`1e-6`; `1` for one).
fn log_labels(decs: &[Dec]) -> Vec<Tick> {
    let plain = decs.iter().all(|d| (1e-3..1e5).contains(&d.value()));
    decs.iter()
        .map(|&d| Tick {
            value: d.value(),
            label: if plain { d.plain() } else { d.scientific() },
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn labels_of(t: &Ticks) -> Vec<String> {
        t.major.iter().map(|t| t.label.clone()).collect()
    }

    #[test]
    fn a_tick_at_zero_is_zero() {
        // a residual that starts at -1e-20 and a range across zero: plotters' own key points
        // gave values such as -2e-21 here
        for (lo, hi) in [
            (-1e-20, 1.0),
            (-0.3, 0.7),
            (-0.05, 1.05),
            (-1.0, 1e-20),
            (-7.3, 2.1),
        ] {
            let t = linear(lo, hi, 6);
            let zero = t
                .major
                .iter()
                .find(|t| t.value.abs() < 1e-9 * (hi - lo))
                .unwrap_or_else(|| panic!("no tick near 0 in {:?}", labels_of(&t)));
            assert_eq!(zero.value, 0.0, "[{lo}, {hi}]");
            assert_eq!(zero.label, "0", "[{lo}, {hi}]");
            assert!(t.major.iter().all(|t| t.value >= lo && t.value <= hi));
        }
        assert_eq!(
            labels_of(&linear(-0.3, 0.7, 6)),
            ["-0.2", "0", "0.2", "0.4", "0.6"]
        );
        assert_eq!(
            labels_of(&linear(-1e-20, 1.0, 6)),
            ["0", "0.2", "0.4", "0.6", "0.8", "1"]
        );
    }

    #[test]
    fn steps_are_one_two_or_five_times_a_power_of_ten() {
        for (lo, hi, target) in [
            (0.0, 1.0, 5),
            (-3.7, 12.1, 7),
            (1e-9, 3e-9, 6),
            (12.0, 13.0, 8),
            (-2e6, 7e6, 6),
            (0.0, 0.37, 4),
        ] {
            let t = linear(lo, hi, target);
            assert!(t.major.len() >= 2, "{lo} {hi}: {:?}", labels_of(&t));
            assert!(t.major.len() <= 2 * target + 1, "{:?}", labels_of(&t));
            let step = t.major[1].value - t.major[0].value;
            let m = step / 10f64.powf(step.log10().floor());
            assert!(
                [1.0, 2.0, 5.0, 10.0].iter().any(|n| (m - n).abs() < 1e-9),
                "step {step} for [{lo}, {hi}]"
            );
            for w in t.major.windows(2) {
                assert!(((w[1].value - w[0].value) - step).abs() < 1e-9 * step);
            }
        }
    }

    #[test]
    fn labels_are_compact_and_tell_ticks_apart() {
        assert_eq!(
            labels_of(&linear(0.0, 1.0, 5)),
            ["0", "0.2", "0.4", "0.6", "0.8", "1"]
        );
        assert_eq!(
            labels_of(&linear(0.0, 5e-6, 5)),
            ["0", "1e-6", "2e-6", "3e-6", "4e-6", "5e-6"]
        );
        assert_eq!(labels_of(&linear(0.0, 3e5, 3)), ["0", "1e5", "2e5", "3e5"]);
        assert_eq!(
            labels_of(&linear(1000.0, 4000.0, 3)),
            ["1000", "2000", "3000", "4000"]
        );
        // an energy varying by 1e-9 around 12.7436: every label distinct, none rounded away
        let t = linear(12.7436 - 1e-9, 12.7436 + 1e-9, 5);
        let l = labels_of(&t);
        for w in l.windows(2) {
            assert_ne!(w[0], w[1], "{l:?}");
        }
        assert!(l.contains(&"12.7436".to_string()), "{l:?}");
        // ticks around 1e-6 keep enough mantissa digits
        let l = labels_of(&linear(0.999e-6, 1.06e-6, 6));
        assert_eq!(l[0], "1e-6");
        assert_eq!(l[1], "1.01e-6");
    }

    #[test]
    fn log_axes_get_decades_below_one_too() {
        assert_eq!(
            labels_of(&log(1e-6, 1e-2)),
            ["1e-6", "1e-5", "1e-4", "1e-3", "1e-2"]
        );
        assert_eq!(labels_of(&log(0.006, 1.5)), ["0.01", "0.1", "1"]);
        // a ratio of 0.02 .. 1.2 (Paper A Fig. 5): 1-2-5 ticks below 1
        assert_eq!(
            labels_of(&log(0.015, 1.2)),
            ["0.02", "0.05", "0.1", "0.2", "0.5", "1"]
        );
        // many decades: every other one, still starting from a labelled decade
        let t = log(1e-16, 1e4);
        assert!(t.major.len() <= MAX_LOG_TICKS, "{:?}", labels_of(&t));
        assert!(labels_of(&t).contains(&"1".to_string()));
        assert!(labels_of(&t).contains(&"1e-16".to_string()));
        // narrower than a 1-2-5 step: linear ticks
        assert!(log(1.1, 1.3).major.len() >= 2);
        assert!(log(-1.0, 1.0).major.is_empty());
    }
}
