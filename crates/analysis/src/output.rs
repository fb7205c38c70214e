//! CSV and JSON writers for time series.

use crate::error::AnalysisError;
use mbd_model::System;
use mbd_solve::{Flow, Observer, SolveError, State};
use serde::Serialize;
use std::io::Write;
use std::path::Path;

/// Named columns of equal length.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct TimeSeries {
    /// Column names (the first is usually `t`).
    pub names: Vec<String>,
    /// Columns.
    pub columns: Vec<Vec<f64>>,
}

impl TimeSeries {
    /// An empty series with the given column names.
    pub fn new<S: Into<String>>(names: impl IntoIterator<Item = S>) -> Self {
        let names: Vec<String> = names.into_iter().map(Into::into).collect();
        let columns = vec![Vec::new(); names.len()];
        TimeSeries { names, columns }
    }
    /// Appends a row.
    pub fn push(&mut self, row: &[f64]) -> Result<(), AnalysisError> {
        if row.len() != self.names.len() {
            return Err(AnalysisError::Dimension {
                what: "time series row",
                expected: self.names.len(),
                got: row.len(),
            });
        }
        for (c, &x) in self.columns.iter_mut().zip(row) {
            c.push(x);
        }
        Ok(())
    }
    /// Number of rows.
    pub fn len(&self) -> usize {
        self.columns.first().map_or(0, Vec::len)
    }
    /// Whether there are no rows.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
    /// Writes CSV (header line, then rows; full precision).
    pub fn write_csv<W: Write>(&self, mut w: W) -> std::io::Result<()> {
        writeln!(w, "{}", self.names.join(","))?;
        for r in 0..self.len() {
            let row: Vec<String> = self.columns.iter().map(|c| format!("{:e}", c[r])).collect();
            writeln!(w, "{}", row.join(","))?;
        }
        Ok(())
    }
    /// Writes CSV to a file.
    pub fn save_csv(&self, path: impl AsRef<Path>) -> Result<(), AnalysisError> {
        let p = path.as_ref();
        let io = |e: std::io::Error| AnalysisError::Io {
            path: p.display().to_string(),
            message: e.to_string(),
        };
        let f = std::fs::File::create(p).map_err(io)?;
        self.write_csv(std::io::BufWriter::new(f)).map_err(io)
    }
    /// JSON object `{ name: [values...] }` (non-finite values become null).
    pub fn to_json(&self) -> serde_json::Value {
        let mut m = serde_json::Map::new();
        for (n, c) in self.names.iter().zip(&self.columns) {
            m.insert(n.clone(), serde_json::Value::from(c.clone()));
        }
        serde_json::Value::Object(m)
    }
    /// Writes JSON to a file.
    pub fn save_json(&self, path: impl AsRef<Path>) -> Result<(), AnalysisError> {
        let p = path.as_ref();
        let s = serde_json::to_string_pretty(&self.to_json()).map_err(|e| AnalysisError::Io {
            path: p.display().to_string(),
            message: e.to_string(),
        })?;
        std::fs::write(p, s).map_err(|e| AnalysisError::Io {
            path: p.display().to_string(),
            message: e.to_string(),
        })
    }
}

/// An [`Observer`] that streams `t, q..., v..., H` rows as CSV to a writer, keeping nothing in
/// memory (for long runs).
pub struct CsvObserver<W: Write> {
    w: W,
    header_written: bool,
}

impl<W: Write> CsvObserver<W> {
    /// Streams to `w` (wrap files in a `BufWriter`).
    pub fn new(w: W) -> Self {
        CsvObserver {
            w,
            header_written: false,
        }
    }
    /// The writer back.
    pub fn into_inner(self) -> W {
        self.w
    }
}

impl<W: Write> Observer for CsvObserver<W> {
    fn observe(&mut self, sys: &System, s: &State, _step: usize) -> Result<Flow, SolveError> {
        let err = |e: std::io::Error| SolveError::Observer {
            t: s.t,
            message: e.to_string(),
        };
        if !self.header_written {
            let mut h = vec!["t".to_string()];
            let names = sys.coordinate_names();
            h.extend(names.iter().cloned());
            h.extend(names.iter().map(|n| format!("d_{n}")));
            h.push("H".into());
            writeln!(self.w, "{}", h.join(",")).map_err(err)?;
            self.header_written = true;
        }
        write!(self.w, "{:e}", s.t).map_err(err)?;
        for x in s.q.iter().chain(s.v.iter()) {
            write!(self.w, ",{x:e}").map_err(err)?;
        }
        writeln!(self.w, ",{:e}", sys.energy(s.q.as_slice(), s.v.as_slice())).map_err(err)?;
        Ok(Flow::Continue)
    }
}
