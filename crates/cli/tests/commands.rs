//! The commands on the example models: every solver runs and writes the documented columns;
//! `check`, `plot` and `animate` produce what they promise.

mod common;
use common::{example_models, mbd, pendulum_csv, read_csv, run_model, run_model_until, scratch};
use std::path::Path;

fn expected_columns(model: &Path) -> Vec<String> {
    let sys = mbd_model::System::from_path(model).unwrap();
    let names = sys.coordinate_names();
    let mut c = vec!["t".to_string()];
    c.extend(names.iter().cloned());
    c.extend(names.iter().map(|n| format!("d_{n}")));
    c.extend(["H", "max_abs_phi", "max_abs_phidot"].map(String::from));
    // where H is not conserved, the energy balance
    if !sys.is_conservative() || sys.is_rheonomic() {
        c.extend(["W_external", "E_dissipated", "energy_balance"].map(String::from));
    }
    c
}

/// Every registered solver (`mbd::registry()`), with `--h` and, for adaptive ones, `--tol`,
/// and one spec with options.
fn every_registered_solver() -> Vec<(String, &'static [&'static str], &'static str)> {
    let mut v = vec![];
    for (_, var) in mbd::registry().variants() {
        v.push((var.spec.to_string(), &["--h", "0.01"][..], var.refuses));
        if var.adaptive {
            v.push((var.spec.to_string(), &["--tol", "1e-6"][..], var.refuses));
        }
    }
    v.push(("symplectic:1:gamma=1".into(), &["--h", "0.01"][..], ""));
    v
}

#[test]
fn mbd_solvers_lists_the_registry() {
    let out = mbd(["solvers"]);
    assert_eq!(out.code, 0, "{}", out.stderr);
    for (_, v) in mbd::registry().variants() {
        assert!(
            out.stdout.lines().any(|l| l.starts_with(v.spec)),
            "{} missing from:\n{}",
            v.spec,
            out.stdout
        );
    }
}

#[test]
fn every_solver_runs_every_example_model() {
    let d = scratch("all");
    let solvers = every_registered_solver();
    for model in example_models() {
        let want = expected_columns(&model);
        let conservative = mbd_model::System::from_path(&model)
            .unwrap()
            .is_conservative();
        for (k, (solver, step, refuses)) in solvers.iter().enumerate() {
            let csv = d.join(format!("{k}.csv"));
            // Andrews' squeezer moves on a time scale of 1e-4 s (the crank turns 2.5 times in
            // 0.03 s): fixed steps of 1e-4, every 100th written (the same three rows); the
            // flyball governor's stiff dampers put h = 1e-3 beyond plain RK4's stability:
            // fixed steps of 1e-4 for 2e-3 s (the swarm of FA-DAE searches 54 coordinates per
            // step), every 10th written
            let squeezer: &[&str] = &["--h", "1e-4", "--every", "100"];
            let governor: &[&str] = &["--h", "1e-4", "--every", "10"];
            let (step, t_end) = match step[0] {
                "--h" if model.ends_with("andrews_squeezer.toml") => (squeezer, "0.02"),
                "--h" if model.ends_with("flyball_governor.toml") => (governor, "0.002"),
                _ => (*step, "0.02"),
            };
            let out = run_model_until(&model, solver, step, &csv, t_end);
            let what = format!("{} with {solver} {step:?}", model.display());
            // a solver that does not run the model's spatial bodies refuses it, saying so (or
            // saying that the model is not conservative, where that is the documented cause)
            let sys = mbd_model::System::from_path(&model).unwrap();
            if sys.has_spatial() {
                if let Err(e) = mbd::Simulation::new(sys, solver) {
                    assert_eq!(out.code, 1, "{what}: {}", out.stderr);
                    let documented = !conservative
                        && refuses.contains("non-conservative")
                        && out.stderr.contains("conservative");
                    assert!(
                        out.stderr.contains("spatial") || documented,
                        "{what}: {} ({e})",
                        out.stderr
                    );
                    continue;
                }
            }
            if !conservative && refuses.contains("non-conservative") {
                // a documented refusal: a runtime error that says why
                assert_eq!(out.code, 1, "{what}: {}", out.stderr);
                assert!(
                    out.stderr.contains("conservative"),
                    "{what}: {}",
                    out.stderr
                );
                continue;
            }
            assert_eq!(out.code, 0, "{what}: {}", out.stderr);
            // e(H) only where H is conserved; otherwise the line names why it is not
            let conserved = mbd_model::System::from_path(&model)
                .map(|s| s.is_conservative() && !s.is_rheonomic())
                .unwrap_or(false);
            let energy = if conserved {
                "e(H) = "
            } else {
                "H not conserved ("
            };
            assert!(
                out.stderr.contains("mbd run: ") && out.stderr.contains(energy),
                "{what}: {}",
                out.stderr
            );
            let (head, rows) = read_csv(&csv);
            assert_eq!(head, want, "{what}");
            let t: Vec<f64> = rows.iter().map(|r| r[0]).collect();
            assert_eq!(t[0], 0.0, "{what}");
            let end: f64 = t_end.parse().unwrap();
            assert!((t[t.len() - 1] - end).abs() < 1e-12, "{what}: {t:?}");
            if step[0] == "--h" {
                assert_eq!(rows.len(), 3, "{what}");
            }
            // the constraint residuals are columns of small numbers
            let phi = head.iter().position(|c| c == "max_abs_phi").unwrap();
            assert!(rows.iter().all(|r| r[phi].abs() < 1e-6), "{what}");
        }
    }
}

#[test]
fn modified_lagrangian_runs_on_a_conservative_model() {
    let d = scratch("modified");
    let model = common::repo().join("examples/models/pendulum.toml");
    let csv = d.join("m.csv");
    let out = run_model(&model, "symplectic:1:modified", &["--h", "0.01"], &csv);
    assert_eq!(out.code, 0, "{}", out.stderr);
    assert_eq!(read_csv(&csv).1.len(), 3);
    // a conservative model without drivers gets the full order: no caveat
    assert!(!out.stderr.contains("warning"), "{}", out.stderr);
}

/// On a model with drivers the modified-Lagrangian schemes run at the plain order, and `run`
/// says so (the driven arm without its force elements, which the schemes refuse).
#[test]
fn modified_lagrangian_warns_about_drivers() {
    let d = scratch("modified_driven");
    let text =
        std::fs::read_to_string(common::repo().join("examples/models/driven_three_link_arm.json"))
            .unwrap();
    let mut json: serde_json::Value = serde_json::from_str(&text).unwrap();
    json["forces"] = serde_json::Value::Array(Vec::new());
    let model = d.join("driven.json");
    std::fs::write(&model, json.to_string()).unwrap();
    let csv = d.join("m.csv");
    for (s, order) in [(1, 2), (2, 4)] {
        let out = run_model(
            &model,
            &format!("symplectic:{s}:modified"),
            &["--h", "0.01"],
            &csv,
        );
        assert_eq!(out.code, 0, "{}", out.stderr);
        assert!(
            out.stderr
                .contains("warning: the modified-Lagrangian terms are derived")
                && out
                    .stderr
                    .contains(&format!("order {order} (not {})", order + 2)),
            "{}",
            out.stderr
        );
    }
}

#[test]
fn adaptive_index1_dopri5_follows_its_tolerance() {
    let d = scratch("index1");
    let model = common::repo().join("examples/models/four_bar.toml");
    let run = |tol: &str| {
        let json = d.join(format!("four_bar_{tol}.json"));
        let out = mbd([
            "run".as_ref(),
            model.as_os_str(),
            "--solver".as_ref(),
            "index1:dopri5".as_ref(),
            "--t-end".as_ref(),
            "1".as_ref(),
            "--tol".as_ref(),
            tol.as_ref(),
            "--out".as_ref(),
            json.as_os_str(),
        ]);
        assert_eq!(out.code, 0, "--tol {tol}: {}", out.stderr);
        assert!(
            out.stderr.contains("with index1:dopri5"),
            "--tol {tol}: {}",
            out.stderr
        );
        let v: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
        assert_eq!(v["solver"], "index1:dopri5");
        assert!(v["h"].is_null());
        assert_eq!(v["tol"], tol.parse::<f64>().unwrap());
        let cols: Vec<String> = serde_json::from_value(v["columns"].clone()).unwrap();
        assert_eq!(cols, expected_columns(&model));
        let rows: Vec<Vec<f64>> = serde_json::from_value(v["rows"].clone()).unwrap();
        assert!(rows.iter().all(|r| r.len() == cols.len()));
        assert_eq!(rows[0][0], 0.0);
        assert!((rows[rows.len() - 1][0] - 1.0).abs() < 1e-12);
        // no stabilisation: the written residuals are the DOPRI5 error's drift
        let phi = cols.iter().position(|c| c == "max_abs_phi").unwrap();
        let worst = rows.iter().fold(0.0f64, |m, r| m.max(r[phi].abs()));
        assert!(worst < 1e-6, "--tol {tol}: max_abs_phi = {worst:e}");
        let steps = v["summary"]["steps"].as_u64().unwrap();
        (steps, worst, v["summary"]["e_phi"].as_f64().unwrap())
    };
    let (loose_steps, loose_phi, _) = run("1e-6");
    let (tight_steps, tight_phi, tight_e_phi) = run("1e-9");
    // the tolerance reaches the index-1 integrator: more steps and much less drift when tighter
    assert!(
        tight_steps > 2 * loose_steps,
        "{tight_steps} vs {loose_steps}"
    );
    assert!(
        tight_phi < loose_phi / 100.0,
        "{tight_phi:e} vs {loose_phi:e}"
    );
    assert!(tight_e_phi < 1e-8, "{tight_e_phi:e}");
}

#[test]
fn every_k_writes_every_kth_step_and_the_last() {
    let d = scratch("every");
    let csv = d.join("e.csv");
    let out = mbd([
        "run".as_ref(),
        "examples/models/pendulum.toml".as_ref(),
        "--solver".as_ref(),
        "symplectic:2".as_ref(),
        "--t-end".as_ref(),
        "0.1".as_ref(),
        "--h".as_ref(),
        "0.01".as_ref(),
        "--every".as_ref(),
        "3".as_ref(),
        "--out".as_ref(),
        csv.as_os_str(),
    ]);
    assert_eq!(out.code, 0, "{}", out.stderr);
    let t: Vec<f64> = read_csv(&csv).1.iter().map(|r| r[0]).collect();
    let want = [0.0, 0.03, 0.06, 0.09, 0.1];
    assert_eq!(t.len(), want.len(), "{t:?}");
    assert!(
        t.iter().zip(want).all(|(a, b)| (a - b).abs() < 1e-12),
        "{t:?}"
    );
    assert!(out.stderr.contains("10 steps"), "{}", out.stderr);
}

#[test]
fn json_output_has_metadata_and_rows() {
    let d = scratch("json");
    let json = d.join("r.json");
    let model = common::repo().join("examples/models/slider_crank_spring.toml");
    let out = run_model(&model, "tangent:rk4", &["--h", "0.005"], &json);
    assert_eq!(out.code, 0, "{}", out.stderr);
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(v["solver"], "tangent:rk4");
    assert_eq!(v["h"], 0.005);
    assert!(v["tol"].is_null());
    assert!(v["model"]
        .as_str()
        .unwrap()
        .ends_with("slider_crank_spring.toml"));
    let cols: Vec<String> = serde_json::from_value(v["columns"].clone()).unwrap();
    assert_eq!(cols, expected_columns(&model));
    let rows = v["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 5);
    assert!(rows
        .iter()
        .all(|r| r.as_array().unwrap().len() == cols.len()));
    assert_eq!(v["summary"]["steps"], 4);
}

#[test]
fn stdout_gets_the_csv_without_out() {
    let out = mbd([
        "run",
        "examples/models/pendulum.toml",
        "--solver",
        "rk4",
        "--t-end",
        "0.02",
        "--h",
        "0.01",
    ]);
    assert_eq!(out.code, 0, "{}", out.stderr);
    let lines: Vec<&str> = out.stdout.lines().collect();
    assert_eq!(lines.len(), 4);
    assert!(lines[0].starts_with("t,"));
    // no progress bar when stderr is not a terminal: just the summary line
    assert_eq!(out.stderr.lines().count(), 1, "{}", out.stderr);
}

#[test]
fn check_prints_the_degrees_of_freedom_and_initial_state() {
    let out = mbd(["check", "examples/models/slider_crank_spring.toml"]);
    assert_eq!(out.code, 0, "{}", out.stderr);
    for needle in [
        "bodies (3):",
        "crank_pivot",
        "prismatic",
        "degrees of freedom: 1",
        "consistent initial state",
        "crank.theta",
        "|q_consistent - q_file|_max = ",
    ] {
        assert!(
            out.stdout.contains(needle),
            "lacks {needle:?}:\n{}",
            out.stdout
        );
    }
    let out = mbd(["check", "examples/models/manipulator.json"]);
    assert!(
        out.stdout.contains("degrees of freedom: 2"),
        "{}",
        out.stdout
    );
}

#[test]
fn plot_writes_an_svg_and_leaves_the_csv_alone() {
    let d = scratch("plot");
    let csv = pendulum_csv(&d);
    let before = std::fs::read(&csv).unwrap();
    // default output: the CSV's name with .svg, next to it
    let out = mbd([
        "plot".as_ref(),
        csv.as_os_str(),
        "--y".as_ref(),
        "H".as_ref(),
        "--y".as_ref(),
        "max_abs_phi".as_ref(),
    ]);
    assert_eq!(out.code, 0, "{}", out.stderr);
    let svg = std::fs::read_to_string(d.join("pendulum.svg")).unwrap();
    assert!(svg.contains("<svg") && svg.contains("max_abs_phi"));
    assert_eq!(
        std::fs::read(&csv).unwrap(),
        before,
        "the data CSV was overwritten"
    );
}

/// `mbd plot` titles its axes with the columns' units, writes round tick labels and creates
/// the output's directory.
#[test]
fn plot_titles_axes_with_units() {
    let d = scratch("plot-units");
    let csv = pendulum_csv(&d);
    let svg = d.join("figures").join("rod.svg");
    let out = mbd([
        "plot".as_ref(),
        csv.as_os_str(),
        "--y".as_ref(),
        "rod.theta".as_ref(),
        "--y".as_ref(),
        "d_rod.theta".as_ref(),
        "-o".as_ref(),
        svg.as_os_str(),
    ]);
    assert_eq!(out.code, 0, "{}", out.stderr);
    let svg = std::fs::read_to_string(&svg).unwrap();
    let texts: Vec<&str> = svg
        .split("<text")
        .skip(1)
        .filter_map(|s| {
            let s = &s[s.find('>')? + 1..];
            Some(s[..s.find("</text>")?].trim())
        })
        .collect();
    for title in [
        "t [s]",
        "rod.theta [rad], d_rod.theta [rad/s]",
        "rod.theta [rad]",
    ] {
        assert!(texts.contains(&title), "no {title:?} in {texts:?}");
    }
    assert!(texts.contains(&"0"), "a tick at 0 labelled 0: {texts:?}");
}

#[test]
fn animate_writes_a_self_contained_page() {
    let d = scratch("animate");
    let csv = pendulum_csv(&d);
    let html = d.join("a.html");
    let out = mbd([
        "animate".as_ref(),
        csv.as_os_str(),
        "--model".as_ref(),
        "examples/models/pendulum.toml".as_ref(),
        "-o".as_ref(),
        html.as_os_str(),
    ]);
    assert_eq!(out.code, 0, "{}", out.stderr);
    let page = std::fs::read_to_string(&html).unwrap();
    for forbidden in [
        "<script src",
        "<link",
        "fetch(",
        "XMLHttpRequest",
        "@import",
        "https://",
    ] {
        assert!(!page.contains(forbidden), "page contains {forbidden:?}");
    }
    assert!(page.contains("id=\"slider\"") && page.contains("id=\"play\""));
    assert!(page.contains("\"t\":[0.0,"), "trajectory embedded");
}

#[test]
fn help_shows_examples() {
    let out = mbd(["--help"]);
    assert_eq!(out.code, 0);
    assert!(out.stdout.contains("Examples:") && out.stdout.contains("mbd run examples/models/"));
    for cmd in ["run", "check", "plot", "animate"] {
        let out = mbd([cmd, "--help"]);
        assert_eq!(out.code, 0, "{cmd}");
        assert!(
            out.stdout.contains(&format!("mbd {cmd} ")),
            "{cmd} --help:\n{}",
            out.stdout
        );
    }
}

/// `mbd run --reactions` adds `<joint>.fx, .fy, .mz` per joint, the same in CSV and JSON: on
/// the slider-crank file every row's reactions equal the library's `ReactionSolver` at that
/// row's state (the CSV holds the state to full precision).
#[test]
fn run_reactions_adds_three_columns_per_joint() {
    let dir = scratch("reactions");
    let model = common::repo().join("examples/models/slider_crank_spring.toml");
    let csv = dir.join("r.csv");
    let o = run_model(&model, "rk4", &["--h", "0.005", "--reactions"], &csv);
    assert_eq!(o.code, 0, "{}", o.stderr);
    let sys = mbd_model::System::from_path(&model).unwrap();
    let (head, rows) = read_csv(&csv);
    // the reactions come after the residuals, before the energy balance
    let mut want = expected_columns(&model);
    let at = want.iter().position(|c| c == "max_abs_phidot").unwrap() + 1;
    let reactions: Vec<String> = sys
        .joints()
        .iter()
        .flat_map(|j| ["fx", "fy", "mz"].map(|c| format!("{}.{c}", j.name)))
        .collect();
    want.splice(at..at, reactions);
    assert_eq!(head, want);
    let n = sys.n_coords();
    let mut rs = mbd_solve::ReactionSolver::new(&sys).unwrap();
    let mut out = vec![mbd_solve::JointReaction::default(); sys.joints().len()];
    for row in &rows {
        let mut s = mbd_solve::State::consistent(&sys, 0.0).unwrap();
        s.t = row[0];
        s.q.as_mut_slice().copy_from_slice(&row[1..1 + n]);
        s.v.as_mut_slice().copy_from_slice(&row[1 + n..1 + 2 * n]);
        rs.compute(&sys, &s, &mut out).unwrap();
        let got = &row[at..at + 3 * out.len()];
        for (k, r) in out.iter().enumerate() {
            assert_eq!(got[3 * k..3 * k + 3], [r.force[0], r.force[1], r.moment]);
        }
    }
    let json = dir.join("r.json");
    let o = run_model(&model, "rk4", &["--h", "0.005", "--reactions"], &json);
    assert_eq!(o.code, 0, "{}", o.stderr);
    let doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let cols: Vec<String> = serde_json::from_value(doc["columns"].clone()).unwrap();
    assert_eq!(cols, want);
}

/// A spatial model whose given velocity leaves its joint (a radial component on the spherical
/// pendulum) gets the warning with advice that fits spatial bodies, which take no `inputs`.
#[test]
fn the_initial_change_warning_on_spatial_bodies_does_not_advise_inputs() {
    let dir = scratch("spatial_inputs");
    let text =
        std::fs::read_to_string(common::repo().join("examples/models/spherical_pendulum.toml"))
            .unwrap();
    let pushed = text.replacen(
        "velocity = [0.0, 1.5, 0.0]",
        "velocity = [0.3, 1.5, 0.0]",
        1,
    );
    assert_ne!(pushed, text);
    let model = dir.join("pushed.toml");
    std::fs::write(&model, pushed).unwrap();
    let o = run_model(&model, "rk4", &["--h", "0.005"], &dir.join("pushed.csv"));
    assert_eq!(o.code, 0, "{}", o.stderr);
    assert!(
        o.stderr.contains("d_bob.x given 0.3 used")
            && o.stderr.contains("spatial bodies have no inputs")
            && !o.stderr.contains("inputs = ["),
        "{}",
        o.stderr
    );
}

/// A slider-crank file that gives only the crank's 6 rad/s: `mbd run` warns that the
/// consistent state changed it, naming the value given and used and how to keep it; with
/// `inputs = ["d_theta"]` on the crank the run starts at exactly 6 rad/s, without the warning.
#[test]
fn run_warns_about_changed_initial_values_and_keeps_inputs() {
    let dir = scratch("inputs");
    let text =
        std::fs::read_to_string(common::repo().join("examples/models/slider_crank_spring.toml"))
            .unwrap();
    let mut given_only: Vec<String> = Vec::new();
    for line in text.lines() {
        if line.starts_with("velocity = ") {
            let keep_rate = line.ends_with(", 6.0]");
            given_only.push(if keep_rate {
                "velocity = [0.0, 0.0, 6.0]".into()
            } else {
                "velocity = [0.0, 0.0, 0.0]".into()
            });
        } else {
            given_only.push(line.to_string());
        }
    }
    let plain = dir.join("plain.toml");
    std::fs::write(&plain, given_only.join("\n")).unwrap();
    let out = dir.join("plain.csv");
    let o = run_model(&plain, "rk4", &["--h", "0.005"], &out);
    assert_eq!(o.code, 0, "{}", o.stderr);
    assert!(
        o.stderr
            .contains("warning: the initial state was made consistent")
            && o.stderr.contains("d_crank.theta given 6 used 0.")
            && o.stderr.contains("inputs = [\"d_theta\"]"),
        "{}",
        o.stderr
    );
    let marked = dir.join("marked.toml");
    let with_input = given_only.join("\n").replacen(
        "velocity = [0.0, 0.0, 6.0]",
        "velocity = [0.0, 0.0, 6.0]\ninputs = [\"d_theta\"]",
        1,
    );
    std::fs::write(&marked, with_input).unwrap();
    let out = dir.join("marked.csv");
    let o = run_model(&marked, "rk4", &["--h", "0.005"], &out);
    assert_eq!(o.code, 0, "{}", o.stderr);
    assert!(!o.stderr.contains("d_crank.theta given"), "{}", o.stderr);
    let (head, rows) = read_csv(&out);
    let k = head.iter().position(|h| h == "d_crank.theta").unwrap();
    assert_eq!(rows[0][k], 6.0);
}

/// `mbd plot` reads the JSON that `mbd run` writes as well as its CSV.
#[test]
fn plot_reads_the_json_of_run() {
    let dir = scratch("plot-json");
    let json = dir.join("p.json");
    let o = run_model(
        &common::repo().join("examples/models/pendulum.toml"),
        "rk4",
        &["--h", "0.005"],
        &json,
    );
    assert_eq!(o.code, 0, "{}", o.stderr);
    let svg = dir.join("p.svg");
    let o = mbd([
        "plot".as_ref(),
        json.as_os_str(),
        "--y".as_ref(),
        "rod.theta".as_ref(),
        "-o".as_ref(),
        svg.as_os_str(),
    ]);
    assert_eq!(o.code, 0, "{}", o.stderr);
    assert!(std::fs::read_to_string(&svg).unwrap().contains("<svg"));
}

/// `--save-state` writes the final state and `--initial-state` restarts from it: RUN 0 -> 1 s
/// then 1 -> 2 s ends where one run 0 -> 2 s ends, bit for bit, at h = 1e-3 and 0.01 (RK4 on
/// the pendulum; at 0.01 the first run's last step was 1 - 0.99 = 0.010000000000000009 until
/// the run loop kept the nominal h there, and the restart differed by 5.6e-17). A state of
/// another model is refused naming the difference, and an end time before the saved time is a
/// usage error.
#[test]
fn save_and_restart_from_a_state() {
    for h in ["1e-3", "0.01"] {
        save_and_restart_bit_for_bit(h);
    }
}

fn save_and_restart_bit_for_bit(h: &str) {
    let dir = scratch(&format!("restart_{h}"));
    let model = common::repo().join("examples/models/pendulum.toml");
    let arg = |p: &Path| p.as_os_str().to_owned();
    let run = |t_end: &str, extra: Vec<std::ffi::OsString>| {
        let mut a: Vec<std::ffi::OsString> = vec![
            "run".into(),
            arg(&model),
            "--solver".into(),
            "rk4".into(),
            "--t-end".into(),
            t_end.into(),
            "--h".into(),
            h.into(),
            "--out".into(),
            "/dev/null".into(),
        ];
        a.extend(extra);
        mbd(a)
    };
    let (half, whole, second) = (
        dir.join("half.json"),
        dir.join("whole.json"),
        dir.join("second.json"),
    );
    for (t_end, extra) in [
        ("1", vec!["--save-state".into(), arg(&half)]),
        ("2", vec!["--save-state".into(), arg(&whole)]),
        (
            "2",
            vec![
                "--initial-state".into(),
                arg(&half),
                "--save-state".into(),
                arg(&second),
            ],
        ),
    ] {
        let o = run(t_end, extra);
        assert_eq!(o.code, 0, "{}", o.stderr);
    }
    let read = |p: &Path| -> serde_json::Value {
        serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap()
    };
    let (a, b) = (read(&whole), read(&second));
    assert_eq!(a["t"], b["t"]);
    assert_eq!(a["q"], b["q"]);
    assert_eq!(a["v"], b["v"]);
    let o = run("0.5", vec!["--initial-state".into(), arg(&half)]);
    assert_eq!(o.code, 2, "{}", o.stderr);
    assert!(
        o.stderr.contains("not after the initial state's time 1"),
        "{}",
        o.stderr
    );
    let other = mbd([
        "run".as_ref(),
        common::repo()
            .join("examples/models/four_bar.toml")
            .as_os_str(),
        "--solver".as_ref(),
        "rk4".as_ref(),
        "--t-end".as_ref(),
        "2".as_ref(),
        "--h".as_ref(),
        "1e-3".as_ref(),
        "--initial-state".as_ref(),
        half.as_os_str(),
    ]);
    assert_eq!(other.code, 2, "{}", other.stderr);
    assert!(
        other.stderr.contains("do not match the model's"),
        "{}",
        other.stderr
    );
}

/// A model file's sensors become `mbd run` columns after the residuals.
#[test]
fn run_writes_the_model_sensors() {
    let dir = scratch("sensors");
    let model = dir.join("pendulum_tip.toml");
    let text =
        std::fs::read_to_string(common::repo().join("examples/models/pendulum.toml")).unwrap();
    std::fs::write(
        &model,
        format!(
            "{text}\n[[sensors]]\ntype = \"point\"\nname = \"tip\"\nbody = \"rod\"\npoint = [0.5, 0.0]\n\n\
             [[sensors]]\ntype = \"joint\"\nname = \"swing\"\njoint = \"pivot\"\n"
        ),
    )
    .unwrap();
    let csv = dir.join("p.csv");
    let o = run_model(&model, "rk4", &["--h", "0.005"], &csv);
    assert_eq!(o.code, 0, "{}", o.stderr);
    let (head, rows) = read_csv(&csv);
    let tail: Vec<&str> = head[head.len() - 8..].iter().map(String::as_str).collect();
    assert_eq!(
        tail,
        [
            "tip.x",
            "tip.y",
            "tip.vx",
            "tip.vy",
            "tip.ax",
            "tip.ay",
            "swing.angle",
            "swing.rate"
        ]
    );
    // the pivot is at the origin and the tip 1 m from it
    for r in &rows {
        let (x, y) = (r[head.len() - 8], r[head.len() - 7]);
        assert!((x.hypot(y) - 1.0).abs() < 1e-9, "{x} {y}");
    }
}

/// `mbd run --out` creates the output's folders (as `plot` and `animate` do).
#[test]
fn run_creates_the_output_folder() {
    let d = scratch("run-out-folder");
    let csv = d.join("new").join("sub").join("pendulum.csv");
    assert!(!csv.parent().unwrap().exists());
    common::run_pendulum_to(&csv);
    let text = std::fs::read_to_string(&csv).unwrap();
    assert_eq!(text.lines().count(), 12, "{text}");
}

/// `--atol` sets the absolute part of the adaptive tolerance: it needs `--tol`, must be
/// positive, and is recorded in the JSON output; a tighter one takes more steps.
#[test]
fn atol_sets_the_absolute_tolerance_of_adaptive_runs() {
    let dir = scratch("atol");
    let model = common::repo().join("examples/models/pendulum.toml");
    let json = dir.join("p.json");
    let run = |extra: &[&str]| run_model_until(&model, "index1:dopri5", extra, &json, "1");
    let without = run(&["--atol", "1e-12"]);
    assert_ne!(without.code, 0, "--atol without --tol ran");
    assert!(without.stderr.contains("--tol"), "{}", without.stderr);
    let negative = run(&["--tol", "1e-6", "--atol", "-1"]);
    assert_ne!(negative.code, 0);
    assert!(
        negative.stderr.contains("absolute tolerance"),
        "{}",
        negative.stderr
    );
    let steps = |extra: &[&str]| {
        let out = run(extra);
        assert_eq!(out.code, 0, "{extra:?}: {}", out.stderr);
        let v: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
        let rows: Vec<Vec<f64>> = serde_json::from_value(v["rows"].clone()).unwrap();
        (rows.len(), v["atol"].clone())
    };
    let (loose, none) = steps(&["--tol", "1e-4"]);
    assert!(none.is_null());
    let (tight, atol) = steps(&["--tol", "1e-4", "--atol", "1e-10"]);
    assert_eq!(atol, 1e-10);
    assert!(tight > loose, "{tight} rows against {loose}");
}
