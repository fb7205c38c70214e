//! Reading result CSVs (a header line of column names, then rows of numbers).

use crate::error::CliError;
use std::path::Path;

/// The largest result file `mbd plot` reads (1 GiB: about 5 million rows of a 10-body model).
pub const MAX_TABLE_BYTES: u64 = 1 << 30;

/// A CSV result: named columns of numbers.
#[derive(Clone, Debug, PartialEq)]
pub struct Table {
    /// The file it was read from (for messages).
    pub path: String,
    /// Column names.
    pub names: Vec<String>,
    /// Rows, each as long as `names`.
    pub rows: Vec<Vec<f64>>,
}

impl Table {
    /// Reads a result file: CSV, or the JSON that `mbd run --out FILE.json` writes (by the
    /// extension `.json`); errors name the file and the line (CSV) or what is missing (JSON).
    pub fn read(path: &Path) -> Result<Table, CliError> {
        let text =
            mbd_model::read_text(path, MAX_TABLE_BYTES).map_err(|e| CliError::read(path, e))?;
        let name = path.display().to_string();
        match path.extension().and_then(|e| e.to_str()) {
            Some(e) if e.eq_ignore_ascii_case("json") => Table::parse_json(&name, &text),
            _ => Table::parse(&name, &text),
        }
    }

    /// Parses the JSON of `mbd run` (`"columns"`: names, `"rows"`: rows of numbers; `null`
    /// entries, written for non-finite values, read as NaN).
    pub fn parse_json(path: &str, text: &str) -> Result<Table, CliError> {
        let bad = |message: String| CliError::Json {
            path: path.to_string(),
            message,
        };
        let doc: serde_json::Value =
            serde_json::from_str(text).map_err(|e| bad(format!("not JSON: {e}")))?;
        let names: Vec<String> = doc["columns"]
            .as_array()
            .ok_or_else(|| bad("no \"columns\" list".into()))?
            .iter()
            .map(|c| c.as_str().map(String::from))
            .collect::<Option<_>>()
            .ok_or_else(|| bad("\"columns\" must hold names".into()))?;
        let rows_json = doc["rows"]
            .as_array()
            .ok_or_else(|| bad("no \"rows\" list".into()))?;
        let mut rows = Vec::with_capacity(rows_json.len());
        for (i, r) in rows_json.iter().enumerate() {
            let row: Vec<f64> = r
                .as_array()
                .ok_or_else(|| bad(format!("row {i} is not a list")))?
                .iter()
                .map(|x| {
                    if x.is_null() {
                        Some(f64::NAN)
                    } else {
                        x.as_f64()
                    }
                })
                .collect::<Option<_>>()
                .ok_or_else(|| bad(format!("row {i} holds a value that is not a number")))?;
            if row.len() != names.len() {
                return Err(bad(format!(
                    "row {i}: {} values for {} columns",
                    row.len(),
                    names.len()
                )));
            }
            rows.push(row);
        }
        if rows.is_empty() {
            return Err(bad("no rows of data".into()));
        }
        Ok(Table {
            path: path.to_string(),
            names,
            rows,
        })
    }

    /// Parses CSV text (`path` is used in messages).
    pub fn parse(path: &str, text: &str) -> Result<Table, CliError> {
        let bad = |line: usize, message: String| CliError::Csv {
            path: path.to_string(),
            line,
            message,
        };
        let mut lines = text
            .lines()
            .enumerate()
            .filter(|(_, l)| !l.trim().is_empty());
        let names: Vec<String> = match lines.next() {
            Some((_, head)) => head.split(',').map(|c| c.trim().to_string()).collect(),
            None => return Err(bad(1, "the file is empty".into())),
        };
        if names.iter().any(|n| n.parse::<f64>().is_ok()) {
            return Err(bad(1, "the first line must name the columns".into()));
        }
        let mut rows = Vec::new();
        for (i, l) in lines {
            let row: Vec<f64> = l
                .split(',')
                .map(|x| {
                    let x = x.trim();
                    x.parse::<f64>()
                        .map_err(|_| bad(i + 1, format!("'{x}' is not a number")))
                })
                .collect::<Result<_, _>>()?;
            if row.len() != names.len() {
                return Err(bad(
                    i + 1,
                    format!("{} values for {} columns", row.len(), names.len()),
                ));
            }
            rows.push(row);
        }
        if rows.is_empty() {
            return Err(bad(2, "no rows of data".into()));
        }
        Ok(Table {
            path: path.to_string(),
            names,
            rows,
        })
    }

    /// The index of column `name`, or an error listing the available columns.
    pub fn column_index(&self, name: &str) -> Result<usize, CliError> {
        self.names
            .iter()
            .position(|n| n == name)
            .ok_or_else(|| CliError::UnknownColumn {
                column: name.to_string(),
                path: self.path.clone(),
                available: self.names.join(", "),
            })
    }

    /// The values of column `name`.
    pub fn column(&self, name: &str) -> Result<Vec<f64>, CliError> {
        let k = self.column_index(name)?;
        Ok(self.rows.iter().map(|r| r[k]).collect())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_and_reports_bad_lines() {
        let t = Table::parse("r.csv", "t,a.x\n0,1\n0.1,2e0\n").unwrap();
        assert_eq!(t.column("a.x").unwrap(), vec![1.0, 2.0]);
        let e = t.column("b").unwrap_err().to_string();
        assert!(e.contains("'b'") && e.contains("t, a.x"), "{e}");
        let e = Table::parse("r.csv", "t,a\n0,1\n1,zz\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("line 3") && e.contains("'zz'"), "{e}");
        let e = Table::parse("r.csv", "t,a\n0,1,2\n")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("line 2") && e.contains("3 values for 2 columns"),
            "{e}"
        );
        assert!(Table::parse("r.csv", "").is_err());
        assert!(Table::parse("r.csv", "1,2\n3,4\n").is_err());
    }

    #[test]
    fn parses_the_json_of_mbd_run() {
        let t = Table::parse_json(
            "r.json",
            r#"{"columns": ["t", "a.x"], "rows": [[0.0, 1.0], [0.1, null]], "summary": {}}"#,
        )
        .unwrap();
        assert_eq!(t.column("t").unwrap(), vec![0.0, 0.1]);
        assert!(t.column("a.x").unwrap()[1].is_nan());
        let e = Table::parse_json("r.json", r#"{"rows": []}"#)
            .unwrap_err()
            .to_string();
        assert!(e.contains("no \"columns\" list"), "{e}");
        let e = Table::parse_json("r.json", r#"{"columns": ["t"], "rows": [[0.0, 1.0]]}"#)
            .unwrap_err()
            .to_string();
        assert!(e.contains("row 0: 2 values for 1 columns"), "{e}");
    }
}
