//! Assembly from joint coordinates: revolute angles, prismatic slides and their rates given
//! per joint place the bodies and are kept exactly by the consistent initial state.

use mbd::model::{models, JointInitialSpec, ModelFile, System};
use mbd::solve::{consistent_state, initial_changes};

fn with_assembly(file: &ModelFile, entries: &[(&str, Option<f64>, Option<f64>)]) -> ModelFile {
    let mut file = file.clone();
    file.assembly = entries
        .iter()
        .map(|&(joint, coordinate, rate)| JointInitialSpec {
            joint: joint.into(),
            coordinate,
            rate,
        })
        .collect();
    file
}

fn max_abs(x: &[f64]) -> f64 {
    x.iter().fold(0.0, |m, v| m.max(v.abs()))
}

/// An open chain is placed exactly by the tree: a double pendulum given both relative angles
/// and rates has them in its guess, with every constraint and its velocity form at round-off
/// before any projection.
#[test]
fn an_open_chain_is_placed_exactly_from_its_joint_angles() {
    let sys = models::paper_a_double_pendulum().unwrap();
    let names: Vec<String> = sys.joints().iter().map(|j| j.name.clone()).collect();
    let base = sys.to_model_file();
    let file = with_assembly(
        &base,
        &[
            (&names[0], Some(-0.4), Some(1.5)),
            (&names[1], Some(0.9), Some(-2.0)),
        ],
    );
    let sys = file.build().unwrap();
    let (q, v) = sys.initial_guess();
    assert_eq!((q[2], q[5]), (-0.4, -0.4 + 0.9));
    assert_eq!((v[2], v[5]), (1.5, 1.5 - 2.0));
    let mut phi = vec![0.0; sys.n_constraints()];
    sys.phi(q.as_slice(), 0.0, &mut phi);
    assert!(max_abs(&phi) < 1e-15, "{phi:?}");
    sys.phi_dot(q.as_slice(), v.as_slice(), 0.0, &mut phi);
    assert!(max_abs(&phi) < 1e-15, "{phi:?}");
    // the projection has nothing to do
    let x = consistent_state(&sys, 0.0).unwrap();
    assert!(
        x.position_correction < 1e-15 && x.velocity_correction < 1e-14,
        "{x:?}"
    );
}

/// A closed loop: the slider-crank given only its crank angle and rate (the stored poses are
/// the model's own, at another crank angle) starts at exactly that angle and rate, on the
/// constraints, and `initial_changes` reports no change of the crank.
#[test]
fn a_closed_loop_keeps_the_given_crank_angle_and_rate() {
    let base = models::slider_crank().unwrap().to_model_file();
    let file = with_assembly(&base, &[("crank_pin", Some(1.1), Some(6.0))]);
    let sys = file.build().unwrap();
    let x = consistent_state(&sys, 0.0).unwrap();
    let (q, v) = (x.q.as_slice(), x.v.as_slice());
    let crank = 0; // the first body
    assert!((q[3 * crank + 2] - 1.1).abs() < 1e-14, "{}", q[2]);
    assert!((v[3 * crank + 2] - 6.0).abs() < 1e-12, "{}", v[2]);
    assert!(x.residual < 1e-13 && x.velocity_residual < 1e-12, "{x:?}");
    let changes = initial_changes(&sys, q, v);
    assert!(
        changes
            .iter()
            .all(|c| !c.name.starts_with("crank.") && !c.name.starts_with("d_crank.")),
        "{changes:?}"
    );
    // the model without assembly starts elsewhere
    let plain = consistent_state(&base.build().unwrap(), 0.0).unwrap();
    assert!((plain.q[2] - 1.1).abs() > 0.1);
}

/// A crank angle given without a rate keeps the crank's rate from the bodies' stored velocities
/// (consistent at another angle), not the rate the velocity projection would pick: the
/// slider-crank with consistent velocities at its stored angle (crank rate 1.68 rad/s),
/// re-assembled at a crank angle 0.7 rad further on, starts at that crank rate (before: 1.34,
/// the projection spread the rod's and the slider's now inconsistent velocities over the
/// crank too). A given rate still wins.
#[test]
fn a_crank_angle_without_a_rate_keeps_the_bodies_crank_rate() {
    let sys = models::slider_crank().unwrap();
    let x = consistent_state(&sys, 0.0).unwrap();
    let mut base = sys.to_model_file();
    // consistent velocities at the stored angle: the projection of a 30 rad/s crank rate
    let crank_angle = x.q[2];
    let w = 30.0;
    let (qs, vs) = {
        let mut v = x.v.clone();
        v.fill(0.0);
        v[2] = w;
        let p = mbd::solve::project_state(
            &sys,
            x.q.as_slice(),
            v.as_slice(),
            0.0,
            mbd::solve::ConsistentOptions::default(),
        )
        .unwrap();
        (p.q, p.v)
    };
    for (i, b) in base.bodies.iter_mut().enumerate() {
        b.position = [qs[3 * i], qs[3 * i + 1], qs[3 * i + 2]];
        b.velocity = [vs[3 * i], vs[3 * i + 1], vs[3 * i + 2]];
    }
    let given_w = vs[2];
    for (rate, want) in [(None, given_w), (Some(-4.0), -4.0)] {
        let file = with_assembly(&base, &[("crank_pin", Some(crank_angle + 0.7), rate)]);
        let sys = file.build().unwrap();
        let c = consistent_state(&sys, 0.0).unwrap();
        assert!((c.q[2] - crank_angle - 0.7).abs() < 1e-14, "{}", c.q[2]);
        assert!(
            (c.v[2] - want).abs() < 1e-12 * want.abs(),
            "rate {rate:?}: {} against {want}",
            c.v[2]
        );
        assert!(c.residual < 1e-13 && c.velocity_residual < 1e-12, "{c:?}");
    }
}

/// A prismatic joint's slide and rate: a slider placed on its guide at s = 0.35 moving at
/// -0.2 m/s, read back as the guide's coordinate.
#[test]
fn a_slide_and_its_rate_place_a_slider() {
    let text = r#"
[[bodies]]
name = "slider"
mass = 1.0
inertia = 0.1
position = [5.0, 3.0, 0.4]
[[joints]]
type = "prismatic"
name = "guide"
body_a = "ground"
point_a = [1.0, 2.0]
body_b = "slider"
point_b = [0.1, 0.0]
axis = [3.0, 4.0]
angle = 0.25
[[assembly]]
joint = "guide"
coordinate = 0.35
rate = -0.2
"#;
    let sys = System::from_toml(text).unwrap();
    let x = consistent_state(&sys, 0.0).unwrap();
    let (q, v) = (x.q.as_slice(), x.v.as_slice());
    assert!(x.position_correction < 1e-15, "{x:?}");
    assert_eq!(q[2], 0.25);
    let (s, c) = q[2].sin_cos();
    let p = [q[0] + c * 0.1, q[1] + s * 0.1];
    let u = [0.6, 0.8];
    let slide = (p[0] - 1.0) * u[0] + (p[1] - 2.0) * u[1];
    let across = -(p[0] - 1.0) * u[1] + (p[1] - 2.0) * u[0];
    assert!(
        (slide - 0.35).abs() < 1e-15 && across.abs() < 1e-15,
        "{slide} {across}"
    );
    let rate = v[0] * u[0] + v[1] * u[1];
    assert!((rate + 0.2).abs() < 1e-15 && v[2] == 0.0, "{v:?}");
    // written back to a file and read again
    let back = sys.to_model_file();
    assert_eq!(back.assembly.len(), 1);
    assert_eq!(back.assembly[0].coordinate, Some(0.35));
}

/// Bad entries are refused naming the joint: another joint kind, a joint given twice, an
/// entry without values, a non-finite value, an unknown joint; and more coordinates than the
/// loop's degree of freedom are refused naming the joints.
#[test]
fn bad_assembly_entries_are_refused() {
    let base = models::slider_crank().unwrap().to_model_file();
    let err = |entries: &[(&str, Option<f64>, Option<f64>)]| {
        with_assembly(&base, entries)
            .build()
            .unwrap_err()
            .to_string()
    };
    let e = err(&[("slide", Some(0.1), None), ("slide", None, Some(1.0))]);
    assert!(
        e.contains("joint 'slide'") && e.contains("given twice"),
        "{e}"
    );
    let e = err(&[("crank_pin", None, None)]);
    assert!(e.contains("neither 'coordinate' nor 'rate'"), "{e}");
    let e = err(&[("crank_pin", Some(f64::INFINITY), None)]);
    assert!(
        e.contains("joint 'crank_pin'") && e.contains("not finite"),
        "{e}"
    );
    let e = err(&[("no_such_joint", Some(1.0), None)]);
    assert!(
        e.contains("'no_such_joint'") && e.contains("no joint has this name"),
        "{e}"
    );
    let mut welded = base.clone();
    welded.joints.push(
        ModelFile::from_toml(
            "bodies = []\n[[joints]]\ntype = \"weld\"\nname = \"w\"\nbody_a = \"ground\"\nbody_b = \"crank\"\n",
        )
        .unwrap()
        .joints[0]
            .clone(),
    );
    let e = with_assembly(&welded, &[("w", Some(0.0), None)])
        .to_builder()
        .unwrap()
        .build()
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("joint 'w'") && e.contains("revolute or prismatic"),
        "{e}"
    );
    // the crank angle and the slide both given: one degree of freedom, two held coordinates
    let sys = with_assembly(
        &base,
        &[("crank_pin", Some(1.1), None), ("slide", Some(0.2), None)],
    )
    .build()
    .unwrap();
    let e = consistent_state(&sys, 0.0).unwrap_err().to_string();
    assert!(
        e.contains("joints 'crank_pin', 'slide'")
            && e.contains("2 joint coordinates given, but the model has 1 degree(s) of freedom"),
        "{e}"
    );
}
