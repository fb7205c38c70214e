//! The defaults stated in the documentation are the defaults of the code.
//!
//! The tables in the doc comments of `FaDaeOptions` and `BoxSettings` (src/options.rs), and
//! every `` `name = value` `` that the crate documentation (src/lib.rs) and
//! docs/firefly-gauss.md state for an option, are compared with `FaDaeOptions::default()`.
//! Editing either side alone fails this test; so does adding a field without documenting its
//! default.

use mbd_firefly_gauss::{BoxSettings, FaDaeOptions};
use std::collections::BTreeSet;

const OPTIONS_RS: &str = include_str!("../src/options.rs");
const LIB_RS: &str = include_str!("../src/lib.rs");
const GUIDE_MD: &str = include_str!("../../../docs/firefly-gauss.md");

/// A default as the documentation must state it.
#[derive(Debug)]
enum V {
    /// A number: the cell's first word must parse to exactly this value.
    Num(f64),
    /// A name (enum variant, bool, function path) the cell must contain.
    Word(String),
}

fn num(x: impl Into<f64>) -> V {
    V::Num(x.into())
}

fn word(x: impl std::fmt::Debug) -> V {
    V::Word(format!("{x:?}"))
}

/// Every documented default of `FaDaeOptions` (fields of `firefly` flattened; its `seed` is
/// ignored by the solver), from the code.
fn options_defaults() -> Vec<(String, V)> {
    let d = FaDaeOptions::default();
    let f = &d.firefly;
    let v = vec![
        ("partition", word(&d.partition)),
        ("firefly.population", num(f.population as f64)),
        ("firefly.beta0", num(f.beta0)),
        ("firefly.beta_min", num(f.beta_min)),
        ("firefly.gamma", num(f.gamma)),
        ("firefly.alpha", num(f.alpha)),
        ("firefly.alpha_decay", num(f.alpha_decay)),
        ("firefly.variant", word(f.variant)),
        ("firefly.boundary", word(f.boundary)),
        ("firefly.distance", word(f.distance)),
        ("firefly.best_random_walk", word(f.best_random_walk)),
        ("max_generations", num(d.max_generations as f64)),
        ("tolerance", num(d.tolerance)),
        ("stage_generations", num(d.stage_generations as f64)),
        (
            "stagnation_generations",
            d.stagnation_generations
                .map_or(V::Word("None".into()), |k| num(k as f64)),
        ),
        ("predictor", word(d.predictor)),
        (
            "bounds",
            V::Word(if d.bounds == BoxSettings::default() {
                "BoxSettings::default".into()
            } else {
                "(not BoxSettings::default)".into()
            }),
        ),
        ("seed", num(d.seed as f64)),
        ("seed_predictor", word(d.seed_predictor)),
        ("polish", word(d.polish)),
        ("polish_max_iter", num(d.polish_max_iter as f64)),
        ("parallel", word(d.parallel)),
        ("newton_tol", num(d.newton_tol)),
        ("newton_max_iter", num(d.newton_max_iter as f64)),
        ("on_miss", word(d.on_miss)),
        ("repartition_threshold", num(d.repartition_threshold)),
        ("predictor_offset", num(d.predictor_offset)),
    ];
    v.into_iter().map(|(k, v)| (k.to_string(), v)).collect()
}

fn box_defaults() -> Vec<(String, V)> {
    let b = BoxSettings::default();
    vec![
        ("safety", num(b.safety)),
        ("min_relative", num(b.min_relative)),
        ("edge_fraction", num(b.edge_fraction)),
        ("expansion", num(b.expansion)),
        ("max_expansions", num(b.max_expansions)),
        ("min_shrink", num(b.min_shrink)),
        ("max_shrink", num(b.max_shrink)),
    ]
    .into_iter()
    .map(|(k, v)| (k.to_string(), v))
    .collect()
}

/// The top-level field names of a value's pretty `Debug` output.
fn debug_fields(pretty: &str) -> BTreeSet<String> {
    pretty
        .lines()
        .filter(|l| l.starts_with("    ") && !l.starts_with("     "))
        .filter_map(|l| l.trim().split_once(':').map(|(k, _)| k.to_string()))
        .collect()
}

/// The `| field | default |` table in the doc comment right above `pub struct {name}`.
fn doc_table(name: &str) -> Vec<(String, String)> {
    let head = format!("pub struct {name} ");
    let end = OPTIONS_RS.find(&head).expect("struct in options.rs");
    let doc: Vec<&str> = OPTIONS_RS[..end]
        .lines()
        .rev()
        .skip_while(|l| l.trim().is_empty() || l.starts_with("#["))
        .take_while(|l| l.starts_with("///"))
        .collect();
    doc.iter()
        .rev()
        .filter_map(|l| l.strip_prefix("/// | `"))
        .map(|row| {
            let (field, rest) = row.split_once("` |").expect("row: | `field` | default |");
            let cell = rest
                .trim()
                .strip_suffix('|')
                .expect("row ends with |")
                .trim();
            (field.to_string(), cell.to_string())
        })
        .collect()
}

/// The number a documented value starts with (`4e-15 (about 16 ulps)`, `2%`).
fn leading_number(s: &str) -> Option<f64> {
    let w: String = s
        .trim_start_matches('`')
        .chars()
        .take_while(|c| c.is_ascii_digit() || matches!(c, '.' | 'e' | '-' | '+' | '%'))
        .collect();
    match w.strip_suffix('%') {
        Some(p) => p.parse::<f64>().ok().map(|x| x / 100.0),
        None => w.parse().ok(),
    }
}

fn agrees(stated: &str, v: &V) -> bool {
    match v {
        V::Num(x) => leading_number(stated) == Some(*x),
        V::Word(w) => stated.contains(w.as_str()),
    }
}

fn check_table(name: &str, code: &[(String, V)]) {
    let table = doc_table(name);
    let doc_keys: BTreeSet<_> = table.iter().map(|(k, _)| k.clone()).collect();
    let code_keys: BTreeSet<_> = code.iter().map(|(k, _)| k.clone()).collect();
    assert_eq!(doc_keys, code_keys, "{name}: documented fields vs fields");
    assert_eq!(
        doc_keys.len(),
        table.len(),
        "{name}: a field documented twice"
    );
    for (k, cell) in &table {
        let (_, v) = code.iter().find(|(c, _)| c == k).expect("key");
        assert!(
            agrees(cell, v),
            "{name}.{k}: documented `{cell}`, code {v:?}"
        );
    }
}

#[test]
fn doc_tables_equal_default() {
    let opts = options_defaults();
    check_table("FaDaeOptions", &opts);
    check_table("BoxSettings", &box_defaults());
    // every field of the structs is in the lists above (a new field needs a documented default)
    let d = FaDaeOptions::default();
    let top: BTreeSet<String> = opts
        .iter()
        .map(|(k, _)| k.split('.').next().unwrap_or(k).to_string())
        .collect();
    assert_eq!(top, debug_fields(&format!("{d:#?}")));
    let mut ff: BTreeSet<String> = opts
        .iter()
        .filter_map(|(k, _)| k.strip_prefix("firefly.").map(str::to_string))
        .collect();
    ff.insert("seed".into()); // ignored by the solver: every step derives its own seed
    assert_eq!(ff, debug_fields(&format!("{:#?}", d.firefly)));
    let bx: BTreeSet<String> = box_defaults().into_iter().map(|(k, _)| k).collect();
    assert_eq!(bx, debug_fields(&format!("{:#?}", d.bounds)));
}

/// Every `` `name = value` `` in `text` whose name is an option (last path component).
fn stated_values(text: &str) -> Vec<(String, String)> {
    let mut out = Vec::new();
    for chunk in text.split('`').skip(1).step_by(2) {
        if let Some((k, v)) = chunk.split_once(" = ") {
            out.push((k.trim().to_string(), v.trim().to_string()));
        }
    }
    out
}

#[test]
fn defaults_stated_in_prose_equal_default() {
    let all: Vec<(String, V)> = options_defaults()
        .into_iter()
        .chain(box_defaults())
        .collect();
    let leaf = |k: &str| k.rsplit('.').next().unwrap_or(k).to_string();
    let mut checked = BTreeSet::new();
    for (file, text) in [("src/lib.rs", LIB_RS), ("docs/firefly-gauss.md", GUIDE_MD)] {
        for (name, value) in stated_values(text) {
            let Some((_, v)) = all.iter().find(|(k, _)| leaf(k) == name) else {
                continue;
            };
            assert!(
                agrees(&value, v),
                "{file}: `{name} = {value}`, but the default is {v:?}"
            );
            checked.insert(name);
        }
    }
    // the guide states these; the test must not pass by finding nothing
    for name in [
        "tolerance",
        "stage_generations",
        "stagnation_generations",
        "safety",
        "repartition_threshold",
    ] {
        assert!(
            checked.contains(name),
            "no `{name} = ...` found: {checked:?}"
        );
    }
}
