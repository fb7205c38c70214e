#![allow(dead_code)] // the frame offers more than every experiment uses
//! SVG figures (plotters) with the data written as CSV beside each.

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
    /// x-axis label with unit, e.g. "time t [s]".
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
    pub fn save(&self, path: &Path) -> Result<(), String> {
        if let Some(dir) = path.parent() {
            std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
        }
        let mut csv = String::from("series,x,y\n");
        for s in &self.series {
            for (x, y) in s.x.iter().zip(&s.y) {
                csv += &format!("\"{}\",{x:e},{y:e}\n", s.label.replace('"', "'"));
            }
        }
        std::fs::write(path.with_extension("csv"), csv)
            .map_err(|e| format!("{}: {e}", path.display()))?;
        let (x0, x1) = self.range(true, self.log_x);
        let (y0, y1) = self.range(false, self.log_y);
        let r = match (self.log_x, self.log_y) {
            (false, false) => self.draw(path, x0..x1, y0..y1),
            (true, false) => self.draw(path, (x0..x1).log_scale(), y0..y1),
            (false, true) => self.draw(path, x0..x1, (y0..y1).log_scale()),
            (true, true) => self.draw(path, (x0..x1).log_scale(), (y0..y1).log_scale()),
        };
        r.map_err(|e| format!("plotting {}: {e}", path.display()))
    }

    fn draw<X, Y>(&self, path: &Path, xr: X, yr: Y) -> Result<(), Box<dyn std::error::Error>>
    where
        X: AsRangedCoord<Value = f64>,
        Y: AsRangedCoord<Value = f64>,
        X::CoordDescType: ValueFormatter<f64>,
        Y::CoordDescType: ValueFormatter<f64>,
    {
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
            .x_label_formatter(&|v| fmt_tick(*v))
            .y_label_formatter(&|v| fmt_tick(*v))
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

fn fmt_tick(v: f64) -> String {
    let a = v.abs();
    if a != 0.0 && !(1e-3..1e4).contains(&a) {
        format!("{v:.0e}")
    } else {
        let s = format!("{v:.3}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    }
}
