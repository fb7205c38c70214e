//! A state saved as JSON and read back as an initial state (restarts): `mbd run --save-state`
//! and `--initial-state`.
//!
//! The file is one object: `"format": "mbd-state"`, `"version": 1`, the time `"t"`, the
//! coordinate names `"coordinates"` (`body.x`, ... in model order, [`System::coordinate_names`])
//! and the values `"q"` and `"v"`, in full precision (`serde_json` writes the shortest string
//! that reads back to the same `f64`, so a round trip is exact).

use crate::error::AnalysisError;
use mbd_model::System;
use mbd_solve::State;
use nalgebra::DVector;
use serde_json::{json, Value};
use std::path::Path;

/// The `"format"` tag of a state file.
pub const STATE_FORMAT: &str = "mbd-state";

/// The JSON of `state` of `sys` (see the module documentation).
pub fn state_to_json(sys: &System, state: &State) -> Value {
    json!({
        "format": STATE_FORMAT,
        "version": 1,
        "t": state.t,
        "coordinates": sys.coordinate_names(),
        "q": state.q.as_slice(),
        "v": state.v.as_slice(),
    })
}

/// Writes `state` of `sys` to `path` as JSON.
pub fn save_state(sys: &System, state: &State, path: &Path) -> Result<(), AnalysisError> {
    let io = |message: String| AnalysisError::Io {
        path: path.display().to_string(),
        message,
    };
    let text =
        serde_json::to_string_pretty(&state_to_json(sys, state)).map_err(|e| io(e.to_string()))?;
    std::fs::write(path, text).map_err(|e| io(e.to_string()))
}

/// The state in `text` for `sys`: its coordinate names must be the model's, in order (an error
/// names the first that differs), and every value finite. `path` is for the messages.
pub fn state_from_json(sys: &System, text: &str, path: &str) -> Result<State, AnalysisError> {
    let bad = |message: String| AnalysisError::Io {
        path: path.to_string(),
        message,
    };
    let doc: Value = serde_json::from_str(text).map_err(|e| bad(format!("not JSON: {e}")))?;
    if doc["format"] != STATE_FORMAT {
        return Err(bad(format!(
            "not a state file (\"format\" must be \"{STATE_FORMAT}\"; `mbd run --save-state` \
             writes one)"
        )));
    }
    let names: Vec<String> = serde_json::from_value(doc["coordinates"].clone())
        .map_err(|_| bad("\"coordinates\" must be a list of names".into()))?;
    let want = sys.coordinate_names();
    if names != want {
        let k = names
            .iter()
            .zip(&want)
            .position(|(a, b)| a != b)
            .unwrap_or(names.len().min(want.len()));
        return Err(bad(format!(
            "its coordinates do not match the model's: {} against {} (first difference at \
             position {k}: {:?} in the file, {:?} in the model)",
            names.len(),
            want.len(),
            names.get(k),
            want.get(k)
        )));
    }
    let numbers = |key: &str| -> Result<Vec<f64>, AnalysisError> {
        let v: Vec<f64> = serde_json::from_value(doc[key].clone())
            .map_err(|_| bad(format!("\"{key}\" must be a list of numbers")))?;
        if v.len() != want.len() {
            return Err(bad(format!(
                "\"{key}\" has {} values for {} coordinates",
                v.len(),
                want.len()
            )));
        }
        if let Some(i) = v.iter().position(|x| !x.is_finite()) {
            return Err(bad(format!("\"{key}\" for {} is not finite", want[i])));
        }
        Ok(v)
    };
    let t = doc["t"]
        .as_f64()
        .filter(|t| t.is_finite())
        .ok_or_else(|| bad("\"t\" must be a finite number".into()))?;
    let (q, v) = (numbers("q")?, numbers("v")?);
    State::new(sys, t, DVector::from_vec(q), DVector::from_vec(v)).map_err(|e| bad(e.to_string()))
}

/// Reads a state file for `sys` (see [`state_from_json`]).
///
/// ```
/// use mbd_analysis::{load_state, save_state};
/// let sys = mbd_model::models::pendulum(1.0, 1.0, 0.3, 9.81)?;
/// let mut s = mbd_solve::State::consistent(&sys, 0.0)?;
/// s.t = 1.25;
/// let p = std::env::temp_dir().join(format!("mbd-state-doc-{}.json", std::process::id()));
/// save_state(&sys, &s, &p)?;
/// assert_eq!(load_state(&sys, &p)?, s);
/// # std::fs::remove_file(&p).ok();
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn load_state(sys: &System, path: &Path) -> Result<State, AnalysisError> {
    let text = mbd_model::read_text(path, mbd_model::MAX_MODEL_FILE_BYTES).map_err(|e| {
        AnalysisError::Io {
            path: path.display().to_string(),
            message: e.to_string(),
        }
    })?;
    state_from_json(sys, &text, &path.display().to_string())
}
