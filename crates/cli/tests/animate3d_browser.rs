//! Drives the 3D animation page (models with spatial bodies) in headless Chromium in a
//! 1000 x 700 window: the heavy top (examples/models/heavy_top.toml) and a chain of two rods on
//! ball joints ending in a flat plate (a model written here), each at a given time and, for the
//! chain, from two cameras set through the URL hash. On each page:
//!
//! * the published camera matrix is the one the documented formula gives for the published
//!   angles, zoom, focal length and target, and the requested angles are the published ones;
//! * the drawn centre of mass of every body is the CSV's `(x, y, z)` projected through that
//!   matrix, to within 1 px;
//! * every corner of every box face is the CSV's centre of mass plus the equivalent inertia
//!   box's half-extents (computed here from the model's mass and moments) along the CSV's
//!   directors, projected, to within 1 px; so is the distance of opposite corners;
//! * the joints, the links from centres of mass to joints and the trace's polyline (the
//!   `--trace` point of every frame) sit where the CSV and the model put them;
//! * the axes are labelled `x`, `y`, `z`, the legend lies beside the drawing, the page needs no
//!   scrollbar and contains no `http://` or `https://`;
//!
//! and screenshots from the two cameras differ. Skips (with a message) when Chromium is not
//! installed.

mod common;
use common::browser::{
    by_id, check_fits_the_window, chrome, chromium, dom_at_1000x700, elements, png_size, Element,
    WINDOW,
};
use common::{mbd, read_csv, repo, scratch};
use std::path::{Path, PathBuf};

const TOP: &str = "examples/models/heavy_top.toml";

/// Two rods hung on ball joints and a flat plate (`J_3 = J_1 + J_2`: a zero half-extent) on the
/// second rod's end, swinging out of any one plane.
const CHAIN: &str = r#"
spatial_gravity = [0.0, 0.0, -9.81]

[[spatial_bodies]]
name = "rod1"
mass = 1.0
moments = [0.05, 0.05, 0.002]
position = [0.0, 0.0, -0.4]
velocity = [0.8, 0.0, 0.0]

[[spatial_bodies]]
name = "rod2"
mass = 1.0
moments = [0.05, 0.05, 0.002]
position = [0.0, 0.0, -1.2]
velocity = [1.6, 0.5, 0.0]

[[spatial_bodies]]
name = "plate"
mass = 2.0
moments = [0.04, 0.01, 0.05]
position = [0.0, 0.0, -1.8]
orientation = { euler = { sequence = "xyz", angles = [1.5707963267948966, 0.0, 0.0] } }
angular_velocity = [0.0, 0.0, 3.0]

[[spatial_joints]]
type = "spherical"
name = "pivot"
body_a = "ground"
body_b = "rod1"
point_b = [0.0, 0.0, 0.4]

[[spatial_joints]]
type = "spherical"
name = "elbow"
body_a = "rod1"
point_a = [0.0, 0.0, -0.4]
body_b = "rod2"
point_b = [0.0, 0.0, 0.4]

[[spatial_joints]]
type = "spherical"
name = "wrist"
body_a = "rod2"
point_a = [0.0, 0.0, -0.4]
body_b = "plate"
point_b = [0.0, 0.2, 0.0]
"#;

type P3 = [f64; 3];

/// The camera the page publishes on `<svg id="stage">`.
struct Camera {
    m: [f64; 12],
    az: f64,
    el: f64,
    zoom: f64,
    focal: f64,
    distance: f64,
    target: P3,
    cx: f64,
    cy: f64,
}

fn nums(e: &Element, k: &str) -> Vec<f64> {
    e.get(k)
        .unwrap_or_else(|| panic!("no {k}"))
        .split_whitespace()
        .map(|v| v.parse().unwrap())
        .collect()
}

impl Camera {
    fn of(stage: &Element) -> Camera {
        let m = nums(stage, "data-matrix");
        let t = nums(stage, "data-target");
        Camera {
            m: std::array::from_fn(|k| m[k]),
            az: stage.num("data-az"),
            el: stage.num("data-el"),
            zoom: stage.num("data-zoom"),
            focal: stage.num("data-focal"),
            distance: stage.num("data-distance"),
            target: [t[0], t[1], t[2]],
            cx: stage.num("data-cx"),
            cy: stage.num("data-cy"),
        }
    }
    /// `(u w, v w, w) = M (p, 1)`.
    fn project(&self, p: P3) -> (f64, f64) {
        let row = |k: usize| {
            self.m[4 * k] * p[0]
                + self.m[4 * k + 1] * p[1]
                + self.m[4 * k + 2] * p[2]
                + self.m[4 * k + 3]
        };
        let w = row(2);
        assert!(w > 0.0, "{p:?} behind the camera");
        (row(0) / w, row(1) / w)
    }
    /// The matrix of docs/cli.md from the angles, distance, target, focal length and centre.
    fn derived(&self) -> [f64; 12] {
        let (a, e) = (self.az.to_radians(), self.el.to_radians());
        let dir = [e.cos() * a.cos(), e.cos() * a.sin(), e.sin()];
        let c: P3 = std::array::from_fn(|k| self.target[k] + self.distance * dir[k]);
        let f = dir.map(|x| -x);
        let r = [-a.sin(), a.cos(), 0.0];
        let u = [
            r[1] * f[2] - r[2] * f[1],
            r[2] * f[0] - r[0] * f[2],
            r[0] * f[1] - r[1] * f[0],
        ];
        let rows: [P3; 3] = [
            std::array::from_fn(|k| self.focal * r[k] + self.cx * f[k]),
            std::array::from_fn(|k| -self.focal * u[k] + self.cy * f[k]),
            f,
        ];
        let mut m = [0.0; 12];
        for (i, row) in rows.iter().enumerate() {
            m[4 * i..4 * i + 3].copy_from_slice(row);
            m[4 * i + 3] = -(0..3).map(|k| row[k] * c[k]).sum::<f64>();
        }
        m
    }
}

fn dist(a: (f64, f64), b: (f64, f64)) -> f64 {
    (a.0 - b.0).hypot(a.1 - b.1)
}

/// The `points` of a polygon or polyline.
fn points(e: &Element) -> Vec<(f64, f64)> {
    e.get("points")
        .unwrap_or("")
        .split_whitespace()
        .map(|p| {
            let (x, y) = p.split_once(',').expect("x,y");
            (x.parse().unwrap(), y.parse().unwrap())
        })
        .collect()
}

/// One spatial body's pose in a CSV row: centre of mass and directors.
struct Pose {
    x: P3,
    d: [P3; 3],
}

impl Pose {
    fn of(head: &[String], row: &[f64], name: &str) -> Pose {
        let c = |s: &str| {
            let n = format!("{name}.{s}");
            row[head
                .iter()
                .position(|h| *h == n)
                .unwrap_or_else(|| panic!("no column {n}"))]
        };
        Pose {
            x: [c("x"), c("y"), c("z")],
            d: std::array::from_fn(|i| ["x", "y", "z"].map(|a| c(&format!("d{}{a}", i + 1)))),
        }
    }
    /// The world position of a principal-frame point.
    fn at(&self, p: P3) -> P3 {
        std::array::from_fn(|c| self.x[c] + (0..3).map(|i| p[i] * self.d[i][c]).sum::<f64>())
    }
}

/// A body-frame point in the principal frame: `A^T p`.
fn principal(b: &mbd_model::spatial::SpatialBody, p: P3) -> P3 {
    let a = b.inertia.axes();
    std::array::from_fn(|i| (0..3).map(|j| a[(j, i)] * p[j]).sum())
}

/// The page's embedded data (for the drawn thickness of flat bodies).
fn page_data(html: &Path) -> serde_json::Value {
    let text = std::fs::read_to_string(html).unwrap();
    for bad in ["http://", "https://"] {
        assert!(!text.contains(bad), "the page contains {bad}");
    }
    let start = text.find("type=\"application/json\">").unwrap() + 24;
    let end = start + text[start..].find("</script>").unwrap();
    serde_json::from_str(&text[start..end]).unwrap()
}

/// What one page check measured (worst pixel errors).
#[derive(Debug, Default)]
struct Measured {
    com: f64,
    corner: f64,
    diagonal: f64,
    joint: f64,
    trace: f64,
    matrix: f64,
    corners_checked: usize,
}

/// Checks one page's DOM against the CSV row at its time (see the file's documentation).
fn check_page(
    dom: &str,
    sys: &mbd_model::System,
    data: &serde_json::Value,
    csv: &(Vec<String>, Vec<Vec<f64>>),
    trace: (usize, P3),
) -> (Camera, Measured) {
    let svg = elements(dom, "svg");
    let stage = by_id(&svg, "stage");
    let cam = Camera::of(stage);
    let mut got = Measured::default();
    let scale = cam.m.iter().fold(0.0f64, |s, x| s.max(x.abs()));
    for (a, b) in cam.m.iter().zip(cam.derived()) {
        got.matrix = got.matrix.max((a - b).abs() / scale);
    }
    assert!(
        got.matrix < 1e-12,
        "published matrix != derived: {}",
        got.matrix
    );
    let c = cam.project(cam.target);
    assert!(
        dist(c, (cam.cx, cam.cy)) < 1e-6,
        "the target projects to the centre"
    );

    let (head, rows) = csv;
    let t = stage.num("data-t");
    let row = rows
        .iter()
        .find(|r| r[0] == t)
        .expect("the frame shown is a CSV row");
    let circles = elements(dom, "circle");
    let polygons = elements(dom, "polygon");
    let lines = elements(dom, "line");
    let find = |cls: &str, k: &str, v: &str| -> Vec<&Element> {
        circles
            .iter()
            .chain(&lines)
            .filter(|e| e.has_class(cls) && e.get(k) == Some(v))
            .collect()
    };
    let radius = {
        let (lo, hi) = (&data["scene"]["lo"], &data["scene"]["hi"]);
        0.5 * (0..3)
            .map(|k| (hi[k].as_f64().unwrap() - lo[k].as_f64().unwrap()).powi(2))
            .sum::<f64>()
            .sqrt()
    };
    for (k, b) in sys.spatial_bodies().iter().enumerate() {
        let pose = Pose::of(head, row, &b.name);
        let com = find("com", "data-body", &b.name);
        assert_eq!(com.len(), 1, "one centre of mass for {}", b.name);
        let e = dist((com[0].num("cx"), com[0].num("cy")), cam.project(pose.x));
        assert!(e <= 1.0, "{}: centre of mass {e} px off", b.name);
        got.com = got.com.max(e);

        // the equivalent box: a = sqrt(3 (J2 + J3 - J1) / (2 m)), ...
        let (m, j) = (b.inertia.mass(), b.inertia.moments());
        let mut half: P3 = std::array::from_fn(|i| {
            (3.0 * (j[(i + 1) % 3] + j[(i + 2) % 3] - j[i]).max(0.0) / (2.0 * m)).sqrt()
        });
        for (i, h) in half.iter_mut().enumerate() {
            if *h < 1e-9 {
                // flat: drawn thin, a small fraction of the scene
                let thin = data["bodies"][k]["drawn"][i].as_f64().unwrap();
                assert!(
                    thin > 0.0 && thin <= 0.01 * radius,
                    "{} thickness {thin}",
                    b.name
                );
                *h = thin;
            }
        }
        let faces: Vec<&Element> = polygons
            .iter()
            .filter(|p| p.get("data-body") == Some(&b.name))
            .collect();
        assert_eq!(faces.len(), 6, "six faces for {}", b.name);
        for face in faces {
            let name = face.get("data-face").unwrap();
            let s = if name.starts_with('+') { 1.0 } else { -1.0 };
            let axis: usize = name[1..].parse::<usize>().unwrap() - 1;
            let others: Vec<usize> = (0..3).filter(|&i| i != axis).collect();
            let pts = points(face);
            assert_eq!(pts.len(), 4);
            for (p, (s0, s1)) in
                pts.iter()
                    .zip([(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)])
            {
                let mut corner = [0.0; 3];
                corner[axis] = s * half[axis];
                corner[others[0]] = s0 * half[others[0]];
                corner[others[1]] = s1 * half[others[1]];
                let e = dist(*p, cam.project(pose.at(corner)));
                assert!(
                    e <= 1.0,
                    "{} face {name}: corner {corner:?} {e} px off",
                    b.name
                );
                got.corner = got.corner.max(e);
                got.corners_checked += 1;
            }
            // opposite corners of the face: their drawn distance is the projected one
            let want = dist(
                cam.project(pose.at(corner_of(axis, s, &others, half, -1.0))),
                cam.project(pose.at(corner_of(axis, s, &others, half, 1.0))),
            );
            let e = (dist(pts[0], pts[2]) - want).abs();
            assert!(e <= 1.0, "{} face {name}: diagonal {e} px off", b.name);
            got.diagonal = got.diagonal.max(e);
        }
    }
    // joints and links: on each body side, at the model's marker point
    for j in sys.spatial_joints() {
        let (ma, mb) = j.joint.markers();
        for (side, r, p) in [("a", j.a, ma.point), ("b", j.b, mb.point)] {
            let Some(k) = r.index() else { continue };
            let body = &sys.spatial_bodies()[k];
            let pose = Pose::of(head, row, &body.name);
            let w = cam.project(pose.at(principal(body, p)));
            let dot = circles
                .iter()
                .find(|c| {
                    c.has_class("joint")
                        && c.get("data-joint") == Some(&j.name)
                        && c.get("data-side") == Some(side)
                })
                .unwrap_or_else(|| panic!("joint {} side {side}", j.name));
            let e = dist((dot.num("cx"), dot.num("cy")), w);
            let link = lines
                .iter()
                .find(|l| {
                    l.has_class("link")
                        && l.get("data-joint") == Some(&j.name)
                        && l.get("data-body") == Some(&body.name)
                })
                .expect("link drawn");
            let e2 = dist((link.num("x2"), link.num("y2")), w)
                .max(dist((link.num("x1"), link.num("y1")), cam.project(pose.x)));
            assert!(
                e <= 1.0 && e2 <= 1.0,
                "joint {} side {side}: {e}, link {e2} px off",
                j.name
            );
            got.joint = got.joint.max(e).max(e2);
        }
    }
    // the trace: the traced point of every frame
    let (k, p) = trace;
    let name = &sys.spatial_bodies()[k].name;
    let poly = elements(dom, "polyline")
        .into_iter()
        .find(|e| e.has_class("trace"))
        .expect("trace drawn");
    assert_eq!(poly.get("data-trace"), Some(name.as_str()));
    let pts = points(&poly);
    assert_eq!(pts.len(), rows.len(), "one trace point per frame");
    for (r, q) in rows.iter().zip(&pts) {
        let e = dist(*q, cam.project(Pose::of(head, r, name).at(p)));
        assert!(e <= 1.0, "trace at t = {}: {e} px off", r[0]);
        got.trace = got.trace.max(e);
    }
    // axes labels, legend beside the drawing, no scrollbar
    let texts = elements(dom, "text");
    let labels: Vec<&str> = texts
        .iter()
        .filter(|t| t.has_class("axis-label"))
        .map(|t| t.text.as_str())
        .collect();
    assert_eq!(labels, ["x", "y", "z"]);
    let plot = nums(stage, "data-plot");
    let rects = elements(dom, "rect");
    let lb = by_id(&rects, "legend-box");
    assert!(
        lb.num("x") >= plot[2] && lb.num("x") + lb.num("width") <= WINDOW.0,
        "legend beside the plot"
    );
    check_fits_the_window(dom);
    (cam, got)
}

fn corner_of(axis: usize, s: f64, others: &[usize], half: P3, sign: f64) -> P3 {
    let mut c = [0.0; 3];
    c[axis] = s * half[axis];
    c[others[0]] = sign * half[others[0]];
    c[others[1]] = sign * half[others[1]];
    c
}

/// `mbd run MODEL` (projected RK4, 1 s) into `csv`, then `mbd animate` into `html`.
fn run_and_animate(model: &Path, csv: &Path, html: &Path, h: &str, extra: &[&str]) -> String {
    let out = mbd([
        "run".as_ref(),
        model.as_os_str(),
        "--solver".as_ref(),
        "rk4-projected".as_ref(),
        "--t-end".as_ref(),
        "1".as_ref(),
        "--h".as_ref(),
        h.as_ref(),
        "--every".as_ref(),
        "5".as_ref(),
        "--out".as_ref(),
        csv.as_os_str(),
    ]);
    assert_eq!(out.code, 0, "{}", out.stderr);
    let mut args: Vec<std::ffi::OsString> = vec![
        "animate".into(),
        csv.into(),
        "--model".into(),
        model.into(),
        "-o".into(),
        html.into(),
    ];
    args.extend(extra.iter().map(Into::into));
    let out = mbd(args);
    assert_eq!(out.code, 0, "{}", out.stderr);
    out.stderr
}

fn url(html: &Path, hash: &str) -> String {
    format!("file://{}#{hash}", html.canonicalize().unwrap().display())
}

fn screenshot(bin: &Path, d: &Path, name: &str, url: &str) -> Vec<u8> {
    let png = d.join(format!("{name}.png"));
    chrome(
        bin,
        &d.join(format!("profile-{name}")),
        WINDOW,
        &[format!("--screenshot={}", png.display()), url.to_string()],
    );
    let bytes =
        std::fs::read(&png).unwrap_or_else(|e| panic!("no screenshot {}: {e}", png.display()));
    assert_eq!(png_size(&bytes), (1000, 700), "screenshot size");
    bytes
}

fn browser() -> Option<PathBuf> {
    let b = chromium();
    if b.is_none() {
        eprintln!("skipped: Chromium not found at $CHROMIUM or /usr/bin/chromium (install with apt-get install chromium)");
    }
    b
}

#[test]
fn heavy_top_page_draws_the_body_where_the_csv_puts_it() {
    let Some(bin) = browser() else { return };
    let d = scratch("anim3d-top");
    let (csv, html) = (d.join("top.csv"), d.join("pages").join("top.html"));
    let model = repo().join(TOP);
    let stderr = run_and_animate(&model, &csv, &html, "1e-3", &[]);
    assert!(!stderr.contains("planar"), "{stderr}");
    let sys = mbd_model::System::from_path(&model).unwrap();
    let data = page_data(&html);
    let table = read_csv(&csv);
    let dom = dom_at_1000x700(&bin, &d.join("dom"), &url(&html, "t=0.5"));
    std::fs::write(d.join("dom.html"), &dom).unwrap();
    let (cam, got) = check_page(&dom, &sys, &data, &table, (0, [0.0; 3]));
    eprintln!(
        "heavy top at t = 0.5: {got:?}, camera az {} el {} zoom {}",
        cam.az, cam.el, cam.zoom
    );
    assert_eq!(
        (cam.az, cam.el, cam.zoom),
        (35.0, 22.0, 1.0),
        "the default camera"
    );
    assert_eq!(got.corners_checked, 24);
    // the ground point of the tip: a square at the origin's projection
    let rects = elements(&dom, "rect");
    let g = rects
        .iter()
        .find(|r| r.has_class("ground") && r.get("data-joint") == Some("tip"))
        .expect("ground point");
    let o = cam.project([0.0; 3]);
    assert!(dist((g.num("x") + 4.0, g.num("y") + 4.0), o) <= 1.0);
}

#[test]
fn chain_page_follows_the_camera_set_in_the_url() {
    let Some(bin) = browser() else { return };
    let d = scratch("anim3d-chain");
    let model = d.join("chain.toml");
    std::fs::write(&model, CHAIN).unwrap();
    let (csv, html) = (d.join("chain.csv"), d.join("chain.html"));
    run_and_animate(&model, &csv, &html, "2e-3", &["--trace", "plate:0,-0.2,0"]);
    let sys = mbd_model::System::from_path(&model).unwrap();
    let data = page_data(&html);
    let table = read_csv(&csv);
    let trace = (2, principal(&sys.spatial_bodies()[2], [0.0, -0.2, 0.0]));
    let mut seen = Vec::new();
    for (k, (az, el, zoom)) in [(35.0, 22.0, 1.0), (120.0, 50.0, 1.5)]
        .into_iter()
        .enumerate()
    {
        let hash = format!("t=0.6&az={az}&el={el}&zoom={zoom}");
        let dom = dom_at_1000x700(&bin, &d.join(format!("dom-{k}")), &url(&html, &hash));
        std::fs::write(d.join(format!("dom-{k}.html")), &dom).unwrap();
        let (cam, got) = check_page(&dom, &sys, &data, &table, trace);
        eprintln!("chain at t = 0.6, camera ({az}, {el}, {zoom}): {got:?}");
        assert_eq!(
            (cam.az, cam.el, cam.zoom),
            (az, el, zoom),
            "the camera of the URL"
        );
        assert_eq!(got.corners_checked, 3 * 24);
        let shot = screenshot(&bin, &d, &format!("shot-{k}"), &url(&html, &hash));
        seen.push((cam, shot));
    }
    // the second camera moved the drawing: the bodies' centres of mass moved on the screen,
    // the target stayed at the centre, and the focal length grew by the zoom
    let (a, b) = (&seen[0].0, &seen[1].0);
    assert!(
        (b.focal / a.focal - 1.5).abs() < 1e-12,
        "{} {}",
        a.focal,
        b.focal
    );
    let row = table.1.iter().find(|r| (r[0] - 0.6).abs() < 1e-9).unwrap();
    let moved = sys
        .spatial_bodies()
        .iter()
        .map(|body| {
            let x = Pose::of(&table.0, row, &body.name).x;
            dist(a.project(x), b.project(x))
        })
        .fold(0.0f64, f64::max);
    assert!(moved > 30.0, "the centres of mass moved {moved} px");
    assert_ne!(
        seen[0].1, seen[1].1,
        "the screenshots from two cameras are identical"
    );
}

/// The spherical pendulum's point mass is a sphere (`circle.point-mass`) centred on the
/// projection of its position in the CSV, its rod a line from the ground point to it.
#[test]
fn spherical_pendulum_page_draws_the_point_mass_where_the_csv_puts_it() {
    let Some(bin) = browser() else { return };
    let d = scratch("anim3d-point-mass");
    let (csv, html) = (d.join("pm.csv"), d.join("pm.html"));
    let model = repo().join("examples/models/spherical_pendulum.toml");
    run_and_animate(&model, &csv, &html, "1e-3", &[]);
    let (head, rows) = read_csv(&csv);
    let dom = dom_at_1000x700(&bin, &d.join("dom"), &url(&html, "t=0.5"));
    let cam = Camera::of(by_id(&elements(&dom, "svg"), "stage"));
    let t = by_id(&elements(&dom, "svg"), "stage").num("data-t");
    let row = rows.iter().find(|r| r[0] == t).expect("a CSV row");
    let col = |n: &str| row[head.iter().position(|h| h == n).unwrap()];
    let at = cam.project([col("bob.x"), col("bob.y"), col("bob.z")]);
    let circles = elements(&dom, "circle");
    let s = circles
        .iter()
        .find(|c| c.has_class("point-mass") && c.get("data-body") == Some("bob"))
        .expect("the point mass's sphere");
    let got = (s.num("cx"), s.num("cy"));
    eprintln!(
        "point mass at t = {t}: {got:?}, CSV {at:?}, radius {}",
        s.num("r")
    );
    assert!(dist(got, at) <= 1e-3, "{got:?} vs {at:?}");
    assert!(s.num("r") >= 2.0);
    let rod = elements(&dom, "line")
        .into_iter()
        .find(|l| l.has_class("rod") && l.get("data-joint") == Some("rod"))
        .expect("the rod");
    assert!(dist((rod.num("x2"), rod.num("y2")), at) <= 1e-3);
    assert!(dist((rod.num("x1"), rod.num("y1")), cam.project([0.0; 3])) <= 1e-3);
}
