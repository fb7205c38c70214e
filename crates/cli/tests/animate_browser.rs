//! Drives the animation page in headless Chromium in a 1000 x 700 window, at two times:
//!
//! * the drawn centres of mass and joints sit where the CSV and the model put them (through the
//!   page's published transform, to within a pixel);
//! * the axes have round tick labels (a `0` on each axis) at the places the transform gives,
//!   and the titles `x [m]`, `y [m]`;
//! * the scale bar is a round length whose drawn pixels are its metres times the published
//!   scale, and the model's crank (its two pins, read from the model file) spans its length
//!   times the same scale between its drawn joints;
//! * the legend names what the page draws and lies beside the plot area, clear of the
//!   mechanism; the body names cross no link;
//! * the page fits the window (no scrollbar);
//!
//! and screenshots at the two times differ. Skips (with a message) when Chromium is not
//! installed.

mod common;
use common::browser::{
    by_id, check_fits_the_window, chrome, chromium, dom_at_1000x700, elements, png_size, Element,
    WINDOW,
};
use common::{mbd, scratch};

const MODEL: &str = "examples/models/slider_crank_spring.toml";
/// A box `[x0, x1] x [y0, y1]` in pixels.
#[derive(Clone, Copy, Debug)]
struct Rect {
    x0: f64,
    y0: f64,
    x1: f64,
    y1: f64,
}

impl Rect {
    fn grown(self, m: f64) -> Rect {
        Rect {
            x0: self.x0 - m,
            y0: self.y0 - m,
            x1: self.x1 + m,
            y1: self.y1 + m,
        }
    }
    fn contains(&self, p: (f64, f64)) -> bool {
        (self.x0..=self.x1).contains(&p.0) && (self.y0..=self.y1).contains(&p.1)
    }
    fn overlaps(&self, o: &Rect) -> bool {
        self.x0 < o.x1 && o.x0 < self.x1 && self.y0 < o.y1 && o.y0 < self.y1
    }
    /// Whether the segment a-b passes through the box (Liang-Barsky clipping).
    fn hit_by(&self, a: (f64, f64), b: (f64, f64)) -> bool {
        let (dx, dy) = (b.0 - a.0, b.1 - a.1);
        let p = [-dx, dx, -dy, dy];
        let q = [a.0 - self.x0, self.x1 - a.0, a.1 - self.y0, self.y1 - a.1];
        let (mut t0, mut t1) = (0.0f64, 1.0f64);
        for i in 0..4 {
            if p[i] == 0.0 {
                if q[i] < 0.0 {
                    return false;
                }
            } else {
                let r = q[i] / p[i];
                if p[i] < 0.0 {
                    t0 = t0.max(r);
                } else {
                    t1 = t1.min(r);
                }
                if t0 > t1 {
                    return false;
                }
            }
        }
        true
    }
}

/// The points of a `points="x,y x,y ..."` attribute.
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

/// Whether `v` is 1, 2 or 5 times a power of ten.
fn is_round(v: f64) -> bool {
    let m = v / 10f64.powf(v.log10().floor());
    [1.0, 2.0, 5.0, 10.0].iter().any(|n| (m - n).abs() < 1e-9)
}

/// The published transform and the plot area.
struct View {
    scale: f64,
    ox: f64,
    oy: f64,
    plot: Rect,
}

impl View {
    fn of(stage: &Element) -> View {
        let p: Vec<f64> = stage
            .get("data-plot")
            .expect("data-plot")
            .split_whitespace()
            .map(|v| v.parse().unwrap())
            .collect();
        View {
            scale: stage.num("data-scale"),
            ox: stage.num("data-ox"),
            oy: stage.num("data-oy"),
            plot: Rect {
                x0: p[0],
                y0: p[1],
                x1: p[2],
                y1: p[3],
            },
        }
    }
    fn px(&self, p: [f64; 2]) -> (f64, f64) {
        (self.ox + self.scale * p[0], self.oy - self.scale * p[1])
    }
}

/// Tick labels are round numbers placed where the transform puts their values, `0` included.
fn check_axes(texts: &[Element], v: &View) {
    for (axis, min) in [("x", 3), ("y", 2)] {
        let ticks: Vec<&Element> = texts
            .iter()
            .filter(|t| t.has_class("tick") && t.has_class(axis))
            .collect();
        assert!(
            ticks.len() >= min,
            "{} ticks on the {axis} axis",
            ticks.len()
        );
        assert!(
            ticks.iter().any(|t| t.text == "0"),
            "no tick labelled 0 on the {axis} axis"
        );
        let vals: Vec<f64> = ticks.iter().map(|t| t.num("data-value")).collect();
        let step = vals[1] - vals[0];
        assert!(is_round(step), "{axis} tick step {step}");
        for (t, &val) in ticks.iter().zip(&vals) {
            let shown: f64 = t
                .text
                .parse()
                .unwrap_or_else(|_| panic!("tick {:?}", t.text));
            assert_eq!(shown, val, "the label is the tick's value");
            assert!(
                t.text.len() <= 6,
                "compact tick label {:?} on the {axis} axis",
                t.text
            );
            let k = val / step;
            assert!(
                (k - k.round()).abs() < 1e-9,
                "{val} is a multiple of {step}"
            );
            let (at, want) = if axis == "x" {
                (t.num("x"), v.px([val, 0.0]).0)
            } else {
                (t.num("y"), v.px([0.0, val]).1)
            };
            assert!(
                (at - want).abs() <= 0.5,
                "{axis} tick {val} at {at}, not {want}"
            );
        }
    }
    assert_eq!(by_id(texts, "x-label").text, "x [m]");
    assert_eq!(by_id(texts, "y-label").text, "y [m]");
}

/// The scale bar's drawn length is its metres times the scale; so is the crank's, between its
/// two drawn joints (its length read from the model).
fn check_scale(dom: &str, stage: &Element, v: &View, sys: &mbd_model::System) {
    let metres = stage.num("data-scalebar-m");
    let (x1, x2) = (stage.num("data-scalebar-x1"), stage.num("data-scalebar-x2"));
    assert!(is_round(metres), "scale bar of {metres} m");
    let bar_px = x2 - x1;
    assert!(
        (bar_px - metres * v.scale).abs() <= 0.5,
        "scale bar: {bar_px} px drawn for {metres} m at {} px/m",
        v.scale
    );
    assert!(
        (30.0..=200.0).contains(&bar_px),
        "scale bar {bar_px} px long"
    );
    let lines = elements(dom, "line");
    let bar = by_id(&lines, "scalebar");
    assert_eq!(bar.num("data-length-m"), metres);
    assert!((bar.num("x1") - x1).abs() < 1e-6 && (bar.num("x2") - x2).abs() < 1e-6);
    let label = elements(dom, "text")
        .into_iter()
        .find(|t| t.has_class("scalebar-label"))
        .expect("the scale bar is labelled");
    assert_eq!(
        label.text.strip_suffix(" m").map(str::parse::<f64>),
        Some(Ok(metres)),
        "scale bar label {:?}",
        label.text
    );

    // the crank: its two pins in its own frame give its length
    let crank = sys
        .bodies()
        .iter()
        .position(|b| b.name == "crank")
        .expect("the model has a crank");
    let mut pins = Vec::new();
    for j in sys.joints() {
        let mbd_model::JointKind::Revolute(r) = &j.kind else {
            continue;
        };
        for (body, p) in [(r.a, r.pa), (r.b, r.pb)] {
            if body.index() == Some(crank) {
                pins.push((j.name.clone(), p));
            }
        }
    }
    assert_eq!(pins.len(), 2, "the crank has two pins: {pins:?}");
    let length = (pins[0].1[0] - pins[1].1[0]).hypot(pins[0].1[1] - pins[1].1[1]);
    let circles = elements(dom, "circle");
    let at = |name: &str| {
        let c = circles
            .iter()
            .find(|c| c.has_class("joint") && c.get("data-joint") == Some(name))
            .unwrap_or_else(|| panic!("joint {name} not drawn"));
        (c.num("cx"), c.num("cy"))
    };
    let (a, b) = (at(&pins[0].0), at(&pins[1].0));
    let drawn = (a.0 - b.0).hypot(a.1 - b.1);
    assert!(
        (drawn - length * v.scale).abs() <= 1.0,
        "the {length} m crank spans {drawn} px, not {} px",
        length * v.scale
    );
    // the same pixels per metre as the scale bar
    let (per_m_bar, per_m_crank) = (bar_px / metres, drawn / length);
    assert!(
        (per_m_bar - per_m_crank).abs() <= 0.01 * per_m_bar,
        "scale bar {per_m_bar} px/m, crank {per_m_crank} px/m"
    );
}

/// The legend lists what the page draws and sits outside the plot area, clear of every drawn
/// centre of mass and joint.
fn check_legend(dom: &str, v: &View) {
    let rects = elements(dom, "rect");
    let b = by_id(&rects, "legend-box");
    let legend = Rect {
        x0: b.num("x"),
        y0: b.num("y"),
        x1: b.num("x") + b.num("width"),
        y1: b.num("y") + b.num("height"),
    };
    assert!(legend.x1 <= WINDOW.0 && legend.y1 <= WINDOW.1, "{legend:?}");
    assert!(
        !legend.overlaps(&v.plot),
        "legend {legend:?} on the plot area"
    );
    let keys: Vec<String> = elements(dom, "g")
        .iter()
        .filter(|g| g.has_class("legend-entry"))
        .filter_map(|g| g.get("data-legend").map(String::from))
        .collect();
    for k in ["body", "com", "trace", "joint", "ground", "guide", "spring"] {
        assert!(keys.iter().any(|x| x == k), "legend lacks {k}: {keys:?}");
    }
    for c in elements(dom, "circle") {
        if c.get("data-body").is_some() || c.get("data-joint").is_some() {
            let p = (c.num("cx"), c.num("cy"));
            assert!(!legend.contains(p), "{:?} under the legend", c.attrs);
            assert!(v.plot.contains(p), "{:?} outside the plot area", c.attrs);
        }
    }
}

/// Every body's name lies inside the plot area and crosses no link (the bars and the slider's
/// block, with half a bar's stroke around them) and no other name.
fn check_labels(dom: &str, v: &View, sys: &mbd_model::System) {
    let mut links: Vec<((f64, f64), (f64, f64))> = Vec::new();
    for shape in ["polyline", "polygon"] {
        for e in elements(dom, shape) {
            if e.get("data-body").is_none() {
                continue;
            }
            let p = points(&e);
            let n = if shape == "polyline" {
                p.len() - 1
            } else {
                p.len()
            };
            links.extend((0..n).map(|k| (p[k], p[(k + 1) % p.len()])));
        }
    }
    assert!(links.len() >= 2 + 4, "two bars and a block: {links:?}");
    let mut boxes: Vec<(String, Rect)> = Vec::new();
    for t in elements(dom, "text")
        .iter()
        .filter(|t| t.has_class("label"))
    {
        let r = Rect {
            x0: t.num("data-bx"),
            y0: t.num("data-by"),
            x1: t.num("data-bx") + t.num("data-bw"),
            y1: t.num("data-by") + t.num("data-bh"),
        };
        assert!(
            r.x1 > r.x0 + 10.0 && r.y1 > r.y0 + 5.0,
            "{} box {r:?}",
            t.text
        );
        // the text is centred in its box
        assert!((t.num("x") - 0.5 * (r.x0 + r.x1)).abs() < 0.01);
        assert!(
            r.x0 >= v.plot.x0 && r.x1 <= v.plot.x1 && r.y0 >= v.plot.y0 && r.y1 <= v.plot.y1,
            "label {} at {r:?} leaves the plot area",
            t.text
        );
        for (a, b) in &links {
            assert!(
                !r.grown(2.5).hit_by(*a, *b),
                "label {} at {r:?} overlaps the link {a:?}-{b:?}",
                t.text
            );
        }
        for (other, o) in &boxes {
            assert!(!r.overlaps(o), "labels {} and {other} overlap", t.text);
        }
        boxes.push((t.text.clone(), r));
    }
    let mut names: Vec<String> = boxes.into_iter().map(|(n, _)| n).collect();
    names.sort();
    let mut want: Vec<String> = sys.bodies().iter().map(|b| b.name.clone()).collect();
    want.sort();
    assert_eq!(names, want, "one label per body");
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
    let html = d.join("pages").join("slider.html"); // the directory does not exist yet
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

        let dom = dom_at_1000x700(&bin, &d.join(format!("dom-{k}")), &url(t));
        std::fs::write(d.join(format!("dom-{k}.html")), &dom).unwrap();
        let svg = elements(&dom, "svg");
        let stage = svg
            .iter()
            .find(|a| a.get("id") == Some("stage"))
            .unwrap_or_else(|| panic!("no #stage in the DOM:\n{dom}"));
        let v = View::of(stage);
        assert!(
            (stage.num("data-t") - row[0]).abs() < 1e-12,
            "frame shown for t = {t}"
        );

        let circles = elements(&dom, "circle");
        let mut checked = 0;
        for (i, b) in sys.bodies().iter().enumerate() {
            let c = circles
                .iter()
                .find(|a| a.has_class("com") && a.get("data-body") == Some(&b.name))
                .unwrap_or_else(|| panic!("no centre of mass drawn for {}", b.name));
            let (ex, ey) = v.px([q[3 * i], q[3 * i + 1]]);
            let (cx, cy) = (c.num("cx"), c.num("cy"));
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
                .find(|c| c.has_class("joint") && c.get("data-joint") == Some(&j.name))
                .unwrap_or_else(|| panic!("joint {} not drawn", j.name));
            let (ex, ey) = v.px([w[0], w[1]]);
            assert!(
                (c.num("cx") - ex).abs() <= 1.0 && (c.num("cy") - ey).abs() <= 1.0,
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

        check_fits_the_window(&dom);
        check_axes(&elements(&dom, "text"), &v);
        check_scale(&dom, stage, &v, &sys);
        check_legend(&dom, &v);
        check_labels(&dom, &v, &sys);

        let png = d.join(format!("shot-{k}.png"));
        chrome(
            &bin,
            &d.join(format!("profile-shot-{k}")),
            WINDOW,
            &[format!("--screenshot={}", png.display()), url(t)],
        );
        let bytes =
            std::fs::read(&png).unwrap_or_else(|e| panic!("no screenshot {}: {e}", png.display()));
        assert_eq!(png_size(&bytes), (1000, 700), "screenshot size");
        shots.push(bytes);
    }
    assert_ne!(
        shots[0], shots[1],
        "the screenshots at two times are identical"
    );
}
