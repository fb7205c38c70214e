//! SVG figures (plotters) with the data written as CSV beside each (feature `plot`): what the
//! report of `cargo xtask reproduce` draws, available to any user of the crate.
//!
//! Ticks come from [`crate::ticks`]: round values (1, 2 or 5 times a power of ten; decades on a
//! log axis, below 1 too), a tick at zero labelled `0`, and labels with as many digits as the
//! axis range needs to tell neighbouring ticks apart (an energy that varies by 1e-9 around
//! 12.7436 gets labels such as `12.7436000005`, not twelve labels reading `12.744`).
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
use crate::ticks::{self, Ticks};
use plotters::coord::ranged1d::{KeyPointHint, NoDefaultFormatting, Ranged, ValueFormatter};
use plotters::prelude::*;
use std::ops::Range;
use std::path::Path;

/// Width and height of a figure in pixels.
const SIZE: (u32, u32) = (860, 540);
/// Font size of the tick labels.
const TICK_FONT: u32 = 13;

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
        let x = Axis::new(x0, x1, self.log_x, 8);
        let y = Axis::new(y0, y1, self.log_y, 6);
        self.draw(path, x, y)
            .map_err(|e| io(path, &format!("plotting: {e}")))
    }

    fn draw(&self, path: &Path, x: Axis, y: Axis) -> Result<(), Box<dyn std::error::Error>> {
        // room for the longest y tick label (about 0.6 em a character) and the rotated title
        let widest = y
            .ticks
            .major
            .iter()
            .map(|t| t.label.len())
            .max()
            .unwrap_or(1);
        let y_area = (widest as u32 * TICK_FONT * 6 / 10 + 40).clamp(60, 200);
        let corner = self.emptiest_corner(&x, &y, SIZE.0.saturating_sub(y_area + 28) as f64);
        let root = SVGBackend::new(path, SIZE).into_drawing_area();
        root.fill(&WHITE)?;
        let mut chart = ChartBuilder::on(&root)
            .caption(&self.title, ("sans-serif", 20))
            .margin(14)
            .x_label_area_size(46)
            .y_label_area_size(y_area)
            .build_cartesian_2d(x, y)?;
        chart
            .configure_mesh()
            .x_desc(self.x_label.as_str())
            .y_desc(self.y_label.as_str())
            .label_style(("sans-serif", TICK_FONT))
            .axis_desc_style(("sans-serif", 15))
            .light_line_style(RGBColor(238, 238, 238))
            .bold_line_style(RGBColor(200, 200, 200))
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
            .position(corner)
            .draw()?;
        root.present()?;
        Ok(())
    }

    /// The place along the plot area's border (a corner first, then the middle of a side) where
    /// the series' legend covers the fewest data points (upper right on a tie); `width` is the
    /// plot area's width in pixels.
    fn emptiest_corner(&self, x: &Axis, y: &Axis, width: f64) -> SeriesLabelPosition {
        // the legend's size as fractions of the plot area (about 7 px a character, 20 px a row)
        let longest = self.series.iter().map(|s| s.label.len()).max().unwrap_or(0);
        let w = ((longest as f64 * 7.0 + 60.0) / width.max(1.0)).min(1.0);
        let h = ((self.series.len() as f64 * 20.0 + 20.0) / 430.0).min(1.0);
        let corners = [
            (SeriesLabelPosition::UpperRight, 1.0 - w, 1.0, 1.0 - h, 1.0),
            (SeriesLabelPosition::UpperLeft, 0.0, w, 1.0 - h, 1.0),
            (SeriesLabelPosition::LowerRight, 1.0 - w, 1.0, 0.0, h),
            (SeriesLabelPosition::LowerLeft, 0.0, w, 0.0, h),
            (
                SeriesLabelPosition::MiddleRight,
                1.0 - w,
                1.0,
                0.5 - h / 2.0,
                0.5 + h / 2.0,
            ),
            (
                SeriesLabelPosition::MiddleLeft,
                0.0,
                w,
                0.5 - h / 2.0,
                0.5 + h / 2.0,
            ),
            (
                SeriesLabelPosition::UpperMiddle,
                0.5 - w / 2.0,
                0.5 + w / 2.0,
                1.0 - h,
                1.0,
            ),
            (
                SeriesLabelPosition::LowerMiddle,
                0.5 - w / 2.0,
                0.5 + w / 2.0,
                0.0,
                h,
            ),
        ];
        let mut best = (usize::MAX, SeriesLabelPosition::UpperRight);
        for (pos, x0, x1, y0, y1) in corners {
            let under = self
                .series
                .iter()
                .flat_map(|s| s.x.iter().zip(&s.y))
                .filter(|(px, py)| {
                    let (fx, fy) = (x.fraction(**px), y.fraction(**py));
                    (x0..=x1).contains(&fx) && (y0..=y1).contains(&fy)
                })
                .count();
            if under < best.0 {
                best = (under, pos);
            }
        }
        best.1
    }
}

/// One axis of a figure: its range, linear or logarithmic, and its ticks (plotters draws the
/// labelled ones as bold grid lines with their labels, the others as light lines).
struct Axis {
    lo: f64,
    hi: f64,
    log: bool,
    ticks: Ticks,
}

impl Axis {
    /// About `target` labelled ticks on a linear axis; decades on a log one.
    fn new(lo: f64, hi: f64, log: bool, target: usize) -> Axis {
        let ticks = if log {
            ticks::log(lo, hi)
        } else {
            ticks::linear(lo, hi, target)
        };
        Axis { lo, hi, log, ticks }
    }

    /// Where `v` lies between the ends, as a fraction (0 at `lo`, 1 at `hi`).
    fn fraction(&self, v: f64) -> f64 {
        if self.log {
            (v.ln() - self.lo.ln()) / (self.hi.ln() - self.lo.ln())
        } else {
            (v - self.lo) / (self.hi - self.lo)
        }
    }
}

impl Ranged for Axis {
    type FormatOption = NoDefaultFormatting;
    type ValueType = f64;

    fn map(&self, v: &f64, limit: (i32, i32)) -> i32 {
        let f = self.fraction(*v);
        let f = if f.is_finite() { f } else { 0.0 };
        // `as` saturates: a point far outside the range lands outside the plot, clipped there
        (limit.0 as f64 + f * (limit.1 - limit.0) as f64).round() as i32
    }

    fn key_points<H: KeyPointHint>(&self, hint: H) -> Vec<f64> {
        let mut v: Vec<f64> = self.ticks.major.iter().map(|t| t.value).collect();
        if hint.weight().allow_light_points() {
            v.extend(&self.ticks.minor);
        }
        v
    }

    fn range(&self) -> Range<f64> {
        self.lo..self.hi
    }
}

impl ValueFormatter<f64> for Axis {
    fn format(v: &f64) -> String {
        format!("{v}")
    }
    /// The tick's own label (built from exact decimals, see [`crate::ticks`]).
    fn format_ext(&self, v: &f64) -> String {
        self.ticks
            .major
            .iter()
            .find(|t| t.value == *v)
            .map_or_else(|| format!("{v}"), |t| t.label.clone())
    }
}

#[cfg(test)]
mod tests {
    use super::{Figure, Series};

    /// The text of every `<text>` element of an SVG.
    fn texts(svg: &str) -> Vec<String> {
        svg.split("<text")
            .skip(1)
            .filter_map(|s| {
                let s = &s[s.find('>')? + 1..];
                Some(s[..s.find("</text>")?].trim().to_string())
            })
            .collect()
    }

    /// Draws one curve through `(x, y)` and returns the figure's texts.
    fn drawn(name: &str, fig: Figure) -> Vec<String> {
        let dir = std::env::temp_dir().join(format!("mbd-plot-{name}-{}", std::process::id()));
        let path = dir.join("figure.svg");
        fig.save(&path).unwrap();
        let t = texts(&std::fs::read_to_string(&path).unwrap());
        let _ = std::fs::remove_dir_all(&dir);
        t
    }

    #[test]
    fn a_zero_tick_reads_0() {
        for (k, (lo, hi)) in [(-1e-20, 1.0), (-0.3, 0.7), (-1e-20, 1e-20 + 3.0)]
            .into_iter()
            .enumerate()
        {
            let s: Vec<f64> = (0..=20).map(|k| k as f64 / 20.0).collect();
            let y: Vec<f64> = s.iter().map(|s| lo + (hi - lo) * s).collect();
            let fig = Figure::new("zero", "t [s]", "y [m]").with(Series::line("y", y.clone(), y));
            let labels = drawn(&format!("zero-{k}"), fig);
            assert!(
                labels.iter().filter(|l| *l == "0").count() >= 2,
                "[{lo}, {hi}]: a 0 on both axes: {labels:?}"
            );
            for l in &labels {
                if let Ok(v) = l.parse::<f64>() {
                    assert!(v == 0.0 || v.abs() > 1e-12, "[{lo}, {hi}]: label {l}");
                }
            }
        }
    }

    #[test]
    fn a_log_axis_below_one_has_decade_ticks() {
        let x: Vec<f64> = (0..5).map(f64::from).collect();
        let y: Vec<f64> = x.iter().map(|k| 1e-6 * 10f64.powf(*k)).collect();
        let fig = Figure::new("log", "k", "y")
            .log(false, true)
            .with(Series::points("y", x, y));
        let labels = drawn("log", fig);
        for d in ["1e-6", "1e-5", "1e-4", "1e-3", "1e-2"] {
            assert!(labels.iter().any(|l| l == d), "no tick {d}: {labels:?}");
        }
    }

    #[test]
    fn tiny_variations_get_distinct_labels() {
        // an energy varying by 1e-9 around 12.7436: every label used to read "12.744"
        let t: Vec<f64> = (0..50).map(|k| 0.1 * k as f64).collect();
        let e: Vec<f64> = t.iter().map(|t| 12.7436 + 1e-9 * t.sin()).collect();
        let fig = Figure::new("energy", "t [s]", "H [J]").with(Series::line("H", t, e));
        let labels: Vec<String> = drawn("energy", fig)
            .into_iter()
            .filter(|l| l.starts_with("12.7"))
            .collect();
        assert!(labels.len() >= 3, "{labels:?}");
        for (k, l) in labels.iter().enumerate() {
            assert!(!labels[..k].contains(l), "{l} twice: {labels:?}");
        }
    }
}
