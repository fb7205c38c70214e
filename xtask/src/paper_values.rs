//! The papers' numbers, from `xtask/data/paper_values.json` (compiled in), and their
//! bibliographic references.

use crate::report::PaperValue;
use serde::Deserialize;
use std::sync::OnceLock;

const DATA: &str = include_str!("../data/paper_values.json");

/// A cell of a paper's table: a number, or the legible part of an illegible one.
#[derive(Clone, Debug, Deserialize)]
#[serde(untagged)]
pub enum Cell {
    /// A legible value.
    Num(f64),
    /// What the scan kept (e.g. `"2.8782e-?"`).
    Text(String),
}

impl Cell {
    /// As a report value.
    pub fn value(&'static self) -> PaperValue {
        match self {
            Cell::Num(x) => PaperValue::Value(*x),
            Cell::Text(s) => PaperValue::Illegible(s.as_str()),
        }
    }
}

/// The three references.
#[derive(Clone, Debug, Deserialize)]
pub struct References {
    /// Paper A.
    pub paper_a: String,
    /// Paper B.
    pub paper_b: String,
    /// Paper C.
    pub paper_c: String,
}

/// A table of rows.
#[derive(Clone, Debug, Deserialize)]
pub struct Rows<T> {
    /// The rows.
    pub rows: Vec<T>,
}

/// Paper A's tables.
#[derive(Clone, Debug, Deserialize)]
pub struct PaperA {
    /// Table 1: (s, gamma_T?, [E|dx|, E|dy|, E|dH|]).
    pub table1: Rows<(usize, bool, [f64; 3])>,
    /// Table 2: (s, [dW_1, dW_2, gamma_opt]).
    pub table2: Rows<(usize, [f64; 3])>,
    /// Table 3: (s, gamma = 0 row, gamma_opt row).
    pub table3: Rows<(usize, [f64; 3], [f64; 3])>,
}

/// A row of paper C's tables.
#[derive(Clone, Debug, Deserialize)]
pub struct PaperCRow {
    /// Step size.
    pub h: f64,
    /// e(H).
    pub e_h: Cell,
    /// MRE(H).
    pub mre_h: Cell,
    /// e(Phi).
    pub e_phi: Cell,
    /// e(Phidot).
    pub e_phidot: Cell,
    /// e(Phiddot).
    pub e_phiddot: Cell,
    /// Runtime in seconds.
    pub runtime: f64,
}

/// Paper C's tables.
#[derive(Clone, Debug, Deserialize)]
pub struct PaperC {
    /// Table 1 (FA-DAE rows).
    pub table1: Rows<PaperCRow>,
    /// Table 2's RK4 row.
    pub rk4: PaperCRow,
}

/// Everything in the data file.
#[derive(Clone, Debug, Deserialize)]
pub struct PaperValues {
    /// References.
    pub references: References,
    /// Paper A.
    pub paper_a: PaperA,
    /// Paper C.
    pub paper_c: PaperC,
}

/// The parsed data file (parsed once; its validity is a unit test).
pub fn get() -> Result<&'static PaperValues, String> {
    static CELL: OnceLock<Result<PaperValues, String>> = OnceLock::new();
    CELL.get_or_init(|| {
        serde_json::from_str(DATA).map_err(|e| format!("xtask/data/paper_values.json: {e}"))
    })
    .as_ref()
    .map_err(Clone::clone)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_data_file_parses_and_keeps_the_tables_shapes() {
        let v = get().unwrap();
        assert_eq!(v.paper_a.table1.rows.len(), 8);
        assert_eq!(v.paper_a.table2.rows.len(), 2);
        assert_eq!(v.paper_a.table3.rows.len(), 2);
        assert_eq!(v.paper_c.table1.rows.len(), 3);
        assert!(matches!(v.paper_c.table1.rows[0].e_h, Cell::Text(_)));
        assert!(matches!(
            v.paper_c.table1.rows[2].e_h.value(),
            PaperValue::Value(x) if x == 7.4496e-3
        ));
        assert!(v.references.paper_a.contains("2024"));
    }
}
