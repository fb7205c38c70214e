//! Drives the animation page in headless Chromium: at two times the drawn centres of mass and
//! joints sit where the CSV and the model put them (through the page's published transform, to
//! within a pixel), and screenshots at the two times differ. Skips (with a message) when
//! Chromium is not installed.

mod common;
use common::{mbd, scratch};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

const MODEL: &str = "examples/models/slider_crank_spring.toml";

fn chromium() -> Option<PathBuf> {
    let p = std::env::var_os("CHROMIUM")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from("/usr/bin/chromium"));
    p.exists().then_some(p)
}

/// Runs Chromium headless with a fresh profile; returns stdout.
fn chrome(bin: &Path, profile: &Path, extra: &[String]) -> String {
    let mut child = Command::new(bin)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            "--no-first-run",
            "--hide-scrollbars",
        ])
        .arg(format!("--user-data-dir={}", profile.display()))
        .args(extra)
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .expect("chromium starts");
    let start = Instant::now();
    loop {
        if child.try_wait().expect("wait on chromium").is_some() {
            break;
        }
        if start.elapsed() > Duration::from_secs(120) {
            let _ = child.kill();
            panic!("chromium did not finish within 120 s");
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    let out = child.wait_with_output().expect("chromium output");
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// The attributes of every `<tag ...>` element in serialised HTML.
fn elements(html: &str, tag: &str) -> Vec<HashMap<String, String>> {
    let open = format!("<{tag} ");
    let mut v = Vec::new();
    let mut rest = html;
    while let Some(i) = rest.find(&open) {
        rest = &rest[i + open.len()..];
        let end = rest.find('>').expect("tag closes");
        let mut attrs = HashMap::new();
        let mut s = &rest[..end];
        while let Some(eq) = s.find("=\"") {
            let name = s[..eq].trim().to_string();
            let after = &s[eq + 2..];
            let close = after.find('"').expect("attribute closes");
            attrs.insert(name, after[..close].to_string());
            s = &after[close + 1..];
        }
        v.push(attrs);
    }
    v
}

fn num(attrs: &HashMap<String, String>, k: &str) -> f64 {
    attrs
        .get(k)
        .unwrap_or_else(|| panic!("attribute {k} missing in {attrs:?}"))
        .parse()
        .unwrap()
}

#[test]
fn page_draws_the_trajectory_at_the_requested_time() {
    let Some(bin) = chromium() else {
        eprintln!(
            "skipped: Chromium not found at $CHROMIUM or /usr/bin/chromium \
             (install with apt-get install chromium)"
        );
        return;
    };
    let d = scratch("browser");
    let csv = d.join("slider.csv");
    let html = d.join("slider.html");
    let out = mbd([
        "run".as_ref(),
        MODEL.as_ref(),
        "--solver".as_ref(),
        "symplectic:2".as_ref(),
        "--t-end".as_ref(),
        "1".as_ref(),
        "--h".as_ref(),
        "0.01".as_ref(),
        "--out".as_ref(),
        csv.as_os_str(),
    ]);
    assert_eq!(out.code, 0, "{}", out.stderr);
    let out = mbd([
        "animate".as_ref(),
        csv.as_os_str(),
        "--model".as_ref(),
        MODEL.as_ref(),
        "-o".as_ref(),
        html.as_os_str(),
    ]);
    assert_eq!(out.code, 0, "{}", out.stderr);

    let sys = mbd_model::System::from_path(common::repo().join(MODEL)).unwrap();
    let text = std::fs::read_to_string(&csv).unwrap();
    let mut lines = text.lines();
    let head: Vec<&str> = lines.next().unwrap().split(',').collect();
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect();
    let url = |t: f64| format!("file://{}#t={t}", html.canonicalize().unwrap().display());

    let mut shots = Vec::new();
    for (k, t) in [0.25, 0.75].into_iter().enumerate() {
        let row = rows
            .iter()
            .min_by(|a, b| (a[0] - t).abs().total_cmp(&(b[0] - t).abs()))
            .unwrap();
        let q: Vec<f64> = sys
            .coordinate_names()
            .iter()
            .map(|n| row[head.iter().position(|h| h == n).unwrap()])
            .collect();

        let dom = chrome(
            &bin,
            &d.join(format!("profile-dom-{k}")),
            &["--dump-dom".into(), url(t)],
        );
        let svg = elements(&dom, "svg");
        let stage = svg
            .iter()
            .find(|a| a.get("id").map(String::as_str) == Some("stage"))
            .unwrap_or_else(|| panic!("no #stage in the DOM:\n{dom}"));
        let (scale, ox, oy) = (
            num(stage, "data-scale"),
            num(stage, "data-ox"),
            num(stage, "data-oy"),
        );
        assert!(
            (num(stage, "data-t") - row[0]).abs() < 1e-12,
            "frame shown for t = {t}"
        );
        let px = |p: [f64; 2]| (ox + scale * p[0], oy - scale * p[1]);

        let circles = elements(&dom, "circle");
        let mut checked = 0;
        for (i, b) in sys.bodies().iter().enumerate() {
            let c = circles
                .iter()
                .find(|a| {
                    a.get("class").map(String::as_str) == Some("com")
                        && a.get("data-body") == Some(&b.name)
                })
                .unwrap_or_else(|| panic!("no centre of mass drawn for {}", b.name));
            let (ex, ey) = px([q[3 * i], q[3 * i + 1]]);
            let (cx, cy) = (num(c, "cx"), num(c, "cy"));
            assert!(
                (cx - ex).abs() <= 1.0 && (cy - ey).abs() <= 1.0,
                "{} at t = {t}: drawn ({cx}, {cy}), expected ({ex}, {ey})",
                b.name
            );
            checked += 1;
        }
        // joints: where the model's attachment point on the second body is
        for j in sys.joints() {
            let mbd_model::JointKind::Revolute(mbd_model::joints::Revolute { a, pa, b, pb }) =
                &j.kind
            else {
                continue;
            };
            let w = match (b, a) {
                (mbd_model::BodyRef::Body(hb), _) => sys.point_position(*hb, *pb, &q),
                (_, mbd_model::BodyRef::Body(ha)) => sys.point_position(*ha, *pa, &q),
                _ => continue,
            };
            let c = circles
                .iter()
                .find(|c| c.get("data-joint") == Some(&j.name))
                .unwrap_or_else(|| panic!("joint {} not drawn", j.name));
            let (ex, ey) = px([w[0], w[1]]);
            assert!(
                (num(c, "cx") - ex).abs() <= 1.0 && (num(c, "cy") - ey).abs() <= 1.0,
                "joint {} at t = {t}",
                j.name
            );
            checked += 1;
        }
        assert_eq!(
            checked,
            3 + 3,
            "three bodies and three revolute joints checked"
        );

        let png = d.join(format!("shot-{k}.png"));
        chrome(
            &bin,
            &d.join(format!("profile-shot-{k}")),
            &[
                format!("--screenshot={}", png.display()),
                "--window-size=800,600".into(),
                url(t),
            ],
        );
        let bytes =
            std::fs::read(&png).unwrap_or_else(|e| panic!("no screenshot {}: {e}", png.display()));
        assert!(bytes.starts_with(b"\x89PNG"), "not a PNG");
        shots.push(bytes);
    }
    assert_ne!(
        shots[0], shots[1],
        "the screenshots at two times are identical"
    );
}
