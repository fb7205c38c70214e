//! Paper B's experiments.
//!
//! STUB — to be filled in by the engineer who owns paper B's solver crate. Instructions:
//! - Return one [`Experiment`] per table/figure group from `experiments()` (ids like
//!   "paper-b-table1"), each a `fn(&Ctx) -> Result<Section, String>`.
//! - Put tables in `Section::tables` ([`crate::report::Table`]) with the paper's values
//!   ([`crate::report::PaperValue`]: `Illegible` for values the scan lost) beside ours and the
//!   ratio; settings and seeds in `Section::settings`; notes (e.g. readings of illegible
//!   settings) in `Section::notes`.
//! - Figures: build a [`crate::plot::Figure`] (axes labelled with units, log scales where
//!   errors span decades), save it with `fig.save(&ctx.figure_path("paper_b_fig3.svg"))`
//!   (writes the CSV beside it) and push a [`crate::report::FigureRef`].
//! - Claims: [`crate::report::Claim::check`] with the measured numbers as evidence.
//! - `Section::summary`: JSON deep-merged into summary.json (arrays concatenate), under the
//!   key "paper_b" with the field names of the reproduce issue; numbers via
//!   [`crate::report::num`]. Wall-clock numbers only in fields named `runtime_s` or in
//!   `Section::timings`, so the rest of summary.json is deterministic.
//! - `ctx.quick`: shorten runs so the experiment takes a few seconds, but exercise every path.
//! - Add your solver crate to xtask/Cargo.toml (`mbd-xxx.workspace = true`).

use crate::report::Experiment;

/// Paper B's experiments (none yet).
pub fn experiments() -> Vec<Experiment> {
    Vec::new()
}
