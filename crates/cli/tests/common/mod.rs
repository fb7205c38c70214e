//! Helpers shared by the command-line tests: run the `mbd` binary, find example models, make
//! scratch directories.
#![allow(dead_code)]

pub mod browser;

use std::path::{Path, PathBuf};
use std::process::Command;

/// What one run of the binary gave.
pub struct Out {
    pub code: i32,
    pub stdout: String,
    pub stderr: String,
}

/// Runs `mbd` with the arguments, in the repository root (so `examples/models/...` resolves).
pub fn mbd<I, S>(args: I) -> Out
where
    I: IntoIterator<Item = S>,
    S: AsRef<std::ffi::OsStr>,
{
    let out = Command::new(env!("CARGO_BIN_EXE_mbd"))
        .args(args)
        .current_dir(repo())
        .output()
        .expect("the mbd binary runs");
    Out {
        code: out.status.code().unwrap_or(-1),
        stdout: String::from_utf8_lossy(&out.stdout).into_owned(),
        stderr: String::from_utf8_lossy(&out.stderr).into_owned(),
    }
}

/// The repository root.
pub fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// A scratch directory for one test, removed with everything in it when the guard is dropped
/// (at the end of the test, passed or failed by a panic), so runs leave nothing behind.
pub struct Scratch(PathBuf);

impl std::ops::Deref for Scratch {
    type Target = Path;
    fn deref(&self) -> &Path {
        &self.0
    }
}

impl AsRef<Path> for Scratch {
    fn as_ref(&self) -> &Path {
        &self.0
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// A fresh scratch directory for one test (see [`Scratch`]).
pub fn scratch(name: &str) -> Scratch {
    let d = std::env::temp_dir().join(format!("mbd-cli-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("scratch directory");
    Scratch(d)
}

/// The example model files.
pub fn example_models() -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(repo().join("examples/models"))
        .expect("examples/models exists")
        .map(|e| e.expect("dir entry").path())
        .filter(|p| {
            matches!(
                p.extension().and_then(|e| e.to_str()),
                Some("toml" | "json")
            )
        })
        .collect();
    v.sort();
    v
}

/// Asserts the exit code and that stderr contains every needle.
pub fn assert_fails(out: &Out, code: i32, needles: &[&str]) {
    assert_eq!(out.code, code, "exit code; stderr:\n{}", out.stderr);
    for n in needles {
        assert!(
            out.stderr.contains(n),
            "stderr lacks {n:?}; stderr:\n{}",
            out.stderr
        );
    }
}

/// A CSV of a short pendulum run, written to `dir`.
pub fn pendulum_csv(dir: &Path) -> PathBuf {
    let csv = dir.join("pendulum.csv");
    run_pendulum_to(&csv);
    csv
}

/// Runs the example pendulum for 0.1 s with RK4 (h = 0.01) into `csv`; the run must succeed.
pub fn run_pendulum_to(csv: &Path) {
    let out = mbd([
        "run".as_ref(),
        "examples/models/pendulum.toml".as_ref(),
        "--solver".as_ref(),
        "rk4".as_ref(),
        "--t-end".as_ref(),
        "0.1".as_ref(),
        "--h".as_ref(),
        "0.01".as_ref(),
        "--out".as_ref(),
        csv.as_os_str(),
    ]);
    assert_eq!(out.code, 0, "{}", out.stderr);
}

/// A result CSV's header and rows.
pub fn read_csv(p: &Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(p).unwrap();
    let mut lines = text.lines();
    let head = lines.next().unwrap().split(',').map(String::from).collect();
    let rows = lines
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect();
    (head, rows)
}

/// `mbd run MODEL --solver SOLVER --t-end 0.02 STEP.. --out OUT`.
pub fn run_model(model: &Path, solver: &str, step: &[&str], out: &Path) -> Out {
    run_model_until(model, solver, step, out, "0.02")
}

/// [`run_model`] to the end time `t_end`.
pub fn run_model_until(model: &Path, solver: &str, step: &[&str], out: &Path, t_end: &str) -> Out {
    let mut a: Vec<std::ffi::OsString> = vec![
        "run".into(),
        model.into(),
        "--solver".into(),
        solver.into(),
        "--t-end".into(),
        t_end.into(),
    ];
    a.extend(step.iter().map(Into::into));
    a.extend(["--out".into(), out.into()]);
    mbd(a)
}
