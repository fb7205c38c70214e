//! `mbd plot`: columns of a result CSV as an SVG figure.

use crate::args::PlotArgs;
use crate::error::CliError;
use crate::table::Table;
use mbd_analysis::plot::{Figure, Series};
use std::path::{Path, PathBuf};

/// Draws the figure and returns the path of the SVG written.
pub fn plot(args: &PlotArgs) -> Result<PathBuf, CliError> {
    let table = Table::read(&args.csv)?;
    let x = table.column(&args.x)?;
    let ys: Vec<(String, Vec<f64>)> = args
        .y
        .iter()
        .map(|c| Ok((c.clone(), table.column(c)?)))
        .collect::<Result<_, CliError>>()?;
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| args.csv.with_extension("svg"));
    let title = args
        .csv
        .file_name()
        .map(|f| f.to_string_lossy().into_owned())
        .unwrap_or_default();
    let mut fig = Figure::new(title, args.x.clone(), args.y.join(", "));
    for (name, y) in ys {
        fig = fig.with(Series::line(name, x.clone(), y));
    }
    save_svg_only(&fig, &out)?;
    Ok(out)
}

/// `Figure::save` also writes the data next to the SVG (same name, extension `.csv`), which
/// could overwrite the very CSV being plotted: draw into a private temporary directory and
/// copy only the SVG.
fn save_svg_only(fig: &Figure, out: &Path) -> Result<(), CliError> {
    let tmp = std::env::temp_dir().join(format!("mbd-plot-{}", std::process::id()));
    let svg = tmp.join("figure.svg");
    let drawn = fig.save(&svg).map_err(|e| CliError::Plot {
        path: out.display().to_string(),
        message: e.to_string(),
    });
    let copied = drawn.and_then(|()| {
        std::fs::copy(&svg, out)
            .map(|_| ())
            .map_err(|e| CliError::write(out, e))
    });
    // best effort: a leftover temporary directory is harmless
    let _ = std::fs::remove_dir_all(&tmp);
    copied
}
