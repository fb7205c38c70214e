//! `mbd plot`: columns of a result CSV as an SVG figure, its axes titled with the columns'
//! units (`mbd_analysis::units`).

use crate::args::PlotArgs;
use crate::error::CliError;
use crate::table::Table;
use mbd_analysis::plot::{Figure, Series};
use mbd_analysis::units::{axis_label, unit_of};
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
    let mut fig = Figure::new(title, axis_label(&args.x), y_title(&args.y));
    for (name, y) in ys {
        fig = fig.with(Series::line(axis_label(&name), x.clone(), y));
    }
    save_svg_only(&fig, &out)?;
    Ok(out)
}

/// The y axis title: the columns and their common unit (`crank.x, slider.x [m]`), or each
/// column with its own unit when they differ (`slider.x [m], crank.theta [rad]`).
pub fn y_title(columns: &[String]) -> String {
    let units: Vec<Option<&str>> = columns.iter().map(|c| unit_of(c)).collect();
    match units.first() {
        Some(Some(u)) if units.iter().all(|v| *v == Some(*u)) => {
            format!("{} [{u}]", columns.join(", "))
        }
        _ => columns
            .iter()
            .map(|c| axis_label(c))
            .collect::<Vec<_>>()
            .join(", "),
    }
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
        if let Some(dir) = out.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir).map_err(|e| CliError::write(out, e))?;
        }
        std::fs::copy(&svg, out)
            .map(|_| ())
            .map_err(|e| CliError::write(out, e))
    });
    // best effort: a leftover temporary directory is harmless
    let _ = std::fs::remove_dir_all(&tmp);
    copied
}

#[cfg(test)]
mod tests {
    use super::y_title;

    fn cols(c: &[&str]) -> Vec<String> {
        c.iter().map(|s| s.to_string()).collect()
    }

    #[test]
    fn y_titles_carry_units() {
        assert_eq!(
            y_title(&cols(&["crank.x", "slider.x"])),
            "crank.x, slider.x [m]"
        );
        assert_eq!(
            y_title(&cols(&["slider.x", "crank.theta"])),
            "slider.x [m], crank.theta [rad]"
        );
        assert_eq!(y_title(&cols(&["max_abs_phi"])), "max_abs_phi");
        assert_eq!(y_title(&cols(&["H", "max_abs_phi"])), "H [J], max_abs_phi");
    }
}
