//! SVG figures (plotters) with the data written as CSV beside each (feature `plot`): what the
//! report of `cargo xtask reproduce` draws, available to any user of the crate.
//!
//! Tick labels carry as many digits as the axis range needs to tell neighbouring ticks apart
//! (an energy that varies by 1e-9 around 12.7436 gets labels such as `12.743600001`, not twelve
//! labels reading `12.744`).
//!
//! ```
//! use mbd_analysis::plot::{Figure, Series};
//! let t: Vec<f64> = (0..50).map(|k| 0.1 * k as f64).collect();
//! let e: Vec<f64> = t.iter().map(|t| 12.7436 + 1e-9 * t.sin()).collect();
//! let dir = std::env::temp_dir().join(format!("mbd-plot-doc-{}", std::process::id()));
//! let path = dir.join("energy.svg");
//! Figure::new("energy", "t [s]", "H [J]").with(Series::line("RK4", t, e)).save(&path)?;
//! assert!(std::fs::read_to_string(&path)?.contains("<svg"));
//! assert!(path.with_extension("csv").exists());
//! # std::fs::remove_dir_all(&dir)?;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use crate::error::AnalysisError;
use plotters::coord::ranged1d::{AsRangedCoord, ValueFormatter};
use plotters::prelude::*;
use std::path::Path;

/// One curve.
#[derive(Clone, Debug)]
pub struct Series {
    /// Legend label.
    pub label: String,
    /// Abscissae.
    pub x: Vec<f64>,
    /// Ordinates.
    pub y: Vec<f64>,
    /// Draw markers at the points (for sparse data such as convergence studies).
    pub markers: bool,
}

impl Series {
    /// A line.
    pub fn line(label: impl Into<String>, x: Vec<f64>, y: Vec<f64>) -> Self {
        Series {
            label: label.into(),
            x,
            y,
            markers: false,
        }
    }
    /// A line with markers.
    pub fn points(label: impl Into<String>, x: Vec<f64>, y: Vec<f64>) -> Self {
        Series {
            label: label.into(),
            x,
            y,
            markers: true,
        }
    }
}

/// A 2D chart.
#[derive(Clone, Debug)]
pub struct Figure {
    /// Title.
    pub title: String,
    /// x-axis label with unit, e.g. `"time t [s]"`.
    pub x_label: String,
    /// y-axis label with unit.
    pub y_label: String,
    /// Logarithmic x axis.
    pub log_x: bool,
    /// Logarithmic y axis.
    pub log_y: bool,
    /// Curves.
    pub series: Vec<Series>,
}

impl Figure {
    /// A figure with linear axes.
    pub fn new(
        title: impl Into<String>,
        x_label: impl Into<String>,
        y_label: impl Into<String>,
    ) -> Self {
        Figure {
            title: title.into(),
            x_label: x_label.into(),
            y_label: y_label.into(),
            log_x: false,
            log_y: false,
            series: vec![],
        }
    }
    /// Log scales.
    pub fn log(mut self, x: bool, y: bool) -> Self {
        self.log_x = x;
        self.log_y = y;
        self
    }
    /// Adds a curve.
    pub fn with(mut self, s: Series) -> Self {
        self.series.push(s);
        self
    }

    /// The spacing of neighbouring tick values on a linear axis (about a tenth of the range;
    /// 0 on a log axis, whose ticks differ by factors).
    fn tick_step(&self, xs: bool) -> f64 {
        let log = if xs { self.log_x } else { self.log_y };
        if log {
            return 0.0;
        }
        let (lo, hi) = self.range(xs, false);
        (hi - lo) / 10.0
    }

    fn range(&self, xs: bool, log: bool) -> (f64, f64) {
        let vals = self
            .series
            .iter()
            .flat_map(|s| if xs { s.x.iter() } else { s.y.iter() })
            .copied();
        let vals: Vec<f64> = vals
            .filter(|v| v.is_finite() && (!log || *v > 0.0))
            .collect();
        if vals.is_empty() {
            return if log { (1e-16, 1.0) } else { (0.0, 1.0) };
        }
        let (mut lo, mut hi) = vals
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
                (a.min(v), b.max(v))
            });
        if log {
            lo /= 1.5;
            hi *= 1.5;
        } else {
            let pad = if hi > lo {
                0.05 * (hi - lo)
            } else {
                lo.abs().max(1.0) * 0.05
            };
            lo -= pad;
            hi += pad;
        }
        (lo, hi)
    }

    /// Writes the SVG to `path` and the data to the same path with extension `.csv`
    /// (columns `series,x,y`).
    pub fn save(&self, path: &Path) -> Result<(), AnalysisError> {
        let io = |p: &Path, e: &dyn std::fmt::Display| AnalysisError::Io {
            path: p.display().to_string(),
            message: e.to_string(),
        };
        if let Some(dir) = path.parent() {
            std::fs::create_dir_all(dir).map_err(|e| io(dir, &e))?;
        }
        let mut csv = String::from("series,x,y\n");
        for s in &self.series {
            for (x, y) in s.x.iter().zip(&s.y) {
                csv += &format!("\"{}\",{x:e},{y:e}\n", s.label.replace('"', "'"));
            }
        }
        std::fs::write(path.with_extension("csv"), csv).map_err(|e| io(path, &e))?;
        let (x0, x1) = self.range(true, self.log_x);
        let (y0, y1) = self.range(false, self.log_y);
        let r = match (self.log_x, self.log_y) {
            (false, false) => self.draw(path, x0..x1, y0..y1),
            (true, false) => self.draw(path, (x0..x1).log_scale(), y0..y1),
            (false, true) => self.draw(path, x0..x1, (y0..y1).log_scale()),
            (true, true) => self.draw(path, (x0..x1).log_scale(), (y0..y1).log_scale()),
        };
        r.map_err(|e| io(path, &format!("plotting: {e}")))
    }

    fn draw<X, Y>(&self, path: &Path, xr: X, yr: Y) -> Result<(), Box<dyn std::error::Error>>
    where
        X: AsRangedCoord<Value = f64>,
        Y: AsRangedCoord<Value = f64>,
        X::CoordDescType: ValueFormatter<f64>,
        Y::CoordDescType: ValueFormatter<f64>,
    {
        let (xstep, ystep) = (self.tick_step(true), self.tick_step(false));
        let root = SVGBackend::new(path, (860, 540)).into_drawing_area();
        root.fill(&WHITE)?;
        let mut chart = ChartBuilder::on(&root)
            .caption(&self.title, ("sans-serif", 20))
            .margin(14)
            .x_label_area_size(46)
            .y_label_area_size(78)
            .build_cartesian_2d(xr, yr)?;
        chart
            .configure_mesh()
            .x_desc(self.x_label.as_str())
            .y_desc(self.y_label.as_str())
            .x_label_formatter(&|v| fmt_tick(*v, xstep))
            .y_label_formatter(&|v| fmt_tick(*v, ystep))
            .draw()?;
        let palette = [
            RGBColor(31, 119, 180),
            RGBColor(214, 39, 40),
            RGBColor(44, 160, 44),
            RGBColor(255, 127, 14),
            RGBColor(148, 103, 189),
            RGBColor(140, 86, 75),
            RGBColor(227, 119, 194),
            RGBColor(23, 190, 207),
        ];
        for (i, s) in self.series.iter().enumerate() {
            let color = palette[i % palette.len()];
            let pts: Vec<(f64, f64)> =
                s.x.iter()
                    .zip(&s.y)
                    .filter(|(x, y)| {
                        x.is_finite()
                            && y.is_finite()
                            && (!self.log_x || **x > 0.0)
                            && (!self.log_y || **y > 0.0)
                    })
                    .map(|(x, y)| (*x, *y))
                    .collect();
            chart
                .draw_series(LineSeries::new(pts.clone(), color.stroke_width(2)))?
                .label(s.label.as_str())
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2))
                });
            if s.markers {
                chart.draw_series(pts.iter().map(|&p| Circle::new(p, 4, color.filled())))?;
            }
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .position(SeriesLabelPosition::UpperRight)
            .draw()?;
        root.present()?;
        Ok(())
    }
}

/// A tick label that resolves ticks `step` apart (`step = 0`: log axis, three significant
/// digits suffice).
pub(crate) fn fmt_tick(v: f64, step: f64) -> String {
    let a = v.abs();
    // digits after the decimal point needed to tell ticks `step` apart
    let need = if step > 0.0 && step.is_finite() {
        (-(step.log10()).floor() + 1.0).clamp(0.0, 15.0) as usize
    } else {
        3
    };
    if a != 0.0 && !(1e-3..1e4).contains(&a) {
        // scientific: enough mantissa digits for the step relative to the value
        let mant = if step > 0.0 && step.is_finite() {
            ((a / step).log10().ceil() as i64).clamp(0, 15) as usize
        } else {
            0
        };
        format!("{v:.mant$e}")
    } else {
        let s = format!("{v:.need$}");
        if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s
        }
    }
}

#[cfg(test)]
mod tests {
    use super::fmt_tick;

    #[test]
    fn tick_labels_resolve_neighbouring_ticks() {
        // an energy varying by 1e-9 around 12.7436: every label used to read "12.744"
        let ticks: Vec<f64> = (0..5).map(|k| 12.7436 + 2e-10 * k as f64).collect();
        let labels: Vec<String> = ticks.iter().map(|&v| fmt_tick(v, 2e-10)).collect();
        for w in labels.windows(2) {
            assert_ne!(w[0], w[1], "{labels:?}");
        }
        assert_eq!(fmt_tick(0.5, 0.1), "0.5");
        assert_eq!(fmt_tick(2.0, 0.5), "2");
        // small values in scientific notation keep enough mantissa digits
        let a = fmt_tick(1.0e-6, 1e-8);
        let b = fmt_tick(1.01e-6, 1e-8);
        assert_ne!(a, b);
        // log axes: three significant digits
        assert_eq!(fmt_tick(1e-8, 0.0), "1e-8");
    }
}
