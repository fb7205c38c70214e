//! The one error type of the command-line program.

use thiserror::Error;

/// Everything that can stop a command. [`CliError::exit_code`] maps each to the process exit
/// code: 2 for usage errors (as clap's own), 1 for everything else.
#[derive(Debug, Error)]
pub enum CliError {
    /// A combination of options that cannot work (found after clap parsed them).
    #[error("{0}")]
    Usage(String),
    /// The model file could not be read.
    #[error("cannot read model file '{path}': {message}; check the path (examples are in examples/models/)")]
    ModelRead {
        /// The path given.
        path: String,
        /// The operating system's message.
        message: String,
    },
    /// The model file was read but is not a valid model.
    #[error("invalid model file '{path}': {message}{location}\n(the format is described in docs/model-files.md)")]
    Model {
        /// The path given.
        path: String,
        /// What the model loader reported (parser errors carry line and column).
        message: String,
        /// Where the element at fault is defined, e.g. `" (body 'crank' is defined at line 12)"`,
        /// or empty.
        location: String,
    },
    /// The consistent initial state could not be found.
    #[error("model '{path}': no consistent initial state: {source}; check the initial positions in the model file")]
    Initial {
        /// The model path.
        path: String,
        /// The projection's error.
        #[source]
        source: Box<mbd_solve::SolveError>,
    },
    /// The solver could not be built or failed during the run.
    #[error("solver '{solver}' failed: {source}{hint}")]
    Solve {
        /// The solver as given on the command line.
        solver: String,
        /// The error.
        #[source]
        source: Box<mbd_solve::SolveError>,
        /// What to try, or empty.
        hint: String,
    },
    /// A file could not be written or read.
    #[error("cannot {action} '{path}': {message}; {hint}")]
    Io {
        /// "write" or "read".
        action: &'static str,
        /// The path.
        path: String,
        /// The operating system's message.
        message: String,
        /// What to do.
        hint: &'static str,
    },
    /// A result file is not a CSV table of numbers.
    #[error("'{path}' line {line}: {message}; give a CSV written by `mbd run --out FILE.csv`")]
    Csv {
        /// The file.
        path: String,
        /// 1-based line number.
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// A result file is not the JSON `mbd run` writes.
    #[error("'{path}': {message}; give a JSON written by `mbd run --out FILE.json`")]
    Json {
        /// The file.
        path: String,
        /// What is wrong.
        message: String,
    },
    /// A column asked for is not in the file.
    #[error("column '{column}' is not in '{path}'; available columns: {available}")]
    UnknownColumn {
        /// The column asked for.
        column: String,
        /// The file.
        path: String,
        /// The columns of the file, comma separated.
        available: String,
    },
    /// A result file does not belong to the model given.
    #[error("'{csv}' does not match model '{model}': missing column(s) {missing}; create the CSV from this model with `mbd run {model} --out FILE.csv ...`")]
    Mismatch {
        /// The CSV path.
        csv: String,
        /// The model path.
        model: String,
        /// The columns the model needs that the CSV lacks.
        missing: String,
    },
    /// A figure could not be drawn.
    #[error("cannot draw '{path}': {message}")]
    Plot {
        /// The output path.
        path: String,
        /// The plotting library's message.
        message: String,
    },
}

impl CliError {
    /// The process exit code: 2 for usage errors, 1 otherwise.
    pub fn exit_code(&self) -> u8 {
        match self {
            CliError::Usage(_) => 2,
            _ => 1,
        }
    }

    /// An error writing `path`.
    pub fn write(path: &std::path::Path, e: impl std::fmt::Display) -> CliError {
        CliError::Io {
            action: "write",
            path: path.display().to_string(),
            message: e.to_string(),
            hint: "check that the directory exists and is writable",
        }
    }

    /// An error reading `path`.
    pub fn read(path: &std::path::Path, e: impl std::fmt::Display) -> CliError {
        CliError::Io {
            action: "read",
            path: path.display().to_string(),
            message: e.to_string(),
            hint: "check the path",
        }
    }
}
