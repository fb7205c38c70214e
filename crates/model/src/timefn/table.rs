//! Tabulated functions of time (see [`Table`]).

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use std::borrow::Cow;
use std::cell::RefCell;
use std::path::{Path, PathBuf};
use thiserror::Error;

/// How a [`Table`] interpolates between its samples.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum Interpolation {
    /// Straight lines between samples: continuous, its first derivative jumps at the samples
    /// and its second derivative is zero (a driver's accelerations jump there).
    Linear,
    /// The natural cubic spline: value, first and second derivative continuous.
    #[default]
    CubicSpline,
}

/// What a [`Table`] gives outside its first and last sample time.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum Extrapolation {
    /// The end value, with zero derivatives (the first derivative jumps at the end unless the
    /// table ends flat).
    #[default]
    Hold,
    /// The straight line with the end's value and slope (for the natural spline this keeps the
    /// function C2, its second derivative being zero at the ends).
    Linear,
}

/// Why a table cannot be built.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum TableError {
    /// Fewer than two samples.
    #[error("a table needs at least 2 samples, got {0}")]
    TooFewSamples(usize),
    /// The time and value columns differ in length.
    #[error("a table's 't' has {t} entries but 'values' has {values}")]
    Length {
        /// Entries of `t`.
        t: usize,
        /// Entries of `values`.
        values: usize,
    },
    /// A sample is NaN or infinite.
    #[error("sample {index} is not finite (t = {t}, value = {value})")]
    NotFinite {
        /// The sample's index (from 0).
        index: usize,
        /// Its time.
        t: f64,
        /// Its value.
        value: f64,
    },
    /// The sample times do not strictly increase.
    #[error(
        "sample times must strictly increase: t[{index}] = {t} does not exceed t[{}] = {previous}",
        index - 1
    )]
    NotIncreasing {
        /// The index of the offending sample (from 0).
        index: usize,
        /// Its time.
        t: f64,
        /// The time before it.
        previous: f64,
    },
    /// A table gives both inline samples and a file, or neither.
    #[error("a table gives its samples either inline ('t' and 'values') or as 'file', not {0}")]
    Source(&'static str),
    /// The table file could not be read.
    #[error("table file '{path}': {message}")]
    Io {
        /// The file.
        path: String,
        /// What went wrong.
        message: String,
    },
    /// A line of the table file does not parse.
    #[error("table file '{path}', line {line}: {message}")]
    Csv {
        /// The file.
        path: String,
        /// The line (from 1).
        line: usize,
        /// What is wrong with it.
        message: String,
    },
}

/// The largest table file read: far above any measured input (a million samples in CSV are
/// about 40 MB), and a device such as `/dev/zero` is refused instead of read forever.
pub const MAX_TABLE_FILE_BYTES: u64 = 64 << 20;

/// A tabulated function of time: samples `(t_i, y_i)` interpolated linearly or by a natural
/// cubic spline, given inline or read from a CSV file.
///
/// The natural spline `s` is the C2 piecewise cubic through the samples with `s'' = 0` at both
/// ends. Its second derivatives `M_i = s''(t_i)` solve the tridiagonal system
///
/// ```text
/// h_{i-1} M_{i-1} + 2 (h_{i-1} + h_i) M_i + h_i M_{i+1} = 6 (d_i - d_{i-1}),   i = 1..n-2,
/// ```
///
/// with `h_i = t_{i+1} - t_i`, `d_i = (y_{i+1} - y_i) / h_i` and `M_0 = M_{n-1} = 0`
/// (diagonally dominant, so the Thomas algorithm needs no pivoting). On `[t_i, t_{i+1}]`, with
/// `a = (t_{i+1} - t) / h_i` and `b = 1 - a`,
///
/// ```text
/// s   = a y_i + b y_{i+1} + ((a^3 - a) M_i + (b^3 - b) M_{i+1}) h_i^2 / 6
/// s'  = d_i + (-(3 a^2 - 1) M_i + (3 b^2 - 1) M_{i+1}) h_i / 6
/// s'' = a M_i + b M_{i+1}.
/// ```
///
/// The interpolation error of a smooth function is O(h^4) in the value, O(h^3) in the first
/// and O(h^2) in the second derivative away from the ends (the natural end condition costs
/// O(h^2) near them unless the function's second derivative vanishes there).
///
///
/// ```
/// use mbd_model::{Interpolation, Table, TimeFunction};
/// let table = Table::new(vec![0.0, 1.0, 2.0], vec![0.0, 1.0, 0.0], Interpolation::Linear)?;
/// let f = TimeFunction::Table(table);
/// assert_eq!(f.eval(0.5), [0.5, 1.0, 0.0]);
/// # Ok::<(), mbd_model::TableError>(())
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "TableSpec", into = "TableSpec")]
pub struct Table {
    t: Vec<f64>,
    y: Vec<f64>,
    /// Second derivatives at the samples (all zero for linear interpolation).
    m: Vec<f64>,
    interpolation: Interpolation,
    extrapolation: Extrapolation,
}

impl Table {
    /// A table through the samples `(t[i], values[i])`, holding its end values outside them.
    pub fn new(
        t: Vec<f64>,
        values: Vec<f64>,
        interpolation: Interpolation,
    ) -> Result<Table, TableError> {
        if t.len() != values.len() {
            return Err(TableError::Length {
                t: t.len(),
                values: values.len(),
            });
        }
        if t.len() < 2 {
            return Err(TableError::TooFewSamples(t.len()));
        }
        for (index, (&ti, &yi)) in t.iter().zip(&values).enumerate() {
            if !ti.is_finite() || !yi.is_finite() {
                return Err(TableError::NotFinite {
                    index,
                    t: ti,
                    value: yi,
                });
            }
            if index > 0 && ti <= t[index - 1] {
                return Err(TableError::NotIncreasing {
                    index,
                    t: ti,
                    previous: t[index - 1],
                });
            }
        }
        let m = match interpolation {
            Interpolation::Linear => vec![0.0; t.len()],
            Interpolation::CubicSpline => natural_spline_moments(&t, &values),
        };
        Ok(Table {
            t,
            y: values,
            m,
            interpolation,
            extrapolation: Extrapolation::Hold,
        })
    }

    /// Reads the samples from a CSV file: one sample per line, fields separated by commas,
    /// semicolons or white space; blank lines and lines starting with `#` are skipped. The
    /// first column is the time; the value is the column named `column` in a header line, or
    /// the second column when `column` is `None`. A header line (the first line that is not
    /// all numbers) is optional without `column`.
    pub fn from_csv(
        path: &Path,
        column: Option<&str>,
        interpolation: Interpolation,
    ) -> Result<Table, TableError> {
        let name = path.display().to_string();
        let text =
            crate::file::read_text(path, MAX_TABLE_FILE_BYTES).map_err(|e| TableError::Io {
                path: name.clone(),
                message: e.to_string(),
            })?;
        let (t, y) = parse_csv(&text, column).map_err(|(line, message)| TableError::Csv {
            path: name,
            line,
            message,
        })?;
        Table::new(t, y, interpolation)
    }

    /// The same table with another rule outside its sample times.
    pub fn with_extrapolation(mut self, extrapolation: Extrapolation) -> Table {
        self.extrapolation = extrapolation;
        self
    }

    /// The sample times.
    pub fn times(&self) -> &[f64] {
        &self.t
    }
    /// The sample values.
    pub fn values(&self) -> &[f64] {
        &self.y
    }
    /// The interpolation rule.
    pub fn interpolation(&self) -> Interpolation {
        self.interpolation
    }
    /// The rule outside the sample times.
    pub fn extrapolation(&self) -> Extrapolation {
        self.extrapolation
    }

    /// Whether every sample has the same value.
    pub(crate) fn is_constant(&self) -> bool {
        self.y.iter().all(|&v| v == self.y[0])
    }

    /// `(f(t), f'(t), f''(t))`: O(log n) to find the interval, then O(1).
    pub(crate) fn eval(&self, t: f64) -> [f64; 3] {
        let n = self.t.len();
        let (first, last) = (self.t[0], self.t[n - 1]);
        if t < first || t > last {
            let (i, end) = if t < first { (0, first) } else { (n - 2, last) };
            let [v, d, _] = self.inside(i, end);
            return match self.extrapolation {
                Extrapolation::Hold => [v, 0.0, 0.0],
                Extrapolation::Linear => [v + d * (t - end), d, 0.0],
            };
        }
        // The interval [t_i, t_{i+1}] holding t (the last one for t = t_{n-1}).
        let i = self.t.partition_point(|&ti| ti <= t).clamp(1, n - 1) - 1;
        self.inside(i, t)
    }

    /// The interpolant of interval `i` at `t`.
    fn inside(&self, i: usize, t: f64) -> [f64; 3] {
        let h = self.t[i + 1] - self.t[i];
        let (y0, y1, m0, m1) = (self.y[i], self.y[i + 1], self.m[i], self.m[i + 1]);
        let a = (self.t[i + 1] - t) / h;
        let b = 1.0 - a;
        let slope = (y1 - y0) / h;
        [
            a * y0 + b * y1 + ((a * a * a - a) * m0 + (b * b * b - b) * m1) * h * h / 6.0,
            slope + (-(3.0 * a * a - 1.0) * m0 + (3.0 * b * b - 1.0) * m1) * h / 6.0,
            a * m0 + b * m1,
        ]
    }
}

/// Second derivatives of the natural cubic spline through `(t, y)` (Thomas algorithm on the
/// tridiagonal system of the module docs).
fn natural_spline_moments(t: &[f64], y: &[f64]) -> Vec<f64> {
    let n = t.len();
    let mut m = vec![0.0; n];
    if n < 3 {
        return m;
    }
    // Forward elimination over the interior unknowns M_1..M_{n-2}: diag and rhs overwritten.
    let mut diag = vec![0.0; n];
    let mut rhs = vec![0.0; n];
    for i in 1..n - 1 {
        let (h0, h1) = (t[i] - t[i - 1], t[i + 1] - t[i]);
        diag[i] = 2.0 * (h0 + h1);
        rhs[i] = 6.0 * ((y[i + 1] - y[i]) / h1 - (y[i] - y[i - 1]) / h0);
        if i > 1 {
            let w = h0 / diag[i - 1];
            diag[i] -= w * h0;
            rhs[i] -= w * rhs[i - 1];
        }
    }
    for i in (1..n - 1).rev() {
        let h1 = t[i + 1] - t[i];
        m[i] = (rhs[i] - h1 * m[i + 1]) / diag[i];
    }
    m
}

/// Splits a CSV line into fields.
fn fields(line: &str) -> impl Iterator<Item = &str> {
    line.split(|c: char| c == ',' || c == ';' || c.is_whitespace())
        .filter(|f| !f.is_empty())
}

/// The time column and the chosen value column of a CSV text; errors carry the line number.
fn parse_csv(text: &str, column: Option<&str>) -> Result<(Vec<f64>, Vec<f64>), (usize, String)> {
    let mut value_col = if column.is_none() { Some(1) } else { None };
    let mut seen_data = false;
    let (mut t, mut y) = (Vec::new(), Vec::new());
    for (k, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let row: Vec<&str> = fields(line).collect();
        let numbers: Option<Vec<f64>> = row.iter().map(|f| f.parse::<f64>().ok()).collect();
        let Some(numbers) = numbers else {
            if seen_data {
                return Err((k + 1, format!("'{line}' is not a row of numbers")));
            }
            if let Some(name) = column {
                let index = row.iter().position(|f| *f == name).ok_or_else(|| {
                    (
                        k + 1,
                        format!("no column named '{name}' in the header (columns: {row:?})"),
                    )
                })?;
                if index == 0 {
                    return Err((k + 1, format!("column '{name}' is the time column")));
                }
                value_col = Some(index);
            }
            seen_data = true;
            continue;
        };
        seen_data = true;
        let Some(c) = value_col else {
            return Err((
                k + 1,
                format!(
                    "the file has no header line naming column '{}'",
                    column.unwrap_or("")
                ),
            ));
        };
        let value = numbers.get(c).ok_or_else(|| {
            (
                k + 1,
                format!(
                    "{} field(s), the value column is number {}",
                    numbers.len(),
                    c + 1
                ),
            )
        })?;
        t.push(numbers[0]);
        y.push(*value);
    }
    Ok((t, y))
}

thread_local! {
    /// The directory relative table paths are read from while a model file is parsed.
    static BASE_DIR: RefCell<Option<PathBuf>> = const { RefCell::new(None) };
}

/// Runs `f` (a parse of a model file) with relative table paths resolved against `dir`; the
/// previous directory is restored afterwards, also when `f` panics.
pub(crate) fn with_base_dir<R>(dir: Option<&Path>, f: impl FnOnce() -> R) -> R {
    struct Restore(Option<PathBuf>);
    impl Drop for Restore {
        fn drop(&mut self) {
            let old = self.0.take();
            BASE_DIR.with(|b| *b.borrow_mut() = old);
        }
    }
    let old = BASE_DIR.with(|b| b.replace(dir.map(Path::to_path_buf)));
    let _restore = Restore(old);
    f()
}

/// A table in a model file: the samples inline (`t` and `values`) or in a CSV `file` (a path
/// relative to the model file), read when the model is loaded. Written back inline.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct TableSpec {
    /// Sample times, strictly increasing (s).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub t: Vec<f64>,
    /// The values at the sample times.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub values: Vec<f64>,
    /// A CSV file of samples instead of `t` and `values` (see `docs/model-files.md`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub file: Option<String>,
    /// The value column's name in the file's header (default: the second column).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub column: Option<String>,
    /// `"cubic_spline"` (default) or `"linear"`.
    #[serde(default)]
    pub interpolation: Interpolation,
    /// Outside the sample times: `"hold"` (default) or `"linear"`.
    #[serde(default)]
    pub extrapolation: Extrapolation,
}

impl TryFrom<TableSpec> for Table {
    type Error = TableError;
    fn try_from(s: TableSpec) -> Result<Table, TableError> {
        let table = match (&s.file, s.t.is_empty() && s.values.is_empty()) {
            (Some(file), true) => {
                let path = BASE_DIR.with(|b| match &*b.borrow() {
                    Some(dir) => dir.join(file),
                    None => PathBuf::from(file),
                });
                Table::from_csv(&path, s.column.as_deref(), s.interpolation)?
            }
            (Some(_), false) => return Err(TableError::Source("both")),
            (None, _) if s.column.is_some() => {
                return Err(TableError::Source("'column' without 'file'"))
            }
            (None, _) => Table::new(s.t, s.values, s.interpolation)?,
        };
        Ok(table.with_extrapolation(s.extrapolation))
    }
}

impl From<Table> for TableSpec {
    fn from(t: Table) -> TableSpec {
        TableSpec {
            t: t.t,
            values: t.y,
            file: None,
            column: None,
            interpolation: t.interpolation,
            extrapolation: t.extrapolation,
        }
    }
}

impl JsonSchema for Table {
    fn schema_name() -> Cow<'static, str> {
        TableSpec::schema_name()
    }
    fn json_schema(generator: &mut schemars::SchemaGenerator) -> schemars::Schema {
        TableSpec::json_schema(generator)
    }
}

#[cfg(test)]
mod tests;
