//! # mbd-cli
//!
//! The `mbd` command-line program: simulate planar and spatial rigid multibody models from model files
//! (`docs/model-files.md`) with any solver of the workspace, and look at the results.
//!
//! * `mbd run MODEL --solver SOLVER --t-end T (--h H | --tol TOL) [--out FILE.csv|FILE.json]
//!   [--every K]` integrates and writes `t`, the coordinates, velocities, energy and
//!   constraint residuals;
//! * `mbd check MODEL` validates a model and prints its bodies, joints, degrees of freedom and
//!   consistent initial state;
//! * `mbd plot RESULT.csv --y COL [--y COL ...] [--x t] [-o out.svg]` draws an SVG figure;
//! * `mbd animate RESULT.csv --model MODEL -o anim.html [--trace BODY]` writes a self-contained
//!   animated page (2D for planar models, 3D for models with spatial bodies);
//! * `mbd solvers` lists the solvers of the registry (`mbd::registry()`).
//!
//! `docs/cli.md` describes the commands, the output columns and the solvers. The library side
//! is usable too, e.g. to run a command line from code:
//!
//! ```
//! use clap::Parser;
//!
//! let cli = mbd_cli::Cli::try_parse_from(["mbd", "solvers"])?;
//! let table = mbd_cli::solvers::table();
//! assert!(table.contains("tangent:dopri5"));
//! mbd_cli::execute(cli)?;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
#![warn(missing_docs)]

/// Writes a line to standard error like `eprintln!`, but ignores a failed write: a closed
/// pipe (`mbd run ... 2>&1 | head`) must not turn a finished run into a panic (exit 101).
macro_rules! note {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stderr(), $($arg)*);
    }};
}

/// Writes `text` to standard output, ignoring a failed write (a reader that closed the pipe,
/// `mbd solvers | head -1`, is not an error of the command).
fn out(text: &str) {
    use std::io::Write as _;
    let _ = std::io::stdout().write_all(text.as_bytes());
}

pub mod animate;
pub mod animate3d;
pub mod args;
pub mod check;
pub mod error;
pub mod model;
pub mod plot;
pub mod run;
pub mod solvers;
pub mod table;

pub use args::{Cli, Command};
pub use error::CliError;

/// Runs one parsed command line, printing results on standard output and the run summary on
/// standard error.
pub fn execute(cli: Cli) -> Result<(), CliError> {
    match cli.command {
        Command::Run(args) => {
            let summary = run::run(&args)?;
            note!("{}", summary.line(&args.solver));
            if let Some(w) = summary.stats.warning() {
                note!("warning: {w}");
            }
            if let Some(out) = &args.out {
                note!("wrote {}", out.display());
            }
            Ok(())
        }
        Command::Check(args) => {
            out(&check::check(&args)?);
            Ok(())
        }
        Command::Plot(args) => {
            let out = plot::plot(&args)?;
            note!("wrote {}", out.display());
            Ok(())
        }
        Command::Animate(args) => {
            animate::animate(&args)?;
            note!("wrote {}", args.out.display());
            Ok(())
        }
        Command::Solvers(args) => {
            if args.markdown {
                out(&mbd::registry().markdown_table());
            } else {
                out(&solvers::table());
            }
            Ok(())
        }
    }
}
