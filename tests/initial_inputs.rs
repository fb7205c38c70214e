//! Initial inputs: values a model marks to be kept by the consistent-state solve, the others
//! solved for; the changes of given values reported; inputs that over-determine an equation
//! are an error naming it.

use mbd::model::{Body, Coord, ModelFile, System, SystemBuilder};
use mbd::solve::{consistent_state, initial_changes, SolveError};

/// The project's slider-crank (crank 0.15 m at 45 degrees, rod 0.5 m, slider on the x axis)
/// whose crank is given only its angular velocity, 6 rad/s (every other velocity 0); `mark`
/// changes the bodies (inputs, positions).
fn slider_crank(mark: impl Fn(&str, Body) -> Body) -> System {
    let mut file = mbd::model::models::slider_crank().unwrap().to_model_file();
    file.gravity = [0.0, 0.0];
    for body in &mut file.bodies {
        body.velocity = [0.0; 3];
    }
    file.bodies[0].velocity[2] = 6.0;
    let mut b = SystemBuilder::new();
    let sys = file.build().unwrap();
    for body in sys.bodies() {
        b.add_body(mark(&body.name, body.clone()));
    }
    for j in sys.joints() {
        b.add_joint(j.clone());
    }
    b.build().unwrap()
}

/// Without inputs the mass-weighted projection shares the crank's 6 rad/s out among the bodies
/// (the crank keeps about 0.34 rad/s), and the change is reported; with the crank's angular
/// velocity an input it is exactly 6 rad/s and the others follow from the constraints.
#[test]
fn a_marked_crank_velocity_is_kept_exactly() {
    let plain = slider_crank(|_, b| b);
    let x = consistent_state(&plain, 0.0).unwrap();
    assert!(x.v[2] < 1.0, "{}", x.v[2]);
    let changes = initial_changes(&plain, x.q.as_slice(), x.v.as_slice());
    let c = changes
        .iter()
        .find(|c| c.name == "d_crank.theta")
        .expect("the crank's rate is reported");
    assert_eq!(c.given, 6.0);
    assert!((c.used - x.v[2]).abs() == 0.0);

    let marked = slider_crank(|name, b| {
        if name == "crank" {
            b.input_velocity(Coord::Theta)
        } else {
            b
        }
    });
    let x = consistent_state(&marked, 0.0).unwrap();
    assert_eq!(x.v[2], 6.0);
    assert!(x.velocity_residual < 1e-13, "{}", x.velocity_residual);
    // the crank's centre moves at r/2 * 6 rad/s about the pin
    let speed = x.v[0].hypot(x.v[1]);
    assert!((speed - 0.075 * 6.0).abs() < 1e-12, "{speed}");
    assert!(initial_changes(&marked, x.q.as_slice(), x.v.as_slice()).is_empty());
}

/// A position input is kept too: a crank angle given 0.1 rad off the other bodies' positions
/// stays, and the rod and slider move to meet it.
#[test]
fn a_marked_crank_angle_is_kept_and_the_others_assemble() {
    let sys = slider_crank(|name, b| {
        if name == "crank" {
            let th = b.position[2] + 0.1;
            let r = 0.15;
            b.position(0.5 * r * th.cos(), 0.5 * r * th.sin(), th)
                .input_position(Coord::Theta)
        } else {
            b
        }
    });
    let x = consistent_state(&sys, 0.0).unwrap();
    assert_eq!(x.q[2], std::f64::consts::FRAC_PI_4 + 0.1);
    assert!(x.residual < 1e-13, "{}", x.residual);
    assert!(x.position_correction > 1e-3);
}

/// Inputs that leave an equation no free velocity: the crank's rate and the slider's velocity
/// both kept, inconsistent with each other, are an error naming the inputs and an equation.
#[test]
fn over_determining_inputs_are_an_error_naming_them() {
    let sys = slider_crank(|name, b| match name {
        "crank" => b.input_velocity(Coord::Theta),
        "slider" => b.velocity(1.0, 0.0, 0.0).input_velocity(Coord::X),
        _ => b,
    });
    let e = consistent_state(&sys, 0.0).unwrap_err();
    assert!(
        matches!(
            e,
            SolveError::OverdeterminedInputs {
                level: "velocity",
                ..
            }
        ),
        "{e:?}"
    );
    let m = e.to_string();
    assert!(
        m.contains("d_crank.theta") && m.contains("d_slider.x"),
        "{m}"
    );
}

/// Model files mark inputs by name (`inputs = ["d_theta"]`); a point mass cannot mark its
/// angle, a body with a frame offset cannot mark x or y; the inputs survive a round trip
/// through the file format.
#[test]
fn model_files_mark_inputs_by_name() {
    let text = r#"
        [[bodies]]
        name = "rod"
        mass = 1.0
        inertia = 0.1
        position = [0.5, 0.0, 0.0]
        velocity = [0.0, 0.0, 2.0]
        inputs = ["d_theta", "theta"]

        [[joints]]
        type = "revolute"
        name = "pin"
        body_a = "ground"
        point_a = [0.0, 0.0]
        body_b = "rod"
        point_b = [-0.5, 0.0]
    "#;
    let sys = ModelFile::from_toml(text).unwrap().build().unwrap();
    assert_eq!(sys.bodies()[0].inputs.velocity, [false, false, true]);
    assert_eq!(sys.bodies()[0].inputs.position, [false, false, true]);
    let x = consistent_state(&sys, 0.0).unwrap();
    assert_eq!(x.v[2], 2.0);
    let back = sys.to_model_file().to_toml().unwrap();
    assert!(back.contains("inputs = [\"theta\", \"d_theta\"]"), "{back}");

    let bad = text.replace("inputs = [\"d_theta\", \"theta\"]", "inputs = [\"d_phi\"]");
    let e = ModelFile::from_toml(&bad).unwrap_err().to_string();
    assert!(e.contains("d_phi") && e.contains("d_theta"), "{e}");
    let framed = text.replace(
        "inputs = [\"d_theta\", \"theta\"]",
        "inputs = [\"x\"]\n        com = [0.1, 0.0]",
    );
    let e = ModelFile::from_toml(&framed)
        .unwrap()
        .build()
        .unwrap_err()
        .to_string();
    assert!(e.contains("'rod'") && e.contains("com"), "{e}");
    let point = text
        .replace("inertia = 0.1\n", "kind = \"point_mass\"\n")
        .replace("velocity = [0.0, 0.0, 2.0]", "velocity = [0.0, 2.0, 0.0]")
        .replace("point_b = [-0.5, 0.0]", "point_b = [0.0, 0.0]");
    let e = ModelFile::from_toml(&point)
        .unwrap()
        .build()
        .unwrap_err()
        .to_string();
    assert!(e.contains("point mass has no angle"), "{e}");
}
