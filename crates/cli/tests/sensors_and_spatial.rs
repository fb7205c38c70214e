//! The command line on what a model file adds beyond bodies and joints: reaction and energy
//! sensors, assembly from joint coordinates, spatial bodies.

mod common;
use common::{mbd, read_csv, run_model, scratch};

/// Reaction and energy sensors and assembly from joint coordinates, in a model file: `check`
/// lists them (and the bodies the assembly places), `run` writes the sensors' columns, and the
/// energy sensor's total is the `H` column.
#[test]
fn check_and_run_show_reaction_and_energy_sensors_and_the_assembly() {
    let d = scratch("sensors");
    let text =
        std::fs::read_to_string(common::repo().join("examples/models/slider_crank_spring.toml"))
            .unwrap()
            + r#"
[[sensors]]
type = "reaction"
name = "pin"
joint = "crank_pin"

[[sensors]]
type = "energy"
name = "all"

[[sensors]]
type = "energy"
name = "rod_e"
body = "rod"

[[assembly]]
joint = "crank_pivot"
coordinate = 1.0
rate = 6.0
"#;
    let model = d.join("sensors.toml");
    std::fs::write(&model, text).unwrap();
    let out = mbd(["check".as_ref(), model.as_os_str()]);
    assert_eq!(out.code, 0, "{}", out.stderr);
    for needle in [
        "sensors (3):",
        "pin              reaction of joint crank_pin",
        "all              energy of the model",
        "rod_e            energy of rod",
        "assembly from joint coordinates (1):",
        "crank_pivot      coordinate 1, rate 6",
        "places crank, rod, slider",
    ] {
        assert!(
            out.stdout.contains(needle),
            "lacks {needle:?}:\n{}",
            out.stdout
        );
    }
    let csv = d.join("out.csv");
    let out = run_model(&model, "rk4", &["--h", "0.01"], &csv);
    assert_eq!(out.code, 0, "{}", out.stderr);
    let (head, rows) = read_csv(&csv);
    let at = |c: &str| {
        head.iter()
            .position(|h| h == c)
            .unwrap_or_else(|| panic!("no column {c} in {head:?}"))
    };
    for c in [
        "pin.fx",
        "pin.fy",
        "pin.mz",
        "pin.fx_body",
        "pin.fy_body",
        "rod_e.kinetic",
    ] {
        at(c);
    }
    for r in &rows {
        assert_eq!(r[at("all.total")], r[at("H")]);
        assert!(r[at("rod_e.kinetic")] > 0.0);
    }
    // the crank starts at the assembled angle and rate
    assert!((rows[0][at("crank.theta")] - 1.0).abs() < 1e-9);
    assert!((rows[0][at("d_crank.theta")] - 6.0).abs() < 1e-9);
}

/// `mbd check` on a spatial model lists its spatial bodies and joints.
#[test]
fn check_lists_spatial_bodies_and_joints() {
    let out = mbd(["check", "examples/models/heavy_top.toml"]);
    assert_eq!(out.code, 0, "{}", out.stderr);
    for needle in [
        "spatial gravity: [0, 0, -9.81] m/s^2",
        "spatial bodies (1):",
        "principal moments [0.3, 0.3, 0.1]",
        "tip              spherical    ground - top (3 equations)",
        "degrees of freedom: 3",
        "top.d3z",
    ] {
        assert!(
            out.stdout.contains(needle),
            "lacks {needle:?}:\n{}",
            out.stdout
        );
    }
}

/// `mbd check` lists spatial force elements; `mbd run` with `--energy` books the damper's
/// loss and the thruster's work so that the balance closes.
#[test]
fn spatial_forces_are_listed_and_balanced() {
    let model = common::repo().join("examples/models/spatial_spring_pendulum.toml");
    let out = mbd(["check".as_ref(), model.as_os_str()]);
    assert_eq!(out.code, 0, "{}", out.stderr);
    for needle in [
        "spatial forces (2):",
        "strut            spring_damper  ground - rod (non-conservative)",
        "thruster         force          rod - ground (non-conservative)",
    ] {
        assert!(
            out.stdout.contains(needle),
            "lacks {needle:?}:\n{}",
            out.stdout
        );
    }
    let d = scratch("spatial-forces");
    let csv = d.join("pendulum.csv");
    let out = run_model(&model, "symplectic:2", &["--h", "1e-3"], &csv);
    assert_eq!(out.code, 0, "{}", out.stderr);
    assert!(
        out.stderr
            .contains("H not conserved (non-conservative forces strut, thruster)"),
        "{}",
        out.stderr
    );
    let residual: f64 = out
        .stderr
        .split("energy balance residual ")
        .nth(1)
        .and_then(|r| r.split_whitespace().next())
        .and_then(|x| x.parse().ok())
        .expect("the summary states the balance residual");
    assert!(residual < 1e-9, "{residual:e}");
    let (head, rows) = read_csv(&csv);
    assert!(
        head.iter().any(|h| h == "rod.d3z") && rows.len() > 2,
        "{head:?}"
    );
}

/// `mbd run` writes a spatial model's columns (with `--reactions`, the ball joint's force and
/// zero moment); `mbd animate` draws it on the 3D page without a warning, and a `--trace` body
/// the model lacks is an error naming it.
#[test]
fn a_spatial_model_runs_and_is_animated_in_3d() {
    let d = scratch("top");
    let model = common::repo().join("examples/models/heavy_top.toml");
    let csv = d.join("top.csv");
    let out = run_model(
        &model,
        "rk4-projected",
        &["--h", "0.01", "--reactions"],
        &csv,
    );
    assert_eq!(out.code, 0, "{}", out.stderr);
    let (head, rows) = read_csv(&csv);
    assert!(
        head.iter().any(|h| h == "top.d3z") && rows.len() == 3,
        "{head:?}"
    );
    // the ball joint's reaction: a force and no moment about the tip
    let at = |c: &str| head.iter().position(|h| h == c).unwrap();
    for r in &rows {
        assert!(r[at("tip.fz")] > 1.0, "{}", r[at("tip.fz")]);
        for c in ["tip.mx", "tip.my", "tip.mz"] {
            assert!(r[at(c)].abs() < 1e-9, "{c} = {}", r[at(c)]);
        }
    }
    let page = d.join("top.html");
    let out = mbd([
        "animate".as_ref(),
        "--model".as_ref(),
        model.as_os_str(),
        "--out".as_ref(),
        page.as_os_str(),
        csv.as_os_str(),
    ]);
    assert_eq!(out.code, 0, "{}", out.stderr);
    assert!(
        !out.stderr.contains("warning") && !out.stderr.contains("planar"),
        "{}",
        out.stderr
    );
    let html = std::fs::read_to_string(&page).unwrap();
    assert!(
        html.contains("data-matrix") || html.contains("mbdCamera"),
        "the 3D page"
    );
    std::fs::remove_file(&page).unwrap();
    for (trace, needles) in [
        ("tpo", &["--trace", "'tpo'", "not a body", "top"][..]),
        ("top:1,2", &["--trace", "'1,2'", "three finite numbers"][..]),
    ] {
        let out = mbd([
            "animate".as_ref(),
            "--model".as_ref(),
            model.as_os_str(),
            "--out".as_ref(),
            page.as_os_str(),
            "--trace".as_ref(),
            trace.as_ref(),
            csv.as_os_str(),
        ]);
        common::assert_fails(&out, 2, needles);
        assert!(!page.exists(), "no page written for --trace {trace}");
    }
    // a planar model has no body to trace in 3D
    let pend = common::pendulum_csv(&d);
    let out = mbd([
        "animate".as_ref(),
        pend.as_os_str(),
        "--model".as_ref(),
        "examples/models/pendulum.toml".as_ref(),
        "-o".as_ref(),
        page.as_os_str(),
        "--trace".as_ref(),
        "bob".as_ref(),
    ]);
    common::assert_fails(&out, 2, &["--trace bob", "no spatial bodies"]);
}
