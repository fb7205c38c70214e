#![allow(dead_code)] // the frame offers more than every experiment uses
//! The report frame: experiments, their sections (tables, figures, claims, summary JSON), and
//! the writers of `REPORT.md` and `summary.json`.

use serde_json::{Map, Value};
use std::path::PathBuf;

/// Which part of the report an experiment belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Part {
    /// Paper A (symplectic).
    PaperA,
    /// Paper B (tangent space).
    PaperB,
    /// Paper C (firefly).
    PaperC,
    /// The project's own experiments.
    Own,
}

impl Part {
    /// The CLI / JSON name.
    pub fn key(self) -> &'static str {
        match self {
            Part::PaperA => "paper_a",
            Part::PaperB => "paper_b",
            Part::PaperC => "paper_c",
            Part::Own => "own",
        }
    }
    /// Heading in the report.
    pub fn title(self) -> &'static str {
        match self {
            Part::PaperA => "Paper A: parameter-preadjusted symplectic algorithm",
            Part::PaperB => "Paper B: tangent-space parameterisation",
            Part::PaperC => "Paper C: firefly algorithm for the DAE",
            Part::Own => "The project's own experiments",
        }
    }
}

/// What every experiment gets.
#[derive(Clone, Debug)]
pub struct Ctx {
    /// Shortened runs (CI): must still exercise every code path of the experiment.
    pub quick: bool,
    /// Output directory (figures go to `out/figures`).
    pub out: PathBuf,
    /// Threads available to the experiment for its own parallel work (1 = serial).
    pub jobs: usize,
}

impl Ctx {
    /// Path of a figure file (SVG) or its data (CSV) in `out/figures`.
    pub fn figure_path(&self, file: &str) -> PathBuf {
        self.out.join("figures").join(file)
    }
}

/// An experiment: a named function producing a [`Section`].
pub struct Experiment {
    /// Short id, e.g. "paper-a-table1".
    pub id: &'static str,
    /// Part of the report.
    pub part: Part,
    /// Title.
    pub title: &'static str,
    /// The experiment.
    pub run: fn(&Ctx) -> Result<Section, String>,
}

/// Whether a claim held.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Verdict {
    /// It held.
    Held,
    /// It did not.
    NotHeld,
    /// It could not be checked (say why in the evidence).
    NotChecked,
}

/// A claim of a paper (or of the project) and what we measured.
#[derive(Clone, Debug)]
pub struct Claim {
    /// The claim, as stated.
    pub text: String,
    /// Held or not.
    pub verdict: Verdict,
    /// The measured numbers.
    pub evidence: String,
    /// A claim on wall-clock time: its verdict depends on the machine and its load, so it is
    /// kept apart in the determinism check and not enforced by `--strict` in quick mode.
    pub timing: bool,
    /// Documented as an expected miss, with the reason (shown in the report): `--strict` does
    /// not fail on it.
    pub expected_miss: Option<String>,
}

impl Claim {
    /// A claim checked by a boolean.
    pub fn check(text: impl Into<String>, held: bool, evidence: impl Into<String>) -> Self {
        Claim {
            text: text.into(),
            verdict: if held {
                Verdict::Held
            } else {
                Verdict::NotHeld
            },
            evidence: evidence.into(),
            timing: false,
            expected_miss: None,
        }
    }

    /// A claim that this run could not check, and why.
    pub fn not_checked(text: impl Into<String>, why: impl Into<String>) -> Self {
        Claim {
            verdict: Verdict::NotChecked,
            ..Claim::check(text, true, why)
        }
    }

    /// A claim on measured wall-clock time (see [`Claim::timing`]).
    pub fn timing(text: impl Into<String>, held: bool, evidence: impl Into<String>) -> Self {
        Claim {
            timing: true,
            ..Claim::check(text, held, evidence)
        }
    }

    /// Marks the claim as an expected miss with its reason (the reason is shown in the report
    /// whether or not the claim holds).
    pub fn expected_miss(mut self, reason: impl Into<String>) -> Self {
        self.expected_miss = Some(reason.into());
        self
    }

    /// Whether `--strict` fails on this claim: it did not hold, it is not a documented
    /// expected miss, and it is not a timing claim of a quick run.
    pub fn fails_strict(&self, quick: bool) -> bool {
        self.verdict == Verdict::NotHeld && self.expected_miss.is_none() && !(quick && self.timing)
    }

    /// The claim as a `summary.json` entry.
    pub fn json(&self, part: Part, experiment: &str) -> Value {
        let held = match self.verdict {
            Verdict::Held => Value::Bool(true),
            Verdict::NotHeld => Value::Bool(false),
            Verdict::NotChecked => Value::Null,
        };
        let mut v = serde_json::json!({
            "part": part.key(),
            "experiment": experiment,
            "claim": self.text,
            "held": held,
            "measured": self.evidence,
            "timing": self.timing,
        });
        if let (Some(r), Value::Object(m)) = (&self.expected_miss, &mut v) {
            m.insert("expected_miss".into(), Value::String(r.clone()));
        }
        v
    }
}

/// A figure written by the experiment (SVG, with its CSV beside it).
#[derive(Clone, Debug)]
pub struct FigureRef {
    /// File name inside `figures/` (the SVG).
    pub file: String,
    /// Caption.
    pub caption: String,
}

/// A Markdown table.
#[derive(Clone, Debug, Default)]
pub struct Table {
    /// Caption shown above.
    pub caption: String,
    /// Column headers.
    pub headers: Vec<String>,
    /// Rows of cells.
    pub rows: Vec<Vec<String>>,
}

impl Table {
    /// A table with a caption and headers.
    pub fn new(caption: impl Into<String>, headers: &[&str]) -> Self {
        Table {
            caption: caption.into(),
            headers: headers.iter().map(|s| s.to_string()).collect(),
            rows: vec![],
        }
    }
    /// Adds a row.
    pub fn row(&mut self, cells: Vec<String>) {
        self.rows.push(cells);
    }
    /// Markdown text.
    pub fn to_markdown(&self) -> String {
        let mut s = String::new();
        if !self.caption.is_empty() {
            s += &format!("**{}**\n\n", self.caption);
        }
        s += &format!("| {} |\n", self.headers.join(" | "));
        s += &format!("|{}\n", "---|".repeat(self.headers.len()));
        for r in &self.rows {
            s += &format!("| {} |\n", r.join(" | "));
        }
        s
    }
}

/// The output of one experiment.
#[derive(Clone, Debug, Default)]
pub struct Section {
    /// Settings used (name, value), including seeds.
    pub settings: Vec<(String, String)>,
    /// Tables.
    pub tables: Vec<Table>,
    /// Free Markdown text (notes, readings of illegible values).
    pub notes: Vec<String>,
    /// Figures.
    pub figures: Vec<FigureRef>,
    /// Claims checked.
    pub claims: Vec<Claim>,
    /// JSON merged (deeply) into `summary.json`; must be deterministic.
    pub summary: Value,
    /// JSON merged into `summary.json`'s `timings` object (wall-clock numbers live only here and
    /// in fields named `runtime_s`).
    pub timings: Value,
    /// JSON merged into `summary.json`'s top level that holds wall-clock numbers (the
    /// `scaling` list); like `timings`, excluded from the determinism comparison.
    pub wall_clock: Value,
}

impl Section {
    /// Adds a setting.
    pub fn setting(&mut self, name: &str, value: impl ToString) {
        self.settings.push((name.to_string(), value.to_string()));
    }
}

/// A paper's value: a number, or illegible in the scan.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PaperValue {
    /// Legible value.
    Value(f64),
    /// Partly legible (e.g. mantissa without exponent), shown as this text.
    Illegible(&'static str),
    /// The paper gives no value.
    None,
}

impl PaperValue {
    /// The cell text.
    pub fn cell(&self) -> String {
        match self {
            PaperValue::Value(v) => fmt_e(*v),
            PaperValue::Illegible(s) => format!("{s} (illegible)"),
            PaperValue::None => "-".into(),
        }
    }
    /// `ours / paper` as text (or "-").
    pub fn ratio(&self, ours: f64) -> String {
        match self {
            PaperValue::Value(p) if *p != 0.0 => format!("{:.3}", ours / p),
            _ => "-".into(),
        }
    }
    /// The value as JSON (null when illegible).
    pub fn json(&self) -> Value {
        match self {
            PaperValue::Value(v) => num(*v),
            _ => Value::Null,
        }
    }
}

/// Scientific notation with 3 significant digits.
pub fn fmt_e(x: f64) -> String {
    if x.is_finite() {
        format!("{x:.3e}")
    } else {
        format!("{x}")
    }
}

/// A JSON number (null for NaN/inf, which JSON lacks).
pub fn num(x: f64) -> Value {
    serde_json::Number::from_f64(x).map_or(Value::Null, Value::Number)
}

/// Deep-merges `b` into `a` (objects merge by key; arrays concatenate; other values replace).
pub fn merge(a: &mut Value, b: Value) {
    match (a, b) {
        (Value::Object(am), Value::Object(bm)) => {
            for (k, v) in bm {
                merge(am.entry(k).or_insert(Value::Null), v);
            }
        }
        (a @ Value::Array(_), Value::Array(bv)) => {
            if let Value::Array(av) = a {
                av.extend(bv);
            }
        }
        (a, b) => {
            if !b.is_null() || a.is_null() {
                *a = b;
            }
        }
    }
}

/// The result of running one experiment.
pub struct Outcome {
    /// The experiment's id.
    pub id: &'static str,
    /// Part.
    pub part: Part,
    /// Title.
    pub title: &'static str,
    /// Wall time (s).
    pub wall_s: f64,
    /// The section, or the error.
    pub result: Result<Section, String>,
}

/// Writes `REPORT.md` and `summary.json`.
pub fn write_report(
    ctx: &Ctx,
    outcomes: &[Outcome],
    total_wall: f64,
    which: &str,
) -> Result<(), String> {
    let mut md = String::new();
    md += "# mbd: reproduction report\n\n";
    md += &format!(
        "Command: `cargo xtask reproduce {which}{}` · machine: {} cores · jobs: {} · total wall time {:.1} s\n\n",
        if ctx.quick { " --quick" } else { "" },
        std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1),
        ctx.jobs,
        total_wall
    );
    if ctx.quick {
        md += "> **Quick mode**: runs are shortened (fewer steps, shorter spans, smaller sweeps); the numbers are not the papers' settings. Run without `--quick` for the full report.\n\n";
    }
    md += "Paper values come from the papers' tables (OCR of the published scans, kept in `xtask/data/paper_values.json` with the bibliographic references); a value the scan lost is marked *illegible* and never invented. Ratios are ours / paper.\n\n";
    let refs = &crate::paper_values::get()?.references;
    md += &format!(
        "The papers:\n\n- **A**: {}\n- **B**: {}\n- **C**: {}\n\n",
        refs.paper_a, refs.paper_b, refs.paper_c
    );
    let failures: Vec<&Outcome> = outcomes.iter().filter(|o| o.result.is_err()).collect();
    // claims summary
    md += "## Claims\n\nEvery claim the experiments check, with its verdict. `cargo xtask reproduce --strict` exits non-zero when a claim does not hold unless it is documented here as an expected miss (with its reason); claims on wall-clock time are marked *(timing)* and are not enforced in quick mode.\n\n| part | claim | verdict | measured |\n|---|---|---|---|\n";
    let mut claims_json = Vec::new();
    for o in outcomes {
        if let Ok(s) = &o.result {
            for c in &s.claims {
                let v = match (c.verdict, &c.expected_miss) {
                    (Verdict::Held, _) => "held".to_string(),
                    (Verdict::NotHeld, None) => "**did not hold**".to_string(),
                    (Verdict::NotHeld, Some(r)) => format!("did not hold (expected miss: {r})"),
                    (Verdict::NotChecked, _) => "not checked".to_string(),
                };
                md += &format!(
                    "| {} | {}{} | {} | {} |\n",
                    o.part.key(),
                    c.text,
                    if c.timing { " *(timing)*" } else { "" },
                    v,
                    c.evidence
                );
                claims_json.push(c.json(o.part, o.id));
            }
        }
    }
    md += "\n";
    if !failures.is_empty() {
        md += "## Failed experiments\n\n";
        for f in &failures {
            if let Err(e) = &f.result {
                md += &format!("- `{}` ({}): {}\n", f.id, f.title, e);
            }
        }
        md += "\n";
    }
    let mut parts: Vec<Part> = outcomes.iter().map(|o| o.part).collect();
    parts.sort();
    parts.dedup();
    for p in parts {
        md += &format!("## {}\n\n", p.title());
        for o in outcomes.iter().filter(|o| o.part == p) {
            md += &format!("### {} (`{}`)\n\n", o.title, o.id);
            md += &format!("Wall time: {:.2} s\n\n", o.wall_s);
            match &o.result {
                Err(e) => md += &format!("**FAILED**: {e}\n\n"),
                Ok(s) => {
                    if !s.settings.is_empty() {
                        md += "Settings: ";
                        md += &s
                            .settings
                            .iter()
                            .map(|(k, v)| format!("{k} = {v}"))
                            .collect::<Vec<_>>()
                            .join("; ");
                        md += "\n\n";
                    }
                    for n in &s.notes {
                        md += n;
                        md += "\n\n";
                    }
                    for t in &s.tables {
                        md += &t.to_markdown();
                        md += "\n";
                    }
                    for f in &s.figures {
                        md += &format!(
                            "![{}](figures/{})\n\n*{}* ([SVG](figures/{}), [data](figures/{}))\n\n",
                            f.caption,
                            f.file,
                            f.caption,
                            f.file,
                            f.file.replace(".svg", ".csv")
                        );
                    }
                }
            }
        }
    }
    std::fs::write(ctx.out.join("REPORT.md"), md).map_err(|e| format!("writing REPORT.md: {e}"))?;

    let mut summary = Value::Object(Map::new());
    let mut timings = Map::new();
    for o in outcomes {
        timings.insert(
            o.id.to_string(),
            serde_json::json!({ "wall_s": num(o.wall_s) }),
        );
        if let Ok(s) = &o.result {
            merge(&mut summary, s.summary.clone());
            if !s.wall_clock.is_null() {
                merge(&mut summary, s.wall_clock.clone());
            }
            if !s.timings.is_null() {
                let mut t = timings.remove(o.id).unwrap_or(Value::Null);
                merge(&mut t, s.timings.clone());
                timings.insert(o.id.to_string(), t);
            }
        }
    }
    if let Value::Object(m) = &mut summary {
        m.insert("quick".into(), Value::Bool(ctx.quick));
        m.insert("claims".into(), Value::Array(claims_json));
        m.insert(
            "failures".into(),
            Value::Array(
                failures
                    .iter()
                    .map(|f| serde_json::json!({"id": f.id, "error": f.result.as_ref().err().cloned().unwrap_or_default()}))
                    .collect(),
            ),
        );
        timings.insert("total_wall_s".into(), num(total_wall));
        m.insert("timings".into(), Value::Object(timings));
    }
    let text = serde_json::to_string_pretty(&summary)
        .map_err(|e| format!("serialising summary.json: {e}"))?;
    std::fs::write(ctx.out.join("summary.json"), text)
        .map_err(|e| format!("writing summary.json: {e}"))?;
    Ok(())
}

#[cfg(test)]
mod tests;
