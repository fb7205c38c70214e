//! The `mbd` binary: parses the command line (usage errors exit with code 2, from clap) and
//! runs the command (runtime errors exit with code 1; see `mbd_cli::CliError`).

use clap::Parser;
use std::process::ExitCode;

fn main() -> ExitCode {
    let cli = mbd_cli::Cli::parse();
    match mbd_cli::execute(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            // (a failed write, e.g. to a closed pipe, must not panic: the exit code says it)
            use std::io::Write as _;
            let _ = writeln!(std::io::stderr(), "error: {e}");
            ExitCode::from(e.exit_code())
        }
    }
}
