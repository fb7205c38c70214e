//! Every bad input gives the documented exit code (2 usage, 1 runtime) and a message that
//! names what is at fault.

mod common;
use common::{assert_fails, mbd, pendulum_csv, scratch};
use std::path::Path;

const PENDULUM: &str = "examples/models/pendulum.toml";

fn run_with(extra: &[&str]) -> common::Out {
    let mut a = vec!["run", PENDULUM];
    a.extend_from_slice(extra);
    mbd(a)
}

#[test]
fn unknown_solver() {
    let out = run_with(&["--solver", "rk5", "--t-end", "1", "--h", "0.01"]);
    assert_fails(
        &out,
        2,
        &[
            "unknown solver 'rk5'",
            "index1:dopri5",
            "tangent:dopri5",
            "firefly-gauss",
        ],
    );
}

#[test]
fn bad_symplectic_options() {
    let out = run_with(&["--solver", "symplectic:0", "--t-end", "1", "--h", "0.01"]);
    assert_fails(&out, 2, &["S must be a whole number"]);
    let out = run_with(&[
        "--solver",
        "symplectic:3:modified",
        "--t-end",
        "1",
        "--h",
        "0.01",
    ]);
    assert_fails(&out, 2, &["S = 1 or 2", "symplectic:2:modified"]);
}

#[test]
fn negative_and_zero_step() {
    for h in ["-0.01", "0", "nan"] {
        let out = run_with(&["--solver", "rk4", "--t-end", "1", "--h", h]);
        assert_fails(&out, 2, &["--h", "step size must be a positive number"]);
    }
    let out = run_with(&["--solver", "rk4", "--t-end", "1", "--h", "abc"]);
    assert_fails(&out, 2, &["'abc' is not a number"]);
}

/// A step longer than the run is one step of the run's length, with a warning saying so.
#[test]
fn a_step_longer_than_the_run_warns() {
    let out = run_with(&[
        "--solver",
        "rk4",
        "--t-end",
        "0.01",
        "--h",
        "5",
        "--out",
        "/dev/null",
    ]);
    assert_eq!(out.code, 0, "{}", out.stderr);
    assert!(
        out.stderr
            .contains("warning: --h 5 is longer than the run (0.01 s)")
            && out.stderr.contains("1 steps"),
        "{}",
        out.stderr
    );
    let out = run_with(&[
        "--solver",
        "rk4",
        "--t-end",
        "1",
        "--h",
        "0.5",
        "--out",
        "/dev/null",
    ]);
    assert!(
        !out.stderr.contains("longer than the run"),
        "{}",
        out.stderr
    );
}

#[test]
fn end_time_not_after_start() {
    for t in ["0", "-1"] {
        let out = run_with(&["--solver", "rk4", "--t-end", t, "--h", "0.01"]);
        assert_fails(
            &out,
            2,
            &["--t-end", "end time must be after the start time t0 = 0"],
        );
    }
}

#[test]
fn step_and_tolerance_together_or_neither() {
    let out = run_with(&[
        "--solver",
        "tangent:dopri5",
        "--t-end",
        "1",
        "--h",
        "0.01",
        "--tol",
        "1e-6",
    ]);
    assert_fails(&out, 2, &["cannot be used with"]);
    let out = run_with(&["--solver", "tangent:dopri5", "--t-end", "1"]);
    assert_fails(&out, 2, &["--h", "--tol"]);
}

#[test]
fn tolerance_with_a_solver_without_error_estimate() {
    let out = run_with(&["--solver", "rk4", "--t-end", "1", "--tol", "1e-6"]);
    assert_fails(
        &out,
        2,
        &[
            "--tol needs a solver with an embedded error estimate",
            "'rk4'",
            "index1:dopri5",
            "tangent:dopri5",
        ],
    );
    let out = run_with(&["--solver", "tangent:dopri5", "--t-end", "1", "--tol", "2"]);
    assert_fails(&out, 2, &["tolerance must lie in (0, 1)"]);
}

#[test]
fn index1_dopri5_with_a_bad_tolerance() {
    for tol in ["0", "-0.001", "1", "inf"] {
        let out = run_with(&["--solver", "index1:dopri5", "--t-end", "1", "--tol", tol]);
        assert_fails(&out, 2, &["--tol", "tolerance must lie in (0, 1)"]);
    }
    for tol in ["1e-30", "9e-15"] {
        let out = run_with(&["--solver", "index1:dopri5", "--t-end", "1", "--tol", tol]);
        assert_fails(
            &out,
            2,
            &["--tol", "below what double precision can deliver"],
        );
    }
    // the smallest tolerance the help states runs
    let help = mbd(["run", "--help"]).stdout;
    assert!(help.contains("from 1e-14 to below 1"), "{help}");
    let out = run_with(&[
        "--solver",
        "index1:dopri5",
        "--t-end",
        "0.01",
        "--tol",
        "1e-14",
        "--out",
        "/dev/null",
    ]);
    assert_eq!(out.code, 0, "{}", out.stderr);
    let out = run_with(&["--solver", "index1:dopri5", "--t-end", "1", "--tol", "abc"]);
    assert_fails(&out, 2, &["'abc' is not a number"]);
    let out = run_with(&["--solver", "index1:rk45", "--t-end", "1", "--tol", "1e-6"]);
    assert_fails(&out, 2, &["solver 'index1:rk45'", "index1:dopri5"]);
}

#[test]
fn missing_model_file() {
    let out = mbd([
        "run",
        "no/such/model.toml",
        "--solver",
        "rk4",
        "--t-end",
        "1",
        "--h",
        "0.01",
    ]);
    assert_fails(&out, 1, &["cannot read model file 'no/such/model.toml'"]);
    let out = mbd(["check", "no/such/model.toml"]);
    assert_fails(&out, 1, &["cannot read model file 'no/such/model.toml'"]);
}

fn write(dir: &Path, name: &str, text: &str) -> String {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p.display().to_string()
}

const GOOD_BODY: &str =
    "gravity = [0.0, -9.81]\n\n[[bodies]]\nname = \"rod\"\nmass = 1.0\ninertia = 0.1\n";

#[test]
fn malformed_model_syntax_gives_line_and_column() {
    let d = scratch("syntax");
    let toml = write(
        &d,
        "bad.toml",
        "gravity = [0.0, -9.81]\n\n[[bodies]]\nname = \"rod\"\nmass = = 1.0\n",
    );
    let out = mbd(["check", &toml]);
    assert_fails(
        &out,
        1,
        &["invalid model file", "bad.toml", "line 5", "column"],
    );
    let json = write(
        &d,
        "bad.json",
        "{\n  \"bodies\": [\n    { \"name\": \"rod\", \"mass\": 1.0,, }\n  ]\n}\n",
    );
    let out = mbd(["check", &json]);
    assert_fails(
        &out,
        1,
        &["invalid model file", "bad.json", "line 3", "column"],
    );
}

#[test]
fn unknown_field_is_named_with_its_line() {
    let d = scratch("field");
    let toml = write(
        &d,
        "field.toml",
        &GOOD_BODY.replace("mass = 1.0", "masss = 1.0"),
    );
    let out = mbd(["check", &toml]);
    assert_fails(
        &out,
        1,
        &["invalid model file", "unknown field", "masss", "line 5"],
    );
}

#[test]
fn bad_value_names_the_element_field_and_line() {
    let d = scratch("value");
    let toml = write(
        &d,
        "value.toml",
        &GOOD_BODY.replace("mass = 1.0", "mass = -2.0"),
    );
    let out = mbd(["check", &toml]);
    assert_fails(&out, 1, &["invalid model file", "rod", "mass", "line 4"]);
    let out = mbd([
        "run", &toml, "--solver", "rk4", "--t-end", "1", "--h", "0.01",
    ]);
    assert_fails(&out, 1, &["invalid model file", "mass"]);
}

#[test]
fn model_file_with_unknown_extension() {
    let d = scratch("ext");
    let p = write(&d, "model.yaml", GOOD_BODY);
    let out = mbd(["check", &p]);
    assert_fails(&out, 1, &["model.yaml", "end in .toml or .json"]);
}

#[test]
fn unknown_plot_column_lists_the_available_ones() {
    let d = scratch("plotcol");
    let csv = pendulum_csv(&d);
    let out = mbd([
        "plot".as_ref(),
        csv.as_os_str(),
        "--y".as_ref(),
        "nope".as_ref(),
    ]);
    assert_fails(
        &out,
        1,
        &[
            "column 'nope' is not in",
            "available columns: t, ",
            "max_abs_phi",
        ],
    );
    let out = mbd([
        "plot".as_ref(),
        csv.as_os_str(),
        "--x".as_ref(),
        "time".as_ref(),
        "--y".as_ref(),
        "H".as_ref(),
    ]);
    assert_fails(&out, 1, &["column 'time' is not in"]);
}

#[test]
fn animate_csv_from_another_model() {
    let d = scratch("mismatch");
    let csv = pendulum_csv(&d);
    let html = d.join("a.html");
    let out = mbd([
        "animate".as_ref(),
        csv.as_os_str(),
        "--model".as_ref(),
        "examples/models/slider_crank_spring.toml".as_ref(),
        "-o".as_ref(),
        html.as_os_str(),
    ]);
    assert_fails(
        &out,
        1,
        &["does not match model", "missing column(s) crank.x"],
    );
    assert!(!html.exists());
}

#[test]
fn result_file_that_is_not_a_csv() {
    let d = scratch("notcsv");
    let p = write(&d, "x.csv", "t,a\n0,1\n0.1,oops\n");
    let out = mbd(["plot", &p, "--y", "a"]);
    assert_fails(&out, 1, &["line 3", "'oops' is not a number"]);
    let out = mbd(["plot", "no/such.csv", "--y", "a"]);
    assert_fails(&out, 1, &["cannot read 'no/such.csv'"]);
}

#[test]
fn unwritable_output_paths() {
    let d = scratch("unwritable");
    // a path below a regular file cannot be created, not even by root
    let blocker = d.join("file");
    std::fs::write(&blocker, "x").unwrap();
    let target = blocker.join("out.csv");
    let out = mbd([
        "run".as_ref(),
        PENDULUM.as_ref(),
        "--solver".as_ref(),
        "rk4".as_ref(),
        "--t-end".as_ref(),
        "0.1".as_ref(),
        "--h".as_ref(),
        "0.01".as_ref(),
        "--out".as_ref(),
        target.as_os_str(),
    ]);
    let shown = format!("cannot write '{}'", target.display());
    assert_fails(&out, 1, &[&shown, "writable"]);

    let csv = pendulum_csv(&d);
    let svg = blocker.join("f.svg");
    let out = mbd([
        "plot".as_ref(),
        csv.as_os_str(),
        "--y".as_ref(),
        "H".as_ref(),
        "-o".as_ref(),
        svg.as_os_str(),
    ]);
    assert_fails(&out, 1, &[&format!("'{}'", svg.display())]);

    let html = blocker.join("a.html");
    let out = mbd([
        "animate".as_ref(),
        csv.as_os_str(),
        "--model".as_ref(),
        PENDULUM.as_ref(),
        "-o".as_ref(),
        html.as_os_str(),
    ]);
    assert_fails(&out, 1, &[&format!("cannot write '{}'", html.display())]);
}

#[test]
fn output_extension_must_be_csv_or_json() {
    let out = run_with(&[
        "--solver", "rk4", "--t-end", "0.1", "--h", "0.01", "--out", "x.txt",
    ]);
    assert_fails(&out, 2, &["x.txt", ".csv or .json"]);
}

#[test]
fn every_must_be_positive() {
    let out = run_with(&[
        "--solver", "rk4", "--t-end", "0.1", "--h", "0.01", "--every", "0",
    ]);
    assert_fails(&out, 2, &["--every"]);
}

/// Step counts out of range say so, with compact numbers: a run beyond the library's 1e12
/// steps, one beyond `--max-steps` (default 1e9) naming the flag; a span far below h runs as
/// one step.
#[test]
fn step_counts_out_of_range() {
    let out = run_with(&["--solver", "rk4", "--t-end", "1e12", "--h", "1e-3"]);
    assert_fails(
        &out,
        2,
        &["1000000000000000 steps of h = 0.001", "larger step"],
    );
    let out = run_with(&["--solver", "rk4", "--t-end", "1", "--h", "1e-12"]);
    assert_fails(&out, 2, &["1000000000000 steps", "--max-steps 1000000000"]);
    let out = run_with(&[
        "--solver", "rk4", "--t-end", "1e-300", "--h", "1e-3", "--out", "-",
    ]);
    assert_eq!(out.code, 0, "{}", out.stderr);
    assert_eq!(out.stdout.lines().count(), 3, "header and two rows");
}

/// Counts accept exponent form and say what is wrong; a negative infinite step is a value
/// the step-size check names, not an unknown flag.
#[test]
fn counts_and_signed_values() {
    let out = run_with(&[
        "--solver", "rk4", "--t-end", "0.01", "--h", "1e-3", "--every", "1e20",
    ]);
    assert_fails(&out, 2, &["1e20 is more than the largest count"]);
    let out = run_with(&[
        "--solver", "rk4", "--t-end", "0.01", "--h", "1e-3", "--every", "2.5",
    ]);
    assert_fails(&out, 2, &["whole number of steps"]);
    let out = run_with(&[
        "--solver", "rk4", "--t-end", "0.01", "--h", "1e-3", "--every", "1e1", "--out", "-",
    ]);
    assert_eq!(out.code, 0, "{}", out.stderr);
    assert_eq!(out.stdout.lines().count(), 3, "header, steps 0 and 10");
    let out = run_with(&["--solver", "rk4", "--t-end", "0.01", "--h", "-inf"]);
    assert_fails(
        &out,
        2,
        &["'-inf' for '--h <H>'", "positive number of seconds"],
    );
}

/// `/dev/null` and `-` are outputs; an endless device is not a model file.
#[test]
fn devices_as_files() {
    let out = run_with(&[
        "--solver",
        "rk4",
        "--t-end",
        "0.01",
        "--h",
        "1e-3",
        "--out",
        "/dev/null",
    ]);
    assert_eq!(out.code, 0, "{}", out.stderr);
    let out = mbd(["check", "/dev/zero"]);
    assert_fails(&out, 1, &["'/dev/zero'", "more than 67108864 bytes"]);
}

/// The drift guard's message names the CLI's flags (not a library field), and the flags work:
/// plain RK4 at h = 0.1 on the pendulum drifts past the default guard at 5.5 s, passes with
/// --drift-tol 10 and with --no-drift-guard.
#[test]
fn drift_guard_flags() {
    let base = [
        "--solver",
        "rk4",
        "--t-end",
        "10",
        "--h",
        "0.1",
        "--out",
        "/dev/null",
    ];
    let out = run_with(&base);
    assert_fails(
        &out,
        1,
        &["constraint drift", "--drift-tol", "--no-drift-guard"],
    );
    assert!(!out.stderr.contains("RunConfig"), "{}", out.stderr);
    let mut loose = base.to_vec();
    loose.extend(["--drift-tol", "10"]);
    assert_eq!(run_with(&loose).code, 0);
    let mut off = base.to_vec();
    off.push("--no-drift-guard");
    assert_eq!(run_with(&off).code, 0);
    let mut both = off.clone();
    both.extend(["--drift-tol", "1"]);
    assert_fails(&run_with(&both), 2, &["cannot be used with"]);
}

/// Structural refusals name the element and the reason, say "unsupported" once and give no
/// step-size advice: the modified Lagrangian on a damped model names the damper and the
/// solver that takes it; FA-DAE on a model without a degree of freedom says so.
#[test]
fn structural_refusals_name_the_cause() {
    let out = mbd([
        "run",
        "examples/models/slider_crank_spring.toml",
        "--solver",
        "symplectic:1:modified",
        "--t-end",
        "0.1",
        "--h",
        "1e-3",
        "--out",
        "/dev/null",
    ]);
    assert_fails(
        &out,
        1,
        &[
            "'return_spring' (spring_damper)",
            "symplectic:S without :modified",
        ],
    );
    assert!(!out.stderr.contains("smaller --h"), "{}", out.stderr);
    let dir = scratch("welded");
    let model = dir.join("welded.toml");
    std::fs::write(
        &model,
        "[[bodies]]\nname = \"rod\"\nmass = 1.0\ninertia = 0.1\nposition = [0.5, 0.0, 0.0]\n\n\
         [[joints]]\ntype = \"weld\"\nname = \"fix\"\nbody_a = \"ground\"\npoint_a = [0.5, 0.0]\n\
         body_b = \"rod\"\npoint_b = [0.0, 0.0]\n",
    )
    .unwrap();
    let out = mbd([
        "run".as_ref(),
        model.as_os_str(),
        "--solver".as_ref(),
        "firefly-gauss".as_ref(),
        "--t-end".as_ref(),
        "0.1".as_ref(),
        "--h".as_ref(),
        "1e-2".as_ref(),
    ]);
    assert_fails(
        &out,
        1,
        &["3 constraints on 3 coordinates leave no degree of freedom"],
    );
    assert_eq!(
        out.stderr.matches("unsupported").count(),
        1,
        "{}",
        out.stderr
    );
    assert!(!out.stderr.contains("smaller --h"), "{}", out.stderr);
}

/// A double parallelogram with a third crank (one redundant equation) turning without gravity
/// through its flat position at t = 0.25 s: a run of symplectic (2,2) that ends there stops
/// (the state there cannot be computed), while one that goes on steps over it (h = 1e-4 to
/// 0.5 s) or does not land on it (h = 3e-3). The message says so and suggests the other
/// solvers that pass, not the one that stopped.
#[test]
fn a_singular_stop_of_a_passing_solver_suggests_another_step_or_solver() {
    let dir = scratch("singular_hint");
    let model = dir.join("double_parallelogram_3.toml");
    // theta = pi - 1 + 4 t: flat at t = 0.25 s, on the grid of h = 1e-4 and off that of 3e-3
    let flat_at_quarter = double_parallelogram_3(0.0, std::f64::consts::PI - 1.0, 4.0);
    std::fs::write(&model, flat_at_quarter).unwrap();
    let model = model.to_str().unwrap();
    let run = |h: &str, t_end: &str| {
        mbd([
            "run",
            model,
            "--solver",
            "symplectic:2",
            "--t-end",
            t_end,
            "--h",
            h,
            "--out",
            "/dev/null",
        ])
    };
    let out = run("1e-4", "0.25");
    assert_fails(
        &out,
        1,
        &[
            "singular",
            "this solver usually passes",
            "ends or starts on the configuration",
            "another --h may pass",
            "rk4-projected or symplectic:1",
        ],
    );
    let out = run("1e-4", "0.5");
    assert_eq!(out.code, 0, "{}", out.stderr);
    assert!(out.stderr.contains("stepped over"), "{}", out.stderr);
    let out = run("3e-3", "0.5");
    assert_eq!(out.code, 0, "{}", out.stderr);
    assert!(!out.stderr.contains("stepped over"), "{}", out.stderr);
}

/// Three cranks of 0.5 m pinned at x = 0, 1, 2 to a 2 m coupler, released at `a` rad turning
/// at `w` rad/s (the coupler's velocity follows from the cranks': a parallelogram translates
/// it), under gravity `g` (m/s^2, downwards).
fn double_parallelogram_3(g: f64, a: f64, w: f64) -> String {
    let mut text = format!("gravity = [0.0, {:?}]\n", -g);
    for k in 0..3 {
        text += &format!(
            "[[bodies]]\nname = \"crank{k}\"\nmass = 1.0\ninertia = 0.020833333333333332\n\
             com = [0.25, 0.0]\nposition = [{k}.0, 0.0, {a:?}]\nvelocity = [0.0, 0.0, {w:?}]\n"
        );
    }
    let (s, c) = (0.5 * a.sin(), 0.5 * a.cos());
    text += &format!(
        "[[bodies]]\nname = \"coupler\"\nmass = 4.0\ninertia = 1.3333333333333333\n\
         com = [1.0, 0.0]\nposition = [{c:e}, {s:e}, 0.0]\nvelocity = [{:e}, {:e}, 0.0]\n",
        -w * s,
        w * c
    );
    for k in 0..3 {
        text += &format!(
            "[[joints]]\ntype = \"revolute\"\nname = \"pivot{k}\"\nbody_a = \"ground\"\n\
             point_a = [{k}.0, 0.0]\nbody_b = \"crank{k}\"\n\
             [[joints]]\ntype = \"revolute\"\nname = \"pin{k}\"\nbody_a = \"crank{k}\"\n\
             point_a = [0.5, 0.0]\nbody_b = \"coupler\"\npoint_b = [{k}.0, 0.0]\n"
        );
    }
    text
}

/// A reader that closes the pipe early (`mbd ... 2>&1 | true`) does not turn a finished run
/// into a panic: the messages are dropped and the exit code is the run's (it was 101).
#[test]
fn a_closed_pipe_is_not_a_panic() {
    let bin = env!("CARGO_BIN_EXE_mbd");
    let script = format!(
        "cd '{}' && '{bin}' run {PENDULUM} --solver rk4 --t-end 0.5 --h 1e-4 --out /dev/null \
         2>&1 | true; echo \"code ${{PIPESTATUS[0]}}\"; '{bin}' solvers | true; \
         echo \"code ${{PIPESTATUS[0]}}\"",
        common::repo().display()
    );
    let o = std::process::Command::new("bash")
        .args(["-c", &script])
        .output()
        .expect("bash");
    let text = String::from_utf8_lossy(&o.stdout);
    assert_eq!(text.matches("code 0").count(), 2, "{text}");
}
