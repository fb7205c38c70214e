//! `mbd animate`: a self-contained HTML page animating a result CSV (the planar page; a model
//! with spatial bodies gets the 3D page of [`crate::animate3d`]).
//!
//! The page (template `animate.html`, inline CSS and JavaScript, no network access) embeds the
//! trajectory, the model's geometry and the world extent of every frame as JSON and draws with
//! inline SVG: each body as the polygon through its joint and force attachment points and its
//! centre of mass (a bar when those points lie on one line), a dot at every centre of mass and
//! its trace over the run, circles at the joints, triangles at ground pins, dashed guides of
//! prismatic joints on ground, and springs; around it axes in metres, a legend with a scale
//! bar, and body names placed off the links.
//!
//! The SVG fills the window (title and controls included, no scrollbars) and its user units are
//! CSS pixels; it publishes its world-to-pixel transform as `data-scale`, `data-ox`, `data-oy`
//! (`px = ox + scale x`, `py = oy - scale y`), the scale bar as `data-scalebar-m` (its length in
//! metres) and `data-scalebar-x1`, `data-scalebar-x2`, `data-scalebar-y` (its drawn ends), and
//! the frame shown as `data-frame`, `data-t`. A URL hash `#t=1.25` opens the page paused at the
//! frame nearest that time.

use crate::args::AnimateArgs;
use crate::error::CliError;
use crate::table::Table;
use mbd_model::{BodyRef, System};
use serde::Serialize;

#[derive(Serialize)]
struct BodyGeom {
    name: String,
    /// Local points (body frame, relative to the centre of mass) in drawing order.
    outline: Vec<[f64; 2]>,
}

#[derive(Serialize)]
struct JointGeom {
    name: String,
    kind: &'static str,
    a: i64,
    pa: Option<[f64; 2]>,
    b: i64,
    pb: Option<[f64; 2]>,
    axis: Option<[f64; 2]>,
}

#[derive(Serialize)]
struct SpringGeom {
    name: String,
    a: i64,
    pa: [f64; 2],
    b: i64,
    pb: [f64; 2],
}

/// The world box `[lo, hi]` (metres) that holds every drawn point of every frame; the page fits
/// it into the window.
#[derive(Clone, Copy, Debug, Serialize, PartialEq)]
struct Extent {
    /// Smallest x and y.
    lo: [f64; 2],
    /// Largest x and y.
    hi: [f64; 2],
}

#[derive(Serialize)]
struct Page<'a> {
    model: &'a str,
    extent: Extent,
    bodies: Vec<BodyGeom>,
    joints: Vec<JointGeom>,
    springs: Vec<SpringGeom>,
    t: Vec<f64>,
    q: Vec<Vec<f64>>,
}

fn index(r: BodyRef) -> i64 {
    r.index().map_or(-1, |i| i as i64)
}

fn joint_geom(sys: &System) -> Vec<JointGeom> {
    sys.joints()
        .iter()
        .map(|j| {
            let sk = j.sketch();
            let (a, pa, b, pb, axis) = (index(sk.a), sk.point_a, index(sk.b), sk.point_b, sk.axis);
            JointGeom {
                name: j.name.clone(),
                kind: j.kind_name(),
                a,
                pa,
                b,
                pb,
                axis,
            }
        })
        .collect()
}

fn spring_geom(sys: &System) -> Vec<SpringGeom> {
    sys.forces()
        .iter()
        .filter_map(|f| {
            let sk = f.sketch()?;
            Some(SpringGeom {
                name: f.name.clone(),
                a: index(sk.a),
                pa: sk.point_a?,
                b: index(sk.b),
                pb: sk.point_b?,
            })
        })
        .collect()
}

/// Each body's outline: its centre of mass and attachment points, ordered by angle around
/// their mean so the polygon does not cross itself.
fn body_geom(sys: &System, joints: &[JointGeom], springs: &[SpringGeom]) -> Vec<BodyGeom> {
    sys.bodies()
        .iter()
        .enumerate()
        .map(|(i, b)| {
            let i = i as i64;
            let mut pts: Vec<[f64; 2]> = vec![[0.0, 0.0]];
            let mut add = |p: [f64; 2]| {
                if !pts
                    .iter()
                    .any(|o| (o[0] - p[0]).abs() + (o[1] - p[1]).abs() < 1e-12)
                {
                    pts.push(p);
                }
            };
            for j in joints {
                if let (true, Some(p)) = (j.a == i, j.pa) {
                    add(p);
                }
                if let (true, Some(p)) = (j.b == i, j.pb) {
                    add(p);
                }
            }
            for s in springs {
                if s.a == i {
                    add(s.pa);
                }
                if s.b == i {
                    add(s.pb);
                }
            }
            if let Some(ends) = bar_ends(&pts) {
                pts = ends.to_vec();
            } else if pts.len() > 2 {
                let n = pts.len() as f64;
                let cx = pts.iter().map(|p| p[0]).sum::<f64>() / n;
                let cy = pts.iter().map(|p| p[1]).sum::<f64>() / n;
                pts.sort_by(|p, q| {
                    let ap = (p[1] - cy).atan2(p[0] - cx);
                    let aq = (q[1] - cy).atan2(q[0] - cx);
                    ap.total_cmp(&aq)
                });
            }
            BodyGeom {
                name: b.name.clone(),
                outline: pts,
            }
        })
        .collect()
}

/// The two extreme points when all of `pts` (three or more) lie on one line (a link drawn as a
/// bar, not as a polygon without area); `None` otherwise.
fn bar_ends(pts: &[[f64; 2]]) -> Option<[[f64; 2]; 2]> {
    if pts.len() < 3 {
        return None;
    }
    // the direction through the two points farthest apart
    let mut far = (0.0, 0, 0);
    for i in 0..pts.len() {
        for j in i + 1..pts.len() {
            let d = (pts[j][0] - pts[i][0]).hypot(pts[j][1] - pts[i][1]);
            if d > far.0 {
                far = (d, i, j);
            }
        }
    }
    let (len, a, b) = far;
    if len <= 0.0 {
        return None;
    }
    let u = [(pts[b][0] - pts[a][0]) / len, (pts[b][1] - pts[a][1]) / len];
    let off_line = |p: &[f64; 2]| ((p[0] - pts[a][0]) * u[1] - (p[1] - pts[a][1]) * u[0]).abs();
    pts.iter()
        .all(|p| off_line(p) <= 1e-9 * len)
        .then_some([pts[a], pts[b]])
}

fn world(q: &[f64], body: i64, p: [f64; 2]) -> [f64; 2] {
    if body < 0 {
        return p;
    }
    let k = 3 * body as usize;
    let (s, c) = q[k + 2].sin_cos();
    [q[k] + c * p[0] - s * p[1], q[k + 1] + s * p[0] + c * p[1]]
}

/// The box that holds every drawn point of every frame (a unit box around the origin when
/// there is none).
fn extent(
    frames: &[Vec<f64>],
    bodies: &[BodyGeom],
    joints: &[JointGeom],
    springs: &[SpringGeom],
) -> Extent {
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    let mut grow = |p: [f64; 2]| {
        for k in 0..2 {
            if p[k].is_finite() {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
    };
    for q in frames {
        for (i, b) in bodies.iter().enumerate() {
            for &p in &b.outline {
                grow(world(q, i as i64, p));
            }
        }
    }
    for j in joints {
        for (body, p) in [(j.a, j.pa), (j.b, j.pb)] {
            if let (-1, Some(p)) = (body, p) {
                grow(p);
            }
        }
    }
    for s in springs {
        for (body, p) in [(s.a, s.pa), (s.b, s.pb)] {
            if body == -1 {
                grow(p);
            }
        }
    }
    if !(lo[0] <= hi[0] && lo[1] <= hi[1]) {
        lo = [-1.0, -1.0];
        hi = [1.0, 1.0];
    }
    Extent { lo, hi }
}

fn html_escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// Builds the page for a trajectory of `sys` (`t` and, per frame, all coordinates).
pub fn page(title: &str, sys: &System, t: Vec<f64>, q: Vec<Vec<f64>>) -> Result<String, CliError> {
    let joints = joint_geom(sys);
    let springs = spring_geom(sys);
    let bodies = body_geom(sys, &joints, &springs);
    let extent = extent(&q, &bodies, &joints, &springs);
    let data = Page {
        model: title,
        extent,
        bodies,
        joints,
        springs,
        t,
        q,
    };
    let json = serde_json::to_string(&data).map_err(|e| CliError::Plot {
        path: title.to_string(),
        message: e.to_string(),
    })?;
    // keep the JSON from closing its <script> element
    let json = json.replace("</", "<\\/");
    Ok(include_str!("animate.html")
        .replace("__TITLE__", &html_escape(title))
        .replace("__DATA__", &json))
}

/// Reads the CSV and the model, checks that they belong together and writes the page: the
/// planar page, or for a model with spatial bodies the 3D page of [`crate::animate3d`].
pub fn animate(args: &AnimateArgs) -> Result<(), CliError> {
    let sys = crate::model::load(&args.model)?;
    if sys.has_spatial() {
        crate::animate3d::check_trace(&sys, args.trace.as_ref())?;
        if !sys.bodies().is_empty() {
            note!(
                "note: the model's {} planar bod{} drawn as centres of mass in the plane z = 0",
                sys.bodies().len(),
                if sys.bodies().len() == 1 {
                    "y is"
                } else {
                    "ies are"
                }
            );
        }
    } else if let Some(t) = &args.trace {
        return Err(CliError::Usage(format!(
            "--trace {}: the model has no spatial bodies; the planar page draws the path of \
             every centre of mass",
            t.body
        )));
    }
    let table = Table::read(&args.csv)?;
    let names = sys.coordinate_names();
    let missing: Vec<&str> = std::iter::once("t")
        .chain(names.iter().map(String::as_str))
        .filter(|n| !table.names.iter().any(|c| c == n))
        .collect();
    if !missing.is_empty() {
        return Err(CliError::Mismatch {
            csv: args.csv.display().to_string(),
            model: args.model.display().to_string(),
            missing: missing.join(", "),
        });
    }
    let t = table.column("t")?;
    let cols: Vec<usize> = names
        .iter()
        .map(|n| table.column_index(n))
        .collect::<Result<_, _>>()?;
    let q: Vec<Vec<f64>> = table
        .rows
        .iter()
        .map(|r| cols.iter().map(|&k| r[k]).collect())
        .collect();
    let title = format!(
        "{} ({})",
        args.model.display(),
        args.csv
            .file_name()
            .map(|f| f.to_string_lossy())
            .unwrap_or_default()
    );
    let html = if sys.has_spatial() {
        crate::animate3d::page(&title, &sys, args.trace.as_ref(), t, q)?
    } else {
        page(&title, &sys, t, q)?
    };
    if let Some(dir) = args.out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|e| CliError::write(&args.out, e))?;
    }
    std::fs::write(&args.out, html).map_err(|e| CliError::write(&args.out, e))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn geometry_and_extent_of_the_slider_crank() {
        let sys = mbd_model::models::slider_crank().unwrap();
        let joints = joint_geom(&sys);
        let springs = spring_geom(&sys);
        let bodies = body_geom(&sys, &joints, &springs);
        // every body's outline spans its joint points (a link's two pins), without repeats
        for (i, b) in bodies.iter().enumerate() {
            for j in &joints {
                for (body, p) in [(j.a, j.pa), (j.b, j.pb)] {
                    if let (true, Some(p)) = (body == i as i64, p) {
                        let on = b.outline.iter().any(|o| {
                            let (d, e) = (o[0] - p[0], o[1] - p[1]);
                            d.hypot(e) < 1e-12
                        });
                        let between = b.outline.len() == 2 && {
                            let (a, c) = (b.outline[0], b.outline[1]);
                            let t = ((p[0] - a[0]) * (c[0] - a[0]) + (p[1] - a[1]) * (c[1] - a[1]))
                                / ((c[0] - a[0]).powi(2) + (c[1] - a[1]).powi(2));
                            (-1e-12..=1.0 + 1e-12).contains(&t)
                        };
                        assert!(on || between, "{} {}", b.name, j.name);
                    }
                }
            }
            for (k, p) in b.outline.iter().enumerate() {
                assert!(!b.outline[..k].contains(p), "{} repeats {p:?}", b.name);
            }
        }
        let (q, _) = sys.initial_guess();
        let mut q2 = q.as_slice().to_vec();
        q2[0] += 3.0; // a frame far to the right
        let frames = vec![q.as_slice().to_vec(), q2];
        let e = extent(&frames, &bodies, &joints, &springs);
        assert!(e.hi[0] - e.lo[0] >= 3.0, "{e:?}");
        for f in &frames {
            for (i, b) in bodies.iter().enumerate() {
                for &p in &b.outline {
                    let w = world(f, i as i64, p);
                    for k in 0..2 {
                        assert!(e.lo[k] <= w[k] && w[k] <= e.hi[k], "{w:?} outside {e:?}");
                    }
                }
            }
        }
    }

    #[test]
    fn links_whose_points_lie_on_a_line_are_bars() {
        // a crank: centre of mass between its two pins
        let pts = [[0.0, 0.0], [-0.075, 0.0], [0.075, 0.0]];
        assert_eq!(bar_ends(&pts), Some([[-0.075, 0.0], [0.075, 0.0]]));
        // a slanted link with its centre of mass beyond one pin
        let pts = [[0.0, 0.0], [0.1, 0.2], [0.2, 0.4]];
        assert_eq!(bar_ends(&pts), Some([[0.0, 0.0], [0.2, 0.4]]));
        // a plate
        assert_eq!(bar_ends(&[[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]), None);
        assert_eq!(bar_ends(&[[0.0, 0.0], [1.0, 0.0]]), None);
    }

    #[test]
    fn names_cannot_break_out_of_the_page() {
        let mut b = mbd_model::SystemBuilder::new();
        let h = b.add_body(mbd_model::Body::new("</script><b>x").rod(1.0, 1.0));
        b.add_joint(mbd_model::Joint::revolute(
            "pin",
            mbd_model::BodyRef::Ground,
            [0.0, 0.0],
            h,
            [-0.5, 0.0],
        ));
        let sys = b.build().unwrap();
        let html = page("<title>", &sys, vec![0.0], vec![vec![0.5, 0.0, 0.0]]).unwrap();
        assert_eq!(
            html.matches("</script>").count(),
            2,
            "only the page's own scripts close"
        );
        assert!(html.contains("&lt;title&gt;"));
    }
}
