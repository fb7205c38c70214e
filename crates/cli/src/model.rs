//! Loading model files with messages that name the file and, where possible, the line.

use crate::error::CliError;
use mbd_model::{ModelError, ModelFile, System};
use std::path::Path;

/// Loads a model file (`.toml` or `.json`), turning the loader's errors into [`CliError`]s that
/// name the file; for errors about an element (a body, joint or force named in quotes) the
/// line where that element's name appears in the file is added.
pub fn load(path: &Path) -> Result<System, CliError> {
    let text = mbd_model::read_text(path, mbd_model::MAX_MODEL_FILE_BYTES).map_err(|e| {
        CliError::ModelRead {
            path: path.display().to_string(),
            message: e.to_string(),
        }
    })?;
    let result = match path.extension().and_then(|e| e.to_str()) {
        Some("json" | "toml") => ModelFile::from_text_at(&text, path).and_then(|m| m.build()),
        _ => {
            return Err(CliError::Model {
                path: path.display().to_string(),
                message: "unknown extension; model files end in .toml or .json".into(),
                location: String::new(),
            })
        }
    };
    result.map_err(|e| model_error(path, &text, &e))
}

fn model_error(path: &Path, text: &str, e: &ModelError) -> CliError {
    let (message, location) = match e {
        // the parser's message already carries line and column
        ModelError::Parse { message, .. } => (message.trim_end().to_string(), String::new()),
        other => {
            let message = other.to_string();
            let location = candidate_names(&message)
                .into_iter()
                .find_map(|name| {
                    let line = line_of_name(text, name)?;
                    Some(format!(" (see line {line}, where '{name}' is defined)"))
                })
                .unwrap_or_default();
            (message, location)
        }
    };
    CliError::Model {
        path: path.display().to_string(),
        message,
        location,
    }
}

/// Names of the element a message may be about: the last word before the first `:` (as in
/// `rod: parameter 'mass' ...` or `joint 'pin': ...`), then the first quoted word.
fn candidate_names(message: &str) -> Vec<&str> {
    let mut v = Vec::new();
    if let Some((head, _)) = message.split_once(':') {
        if let Some(last) = head.split_whitespace().last() {
            let last = last.trim_matches('\'');
            if !last.is_empty() {
                v.push(last);
            }
        }
    }
    v.extend(quoted_name(message));
    v
}

/// The first `'quoted'` word of a message.
fn quoted_name(message: &str) -> Option<&str> {
    let start = message.find('\'')? + 1;
    let len = message[start..].find('\'')?;
    Some(&message[start..start + len])
}

/// The 1-based line of the first `name = "..."` / `"name": "..."` entry with this value.
fn line_of_name(text: &str, name: &str) -> Option<usize> {
    let quoted = format!("\"{name}\"");
    text.lines()
        .position(|l| l.contains("name") && l.contains(&quoted))
        .map(|i| i + 1)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn element_errors_point_at_the_line_of_the_element() {
        let text =
            "gravity = [0.0, -9.81]\n\n[[bodies]]\nname = \"rod\"\nmass = -1.0\ninertia = 0.1\n";
        let e = System::from_toml(text).unwrap_err();
        let msg = model_error(Path::new("m.toml"), text, &e).to_string();
        assert!(msg.contains("invalid model file 'm.toml'"), "{msg}");
        assert!(msg.contains("mass"), "{msg}");
        assert!(msg.contains("line 4"), "{msg}");
    }

    #[test]
    fn candidates_come_from_the_element_prefix_then_quotes() {
        assert_eq!(candidate_names("rod: parameter 'mass'"), ["rod", "mass"]);
        assert_eq!(candidate_names("joint 'pin': x"), ["pin", "pin"]);
        assert!(candidate_names("nothing here").is_empty());
    }

    #[test]
    fn quoted_names_are_found() {
        assert_eq!(quoted_name("body 'crank': bad"), Some("crank"));
        assert_eq!(quoted_name("no quotes"), None);
    }
}
