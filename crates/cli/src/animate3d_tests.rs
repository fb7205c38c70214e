//! Unit tests of the 3D page: the equivalent inertia box, the markers in the principal frames,
//! `--trace`, the scene and mixed models.

use super::*;

/// A uniform box's principal moments: `J_1 = m (b^2 + c^2) / 3` etc.
fn box_moments(m: f64, h: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|i| m * (h[(i + 1) % 3].powi(2) + h[(i + 2) % 3].powi(2)) / 3.0)
}

#[test]
fn the_equivalent_box_of_a_box_is_the_box() {
    for (m, h) in [
        (2.0, [0.3, 0.1, 0.05]),
        (0.25, [1.0, 1.0, 1.0]),
        (7.0, [0.02, 0.5, 0.2]),
    ] {
        let got = equivalent_box(m, box_moments(m, h));
        for k in 0..3 {
            assert!((got[k] - h[k]).abs() <= 1e-14 * h[k], "{got:?} != {h:?}");
        }
    }
    // the heavy top: a = b = sqrt(3 (0.3 + 0.1 - 0.3) / 2), c = sqrt(3 (0.3 + 0.3 - 0.1) / 2)
    let top = equivalent_box(1.0, [0.3, 0.3, 0.1]);
    assert!((top[0] - 0.15f64.sqrt()).abs() < 1e-15, "{top:?}");
    assert!((top[1] - 0.15f64.sqrt()).abs() < 1e-15, "{top:?}");
    assert!((top[2] - 0.75f64.sqrt()).abs() < 1e-15, "{top:?}");
    // a uniform cube of side 1 and mass 6: J = 1 about every axis, half-extent 0.5
    assert_eq!(equivalent_box(6.0, [1.0, 1.0, 1.0]), [0.5, 0.5, 0.5]);
}

#[test]
fn flat_and_thin_bodies_have_zero_extents() {
    // a plate 2a x 2b: J_3 = J_1 + J_2, no thickness
    let plate = equivalent_box(2.0, box_moments(2.0, [0.3, 0.2, 0.0]));
    assert!((plate[0] - 0.3).abs() < 1e-15 && (plate[1] - 0.2).abs() < 1e-15);
    assert_eq!(plate[2], 0.0);
    // a thin rod of length L along z: J_1 = J_2 = m L^2 / 12, J_3 = 0
    let (m, l) = (3.0, 1.2);
    let rod = equivalent_box(m, [m * l * l / 12.0, m * l * l / 12.0, 0.0]);
    assert_eq!(&rod[..2], &[0.0, 0.0]);
    assert!((rod[2] - 0.5 * l).abs() < 1e-15, "{rod:?}");
    // a round-off violation of the triangle inequality: zero, not NaN
    let r = equivalent_box(1.0, [1.0, 1.0, 2.0 + 4e-16]);
    assert_eq!(r[2], 0.0);
    assert!(r.iter().all(|x| x.is_finite()));
}

const CHAIN: &str = r#"
spatial_gravity = [0.0, 0.0, -9.81]
[[spatial_bodies]]
name = "rod"
mass = 1.0
moments = [0.05, 0.05, 0.002]
position = [0.0, 0.0, -0.4]
[[spatial_bodies]]
name = "plate"
mass = 2.0
moments = [0.01, 0.04, 0.05]
axes = [[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]
position = [0.0, 0.0, -1.0]
[[spatial_joints]]
type = "spherical"
name = "pivot"
body_a = "ground"
point_a = [0.0, 0.0, 0.0]
body_b = "rod"
point_b = [0.0, 0.0, 0.4]
[[spatial_joints]]
type = "spherical"
name = "hinge"
body_a = "rod"
point_a = [0.0, 0.0, -0.4]
body_b = "plate"
point_b = [0.1, 0.0, 0.2]
"#;

#[test]
fn joint_points_are_lowered_to_the_principal_frames() {
    // the plate's principal axes are its body axes turned by 90 degrees about z: its body
    // point (0.1, 0, 0.2) is (0, -0.1, 0.2) in its principal frame, and at the initial
    // state (the plate's centre of mass 0.2 below the hinge, but 0.1 to the side) the
    // lowered point sits at the body point's place, x + R p
    let sys = System::from_toml(CHAIN).unwrap();
    let (joints, springs) = links(&sys);
    assert!(springs.is_empty());
    let hinge = &joints[1];
    assert_eq!((hinge.a, hinge.b, hinge.kind), (0, 1, "spherical"));
    for (got, want) in hinge.pb.iter().zip([0.0, -0.1, 0.2]) {
        assert!((got - want).abs() < 1e-15, "{:?}", hinge.pb);
    }
    let (q, _) = sys.initial_guess();
    let w = world(q.as_slice(), &page_bodies(&sys), 1, hinge.pb);
    for (got, want) in w.iter().zip([0.1, 0.0, -0.8]) {
        assert!((got - want).abs() < 1e-12, "{w:?}");
    }
    let pivot = world(q.as_slice(), &page_bodies(&sys), 0, joints[0].pb);
    assert!(pivot.iter().all(|x| x.abs() < 1e-12), "{pivot:?}");
}

#[test]
fn trace_defaults_to_the_last_body_and_names_a_bad_body() {
    let sys = System::from_toml(CHAIN).unwrap();
    let t = resolve_trace(&sys, None).unwrap();
    assert_eq!((t.body, t.point), (1, [0.0; 3]));
    assert!(t.label.contains("plate"));
    let spec = TraceSpec {
        body: "plate".into(),
        point: Some([0.1, 0.0, 0.0]),
    };
    let t = resolve_trace(&sys, Some(&spec)).unwrap();
    assert_eq!(t.body, 1);
    assert!((t.point[1] + 0.1).abs() < 1e-15, "{:?}", t.point);
    let bad = TraceSpec {
        body: "rdo".into(),
        point: None,
    };
    let e = resolve_trace(&sys, Some(&bad)).unwrap_err().to_string();
    assert!(e.contains("'rdo'") && e.contains("rod, plate"), "{e}");
}

#[test]
fn the_page_holds_every_box_corner_and_draws_flat_bodies_thin() {
    let sys = System::from_toml(CHAIN).unwrap();
    let (q, _) = sys.initial_guess();
    let mut q2 = q.as_slice().to_vec();
    for k in [0, 12] {
        q2[k] += 2.0; // both bodies 2 m along x
    }
    let frames = vec![q.as_slice().to_vec(), q2];
    let html = page("<chain>", &sys, None, vec![0.0, 1.0], frames.clone()).unwrap();
    assert_eq!(
        html.matches("</script>").count(),
        2,
        "only the page's scripts close"
    );
    assert!(html.contains("&lt;chain&gt;") && !html.contains("http://"));
    let start = html.find("type=\"application/json\">").unwrap() + 24;
    let end = start + html[start..].find("</script>").unwrap();
    let v: serde_json::Value = serde_json::from_str(&html[start..end]).unwrap();
    let num = |x: &serde_json::Value| x.as_f64().unwrap();
    let lo: Vec<f64> = v["scene"]["lo"]
        .as_array()
        .unwrap()
        .iter()
        .map(num)
        .collect();
    let hi: Vec<f64> = v["scene"]["hi"]
        .as_array()
        .unwrap()
        .iter()
        .map(num)
        .collect();
    assert!(hi[0] - lo[0] >= 2.0, "{lo:?} {hi:?}");
    let radius = 0.5 * (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt();
    for (k, b) in v["bodies"].as_array().unwrap().iter().enumerate() {
        let half: Vec<f64> = b["half"].as_array().unwrap().iter().map(num).collect();
        let drawn: Vec<f64> = b["drawn"].as_array().unwrap().iter().map(num).collect();
        let m = &sys.spatial_bodies()[k].inertia;
        assert_eq!(half, equivalent_box(m.mass(), m.moments()).to_vec());
        for i in 0..3 {
            assert_eq!(drawn[i], half[i].max(THIN * radius), "{} {i}", b["name"]);
        }
        for f in &frames {
            for c in corners([half[0], half[1], half[2]]) {
                let w = world(f, &page_bodies(&sys), k as i64, c);
                assert!((0..3).all(|i| lo[i] <= w[i] && w[i] <= hi[i]), "{w:?}");
            }
        }
    }
    // the plate (J_3 = J_1 + J_2) is flat, drawn with a small positive thickness
    let plate = &v["bodies"][1];
    assert_eq!(num(&plate["half"][2]), 0.0);
    let thick = num(&plate["drawn"][2]);
    assert!(thick > 0.0 && thick <= 0.01 * radius, "{thick} of {radius}");
}

#[test]
fn planar_bodies_of_a_mixed_model_are_centres_of_mass_at_z_0() {
    let mixed = format!(
        "{CHAIN}\n[[bodies]]\nname = \"crank\"\nmass = 1.0\ninertia = 0.1\n\
         position = [3.0, 0.5, 0.2]\n"
    );
    let sys = System::from_toml(&mixed).unwrap();
    let (q, _) = sys.initial_guess();
    let html = page("m", &sys, None, vec![0.0], vec![q.as_slice().to_vec()]).unwrap();
    let start = html.find("type=\"application/json\">").unwrap() + 24;
    let end = start + html[start..].find("</script>").unwrap();
    let v: serde_json::Value = serde_json::from_str(&html[start..end]).unwrap();
    assert_eq!(v["planar"][0]["name"], "crank");
    assert_eq!(v["planar"][0]["off"], 0);
    // the spatial bodies' coordinates follow the planar body's three
    assert_eq!(v["bodies"][0]["off"], 3);
    assert_eq!(v["bodies"][1]["off"], 15);
    // the scene reaches the planar centre of mass (3, 0.5) in the plane z = 0
    assert_eq!(v["scene"]["hi"][0], 3.0);
    assert!(v["scene"]["hi"][2].as_f64().unwrap() >= 0.0);
    // the trace defaults to the last spatial body, not the planar one
    assert_eq!(v["trace"]["body"], 1);
    let spec = TraceSpec {
        body: "crank".into(),
        point: None,
    };
    let e = page(
        "m",
        &sys,
        Some(&spec),
        vec![0.0],
        vec![q.as_slice().to_vec()],
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("'crank' is a planar body"), "{e}");
}

#[test]
fn point_masses_are_spheres_after_the_bodies_and_joints_reach_them() {
    let model = format!(
        "{CHAIN}\n[[spatial_bodies]]\nname = \"bob\"\nkind = \"point_mass\"\nmass = 0.5\n\
         position = [2.0, -1.0, -3.0]\n\n[[spatial_joints]]\ntype = \"distance\"\n\
         name = \"tether\"\nbody_a = \"ground\"\nbody_b = \"bob\"\nlength = 3.741657386773941\n"
    );
    let sys = System::from_toml(&model).unwrap();
    let (q, _) = sys.initial_guess();
    let html = page("m", &sys, None, vec![0.0], vec![q.as_slice().to_vec()]).unwrap();
    let start = html.find("type=\"application/json\">").unwrap() + 24;
    let end = start + html[start..].find("</script>").unwrap();
    let v: serde_json::Value = serde_json::from_str(&html[start..end]).unwrap();
    let nb = sys.spatial_bodies().len();
    let bob = &v["bodies"][nb];
    assert_eq!(bob["name"], "bob");
    assert_eq!(bob["point"], true);
    assert_eq!(bob["off"], 12 * nb);
    assert!(bob["drawn"][0].as_f64().unwrap() > 0.0);
    assert_eq!(v["bodies"][0]["point"], false);
    let tether = v["joints"]
        .as_array()
        .unwrap()
        .iter()
        .find(|j| j["name"] == "tether")
        .unwrap();
    assert_eq!(tether["b"], nb);
    // the scene reaches the point mass, and a trace on it is its position
    assert_eq!(v["scene"]["lo"][2], -3.0);
    let spec = TraceSpec {
        body: "bob".into(),
        point: None,
    };
    let html = page(
        "m",
        &sys,
        Some(&spec),
        vec![0.0],
        vec![q.as_slice().to_vec()],
    )
    .unwrap();
    assert!(
        html.contains("\"trace\":{\"body\":2,\"point\":[0.0,0.0,0.0]"),
        "trace"
    );
}
